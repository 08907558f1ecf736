//! The Jacobians of a batch of planar chains: each chain's O(n) tangents
//! ([`PlanarTangents`](crate::PlanarTangents), through `PlanarTension`'s
//! `Derivatives::state_jacobians`), the chains spread over the cores. Not in SIMD lanes:
//! each chain runs the single-chain code, so the results are its results bit for bit.

use nalgebra::{DVector, Dyn, U2, Vector2};
use rayon::prelude::*;

use super::transpose::transpose_square;
use super::{Failure, PlanarBatch, check_len};
use crate::error::Result;
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
        // About a thousand rods' work a task (each chain's Jacobians are n² entries).
        let per_task = (1024 / (n * n)).max(1);
        if chains <= per_task || rayon::current_num_threads() == 1 {
            // One task's work, or one thread: no handing over to the pool.
            let mut scratch = scratch();
            let blocks = dq.chunks_mut(n * n).zip(dqd.chunks_mut(n * n)).enumerate();
            return Ok(blocks.filter_map(|(k, (dq, dqd))| one(&mut scratch, k, dq, dqd)).collect());
        }
        let blocks = dq.par_chunks_mut(n * n).zip(dqd.par_chunks_mut(n * n)).enumerate();
        Ok(blocks
            .with_min_len(per_task)
            .map_init(scratch, |s, (k, (dq, dqd))| one(s, k, dq, dqd))
            .flatten()
            .collect())
    }
}
