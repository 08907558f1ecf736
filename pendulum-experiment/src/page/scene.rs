//! What the page shows of a run, read from its files: the positions of pivot and masses
//! at every kept sample, the energy ledger, the parameters and the shape summary.

use std::path::Path;

use pendulum_core::TurningFrame;
use serde::Serialize;

use crate::description::{Dimension, DriveConfig};
use crate::error::{Error, Result};
use crate::run_dir::{Run, Trajectory};

/// Frames a page holds by default: a 300 s run of 100 links at 500 samples stays whole,
/// and a run of 100 links stays within about 15 MB (about 7.5 bytes per coordinate).
pub const DEFAULT_FRAMES: usize = 6000;

/// The page's data.
#[derive(Debug, Serialize)]
pub struct Scene {
    /// 2 or 3.
    pub dim: usize,
    /// Links.
    pub links: usize,
    /// Σ l_i, m: the scale of the view.
    pub reach: f64,
    /// Kept sample times, s.
    pub times: Vec<f32>,
    /// Per kept sample: the pivot then every mass, x, y, z each (z = 0 in 2D; 2D y is up),
    /// in units of [`unit`](Self::unit) (whole numbers keep the page small).
    pub positions: Vec<i64>,
    /// The positions' unit, m: a millionth of the chain's length.
    pub unit: f64,
    /// The inertial-frame energy H at the kept samples, J (NaN where energy.csv has no row).
    pub energy: Vec<f32>,
    /// What the ledger says it should be, H0 + W_drive + W_torque − E_damped, J.
    pub predicted: Vec<f32>,
    /// Whether the pivot circles the vertical (the page then offers the co-rotating frame).
    pub turning: bool,
    /// A circling pivot's azimuth φ at the kept samples, rad (the co-rotating frame turns
    /// every point by −φ: [`TurningFrame`]); empty for other runs.
    pub phases: Vec<f32>,
    /// Samples in the trajectory.
    pub samples: u64,
    /// One sample in `every` is kept.
    pub every: u64,
    /// Lines of the parameter panel.
    pub parameters: Vec<String>,
    /// The shape summary (shape.json), when the run has one.
    pub shape: Option<serde_json::Value>,
}

impl Scene {
    /// Reads the run in `dir`, keeping at most `frames` samples (every k-th).
    pub fn read(dir: &Path, run: &Run, frames: usize) -> Result<Self> {
        let config = &run.file.config;
        let mut count = Trajectory::open(&run.trajectory, config)?;
        let mut row = count.row();
        while count.next(&mut row)? {}
        let samples = count.rows;
        if samples == 0 {
            return Err(Error::invalid(format!("{}: no samples", run.trajectory.display())));
        }
        let every = samples.div_ceil(frames as u64).max(1);
        let mut trajectory = Trajectory::open(&run.trajectory, config)?;
        let reach: f64 = config.lengths.iter().sum();
        let unit = reach * 1e-6;
        let turning = matches!(config.drive, DriveConfig::Circle { .. } | DriveConfig::RampedCircle { .. });
        let (mut times, mut positions, mut phases) = (Vec::new(), Vec::new(), Vec::new());
        let mut index = 0;
        while trajectory.next(&mut row)? {
            if index % every == 0 {
                times.push(row.t as f32);
                if turning {
                    phases.push(TurningFrame::of_pivot(&row.pivot).phase() as f32);
                }
                for p in std::iter::once(&row.pivot).chain(&row.masses) {
                    positions.extend(p.iter().map(|v| (v / unit).round() as i64));
                }
            }
            index += 1;
        }
        let (energy, predicted) = ledger(dir, &times)?;
        let shape =
            std::fs::read_to_string(dir.join("shape.json")).ok().and_then(|t| serde_json::from_str(&t).ok());
        Ok(Self {
            dim: if config.dim == Dimension::Two { 2 } else { 3 },
            links: config.links(),
            reach,
            times,
            positions,
            unit,
            energy,
            predicted,
            turning,
            phases,
            samples,
            every,
            parameters: parameters(run),
            shape,
        })
    }

    /// Kept samples.
    pub fn frame_count(&self) -> usize {
        self.times.len()
    }
}

/// H and H0 + W at the kept times, from energy.csv (the rows with those times; missing
/// rows as NaN, which the plot skips).
fn ledger(dir: &Path, times: &[f32]) -> Result<(Vec<f32>, Vec<f32>)> {
    let path = dir.join("energy.csv");
    let text = std::fs::read_to_string(&path)
        .map_err(|e| Error::invalid(format!("cannot read {}: {e}", path.display())))?;
    let mut rows = Vec::new();
    for (number, line) in text.lines().enumerate().skip(1) {
        let fields: Vec<f64> = line.split(',').filter_map(|v| v.trim().parse().ok()).collect();
        if fields.len() != 6 {
            return Err(Error::invalid(format!(
                "{} line {}: expected 6 numbers",
                path.display(),
                number + 1
            )));
        }
        rows.push(fields);
    }
    let h0 = rows.first().map_or(0.0, |r| r[1]);
    let (mut energy, mut predicted) = (Vec::new(), Vec::new());
    let mut k = 0;
    for &t in times {
        while k < rows.len() && (rows[k][0] as f32) < t {
            k += 1;
        }
        match rows.get(k).filter(|r| r[0] as f32 == t) {
            Some(r) => {
                energy.push(r[1] as f32);
                predicted.push((h0 + r[2] + r[3] - r[4]) as f32);
            }
            None => {
                energy.push(f32::NAN);
                predicted.push(f32::NAN);
            }
        }
    }
    Ok((energy, predicted))
}

/// The parameter panel's lines.
fn parameters(run: &Run) -> Vec<String> {
    let c = &run.file.config;
    let mass: f64 = c.masses.iter().sum();
    let reach: f64 = c.lengths.iter().sum();
    let drive = match &c.drive {
        DriveConfig::Fixed => "pivot fixed".to_string(),
        DriveConfig::Harmonic { amplitude, omega, .. } => {
            format!("pivot harmonic: A = {amplitude} m, ω = {omega} rad/s")
        }
        DriveConfig::Circle { radius, omega } => {
            format!("pivot on a circle: R = {radius} m, ω = {omega} rad/s")
        }
        DriveConfig::RampedCircle { radius, initial_omega, omega, duration } => {
            format!(
                "pivot on a circle: R = {radius} m, ω from {initial_omega} to {omega} rad/s over {duration} s"
            )
        }
        DriveConfig::Sampled { .. } => c.drive.sampled_words().unwrap_or_default(),
    };
    let damping = c.damping.iter().fold(0.0_f64, |a, b| a.max(*b));
    let mut lines = vec![
        format!(
            "{} links, {}D, L = {reach:.4} m, M = {mass:.4} kg, g = {} m/s²",
            c.links(),
            if c.dim == Dimension::Two { 2 } else { 3 },
            c.gravity
        ),
        drive,
        format!("damping λ ≤ {damping} N·m·s"),
        format!("integrator {:?}, h = {:.4e} s, t = 0 … {} s", c.integrator, c.step, run.reached()),
    ];
    if let Some(chosen) = &c.chosen {
        lines.push(format!("chosen: {chosen}"));
    }
    lines
}
