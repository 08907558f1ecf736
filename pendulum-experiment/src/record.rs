//! A run kept in memory, sample by sample, as plain arrays: what a front end in another
//! language (Python's numpy arrays) or a test reads instead of files.

use crate::assemble::Sample;
use crate::error::Result;
use crate::run::Sink;

/// Every sample of a run, in memory: row `k` of each field is sample `k`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Recorder {
    /// Times, s.
    pub times: Vec<f64>,
    /// The state at each sample (coordinates, then rates; 3D: unit directions `u` then
    /// `w = u̇`), row after row.
    pub states: Vec<Vec<f64>>,
    /// The pivot, then every mass, (x, y, z) in m (z = 0 in 2D), row after row.
    pub positions: Vec<Vec<[f64; 3]>>,
    /// Inertial-frame energy `H = T + U`, J.
    pub energy: Vec<f64>,
    /// Work done by the drive since t = 0, J.
    pub drive_work: Vec<f64>,
    /// Work done by the torques since t = 0, J.
    pub torque_work: Vec<f64>,
    /// Energy dissipated by damping since t = 0, J.
    pub damped: Vec<f64>,
    /// `H − H0 − (W_drive + W_torque − E_damped)`, J: zero up to the integrator's error.
    pub balance_residual: Vec<f64>,
}

impl Recorder {
    /// Samples recorded.
    pub fn len(&self) -> usize {
        self.times.len()
    }

    /// Whether nothing was recorded.
    pub fn is_empty(&self) -> bool {
        self.times.is_empty()
    }
}

impl Sink for Recorder {
    fn sample(&mut self, s: &Sample, h0: f64) -> Result<()> {
        self.times.push(s.t);
        self.states.push(s.state.clone());
        self.positions.push(std::iter::once(s.pivot).chain(s.masses.iter().copied()).collect());
        self.energy.push(s.energy);
        self.drive_work.push(s.ledger.drive);
        self.torque_work.push(s.ledger.torque);
        self.damped.push(s.ledger.damped);
        self.balance_residual.push(s.energy - h0 - s.ledger.net());
        Ok(())
    }
}
