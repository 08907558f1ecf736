//! Runs of the implicit rod midpoint step ([`RodMidpoint`]) for a batch of chains in
//! directions: each chain's own integrator, the chains spread over the cores. Not in SIMD
//! lanes: the step's Newton iterations and step halvings differ from chain to chain, so
//! each chain runs the single-chain code and gets its results bit for bit.

use nalgebra::{DefaultAllocator, DimName, Dyn, allocator::Allocator};
use rayon::prelude::*;

use super::{DirectionsBatch, Failure};
use crate::drive::Drive;
use crate::energy::Accounted;
use crate::error::{Error, Result};
use crate::integrate::{Integrator, State};
use crate::models::Directions;
use crate::rod_midpoint::RodMidpoint;

impl<S: DimName, Dr: Drive<S> + Clone + Sync> DirectionsBatch<S, Dr>
where
    DefaultAllocator: Allocator<S>,
{
    /// `steps` steps of the implicit rod midpoint of size `h` (s) for every chain, each from
    /// its own state and time (with the energy ledger when the batch is
    /// [`accounted`](Self::accounted)): exactly what `steps` calls of
    /// `RodMidpoint::new().step` give for each chain alone. The chains go over the current
    /// rayon pool, one task each.
    ///
    /// Returns the chains that failed, in order, each left at the start of the step that
    /// failed, with that step's error; the others go on. Errors:
    /// [`Error::InvalidStepSize`] for a zero or non-finite `h`, [`Error::LengthMismatch`]
    /// for a number of states other than `B` or a state of the wrong length.
    pub fn integrate_rod_midpoint(
        &self,
        states: &mut [State<Dyn>],
        h: f64,
        steps: usize,
    ) -> Result<Vec<Failure>> {
        if !h.is_finite() || h == 0.0 {
            return Err(Error::InvalidStepSize { h });
        }
        self.check_states(states)?;
        let run = |chain: usize, state: &mut State<Dyn>| {
            let mut integrator = RodMidpoint::new();
            let model = self.model(chain);
            let result = if self.is_accounted() {
                let system = Accounted::of(model.clone());
                let step = <RodMidpoint as Integrator<Accounted<Directions<S, Dr>>>>::step;
                (0..steps).try_for_each(|_| step(&mut integrator, &system, state, h))
            } else {
                let step = <RodMidpoint as Integrator<Directions<S, Dr>>>::step;
                (0..steps).try_for_each(|_| step(&mut integrator, model, state, h))
            };
            result.err().map(|error| Failure { chain, error })
        };
        Ok(states.par_iter_mut().enumerate().filter_map(|(chain, state)| run(chain, state)).collect())
    }
}
