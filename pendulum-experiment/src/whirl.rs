//! The shape a whirled chain takes (3D, pivot circling the vertical, steady or ramped):
//! the core's shape analysis ([`ShapeTracker`]) fed along a run, for any front end to
//! present.

use nalgebra::{DVector, U3};
use pendulum_core::{Directions, ShapeOptions, ShapeReport, ShapeTracker, Turning};

use crate::assemble::{chain, turning_drive, whirl_model};
use crate::description::{Dimension, RunConfig};
use crate::error::{Error, Result};

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
