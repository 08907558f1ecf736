//! `docs/ensembles-speed.svg`: each row's batch ÷ single-chain call per chain, one thread,
//! from the medians, as horizontal bars (`f64`, and `f32` below it where it ran), with the
//! single call (1×) and the issue's 3× marked (plotters, SVG backend, the embedded font of
//! `bench.svg`).

use anyhow::{Result, anyhow};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::measured::Measured;
use super::rows::rows;

/// The sections' names on the plot, in [`super::SECTIONS`] order.
const SHORT: [&str; 6] = ["accelerations", "1024 chains", "whirl", "planar runs", "generated", "Jacobians"];

/// Height of a row, px.
const ROW: u32 = 24;

/// The SVG text of the plot of `measured`'s rows whose single call and batch both ran.
pub fn svg(measured: &Measured) -> Result<String> {
    crate::bench::plot::register_font();
    let ratio = |a: &str, b: &str| Some(measured.get(a)?.median / measured.get(b)?.median);
    let bars: Vec<(String, f64, Option<f64>)> = rows()
        .into_iter()
        .filter_map(|r| {
            let f64 = ratio(&r.single, &r.batch)?;
            let f32 = r.f32.as_deref().and_then(|f| ratio(&r.single, f));
            Some((format!("{}: {}", SHORT[r.section], r.label.replace('`', "")), f64, f32))
        })
        .collect();
    let count = bars.len().max(1) as f64;
    let widest = bars.iter().map(|b| b.1.max(b.2.unwrap_or(0.0))).fold(3.5, f64::max);
    let mut text = String::new();
    {
        let height = ROW * bars.len().max(1) as u32 + 110;
        let root = SVGBackend::with_string(&mut text, (1200, height)).into_drawing_area();
        let err = |e: DrawingAreaErrorKind<_>| anyhow!("plot: {e}");
        root.fill(&WHITE).map_err(err)?;
        let mut chart = ChartBuilder::on(&root)
            .caption("batch ÷ single-chain call, per chain, one thread (medians)", ("sans-serif", 20))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(400)
            .build_cartesian_2d(0.0..widest * 1.08, 0.0..count)
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
        // Row k from the top: its band is [count − k − 1, count − k].
        let top = |k: usize| count - k as f64;
        chart
            .draw_series(bars.iter().enumerate().map(|(k, b)| {
                let low = if b.2.is_some() { top(k) - 0.5 } else { top(k) - 0.85 };
                Rectangle::new([(0.0, top(k) - 0.1), (b.1, low)], blue.filled())
            }))
            .map_err(err)?
            .label("f64")
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 16, y + 5)], blue.filled()));
        chart
            .draw_series(bars.iter().enumerate().filter_map(|(k, b)| {
                Some(Rectangle::new([(0.0, top(k) - 0.5), (b.2?, top(k) - 0.85)], orange.filled()))
            }))
            .map_err(err)?
            .label("f32")
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 16, y + 5)], orange.filled()));
        for (at, colour, name) in [(1.0, BLACK, "single call"), (3.0, RED, "the issue's 3×")] {
            let style = ShapeStyle::from(colour.mix(0.8)).stroke_width(2);
            chart
                .draw_series(std::iter::once(PathElement::new(vec![(at, 0.0), (at, count)], style)))
                .map_err(err)?
                .label(name)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], style));
        }
        let label = ("sans-serif", 14).into_font().color(&BLACK).pos(Pos::new(HPos::Right, VPos::Center));
        for (k, b) in bars.iter().enumerate() {
            let (x, y) = chart.backend_coord(&(0.0, top(k) - 0.5));
            root.draw(&Text::new(b.0.clone(), (x - 8, y), label.clone())).map_err(err)?;
            let value = ("sans-serif", 12).into_font().color(&BLACK).pos(Pos::new(HPos::Left, VPos::Center));
            let (x, y) = chart.backend_coord(&(b.1, top(k) - 0.3));
            root.draw(&Text::new(format!("{:.2}", b.1), (x + 4, y), value)).map_err(err)?;
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
        let svg = svg(&m).unwrap();
        assert!(svg.starts_with("<svg"), "{}", &svg[..100]);
        for text in ["generated: planar accelerations, n = 8", "whirl: RK4, one step a call", "2.65", "2.96"]
        {
            assert!(svg.contains(text), "missing {text}");
        }
        // Two f64 bars and one f32 bar, each colour once more in the legend.
        assert_eq!(svg.matches(r##"fill="#1F77B4""##).count(), 2 + 1, "{svg}");
        assert_eq!(svg.matches(r##"fill="#FF7F0E""##).count(), 1 + 1, "{svg}");
    }
}
