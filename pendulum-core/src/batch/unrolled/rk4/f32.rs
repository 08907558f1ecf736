//! RK4 runs of a batch of generated models in single precision: the `f64` runs' steps
//! (`rk4/mod.rs`) on eight `f32` chains a register (two blocks of four in one AVX2 register),
//! each chain's constants rounded to `f32`, the sines from the single-precision kernel,
//! the states as numpy holds them: `B` rows of `x = (q, q̇)` and of their compensations.
//! Not bit for bit anything: the error against the `f64` runs is measured in
//! `docs/ensembles.md` and checked in the tests.

use nalgebra::{U2, U3};

use super::{Block, Pivot, Stages, check_run, drive_of, rk4_run_group};
use crate::batch::check_t0;
use crate::batch::unrolled::spatial::singular_angle;
use crate::batch::unrolled::{
    GROUP, Groups, PlanarKernel, SineRoom, SpatialKernel, UnrolledBatch, UnrolledSpatialBatch,
};
use crate::batch::{Failure, WIDTH, block_chains, check_len, for_blocks_of, non_finite};
use crate::drive::Drive;
use crate::error::{Error, Result};
use crate::lanes::Lanes32;

/// A block of four chains in `f32` lanes.
type F32x4 = Lanes32<WIDTH>;

impl<M: PlanarKernel<N>, const N: usize> UnrolledBatch<M, N> {
    /// [`integrate_rk4`](Self::integrate_rk4) in single precision: `steps` steps of RK4 of
    /// size `h` (s) for every chain from its row of `x`, `(θ, θ̇)` (`B` rows of `2N`, numpy's
    /// `(B, 2N)` in `f32`), with the rounding compensations in `carry` laid out the same way
    /// (zeros to start; kept from call to call, so that `n` calls of one step equal one call
    /// of `n` steps), both overwritten; joint torques (`B` rows of `N`) and pivot
    /// accelerations (`B` rows of 2) held as there. Eight chains a register with AVX2.
    ///
    /// Returns the chains that failed, in order, their rows left at the start of the step
    /// that failed: a non-finite input (named), else [`Error::NonFiniteState`] with the
    /// step's time counted from the call's start. Errors: [`Error::InvalidStepSize`] for a
    /// zero or non-finite `h`, [`Error::LengthMismatch`] for arrays not of `B` rows.
    pub fn integrate_rk4_f32(
        &self,
        (x, carry): (&mut [f32], &mut [f32]),
        torque: Option<&[f32]>,
        pivot: Option<&[f32]>,
        h: f64,
        steps: usize,
    ) -> Result<Vec<Failure>> {
        integrate_f32::<_, _, N, 1, GROUP>(self, (x, carry), (torque, pivot), None, (h, steps))
    }

    /// [`integrate_rk4_f32`](Self::integrate_rk4_f32) with chain `k`'s pivot moved by
    /// `drives[k]` from the time `t0` (s), as
    /// [`integrate_rk4_driven`](Self::integrate_rk4_driven) moves it: its acceleration
    /// computed in `f64` at each stage's time (`t`, `t + h/2`, `t + h`, with `t = t0 + j h`
    /// at step `j`) and rounded to `f32`; the torques held. Not bit for bit anything: its
    /// error against the `f64` driven run is measured in `docs/ensembles.md`.
    ///
    /// Returns the chains that failed, as [`integrate_rk4_f32`](Self::integrate_rk4_f32)
    /// does (a failed step's time counted from `t0`; a drive whose acceleration is not
    /// finite in `f32` fails its chain at that step). Errors as there,
    /// [`Error::LengthMismatch`] for a number of drives other than `B`, and
    /// [`Error::NonFinite`] for a non-finite `t0`.
    pub fn integrate_rk4_driven_f32<Dr: Drive<U2> + Sync>(
        &self,
        (x, carry): (&mut [f32], &mut [f32]),
        (t0, drives): (f64, &[Dr]),
        torque: Option<&[f32]>,
        h: f64,
        steps: usize,
    ) -> Result<Vec<Failure>> {
        let drive = drive_of(drives, self.len())?;
        integrate_f32::<_, _, N, 1, GROUP>(self, (x, carry), (torque, None), Some((t0, &drive)), (h, steps))
    }
}

impl<M: SpatialKernel<N>, const N: usize> UnrolledSpatialBatch<M, N> {
    /// [`integrate_rk4`](Self::integrate_rk4) in single precision: `steps` steps of RK4 of
    /// size `h` (s) for every chain from its row of `x`, `(θ, φ, θ̇, φ̇)` (`B` rows of `4N`),
    /// with the rounding compensations in `carry` laid out the same way (zeros to start;
    /// kept from call to call), both overwritten; generalized torques (`B` rows of `2N`) and
    /// pivot accelerations (`B` rows of 3) held. Eight chains a register with AVX2.
    ///
    /// Returns the chains that failed, in order, their rows left at the start of the step
    /// that failed: a non-finite input (named), a polar angle whose sine in `f32` is below
    /// the tolerance at that start ([`Error::SingularAngle`]), else
    /// [`Error::NonFiniteState`] with the step's time counted from the call's start (a
    /// stage that reached a pole included). Errors as the planar batch's.
    pub fn integrate_rk4_f32(
        &self,
        (x, carry): (&mut [f32], &mut [f32]),
        torque: Option<&[f32]>,
        pivot: Option<&[f32]>,
        h: f64,
        steps: usize,
    ) -> Result<Vec<Failure>> {
        integrate_f32::<_, _, N, 2, { 2 * GROUP }>(self, (x, carry), (torque, pivot), None, (h, steps))
    }

    /// [`integrate_rk4_f32`](Self::integrate_rk4_f32) with chain `k`'s pivot moved by
    /// `drives[k]` from the time `t0` (s): its acceleration computed in `f64` at each
    /// stage's time (`t = t0 + j h` at step `j`) and rounded to `f32`; the torques held.
    /// Chains whirled by their top ends in single precision, each on its own
    /// [`Circle`](crate::Circle), say. Failures and errors as the planar batch's
    /// `integrate_rk4_driven_f32`.
    pub fn integrate_rk4_driven_f32<Dr: Drive<U3> + Sync>(
        &self,
        (x, carry): (&mut [f32], &mut [f32]),
        (t0, drives): (f64, &[Dr]),
        torque: Option<&[f32]>,
        h: f64,
        steps: usize,
    ) -> Result<Vec<Failure>> {
        let drive = drive_of(drives, self.len())?;
        let run = (h, steps);
        integrate_f32::<_, _, N, 2, { 2 * GROUP }>(self, (x, carry), (torque, None), Some((t0, &drive)), run)
    }
}

/// Chain `k`'s pivot acceleration at time `t` (m/s²), from its drive.
type DriveAt<'a> = &'a (dyn Fn(usize, f64) -> [f64; 3] + Sync);

/// The run of `integrate_rk4_f32` for a batch whose blocks hold `C` arrays of `N`
/// coordinates (`A = C · GROUP` a group): rows of `2CN` in `x` and `carry`, torques rows
/// of `CN`, pivot accelerations rows of [`Groups::SPACE`] held, or the pivots moved by
/// `drive` from its start time.
fn integrate_f32<M, K, const N: usize, const C: usize, const A: usize>(
    batch: &UnrolledBatch<M, N, K>,
    (x, carry): (&mut [f32], &mut [f32]),
    (torque, pivot): (Option<&[f32]>, Option<&[f32]>),
    drive: Option<(f64, DriveAt<'_>)>,
    (h, steps): (f64, usize),
) -> Result<Vec<Failure>>
where
    UnrolledBatch<M, N, K>: Stages<N, A>,
{
    let (chains, m) = (batch.len(), C * N);
    let space = <UnrolledBatch<M, N, K> as Groups<N, A>>::SPACE;
    check_run(h, chains, [m, space], (torque, pivot))?;
    let t0 = drive.map_or(0.0, |(t0, _)| t0);
    check_t0(t0)?;
    check_len("x", x, chains, 2 * m)?;
    check_len("carry", carry, chains, 2 * m)?;
    let forced = torque.is_some() || pivot.is_some() || drive.is_some();
    let moved = match drive {
        Some((t0, drive)) => Pivot::Driven { drive, t0: Some(t0) },
        None => Pivot::Held(None),
    };
    let solves = (4 * N).saturating_mul(steps);
    let mut rows: Vec<(&mut [f32], &mut [f32])> = x.chunks_mut(2 * m).zip(carry.chunks_mut(2 * m)).collect();
    Ok(for_blocks_of::<{ GROUP * WIDTH }, _, _, _>(&mut rows, 1, solves, SineRoom::new, |room, g, rows| {
        let first = GROUP * g;
        let count = rows.len().div_ceil(WIDTH);
        let mut s: [Block<F32x4, N, C>; GROUP] = std::array::from_fn(|_| Block::default());
        for (j, (s, block)) in s.iter_mut().zip(rows.chunks(WIDTH)).enumerate() {
            let own: [(&[f32], &[f32]); WIDTH] = std::array::from_fn(|k| {
                let (x, carry) = &block[k.min(block.len() - 1)];
                (&**x, &**carry)
            });
            let ids = block_chains::<WIDTH>(first + j, chains);
            *s = Block::from_rows(own, [(0.0, 0.0); WIDTH], ids, (torque, pivot), space);
        }
        let group = (&batch.blocks_f32[..], first, count);
        let alive =
            rk4_run_group::<M, K, f32, N, C, A>(batch, group, room, (h, steps), (moved, forced), &mut s);
        let mut failures = Vec::new();
        for (j, (s, block)) in s.iter().zip(rows.chunks_mut(WIDTH)).enumerate() {
            for (k, (x, carry)) in block.iter_mut().enumerate() {
                for ((x, carry), (new, new_carry)) in x.iter_mut().zip(carry.iter_mut()).zip(s.row::<f32>(k))
                {
                    (*x, *carry) = (new, new_carry);
                }
                if !alive[j][k] {
                    let chain = WIDTH * (first + j) + k;
                    let bad =
                        |what, v: &[f32], per: usize| non_finite(what, &v[per * chain..per * (chain + 1)]);
                    let error = non_finite("x", x)
                        .or_else(|| torque.and_then(|t| bad("torque", t, m)))
                        .or_else(|| pivot.and_then(|p| bad("pivot_acceleration", p, space)))
                        .or_else(|| (C == 2).then(|| singular_angle(&x[..N])).flatten())
                        .unwrap_or(Error::NonFiniteState { t: t0 + f64::from(s.t.0[k]), h });
                    failures.push(Failure { chain, error });
                }
            }
        }
        failures
    }))
}
