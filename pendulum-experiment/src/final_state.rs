//! `final.json`: the state a run ended in, exactly, so that another run can start from it
//! (`--initial RUN_DIR` or `--initial RUN_DIR/final.json`) and continue, ramp down or
//! sweep on.

use std::path::{Path, PathBuf};

use pendulum_core::TurningFrame;
use serde::{Deserialize, Serialize};

use crate::description::Dimension;
use crate::error::{Error, Result};
use crate::file::VERSION;
use crate::json::write_json_atomic;
use crate::spelling::opt;

/// The file name a run writes its final state to.
pub const FILE_NAME: &str = "final.json";

/// A run's last state in the coordinates it was integrated in: 2D the angles `θ_i` (rad)
/// and rates `θ̇_i` (rad/s); 3D the unit link directions `u_i` and their rates
/// `w_i = u̇_i` (1/s), three components each, link after link. Numbers are written in
/// the shortest form that reads back to the same bits.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FinalState {
    /// Always `"pendulum"`.
    pub program: String,
    /// The version of the program that wrote the file.
    pub version: String,
    /// Space dimension.
    pub dim: Dimension,
    /// Number of links.
    pub links: usize,
    /// The time the state was reached, s.
    pub t: f64,
    /// `"angles"` (2D) or `"directions"` (3D).
    pub representation: String,
    /// 2D `θ_1..θ_n`; 3D `u_1..u_n` (3 components each).
    pub coordinates: Vec<f64>,
    /// 2D `θ̇_1..θ̇_n`; 3D `w_1..w_n`.
    pub rates: Vec<f64>,
    /// 3D with a pivot circling the vertical (circle drive, steady or ramped): its azimuth
    /// `φ` at `t`, rad. A run that continues from this state starts its drive at phase 0,
    /// so it turns the state by `−φ` about the vertical: the chain keeps its place relative
    /// to the pivot.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pivot_phase: Option<f64>,
}

impl FinalState {
    /// The final state of a run of `links` links in `dim` at time `t`, from the motion's
    /// state (coordinates, then rates).
    pub fn new(dim: Dimension, links: usize, t: f64, motion: &[f64], pivot_phase: Option<f64>) -> Self {
        let half = motion.len() / 2;
        Self {
            program: "pendulum".into(),
            version: VERSION.into(),
            dim,
            links,
            t,
            representation: representation(dim).into(),
            coordinates: motion[..half].to_vec(),
            rates: motion[half..].to_vec(),
            pivot_phase,
        }
    }

    /// The state a continuing run starts from: coordinates then rates, in 3D seen in the
    /// frame turning with the pivot ([`TurningFrame`]) when the pivot circled.
    pub fn start(&self) -> Vec<f64> {
        let state: Vec<f64> = self.coordinates.iter().chain(&self.rates).copied().collect();
        match (self.dim, self.pivot_phase) {
            (Dimension::Three, Some(phase)) => TurningFrame::at(phase).turn_vectors(&state),
            _ => state,
        }
    }

    /// Whether `--initial PATH` names a final state: a `.json` file or a directory.
    pub fn names(path: &Path) -> bool {
        path.is_dir() || path.extension().is_some_and(|e| e == "json")
    }

    /// Reads the final state at `path` (a `final.json`, or a run directory holding one)
    /// for a run of `links` links in `dim`; errors name the file and what does not fit.
    pub fn read_for(path: &Path, dim: Dimension, links: usize) -> Result<Self> {
        let file: PathBuf = if path.is_dir() { path.join(FILE_NAME) } else { path.to_path_buf() };
        let fail = |m: String| Error::invalid(format!("{} {}: {m}", opt("initial"), file.display()));
        let text = std::fs::read_to_string(&file).map_err(|e| fail(format!("cannot read it: {e}")))?;
        let state: Self =
            serde_json::from_str(&text).map_err(|e| fail(format!("not a pendulum final state: {e}")))?;
        if state.program != "pendulum" {
            return Err(fail(format!("written by '{}', not pendulum", state.program)));
        }
        if state.dim != dim || state.links != links {
            return Err(fail(format!(
                "a state of {} links in {}, this run has {links} links in {}",
                state.links,
                state.dim.name(),
                dim.name()
            )));
        }
        let per_link = if dim == Dimension::Two { 1 } else { 3 };
        let expected = per_link * links;
        if state.representation != representation(dim)
            || state.coordinates.len() != expected
            || state.rates.len() != expected
        {
            return Err(fail(format!(
                "expected {expected} {} and {expected} rates, got {} '{}' and {} rates",
                representation(dim),
                state.coordinates.len(),
                state.representation,
                state.rates.len()
            )));
        }
        if let Some(v) = state.coordinates.iter().chain(&state.rates).find(|v| !v.is_finite()) {
            return Err(fail(format!("{v} is not finite")));
        }
        Ok(state)
    }

    /// Writes the file into `dir`.
    pub fn write(&self, dir: &Path) -> Result<()> {
        write_json_atomic(&dir.join(FILE_NAME), self)
    }
}

fn representation(dim: Dimension) -> &'static str {
    if dim == Dimension::Two { "angles" } else { "directions" }
}
