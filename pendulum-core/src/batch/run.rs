//! Whole runs of a batch: [`trajectory::run`] with projected RK4 for every chain at once,
//! the samples taken on all cores.

use std::ops::ControlFlow;

use nalgebra::{DVector, DefaultAllocator, DimName, Dyn, allocator::Allocator};

use super::DirectionsBatch;
use super::rk4::Plan;
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
    /// Each block of chains runs on its own from the first step to the last; the states
    /// leave their lanes only to be sampled (on the block's thread).
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
        self.check_states(states)?;
        let t0 = states.first().map_or(0.0, |s| s.t());
        if let Some(s) = states.iter().find(|s| s.t() != t0) {
            return Err(Error::InvalidRun {
                what: "start time of a chain",
                requirement: "that of chain 0",
                value: s.t(),
            });
        }
        let (n, step) = trajectory::plan(t0, t1, h)?;
        let plan = Plan { h: step, steps: n, every: every as u64 };
        let ends = self.rk4(states, observers, plan, Some(&sample));
        let ends = ends
            .into_iter()
            .map(|(k, end)| match end.failure {
                Some((error, failed)) => {
                    Err(Error::StepFailed { t: states[k].t(), step: failed, source: Box::new(error) })
                }
                None => Ok(Summary {
                    steps: end.steps,
                    samples: 1 + end.samples,
                    h: step,
                    t: states[k].t(),
                    stopped_early: end.stopped,
                }),
            })
            .collect();
        Ok(ends)
    }
}
