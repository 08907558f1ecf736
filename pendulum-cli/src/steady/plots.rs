//! The pictures of `pendulum steady` (plotters, PNG): the branch diagram branches.png and
//! the shapes at the listed speeds, shapes.png.
//!
//! Both use one code: colour = node count (grey: the vertical), line = stability,
//! **thick solid** stable, **thin solid** gyroscopically stabilised (spectrally stable,
//! index > 0: destroyed by damping in the turning frame), **dashed** unstable.

use std::path::Path;

use nalgebra::Dyn;
use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::branches::Family;
use super::nodes_name;
use crate::error::CliResult;
use crate::plot::{drawing_failed, fonts};
use pendulum_core::{Chain, Verdict};
use pendulum_experiment::steady::AtSpeed;

pub(crate) type Chart<'a> = ChartContext<'a, BitMapBackend<'a>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

pub(crate) const GREY: RGBColor = RGBColor(140, 140, 140);

/// The colour of a node count (`None`: the vertical).
pub(crate) fn colour(nodes: Option<usize>) -> RGBColor {
    const PALETTE: [RGBColor; 6] = [
        RGBColor(0, 90, 181),
        RGBColor(220, 50, 32),
        RGBColor(0, 140, 70),
        RGBColor(120, 80, 160),
        RGBColor(230, 150, 0),
        RGBColor(140, 86, 75),
    ];
    nodes.map_or(GREY, |k| PALETTE[(k + PALETTE.len() - 1) % PALETTE.len()])
}

/// `c` blended toward white, 35 % of it left (the mirror branches).
pub(crate) fn faint(c: RGBColor) -> RGBColor {
    let blend = |v: u8| (255.0 - 0.35 * (255.0 - f64::from(v))).round() as u8;
    RGBColor(blend(c.0), blend(c.1), blend(c.2))
}

/// Draws the polyline `points` in `colour` with the line of `verdict` (module docs).
fn draw_line(
    chart: &mut Chart<'_>,
    points: Vec<(f64, f64)>,
    colour: RGBColor,
    verdict: &Verdict,
) -> Result<(), String> {
    let drawn = match verdict {
        Verdict::Stable => chart.draw_series(LineSeries::new(points, colour.stroke_width(3))).map(|_| ()),
        Verdict::Gyroscopic { .. } => {
            chart.draw_series(LineSeries::new(points, colour.stroke_width(1))).map(|_| ())
        }
        Verdict::Unstable { .. } => {
            chart.draw_series(DashedLineSeries::new(points, 7, 5, colour.stroke_width(2))).map(|_| ())
        }
    };
    drawn.map_err(|e| e.to_string())
}

/// How a line or mark is drawn in a key.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Stroke {
    /// Thick solid: stable.
    Thick,
    /// Thin solid: gyroscopic.
    Thin,
    /// Dashed: unstable.
    Dashed,
    /// A filled dot.
    Dot,
    /// A hollow dot.
    Ring,
    /// Text only.
    Text,
}

fn stroke_of(verdict: &Verdict) -> Stroke {
    match verdict {
        Verdict::Stable => Stroke::Thick,
        Verdict::Gyroscopic { .. } => Stroke::Thin,
        Verdict::Unstable { .. } => Stroke::Dashed,
    }
}

/// Draws a key on `area`: one entry per line, 20 px apart from `top`, a sample of the line
/// or mark then the text.
pub(crate) fn draw_key(
    area: &DrawingArea<BitMapBackend<'_>, Shift>,
    top: i32,
    entries: &[(String, RGBColor, Stroke)],
) -> Result<(), String> {
    let fail = |e: &dyn std::fmt::Display| e.to_string();
    let style = TextStyle::from(("sans-serif", 14).into_font()).pos(Pos::new(HPos::Left, VPos::Center));
    for (row, (text, c, stroke)) in entries.iter().enumerate() {
        let y = top + 20 * row as i32;
        let line = |a: i32, b: i32, w: u32| PathElement::new(vec![(a, y), (b, y)], c.stroke_width(w));
        match stroke {
            Stroke::Thick => area.draw(&line(14, 40, 3)),
            Stroke::Thin => area.draw(&line(14, 40, 1)),
            Stroke::Dashed => area.draw(&line(14, 23, 2)).and_then(|_| area.draw(&line(29, 40, 2))),
            Stroke::Dot => area.draw(&Circle::new((27, y), 5, c.filled())),
            Stroke::Ring => area.draw(&Circle::new((27, y), 5, c.stroke_width(2))),
            Stroke::Text => Ok(()),
        }
        .map_err(|e| fail(&e))?;
        area.draw_text(text, &style, (if *stroke == Stroke::Text { 14 } else { 48 }, y))
            .map_err(|e| fail(&e))?;
    }
    Ok(())
}

/// The branch diagram: the signed distance of the free end from the axis, `x_n` (m),
/// against `ω` (rad/s), coloured by node count and drawn by stability; for a fixed pivot
/// the mirror branches (`θ → −θ`, the same shapes turned by π) faint and the vertical
/// (`x_n = 0`) in grey; the shapes at the listed speeds as dots (hollow: unstable) on
/// dotted verticals.
pub fn branches(
    path: &Path,
    family: &Family,
    found: &[AtSpeed],
    omega_max: f64,
    radius: f64,
) -> CliResult<()> {
    fonts();
    draw_branches(path, family, found, omega_max, radius).map_err(|e| drawing_failed(path, e))
}

fn draw_branches(
    path: &Path,
    family: &Family,
    found: &[AtSpeed],
    omega_max: f64,
    radius: f64,
) -> Result<(), String> {
    let fail = |e: &dyn std::fmt::Display| e.to_string();
    let root = BitMapBackend::new(path, (1060, 560)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| fail(&e))?;
    let (plot, key) = root.split_horizontally(820);
    let reach = reach(family, radius);
    let caption = if radius == 0.0 {
        "steady rotation on a fixed pivot: the free end's distance from the axis".to_string()
    } else {
        format!("steady rotation, pivot on a circle of R = {radius} m: the free end's distance from the axis")
    };
    let mut chart = ChartBuilder::on(&plot)
        .caption(caption, ("sans-serif", 19))
        .margin(14)
        .x_label_area_size(44)
        .y_label_area_size(64)
        .build_cartesian_2d(0.0..1.02 * omega_max, -1.12 * reach..1.12 * reach)
        .map_err(|e| fail(&e))?;
    let y_desc = if radius == 0.0 { "x_n (m), signed" } else { "x_n (m), + on the pivot's side" };
    chart
        .configure_mesh()
        .x_desc("angular speed ω (rad/s)")
        .y_desc(y_desc)
        .light_line_style(WHITE.mix(0.0))
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 15))
        .draw()
        .map_err(|e| fail(&e))?;
    let mut speeds: Vec<f64> = found.iter().map(|f| f.shape.omega).collect();
    speeds.dedup();
    for &w in &speeds {
        chart
            .draw_series(DashedLineSeries::new(
                [(w, -1.12 * reach), (w, 1.12 * reach)],
                2,
                4,
                BLACK.mix(0.35).stroke_width(1),
            ))
            .map_err(|e| fail(&e))?;
    }
    let counts = draw_family(&mut chart, family, radius)?;
    for f in found {
        let c = colour(f.nodes);
        let at = (f.shape.omega, tip(&f.shape.displacements));
        let style = if f.judged.verdict.is_stable() { c.filled() } else { c.stroke_width(2) };
        chart.draw_series([Circle::new(at, 5, style)]).map_err(|e| fail(&e))?;
    }
    let mut entries = family_key(counts, radius);
    if !found.is_empty() {
        entries.push((String::new(), BLACK, Stroke::Text));
        entries.push(("shape at a listed ω".into(), DARK, Stroke::Dot));
        entries.push(("the same, unstable".into(), DARK, Stroke::Ring));
    }
    draw_key(&key, 60, &entries)?;
    root.present().map_err(|e| fail(&e))
}

/// The free end's signed distance from the axis, `x_n` (m), of a shape's displacements.
fn tip(x: &[f64]) -> f64 {
    *x.last().unwrap_or(&0.0)
}

/// The largest `|x_n|` on the branches of `family` (at least `|radius|` and 1 mm), m: the
/// half-height the branch diagram needs.
pub(crate) fn reach(family: &Family, radius: f64) -> f64 {
    family
        .branches
        .iter()
        .flat_map(|b| b.branch.points.iter().map(|p| tip(&p.displacements).abs()))
        .fold(radius.abs(), f64::max)
        .max(1e-3)
}

/// Draws the branches of `family` on `chart` (ω in rad/s across, `x_n` in m up) as the
/// branch diagram shows them (module docs; for a fixed pivot also the vertical and the
/// faint mirror branches); returns the node counts drawn, ascending, once each.
/// `pendulum sweep` draws the chain's choices over the same lines.
pub(crate) fn draw_family(chart: &mut Chart<'_>, family: &Family, radius: f64) -> Result<Vec<usize>, String> {
    for (from, to, judged) in &family.vertical {
        draw_line(chart, vec![(*from, 0.0), (*to, 0.0)], GREY, &judged.verdict)?;
    }
    let mut counts: Vec<usize> = Vec::new();
    for labelled in &family.branches {
        let points = &labelled.branch.points;
        // Node count and verdict shown for a point (the bifurcation point takes the next's).
        let nodes = |i: usize| labelled.nodes[labelled.shown(i)];
        let verdict = |i: usize| &labelled.judged[labelled.shown(i)].verdict;
        let mut start = 0;
        for i in 1..=points.len() {
            let same =
                i < points.len() && nodes(i) == nodes(start) && verdict(i).label() == verdict(start).label();
            if same {
                continue;
            }
            // The run shares its last point with the next one, so the line is unbroken.
            let last = i.min(points.len() - 1);
            let run: Vec<(f64, f64)> =
                points[start..=last].iter().map(|p| (p.omega, tip(&p.displacements))).collect();
            let c = colour(nodes(start));
            if radius == 0.0 {
                draw_line(chart, run.iter().map(|&(w, x)| (w, -x)).collect(), faint(c), verdict(start))?;
            }
            draw_line(chart, run, c, verdict(start))?;
            counts.extend(nodes(start));
            start = i;
        }
    }
    counts.sort_unstable();
    counts.dedup();
    Ok(counts)
}

/// The grey of the key's samples of line styles.
pub(crate) const DARK: RGBColor = RGBColor(60, 60, 60);

/// The key of the branch lines: colour by node count (`counts`, from [`draw_family`]; for
/// a fixed pivot the vertical and the mirror branches), line by stability.
pub(crate) fn family_key(counts: Vec<usize>, radius: f64) -> Vec<(String, RGBColor, Stroke)> {
    let mut entries: Vec<(String, RGBColor, Stroke)> =
        vec![("colour: node count".into(), BLACK, Stroke::Text)];
    entries.extend(counts.into_iter().map(|k| (nodes_name(k), colour(Some(k)), Stroke::Thick)));
    if radius == 0.0 {
        entries.push(("vertical (on the axis)".into(), GREY, Stroke::Thick));
        entries.push(("faint: mirror image (−θ)".into(), faint(colour(Some(1))), Stroke::Thick));
    }
    entries.push((String::new(), BLACK, Stroke::Text));
    entries.push(("line: stability".into(), BLACK, Stroke::Text));
    entries.push(("stable (index 0)".into(), DARK, Stroke::Thick));
    entries.push(("gyroscopic (index > 0)".into(), DARK, Stroke::Thin));
    entries.push(("unstable".into(), DARK, Stroke::Dashed));
    entries
}

/// Most panels in shapes.png.
const MAX_PANELS: usize = 12;

/// The shapes at each listed speed, one panel per speed (up to 12, three to a row): the
/// masses at `(x_i, z_i)`, `z_i = −Σ_{j≤i} l_j cos θ_j`, in the turning plane, from the
/// pivot at `(R, 0)`; a legend under each panel.
pub fn shapes(
    path: &Path,
    chain: &Chain<Dyn>,
    radius: f64,
    found: &[AtSpeed],
    speeds: &[f64],
) -> CliResult<()> {
    fonts();
    let mut unique: Vec<f64> = Vec::new();
    for &w in speeds {
        if !unique.contains(&w) {
            unique.push(w);
        }
    }
    if unique.len() > MAX_PANELS {
        eprintln!("pendulum: note: shapes.png shows the first {MAX_PANELS} of the {} speeds", unique.len());
        unique.truncate(MAX_PANELS);
    }
    draw_shapes(path, chain, radius, found, &unique).map_err(|e| drawing_failed(path, e))
}

fn draw_shapes(
    path: &Path,
    chain: &Chain<Dyn>,
    radius: f64,
    found: &[AtSpeed],
    speeds: &[f64],
) -> Result<(), String> {
    let fail = |e: &dyn std::fmt::Display| e.to_string();
    let columns = speeds.len().clamp(1, 3);
    let rows = speeds.len().div_ceil(columns).max(1);
    let lines =
        speeds.iter().map(|&w| found.iter().filter(|f| f.shape.omega == w).count()).max().unwrap_or(0);
    let (width, plot_height) = if columns == 1 { (640, 420) } else { (460, 330) };
    let legend_height = 20 * lines as u32 + 14;
    let panel = (width, plot_height + legend_height);
    let root =
        BitMapBackend::new(path, (panel.0 * columns as u32, panel.1 * rows as u32)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| fail(&e))?;
    let total: f64 = chain.lengths().iter().sum();
    let r = 1.05 * (total + radius);
    for (area, &omega) in root.split_evenly((rows, columns)).iter().zip(speeds) {
        let (upper, lower) = area.split_vertically(plot_height);
        let mut chart = ChartBuilder::on(&upper)
            .caption(format!("ω = {omega} rad/s"), ("sans-serif", 17))
            .margin(10)
            .x_label_area_size(36)
            .y_label_area_size(50)
            .build_cartesian_2d(-r..r, -r..0.15 * r)
            .map_err(|e| fail(&e))?;
        let decimals = (-(r / 6.0).log10().floor()).max(0.0) as usize;
        let tick = move |v: &f64| {
            let text = format!("{v:.decimals$}");
            if text.trim_start_matches(['-', '0', '.']).is_empty() { text.replace('-', "") } else { text }
        };
        chart
            .configure_mesh()
            .x_desc("x (m), in the turning plane")
            .y_desc("z (m)")
            .x_label_formatter(&tick)
            .y_label_formatter(&tick)
            .light_line_style(WHITE.mix(0.0))
            .label_style(("sans-serif", 13))
            .draw()
            .map_err(|e| fail(&e))?;
        chart
            .draw_series(DashedLineSeries::new([(0.0, 0.15 * r), (0.0, -r)], 4, 4, GREY.stroke_width(1)))
            .map_err(|e| fail(&e))?;
        let here: Vec<&AtSpeed> = found.iter().filter(|f| f.shape.omega == omega).collect();
        for f in &here {
            let c = colour(f.nodes);
            let mut z = 0.0;
            let mut points = vec![(radius, 0.0)];
            for (l, (theta, x)) in
                chain.lengths().iter().zip(f.shape.theta.iter().zip(&f.shape.displacements))
            {
                z -= l * theta.cos();
                points.push((*x, z));
            }
            draw_line(&mut chart, points.clone(), c, &f.judged.verdict)?;
            chart
                .draw_series(points[1..].iter().map(|&p| Circle::new(p, 3, c.filled())))
                .map_err(|e| fail(&e))?;
        }
        chart
            .draw_series([Rectangle::new(
                [(radius - 0.015 * r, 0.015 * r), (radius + 0.015 * r, -0.015 * r)],
                BLACK.filled(),
            )])
            .map_err(|e| fail(&e))?;
        // The key under the panel: a sample of each shape's line and what it is.
        let entries: Vec<(String, RGBColor, Stroke)> = here
            .iter()
            .map(|f| {
                let what = match f.nodes {
                    Some(k) => format!("#{}: {}, {}", f.branch, nodes_name(k), f.judged.verdict),
                    None => format!("vertical: {}", f.judged.verdict),
                };
                let damped = f.damped.map_or(String::new(), |d| format!("; damped {}", d.verdict.label()));
                (format!("{what}{damped}"), colour(f.nodes), stroke_of(&f.judged.verdict))
            })
            .collect();
        draw_key(&lower, 12, &entries)?;
    }
    root.present().map_err(|e| fail(&e))
}
