//! The folds of the steady branches on the pivot's circle: where atlas.png marks the lowest
//! speed of each forced branch.

use nalgebra::Dyn;
use pendulum_core::{Chain, SteadyRotation};

use crate::error::Result;
use crate::steady::follow;

/// A fold of a steady branch of the chain on a circle of radius R: the lowest speed its
/// shapes exist at (a branch that turns back there, the forced shapes of a circling
/// pivot born in pairs), with the node count there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fold {
    /// The branch's number in `pendulum steady --radius R`'s table.
    pub branch: usize,
    /// The lowest speed on the branch, rad/s.
    pub omega: f64,
    /// Node count of the shape there.
    pub nodes: Option<usize>,
}

/// The folds of the steady branches of `chain` (undamped) on a circle of `radius` (m),
/// followed up to `omega_max` (rad/s) as `pendulum steady` follows them: every branch
/// whose lowest speed lies strictly inside it.
pub fn folds(chain: &Chain<Dyn>, radius: f64, omega_max: f64) -> Result<Vec<Fold>> {
    let problem = SteadyRotation::new(chain, radius)?;
    let free = SteadyRotation::new(chain, 0.0)?;
    let family = follow(&problem, &free, omega_max, None, &|_| true)?;
    Ok(family
        .branches
        .iter()
        .enumerate()
        .filter_map(|(b, labelled)| {
            let points = &labelled.branch.points;
            let lowest = (0..points.len()).min_by(|&i, &j| points[i].omega.total_cmp(&points[j].omega))?;
            (lowest > 0 && lowest + 1 < points.len()).then(|| Fold {
                branch: b + 1,
                omega: points[lowest].omega,
                nodes: labelled.nodes[labelled.shown(lowest)],
            })
        })
        .collect())
}
