//! atlas.json: every parameter, the numbers derived from them, and every point's status
//! and result so far ([`AtlasFile`]); the points a resumed atlas starts from.

use super::{AtlasConfig, AtlasPoint, Derived};
use crate::error::Result;
use crate::points::{PointsFile, Recorded, Status};

/// What atlas.json holds.
pub type AtlasFile = PointsFile<AtlasConfig, Derived, AtlasPoint>;

impl Recorded for AtlasConfig {
    const COMMAND: &'static str = "atlas";
    const CONVENTIONS: &'static str = "SI units: ω in rad/s, R in m, λ in N·m·s, times in s, growth rates in 1/s. Points run \
    kind by kind, then row by row of the y axis, then along the x axis. Each point: a 3D chain from hanging at rest in \
    unit link directions, RK4 + projection, its pivot on the horizontal circle of radius R about the z axis (sudden: at \
    ω from t = 0; ramp-up: ω ramped linearly from 0 over the ramp time); the shape in the frame turning with the pivot: \
    nodes = axis crossings + 1 (the pivot counts as a node), tip radius = the free end's distance from the axis \
    (tip_signed: + on the pivot's side), settled = drift ≤ settle_tolerance · L over the last settle_periods drive \
    periods; nearest = the damped steady shape nearest the final shape, its distance, nodes and growth rate (stable: \
    below 1e-6 |ω|).";

    fn check(&self) -> Result<()> {
        AtlasConfig::check(self)
    }

    fn points(&self) -> Option<usize> {
        Some(self.len())
    }
}

impl AtlasFile {
    /// The points to resume from: the completed ones kept, every other pending again.
    pub fn resumed_points(&self) -> Vec<AtlasPoint> {
        self.points
            .iter()
            .map(|p| match p.status {
                Status::Completed => p.clone(),
                _ => AtlasPoint { status: Status::Pending, error: None, result: None, ..p.clone() },
            })
            .collect()
    }
}
