//! What `pendulum simulate` says about a whirled chain (3D, pivot circling the vertical,
//! steady or ramped): the shape the run library's analysis found, in the user's terms —
//! one summary line, `shape.json` and `shape.png`.

use std::path::Path;

use pendulum_core::{NearestSteady, ShapeReport, WhirlShape};
use pendulum_experiment::words::growth_words;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use crate::error::CliResult;
use crate::plot::{drawing_failed, fonts};

/// The report of a whirled run in the user's terms: its summary line on stdout and (with
/// `plots`) `shape.png` in `out`.
pub fn present(report: &ShapeReport, out: &Path, plots: bool) -> CliResult<()> {
    println!("{}", summary(report));
    if plots {
        plot(&out.join("shape.png"), report)?;
    }
    Ok(())
}

/// Writes `shape.json` (before the pictures, with the run's other data).
pub fn write(report: &ShapeReport, out: &Path) -> CliResult<()> {
    pendulum_experiment::whirl::write_shape_json(&out.join("shape.json"), report)
}

/// `1 node`, `2 nodes`.
fn plural(count: usize, noun: &str) -> String {
    if count == 1 { format!("1 {noun}") } else { format!("{count} {noun}s") }
}

/// `stable`, or `unstable`, with the growth rate of the nearest steady shape.
fn stability(n: &NearestSteady) -> String {
    let rate = growth_words(n.growth_rate, n.rate_bound);
    if n.stable {
        format!("stable (largest growth rate {rate})")
    } else {
        format!("unstable (growth rate {rate})")
    }
}

/// The one line a user came for: nodes, tip radius, settled, and the nearest steady
/// shape with its stability.
pub fn summary(r: &ShapeReport) -> String {
    let s = &r.shape;
    let settled = if r.settling.settled {
        format!(
            "settled (drift {:.1e} m ≤ {:.1e} m over the last {:.3} s)",
            r.settling.drift, r.settling.threshold, r.settling.window
        )
    } else if !r.settling.covered {
        format!("not settled (the run is shorter than the {:.3} s window)", r.settling.window)
    } else {
        format!(
            "not settled (drift {:.1e} m > {:.1e} m over the last {:.3} s)",
            r.settling.drift, r.settling.threshold, r.settling.window
        )
    };
    let nearest = match &r.nearest {
        Ok(n) => format!(
            "nearest steady shape {:.1e} m away: {}, {}",
            n.distance,
            plural(n.shape.nodes, "node"),
            stability(n)
        ),
        Err(e) => format!("no steady shape found nearby ({e})"),
    };
    format!(
        "shape at t = {:.4} s, ω = {:.6} rad/s: {} ({}; the pivot counts as a node), \
         tip radius {:.4e} m, {settled}; {nearest}",
        r.t,
        r.omega,
        plural(s.nodes, "node"),
        plural(s.axis_crossings, "axis crossing"),
        s.tip_radius
    )
}

/// Where the signed radial coordinate changes sign between masses `i` and `i + 1`: the
/// axis crossings, linearly interpolated, as (radial, height) = (0, −depth).
fn crossings(s: &WhirlShape) -> Vec<(f64, f64)> {
    (1..s.radial.len())
        .filter(|&i| s.radial[i - 1] * s.radial[i] < 0.0)
        .map(|i| {
            let (a, b) = (s.radial[i - 1], s.radial[i]);
            let f = a / (a - b);
            (0.0, -(s.depth[i - 1] + f * (s.depth[i] - s.depth[i - 1])))
        })
        .collect()
}

/// `shape.png`: the final shape in its plane, seen in the turning frame — the signed
/// distance from the rotation axis (horizontal, stretched to show the shape) against the
/// depth below the pivot; the axis, the nodes (the pivot and the axis crossings), and the
/// nearest damped steady shape overlaid.
/// What the shape plot shows: the half-width `x` and the vertical range `y` (m), and the
/// stretch across when it is not to scale.
#[derive(Debug, PartialEq)]
struct Frame {
    x: f64,
    y: (f64, f64),
    stretch: Option<f64>,
}

/// The frame of a shape `width` m either side of the axis and `depth` m deep on a plot of
/// `px` pixels (w, h): to scale where the shape allows it (the emptier direction widened),
/// else stretched across by more than [`MOST_UNSTRETCHED`].
fn frame(width: f64, depth: f64, px: (f64, f64)) -> Frame {
    let (top, bottom) = (0.04 * depth, -1.04 * depth);
    let stretch = (px.0 / (2.0 * width)) / (px.1 / (top - bottom));
    if stretch < 1.0 {
        Frame { x: width, y: (top - px.1 * 2.0 * width / px.0, top), stretch: None }
    } else if stretch < MOST_UNSTRETCHED {
        Frame { x: px.0 * (top - bottom) / px.1 / 2.0, y: (bottom, top), stretch: None }
    } else {
        Frame { x: width, y: (bottom, top), stretch: Some(stretch) }
    }
}

/// A chart in metres on both axes.
type Metres<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// The shape plot's layout on `root`, over `x` × `y` (m).
fn layout<'a, DB: DrawingBackend>(
    root: &'a DrawingArea<DB, plotters::coord::Shift>,
    caption: &str,
    x: (f64, f64),
    y: (f64, f64),
) -> Result<Metres<'a, DB>, DrawingAreaErrorKind<DB::ErrorType>> {
    ChartBuilder::on(root)
        .caption(caption, ("sans-serif", 20))
        .margin(14)
        .x_label_area_size(44)
        .y_label_area_size(64)
        .build_cartesian_2d(x.0..x.1, y.0..y.1)
}

/// A shape at most this much wider in pixels per metre across than down is drawn to scale
/// instead.
const MOST_UNSTRETCHED: f64 = 1.5;

fn plot(path: &Path, r: &ShapeReport) -> CliResult<()> {
    fonts();
    let fail = |e: &dyn std::fmt::Display| drawing_failed(path, e);
    let root = BitMapBackend::new(path, (720, 900)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| fail(&e))?;
    let s = &r.shape;
    // The pivot in the plane: (R cos α, 0) in (radial, depth).
    let pivot = (r.radius * s.plane_azimuth.cos(), 0.0);
    let curve = |w: &WhirlShape| -> Vec<(f64, f64)> {
        std::iter::once(pivot).chain(w.radial.iter().zip(&w.depth).map(|(x, d)| (*x, -*d))).collect()
    };
    let chain_points = curve(s);
    let steady_points = r.nearest.as_ref().ok().map(|n| curve(&n.shape));
    let all = chain_points.iter().chain(steady_points.iter().flatten());
    let width = all.clone().map(|p| p.0.abs()).fold(r.radius.abs(), f64::max).max(1e-6) * 1.15;
    let depth = all.map(|p| -p.1).fold(0.0, f64::max).max(1e-6);
    let settled = if r.settling.settled { "settled" } else { "not settled" };
    let stable = match &r.nearest {
        Ok(n) if n.stable => "nearest steady shape stable",
        Ok(_) => "nearest steady shape unstable",
        Err(_) => "no steady shape found",
    };
    let caption = format!("ω = {:.3} rad/s: {}, {settled}; {stable}", r.omega, plural(s.nodes, "node"));
    // The plot's size in pixels, from the same layout drawn into a scratch buffer.
    let (w_px, h_px) = {
        let mut scratch = vec![0u8; 720 * 900 * 3];
        let area = BitMapBackend::with_buffer(&mut scratch, (720, 900)).into_drawing_area();
        let chart = layout(&area, &caption, (-1.0, 1.0), (-1.0, 1.0)).map_err(|e| fail(&e))?;
        let (w, h) = chart.plotting_area().dim_in_pixel();
        (f64::from(w), f64::from(h))
    };
    let Frame { x, y, stretch } = frame(width, depth, (w_px, h_px));
    let mut chart = layout(&root, &caption, (-x, x), y).map_err(|e| fail(&e))?;
    chart
        .configure_mesh()
        .x_desc(if let Some(stretch) = stretch {
            format!(
                "signed distance from the rotation axis in the shape's plane (m), stretched ×{}",
                if stretch < 10.0 { format!("{stretch:.1}") } else { format!("{stretch:.0}") }
            )
        } else {
            "signed distance from the rotation axis in the shape's plane (m), to scale".to_string()
        })
        .y_desc("height relative to the pivot (m)")
        .light_line_style(BLACK.mix(0.03))
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(|e| fail(&e))?;
    let axis = ShapeStyle::from(&BLACK.mix(0.6)).stroke_width(1);
    chart
        .draw_series(DashedLineSeries::new(vec![(0.0, y.1), (0.0, y.0)], 8, 6, axis))
        .map_err(|e| fail(&e))?
        .label("rotation axis")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], axis));
    let blue = RGBColor(31, 90, 180);
    chart
        .draw_series(LineSeries::new(chain_points.clone(), blue.stroke_width(2)))
        .map_err(|e| fail(&e))?
        .label(format!("the chain at t = {:.2} s", r.t))
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], blue.stroke_width(2)));
    chart
        .draw_series(chain_points.iter().skip(1).map(|p| Circle::new(*p, 2, blue.filled())))
        .map_err(|e| fail(&e))?;
    if let Some(points) = steady_points {
        let orange = RGBColor(230, 120, 20);
        chart
            .draw_series(DashedLineSeries::new(points, 10, 5, orange.mix(0.9).stroke_width(3)))
            .map_err(|e| fail(&e))?
            .label("nearest damped steady shape")
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], orange.mix(0.9).stroke_width(3))
            });
    }
    let nodes: Vec<(f64, f64)> = std::iter::once(pivot).chain(crossings(s)).collect();
    chart
        .draw_series(nodes.iter().map(|p| Circle::new(*p, 7, RED.stroke_width(2))))
        .map_err(|e| fail(&e))?
        .label(format!("nodes: the pivot and {}", plural(s.axis_crossings, "axis crossing")))
        .legend(|(x, y)| Circle::new((x + 10, y), 6, RED.stroke_width(2)));
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .draw()
        .map_err(|e| fail(&e))?;
    root.present().map_err(|e| fail(&e))
}

#[cfg(test)]
mod tests {
    use super::{Frame, frame};

    /// Pixels per metre across and down.
    fn scales(f: &Frame, px: (f64, f64)) -> (f64, f64) {
        (px.0 / (2.0 * f.x), px.1 / (f.y.1 - f.y.0))
    }

    #[test]
    fn shapes_are_drawn_to_scale_unless_too_narrow_and_then_say_so() {
        let px = (620.0, 780.0);
        // Issue 34: the ramped 1-node shape (0.86 m out, 0.53 m down) was drawn at
        // 319 px/m across against 1390 px/m down, unlabelled.
        for (width, depth) in [(0.99, 0.53), (0.5, 1.0), (0.3, 1.0)] {
            let f = frame(width, depth, px);
            let (across, down) = scales(&f, px);
            assert!((across / down - 1.0).abs() < 1e-12, "{width} × {depth}: {across} against {down} px/m");
            assert!(f.x >= width && f.y.0 <= -1.04 * depth && f.y.1 >= 0.04 * depth, "{f:?}");
            assert_eq!(f.stretch, None);
        }
        // A 2-node shape 6 cm out of 1 m: stretched across, by the ratio it names.
        let f = frame(0.069, 1.0, px);
        let (across, down) = scales(&f, px);
        assert!((f.stretch.unwrap() - across / down).abs() < 1e-12 && f.stretch.unwrap() > 1.5);
    }
}
