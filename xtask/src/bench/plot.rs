//! `docs/bench.svg`: time per evaluation of the accelerations vs n, log–log, one line per
//! implementation, planar and spatial side by side (plotters, SVG backend). It plots the
//! fastest sample of each benchmark ([`super::Statistic::Fastest`]), the figure least
//! disturbed by other jobs on a shared machine.
//!
//! Text: the SVG backend writes `<text>` elements that the viewer renders with its own
//! fonts; plotters lays the labels out with the `ab_glyph` backend and the Ubuntu Light
//! font embedded in `epaint_default_fonts` (registered once here), so no system font
//! library or font file is involved.

use anyhow::{Result, anyhow};
use plotters::prelude::*;

use super::report::{KINDS, label};
use super::results::Results;

/// One colour per implementation, in [`super::report::IMPLEMENTATIONS`] order.
fn colour(implementation: &str) -> RGBColor {
    match implementation {
        "generated" => RGBColor(31, 119, 180),
        "generated_dense" => RGBColor(23, 190, 207),
        "generated_tension" => RGBColor(188, 189, 34),
        "generic_fixed" => RGBColor(255, 127, 14),
        "generic_dyn" => RGBColor(214, 39, 40),
        "closed_form" => RGBColor(44, 160, 44),
        "tension" => RGBColor(148, 103, 189),
        "directions" => RGBColor(140, 86, 75),
        "directions_angles" => RGBColor(227, 119, 194),
        "baseline" => RGBColor(60, 60, 60),
        _ => RGBColor(127, 127, 127),
    }
}

/// The SVG text of the plot of `results`' `<kind>_accelerations` groups.
pub fn svg(results: &Results) -> Result<String> {
    register_font();
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, (1200, 520)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow!("plot: {e}"))?;
        let panels = root.split_evenly((1, 2));
        for (panel, kind) in panels.iter().zip(KINDS) {
            panel_plot(panel, results, kind)?;
        }
        root.present().map_err(|e| anyhow!("plot: {e}"))?;
    }
    Ok(text)
}

/// Registers the embedded font as plotters' `sans-serif` (once; see the module docs).
pub(super) fn register_font() {
    static FONT: std::sync::Once = std::sync::Once::new();
    FONT.call_once(|| {
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            epaint_default_fonts::UBUNTU_LIGHT,
        );
    });
}

fn panel_plot(
    area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    results: &Results,
    kind: &str,
) -> Result<()> {
    let group = format!("{kind}_accelerations");
    let implementations = results.implementations(&group);
    let all: Vec<(usize, f64)> = implementations.iter().flat_map(|i| results.series(&group, i)).collect();
    if all.is_empty() {
        return Ok(());
    }
    let n_max = all.iter().map(|&(n, _)| n).max().unwrap_or(1).max(2) as f64;
    let t_min = all.iter().map(|&(_, t)| t).fold(f64::INFINITY, f64::min);
    let t_max = all.iter().map(|&(_, t)| t).fold(0.0, f64::max);
    let err = |e: DrawingAreaErrorKind<_>| anyhow!("plot {kind}: {e}");

    let mut chart = ChartBuilder::on(area)
        .caption(format!("{kind} accelerations"), ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d((1.0..n_max * 1.2).log_scale(), (t_min / 1.5..t_max * 1.5).log_scale())
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("links n")
        .y_desc("time per evaluation (fastest sample)")
        .light_line_style(TRANSPARENT)
        .bold_line_style(BLACK.mix(0.12))
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 15))
        .x_label_formatter(&|x| if is_round(*x) { format!("{x:.0}") } else { String::new() })
        .y_label_formatter(&|y| if is_round(*y) { tick_time(*y) } else { String::new() })
        .draw()
        .map_err(err)?;
    for implementation in
        super::report::IMPLEMENTATIONS.iter().map(|(i, _)| *i).filter(|i| implementations.contains(i))
    {
        let points: Vec<(f64, f64)> =
            results.series(&group, implementation).into_iter().map(|(n, t)| (n as f64, t)).collect();
        let style = ShapeStyle::from(colour(implementation)).stroke_width(2);
        chart
            .draw_series(LineSeries::new(points.clone(), style))
            .map_err(err)?
            .label(label(implementation).replace('`', ""))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
        // A lone point (the closed form) gets a larger ring so that it shows above the
        // generated line it sits on.
        let (radius, marker) = if points.len() == 1 { (6, style) } else { (3, style.filled()) };
        chart.draw_series(points.into_iter().map(|p| Circle::new(p, radius, marker))).map_err(err)?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .draw()
        .map_err(err)?;
    Ok(())
}

/// A round time in ns as a tick label: `10 ns`, `2 µs`, `500 ms`.
fn tick_time(ns: f64) -> String {
    let (value, unit) = match ns {
        t if t < 1e3 - 0.5 => (t, "ns"),
        t if t < 1e6 - 0.5 => (t / 1e3, "µs"),
        t if t < 1e9 - 0.5 => (t / 1e6, "ms"),
        t => (t / 1e9, "s"),
    };
    if value < 1.0 { format!("{value} {unit}") } else { format!("{value:.0} {unit}") }
}

/// Whether `x` is 1, 2 or 5 times a power of ten: the labelled ticks of the log n axis
/// (plotters puts a tick at every 1..9 × 10^k; labelling all of them overlaps).
fn is_round(x: f64) -> bool {
    let mantissa = x / 10f64.powf(x.log10().floor());
    [1.0, 2.0, 5.0].iter().any(|m| (mantissa - m).abs() < 1e-9)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_one_two_five_ticks_are_labelled() {
        assert!([1.0, 2.0, 5.0, 10.0, 20.0, 500.0, 1000.0].into_iter().all(is_round));
        assert!(![3.0, 9.0, 30.0, 4096.0].into_iter().any(is_round));
        assert_eq!([10.0, 2000.0, 1e6, 5e8].map(tick_time), ["10 ns", "2 µs", "1 ms", "500 ms"]);
    }

    #[test]
    fn every_implementation_has_a_colour_of_its_own() {
        let colours: Vec<RGBColor> =
            super::super::report::IMPLEMENTATIONS.iter().map(|(i, _)| colour(i)).collect();
        for (k, a) in colours.iter().enumerate() {
            assert_ne!(
                *a,
                colour("unknown"),
                "{} has the fallback grey",
                super::super::report::IMPLEMENTATIONS[k].0
            );
            for b in &colours[k + 1..] {
                assert_ne!(a, b, "{} shares its colour", super::super::report::IMPLEMENTATIONS[k].0);
            }
        }
    }

    #[test]
    fn draws_one_labelled_line_per_implementation() {
        let mut r = Results::default();
        for n in [1, 2, 4, 8] {
            r.insert("planar_accelerations", "generated", n, 10.0 * n as f64);
            r.insert("planar_accelerations", "generic_dyn", n, 40.0 * n as f64);
        }
        r.insert("planar_accelerations", "closed_form", 2, 15.0);
        let svg = svg(&r).unwrap();
        assert!(svg.starts_with("<svg"), "{}", &svg[..100]);
        for text in ["planar accelerations", "generated", "generic Dyn", "closed form (eq 50)", "links n"] {
            assert!(svg.contains(text), "missing {text}");
        }
        assert_eq!(svg.matches("<circle").count(), 4 + 4 + 1, "a marker per measured point");
        std::fs::write(std::env::temp_dir().join("xtask-plot-test.svg"), &svg).unwrap();
    }
}
