//! Runs of RK4 for a batch of generated models, in lanes: each chain's
//! [`Rk4`](crate::integrate::Rk4) on [`FirstOrder::with_inputs`](crate::FirstOrder::with_inputs)
//! of its model, its torques held over the run and its pivot's acceleration held or from
//! its own drive at each stage's time; the states in lanes from the first step to the last.
//! One run serves the planar models (`C = 1` array of `N` coordinates a block, the angles
//! `θ_i`) and the spatial ones (`C = 2`: the polar angles, then the azimuths), through
//! [`Stages`] (`stages.rs`), and both precisions: `f64`, bit for bit each chain alone
//! (`f64.rs`), and `f32`, eight chains an AVX2 register (`f32.rs`).

mod f32;
mod f64;
mod increment;
mod stages;

use self::increment::{Accelerations, increment};
use super::precision::{KernelLanes, Precision, join};
use super::{GROUP, Groups, LinkConstants, SineRoom, UnrolledBatch, unit_blocks};
use nalgebra::{DefaultAllocator, DimName, allocator::Allocator};

use crate::batch::check_held;
use crate::batch::lane_states::non_finite_sum;
use crate::batch::{WIDTH, block_chains, check_len};
use crate::drive::Drive;
use crate::error::{Error, Result};
use crate::integrate::check_step_size;
use crate::integrate::kahan_add;
use crate::lanes::Lane;

/// A block's states in lanes: its `K` arrays of `N` coordinates, their rates and their
/// compensations, `t` and its compensation; and its inputs: the `K` arrays of torques
/// and the pivot acceleration (three components, the third 0 for planar chains) held.
struct Block<L, const N: usize, const K: usize> {
    q: [[L; N]; K],
    qd: [[L; N]; K],
    q_carry: [[L; N]; K],
    qd_carry: [[L; N]; K],
    t: L,
    t_carry: L,
    torque: [[L; N]; K],
    pivot: [L; 3],
}

impl<L: Lane, const N: usize, const K: usize> Default for Block<L, N, K> {
    fn default() -> Self {
        let zero = [[L::splat(0.0); N]; K];
        let t = L::splat(0.0);
        Self { q: zero, qd: zero, q_carry: zero, qd_carry: zero, t, t_carry: t, torque: zero, pivot: [t; 3] }
    }
}

/// A run's held inputs in precision `P`: each chain's torques (rows of `K·N`, N·m) and pivot
/// acceleration (rows of the chain's space, 2 or 3; m/s²); `None`: zeros.
type Held<'a, P> = (Option<&'a [P]>, Option<&'a [P]>);

impl<L: Lane, const N: usize, const K: usize> Block<L, N, K> {
    /// The block of chains `ids` (lane `k` holds chain `ids[k]`): lane `k`'s state
    /// `x = (q, q̇)` (`2KN` entries) and their compensations from `rows[k]`, its time and
    /// the time's compensation from `times[k]`, and its row of the held inputs `held`
    /// (pivot rows of `space` components).
    fn from_rows<P: Precision<Lanes = L>>(
        rows: [(&[P], &[P]); WIDTH],
        times: [(P, P); WIDTH],
        ids: [usize; WIDTH],
        (torque, pivot): Held<'_, P>,
        space: usize,
    ) -> Self {
        let m = K * N;
        let arrays = |offset: usize, carry: bool| -> [[L; N]; K] {
            let entry = |k: usize, j: usize| if carry { rows[k].1[j] } else { rows[k].0[j] };
            std::array::from_fn(|c| std::array::from_fn(|i| P::lanes(|k| entry(k, offset + N * c + i))))
        };
        let held = |v: &[P], per: usize, i: usize| P::lanes(|k| v[per * ids[k] + i]);
        let mut block = Self {
            q: arrays(0, false),
            qd: arrays(m, false),
            q_carry: arrays(0, true),
            qd_carry: arrays(m, true),
            t: P::lanes(|k| times[k].0),
            t_carry: P::lanes(|k| times[k].1),
            ..Self::default()
        };
        if let Some(t) = torque {
            block.torque = std::array::from_fn(|c| std::array::from_fn(|i| held(t, m, N * c + i)));
        }
        if let Some(p) = pivot {
            for (d, pivot) in block.pivot.iter_mut().enumerate().take(space) {
                *pivot = held(p, space, d);
            }
        }
        block
    }

    /// Lane `k`'s state `x = (q, q̇)`, entry by entry with its compensation, as
    /// [`from_rows`](Self::from_rows) took it.
    fn row<P: Precision<Lanes = L>>(&self, k: usize) -> impl Iterator<Item = (P, P)> + '_ {
        fn lane<P: Precision, const N: usize>(v: &[[P::Lanes; N]], k: usize) -> impl Iterator<Item = P> + '_ {
            P::flatten(v.as_flattened()).iter().skip(k).step_by(WIDTH).copied()
        }
        let x = lane::<P, N>(&self.q, k).chain(lane::<P, N>(&self.qd, k));
        x.zip(lane::<P, N>(&self.q_carry, k).chain(lane::<P, N>(&self.qd_carry, k)))
    }
}

/// Each chain's pivot acceleration `p̈` (m/s²) over a run: held (`B` rows of the chain's
/// space, 2 or 3; `None`: at rest), or chain `k`'s at time `t` from `drive(k, t)` (three
/// components, the third 0 for planar chains), asked at each stage's time: from each lane's
/// own time (`t0` `None`, the `f64` runs), or from `t0 + j h` at step `j` (`f32` runs,
/// whose lanes' time is too coarse).
#[derive(Clone, Copy)]
enum Pivot<'a> {
    Held(Option<&'a [f64]>),
    Driven { drive: &'a (dyn Fn(usize, f64) -> [f64; 3] + Sync), t0: Option<f64> },
}

/// Chain `k`'s pivot acceleration `p̈(t)` (m/s²) from `drives[k]`, its `S` components then
/// zeros up to three. Errors: [`Error::LengthMismatch`] for a number of drives other than
/// `chains`.
fn drive_of<S: DimName, Dr: Drive<S> + Sync>(
    drives: &[Dr],
    chains: usize,
) -> Result<impl Fn(usize, f64) -> [f64; 3] + Sync + '_>
where
    DefaultAllocator: Allocator<S>,
{
    check_len("drives", drives, chains, 1)?;
    Ok(|k: usize, t: f64| {
        let a = drives[k].acceleration(t);
        std::array::from_fn(|d| if d < S::DIM { a[d] } else { 0.0 })
    })
}

/// The times of `Rk4`'s four stages from a step's start `t`, as it forms them.
fn stage_times(t: f64, h: f64) -> [f64; 4] {
    let half = t + 0.5 * h;
    [t, half, half, t + h]
}

/// A stage's inputs in lanes: the torques (`A` arrays of `N`, as the coordinates) and the
/// pivot accelerations (three components per unit); `None`: zeros.
type StageInputs<'a, V, const N: usize, const A: usize> = Option<(&'a [[V; N]; A], &'a [[V; 3]; GROUP])>;

/// A batch of generated models as its RK4 run sees it: `A` arrays of `N` coordinates a
/// group ([`GROUP`] blocks of `A / GROUP` arrays each), and the accelerations of a group's
/// blocks in lanes.
trait Stages<const N: usize, const A: usize>: Groups<N, A> {
    /// `q̈` of the first `count` blocks of a group (unit `u`'s arrays from `A / GROUP · u`)
    /// at `state = [q, q̇]`, constants `c` per unit, in lanes of type `V`, with the torques `torque` (arrays as
    /// `q`) and pivot accelerations `pivot` (per unit; the planar kernel reads two): the
    /// sines and cosines of all their angles in one call of the sine kernel (in `room`),
    /// then unit by unit the kernel. A lane the model refuses (a pole) is NaN.
    fn at<P: Precision, V: KernelLanes<P>>(
        c: &[LinkConstants<V, N>; GROUP],
        count: usize,
        room: &mut SineRoom<P::Lanes, N, A>,
        state: [&[[V; N]; A]; 2],
        inputs: StageInputs<'_, V, N, A>,
    ) -> [[V; N]; A];

    /// The error of chain `chain`'s own RK4 step from `start = (t, x)` with its torques `torque`
    /// and its pivot acceleration `pivot(t)` (out of the hot path): the first stage's whose
    /// accelerations fail, else a non-finite increment.
    fn step_error(
        &self,
        chain: usize,
        start: (f64, &[f64]),
        h: f64,
        torque: &[f64],
        pivot: &dyn Fn(f64) -> [f64; 3],
    ) -> Error;
}

/// [`Stages::at`] as an [`Accelerations`] (inlined into the run): the stages' pivot
/// accelerations `pivots` at `t`, `t + h/2` and `t + h`, the `stage`-th call's taken, and
/// the torques `torque`; or, unless `FORCED`, zeros for both (a free run: the kernel's
/// zeros share a register where the inputs' arrays took sixteen at n = 8, 7% of the run).
struct Kernel<'a, B, P: Precision, V, const N: usize, const A: usize, const FORCED: bool> {
    c: &'a [LinkConstants<V, N>; GROUP],
    count: usize,
    room: &'a mut SineRoom<P::Lanes, N, A>,
    torque: &'a [[V; N]; A],
    pivots: &'a [[[V; 3]; GROUP]; 3],
    stage: usize,
    batch: std::marker::PhantomData<B>,
}

impl<B: Stages<N, A>, P: Precision, V: KernelLanes<P>, const N: usize, const A: usize, const FORCED: bool>
    Accelerations<V, N, A> for Kernel<'_, B, P, V, N, A, FORCED>
{
    #[inline(always)]
    fn at(&mut self, q: &[[V; N]; A], qd: &[[V; N]; A]) -> [[V; N]; A] {
        let inputs = FORCED.then(|| (self.torque, &self.pivots[[0, 1, 1, 2][self.stage]]));
        self.stage += 1;
        B::at::<P, V>(self.c, self.count, self.room, [q, qd], inputs)
    }
}

/// `steps` RK4 steps of the blocks `s` of the group starting at block `first` (the first
/// `count` of them, constants `blocks` in precision `P`), in lanes of type `V` (holding one
/// block each, or two; unit `u`'s arrays from `C·u`), with the blocks' held torques and pivot accelerations, or the
/// pivots' from `pivot`'s drives at each step (`FORCED`; zeros otherwise); a lane whose
/// increment is not finite stops at the start of that step. Returns the lanes that ran to
/// the end.
#[inline(always)]
fn rk4_run<
    M,
    K,
    P: Precision,
    V: KernelLanes<P>,
    const N: usize,
    const C: usize,
    const A: usize,
    const FORCED: bool,
>(
    batch: &UnrolledBatch<M, N, K>,
    (blocks, first, count): (&[LinkConstants<P::Lanes, N>], usize, usize),
    room: &mut SineRoom<P::Lanes, N, A>,
    (h, steps): (f64, usize),
    pivot: Pivot<'_>,
    s: &mut [Block<P::Lanes, N, C>; GROUP],
) -> [[bool; WIDTH]; GROUP]
where
    UnrolledBatch<M, N, K>: Stages<N, A>,
{
    let zero = V::splat(0.0);
    let units = count.div_ceil(V::BLOCKS);
    let c: [LinkConstants<V, N>; GROUP] = std::array::from_fn(|u| {
        let [a, b] = unit_blocks(u.min(units - 1), V::BLOCKS, count);
        LinkConstants::joined([&blocks[first + a], &blocks[first + b]])
    });
    let (mut q, mut qd) = ([[zero; N]; A], [[zero; N]; A]);
    let (mut q_carry, mut qd_carry) = ([[zero; N]; A], [[zero; N]; A]);
    let (mut t, mut t_carry) = ([zero; GROUP], [zero; GROUP]);
    let mut torque = [[zero; N]; A];
    // The pivot accelerations at the stages' times `t`, `t + h/2` and `t + h`, per unit.
    let mut pivots = [[[zero; 3]; GROUP]; 3];
    for u in 0..units {
        let [a, b] = unit_blocks(u, V::BLOCKS, count).map(|j| &s[j]);
        for c in 0..C {
            (q[C * u + c], qd[C * u + c]) = (join([&a.q[c], &b.q[c]]), join([&a.qd[c], &b.qd[c]]));
            q_carry[C * u + c] = join([&a.q_carry[c], &b.q_carry[c]]);
            qd_carry[C * u + c] = join([&a.qd_carry[c], &b.qd_carry[c]]);
            torque[C * u + c] = join([&a.torque[c], &b.torque[c]]);
        }
        (t[u], t_carry[u]) = (V::join([a.t, b.t]), V::join([a.t_carry, b.t_carry]));
        let held = std::array::from_fn(|d| V::join([a.pivot[d], b.pivot[d]]));
        for stage in &mut pivots {
            stage[u] = held;
        }
    }
    let mut stopped = [V::none(); GROUP];
    for step in 0..steps {
        if let (true, Pivot::Driven { drive, t0 }) = (FORCED, pivot) {
            for (u, t) in t.iter().enumerate().take(units) {
                let blocks = unit_blocks(u, V::BLOCKS, count);
                let times = t.split();
                // Each block's lanes' pivot accelerations at stages 1, 2 and 4 (3 is 2's time);
                // a unit of one block (four lanes, or an odd last block) asks its drives once.
                let fill = |half: usize| -> [[P::Lanes; 3]; 3] {
                    let chains = block_chains::<WIDTH>(first + blocks[half], batch.len());
                    let t = P::flatten(std::slice::from_ref(&times[half]));
                    let p: [[[f64; 3]; 3]; WIDTH] = std::array::from_fn(|k| {
                        let times = stage_times(t0.map_or(t[k].into(), |t0| t0 + step as f64 * h), h);
                        [0, 1, 3].map(|stage| drive(chains[k], times[stage]))
                    });
                    std::array::from_fn(|stage| {
                        std::array::from_fn(|d| P::lanes(|k| P::rounded(p[k][stage][d])))
                    })
                };
                let first_half = fill(0);
                let at = [first_half, if blocks[1] == blocks[0] { first_half } else { fill(1) }];
                for (stage, pivots) in pivots.iter_mut().enumerate() {
                    pivots[u] = std::array::from_fn(|d| V::join([at[0][stage][d], at[1][stage][d]]));
                }
            }
        }
        let kernel = Kernel::<UnrolledBatch<M, N, K>, P, V, N, A, FORCED> {
            c: &c,
            count,
            room: &mut *room,
            torque: &torque,
            pivots: &pivots,
            stage: 0,
            batch: std::marker::PhantomData,
        };
        let (dq, dqd) = increment(&q, &qd, h, kernel);
        for u in 0..units {
            let arrays = C * u..C * (u + 1);
            let increment = non_finite_sum(dq[arrays.clone()].as_flattened())
                + non_finite_sum(dqd[arrays.clone()].as_flattened());
            let stop = V::or(stopped[u], increment.outside(0, 0));
            stopped[u] = stop;
            let advance = |x: &mut V, carry: &mut V, delta: V| {
                let (new, new_carry) = kahan_add(*x, *carry, delta);
                (*x, *carry) = (V::select(stop, *x, new), V::select(stop, *carry, new_carry));
            };
            advance(&mut t[u], &mut t_carry[u], V::splat(h));
            for a in arrays {
                for i in 0..N {
                    advance(&mut q[a][i], &mut q_carry[a][i], dq[a][i]);
                    advance(&mut qd[a][i], &mut qd_carry[a][i], dqd[a][i]);
                }
            }
        }
        if stopped[..units].iter().all(|&stop| V::all(stop)) {
            break;
        }
    }
    let mut alive = [[false; WIDTH]; GROUP];
    for u in 0..units {
        // Each block of the unit once (an odd last block is both halves).
        let blocks = unit_blocks(u, V::BLOCKS, count);
        for (half, j) in blocks.into_iter().enumerate().take(V::BLOCKS.min(count - V::BLOCKS * u)) {
            for c in 0..C {
                let back = |v: &[V; N], to: &mut [P::Lanes; N]| {
                    for (to, v) in to.iter_mut().zip(v) {
                        *to = v.split()[half];
                    }
                };
                back(&q[C * u + c], &mut s[j].q[c]);
                back(&qd[C * u + c], &mut s[j].qd[c]);
                back(&q_carry[C * u + c], &mut s[j].q_carry[c]);
                back(&qd_carry[C * u + c], &mut s[j].qd_carry[c]);
            }
            (s[j].t, s[j].t_carry) = (t[u].split()[half], t_carry[u].split()[half]);
            let ran = V::select(stopped[u], zero, V::splat(1.0)).split()[half];
            let ran = P::flatten(std::slice::from_ref(&ran));
            alive[j] = std::array::from_fn(|k| ran[k].into() == 1.0);
        }
    }
    alive
}

/// [`rk4_run`] in AVX-512 registers (two blocks each in `f64`) where the CPU has AVX-512
/// VL and the batch allows it, in AVX2 registers where it has AVX2, else in
/// [`Precision::Lanes`].
fn rk4_run_simd<M, K, P: Precision, const N: usize, const C: usize, const A: usize, const FORCED: bool>(
    batch: &UnrolledBatch<M, N, K>,
    group: (&[LinkConstants<P::Lanes, N>], usize, usize),
    room: &mut SineRoom<P::Lanes, N, A>,
    run: (f64, usize),
    pivot: Pivot<'_>,
    s: &mut [Block<P::Lanes, N, C>; GROUP],
) -> [[bool; WIDTH]; GROUP]
where
    UnrolledBatch<M, N, K>: Stages<N, A>,
{
    #[cfg(target_arch = "x86_64")]
    if batch.uses_avx512() {
        // SAFETY: the CPU has AVX-512 VL (and so AVX2), checked just above.
        return unsafe { rk4_run_avx512::<M, K, P, N, C, A, FORCED>(batch, group, room, run, pivot, s) };
    }
    #[cfg(target_arch = "x86_64")]
    if crate::lanes::has_avx2() {
        // SAFETY: the CPU has AVX2, checked just above.
        return unsafe { rk4_run_avx2::<M, K, P, N, C, A, FORCED>(batch, group, room, run, pivot, s) };
    }
    rk4_run::<M, K, P, P::Lanes, N, C, A, FORCED>(batch, group, room, run, pivot, s)
}

/// [`rk4_run_simd`] of a run with inputs (`forced`: torques, held pivot accelerations or
/// drives) or of a free run, compiled apart (its zeros need no arrays).
fn rk4_run_group<M, K, P: Precision, const N: usize, const C: usize, const A: usize>(
    batch: &UnrolledBatch<M, N, K>,
    group: (&[LinkConstants<P::Lanes, N>], usize, usize),
    room: &mut SineRoom<P::Lanes, N, A>,
    run: (f64, usize),
    (pivot, forced): (Pivot<'_>, bool),
    s: &mut [Block<P::Lanes, N, C>; GROUP],
) -> [[bool; WIDTH]; GROUP]
where
    UnrolledBatch<M, N, K>: Stages<N, A>,
{
    if forced {
        rk4_run_simd::<M, K, P, N, C, A, true>(batch, group, room, run, pivot, s)
    } else {
        rk4_run_simd::<M, K, P, N, C, A, false>(batch, group, room, run, pivot, s)
    }
}

/// Errors of a run's arguments: [`Error::InvalidStepSize`] for a zero or non-finite `h`,
/// [`Error::LengthMismatch`] for held inputs not of `chains` rows (torques of `m`, pivot
/// accelerations of `space`).
fn check_run<P>(h: f64, chains: usize, [m, space]: [usize; 2], held: Held<'_, P>) -> Result<()> {
    check_step_size(h)?;
    check_held(held, chains, [m, space])
}

/// [`rk4_run`] compiled for AVX-512, in [`Precision::Wide`]: two blocks in each
/// [`Avx8`](crate::lanes::Avx8) register in `f64` (1.18–1.26× four lanes,
/// `docs/ensembles.md`).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,avx512f,avx512vl")]
fn rk4_run_avx512<M, K, P: Precision, const N: usize, const C: usize, const A: usize, const FORCED: bool>(
    batch: &UnrolledBatch<M, N, K>,
    group: (&[LinkConstants<P::Lanes, N>], usize, usize),
    room: &mut SineRoom<P::Lanes, N, A>,
    run: (f64, usize),
    pivot: Pivot<'_>,
    s: &mut [Block<P::Lanes, N, C>; GROUP],
) -> [[bool; WIDTH]; GROUP]
where
    UnrolledBatch<M, N, K>: Stages<N, A>,
{
    rk4_run::<M, K, P, P::Wide, N, C, A, FORCED>(batch, group, room, run, pivot, s)
}

/// [`rk4_run`] compiled for AVX2, in [`Precision::Registers`] ([`Avx4`](crate::lanes::Avx4)
/// in `f64`, [`AvxF32`](crate::lanes::AvxF32) in `f32`).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn rk4_run_avx2<M, K, P: Precision, const N: usize, const C: usize, const A: usize, const FORCED: bool>(
    batch: &UnrolledBatch<M, N, K>,
    group: (&[LinkConstants<P::Lanes, N>], usize, usize),
    room: &mut SineRoom<P::Lanes, N, A>,
    run: (f64, usize),
    pivot: Pivot<'_>,
    s: &mut [Block<P::Lanes, N, C>; GROUP],
) -> [[bool; WIDTH]; GROUP]
where
    UnrolledBatch<M, N, K>: Stages<N, A>,
{
    rk4_run::<M, K, P, P::Registers, N, C, A, FORCED>(batch, group, room, run, pivot, s)
}
