//! The batch in single precision: the same generated kernel on four `f32` lanes
//! ([`Lanes32`]), the sines from the single-precision kernel, eight per AVX2 instruction. Not bit for bit the
//! `f64` model: its accuracy against it is measured in `docs/ensembles.md` and checked in
//! the tests.

use super::{PlanarKernel, UnrolledBatch};
use crate::batch::{Failure, block_chains_of, check_len, for_blocks_of, simd_kernel};
use crate::error::{Error, Result};
use crate::kinematics::trig32::sin_cos_split_f32;
use crate::lanes::Lanes32;

/// Chains per block in single precision: four `f32` lanes. Eight (one AVX2 register) were
/// measured slower from n = 8 on: the compiler split most of the eight-lane kernel into
/// four-lane and scalar instructions (`docs/ensembles.md`).
pub const WIDTH_F32: usize = 4;

/// A block's numbers in single precision, one per lane.
pub(super) type F32Lanes = Lanes32<WIDTH_F32>;

impl<M: PlanarKernel<N>, const N: usize> UnrolledBatch<M, N> {
    /// [`accelerations`](Self::accelerations) in single precision: the same solve on four
    /// chains at once, from `f32` arrays laid out the same way (`B` rows of `N`; torques and
    /// pivot accelerations optional). Not bit for bit the `f64` model: about 10⁻⁶ of the
    /// largest `|θ̈|` for chains whose masses and lengths stay within a decade of each
    /// other (`docs/ensembles.md`).
    ///
    /// Returns the chains that failed, in order: a non-finite input (named), or
    /// [`Error::SinglePrecisionOverflow`] when finite inputs give a non-finite result; their
    /// rows of `out` are NaN. Errors: [`Error::LengthMismatch`] when an array does not hold
    /// `B` rows.
    pub fn accelerations_f32(
        &self,
        q: &[f32],
        qd: &[f32],
        torque: Option<&[f32]>,
        pivot: Option<&[f32]>,
        out: &mut [f32],
    ) -> Result<Vec<Failure>> {
        let chains = self.len();
        check_len("q", q, chains, N)?;
        check_len("qd", qd, chains, N)?;
        check_len("out", out, chains, N)?;
        if let Some(t) = torque {
            check_len("torque", t, chains, N)?;
        }
        if let Some(p) = pivot {
            check_len("pivot", p, chains, 2)?;
        }
        let failures = for_blocks_of::<WIDTH_F32, _, _, _>(
            out,
            N,
            N,
            || (),
            |_, b, out| {
                let lanes = block_chains_of::<WIDTH_F32>(b, chains);
                self.block_f32_simd(b, lanes, q, qd, torque, pivot, out);
                let mut failures = Vec::new();
                for (k, row) in out.chunks_exact_mut(N).enumerate() {
                    if row.iter().all(|v| v.is_finite()) {
                        continue;
                    }
                    let chain = lanes[k];
                    let input = |what, v: &[f32], m: usize| non_finite(what, &v[chain * m..(chain + 1) * m]);
                    let error = input("q", q, N)
                        .or_else(|| input("qd", qd, N))
                        .or_else(|| torque.and_then(|t| input("torque", t, N)))
                        .or_else(|| pivot.and_then(|p| input("pivot_acceleration", p, 2)))
                        .unwrap_or(Error::SinglePrecisionOverflow);
                    row.fill(f32::NAN);
                    failures.push(Failure { chain, error });
                }
                failures
            },
        );
        Ok(failures)
    }

    simd_kernel! {
        /// One block of [`WIDTH_F32`] chains: gather into lanes, the sines and cosines, the kernel,
        /// scatter into `out` (the block's rows).
        fn block_f32(
            &self,
            b: usize,
            lanes: [usize; WIDTH_F32],
            q: &[f32],
            qd: &[f32],
            torque: Option<&[f32]>,
            pivot: Option<&[f32]>,
            out: &mut [f32],
        ) {
            let gather_one = |v: &[f32], i: usize| Lanes32::from_fn(|k| v[lanes[k] * N + i]);
            let gather = |v: &[f32]| -> [F32Lanes; N] { std::array::from_fn(|i| gather_one(v, i)) };
            let zero = Lanes32([0.0; WIDTH_F32]);
            let angles = gather(q);
            let (mut sin, mut cos) = ([zero; N], [zero; N]);
            sin_cos_split_f32(Lanes32::flatten(&angles), Lanes32::flatten_mut(&mut sin), Lanes32::flatten_mut(&mut cos));
            let trig = std::array::from_fn(|i| [sin[i], cos[i]]);
            let torque = torque.map_or([zero; N], gather);
            let pivot = match pivot {
                Some(p) => [Lanes32::from_fn(|k| p[2 * lanes[k]]), Lanes32::from_fn(|k| p[2 * lanes[k] + 1])],
                None => [zero; 2],
            };
            let accelerations = M::kernel(&self.blocks_f32[b], &trig, &gather(qd), &torque, pivot);
            for (k, row) in out.chunks_exact_mut(N).enumerate() {
                for (o, a) in row.iter_mut().zip(&accelerations) {
                    *o = a.0[k];
                }
            }
        }
        dispatch fn block_f32_simd, block_f32_avx2
    }
}

/// The first non-finite entry of `v` as the single-chain error.
fn non_finite(what: &'static str, v: &[f32]) -> Option<Error> {
    v.iter().position(|x| !x.is_finite()).map(|index| Error::NonFinite {
        what,
        index,
        value: f64::from(v[index]),
    })
}
