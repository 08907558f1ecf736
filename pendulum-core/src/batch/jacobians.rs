//! The Jacobians of a batch in directions: each chain's O(n²) Jacobian
//! ([`Directions::analytic_jacobian`](crate::Directions::analytic_jacobian)) chain by chain,
//! the chains over the cores, every chain's own results bit for bit (the planar ones, in
//! lanes: `planar_jacobians`); and the loop over blocks both use.

use nalgebra::{DVector, DefaultAllocator, DimName, allocator::Allocator};
use rayon::prelude::*;

use super::transpose::transpose_square;
use super::{DirectionsBatch, Failure, check_len};
use crate::drive::Drive;
use crate::error::{Error, Result};

impl<S: DimName, Dr: Drive<S> + Sync> DirectionsBatch<S, Dr>
where
    DefaultAllocator: Allocator<S>,
{
    /// `∂ü/∂u` (1/s²) and `∂ü/∂w` (1/s) of every chain at time `t` (s) and states
    /// `x = (u, w)` (`B` rows of `2·S·n`): written into `du` and `dw` as `B` blocks of
    /// `h × h`, `h = S·n`, row-major (`du[k h² + a h + b] = ∂ü_a/∂u_b` of chain `k`). They
    /// are the lower blocks of each chain's
    /// [`Directions::analytic_jacobian`](crate::Directions::analytic_jacobian), bit for bit:
    /// the Jacobian of the first-order system in the directions' own `S` components each
    /// (the constraint `|u_i| = 1` not imposed), one O(n²) pass a chain. The chains go over
    /// the current rayon pool, each on its own (not in lanes).
    ///
    /// Returns the chains that failed, in order, with their errors (a non-finite state as
    /// the chain alone names it; a non-finite result as
    /// [`Error::NotPositiveDefinite`](crate::Error::NotPositiveDefinite), as in
    /// [`accelerations`](Self::accelerations)); their blocks are NaN. Errors:
    /// [`Error::LengthMismatch`](crate::Error::LengthMismatch) when an array does not hold
    /// `B` rows or blocks.
    pub fn state_jacobians(&self, t: f64, x: &[f64], du: &mut [f64], dw: &mut [f64]) -> Result<Vec<Failure>> {
        let half = S::DIM * self.links();
        check_len("x", x, self.len(), 2 * half)?;
        self.jacobians_of(t, |k, state| state.copy_from_slice(&x[2 * half * k..2 * half * (k + 1)]), du, dw)
    }

    /// [`state_jacobians`](Self::state_jacobians) of the states given as two arrays, the
    /// directions `u` and the rates `w`, `B` rows of `S·n` each (as numpy holds `q` and
    /// `qd`): the same numbers.
    ///
    /// Errors: [`Error::LengthMismatch`](crate::Error::LengthMismatch) when an array does
    /// not hold `B` rows or blocks.
    pub fn state_jacobians_split(
        &self,
        t: f64,
        u: &[f64],
        w: &[f64],
        du: &mut [f64],
        dw: &mut [f64],
    ) -> Result<Vec<Failure>> {
        let half = S::DIM * self.links();
        check_len("u", u, self.len(), half)?;
        check_len("w", w, self.len(), half)?;
        let state = |k: usize, state: &mut DVector<f64>| {
            let rows = half * k..half * (k + 1);
            state.as_mut_slice()[..half].copy_from_slice(&u[rows.clone()]);
            state.as_mut_slice()[half..].copy_from_slice(&w[rows]);
        };
        self.jacobians_of(t, state, du, dw)
    }

    /// The Jacobians of every chain at the state `state(k, x)` writes into `x`.
    fn jacobians_of(
        &self,
        t: f64,
        state: impl Fn(usize, &mut DVector<f64>) + Sync + Send,
        du: &mut [f64],
        dw: &mut [f64],
    ) -> Result<Vec<Failure>> {
        let half = S::DIM * self.links();
        let block = half * half;
        check_len("du", du, self.len(), block)?;
        check_len("dw", dw, self.len(), block)?;
        // Per task: the state and the lower blocks, column-major, reused from chain to chain.
        let scratch = || (DVector::zeros(2 * half), vec![0.0; 2 * block]);
        let one = |(x, lower): &mut (DVector<f64>, Vec<f64>), k: usize, du: &mut [f64], dw: &mut [f64]| {
            state(k, x);
            let model = self.model(k);
            let error = match model.check_state(x) {
                Err(error) => Some(error),
                Ok(()) => {
                    model.lower_jacobian_of_valid(t, x.as_slice(), lower);
                    let finite = lower.iter().fold(true, |all, v| all & v.is_finite());
                    (!finite).then_some(Error::NotPositiveDefinite)
                }
            };
            if let Some(error) = error {
                du.fill(f64::NAN);
                dw.fill(f64::NAN);
                return Some(Failure { chain: k, error });
            }
            // Row-major: the transposes of the column-major blocks.
            transpose_square(&lower[..block], half, du);
            transpose_square(&lower[block..], half, dw);
            None
        };
        Ok(in_blocks(du, dw, block, scratch, one))
    }
}

/// Runs `one(scratch, k, a_k, b_k)` for every block `k` of `a` and `b` (`len` numbers each,
/// the last ones shorter), the blocks over the current rayon pool with a `scratch` from
/// `init` per task, and collects the failures in order.
pub(super) fn in_blocks<N: Send, T, F: IntoIterator<Item = Failure> + Send>(
    a: &mut [N],
    b: &mut [N],
    len: usize,
    init: impl Fn() -> T + Sync + Send,
    one: impl Fn(&mut T, usize, &mut [N], &mut [N]) -> F + Sync + Send,
) -> Vec<Failure> {
    // About a thousand entries' work a task (each chain's Jacobians are O(n²)).
    let per_task = (1024 / len.max(1)).max(1);
    let blocks = a.len().div_ceil(len.max(1));
    if blocks <= per_task || rayon::current_num_threads() == 1 {
        // One task's work, or one thread: no handing over to the pool.
        let mut scratch = init();
        let blocks = a.chunks_mut(len).zip(b.chunks_mut(len)).enumerate();
        return blocks.flat_map(|(k, (a, b))| one(&mut scratch, k, a, b)).collect();
    }
    let blocks = a.par_chunks_mut(len).zip(b.par_chunks_mut(len)).enumerate();
    let failures = blocks.with_min_len(per_task).map_init(init, |s, (k, (a, b))| one(s, k, a, b));
    failures.flat_map_iter(|f| f).collect()
}
