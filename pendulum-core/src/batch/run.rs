//! Whole runs of a batch: [`trajectory::run`] with projected RK4 for every chain at once,
//! the samples taken on all cores.

use std::ops::ControlFlow;

use nalgebra::{DVector, DefaultAllocator, DimName, Dyn, allocator::Allocator};
use rayon::prelude::*;

use super::DirectionsBatch;
use crate::drive::Drive;
use crate::error::{Error, Result};
use crate::integrate::State;
use crate::trajectory::{self, Summary};

impl<S: DimName, Dr: Drive<S> + Sync> DirectionsBatch<S, Dr>
where
    DefaultAllocator: Allocator<S>,
{
    /// Runs every chain from its state at `t0` (the same for all) to `t1` as
    /// [`trajectory::run`] does with `Projected::new(Rk4::new(..))` for that chain alone,
    /// bit for bit: the same [`plan`](trajectory::plan)`(t0, t1, h)` of equal steps,
    /// `sample(observer, t, x)` at the start, after every `every`-th step and after the
    /// last, with chain `k`'s `observers[k]`. A chain stops after a sample that returns
    /// `ControlFlow::Break(())`, or at a failed step; the others go on.
    ///
    /// Between samples the states stay in lanes; the samples of all chains are taken in
    /// parallel.
    ///
    /// Returns per chain, in order, its [`Summary`] or [`Error::StepFailed`] (its state
    /// left at the start of the failed step). Errors: [`Error::InvalidRun`] for a bad `t1`,
    /// `h` or `every = 0`, or states that do not start at one time; the length errors of
    /// [`integrate_rk4`](Self::integrate_rk4).
    #[allow(clippy::too_many_arguments)]
    pub fn run_rk4<T: Send>(
        &self,
        states: &mut [State<Dyn>],
        observers: &mut [T],
        t1: f64,
        h: f64,
        every: usize,
        sample: impl Fn(&mut T, f64, &DVector<f64>) -> ControlFlow<()> + Sync,
    ) -> Result<Vec<Result<Summary>>> {
        if every == 0 {
            let requirement = "at least 1 step";
            return Err(Error::InvalidRun { what: "sampling interval", requirement, value: 0.0 });
        }
        if observers.len() != states.len() {
            return Err(Error::LengthMismatch {
                what: "observers",
                expected: states.len(),
                got: observers.len(),
            });
        }
        self.integrate_rk4(states, 1.0, 0)?; // the lengths, checked
        let t0 = states.first().map_or(0.0, |s| s.t());
        if let Some(s) = states.iter().find(|s| s.t() != t0) {
            return Err(Error::InvalidRun {
                what: "start time of a chain",
                requirement: "that of chain 0",
                value: s.t(),
            });
        }
        let (n, step) = trajectory::plan(t0, t1, h)?;
        let mut ends: Vec<Result<Summary>> = states
            .iter()
            .map(|_| Ok(Summary { steps: 0, samples: 1, h: step, t: t0, stopped_early: false }))
            .collect();
        let mut active = vec![true; states.len()];
        // The samples of the active chains, on all cores: which ones asked to stop.
        let samples = |states: &[State<Dyn>], observers: &mut [T], active: &[bool]| -> Vec<bool> {
            (states, observers, active)
                .into_par_iter()
                .map(|(state, observer, &active)| active && sample(observer, state.t(), state.x()).is_break())
                .collect()
        };
        for (k, stop) in samples(states, observers, &active).into_iter().enumerate() {
            if let (true, Ok(summary)) = (stop, &mut ends[k]) {
                summary.stopped_early = true;
                active[k] = false;
            }
        }
        let mut done = 0u64;
        while done < n && active.contains(&true) {
            // Up to the next sample: every `every` steps, and the last.
            let chunk = (every as u64).min(n - done);
            for (failure, failed_step) in self.rk4(states, step, chunk as usize, Some(&active), done) {
                let t = states[failure.chain].t();
                ends[failure.chain] =
                    Err(Error::StepFailed { t, step: failed_step, source: Box::new(failure.error) });
                active[failure.chain] = false;
            }
            done += chunk;
            let stops = samples(states, observers, &active);
            for (k, stop) in stops.into_iter().enumerate() {
                if let (true, Ok(summary)) = (active[k], &mut ends[k]) {
                    (summary.steps, summary.t, summary.samples) = (done, states[k].t(), summary.samples + 1);
                    if stop {
                        summary.stopped_early = done < n;
                        active[k] = false;
                    }
                }
            }
        }
        Ok(ends)
    }
}
