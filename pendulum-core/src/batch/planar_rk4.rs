//! Runs of RK4 for a batch of planar chains in link angles, in lanes: [`Rk4`] on each
//! chain's first-order system `x = (θ, θ̇)` with its torques and pivot acceleration held,
//! the states in lanes from the first step to the last; in `f64` (four chains a register,
//! eight with AVX-512, bit for bit the chain alone) or `f32` (eight).
//!
//! [`Rk4`]: crate::integrate::Rk4

use nalgebra::{Dyn, U2};

#[cfg(target_arch = "x86_64")]
use super::F64x8;
use super::lane_states::{into_lanes, nan_unless_finite, out_of_lanes};
use super::planar::{Block, Torques, Work, gather_torques};
use super::run_lanes::RunLane;
use super::transpose::{gather_rows, scatter_some_rows};
use super::{
    Blocks, F32x8, F64x4, Failure, PlanarBatch, WIDTH_F32, block_chains, check_len, check_states,
    for_blocks_of, non_finite, one_of, simd_kernel,
};
use crate::batch::{check_held, check_t0};
use crate::drive::Drive;
use crate::error::{Error, Result};
use crate::integrate::check_step_size;
use crate::integrate::{State, kahan_add, rk4_weighted};
use crate::lanes::{Aligned, Lane, Lanes, Lanes32, Masked, one_row_at_a_time};

/// A block's run: `sin θ`, `cos θ` of a stage and the solve's room (`n` lanes), the joint
/// torques, the lanes with torques and the pivot accelerations, the states and their
/// compensations, the stage state `y` (then the increment) and the stages `k1 … k4`, each
/// `2n` lanes.
struct Run<V: RunLane> {
    sin: Aligned<V>,
    cos: Aligned<V>,
    work: Work<V>,
    torque: Aligned<V>,
    /// The pivot accelerations at the stages' times `t`, `t + h/2` and `t + h` (all three
    /// the same when held).
    pivot: [[V; 2]; 3],
    torqued: V::Mask,
    x: Aligned<V>,
    carry: Aligned<V>,
    y: Aligned<V>,
    k: [Aligned<V>; 4],
}

impl<V: RunLane> Run<V> {
    fn new(links: usize) -> Self {
        let lanes = |len: usize| Aligned::filled(V::splat(0.0), len);
        Self {
            sin: lanes(links),
            cos: lanes(links),
            work: Work::new(links),
            torque: lanes(links),
            pivot: [[V::splat(0.0); 2]; 3],
            torqued: V::none(),
            x: lanes(2 * links),
            carry: lanes(2 * links),
            y: lanes(2 * links),
            k: [lanes(2 * links), lanes(2 * links), lanes(2 * links), lanes(2 * links)],
        }
    }
}

impl PlanarBatch {
    /// `steps` steps of RK4 of size `h` (s) for every chain, each from its own state
    /// `x = (θ, θ̇)` (rad, rad/s; `2n` entries) and time, with its joint torques `Q_i` (N·m,
    /// `B` rows of `n`; `None`: none) and pivot acceleration `p̈` (m/s², `B` rows of 2;
    /// `None`: at rest) held over the call (a zero-order hold, as a controller applies its
    /// action): equal bit for bit to `steps` steps of [`Rk4`](crate::integrate::Rk4) on
    /// [`FirstOrder::with_inputs`](crate::FirstOrder::with_inputs)`(`[`PlanarTension`](crate::PlanarTension)`, inputs)`
    /// of that chain alone, the states kept in lanes from the first step to the last.
    ///
    /// Returns the chains that failed, in order: a non-finite state or input (by its entry,
    /// before any step), or a step whose increment is not finite ([`Error::NonFiniteState`]
    /// with the time of that step; the single chain's RK4 fails at the same step, perhaps
    /// naming the non-finite stage instead). A failed chain is left at its last good state
    /// and the others go on. Errors: [`Error::LengthMismatch`] for a number of states other
    /// than `B`, a state not of `2n` entries or inputs not of `B` rows,
    /// [`Error::InvalidStepSize`] for a non-finite or zero `h`.
    pub fn integrate_rk4(
        &self,
        states: &mut [State<Dyn>],
        torque: Option<&[f64]>,
        pivot: Option<&[f64]>,
        h: f64,
        steps: usize,
    ) -> Result<Vec<Failure>> {
        self.runs_f64((states, (torque, pivot), (h, steps)), None)
    }

    /// [`integrate_rk4`](Self::integrate_rk4) with chain `k`'s pivot moved by `drives[k]`
    /// (its pivot acceleration `p̈(t)`, m/s², at each stage's time, as the single chain's RK4
    /// asks for it: `t`, `t + h/2`, `t + h`) and its torques held: equal bit for bit to
    /// `steps` steps of [`Rk4`](crate::integrate::Rk4) on
    /// `FirstOrder::with_inputs(PlanarTension::new(chain), Driven::new(drives[k], ConstantTorque(torque_k)))`
    /// ([`Driven`](crate::Driven), [`ConstantTorque`](crate::ConstantTorque)) of that chain
    /// alone. A Kapitza pendulum per chain ([`Harmonic::vertical`](crate::Harmonic::vertical)),
    /// say, each with its own amplitude and frequency.
    ///
    /// Returns the chains that failed, as [`integrate_rk4`](Self::integrate_rk4) does (a
    /// drive whose acceleration is not finite fails its chain at that step). Errors as
    /// there, and [`Error::LengthMismatch`] for a number of drives other than `B`.
    pub fn integrate_rk4_driven<Dr: Drive<U2> + Sync>(
        &self,
        states: &mut [State<Dyn>],
        drives: &[Dr],
        torque: Option<&[f64]>,
        h: f64,
        steps: usize,
    ) -> Result<Vec<Failure>> {
        let drive = self.pivots_of(drives)?;
        self.runs_f64((states, (torque, None), (h, steps)), Some(&drive))
    }

    /// Chain `k`'s pivot acceleration `p̈(t)` (m/s²) from `drives[k]`, as `(k, t) ↦ p̈`.
    /// Errors: [`Error::LengthMismatch`] for a number of drives other than `B`.
    fn pivots_of<'a, Dr: Drive<U2> + Sync>(
        &self,
        drives: &'a [Dr],
    ) -> Result<impl Fn(usize, f64) -> [f64; 2] + Sync + 'a> {
        if drives.len() != self.len() {
            return Err(Error::LengthMismatch { what: "drives", expected: self.len(), got: drives.len() });
        }
        Ok(|chain: usize, t: f64| {
            let a = drives[chain].acceleration(t);
            [a[0], a[1]]
        })
    }

    /// The `f64` runs in this batch's lanes, the pivots from `drive` (chain, time) when
    /// given, else held; the arguments checked first.
    fn runs_f64(&self, run: RunArgs<'_, '_>, drive: Option<PivotAt<'_>>) -> Result<Vec<Failure>> {
        let (states, (torque, pivot), (h, _)) = &run;
        check_states(states, self.len(), 2 * self.links)?;
        self.check_run(*torque, *pivot, *h)?;
        let h = *h;
        Ok(match &self.blocks {
            Blocks::Four(blocks) => {
                let step =
                    |block: &Block<F64x4>, alive, s: &mut Run<F64x4>| self.rk4_step_simd(block, h, alive, s);
                self.run_f64(blocks, run, drive, step)
            }
            #[cfg(target_arch = "x86_64")]
            Blocks::Eight(blocks) => {
                let step = |block: &Block<F64x8>, alive, s: &mut Run<F64x8>| {
                    // SAFETY: eight-lane blocks exist only where the CPU has AVX-512.
                    unsafe { self.rk4_step_avx512(block, h, alive, s) }
                };
                self.run_f64(blocks, run, drive, step)
            }
            #[cfg(not(target_arch = "x86_64"))]
            Blocks::Never(_) => unreachable!("eight lanes only with AVX-512"),
        })
    }

    /// [`integrate_rk4`](Self::integrate_rk4)'s runs (arguments checked) in blocks of `W`
    /// chains with constants `blocks`, `step` making one step of a block's alive lanes.
    fn run_f64<const W: usize>(
        &self,
        blocks: &[Block<Lanes<W>>],
        (states, (torque, pivot), (h, steps)): RunArgs<'_, '_>,
        drive: Option<PivotAt<'_>>,
        step: impl Fn(&Block<Lanes<W>>, [u64; W], &mut Run<Lanes<W>>) -> [u64; W] + Sync + Send,
    ) -> Vec<Failure> {
        let (n, m) = (self.links, 2 * self.links);
        let solves = n.saturating_mul(4).saturating_mul(steps);
        for_blocks_of::<W, _, _, _>(
            states,
            1,
            solves,
            || self.rooms.take(|| Run::<Lanes<W>>::new(n)),
            |room, b, block| {
                let s = &mut **room;
                let ids = block_chains::<W>(b, self.len());
                let lanes: [usize; W] = std::array::from_fn(|k| k.min(block.len() - 1));
                let mut t = [Lanes([0.0; W]); 2];
                let suspect =
                    into_lanes(lanes.map(|k| &block[k]), m, &mut t, &mut s.x, (&mut s.carry, false)).suspect;
                // A state's entry searched for only where the lanes found one.
                let x = |k: usize| (suspect[k] != 0).then(|| block[k].x().as_slice());
                let (mut failures, ran) = start(s, (ids, block.len(), n), (torque, pivot), x);
                let mut alive = ran.map(u64::from);
                let (constants, lanes_h) = (one_of(blocks, b), Lanes([h; W]));
                for _ in 0..steps {
                    if alive == [0; W] {
                        break;
                    }
                    if let Some(drive) = drive {
                        // The stages' times as `Rk4` forms them from the step's start.
                        for (stage, pivot) in s.pivot.iter_mut().enumerate() {
                            let at = |t: f64| [t, t + 0.5 * h, t + h][stage];
                            let p: [[f64; 2]; W] = std::array::from_fn(|k| drive(ids[k], at(t[0].0[k])));
                            *pivot = [Lanes::from_fn(|k| p[k][0]), Lanes::from_fn(|k| p[k][1])];
                        }
                    }
                    let failed = step(constants, alive, s);
                    let keep = Lanes::<W>::and_not(alive, failed);
                    let (new_t, new_carry) = kahan_add(t[0], t[1], lanes_h);
                    for (k, _) in failed.iter().enumerate().filter(|(_, f)| **f != 0) {
                        let error = Error::NonFiniteState { t: t[0].0[k], h };
                        failures.push(Failure { chain: ids[k], error });
                    }
                    t = [Lanes::select(keep, new_t, t[0]), Lanes::select(keep, new_carry, t[1])];
                    alive = keep;
                }
                out_of_lanes(block.iter_mut(), ran.map(u64::from), m, (&t, &s.x, Some(&s.carry)));
                failures.sort_by_key(|f| f.chain);
                failures
            },
        )
    }

    /// [`integrate_rk4`](Self::integrate_rk4) in single precision: the states as `B` rows
    /// of `2n` of `x`, `(θ, θ̇)` (numpy's `(B, 2n)` in `f32`), and their rounding
    /// compensations the same way in `carry` (zeros to start; kept from call to call, `n`
    /// calls of one step equal one call of `n` steps), both overwritten; eight chains per
    /// AVX2 register, each chain's constants rounded to `f32`, the sines from the
    /// single-precision kernel. Not bit for bit anything: its error against the `f64` run
    /// is measured in `docs/ensembles.md`.
    ///
    /// Returns the chains that failed, in order, as [`integrate_rk4`](Self::integrate_rk4)
    /// does (a failed step's time counted from the call's start), their rows left at the
    /// last good state. Errors as there, and [`Error::LengthMismatch`] for a `carry` not
    /// the size of `x`.
    pub fn integrate_rk4_f32(
        &self,
        (x, carry): (&mut [f32], &mut [f32]),
        torque: Option<&[f32]>,
        pivot: Option<&[f32]>,
        h: f64,
        steps: usize,
    ) -> Result<Vec<Failure>> {
        self.runs_f32((x, carry), (torque, pivot), (h, steps), None)
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
        let drive = self.pivots_of(drives)?;
        check_t0(t0)?;
        self.runs_f32((x, carry), (torque, None), (h, steps), Some((t0, &drive)))
    }

    /// The `f32` runs in this batch's lanes, the pivots from `drive` (chain, time) from its
    /// start time when given, else held; the arguments checked first.
    fn runs_f32(
        &self,
        (x, carry): (&mut [f32], &mut [f32]),
        (torque, pivot): Inputs<'_, f32>,
        (h, steps): (f64, usize),
        drive: Option<(f64, PivotAt<'_>)>,
    ) -> Result<Vec<Failure>> {
        let (n, m) = (self.links, 2 * self.links);
        check_len("x", x, self.len(), m)?;
        check_len("carry", carry, self.len(), m)?;
        self.check_run(torque, pivot, h)?;
        let solves = n.saturating_mul(4).saturating_mul(steps);
        let mut chains: Vec<(&mut [f32], &mut [f32])> = x.chunks_mut(m).zip(carry.chunks_mut(m)).collect();
        Ok(for_blocks_of::<WIDTH_F32, _, _, _>(
            &mut chains,
            1,
            solves,
            || self.rooms.take(|| Run::<F32x8>::new(n)),
            |s, b, block| {
                let (ids, count) = (block_chains::<WIDTH_F32>(b, self.len()), block.len());
                let (mut failures, ran) = start(s, (ids, count, n), (torque, pivot), |k| Some(&*block[k].0));
                let mut alive = ran.map(u32::from);
                let lanes: [usize; WIDTH_F32] = std::array::from_fn(|k| k.min(count - 1));
                gather_rows(lanes.map(|k| &*block[k].0), m, Lanes32::flatten_mut(&mut s.x));
                gather_rows(lanes.map(|k| &*block[k].1), m, Lanes32::flatten_mut(&mut s.carry));
                let constants = one_of(&self.blocks_f32, b);
                let t0 = drive.map_or(0.0, |(t0, _)| t0);
                for step in 0..steps {
                    if alive == [0; WIDTH_F32] {
                        break;
                    }
                    let t = t0 + step as f64 * h;
                    if let Some((_, drive)) = drive {
                        for (stage, pivot) in s.pivot.iter_mut().enumerate() {
                            let at = [t, t + 0.5 * h, t + h][stage];
                            let p: [[f64; 2]; WIDTH_F32] = std::array::from_fn(|k| drive(ids[k], at));
                            *pivot = [0, 1].map(|c| Lanes32::rounded(std::array::from_fn(|k| p[k][c])));
                        }
                    }
                    let failed = self.rk4_step_simd(constants, h, alive, s);
                    for (k, _) in failed.iter().enumerate().filter(|(_, f)| **f != 0) {
                        let error = Error::NonFiniteState { t, h };
                        failures.push(Failure { chain: ids[k], error });
                    }
                    alive = F32x8::and_not(alive, failed);
                }
                // Every row back (lanes that did not step hold the numbers they came with).
                let mut xs: [Option<&mut [f32]>; WIDTH_F32] = Default::default();
                let mut carries: [Option<&mut [f32]>; WIDTH_F32] = Default::default();
                for (k, (x, carry)) in block.iter_mut().enumerate() {
                    (xs[k], carries[k]) = (Some(&mut **x), Some(&mut **carry));
                }
                scatter_some_rows(Lanes32::flatten(&s.x), m, xs);
                scatter_some_rows(Lanes32::flatten(&s.carry), m, carries);
                failures.sort_by_key(|f| f.chain);
                failures
            },
        ))
    }

    /// Checks a run's step and inputs: torques `B` rows of `n`, pivots `B` rows of 2.
    fn check_run<T>(&self, torque: Option<&[T]>, pivot: Option<&[T]>, h: f64) -> Result<()> {
        check_step_size(h)?;
        check_held((torque, pivot), self.len(), [self.links, 2])
    }

    simd_kernel! {
        /// One step of [`Rk4`](crate::integrate::Rk4) in lanes `V` for the chains of
        /// `block`, applied only in the `alive` lanes: the stages, the increment
        /// `h (k1 + 2 k2 + 2 k3 + k4) / 6` ([`rk4_weighted`]), then `x += increment` by
        /// compensated summation ([`State`]'s). Returns the alive lanes whose increment was
        /// not finite (left as they were).
        fn rk4_step<V: RunLane>(&self, block: &Block<V>, h: f64, alive: V::Mask, s: &mut Run<V>) -> V::Mask {
            let Run { sin, cos, work, torque, pivot, torqued, x, carry, y, k: [k1, k2, k3, k4] } = s;
            // Plain calls, not a closure: a closure is not compiled with the kernel's AVX2.
            let at = |stage: usize| ((&torque[..], *torqued), pivot[stage]);
            rates(block, at(0), x, (sin, cos, work), k1);
            // k_{j+1} = f(y) at y = x + a k_j, as nalgebra's `axpy(a, k_j, 1.0)` forms it.
            // (Each loop over rows ends with `one_row_at_a_time`.)
            let (a_half, a_full) = (V::splat(0.5 * h), V::splat(h));
            for ((y, x), k) in y.iter_mut().zip(&*x).zip(&*k1) {
                *y = a_half * *k + *x;
                one_row_at_a_time();
            }
            rates(block, at(1), y, (sin, cos, work), k2);
            for ((y, x), k) in y.iter_mut().zip(&*x).zip(&*k2) {
                *y = a_half * *k + *x;
                one_row_at_a_time();
            }
            rates(block, at(1), y, (sin, cos, work), k3);
            for ((y, x), k) in y.iter_mut().zip(&*x).zip(&*k3) {
                *y = a_full * *k + *x;
                one_row_at_a_time();
            }
            rates(block, at(2), y, (sin, cos, work), k4);
            // The step's end in one pass over the rows (three before): each row's increment,
            // its finiteness (a running sum of `y − y`) and its compensated sum with the
            // state, the new state into k1 and its compensation into k2, both spent.
            let sixth = V::splat(h / 6.0);
            let mut unfinished = V::splat(0.0);
            let rows = (k1.iter_mut().zip(k2.iter_mut())).zip((k3.iter().zip(&*k4)).zip(x.iter().zip(&*carry)));
            for ((k1, k2), ((k3, k4), (x, carry))) in rows {
                let y = rk4_weighted(sixth, [*k1, *k2, *k3, *k4]);
                unfinished += nan_unless_finite(y);
                (*k1, *k2) = kahan_add(*x, *carry, y);
                one_row_at_a_time();
            }
            let bad = V::not_finite(unfinished);
            let keep = V::and_not(alive, bad);
            if V::all(keep) {
                // Every lane steps (the common case): no copy.
                std::mem::swap(x, k1);
                std::mem::swap(carry, k2);
            } else {
                for ((x, carry), (next, next_carry)) in x.iter_mut().zip(carry.iter_mut()).zip(k1.iter().zip(&*k2)) {
                    (*x, *carry) = (V::select(keep, *next, *x), V::select(keep, *next_carry, *carry));
                    one_row_at_a_time();
                }
            }
            V::and(alive, bad)
        }
        dispatch fn rk4_step_simd, rk4_step_avx2, avx512 rk4_step_avx512
    }
}

/// A run's joint torques and pivot accelerations, each optional.
type Inputs<'a, T> = (Option<&'a [T]>, Option<&'a [T]>);

/// An `f64` run's states, held inputs, and step size and count.
type RunArgs<'s, 'a> = (&'s mut [State<Dyn>], Inputs<'a, f64>, (f64, usize));

/// Chain `k`'s pivot acceleration (m/s²) at time `t` (s), as `(k, t) ↦ [p̈_x, p̈_y]`.
type PivotAt<'a> = &'a (dyn Fn(usize, f64) -> [f64; 2] + Sync);

/// A block's start: its first `count` chains `ids` (of `n` links) with a non-finite state
/// (`x(k)` for chain `ids[k]`; `None` for a state already known finite) or input, as
/// failures; which ones can step; the inputs into lanes.
fn start<'x, V: RunLane, const W: usize>(
    s: &mut Run<V>,
    (ids, count, n): ([usize; W], usize, usize),
    (torque, pivot): Inputs<'_, V::Num>,
    x: impl Fn(usize) -> Option<&'x [V::Num]>,
) -> (Vec<Failure>, [bool; W])
where
    V::Num: 'x,
{
    let mut failures = Vec::new();
    let mut ok = [false; W];
    for (k, &c) in ids.iter().enumerate().take(count) {
        let bad = x(k)
            .and_then(|x| non_finite("x", x))
            .or_else(|| torque.and_then(|t| non_finite("torque", &t[c * n..(c + 1) * n])))
            .or_else(|| pivot.and_then(|p| non_finite("pivot_acceleration", &p[2 * c..2 * c + 2])));
        match bad {
            Some(error) => failures.push(Failure { chain: c, error }),
            None => ok[k] = true,
        }
    }
    s.torqued = match torque {
        Some(t) => {
            let flags = gather_torques(t, ids, n, V::flatten_mut(&mut s.torque));
            V::mask(|k| flags[k])
        }
        None => V::none(),
    };
    s.pivot = [match pivot {
        Some(p) => [V::from_nums(|k| p[2 * ids[k]]), V::from_nums(|k| p[2 * ids[k] + 1])],
        None => [V::splat(0.0); 2],
    }; 3];
    (failures, ok)
}

/// `x' = (θ̇, θ̈)` of the block's chains at `x = (θ, θ̇)` (`2n` lanes each), into `out`:
/// [`Block::accelerations`] with the block's torques and pivot accelerations, the sines and
/// the solve in the room given.
#[inline(always)]
fn rates<V: RunLane>(
    block: &Block<V>,
    (torques, pivot): (Torques<'_, V>, [V; 2]),
    x: &[V],
    (sin, cos, work): (&mut [V], &mut [V], &mut Work<V>),
    out: &mut [V],
) {
    let n = x.len() / 2;
    let (angles, rates) = x.split_at(n);
    V::sin_cos(angles, sin, cos);
    let (velocities, accelerations) = out.split_at_mut(n);
    velocities.copy_from_slice(rates);
    block.accelerations([sin, cos, rates], torques, pivot, work, accelerations);
}
