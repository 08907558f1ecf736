//! One point of a sweep: its speed and kind, where it stands, and what the chain did there
//! ([`Outcome`] and [`Status`] of [`crate::points`]).

use serde::{Deserialize, Serialize};

use super::SweepKind;

pub use crate::points::{Outcome, Status};

/// One point of the sweep: a speed and a kind, how it starts, and its result once run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Point {
    /// How it is started.
    pub kind: SweepKind,
    /// The speed held at the end, rad/s.
    pub omega: f64,
    /// `ω / √(g/L)`.
    pub omega_scaled: f64,
    /// The speed the ramp starts from, rad/s (`None`: switched on at ω).
    pub ramp_from: Option<f64>,
    /// The state it starts from.
    pub start: String,
    /// Where it stands.
    pub status: Status,
    /// Why it failed or was not run.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// What the shape analysis said at the end.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub result: Option<Outcome>,
}
