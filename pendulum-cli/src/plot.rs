//! Pictures of a run with plotters: the energy plot (PNG), and the embedded font every
//! plot's labels use (the animation is drawn by [`crate::render`]).
//!
//! Labels use the Ubuntu Light font embedded in the binary (`epaint_default_fonts`),
//! registered with plotters' `ab_glyph` backend: no font file is needed at run time.

use std::path::Path;
use std::sync::Once;

use plotters::prelude::*;
use plotters::style::{FontStyle, register_font};

use crate::error::{CliError, CliResult};

/// Registers the embedded font once.
pub fn fonts() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The font is a valid TTF shipped by the crate; failure would only lose labels.
        let _ = register_font("sans-serif", FontStyle::Normal, epaint_default_fonts::UBUNTU_LIGHT);
    });
}

pub fn drawing_failed(path: &Path, e: impl std::fmt::Display) -> CliError {
    CliError::failed(format!("cannot draw {}: {e}", path.display()))
}

/// Plots the inertial-frame energy `H_in(t)` (J) and the energy the ledger predicts,
/// `H_in(0) + W_drive + W_torque − E_damped`, against time (s). The two coincide for an
/// exact integration; for a conservative run both are the flat line `H_in(0)`.
///
/// The vertical range covers the data and at least ±2 % of `scale` (J) around it, so
/// round-off does not fill the plot, with room above the data for the legend; the
/// caption gives the largest difference.
pub fn energy(path: &Path, times: &[f64], energy: &[f64], predicted: &[f64], scale: f64) -> CliResult<()> {
    fonts();
    let fail = |e: &dyn std::fmt::Display| drawing_failed(path, e);
    let root = BitMapBackend::new(path, (640, 360)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| fail(&e))?;
    let (t0, t1) = (times[0], *times.last().unwrap_or(&times[0]));
    let t1 = if t1 > t0 { t1 } else { t0 + 1.0 };
    let all = energy.iter().chain(predicted).copied();
    let (lo, hi) = all.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
    let mid = 0.5 * (lo + hi);
    let half = (0.55 * (hi - lo)).max(0.02 * scale).max(1e-12);
    let worst = energy.iter().zip(predicted).map(|(h, p)| (h - p).abs()).fold(0.0_f64, f64::max);
    let caption = format!("energy (J); max |H − H0 − W| = {worst:.2e} J");
    let mut chart = ChartBuilder::on(&root)
        .caption(caption, ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(36)
        .y_label_area_size(70)
        .build_cartesian_2d(t0..t1, (mid - half)..(mid + 1.6 * half))
        .map_err(|e| fail(&e))?;
    chart
        .configure_mesh()
        .x_desc("t (s)")
        .y_desc("J")
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(|e| fail(&e))?;
    chart
        .draw_series(LineSeries::new(
            times.iter().copied().zip(predicted.iter().copied()),
            RED.stroke_width(3),
        ))
        .map_err(|e| fail(&e))?
        .label("H0 + W_drive + W_torque − E_damped")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED.stroke_width(3)));
    chart
        .draw_series(LineSeries::new(times.iter().copied().zip(energy.iter().copied()), BLUE.stroke_width(1)))
        .map_err(|e| fail(&e))?
        .label("H (inertial frame)")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLUE));
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .label_font(("sans-serif", 13))
        .draw()
        .map_err(|e| fail(&e))?;
    root.present().map_err(|e| fail(&e))
}
