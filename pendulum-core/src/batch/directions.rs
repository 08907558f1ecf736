//! A batch of chains in unit link directions ([`Directions`]), planar or spatial, each with
//! its own drive: accelerations, and whole steps of projected RK4, for many chains per call.

use std::ops::ControlFlow;

use nalgebra::{DVector, DefaultAllocator, DimName, Dyn, allocator::Allocator};

use super::{
    F64x4, Failure, WIDTH, block_chains, check_len, check_links, for_blocks, gather, non_finite, simd_kernel,
};
use crate::chain::Chain;
use crate::drive::{Drive, Fixed};
use crate::energy::ledger::{LEDGER_LEN, direction_powers};
use crate::error::{Error, Result};
use crate::integrate::State;
use crate::integrate::kahan_add;
use crate::lanes::Lane;
use crate::lanes::Lanes;
use crate::models::Directions;
use crate::models::directions::{project_link, rate_load};
use crate::rods::{Load, Rods, Rows};

/// `B` chains in unit link directions with the same number of links `n`, each with its own
/// masses, lengths, damping, gravity and drive (`S = U2` planar, `U3` spatial).
///
/// [`accelerations`](Self::accelerations) equals [`Directions::accelerations`] chain by
/// chain, and [`step_rk4`](Self::step_rk4) one step of
/// `Projected::new(Rk4::new(..))` ([`Projected`](crate::integrate::Projected),
/// [`Rk4`](crate::integrate::Rk4)) on each chain, bit for bit (module docs of
/// [`batch`](super)).
#[derive(Debug, Clone)]
pub struct DirectionsBatch<S: DimName, Dr = Fixed> {
    models: Vec<Directions<S, Dr>>,
    blocks: Vec<Block>,
    links: usize,
    /// Whether the states carry the energy ledger of [`Accounted`].
    accounted: bool,
}

/// What the solve needs of one block's chains.
#[derive(Debug, Clone)]
struct Block {
    rods: Rods<F64x4>,
    /// `−g` (m/s²) per lane.
    down: F64x4,
    /// Per link, the mass hanging from it (kg), its length (m) and damping `λ` (N·m·s): the
    /// ledger's powers.
    tails: Vec<F64x4>,
    lengths: Vec<F64x4>,
    damping: Vec<F64x4>,
}

/// Per task: the rows of the solve and, for the steps, the stage vectors in lane order.
struct Scratch<const C: usize> {
    solve: Solve<C>,
    /// Time and its compensation (s) per lane.
    t: [F64x4; 2],
    /// The compensation of the state per lane.
    carry: Vec<F64x4>,
    x: Vec<F64x4>,
    y: Vec<F64x4>,
    k: [Vec<F64x4>; 4],
}

/// The steps of a run in lanes: `steps` of size `h` (s), sampled every `every`.
#[derive(Debug, Clone, Copy)]
pub(super) struct Plan {
    pub h: f64,
    pub steps: u64,
    pub every: u64,
}

/// How a chain's run in lanes ended: steps taken and samples (the first included) before
/// it stopped or finished, whether a sample stopped it, and a failure with the step that
/// failed.
#[derive(Debug, Default)]
pub(super) struct End {
    pub steps: u64,
    pub samples: u64,
    pub stopped: bool,
    pub failure: Option<(Error, u64)>,
}

/// The type of "no sampling".
type NoSample = fn(&mut (), f64, &DVector<f64>) -> ControlFlow<()>;

/// The loads and rows of one solve in lanes.
struct Solve<const C: usize> {
    rows: Rows<C, F64x4>,
    loads: Vec<Load<C, F64x4>>,
}

impl<const C: usize> Scratch<C> {
    fn new(links: usize, state_len: usize) -> Self {
        let lanes = || vec![Lanes([0.0; WIDTH]); state_len];
        Self {
            solve: Solve { rows: Rows::with_len(links), loads: vec![Load::zero(); links] },
            t: [Lanes([0.0; WIDTH]); 2],
            carry: lanes(),
            x: lanes(),
            y: lanes(),
            k: [lanes(), lanes(), lanes(), lanes()],
        }
    }
}

impl<S: DimName, Dr: Drive<S> + Sync> DirectionsBatch<S, Dr>
where
    DefaultAllocator: Allocator<S>,
{
    /// The batch of `models`, all with the same number of links.
    ///
    /// Errors: [`Error::EmptyBatch`], [`Error::BatchMismatch`] naming the first model whose
    /// length differs from model 0's, [`Error::LengthMismatch`] for a space other than 2 or
    /// 3 dimensions.
    pub fn new(models: Vec<Directions<S, Dr>>) -> Result<Self> {
        if !(2..=3).contains(&S::DIM) {
            return Err(Error::LengthMismatch { what: "space", expected: 3, got: S::DIM });
        }
        let links = check_links(models.iter().map(Directions::links))?;
        let blocks = (0..models.len().div_ceil(WIDTH))
            .map(|b| {
                let lanes = block_chains(b, models.len());
                let per_link = |of: fn(&Chain<Dyn>) -> &[f64]| -> Vec<F64x4> {
                    (0..links).map(|i| Lanes::from_fn(|k| of(models[lanes[k]].chain())[i])).collect()
                };
                Block {
                    rods: Rods::interleave(lanes.map(|c| models[c].rods())),
                    down: Lanes(lanes.map(|c| -models[c].chain().gravity())),
                    tails: per_link(|c| c.tail_masses().as_slice()),
                    lengths: per_link(|c| c.lengths().as_slice()),
                    damping: per_link(|c| c.damping().as_slice()),
                }
            })
            .collect();
        Ok(Self { models, blocks, links, accounted: false })
    }

    /// The batch of `models` with their energy ledgers: states as
    /// [`Accounted::state`](crate::energy::Accounted) gives them (`(u, w)` then the ledger's
    /// drive work, torque work and damping loss, J), and
    /// [`step_rk4`](Self::step_rk4) / [`integrate_rk4`](Self::integrate_rk4) equal bit for bit to
    /// `Projected<Rk4>` on [`Accounted`](crate::energy::Accounted)`<Directions>`.
    /// [`accelerations`](Self::accelerations) is unchanged (the motion alone).
    ///
    /// Errors: those of [`new`](Self::new).
    pub fn accounted(models: Vec<Directions<S, Dr>>) -> Result<Self> {
        Ok(Self { accounted: true, ..Self::new(models)? })
    }

    /// Number of chains `B`.
    pub fn len(&self) -> usize {
        self.models.len()
    }

    /// Never: a batch has at least one chain.
    pub fn is_empty(&self) -> bool {
        self.models.is_empty()
    }

    /// Links per chain `n`.
    pub fn links(&self) -> usize {
        self.links
    }

    /// Chain `k`'s single-chain model.
    pub fn model(&self, k: usize) -> &Directions<S, Dr> {
        &self.models[k]
    }

    /// Entries of one chain's state, `2·S·n`.
    pub fn state_len(&self) -> usize {
        2 * S::DIM * self.links + if self.accounted { LEDGER_LEN } else { 0 }
    }

    /// The direction accelerations `ü` (1/s²) of every chain at time `t` (s), written into
    /// `out` as `B` rows of `S·n`, at the states `x = (u, w)` given as `B` rows of `2·S·n`.
    ///
    /// Returns the chains that failed (a non-finite state or result), in order; their rows
    /// of `out` are NaN. Errors: [`Error::LengthMismatch`] when an array does not hold `B`
    /// rows.
    pub fn accelerations(&self, t: f64, x: &[f64], out: &mut [f64]) -> Result<Vec<Failure>> {
        let (chains, half) = (self.len(), S::DIM * self.links);
        check_len("x", x, chains, 2 * half)?;
        check_len("out", out, chains, half)?;
        Ok(match S::DIM {
            2 => self.accelerations_in::<2>(t, x, out),
            _ => self.accelerations_in::<3>(t, x, out),
        })
    }

    fn accelerations_in<const C: usize>(&self, t: f64, x: &[f64], out: &mut [f64]) -> Vec<Failure> {
        let (chains, n) = (self.len(), self.links);
        let (half, m) = (C * n, 2 * C * n);
        for_blocks(
            out,
            half,
            n,
            || Scratch::<C>::new(n, self.state_len()),
            |s, b, out| {
                let lanes = block_chains(b, chains);
                gather(x, lanes, m, &mut s.x);
                let [k1, ..] = &mut s.k;
                self.flow_simd::<C>(b, lanes, [t; WIDTH], &s.x, &mut s.solve, k1);
                let mut failures = Vec::new();
                for (k, row) in out.chunks_exact_mut(half).enumerate() {
                    for (i, v) in row.iter_mut().enumerate() {
                        *v = s.k[0][half + i].0[k];
                    }
                    if !row.iter().all(|v| v.is_finite()) {
                        let chain = lanes[k];
                        let error = non_finite("x", &x[chain * m..(chain + 1) * m])
                            .unwrap_or(Error::NotPositiveDefinite);
                        row.fill(f64::NAN);
                        failures.push(Failure { chain, error });
                    }
                }
                failures
            },
        )
    }

    /// One step of RK4 with projection (`Projected<Rk4>`) of size `h` (s) for every chain,
    /// each from its own state and time: [`integrate_rk4`](Self::integrate_rk4) with one step.
    ///
    /// Errors and failures as [`integrate_rk4`](Self::integrate_rk4).
    pub fn step_rk4(&self, states: &mut [State<Dyn>], h: f64) -> Result<Vec<Failure>> {
        self.integrate_rk4(states, h, 1)
    }

    /// `steps` steps of RK4 with projection (`Projected<Rk4>`) of size `h` (s) for every
    /// chain, each from its own state and time; equal bit for bit to `steps` calls of
    /// [`step_rk4`](Self::step_rk4), but the states stay in lanes from the first step to the
    /// last.
    ///
    /// Returns the chains that failed (a non-finite state, or a step that produced one), in
    /// order: each is left at its last good state (the error names the time of the failed
    /// step) and the others go on. Errors: [`Error::LengthMismatch`] for a number of states
    /// other than `B` or a state of the wrong length, [`Error::InvalidStepSize`] for a
    /// non-finite or zero `h`.
    pub fn integrate_rk4(&self, states: &mut [State<Dyn>], h: f64, steps: usize) -> Result<Vec<Failure>> {
        if !h.is_finite() || h == 0.0 {
            return Err(Error::InvalidStepSize { h });
        }
        self.check_states(states)?;
        let mut none = vec![(); states.len()];
        let plan = Plan { h, steps: steps as u64, every: steps.max(1) as u64 };
        let ends = self.rk4(states, &mut none, plan, None::<&NoSample>);
        Ok(ends
            .into_iter()
            .filter_map(|(chain, end)| end.failure.map(|(error, _)| Failure { chain, error }))
            .collect())
    }

    /// One state per chain, each of [`state_len`](Self::state_len) entries.
    pub(super) fn check_states(&self, states: &[State<Dyn>]) -> Result<()> {
        if states.len() != self.len() {
            return Err(Error::LengthMismatch { what: "states", expected: self.len(), got: states.len() });
        }
        match states.iter().find(|s| s.x().len() != self.state_len()) {
            Some(s) => Err(Error::LengthMismatch { what: "x", expected: self.state_len(), got: s.x().len() }),
            None => Ok(()),
        }
    }

    /// Runs the chains `plan.steps` steps of `Projected<Rk4>` of size `plan.h` in lanes,
    /// each block on its own from its first step to its last (no barrier between blocks),
    /// with `sample(observers[k], t, x)` of each running chain at the start and after every
    /// `plan.every`-th step and the last (when given). A chain stops after a sample that
    /// returns `Break`, or at a failed step (its state left at the start of that step).
    /// Returns how each chain ended, in chain order.
    pub(super) fn rk4<T: Send, F>(
        &self,
        states: &mut [State<Dyn>],
        observers: &mut [T],
        plan: Plan,
        sample: Option<&F>,
    ) -> Vec<(usize, End)>
    where
        F: Fn(&mut T, f64, &DVector<f64>) -> ControlFlow<()> + Sync,
    {
        match S::DIM {
            2 => self.rk4_in::<2, T, F>(states, observers, plan, sample),
            _ => self.rk4_in::<3, T, F>(states, observers, plan, sample),
        }
    }

    fn rk4_in<const C: usize, T: Send, F>(
        &self,
        states: &mut [State<Dyn>],
        observers: &mut [T],
        plan: Plan,
        sample: Option<&F>,
    ) -> Vec<(usize, End)>
    where
        F: Fn(&mut T, f64, &DVector<f64>) -> ControlFlow<()> + Sync,
    {
        let n = self.links;
        let mut chains: Vec<(&mut State<Dyn>, &mut T)> =
            states.iter_mut().zip(observers.iter_mut()).collect();
        let solves = n.saturating_mul(4).saturating_mul(plan.steps.min(usize::MAX as u64) as usize);
        // Tasks of whole runs: a block's states stay in lanes from the first step to the
        // last, and go out only to be sampled.
        for_blocks(
            &mut chains,
            1,
            solves,
            || Scratch::<C>::new(n, self.state_len()),
            |s, b, block| {
                let ids = block_chains(b, self.len());
                let lanes: [usize; WIDTH] = std::array::from_fn(|k| k.min(block.len() - 1));
                let mut ends: Vec<End> = block.iter().map(|_| End::default()).collect();
                let mut alive = [0u64; WIDTH];
                for (k, (state, _)) in block.iter().enumerate() {
                    match non_finite("x", state.x().as_slice()) {
                        Some(error) => ends[k].failure = Some((error, 0)),
                        None => alive[k] = 1,
                    }
                }
                let parts: [_; WIDTH] = std::array::from_fn(|k| block[lanes[k]].0.parts());
                s.t = [Lanes::from_fn(|k| parts[k].0), Lanes::from_fn(|k| parts[k].1)];
                for (j, (x, carry)) in s.x.iter_mut().zip(&mut s.carry).enumerate() {
                    *x = Lanes::from_fn(|k| parts[k].2[j]);
                    *carry = Lanes::from_fn(|k| parts[k].3[j]);
                }
                let ran = alive;
                // Chain `k` of the block out of its lane into its state, and sampled.
                let take_sample =
                    |k: usize, s: &Scratch<C>, block: &mut [(&mut State<Dyn>, &mut T)]| -> bool {
                        let Some(sample) = sample else { return false };
                        let (state, observer) = &mut block[k];
                        let x = s.x.iter().zip(&s.carry).map(|(x, carry)| (x.0[k], carry.0[k]));
                        state.set_parts(s.t[0].0[k], s.t[1].0[k], x);
                        sample(observer, state.t(), state.x()).is_break()
                    };
                for (k, end) in ends.iter_mut().enumerate() {
                    if alive[k] != 0 && take_sample(k, s, block) {
                        end.stopped = true;
                        alive[k] = 0;
                    }
                }
                let mut done = 0u64;
                while done < plan.steps && alive != [0; WIDTH] {
                    // Up to the next sample: every `every` steps, and the last.
                    let chunk = plan.every.min(plan.steps - done);
                    for step in done..done + chunk {
                        let failed = self.rk4_step_simd::<C>(b, ids, plan.h, alive, s);
                        for (k, end) in ends.iter_mut().enumerate() {
                            if failed[k] != 0 {
                                end.failure =
                                    Some((Error::NonFiniteState { t: s.t[0].0[k], h: plan.h }, step));
                                alive[k] = 0;
                            }
                        }
                        if alive == [0; WIDTH] {
                            break;
                        }
                    }
                    done += chunk;
                    for (k, end) in ends.iter_mut().enumerate() {
                        if alive[k] != 0 {
                            (end.steps, end.samples) = (done, end.samples + u64::from(sample.is_some()));
                            if take_sample(k, s, block) {
                                end.stopped = done < plan.steps;
                                alive[k] = 0;
                            }
                        }
                    }
                }
                for (k, (state, _)) in block.iter_mut().enumerate() {
                    if ran[k] != 0 {
                        let x = s.x.iter().zip(&s.carry).map(|(x, carry)| (x.0[k], carry.0[k]));
                        state.set_parts(s.t[0].0[k], s.t[1].0[k], x);
                    }
                }
                ids.into_iter().zip(ends).collect()
            },
        )
    }

    simd_kernel! {
        fn rk4_step_simd, rk4_step_avx2 => rk4_step<const C: usize>(
            b: usize,
            chains: [usize; WIDTH],
            h: f64,
            alive: [u64; WIDTH],
            s: &mut Scratch<C>,
        ) -> [u64; WIDTH]
    }

    /// One step of `Projected<Rk4>` in lanes, applied only in the `alive` lanes: the
    /// increment ([`rk4_increment`](Self::rk4_increment)), then `t += h` and `x += increment`
    /// by compensated summation ([`State`]'s), the projection of every link
    /// ([`Constrained::project`]) and the compensation cleared, as `Projected` does. Returns
    /// the alive lanes whose increment was not finite (left as they were).
    #[inline(always)]
    fn rk4_step<const C: usize>(
        &self,
        b: usize,
        chains: [usize; WIDTH],
        h: f64,
        alive: [u64; WIDTH],
        s: &mut Scratch<C>,
    ) -> [u64; WIDTH] {
        self.rk4_increment::<C>(b, chains, s.t[0].0, h, s);
        let mut bad = [0u64; WIDTH];
        for y in &s.y {
            for (bad, y) in bad.iter_mut().zip(y.0) {
                *bad |= !y.is_finite() as u64;
            }
        }
        let keep: [u64; WIDTH] = std::array::from_fn(|k| alive[k] & !bad[k]);
        let [t, t_carry] = &mut s.t;
        let (new_t, new_carry) = kahan_add(*t, *t_carry, Lanes([h; WIDTH]));
        (*t, *t_carry) = (F64x4::select(keep, new_t, *t), F64x4::select(keep, new_carry, *t_carry));
        let zero = Lanes([0.0; WIDTH]);
        // k1 is spent: the next state goes there.
        let next = &mut s.k[0];
        for (((next, x), carry), y) in next.iter_mut().zip(&s.x).zip(&s.carry).zip(&s.y) {
            (*next, _) = kahan_add(*x, *carry, *y);
        }
        let (u, w) = next[..2 * C * self.links].split_at_mut(C * self.links);
        for (u, w) in u.chunks_exact_mut(C).zip(w.chunks_exact_mut(C)) {
            project_link(u, w);
        }
        for ((x, carry), next) in s.x.iter_mut().zip(&mut s.carry).zip(&s.k[0]) {
            *x = F64x4::select(keep, *next, *x);
            *carry = F64x4::select(keep, zero, *carry);
        }
        std::array::from_fn(|k| alive[k] & bad[k])
    }

    simd_kernel! {
        fn flow_simd, flow_avx2 => flow<const C: usize>(
            b: usize,
            chains: [usize; WIDTH],
            t: [f64; WIDTH],
            x: &[F64x4],
            solve: &mut Solve<C>,
            out: &mut [F64x4],
        )
    }

    /// The RK4 stages of [`Rk4`](crate::integrate::Rk4) in lanes, from `s.x` at times `t`,
    /// leaving the increment `h (k1 + 2 k2 + 2 k3 + k4) / 6` in `s.y`.
    #[inline(always)]
    fn rk4_increment<const C: usize>(
        &self,
        b: usize,
        chains: [usize; WIDTH],
        t: [f64; WIDTH],
        h: f64,
        s: &mut Scratch<C>,
    ) {
        let half = 0.5 * h;
        let (x, y, rows) = (&s.x, &mut s.y, &mut s.solve);
        let [k1, k2, k3, k4] = &mut s.k;
        let (half_lanes, h_lanes) = (Lanes([half; WIDTH]), Lanes([h; WIDTH]));
        let axpy = |y: &mut [F64x4], a: F64x4, k: &[F64x4]| {
            for ((y, x), k) in y.iter_mut().zip(x).zip(k) {
                *y = a * *k + *x;
            }
        };
        let at = |dt: f64| -> [f64; WIDTH] { std::array::from_fn(|k| t[k] + dt) };
        self.flow::<C>(b, chains, t, x, rows, k1);
        axpy(y, half_lanes, k1);
        self.flow::<C>(b, chains, at(half), y, rows, k2);
        axpy(y, half_lanes, k2);
        self.flow::<C>(b, chains, at(half), y, rows, k3);
        axpy(y, h_lanes, k3);
        self.flow::<C>(b, chains, at(h), y, rows, k4);
        let (sixth, two) = (Lanes([h / 6.0; WIDTH]), Lanes([2.0; WIDTH]));
        for (j, y) in y.iter_mut().enumerate() {
            *y = sixth * (k1[j] + two * (k2[j] + k3[j]) + k4[j]);
        }
    }

    /// `out = (w, ü(t, x))` for the block's chains in lanes: [`Directions`]' right-hand side,
    /// one tension solve, with each chain's pivot acceleration at its own time.
    #[inline(always)]
    fn flow<const C: usize>(
        &self,
        b: usize,
        chains: [usize; WIDTH],
        t: [f64; WIDTH],
        x: &[F64x4],
        solve: &mut Solve<C>,
        out: &mut [F64x4],
    ) {
        let half = C * self.links;
        let block = &self.blocks[b];
        let zero = Lanes([0.0; WIDTH]);
        let pivots: [_; WIDTH] = std::array::from_fn(|k| self.models[chains[k]].drive().acceleration(t[k]));
        let pivot: [F64x4; C] = std::array::from_fn(|c| Lanes::from_fn(|k| pivots[k][c]));
        let mut gravity = [zero; C];
        gravity[C - 1] = block.down;
        let (directions, rates) = (&x[..half], &x[half..2 * half]);
        let (velocity, acceleration) = out.split_at_mut(half);
        velocity.copy_from_slice(rates);
        let (acceleration, ledger) = acceleration.split_at_mut(half);
        // The loads in a pass of their own: built inside the solve, the builder is not
        // inlined.
        let drag = block.rods.drag();
        for (i, load) in solve.loads.iter_mut().enumerate() {
            let at = |v: &[F64x4]| -> [F64x4; C] { std::array::from_fn(|c| v[i * C + c]) };
            *load = rate_load(at(directions), at(rates), drag[i]);
        }
        let loads = &solve.loads;
        let load = |i: usize| loads[i];
        block.rods.solve(gravity, pivot, &mut solve.rows, load, |i, a, _, _| {
            acceleration[i * C..(i + 1) * C].copy_from_slice(&a);
        });
        if self.accounted {
            // The ledger's rates, as `Accounted`'s right-hand side gives them.
            let velocities: [_; WIDTH] =
                std::array::from_fn(|k| self.models[chains[k]].drive().velocity(t[k]));
            let velocity: [F64x4; C] = std::array::from_fn(|c| Lanes::from_fn(|k| velocities[k][c]));
            let chain = (&block.tails[..], &block.lengths[..], &block.damping[..], -block.down);
            let (drive, damping) = direction_powers(chain, velocity, pivot, rates, acceleration);
            ledger[..LEDGER_LEN].copy_from_slice(&[drive, zero, damping]);
        }
    }
}
