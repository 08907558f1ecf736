//! `model!`'s spatial models in lanes: the generated straight-line tension solve in the
//! spherical angles `q = (θ_1 … θ_n, φ_1 … φ_n)`, run for [`WIDTH`] chains at once (eight
//! in `f64` where the CPU has AVX-512 VL, eight in `f32` with AVX2), one chain per lane,
//! bit for bit each chain's own `Model::accelerations` in `f64`.
//!
//! The model's `accelerations` checks every polar sine (`check_polar_sin`) before its
//! kernel; here the check runs in lanes ([`near_pole`]), and a chain that fails it, or
//! whose result is not finite, is run alone for its error. Their RK4 runs are the planar
//! models' (`rk4`), with two arrays of coordinates a block.

use super::precision::{KernelLanes, Precision};
use super::{
    GROUP, Generated, Groups, LinkConstants, Rows, SineRoom, UnrolledBatch, gather_joined, unit_blocks,
};
use crate::batch::lane_states::non_finite_sum;
use crate::batch::{Failure, WIDTH, first_bad_input, gather, scatter};
use crate::error::{Error, Result};
use crate::kinematics::{SINGULARITY_TOLERANCE, SphericalAngles};
use crate::lanes::Lane;

/// The polar sines `check_polar_sin` accepts, `[SINGULARITY_TOLERANCE, ∞]`, as
/// [`Lane::outside`]'s `(low, span)` of bit patterns.
const ACCEPTED_SINES: (u64, u64) = {
    let low = SINGULARITY_TOLERANCE.to_bits();
    (low, f64::INFINITY.to_bits() - low)
};

/// A spatial model of `N` links whose `(θ̈, φ̈)` is one straight-line kernel over [`Lane`]s:
/// what `pendulum_macros::model!` emits for `kind: spatial` with `algorithm: tension` (the
/// default from two links). Its `Model::accelerations` checks the polar sines, then runs
/// `kernel::<f64>`; [`UnrolledSpatialBatch`] runs it on four or eight chains at once.
#[diagnostic::on_unimplemented(
    message = "`{Self}` has no spatial batched kernel: only `model!`'s spatial models with `algorithm: tension` have one",
    label = "not a spatial model `model!` generated with `algorithm: tension`",
    note = "tension is the default for spatial models from two links; declare a one-link model `{{ kind: spatial, links: 1, algorithm: tension }}` to batch it",
    note = "for planar models use `UnrolledBatch`; for chains built at run time, `DirectionsBatch`"
)]
pub trait SpatialKernel<const N: usize>: Generated<N, Chart = SphericalAngles> {
    /// The model's own `Model::accelerations` on rows: `q`, `qd`, `torque` and `out` of
    /// `2N` (the polar angles, then the azimuths), the pivot's acceleration `p̈` (m/s²).
    fn row_accelerations(
        &self,
        q: &[f64],
        qd: &[f64],
        torque: &[f64],
        pivot: [f64; 3],
        out: &mut [f64],
    ) -> Result<()>;

    /// `[θ̈, φ̈]` (rad/s²), lane by lane, from `trig = [[sin θ_i, cos θ_i], [sin φ_i, cos φ_i]]`,
    /// the rates `[θ̇, φ̇]` (rad/s), the generalized torques `[σ_θ, σ_φ]` (N·m) and the
    /// pivot's acceleration `p̈ = (ẍ, ÿ, z̈)` (m/s²): the rods' tension system in Cartesian
    /// components. Divides by `sin θ_i`: the caller checks the polar sines first.
    fn kernel<V: Lane>(
        c: &LinkConstants<V, N>,
        trig: &[[[V; 2]; N]; 2],
        rates: &[[V; N]; 2],
        torque: &[[V; N]; 2],
        pivot: [V; 3],
    ) -> [[V; N]; 2];
}

/// `B` chains of one generated spatial model type `M` (`N` links each, each its own masses,
/// lengths, damping and gravity), evaluated and stepped four per instruction stream (eight
/// in `f64` with AVX-512, eight in `f32` with AVX2): [`UnrolledBatch`] in the models'
/// spherical angles. Rows are the models' own coordinates: `2N` a chain, the polar angles
/// `θ_i` then the azimuths `φ_i`.
///
/// ```
/// use pendulum_core::batch::UnrolledSpatialBatch;
/// use pendulum_core::Chain;
///
/// pendulum_macros::model! { struct Spatial4 { kind: spatial, links: 4 } }
///
/// let models = (0..8).map(|k| Spatial4::new(Chain::uniform(4, 0.1 + 0.01 * k as f64, 0.2, 9.81).unwrap()));
/// let batch = UnrolledSpatialBatch::new(models.collect())?;
/// let (q, qd) = (vec![0.3; 8 * 8], vec![0.5; 8 * 8]);
/// let mut qdd = vec![0.0; 8 * 8];
/// let failures = batch.accelerations(&q, &qd, None, None, &mut qdd)?;
/// assert!(failures.is_empty());
/// # Ok::<(), pendulum_core::Error>(())
/// ```
pub type UnrolledSpatialBatch<M, const N: usize> = UnrolledBatch<M, N, SphericalAngles>;

/// The lanes where some `|sin θ_i| < SINGULARITY_TOLERANCE` (or a sine is NaN): where the
/// model's `check_polar_sin` refuses the state.
#[inline(always)]
pub(super) fn near_pole<V: Lane, const N: usize>(polar: &[[V; 2]; N]) -> V::Mask {
    let (low, span) = ACCEPTED_SINES;
    // A loop, not a fold: a closure may be compiled apart from the kernel's target features.
    let mut near = V::none();
    for &[sin, _] in polar {
        near = V::or(near, sin.abs().outside(low, span));
    }
    near
}

impl<M: SpatialKernel<N>, const N: usize> UnrolledSpatialBatch<M, N> {
    /// The angle accelerations `(θ̈, φ̈)` (rad/s²) of every chain, written into `out` as `B`
    /// rows of `2N` (the model's coordinates: polar angles, then azimuths), at angles `q`
    /// (rad) and rates `qd` (rad/s) given the same way, with each chain's generalized torques
    /// from `torque` (`B` rows of `2N`, N·m; `None`: none) and pivot acceleration
    /// `p̈ = (ẍ, ÿ, z̈)` from `pivot` (`B` rows of 3, m/s²; `None`: pivots at rest). Row `k`
    /// equals `model(k).accelerations(..)` bit for bit; the blocks go over the current
    /// rayon pool.
    ///
    /// Returns the chains that failed, in order, each with its single model's error (a polar
    /// angle at a pole, `Error::SingularAngle`; a non-finite input, named; a non-finite
    /// result); their rows of `out` are NaN. Errors: [`Error::LengthMismatch`] when an array
    /// does not hold `B` rows.
    pub fn accelerations(
        &self,
        q: &[f64],
        qd: &[f64],
        torque: Option<&[f64]>,
        pivot: Option<&[f64]>,
        out: &mut [f64],
    ) -> Result<Vec<Failure>> {
        self.evaluate::<_, { 2 * GROUP }>(&self.blocks, [q, qd], torque, pivot, out, |chain| {
            self.error_of(chain, q, qd, torque, pivot)
        })
    }

    /// [`accelerations`](Self::accelerations) in single precision: the same solve on eight
    /// chains at once (four without AVX2), from `f32` arrays laid out the same way. Not bit
    /// for bit the `f64` model (its error: `docs/ensembles.md`).
    ///
    /// Returns the chains that failed, in order: a non-finite input (named), a polar sine
    /// (in `f32`) below `SINGULARITY_TOLERANCE` ([`Error::SingularAngle`]), or
    /// [`Error::SinglePrecisionOverflow`] when finite inputs give a non-finite result;
    /// their rows of `out` are NaN. Errors: [`Error::LengthMismatch`].
    pub fn accelerations_f32(
        &self,
        q: &[f32],
        qd: &[f32],
        torque: Option<&[f32]>,
        pivot: Option<&[f32]>,
        out: &mut [f32],
    ) -> Result<Vec<Failure>> {
        self.evaluate::<_, { 2 * GROUP }>(&self.blocks_f32, [q, qd], torque, pivot, out, |chain| {
            first_bad_input(chain, [2 * N, 3], [q, qd], torque, pivot)
                .or_else(|| singular_angle(&q[2 * N * chain..2 * N * chain + N]))
                .unwrap_or(Error::SinglePrecisionOverflow)
        })
    }

    /// Chain `chain`'s single model's error at its row of the inputs (out of the hot path).
    #[cold]
    fn error_of(
        &self,
        chain: usize,
        q: &[f64],
        qd: &[f64],
        torque: Option<&[f64]>,
        pivot: Option<&[f64]>,
    ) -> Error {
        let m = 2 * N;
        let row = |v: &'_ [f64]| v[chain * m..(chain + 1) * m].to_vec();
        let torque = torque.map_or_else(|| vec![0.0; m], row);
        let pivot = pivot.map_or([0.0; 3], |p| [p[3 * chain], p[3 * chain + 1], p[3 * chain + 2]]);
        let mut out = vec![0.0; m];
        match self.models[chain].row_accelerations(&row(q), &row(qd), &torque, pivot, &mut out) {
            Err(error) => error,
            // The kernel's lanes are the single model's: unreachable unless they differ.
            Ok(()) => Error::NonFiniteAccelerations,
        }
    }
}

impl<M: SpatialKernel<N>, const N: usize> Groups<N, { 2 * GROUP }> for UnrolledSpatialBatch<M, N> {
    const ROW: usize = 2 * N;
    const SPACE: usize = 3;

    /// Blocks `c` of a group (at most [`GROUP`], chains `lanes[j]` in block `j`): each
    /// block's angles gathered into lanes (block `j`'s polar angles in the room's array
    /// `2j`, its azimuths in `2j + 1`), the sines and cosines of all of them in one call of
    /// the sine kernel, then the kernel in lanes of type `V` on one block or two at once,
    /// the lanes at a pole made NaN, scattered into `out` (the group's rows).
    #[inline(always)]
    fn group<P: Precision, V: KernelLanes<P>>(
        &self,
        c: &[LinkConstants<P::Lanes, N>],
        room: &mut SineRoom<P::Lanes, N, { 2 * GROUP }>,
        lanes: [[usize; WIDTH]; GROUP],
        Rows { q, qd, torque, pivot }: Rows<'_, P>,
        out: &mut [P],
    ) -> bool {
        let zero = P::Lanes::splat(0.0);
        let (count, m) = (c.len(), 2 * N);
        let mut failed = V::none();
        for (angles, &lanes) in room.angles.chunks_exact_mut(2).zip(&lanes).take(count) {
            gather::<P, WIDTH>(q, lanes, m, P::flatten_mut(angles.as_flattened_mut()));
        }
        room.sin_cos::<P>(2 * count);
        for u in 0..count.div_ceil(V::BLOCKS) {
            let pair = unit_blocks(u, V::BLOCKS, count);
            let mut trig = [[[V::splat(0.0); 2]; N]; 2];
            room.trig(pair.map(|j| 2 * j), &mut trig[0]);
            room.trig(pair.map(|j| 2 * j + 1), &mut trig[1]);
            let blocks = pair.map(|j| lanes[j]);
            let mut rates = [[V::splat(0.0); N]; 2];
            gather_joined::<P, V, N, 2>(qd, blocks, &mut rates);
            let mut torques = [[V::splat(0.0); N]; 2];
            if let Some(t) = torque {
                gather_joined::<P, V, N, 2>(t, blocks, &mut torques);
            }
            let mut pivots = [V::splat(0.0); 3];
            if let Some(p) = pivot {
                let [a, b] = blocks;
                pivots = std::array::from_fn(|d| {
                    V::join([P::lanes(|k| p[3 * a[k] + d]), P::lanes(|k| p[3 * b[k] + d])])
                });
            }
            let constants = LinkConstants::joined([&c[pair[0]], &c[pair[1]]]);
            let mut accelerations = M::kernel(&constants, &trig, &rates, &torques, pivots);
            let near = near_pole(&trig[0]);
            if V::any(near) {
                accelerations[0][0] = V::select(near, V::splat(f64::NAN), accelerations[0][0]);
            }
            failed = V::or(failed, non_finite_sum(accelerations.as_flattened()).outside(0, 0));
            let mut result = [[[zero; N]; 2]; 2];
            for (coordinate, a) in accelerations.iter().enumerate() {
                for (i, &a) in a.iter().enumerate() {
                    [result[0][coordinate][i], result[1][coordinate][i]] = a.split();
                }
            }
            for (result, j) in result.iter().zip(V::BLOCKS * u..count).take(V::BLOCKS) {
                let rows = WIDTH * m * j..(WIDTH * m * (j + 1)).min(out.len());
                scatter::<P, WIDTH>(P::flatten(result.as_flattened()), m, &mut out[rows]);
            }
        }
        !V::any(failed)
    }
}

/// The first polar angle of `polar` (a chain's `θ_i`, `f32`) whose sine in single
/// precision is below the tolerance, named as `check_polar_sin` names it.
pub(super) fn singular_angle(polar: &[f32]) -> Option<Error> {
    polar.iter().enumerate().find_map(|(i, &theta)| {
        let sin_theta = f64::from(theta.sin().abs());
        (sin_theta < SINGULARITY_TOLERANCE).then_some(Error::SingularAngle {
            link: i + 1,
            theta: theta.into(),
            sin_theta,
            tolerance: SINGULARITY_TOLERANCE,
        })
    })
}
