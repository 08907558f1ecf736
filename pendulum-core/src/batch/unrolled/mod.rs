//! `model!`'s tension models in lanes: the generated straight-line tension solve run for
//! [`WIDTH`] chains at once, one chain per lane.
//!
//! A planar model generated with `algorithm: tension` (the default from four links) writes
//! its accelerations once, as a kernel generic over [`Lane`] ([`PlanarKernel::kernel`]).
//! Its own `Model::accelerations` runs the kernel on `f64`; [`UnrolledBatch`] runs it on
//! four chains at once: where the CPU has AVX2, compiled for it on lanes that are one
//! register each (`Avx4`: every operation one instruction, where LLVM left half of
//! [`Lanes`]' arrays scalar or spilled in a kernel this long), on eight (two blocks in one
//! `Avx8` register) where it has AVX-512 VL, elsewhere on [`Lanes`]. Single precision runs
//! eight chains a register with AVX2 (`AvxF32`). The operations are the same, lane by lane, with the same sine
//! kernel, so every chain of a batch gets its single model's `θ̈` bit for bit.
//!
//! The spatial tension models (`spatial`) run the same way: [`SpatialKernel::kernel`] in
//! the model's spherical angles, [`UnrolledSpatialBatch`] on the same lanes.

mod precision;
mod rk4;
mod single;
mod spatial;

use nalgebra::{Const, SVector, U2, Vector2};

pub use self::spatial::{SpatialKernel, UnrolledSpatialBatch};

use self::precision::{KernelLanes, Precision, join};
use super::lane_states::non_finite_sum;
use super::{F64x4, Failure, WIDTH, all_finite, block_chains, check_len, for_blocks_of, gather, scatter};
use crate::batch::check_held;
use crate::error::{Error, Result};
use crate::kinematics::PlanarAngles;
use crate::lanes::{Lane, Lanes, Lanes32};
use crate::model::{Inputs, Model};

/// Blocks of [`WIDTH`] chains whose angles go through the sine kernel in one call: a
/// block's sixteen angles at n = 4 are one turn of the AVX-512 loop, its chain of
/// dependent operations waited on with nothing beside it; four blocks' turns overlap.
const GROUP: usize = 4;

/// The arrays a call evaluates, in precision `P`: `B` rows of angles `q` (rad), rates `qd`
/// (rad/s), joint torques (N·m; `None`: none) and pivot accelerations (2 a row, m/s²;
/// `None`: at rest).
#[derive(Clone, Copy)]
struct Rows<'a, P> {
    q: &'a [P],
    qd: &'a [P],
    torque: Option<&'a [P]>,
    pivot: Option<&'a [P]>,
}

/// A task's arrays for a group's angles and their sines and cosines, in lanes: kept for the
/// task's groups (zeroed per group they were 3% of the n = 8 call). `G` arrays of `N`
/// angles: one per block of a group (planar), or two (spatial: the polar angles, then the
/// azimuths).
pub(super) struct SineRoom<L, const N: usize, const G: usize = GROUP> {
    /// Each block's angles `θ_i` (rad), for the caller to fill.
    pub(super) angles: [[L; N]; G],
    sin: [[L; N]; G],
    cos: [[L; N]; G],
}

impl<L: Lane, const N: usize, const G: usize> SineRoom<L, N, G> {
    pub(super) fn new() -> Self {
        let zero = [[L::splat(0.0); N]; G];
        Self { angles: zero, sin: zero, cos: zero }
    }

    /// `sin θ_i`, `cos θ_i` of the first `count` arrays of angles, by `P`'s sine kernel in
    /// one call.
    #[inline(always)]
    pub(super) fn sin_cos<P: Precision<Lanes = L>>(&mut self, count: usize) {
        P::sin_cos_split(
            P::flatten(self.angles[..count].as_flattened()),
            P::flatten_mut(self.sin[..count].as_flattened_mut()),
            P::flatten_mut(self.cos[..count].as_flattened_mut()),
        );
    }

    /// Arrays `arrays`' `[sin θ_i, cos θ_i]` (after [`sin_cos`](Self::sin_cos)) into `trig`,
    /// in lanes `V` (`arrays[1]` joined only when `V` holds two blocks). (Returned by value,
    /// the array was kept on the stack at n = 16: 0.70×.)
    #[inline(always)]
    pub(super) fn trig<P: Precision<Lanes = L>, V: KernelLanes<P>>(
        &self,
        [a, b]: [usize; 2],
        trig: &mut [[V; 2]; N],
    ) {
        for (i, t) in trig.iter_mut().enumerate() {
            *t = [V::join([self.sin[a][i], self.sin[b][i]]), V::join([self.cos[a][i], self.cos[b][i]])];
        }
    }
}

/// The blocks of unit `u` of the first `count` blocks of a group, in lanes holding
/// `blocks` blocks each: `[u, u]` for one, `[2u, 2u + 1]` for two (`[2u, 2u]` for an odd
/// block left at the end).
#[inline(always)]
fn unit_blocks(u: usize, blocks: usize, count: usize) -> [usize; 2] {
    [blocks * u, (blocks * u + blocks - 1).min(count - 1)]
}

/// Rows `v` (`M·N` a chain) of the chains `blocks[0]`, then `blocks[1]` when `V` holds two
/// blocks, into lanes `out` (entry `N·c + i` of a row in `out[c][i]`).
#[inline(always)]
fn gather_joined<P: Precision, V: KernelLanes<P>, const N: usize, const M: usize>(
    v: &[P],
    blocks: [[usize; WIDTH]; 2],
    out: &mut [[V; N]; M],
) {
    let mut lanes = [[[P::Lanes::splat(0.0); N]; M]; 2];
    for (lanes, &chains) in lanes.iter_mut().zip(&blocks).take(V::BLOCKS) {
        gather::<P, WIDTH>(v, chains, M * N, P::flatten_mut(lanes.as_flattened_mut()));
    }
    for (c, out) in out.iter_mut().enumerate() {
        for (i, out) in out.iter_mut().enumerate() {
            *out = V::join([lanes[0][c][i], lanes[1][c][i]]);
        }
    }
}

/// That `q`, `qd`, `out` and the torques hold `chains` rows of `m`, the pivot
/// accelerations rows of `space`.
fn check_rows<P>(
    [q, qd]: [&[P]; 2],
    torque: Option<&[P]>,
    pivot: Option<&[P]>,
    out: &[P],
    chains: usize,
    [m, space]: [usize; 2],
) -> Result<()> {
    check_len("q", q, chains, m)?;
    check_len("qd", qd, chains, m)?;
    check_len("out", out, chains, m)?;
    check_held((torque, pivot), chains, [m, space])
}

/// The chains whose rows of `out` (`m` each, the first chain `first`) are not all finite,
/// each with `error(chain)`, their rows set to NaN.
fn non_finite_rows<P: Precision>(
    out: &mut [P],
    m: usize,
    first: usize,
    error: &impl Fn(usize) -> Error,
) -> Vec<Failure> {
    let mut failures = Vec::new();
    for (k, row) in out.chunks_exact_mut(m).enumerate() {
        if all_finite(row) {
            continue;
        }
        let chain = first + k;
        failures.push(Failure { chain, error: error(chain) });
        row.fill(P::NAN);
    }
    failures
}

/// A chain's per-link constants as a generated tension model reads them, `N` of each: one
/// number per link (`V = f64`), or one per chain of a block (`V = Lanes<W>`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinkConstants<V, const N: usize> {
    /// `1/m_i`, 1/kg.
    pub inverse_mass: [V; N],
    /// `l_i`, m.
    pub length: [V; N],
    /// `1/l_i`, 1/m.
    pub inverse_length: [V; N],
    /// `λ_i/l_i`, N·s.
    pub drag: [V; N],
    /// `1/m_i + 1/m_{i−1}` (`1/m_0` for the first), 1/kg: the tension system's diagonal.
    pub diagonal: [V; N],
    /// `g`, m/s².
    pub gravity: V,
}

impl<const N: usize> LinkConstants<f64, N> {
    /// The constants of `chains` side by side: lane `k` holds `chains[k]`'s.
    pub fn interleave<const W: usize>(chains: [&Self; W]) -> LinkConstants<Lanes<W>, N> {
        Self::side_by_side(chains, Lanes)
    }

    /// [`interleave`](Self::interleave) rounded to single precision.
    pub fn interleave_f32<const W: usize>(chains: [&Self; W]) -> LinkConstants<Lanes32<W>, N> {
        Self::side_by_side(chains, Lanes32::rounded)
    }

    /// Each constant of `chains`, lane `k` holding `chains[k]`'s, made a lane type by `lanes`.
    fn side_by_side<const W: usize, L>(
        chains: [&Self; W],
        lanes: impl Fn([f64; W]) -> L,
    ) -> LinkConstants<L, N> {
        let each = |of: fn(&Self) -> &[f64; N]| std::array::from_fn(|i| lanes(chains.map(|c| of(c)[i])));
        LinkConstants {
            inverse_mass: each(|c| &c.inverse_mass),
            length: each(|c| &c.length),
            inverse_length: each(|c| &c.inverse_length),
            drag: each(|c| &c.drag),
            diagonal: each(|c| &c.diagonal),
            gravity: lanes(chains.map(|c| c.gravity)),
        }
    }
}

impl<L: Copy, const N: usize> LinkConstants<L, N> {
    /// The constants of blocks `[a, b]` in lanes of type `V` (`b`'s joined only when `V`
    /// holds two blocks).
    #[inline(always)]
    fn joined<P: Precision<Lanes = L>, V: KernelLanes<P>>([a, b]: [&Self; 2]) -> LinkConstants<V, N> {
        LinkConstants {
            inverse_mass: join([&a.inverse_mass, &b.inverse_mass]),
            length: join([&a.length, &b.length]),
            inverse_length: join([&a.inverse_length, &b.inverse_length]),
            drag: join([&a.drag, &b.drag]),
            diagonal: join([&a.diagonal, &b.diagonal]),
            gravity: V::join([a.gravity, b.gravity]),
        }
    }
}

/// A model `model!` generates with `algorithm: tension`, as a batch holds it: the per-link
/// constants `new` stored, and the coordinates it is written in.
#[diagnostic::on_unimplemented(
    message = "`{Self}` has no batched form: only `model!`'s models with `algorithm: tension` batch",
    label = "not a model `model!` generated with `algorithm: tension`",
    note = "tension is the default for planar models from four links and spatial ones from two; declare a smaller one `{{ kind: …, links: …, algorithm: tension }}` to batch it",
    note = "for chains built at run time (`Chain`), use `PlanarBatch` or `DirectionsBatch`"
)]
pub trait Generated<const N: usize>: Send + Sync {
    /// [`PlanarAngles`] or [`SphericalAngles`](crate::kinematics::SphericalAngles).
    type Chart;

    /// The constants `new` stored.
    fn constants(&self) -> &LinkConstants<f64, N>;
}

/// A planar model of `N` links whose `θ̈` is one straight-line kernel over [`Lane`]s: what
/// `pendulum_macros::model!` emits for `kind: planar` with `algorithm: tension`. Its
/// `Model::accelerations` is `kernel::<f64>` (after the sines and cosines, before the
/// finiteness check); [`UnrolledBatch`] runs `kernel::<Lanes<4>>` (and `Lanes32<4>`).
#[diagnostic::on_unimplemented(
    message = "`{Self}` has no planar batched kernel: only `model!`'s planar models with `algorithm: tension` have one",
    label = "not a planar model `model!` generated with `algorithm: tension`",
    note = "tension is the default for planar models from four links; declare a smaller one `{{ kind: planar, links: …, algorithm: tension }}` to batch it",
    note = "for spatial models use `UnrolledSpatialBatch`; for chains built at run time, `PlanarBatch`"
)]
pub trait PlanarKernel<const N: usize>:
    Model<Links = Const<N>, Dof = Const<N>, Space = U2> + Generated<N, Chart = PlanarAngles>
{
    /// `θ̈_i` (rad/s²), lane by lane, from `trig[i] = [sin θ_i, cos θ_i]`, the rates `θ̇_i`
    /// (rad/s), the joint torques `σ_i` (N·m) and the pivot's acceleration `p̈ = (ẍ, ÿ)`
    /// (m/s²): the rods' tension system solved in the links' own frames. A lane whose
    /// result is not finite is the caller's to report.
    fn kernel<V: Lane>(
        c: &LinkConstants<V, N>,
        trig: &[[V; 2]; N],
        rates: &[V; N],
        torque: &[V; N],
        pivot: [V; 2],
    ) -> [V; N];
}

/// `B` chains of one generated model type `M` (`N` links each, each its own masses,
/// lengths, damping and gravity), evaluated and stepped four per instruction stream (eight
/// in `f64` with AVX-512, eight in `f32` with AVX2): planar models in the angles `θ_i`
/// (`K` = [`PlanarAngles`], the default), spatial ones in `(θ_i, φ_i)`
/// ([`UnrolledSpatialBatch`]).
///
/// ```
/// use pendulum_core::batch::UnrolledBatch;
/// use pendulum_core::Chain;
///
/// pendulum_macros::model! { struct Planar4 { kind: planar, links: 4 } }
///
/// let models = (0..8).map(|k| Planar4::new(Chain::uniform(4, 0.1 + 0.01 * k as f64, 0.2, 9.81).unwrap()));
/// let batch = UnrolledBatch::new(models.collect())?;
/// let (q, qd) = (vec![0.3; 8 * 4], vec![0.0; 8 * 4]);
/// let mut qdd = vec![0.0; 8 * 4];
/// let failures = batch.accelerations(&q, &qd, None, None, &mut qdd)?;
/// assert!(failures.is_empty());
/// # Ok::<(), pendulum_core::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct UnrolledBatch<M, const N: usize, K = PlanarAngles> {
    models: Vec<M>,
    /// Per block of [`WIDTH`] chains, their constants side by side.
    blocks: Vec<LinkConstants<F64x4, N>>,
    /// The same in single precision.
    blocks_f32: Vec<LinkConstants<Lanes32<WIDTH>, N>>,
    /// Whether the calls may use AVX-512 where the CPU has it.
    avx512: bool,
    /// The models' coordinates.
    chart: std::marker::PhantomData<K>,
}

impl<M, const N: usize, K> UnrolledBatch<M, N, K> {
    /// The batch of `models` whose constants `constants` reads.
    ///
    /// Errors: [`Error::EmptyBatch`].
    fn with_constants(models: Vec<M>, constants: impl Fn(&M) -> &LinkConstants<f64, N>) -> Result<Self> {
        if models.is_empty() {
            return Err(Error::EmptyBatch);
        }
        let block = |b: usize| block_chains(b, models.len()).map(|c| constants(&models[c]));
        let count = models.len().div_ceil(WIDTH);
        let blocks = (0..count).map(|b| LinkConstants::interleave(block(b))).collect();
        let blocks_f32 = (0..count).map(|b| LinkConstants::interleave_f32(block(b))).collect();
        Ok(Self { models, blocks, blocks_f32, avx512: true, chart: std::marker::PhantomData })
    }

    /// Whether the evaluations and RK4 runs may work on eight `f64` chains per AVX-512
    /// register where the CPU has AVX-512 VL (the default), or keep four per AVX2 register
    /// (`false`; `f32` keeps eight per AVX2 register either way). The results are the same
    /// bits either way; the choice is speed (`docs/ensembles.md`), and the other path for
    /// tests.
    pub fn with_avx512(mut self, allowed: bool) -> Self {
        self.avx512 = allowed;
        self
    }

    /// Whether the calls run with AVX-512 (allowed, and the CPU has AVX-512 VL).
    pub fn uses_avx512(&self) -> bool {
        self.avx512 && crate::lanes::has_avx512vl()
    }

    /// Number of chains `B`.
    pub fn len(&self) -> usize {
        self.models.len()
    }

    /// Never: a batch has at least one chain.
    pub fn is_empty(&self) -> bool {
        self.models.is_empty()
    }

    /// Chain `k`'s model.
    pub fn model(&self, k: usize) -> &M {
        &self.models[k]
    }
}

impl<M: Generated<N>, const N: usize> UnrolledBatch<M, N, M::Chart> {
    /// The batch of `models`, chain `k` being `models[k]`.
    ///
    /// Errors: [`Error::EmptyBatch`].
    pub fn new(models: Vec<M>) -> Result<Self> {
        Self::with_constants(models, M::constants)
    }
}

impl<M: PlanarKernel<N>, const N: usize> UnrolledBatch<M, N> {
    /// The angle accelerations `θ̈` (rad/s²) of every chain, written into `out` as `B` rows of
    /// `N`, at angles `q` (rad) and rates `qd` (rad/s) given the same way, with each chain's
    /// joint torques from `torque` (`B` rows of `N`, N·m; `None`: none) and pivot acceleration
    /// `p̈ = (ẍ, ÿ)` from `pivot` (`B` rows of 2, m/s²; `None`: pivots at rest). Row `k`
    /// equals `model(k).accelerations(..)` bit for bit; the blocks of four chains go over
    /// the current rayon pool.
    ///
    /// Returns the chains that failed, in order, each with its single model's error; their
    /// rows of `out` are NaN. Errors: [`Error::LengthMismatch`] when an array does not hold
    /// `B` rows.
    pub fn accelerations(
        &self,
        q: &[f64],
        qd: &[f64],
        torque: Option<&[f64]>,
        pivot: Option<&[f64]>,
        out: &mut [f64],
    ) -> Result<Vec<Failure>> {
        self.evaluate::<_, GROUP>(&self.blocks, [q, qd], torque, pivot, out, |chain| {
            self.error_of(chain, q, qd, torque, pivot)
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
        let row = |v: &[f64]| SVector::<f64, N>::from_column_slice(&v[chain * N..(chain + 1) * N]);
        let inputs = Inputs {
            torque: torque.map_or_else(SVector::zeros, row),
            pivot_acceleration: pivot
                .map_or_else(Vector2::zeros, |p| Vector2::new(p[2 * chain], p[2 * chain + 1])),
        };
        let mut out = SVector::zeros();
        match self.models[chain].accelerations(&row(q), &row(qd), &inputs, &mut out) {
            Err(error) => error,
            // The kernel's lanes are the single model's: unreachable unless they differ.
            Ok(()) => Error::NonFiniteAccelerations,
        }
    }
}

/// A kind of generated model's evaluation of a group in lanes: `A` arrays of `N` angles a
/// group in its sine room, rows of `ROW` numbers a chain, pivot accelerations of `SPACE`.
trait Groups<const N: usize, const A: usize>: Sync {
    /// Numbers a chain's row of `q`, `qd`, torques and results holds.
    const ROW: usize;
    /// Components of a pivot acceleration.
    const SPACE: usize;

    /// Blocks `c` of a group (at most [`GROUP`], chains `lanes[j]` in block `j`) in lanes of
    /// type `V`, their results scattered into `out` (the group's rows); a lane the model
    /// refuses is left non-finite. Returns whether every result is finite.
    fn group<P: Precision, V: KernelLanes<P>>(
        &self,
        c: &[LinkConstants<P::Lanes, N>],
        room: &mut SineRoom<P::Lanes, N, A>,
        lanes: [[usize; WIDTH]; GROUP],
        rows: Rows<'_, P>,
        out: &mut [P],
    ) -> bool;
}

impl<M: PlanarKernel<N>, const N: usize> Groups<N, GROUP> for UnrolledBatch<M, N> {
    const ROW: usize = N;
    const SPACE: usize = 2;

    /// Blocks `c` of a group (at most [`GROUP`], chains `lanes[j]` in block `j`): each
    /// block's angles gathered into lanes, the sines and cosines of all of them in one call
    /// of the sine kernel, then the kernel in lanes of type `V`, on one block or two at
    /// once ([`KernelLanes::BLOCKS`]), scattered into `out` (the group's rows).
    #[inline(always)]
    fn group<P: Precision, V: KernelLanes<P>>(
        &self,
        c: &[LinkConstants<P::Lanes, N>],
        room: &mut SineRoom<P::Lanes, N, GROUP>,
        lanes: [[usize; WIDTH]; GROUP],
        Rows { q, qd, torque, pivot }: Rows<'_, P>,
        out: &mut [P],
    ) -> bool {
        let zero = P::Lanes::splat(0.0);
        let count = c.len();
        let mut failed = V::none();
        for (angles, &lanes) in room.angles.iter_mut().zip(&lanes).take(count) {
            gather::<P, WIDTH>(q, lanes, N, P::flatten_mut(angles));
        }
        room.sin_cos::<P>(count);
        for u in 0..count.div_ceil(V::BLOCKS) {
            let pair = unit_blocks(u, V::BLOCKS, count);
            let mut trig = [[V::splat(0.0); 2]; N];
            room.trig(pair, &mut trig);
            let blocks = pair.map(|j| lanes[j]);
            let mut rates = [V::splat(0.0); N];
            gather_joined::<P, V, N, 1>(qd, blocks, std::array::from_mut(&mut rates));
            let mut torques = [V::splat(0.0); N];
            if let Some(t) = torque {
                gather_joined::<P, V, N, 1>(t, blocks, std::array::from_mut(&mut torques));
            }
            let mut pivots = [V::splat(0.0); 2];
            if let Some(p) = pivot {
                let [a, b] = blocks;
                let x = [P::lanes(|k| p[2 * a[k]]), P::lanes(|k| p[2 * b[k]])];
                let y = [P::lanes(|k| p[2 * a[k] + 1]), P::lanes(|k| p[2 * b[k] + 1])];
                pivots = [V::join(x), V::join(y)];
            }
            let accelerations = M::kernel(
                &LinkConstants::joined([&c[pair[0]], &c[pair[1]]]),
                &trig,
                &rates,
                &torques,
                pivots,
            );
            failed = V::or(failed, non_finite_sum(&accelerations).outside(0, 0));
            let mut result = [[zero; N]; 2];
            for (i, a) in accelerations.into_iter().enumerate() {
                [result[0][i], result[1][i]] = a.split();
            }
            for (result, j) in result.iter().zip(V::BLOCKS * u..count).take(V::BLOCKS) {
                let rows = WIDTH * N * j..(WIDTH * N * (j + 1)).min(out.len());
                scatter::<P, WIDTH>(P::flatten(result), N, &mut out[rows]);
            }
        }
        !V::any(failed)
    }
}

impl<M: Sync, const N: usize, K: Sync> UnrolledBatch<M, N, K> {
    /// The accelerations of every chain in precision `P`, from the blocks' constants in `P`
    /// (the arrays as `accelerations` takes them, `[q, qd]` first); a chain whose row is not
    /// finite fails with `error(chain)`, its row NaN.
    fn evaluate<P: Precision, const A: usize>(
        &self,
        blocks: &[LinkConstants<P::Lanes, N>],
        [q, qd]: [&[P]; 2],
        torque: Option<&[P]>,
        pivot: Option<&[P]>,
        out: &mut [P],
        error: impl Fn(usize) -> Error + Sync + Send,
    ) -> Result<Vec<Failure>>
    where
        Self: Groups<N, A>,
    {
        let (chains, m) = (self.len(), <Self as Groups<N, A>>::ROW);
        check_rows([q, qd], torque, pivot, out, chains, [m, <Self as Groups<N, A>>::SPACE])?;
        let failures =
            for_blocks_of::<{ GROUP * WIDTH }, _, _, _>(out, m, N, SineRoom::new, |room, g, out| {
                let first = GROUP * g;
                let count = (out.len() / m).div_ceil(WIDTH);
                let lanes = std::array::from_fn(|j| block_chains(first + j.min(count - 1), chains));
                let rows = Rows { q, qd, torque, pivot };
                // The rows are read only when a lane's result was not finite (row by row,
                // the check was a tenth of a call at n = 8).
                let finite = self.group_simd::<P, A>(&blocks[first..first + count], room, lanes, rows, out);
                if finite { Vec::new() } else { non_finite_rows(out, m, WIDTH * first, &error) }
            });
        Ok(failures)
    }

    /// [`Groups::group`] in AVX-512 registers (two blocks each in `f64`) where the CPU has
    /// AVX-512 VL and the batch allows it, in AVX2 registers where it has AVX2, else in
    /// [`Precision::Lanes`].
    fn group_simd<P: Precision, const A: usize>(
        &self,
        c: &[LinkConstants<P::Lanes, N>],
        room: &mut SineRoom<P::Lanes, N, A>,
        lanes: [[usize; WIDTH]; GROUP],
        rows: Rows<'_, P>,
        out: &mut [P],
    ) -> bool
    where
        Self: Groups<N, A>,
    {
        #[cfg(target_arch = "x86_64")]
        if self.uses_avx512() {
            // SAFETY: the CPU has AVX-512 VL (and so AVX2), checked just above.
            return unsafe { self.group_avx512::<P, A>(c, room, lanes, rows, out) };
        }
        #[cfg(target_arch = "x86_64")]
        if crate::lanes::has_avx2() {
            // SAFETY: the CPU has AVX2, checked just above.
            return unsafe { self.group_avx2::<P, A>(c, room, lanes, rows, out) };
        }
        self.group::<P, P::Lanes>(c, room, lanes, rows, out)
    }

    /// [`Groups::group`] compiled for AVX-512 VL, in [`Precision::Wide`]: two blocks an
    /// instruction in `f64` (1.07–1.17× four lanes, `docs/ensembles.md`), and 32 registers
    /// instead of 16 for a kernel that spills.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,avx512f,avx512vl")]
    fn group_avx512<P: Precision, const A: usize>(
        &self,
        c: &[LinkConstants<P::Lanes, N>],
        room: &mut SineRoom<P::Lanes, N, A>,
        lanes: [[usize; WIDTH]; GROUP],
        rows: Rows<'_, P>,
        out: &mut [P],
    ) -> bool
    where
        Self: Groups<N, A>,
    {
        self.group::<P, P::Wide>(c, room, lanes, rows, out)
    }

    /// [`Groups::group`] compiled for AVX2, in [`Precision::Registers`].
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn group_avx2<P: Precision, const A: usize>(
        &self,
        c: &[LinkConstants<P::Lanes, N>],
        room: &mut SineRoom<P::Lanes, N, A>,
        lanes: [[usize; WIDTH]; GROUP],
        rows: Rows<'_, P>,
        out: &mut [P],
    ) -> bool
    where
        Self: Groups<N, A>,
    {
        self.group::<P, P::Registers>(c, room, lanes, rows, out)
    }
}
