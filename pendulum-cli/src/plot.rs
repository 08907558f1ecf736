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

/// The chart's key at `position`: white, framed, 13 px labels.
pub fn key<'a, DB, CT>(
    chart: &mut ChartContext<'a, DB, CT>,
    position: SeriesLabelPosition,
    path: &Path,
) -> CliResult<()>
where
    DB: DrawingBackend + 'a,
    CT: CoordTranslate,
{
    chart
        .configure_series_labels()
        .position(position)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 13))
        .draw()
        .map_err(|e| drawing_failed(path, e))
}

/// Plots the inertial-frame energy `H_in(t)` (J) and the energy the ledger predicts,
/// `H_in(0) + W_drive + W_torque − E_damped`, against time (s). The two coincide for an
/// exact integration; for a conservative run both are the flat line `H_in(0)`.
///
/// The vertical range covers the data and at least ±2 % of `scale` (J) around it, so
/// round-off does not fill the plot, with room above the data for the legend; the
/// caption gives the largest difference. Non-finite values (a run that blew up) are left
/// out of the range and the lines, and the caption says so.
pub fn energy(path: &Path, times: &[f64], energy: &[f64], predicted: &[f64], scale: f64) -> CliResult<()> {
    fonts();
    let fail = |e: &dyn std::fmt::Display| drawing_failed(path, e);
    let root = BitMapBackend::new(path, (640, 360)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| fail(&e))?;
    let (t0, t1) = (times[0], *times.last().unwrap_or(&times[0]));
    let t1 = if t1 > t0 { t1 } else { t0 + 1.0 };
    let finite = |values: &[f64]| -> Vec<(f64, f64)> {
        times
            .iter()
            .zip(values)
            .map(|(&t, &v)| (t, v))
            .filter(|(t, v)| t.is_finite() && v.is_finite())
            .collect()
    };
    let (energy_line, predicted_line) = (finite(energy), finite(predicted));
    let all = energy_line.iter().chain(&predicted_line).map(|&(_, v)| v);
    let (lo, hi) = all.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
    let (lo, hi) = if lo <= hi { (lo, hi) } else { (0.0, 0.0) };
    // Halved before subtracting: the span of values near ±f64::MAX stays finite.
    let mid = 0.5 * lo + 0.5 * hi;
    let half = (0.55 * hi - 0.55 * lo).max(0.02 * scale).clamp(1e-12, f64::MAX / 4.0);
    let worst = energy.iter().zip(predicted).map(|(h, p)| (h - p).abs()).fold(0.0_f64, f64::max);
    let left_out = 2 * times.len().min(energy.len()) - energy_line.len() - predicted_line.len();
    let caption = if left_out == 0 {
        format!("energy (J); max |H − H0 − W| = {worst:.2e} J")
    } else {
        format!("energy (J); max |H − H0 − W| = {worst:.2e} J; {left_out} non-finite values not drawn")
    };
    let mut chart = ChartBuilder::on(&root)
        .caption(caption, ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(36)
        .y_label_area_size(70)
        .build_cartesian_2d(t0..t1, (mid - half)..(mid + 1.6 * half))
        .map_err(|e| fail(&e))?;
    // Plotters writes every digit: beyond 10⁶ J (a run that blew up) the labels are written
    // in scientific notation.
    let big = mid.abs() + 1.6 * half >= 1e6;
    let scientific = |v: &f64| if big { format!("{v:.2e}") } else { format!("{v}") };
    let mut mesh = chart.configure_mesh();
    if big {
        mesh.y_label_formatter(&scientific);
    }
    mesh.x_desc("t (s)").y_desc("J").label_style(("sans-serif", 13)).draw().map_err(|e| fail(&e))?;
    chart
        .draw_series(LineSeries::new(predicted_line, RED.stroke_width(3)))
        .map_err(|e| fail(&e))?
        .label("H0 + W_drive + W_torque − E_damped")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED.stroke_width(3)));
    chart
        .draw_series(LineSeries::new(energy_line, BLUE.stroke_width(1)))
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
