//! Pictures of a run with plotters: the energy plot (PNG) and the animation of the chain
//! (animated GIF; 3D chains drawn in a chosen plane, with the trace of the tip).
//!
//! Labels use the Ubuntu Light font embedded in the binary (`epaint_default_fonts`),
//! registered with plotters' `ab_glyph` backend: no font file is needed at run time.

use std::path::Path;
use std::sync::Once;

use plotters::prelude::*;
use plotters::style::{FontStyle, register_font};

use crate::args::{Dimension, View};
use crate::config::{DriveConfig, RunConfig};
use crate::error::{CliError, CliResult};

/// The chain at one instant: pivot and mass positions (m), inertial frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    /// Time, s.
    pub t: f64,
    /// Pivot position.
    pub pivot: [f64; 3],
    /// Mass positions, mass 1 first.
    pub masses: Vec<[f64; 3]>,
}

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

/// The 2D point a 3D position is drawn at.
fn project(r: &[f64; 3], dim: Dimension, view: View) -> (f64, f64) {
    match (dim, view) {
        (Dimension::Two, _) | (Dimension::Three, View::Xy) => (r[0], r[1]),
        (Dimension::Three, View::Xz) => (r[0], r[2]),
        (Dimension::Three, View::Yz) => (r[1], r[2]),
    }
}

/// Half the width of the drawn square (m): the chain's reach plus the pivot's travel,
/// with a margin.
fn extent(config: &RunConfig) -> f64 {
    let reach: f64 = config.lengths.iter().sum();
    let travel = match config.drive {
        DriveConfig::Fixed => 0.0,
        DriveConfig::Harmonic { amplitude, .. } => amplitude,
        DriveConfig::Circle { radius, .. } | DriveConfig::RampedCircle { radius, .. } => radius,
    };
    1.08 * (reach + travel)
}

/// Draws the animation: one GIF frame per [`Frame`], `delay_ms` apart; rods in black,
/// masses as dots, the pivot as a square, and the trace of the tip over the preceding
/// samples (`tip` at `times`, the last 300 samples) in orange.
pub fn animation(
    path: &Path,
    frames: &[Frame],
    tip: &[[f64; 3]],
    times: &[f64],
    config: &RunConfig,
    delay_ms: u32,
) -> CliResult<()> {
    fonts();
    let fail = |e: &dyn std::fmt::Display| drawing_failed(path, e);
    let (dim, view) = (config.dim, config.view);
    let size = 360;
    let root = BitMapBackend::gif(path, (size, size), delay_ms).map_err(|e| fail(&e))?.into_drawing_area();
    let r = extent(config);
    let n = config.links();
    let dot = if n > 20 {
        2
    } else if n > 8 {
        3
    } else {
        5
    };
    let plane = match (dim, view) {
        (Dimension::Two, _) => "x-y plane",
        (Dimension::Three, View::Xz) => "x-z plane",
        (Dimension::Three, View::Yz) => "y-z plane",
        (Dimension::Three, View::Xy) => "x-y plane (top view)",
    };
    for frame in frames {
        root.fill(&WHITE).map_err(|e| fail(&e))?;
        let mut chart =
            ChartBuilder::on(&root).margin(8).build_cartesian_2d(-r..r, -r..r).map_err(|e| fail(&e))?;
        let end = times.partition_point(|&t| t <= frame.t);
        let start = end.saturating_sub(300);
        let trace = tip[start..end].iter().map(|p| project(p, dim, view));
        chart
            .draw_series(LineSeries::new(trace, RGBColor(255, 150, 40).stroke_width(2)))
            .map_err(|e| fail(&e))?;
        let points: Vec<(f64, f64)> =
            std::iter::once(&frame.pivot).chain(&frame.masses).map(|p| project(p, dim, view)).collect();
        chart
            .draw_series(LineSeries::new(points.iter().copied(), BLACK.stroke_width(2)))
            .map_err(|e| fail(&e))?;
        chart
            .draw_series(points[1..].iter().map(|&p| Circle::new(p, dot, BLUE.filled())))
            .map_err(|e| fail(&e))?;
        let (px, py) = points[0];
        let h = r * 0.02;
        chart
            .draw_series(std::iter::once(Rectangle::new([(px - h, py - h), (px + h, py + h)], RED.filled())))
            .map_err(|e| fail(&e))?;
        let label = format!("t = {:.2} s   {plane}", frame.t);
        root.draw(&Text::new(label, (10, 8), ("sans-serif", 15).into_font())).map_err(|e| fail(&e))?;
        root.present().map_err(|e| fail(&e))?;
    }
    Ok(())
}
