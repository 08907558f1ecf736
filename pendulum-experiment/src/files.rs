//! The sample files of a run: `trajectory.csv` (t, the state, the pivot and every mass)
//! and `energy.csv` (the energy ledger and its balance residual), streamed as the run
//! goes.

use std::path::Path;

use crate::assemble::Sample;
use crate::csv::Csv;
use crate::error::Result;
use crate::run::{Layout, Sink};

/// The columns of energy.csv.
pub const ENERGY_HEADER: [&str; 6] =
    ["t", "energy", "drive_work", "torque_work", "damped", "balance_residual"];

/// trajectory.csv and energy.csv in a directory, one row per sample.
pub struct SampleFiles {
    trajectory: Csv,
    energy: Csv,
    /// Components per position: 2 or 3.
    space: usize,
}

impl SampleFiles {
    /// Creates both files in `dir` with their headers.
    pub fn create(dir: &Path, layout: &Layout) -> Result<Self> {
        Ok(Self {
            trajectory: Csv::create(&dir.join("trajectory.csv"), &layout.trajectory_header())?,
            energy: Csv::create(&dir.join("energy.csv"), &ENERGY_HEADER)?,
            space: layout.dim.space(),
        })
    }

    /// Flushes and syncs both files.
    pub fn finish(self) -> Result<()> {
        self.trajectory.finish()?;
        self.energy.finish()
    }
}

impl Sink for SampleFiles {
    /// A trajectory row and an energy row with the balance residual
    /// `H − H0 − (W_drive + W_torque − E_damped)`.
    fn sample(&mut self, s: &Sample, h0: f64) -> Result<()> {
        let dims = self.space;
        let positions = std::iter::once(&s.pivot).chain(&s.masses).flat_map(|r| r[..dims].iter().copied());
        self.trajectory.row(std::iter::once(s.t).chain(s.state.iter().copied()).chain(positions))?;
        let l = &s.ledger;
        let residual = s.energy - h0 - l.net();
        self.energy.row([s.t, s.energy, l.drive, l.torque, l.damped, residual])
    }
}
