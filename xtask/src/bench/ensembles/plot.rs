//! `docs/ensembles-speed.svg`: each row's batch ÷ single-chain call per chain, one thread,
//! from the medians, as horizontal bars (`f64`, and `f32` below it where it ran; the middle
//! run's, with the range over the runs as a whisker), the single call (1×) and the issue's
//! 3× marked (plotters, SVG backend, the embedded font of `bench.svg`).

use anyhow::{Result, anyhow};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::measured::Measured;
use super::report::{middle, range, ratios};
use super::rows::rows;

/// The sections' names on the plot, in [`super::SECTIONS`] order.
const SHORT: [&str; 6] = ["accelerations", "1024 chains", "whirl", "planar runs", "generated", "Jacobians"];

/// Height of a row, px.
const ROW: u32 = 24;

/// A bar: the middle ratio over the runs and its range.
#[derive(Clone, Copy)]
struct Bar {
    middle: f64,
    low: f64,
    high: f64,
}

impl Bar {
    /// The bar of `values` (each run's ratio), if any ran.
    fn of(values: &[f64]) -> Option<Self> {
        let (low, high) = range(values)?;
        Some(Self { middle: middle(values)?, low, high })
    }
}

/// The SVG text of the plot of the rows whose single call and batch both ran in `runs`.
pub fn svg(runs: &[&Measured]) -> Result<String> {
    crate::bench::plot::register_font();
    let bars: Vec<(String, Bar, Option<Bar>)> = rows()
        .into_iter()
        .filter_map(|r| {
            let f64 = Bar::of(&ratios(runs, &r.single, Some(&r.batch)))?;
            let f32 = Bar::of(&ratios(runs, &r.single, r.f32.as_deref()));
            Some((format!("{}: {}", SHORT[r.section], r.label.replace('`', "")), f64, f32))
        })
        .collect();
    let count = bars.len().max(1) as f64;
    let widest = bars.iter().map(|b| b.1.high.max(b.2.map_or(0.0, |b| b.high))).fold(3.5, f64::max);
    let mut text = String::new();
    {
        let height = ROW * bars.len().max(1) as u32 + 110;
        let root = SVGBackend::with_string(&mut text, (1200, height)).into_drawing_area();
        let err = |e: DrawingAreaErrorKind<_>| anyhow!("plot: {e}");
        root.fill(&WHITE).map_err(err)?;
        let caption = if runs.len() > 1 {
            format!(
                "batch ÷ single-chain call, per chain, one thread (medians; {} runs, their range)",
                runs.len()
            )
        } else {
            "batch ÷ single-chain call, per chain, one thread (medians)".to_string()
        };
        let mut chart = ChartBuilder::on(&root)
            .caption(caption, ("sans-serif", 20))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(400)
            .build_cartesian_2d(0.0..widest * 1.1, 0.0..count)
            .map_err(err)?;
        chart
            .configure_mesh()
            .disable_y_mesh()
            .y_labels(0)
            .x_desc("throughput per chain against the single-chain call (×)")
            .bold_line_style(BLACK.mix(0.12))
            .light_line_style(TRANSPARENT)
            .label_style(("sans-serif", 14))
            .axis_desc_style(("sans-serif", 15))
            .draw()
            .map_err(err)?;
        let (blue, orange) = (RGBColor(31, 119, 180), RGBColor(255, 127, 14));
        // Row k from the top: its band is [count − k − 1, count − k]; f64 in its upper
        // half (all of it without an f32 bar), f32 in its lower.
        let top = |k: usize| count - k as f64;
        let f64_band = |k: usize, f32: bool| (top(k) - 0.1, if f32 { top(k) - 0.5 } else { top(k) - 0.85 });
        let f32_band = |k: usize| (top(k) - 0.5, top(k) - 0.85);
        chart
            .draw_series(bars.iter().enumerate().map(|(k, b)| {
                let (high, low) = f64_band(k, b.2.is_some());
                Rectangle::new([(0.0, high), (b.1.middle, low)], blue.filled())
            }))
            .map_err(err)?
            .label("f64")
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 16, y + 5)], blue.filled()));
        chart
            .draw_series(bars.iter().enumerate().filter_map(|(k, b)| {
                let (high, low) = f32_band(k);
                Some(Rectangle::new([(0.0, high), (b.2?.middle, low)], orange.filled()))
            }))
            .map_err(err)?
            .label("f32")
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 16, y + 5)], orange.filled()));
        if runs.len() > 1 {
            let whiskers = bars.iter().enumerate().flat_map(|(k, b)| {
                let (high, low) = f64_band(k, b.2.is_some());
                let f64 = Some((b.1, 0.5 * (high + low)));
                let f32 = b.2.map(|bar| (bar, 0.5 * (f32_band(k).0 + f32_band(k).1)));
                [f64, f32].into_iter().flatten().map(|(bar, y)| {
                    PathElement::new(vec![(bar.low, y), (bar.high, y)], BLACK.stroke_width(2))
                })
            });
            chart.draw_series(whiskers).map_err(err)?;
        }
        for (at, colour, name) in [(1.0, BLACK, "single call"), (3.0, RED, "the issue's 3×")] {
            let style = ShapeStyle::from(colour.mix(0.8)).stroke_width(2);
            chart
                .draw_series(std::iter::once(PathElement::new(vec![(at, 0.0), (at, count)], style)))
                .map_err(err)?
                .label(name)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], style));
        }
        let label = ("sans-serif", 14).into_font().color(&BLACK).pos(Pos::new(HPos::Right, VPos::Center));
        let value = ("sans-serif", 12).into_font().color(&BLACK).pos(Pos::new(HPos::Left, VPos::Center));
        for (k, b) in bars.iter().enumerate() {
            let (x, y) = chart.backend_coord(&(0.0, top(k) - 0.5));
            root.draw(&Text::new(b.0.clone(), (x - 8, y), label.clone())).map_err(err)?;
            let (x, y) = chart.backend_coord(&(b.1.high, top(k) - 0.3));
            root.draw(&Text::new(format!("{:.2}", b.1.middle), (x + 4, y), value.clone())).map_err(err)?;
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerRight)
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK)
            .label_font(("sans-serif", 14))
            .draw()
            .map_err(err)?;
        root.present().map_err(err)?;
    }
    Ok(text)
}

#[cfg(test)]
mod tests {
    use super::super::measured::Timing;
    use super::*;

    #[test]
    fn draws_a_bar_per_row_that_ran_and_one_per_f32_batch() {
        let mut m = Measured::default();
        let t = |median: f64| Timing { median, fastest: median };
        m.insert("generated/planar/single/8", t(82.0));
        m.insert("generated/planar/batch_1_threads/8", t(31.0));
        m.insert("generated/planar/batch_f32_1_thread/8", t(20.0));
        m.insert("rk4/whirl_100/single", t(6800.0));
        m.insert("rk4/whirl_100/batch_1_threads", t(2300.0));
        let svg = svg(&[&m]).unwrap();
        assert!(svg.starts_with("<svg"), "{}", &svg[..100]);
        for text in ["generated: planar accelerations, n = 8", "whirl: RK4, one step a call", "2.65", "2.96"]
        {
            assert!(svg.contains(text), "missing {text}");
        }
        // Two f64 bars and one f32 bar, each colour once more in the legend.
        assert_eq!(svg.matches(r##"fill="#1F77B4""##).count(), 2 + 1, "{svg}");
        assert_eq!(svg.matches(r##"fill="#FF7F0E""##).count(), 1 + 1, "{svg}");
        // A second run, its batches slower: the range over the runs as whiskers, the
        // middle of the two ratios as the bar's length and label.
        let mut slower = m.clone();
        slower.insert("generated/planar/batch_1_threads/8", t(41.0));
        let svg = super::svg(&[&m, &slower]).unwrap();
        assert!(svg.contains("2 runs, their range"), "{svg}");
        assert!(svg.contains(&format!("{:.2}", 0.5 * (82.0 / 31.0 + 82.0 / 41.0))), "{svg}");
    }
}
