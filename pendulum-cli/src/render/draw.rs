//! One frame of the animation, drawn with plotters into an RGB buffer: axes with tick
//! labels in metres, the rotation axis of a circling pivot, the tip's fading trail, the
//! chain (rods black, masses blue, the pivot a red square), a scale bar and the title
//! line (time, view, playback speed).

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::colors::TRANSPARENT;

use super::view::{AxisMark, Bounds, Projection};
use crate::plot::fonts;

/// The masses.
pub const MASS: RGBColor = RGBColor(20, 60, 220);
/// The pivot.
pub const PIVOT: RGBColor = RGBColor(210, 30, 30);
/// The rotation axis.
const AXIS: RGBColor = RGBColor(90, 90, 90);
/// The grid lines at the ticks.
const GRID: RGBColor = RGBColor(228, 228, 228);
/// The tip's trail, newest part; older parts fade toward white in [`TRAIL_SHADES`] steps.
const TRAIL: RGBColor = RGBColor(255, 140, 0);
const TRAIL_SHADES: usize = 8;

/// The colours drawn (besides the blends of anti-aliased text and edges), for the palette.
pub fn colours() -> Vec<[u8; 3]> {
    let mut all = vec![[255, 255, 255], [0, 0, 0]];
    all.extend([MASS, PIVOT, AXIS, GRID].map(|c| [c.0, c.1, c.2]));
    all.extend((0..TRAIL_SHADES).map(|k| {
        let c = trail_shade(k);
        [c.0, c.1, c.2]
    }));
    all
}

/// Shade `k` of the trail, 0 the faintest.
fn trail_shade(k: usize) -> RGBColor {
    let f = (k + 1) as f64 / TRAIL_SHADES as f64;
    let mix = |c: u8| (255.0 - f * (255.0 - f64::from(c))).round() as u8;
    RGBColor(mix(TRAIL.0), mix(TRAIL.1), mix(TRAIL.2))
}

/// What one frame shows.
#[derive(Debug, Clone, PartialEq)]
pub struct Shot {
    /// Time, s.
    pub t: f64,
    /// The pivot and the masses, mass 1 first, drawn points (m).
    pub points: Vec<(f64, f64)>,
    /// The tip over the preceding stretch, oldest first (m).
    pub trail: Vec<(f64, f64)>,
}

/// Pixel sizes of a frame of side `size`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Layout {
    /// Side of the square frame, px.
    pub size: u32,
    /// Height of the title line.
    title: u32,
    /// Margin around the chart.
    margin: u32,
    /// Space for the x tick labels and description, below the plot.
    x_area: u32,
    /// Space for the y tick labels and description, left of the plot.
    y_area: u32,
    /// Text height of the title, and of the axes' labels.
    title_font: u32,
    font: u32,
}

impl Layout {
    /// The layout of a frame `size` px square.
    pub fn new(size: u32) -> Self {
        let scaled = |px: f64| (px * f64::from(size) / 600.0).round() as u32;
        let (title_font, font) = (scaled(18.0).max(12), scaled(16.0).max(11));
        let title = title_font + scaled(14.0);
        Self { size, title, margin: scaled(12.0), x_area: 3 * font, y_area: 4 * font + 8, title_font, font }
    }

    /// The plot's size inside the axes, px (w, h).
    pub fn plot(&self) -> (u32, u32) {
        let w = self.size - 2 * self.margin - self.y_area;
        let h = self.size - self.title - 2 * self.margin - self.x_area;
        (w, h)
    }
}

/// Everything a frame shows but the chain.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// Pixel sizes.
    pub layout: Layout,
    /// The region shown, m.
    pub viewport: Bounds,
    /// The view.
    pub projection: Projection,
    /// The rotation axis, when the pivot circles it.
    pub axis: Option<AxisMark>,
    /// The title after the time: view and speed.
    pub caption: String,
    /// Decimals of the time in the title.
    pub decimals: usize,
    /// Number of links (sets the dot size).
    pub links: usize,
}

/// Draws `shot` into `buffer` (RGB, `size × size`).
pub fn frame(buffer: &mut [u8], scene: &Scene, shot: &Shot) -> Result<(), String> {
    fonts();
    let l = scene.layout;
    let root = BitMapBackend::with_buffer(buffer, (l.size, l.size)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let (title, body) = root.split_vertically(l.title);
    let decimals = scene.decimals;
    let text = format!("t = {:.decimals$} s   {}", shot.t, scene.caption);
    let style = ("sans-serif", l.title_font).into_font().color(&BLACK);
    let at = (l.margin as i32, (l.title - l.title_font) as i32 / 2 + 2);
    title.draw(&Text::new(text, at, style)).map_err(|e| e.to_string())?;
    chart(&body, scene, shot).map_err(|e| e.to_string())?;
    root.present().map_err(|e| e.to_string())
}

type DrawResult<T> = Result<T, DrawingAreaErrorKind<<BitMapBackend<'static> as DrawingBackend>::ErrorType>>;

fn chart(body: &DrawingArea<BitMapBackend<'_>, Shift>, scene: &Scene, shot: &Shot) -> DrawResult<()> {
    let l = scene.layout;
    let v = scene.viewport;
    let mut chart = ChartBuilder::on(body)
        .margin(l.margin)
        .x_label_area_size(l.x_area)
        .y_label_area_size(l.y_area)
        .build_cartesian_2d(v.x.0..v.x.1, v.y.0..v.y.1)?;
    let (x_desc, y_desc) = scene.projection.labels();
    let text = ("sans-serif", l.font).into_font().color(&BLACK);
    chart
        .configure_mesh()
        .x_labels(7)
        .y_labels(7)
        .bold_line_style(GRID)
        .light_line_style(TRANSPARENT)
        .x_label_formatter(&tick)
        .y_label_formatter(&tick)
        .x_desc(x_desc)
        .y_desc(y_desc)
        .label_style(text.clone())
        .axis_desc_style(text.clone())
        .draw()?;
    let px = |k: f64| (k * f64::from(l.size) / 600.0).round().max(1.0) as i32;
    let line = px(2.0) as u32;
    match scene.axis {
        Some(AxisMark::Line) => {
            let dashed =
                DashedLineSeries::new([(0.0, v.y.0), (0.0, v.y.1)], px(8.0), px(5.0), AXIS.stroke_width(1));
            chart.draw_series(dashed)?;
            let label = Text::new("rotation axis", (px(4.0), px(3.0)), text.clone().color(&AXIS));
            chart.draw_series(std::iter::once(EmptyElement::at((0.0, v.y.1)) + label))?;
        }
        Some(AxisMark::Centre) => {
            let arm = px(8.0);
            let cross = EmptyElement::at((0.0, 0.0))
                + PathElement::new([(-arm, 0), (arm, 0)], AXIS.stroke_width(1))
                + PathElement::new([(0, -arm), (0, arm)], AXIS.stroke_width(1));
            chart.draw_series(std::iter::once(cross))?;
        }
        None => {}
    }
    scale_bar(&mut chart, v, &text, px)?;
    // The trail, oldest (faintest) first, one path per shade.
    let n = shot.trail.len();
    for k in 0..TRAIL_SHADES {
        let (lo, hi) = (k * n / TRAIL_SHADES, ((k + 1) * n / TRAIL_SHADES + 1).min(n));
        if hi >= lo + 2 {
            let path = PathElement::new(shot.trail[lo..hi].to_vec(), trail_shade(k).stroke_width(line));
            chart.draw_series(std::iter::once(path))?;
        }
    }
    chart.draw_series(std::iter::once(PathElement::new(shot.points.clone(), BLACK.stroke_width(line))))?;
    let dot = match scene.links {
        0..=8 => px(6.0),
        9..=20 => px(4.0),
        _ => px(2.5),
    };
    chart.draw_series(shot.points[1..].iter().map(|&p| Circle::new(p, dot, MASS.filled())))?;
    let h = px(5.0);
    let square = EmptyElement::at(shot.points[0]) + Rectangle::new([(-h, -h), (h, h)], PIVOT.filled());
    chart.draw_series(std::iter::once(square))?;
    Ok(())
}

type Chart<'a, 'b> = ChartContext<
    'a,
    BitMapBackend<'b>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// A bar of a round length (1, 2 or 5 × 10ᵏ m, at most a quarter of the width) in the
/// lower left corner, labelled in m, cm or mm.
fn scale_bar(
    chart: &mut Chart<'_, '_>,
    v: Bounds,
    text: &TextStyle<'_>,
    px: impl Fn(f64) -> i32,
) -> DrawResult<()> {
    let (w, h) = (v.x.1 - v.x.0, v.y.1 - v.y.0);
    let length = round_below(0.25 * w);
    let (x0, y0) = (v.x.0 + 0.05 * w, v.y.0 + 0.05 * h);
    let style = BLACK.stroke_width(px(3.0) as u32);
    let tick = px(5.0);
    let bar = EmptyElement::at((x0, y0))
        + PathElement::new([(0, -tick), (0, tick)], style)
        + Text::new(length_words(length), (0, -tick - px(4.0) - text.font.get_size() as i32), text.clone());
    chart.draw_series(std::iter::once(PathElement::new([(x0, y0), (x0 + length, y0)], style)))?;
    chart.draw_series(std::iter::once(bar))?;
    chart.draw_series(std::iter::once(
        EmptyElement::at((x0 + length, y0)) + PathElement::new([(0, -tick), (0, tick)], style),
    ))?;
    Ok(())
}

/// A tick label: at most 6 decimals, no trailing zeros, no "-0".
fn tick(v: &f64) -> String {
    let text = format!("{v:.6}");
    let text = text.trim_end_matches('0').trim_end_matches('.');
    if text == "-0" { "0".into() } else { text.into() }
}

/// The largest of 1, 2, 5 × 10ᵏ not above `x` (> 0).
pub fn round_below(x: f64) -> f64 {
    let decade = 10f64.powf(x.log10().floor());
    [5.0, 2.0, 1.0].into_iter().map(|m| m * decade).find(|&v| v <= x * (1.0 + 1e-12)).unwrap_or(decade)
}

/// A length in the unit that makes it a small number: "2 m", "50 cm", "5 mm", "0.2 mm".
pub fn length_words(metres: f64) -> String {
    let (value, unit) = if metres >= 1.0 {
        (metres, "m")
    } else if metres >= 0.01 {
        (metres * 100.0, "cm")
    } else {
        (metres * 1000.0, "mm")
    };
    format!("{} {unit}", (value * 1e6).round() / 1e6)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_plot_size_is_what_plotters_lays_out() {
        for size in [240, 333, 600, 1000] {
            let layout = Layout::new(size);
            let mut buffer = vec![0; (size * size * 3) as usize];
            let root = BitMapBackend::with_buffer(&mut buffer, (size, size)).into_drawing_area();
            let (_, body) = root.split_vertically(layout.title);
            let chart = ChartBuilder::on(&body)
                .margin(layout.margin)
                .x_label_area_size(layout.x_area)
                .y_label_area_size(layout.y_area)
                .build_cartesian_2d(0.0..1.0, 0.0..1.0)
                .unwrap();
            assert_eq!(chart.plotting_area().dim_in_pixel(), layout.plot(), "size {size}");
        }
    }

    #[test]
    fn scale_bars_have_round_lengths() {
        assert_eq!(round_below(0.3), 0.2);
        assert_eq!(round_below(0.05), 0.05);
        assert_eq!(round_below(7.0), 5.0);
        assert_eq!(length_words(0.05), "5 cm");
        assert_eq!(length_words(2.0), "2 m");
        assert_eq!(length_words(0.0002), "0.2 mm");
        assert_eq!(tick(&-1e-17), "0");
        assert_eq!(tick(&(0.1 + 0.2)), "0.3");
        assert_eq!(tick(&-2.0), "-2");
    }
}
