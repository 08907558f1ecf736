//! Many whirls at once: a chain run from hanging at rest with its pivot on a horizontal
//! circle (switched on or ramped), RK4 with projection and the energy ledger, the shape
//! analysis fed every few steps, for a list of drives as one batch of chains
//! ([`DirectionsBatch::run_rk4`]: four or eight chains per SIMD register, on the current
//! rayon pool). Each whirl is bit for bit the run of [`WhirlRuns::run_one`], so a front end (the CLI's
//! `sweep`, Python's `pendulum.whirls`) may batch whatever points are independent.

use std::ops::ControlFlow;

use nalgebra::{DVector, Dyn, U3};
use pendulum_core::batch::DirectionsBatch;
use pendulum_core::integrate::State;
use pendulum_core::trajectory::{self, Summary};
use pendulum_core::{
    Accounted, Chain, Directions, ShapeOptions, ShapeReport, ShapeTracker, Turning, TurningFrame,
    fastest_decay_bound, normal_modes,
};
use rayon::prelude::*;

use crate::assemble::{Method, directions_integrator, turning_drive, whirl_model};
use crate::balance::{RunBalance, chain_scale};
use crate::description::{DriveConfig, IntegratorKind};
use crate::request::{drive_frequency, fastest_mode, suggested_step};
use crate::steady::round_up;

/// The shape analysis is fed every this many steps (a whirl and the same `simulate` run
/// with `--every 4` report the same).
pub const FEED_EVERY: usize = 4;

/// Settle window of the shape analysis, drive periods (`ShapeOptions` default).
pub const SETTLE_PERIODS: f64 = 5.0;

/// Settled: drift at most this times the chain's length (`ShapeOptions` default).
pub const SETTLE_TOLERANCE: f64 = 1e-3;

/// Default duration: this many decay times of the first mode at rest (600 s for the
/// chain of `docs/rotating-chain.md` §4, whose first mode decays at 0.02 1/s).
const DECAY_TIMES: f64 = 12.0;

/// Default duration of an undamped sweep: this many periods of the first mode at rest.
const UNDAMPED_PERIODS: f64 = 200.0;

/// `√(g/L)`, rad/s, `L = Σ l_i` the chain's length (m), `g` its gravity (m/s²): the unit of
/// scaled speeds (`--scaled`).
pub fn reference_speed(gravity: f64, lengths: &[f64]) -> f64 {
    (gravity / lengths.iter().sum::<f64>()).sqrt()
}

/// `σ = ½ Σ λ_i v_i²`, 1/s: the decay rate of the first mode of the hanging chain under
/// the chain's damping, `v` its mass-normalised shape in link angles.
pub fn first_mode_decay(chain: &Chain<Dyn>) -> f64 {
    let modes = normal_modes(chain);
    let v = modes.shapes.column(0);
    0.5 * chain.damping().iter().zip(v.iter()).map(|(l, v)| l * v * v).sum::<f64>()
}

/// `DECAY_TIMES` (12) decay times of the first mode, rounded up to three digits; undamped,
/// `UNDAMPED_PERIODS` (200) periods of that mode.
pub fn default_duration(chain: &Chain<Dyn>) -> f64 {
    let decay = first_mode_decay(chain);
    if decay > 0.0 {
        round_up(DECAY_TIMES / decay)
    } else {
        let omega_1 = normal_modes(chain).frequencies[0];
        round_up(UNDAMPED_PERIODS * std::f64::consts::TAU / omega_1)
    }
}

/// The step `pendulum simulate` suggests for this chain on a circle of `radius` turning at
/// up to `omega` (rad/s) ([`suggested_step`]: `0.5 / ω_fastest`, at most a fortieth of the
/// drive period, `ω_fastest` with `g_eff = g + R ω²`), here also at most `1 / ν_fastest`
/// (RK4 is stable to `h ν ≈ 2.8` on decaying modes; [`fastest_decay_bound`]); rounded
/// down to two digits.
pub fn default_step(chain: &Chain<Dyn>, radius: f64, omega: f64) -> f64 {
    let circle = DriveConfig::Circle { radius, omega };
    let mut h = suggested_step(fastest_mode(chain, &circle), drive_frequency(&circle));
    let decay = fastest_decay_bound(chain);
    if decay > 0.0 {
        h = h.min(1.0 / decay);
    }
    let unit = 10f64.powi(h.log10().floor() as i32 - 1);
    (h / unit).floor() * unit
}

/// A 3D chain whose pivot circles the vertical.
pub type WhirlModel = Directions<U3, Box<dyn Turning>>;

/// How the whirls of a batch run: the chain, the run's length and step (s), the samples
/// fed to the shape analysis (every `feed_every` steps) and its options, and the energy
/// scale (J) the balance is judged against.
#[derive(Debug, Clone)]
pub struct WhirlRuns {
    pub chain: Chain<Dyn>,
    pub duration: f64,
    pub step: f64,
    pub feed_every: usize,
    pub shape: ShapeOptions,
    pub energy_scale: f64,
}

/// What a whirl's run gave: the shape report at its end, the steps taken and the energy
/// balance along it.
#[derive(Debug, Clone)]
pub struct WhirlEnd {
    pub report: ShapeReport,
    pub steps: u64,
    pub balance: RunBalance,
}

/// Why a whirl did not finish.
#[derive(Debug, Clone, PartialEq)]
pub enum WhirlStop {
    /// `stop` said so (Ctrl-C).
    Interrupted,
    /// A step or the analysis failed; the message says why.
    Failed(String),
}

impl WhirlStop {
    fn of(e: &dyn std::fmt::Display) -> Self {
        Self::Failed(e.to_string())
    }
}

/// The outcome of one whirl.
pub type WhirlResult = Result<WhirlEnd, WhirlStop>;

impl WhirlRuns {
    /// The runs of `chain` for `duration` at `step` (s), the shape analysis fed every
    /// `feed_every` steps and settled within `settle_tolerance` × L over `settle_periods`
    /// drive periods, the energy balance judged against the chain's scale
    /// ([`chain_scale`]).
    pub fn new(
        chain: Chain<Dyn>,
        duration: f64,
        step: f64,
        feed_every: usize,
        (settle_periods, settle_tolerance): (f64, f64),
    ) -> Self {
        let energy_scale =
            chain_scale(chain.masses().as_slice(), chain.lengths().as_slice(), chain.gravity());
        let shape =
            ShapeOptions { periods: settle_periods, tolerance: settle_tolerance, ..ShapeOptions::default() };
        Self { chain, duration, step, feed_every, shape, energy_scale }
    }

    /// The chain with `drive` (a circle or a ramped circle), with its energy ledger.
    pub fn system(&self, drive: &DriveConfig) -> Result<Accounted<WhirlModel>, WhirlStop> {
        Ok(Accounted::of(model(&self.chain, drive)?))
    }

    /// The shape analysis and the energy balance fed by a run of `system`; `stop()` is
    /// asked at every sample.
    pub fn observer<'a>(
        &self,
        system: &'a Accounted<WhirlModel>,
        stop: &'a (dyn Fn() -> bool + Sync),
    ) -> Result<Observer<'a>, WhirlStop> {
        let tracker = ShapeTracker::new(system.motion_system(), self.shape).map_err(|e| WhirlStop::of(&e))?;
        let balance = RunBalance::of_scale(self.energy_scale);
        let motion = DVector::zeros(system.motion_system().state_len());
        Ok(Observer { system, tracker, balance, motion, initial_energy: None, push_error: None, stop })
    }

    /// One whirl with `drive` from the chain's state `start` (`None`: hanging at rest), by
    /// `trajectory::run`; also returns the final state of the motion turned about the axis
    /// so that the pivot is at phase 0 (where a drive starting from it begins).
    pub fn run_one(
        &self,
        drive: &DriveConfig,
        start: Option<DVector<f64>>,
        stop: &(dyn Fn() -> bool + Sync),
    ) -> Result<(WhirlEnd, DVector<f64>), WhirlStop> {
        let system = self.system(drive)?;
        let model = system.motion_system();
        let x0 = start.unwrap_or_else(|| model.hanging());
        let motion_len = x0.len();
        let x0 = system.start(x0.as_slice()).map_err(|e| WhirlStop::of(&e))?;
        let mut observer = self.observer(&system, stop)?;
        let mut solver = directions_integrator(Method::of_kind(IntegratorKind::Rk4), &system)
            .map_err(|e| WhirlStop::of(&e))?;
        let mut state = State::new(0.0, x0);
        let summary = trajectory::run(
            &mut *solver,
            &system,
            &mut state,
            self.duration,
            self.step,
            self.feed_every,
            |t, x| observer.sample(t, x),
        )
        .map_err(|e| WhirlStop::of(&e))?;
        let end = observer.end(summary)?;
        let frame = TurningFrame::at(model.drive().phase(state.t()));
        Ok((end, DVector::from_vec(frame.turn_vectors(&state.x().as_slice()[..motion_len]))))
    }

    /// The whirls with `drives`, each from hanging at rest, as one batch of chains: bit for
    /// bit [`run_one`](Self::run_one) of each; `stop()` is asked at every sample. The shape
    /// reports at the end are computed in parallel too.
    pub fn run_batch(&self, drives: &[DriveConfig], stop: &(dyn Fn() -> bool + Sync)) -> Vec<WhirlResult> {
        let whirls: Vec<(&Chain<Dyn>, &DriveConfig)> = drives.iter().map(|d| (&self.chain, d)).collect();
        self.run_batch_of(&whirls, stop)
    }

    /// The whirls of chains with drives, each from hanging at rest, as one batch: bit for
    /// bit [`run_one`](Self::run_one) of a `WhirlRuns` with that chain. The chains have the
    /// same number of links and may differ in anything else but the masses, lengths and
    /// gravity the energy scale was taken from (`self.chain` is not used).
    pub fn run_batch_of(
        &self,
        whirls: &[(&Chain<Dyn>, &DriveConfig)],
        stop: &(dyn Fn() -> bool + Sync),
    ) -> Vec<WhirlResult> {
        let fail_all = |stop: WhirlStop| whirls.iter().map(|_| Err(stop.clone())).collect();
        let models = match whirls.iter().map(|(c, d)| model(c, d)).collect::<Result<Vec<_>, _>>() {
            Ok(models) => models,
            Err(e) => return fail_all(e),
        };
        let systems = match whirls
            .iter()
            .map(|(c, d)| Ok(Accounted::of(model(c, d)?)))
            .collect::<Result<Vec<_>, _>>()
        {
            Ok(systems) => systems,
            Err(e) => return fail_all(e),
        };
        let batch = match DirectionsBatch::accounted(models) {
            Ok(batch) => batch,
            Err(e) => return fail_all(WhirlStop::of(&e)),
        };
        let started = systems.iter().map(|system| {
            let x0 =
                system.start(system.motion_system().hanging().as_slice()).map_err(|e| WhirlStop::of(&e))?;
            Ok((State::new(0.0, x0), self.observer(system, stop)?))
        });
        let (mut states, mut observers): (Vec<_>, Vec<_>) =
            match started.collect::<Result<Vec<_>, WhirlStop>>() {
                Ok(pairs) => pairs.into_iter().unzip(),
                Err(e) => return fail_all(e),
            };
        let ends = match batch.run_rk4(
            &mut states,
            &mut observers,
            self.duration,
            self.step,
            self.feed_every,
            Observer::sample,
        ) {
            Ok(ends) => ends,
            Err(e) => return fail_all(WhirlStop::of(&e)),
        };
        observers
            .into_par_iter()
            .zip(ends)
            .map(|(observer, end)| observer.end(end.map_err(|e| WhirlStop::of(&e))?))
            .collect()
    }
}

/// `chain` with `drive` (a circle or a ramped circle).
pub fn model(chain: &Chain<Dyn>, drive: &DriveConfig) -> Result<WhirlModel, WhirlStop> {
    let turning = turning_drive(drive)
        .map_err(|e| WhirlStop::of(&e))?
        .ok_or_else(|| WhirlStop::Failed("the drive is not a circle".into()))?;
    Ok(whirl_model(chain.clone(), turning))
}

/// What a whirl's run feeds with its samples: the shape analysis and the energy balance.
pub struct Observer<'a> {
    system: &'a Accounted<WhirlModel>,
    tracker: ShapeTracker<'a, Box<dyn Turning>>,
    balance: RunBalance,
    /// The motion's part of the latest sample (kept: a new array a sample was a few per
    /// cent of an atlas).
    motion: DVector<f64>,
    initial_energy: Option<f64>,
    push_error: Option<pendulum_core::Error>,
    stop: &'a (dyn Fn() -> bool + Sync),
}

impl Observer<'_> {
    /// One sample at time `t` (s) of the state `x` (motion and ledger); stops the run on a
    /// failed analysis or when asked to.
    pub fn sample(&mut self, t: f64, x: &DVector<f64>) -> ControlFlow<()> {
        let energy = self.system.energy(t, x);
        self.balance.add(energy, &self.system.ledger(x), *self.initial_energy.get_or_insert(energy));
        let motion_len = self.motion.len();
        self.motion.copy_from(&x.rows(0, motion_len));
        if let Err(e) = self.tracker.push(t, &self.motion) {
            self.push_error = Some(e);
            return ControlFlow::Break(());
        }
        if (self.stop)() { ControlFlow::Break(()) } else { ControlFlow::Continue(()) }
    }

    /// The whirl's end after its run (`summary`): the shape report, or why there is none.
    pub fn end(self, summary: Summary) -> WhirlResult {
        if let Some(e) = self.push_error {
            return Err(WhirlStop::Failed(format!("shape analysis: {e}")));
        }
        if summary.stopped_early {
            return Err(WhirlStop::Interrupted);
        }
        let report = self.tracker.report().map_err(|e| WhirlStop::Failed(format!("shape analysis: {e}")))?;
        Ok(WhirlEnd { report, steps: summary.steps, balance: self.balance })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_step_resolves_the_fastest_mode() {
        // n = 20, L = 1 m: ω_fastest ≈ 2n √(g/L) = 125 rad/s; the drive adds R ω² to g.
        let chain = Chain::<Dyn>::uniform(20, 0.05, 0.05, 9.81).unwrap();
        let h = default_step(&chain, 0.02, 15.66);
        assert!((3.0e-3..4.1e-3).contains(&h), "{h}");
        assert_eq!(h, (h * 1e4).round() / 1e4);
        // Heavy damping (λ / (m l²) = 8000 1/s) shortens it.
        let damped = chain.with_damping(&[1.0; 20]).unwrap();
        assert!(default_step(&damped, 0.02, 15.66) <= 1.0 / 32000.0);
    }
}
