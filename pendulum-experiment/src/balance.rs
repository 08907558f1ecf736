//! The energy balance of a run: how far the inertial-frame energy strayed from what the
//! ledger says it should be, `max |H − H0 − W|` with `W = W_drive + W_torque − E_damped`,
//! against the energy scale of the run. An exact integration keeps it at round-off; a step
//! too long for the chain shows here first, so a balance that is off is said, not left to
//! be found in energy.csv.

use serde::{Deserialize, Serialize};

use pendulum_core::{Balance, Ledger};

use crate::assemble::Sample;
use crate::description::RunConfig;

/// The fraction of the energy scale beyond which the balance is reported as off.
pub const BALANCE_TOLERANCE: f64 = 1e-2;

/// The worst energy-balance error of a run ([`Balance`] at every sample) and the scale it
/// is judged against.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RunBalance {
    /// `max |H − H0 − W|` over the samples, J.
    pub residual: f64,
    /// The energy scale, J: the larger of [`potential_scale`] and the largest energy that
    /// changed hands (`|H − H0|`, `|W_drive|`, `|W_torque|`, `E_damped`) at any sample.
    pub scale: f64,
}

/// The work gravity could do on the chain, `Σ_k m_k g (l_1 + … + l_k)` (J), with
/// `g ≥ 1 m/s²` so that a chain without gravity still has a scale.
pub fn potential_scale(config: &RunConfig) -> f64 {
    chain_scale(&config.masses, &config.lengths, config.gravity)
}

/// [`potential_scale`] of a chain of `masses` (kg) and `lengths` (m) under `gravity` (m/s²).
pub fn chain_scale(masses: &[f64], lengths: &[f64], gravity: f64) -> f64 {
    let mut reach = 0.0;
    let mut scale = 0.0;
    for (m, l) in masses.iter().zip(lengths) {
        reach += l;
        scale += m * gravity.max(1.0) * reach;
    }
    scale
}

impl RunBalance {
    /// Nothing seen yet: no residual, the chain's [`potential_scale`].
    pub fn new(config: &RunConfig) -> Self {
        Self::of_scale(potential_scale(config))
    }

    /// Nothing seen yet, with the potential scale `scale` (J) of the chain.
    pub fn of_scale(scale: f64) -> Self {
        Self { residual: 0.0, scale }
    }

    /// Takes one sample; `h0` is the first sample's energy, J.
    pub fn push(&mut self, sample: &Sample, h0: f64) {
        self.add(sample.energy, &sample.ledger, h0);
    }

    /// Takes the energy `energy` (J) and the ledger at one instant; `h0` is the energy at
    /// the start, J.
    pub fn add(&mut self, energy: f64, ledger: &Ledger, h0: f64) {
        let change = energy - h0;
        let residual = Balance::between(h0, energy, &Ledger::default(), ledger).residual.abs();
        // `max` drops a NaN for the other value: once NaN, the residual stays NaN.
        self.residual =
            if residual.is_nan() || self.residual.is_nan() { f64::NAN } else { self.residual.max(residual) };
        for exchanged in [change.abs(), ledger.drive.abs(), ledger.torque.abs(), ledger.damped.abs()] {
            self.scale = self.scale.max(exchanged);
        }
    }

    /// The residual as a fraction of the scale.
    pub fn fraction(&self) -> f64 {
        self.residual / self.scale
    }

    /// Whether the residual passes [`BALANCE_TOLERANCE`] of the scale (or is not finite).
    pub fn is_off(&self) -> bool {
        let fraction = self.fraction();
        fraction.is_nan() || fraction > BALANCE_TOLERANCE
    }

    /// A one-line warning when the balance [`is_off`](Self::is_off).
    pub fn warning(&self) -> Option<String> {
        self.is_off().then(|| {
            format!(
                "the energy balance is off by {:.3e} J, {:.1} % of the run's energy scale {:.3e} J \
                 (more than {} %): the step is likely too long for an accurate run",
                self.residual,
                100.0 * self.fraction(),
                self.scale,
                100.0 * BALANCE_TOLERANCE
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_worst_residual_is_kept_and_a_nan_is_never_forgotten() {
        let mut b = RunBalance::of_scale(100.0);
        let ledger = Ledger { drive: 1.0, torque: 0.0, damped: 0.5 };
        b.add(5.3, &ledger, 5.0); // H − H0 − W = 0.3 − 0.5 = −0.2
        b.add(5.5, &ledger, 5.0); // 0.0
        assert!((b.residual - 0.2).abs() < 1e-12 && b.scale == 100.0 && !b.is_off());
        b.add(f64::NAN, &ledger, 5.0);
        b.add(5.5, &ledger, 5.0);
        assert!(b.residual.is_nan() && b.is_off() && b.warning().is_some());
    }
}
