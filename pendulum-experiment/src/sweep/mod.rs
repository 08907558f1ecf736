//! A sweep: which shape a whirled 3D chain chooses along a line of speeds. For every drive
//! speed ω and every kind of start ([`SweepKind`]), the chain is run from hanging at rest
//! (or, ramping down, from the previous point's end) with its pivot on a horizontal circle,
//! RK4 + projection, and the shape analysis reports what it settled into. The independent
//! points (sudden, ramp-up) run as batches of chains, the ramp-down points one after the
//! other ([`Sweep::run`]); a front end is told of every finished point (the CLI writes
//! sweep.json and a line on stderr, Python keeps the arrays).
//!
//! The parts: the request and the resolved parameters, sweep.json ([`config`]), a point
//! and its outcome ([`point`]), the runs ([`runs`]), sweep.csv ([`csv`]).

pub mod config;
pub mod csv;
pub mod point;
pub mod runs;

use serde::{Deserialize, Serialize};

pub use config::{Derived, SweepConfig, SweepFile, SweepRequest, parse_omegas};
pub use point::{Outcome, Point, Status};
pub use runs::Sweep;

/// How a point of the sweep is started.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum SweepKind {
    /// From hanging at rest, the pivot circling at ω from t = 0.
    Sudden,
    /// From hanging at rest, the speed ramped linearly from 0 to ω over --ramp-time, then held.
    RampUp,
    /// The points in decreasing ω, one after the other: the first ramped up from rest like
    /// ramp-up, every next one starting from the previous point's final state, the speed
    /// ramped from the previous ω to its own over --ramp-time, then held.
    RampDown,
}

impl SweepKind {
    /// The name on the command line and in the files.
    pub fn name(self) -> &'static str {
        match self {
            Self::Sudden => "sudden",
            Self::RampUp => "ramp-up",
            Self::RampDown => "ramp-down",
        }
    }
}
