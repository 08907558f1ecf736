//! The batch in single precision: the same generated kernel on eight `f32` lanes, two
//! blocks of four chains in one AVX register where the CPU has AVX2 (`AvxF32`; four
//! [`Lanes32`](crate::lanes::Lanes32) lanes elsewhere), the sines from the
//! single-precision kernel, eight per AVX2 instruction. Not bit for bit the `f64` model:
//! its accuracy against it is measured in `docs/ensembles.md` and checked in the tests.

use super::{GROUP, PlanarKernel, UnrolledBatch};
use crate::batch::{Failure, first_bad_input};
use crate::error::{Error, Result};

impl<M: PlanarKernel<N>, const N: usize> UnrolledBatch<M, N> {
    /// [`accelerations`](Self::accelerations) in single precision: the same solve on eight
    /// chains at once (four without AVX2), from `f32` arrays laid out the same way (`B` rows of `N`; torques and
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
        self.evaluate::<_, GROUP>(&self.blocks_f32, [q, qd], torque, pivot, out, |chain| {
            first_bad_input(chain, [N, 2], [q, qd], torque, pivot).unwrap_or(Error::SinglePrecisionOverflow)
        })
    }
}
