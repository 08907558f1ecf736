//! The shape a whirled chain takes (3D, pivot circling the vertical, steady or ramped):
//! the core's shape analysis ([`ShapeTracker`]) fed along a run, for any front end to
//! present, and `shape.json`, the report in the user's terms.

use std::path::Path;

use nalgebra::{DVector, U3};
use pendulum_core::{Directions, ShapeOptions, ShapeReport, ShapeTracker, Turning, WhirlShape};
use serde_json::json;

use crate::assemble::{chain, turning_drive, whirl_model};
use crate::description::{Dimension, RunConfig};
use crate::error::{Error, Result};
use crate::json::write_json_atomic;

/// The chain of a whirled run with its turning drive, for the shape analysis.
pub struct Whirl {
    model: Directions<U3, Box<dyn Turning>>,
}

impl Whirl {
    /// The whirl of a configuration: `Some` for a 3D chain whose pivot circles the
    /// vertical (a circle drive, steady or ramped).
    pub fn of(config: &RunConfig) -> Result<Option<Self>> {
        if config.dim != Dimension::Three {
            return Ok(None);
        }
        let Some(drive) = turning_drive(&config.drive)? else { return Ok(None) };
        Ok(Some(Self { model: whirl_model(chain(config)?, drive) }))
    }

    /// The circling pivot's azimuth at `t`, rad.
    pub fn phase(&self, t: f64) -> f64 {
        self.model.drive().phase(t)
    }

    /// A tracker of the co-rotating shape with the default options (settled: drift
    /// ≤ 1e-3 L over the last 5 drive periods).
    pub fn tracker(&self) -> Result<Tracker<'_>> {
        Ok(Tracker(ShapeTracker::new(&self.model, ShapeOptions::default())?))
    }
}

/// Follows the shape along a run, sample by sample (bounded memory).
pub struct Tracker<'a>(ShapeTracker<'a, Box<dyn Turning>>);

impl Tracker<'_> {
    /// Takes the sample `(t, x)` of the chain's state `x = (u, w)`.
    pub fn push(&mut self, t: f64, x: &[f64]) -> Result<()> {
        self.0
            .push(t, &DVector::<f64>::from_column_slice(x))
            .map_err(|e| Error::failed(format!("shape analysis: {e}")))
    }

    /// The report at the latest sample: the shape, whether it settled, and the nearest
    /// damped steady shape with its stability.
    pub fn report(&self) -> Result<ShapeReport> {
        self.0.report().map_err(|e| Error::failed(format!("shape analysis: {e}")))
    }
}

fn shape_json(s: &WhirlShape) -> serde_json::Value {
    json!({
        "nodes": s.nodes,
        "axis_crossings": s.axis_crossings,
        "tip_radius": s.tip_radius,
        "plane_azimuth": s.plane_azimuth,
        "out_of_plane": s.out_of_plane,
        "radial": s.radial,
        "depth": s.depth,
        "positions": s.positions.iter().map(|r| [r.x, r.y, r.z]).collect::<Vec<_>>(),
    })
}

/// `shape.json`: the report in the user's terms (conventions stated in the file).
pub fn write_shape_json(path: &Path, r: &ShapeReport) -> Result<()> {
    let nearest = match &r.nearest {
        Ok(n) => json!({
            "found": true,
            "omega": n.omega,
            "distance": n.distance,
            "nodes": n.shape.nodes,
            "stable": n.stable,
            "growth_rate": n.growth_rate,
            "growth_rate_bound": n.rate_bound,
            "shape": shape_json(&n.shape),
        }),
        Err(e) => json!({ "found": false, "reason": e.to_string() }),
    };
    let value = json!({
        "conventions": "co-rotating frame: the pivot at (R, 0, 0), the rotation axis along z (m); \
                        nodes = axis_crossings + 1 (the pivot counts as a node); radial = signed distance \
                        from the axis in the fitted plane, depth below the pivot (m); growth_rate in 1/s, zero within round-off \
                        when its magnitude is at most growth_rate_bound",
        "t": r.t,
        "omega": r.omega,
        "radius": r.radius,
        "nodes": r.shape.nodes,
        "axis_crossings": r.shape.axis_crossings,
        "tip_radius": r.shape.tip_radius,
        "settled": r.settling.settled,
        "drift": r.settling.drift,
        "drift_threshold": r.settling.threshold,
        "window": r.settling.window,
        "window_covered": r.settling.covered,
        "shape": shape_json(&r.shape),
        "nearest": nearest,
    });
    write_json_atomic(path, &value)
}
