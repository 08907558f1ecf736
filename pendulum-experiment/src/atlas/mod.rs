//! The atlas: which shape a whirled 3D chain ends in from hanging at rest, over a grid of
//! two of the drive's speed ω, its circle's radius R, the damping λ and the ramp time.
//!
//! Every point is a whirl ([`WhirlRuns`](crate::whirls::WhirlRuns)): the chain from hanging at rest, its pivot on a
//! horizontal circle switched on at ω (`sudden`) or ramped up from rest (`ramp-up`), RK4 +
//! projection and the shape analysis, the same computation as `pendulum simulate` with
//! those parameters. [`Atlas::run`] runs any set of points as batches of chains
//! ([`WhirlRuns::run_batch_of`](crate::whirls::WhirlRuns::run_batch_of)), so a front end may cut the grid into chunks (rounds on
//! one machine, tasks on a cluster) without changing a bit of any point.
//!
//! The parts: the axes' parameters and the kinds of start (here), a front end's request
//! and its resolution ([`request`]), every parameter of an atlas, its grid and its checks
//! ([`config`]: atlas.json's `config`), the runs ([`run`]), atlas.json ([`file`](mod@file)), the
//! folds of the steady branches the picture marks ([`folds`](mod@folds)).

pub mod config;
pub mod file;
pub mod folds;
pub mod request;
pub mod run;
#[cfg(test)]
mod tests;

use serde::{Deserialize, Serialize};

use crate::spelling::opt;

pub use config::{AtlasConfig, Derived, MAX_POINTS, Setting};
pub use file::AtlasFile;
pub use folds::{Fold, folds};
pub use request::{AtlasRequest, Damping};
pub use run::{Atlas, AtlasPoint};

/// A parameter an axis of the atlas runs over.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Parameter {
    /// The drive's speed ω, rad/s.
    Omega,
    /// The radius R of the pivot's circle, m.
    Radius,
    /// The damping λ of every link, N·m·s.
    Damping,
    /// The length of the ramp from rest to ω, s (ramp-up only).
    RampTime,
}

impl Parameter {
    /// The four, in the order that makes the axes: the first that varies is x.
    pub const ALL: [Self; 4] = [Self::Omega, Self::Radius, Self::Damping, Self::RampTime];

    /// The name in the files and in Python.
    pub fn name(self) -> &'static str {
        match self {
            Self::Omega => "omega",
            Self::Radius => "radius",
            Self::Damping => "damping",
            Self::RampTime => "ramp-time",
        }
    }

    /// Its symbol: ω, R, λ, T.
    pub fn symbol(self) -> &'static str {
        match self {
            Self::Omega => "ω",
            Self::Radius => "R",
            Self::Damping => "λ",
            Self::RampTime => "the ramp time",
        }
    }

    /// The option that sets it, marked for each front end's spelling ([`opt`]).
    pub fn option(self) -> String {
        opt(match self {
            Self::Omega => "omega",
            Self::Radius => "radius",
            Self::Damping => "damping",
            Self::RampTime => "ramp-time",
        })
    }

    /// Its symbol and unit, for axes' labels.
    pub fn label(self) -> &'static str {
        match self {
            Self::Omega => "ω (rad/s)",
            Self::Radius => "R (m)",
            Self::Damping => "λ per link (N·m·s)",
            Self::RampTime => "ramp time (s)",
        }
    }
}

/// How a point of the atlas is started, from hanging at rest.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum AtlasKind {
    /// The pivot circling at ω from t = 0.
    Sudden,
    /// The speed ramped linearly from 0 to ω over the ramp time, then held.
    RampUp,
}

impl AtlasKind {
    /// The name on the command line and in the files.
    pub fn name(self) -> &'static str {
        match self {
            Self::Sudden => "sudden",
            Self::RampUp => "ramp-up",
        }
    }
}

/// An axis: a parameter and its values, increasing or as given (SI units; ω in rad/s).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Axis {
    pub parameter: Parameter,
    pub values: Vec<f64>,
}
