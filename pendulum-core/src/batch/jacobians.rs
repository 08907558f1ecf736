//! The Jacobians of a batch: each planar chain's O(n) tangents
//! ([`PlanarTangents`](crate::PlanarTangents), through `PlanarTension`'s
//! `Derivatives::state_jacobians`), each chain in directions' O(n²) Jacobian
//! ([`Directions::analytic_jacobian`](crate::Directions::analytic_jacobian)), the chains
//! spread over the cores. Not in SIMD lanes: each chain runs the single-chain code, so the
//! results are its results bit for bit.

use nalgebra::{DVector, DefaultAllocator, DimName, Dyn, U2, Vector2, allocator::Allocator};
use rayon::prelude::*;

use super::transpose::transpose_square;
use super::{DirectionsBatch, Failure, PlanarBatch, check_len};
use crate::drive::Drive;
use crate::error::{Error, Result};
use crate::jacobians::{Derivatives, Jacobians};
use crate::model::Inputs;
use crate::models::PlanarTension;

/// A task's room: the state's `θ`, `θ̇`, the inputs and the Jacobians of a chain.
type Scratch = (DVector<f64>, DVector<f64>, Inputs<Dyn, U2>, Jacobians<PlanarTension<Dyn>>);

impl PlanarBatch {
    /// `∂θ̈/∂θ` (1/s²) and `∂θ̈/∂θ̇` (1/s) of every chain at angles `q` (rad) and rates `qd`
    /// (rad/s), `B` rows of `n`, with each chain's pivot acceleration from `pivot` (`B` rows
    /// of 2, m/s²; `None`: at rest): written into `dq` and `dqd` as `B` blocks of `n × n`,
    /// row-major (`dq[k n² + a n + b] = ∂θ̈_a/∂θ_b` of chain `k`), exactly what
    /// `PlanarTension::state_jacobians` gives for each chain alone. The chains go over the
    /// current rayon pool, each on its own.
    ///
    /// Returns the chains that failed, in order, with their errors; their blocks are NaN.
    /// Errors: [`Error::LengthMismatch`](crate::Error::LengthMismatch) when an array does
    /// not hold `B` rows or blocks.
    pub fn state_jacobians(
        &self,
        q: &[f64],
        qd: &[f64],
        pivot: Option<&[f64]>,
        dq: &mut [f64],
        dqd: &mut [f64],
    ) -> Result<Vec<Failure>> {
        let (chains, n) = (self.len(), self.links());
        check_len("q", q, chains, n)?;
        check_len("qd", qd, chains, n)?;
        check_len("dq", dq, chains, n * n)?;
        check_len("dqd", dqd, chains, n * n)?;
        if let Some(p) = pivot {
            check_len("pivot", p, chains, 2)?;
        }
        // Per task: the model's inputs and Jacobians, reused from chain to chain.
        let scratch = || {
            let model = self.chain(0);
            (DVector::zeros(n), DVector::zeros(n), Inputs::<Dyn, U2>::zeros(Dyn(n)), Jacobians::zeros(model))
        };
        let one = |(x, v, inputs, out): &mut Scratch, k: usize, dq: &mut [f64], dqd: &mut [f64]| {
            x.copy_from_slice(&q[k * n..(k + 1) * n]);
            v.copy_from_slice(&qd[k * n..(k + 1) * n]);
            if let Some(p) = pivot {
                inputs.pivot_acceleration = Vector2::new(p[2 * k], p[2 * k + 1]);
            }
            match self.chain(k).state_jacobians(x, v, inputs, out) {
                Ok(()) => {
                    // Row-major: the transposes of nalgebra's column-major blocks.
                    transpose_square(out.q.as_slice(), n, dq);
                    transpose_square(out.qd.as_slice(), n, dqd);
                    None
                }
                Err(error) => {
                    dq.fill(f64::NAN);
                    dqd.fill(f64::NAN);
                    Some(Failure { chain: k, error })
                }
            }
        };
        Ok(chain_by_chain(dq, dqd, n * n, scratch, one))
    }
}

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
        Ok(chain_by_chain(du, dw, block, scratch, one))
    }
}

/// Runs `one(scratch, k, a_k, b_k)` for every chain `k` with its blocks of `a` and `b`
/// (`len` numbers each), the chains over the current rayon pool with a `scratch` from
/// `init` per task, and collects the failures in order.
fn chain_by_chain<T>(
    a: &mut [f64],
    b: &mut [f64],
    len: usize,
    init: impl Fn() -> T + Sync + Send,
    one: impl Fn(&mut T, usize, &mut [f64], &mut [f64]) -> Option<Failure> + Sync + Send,
) -> Vec<Failure> {
    // About a thousand entries' work a task (each chain's Jacobians are O(n²)).
    let per_task = (1024 / len.max(1)).max(1);
    let chains = a.len() / len.max(1);
    if chains <= per_task || rayon::current_num_threads() == 1 {
        // One task's work, or one thread: no handing over to the pool.
        let mut scratch = init();
        let blocks = a.chunks_mut(len).zip(b.chunks_mut(len)).enumerate();
        return blocks.filter_map(|(k, (a, b))| one(&mut scratch, k, a, b)).collect();
    }
    let blocks = a.par_chunks_mut(len).zip(b.par_chunks_mut(len)).enumerate();
    blocks.with_min_len(per_task).map_init(init, |s, (k, (a, b))| one(s, k, a, b)).flatten().collect()
}
