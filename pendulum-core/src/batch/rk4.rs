//! Steps and runs of projected RK4 for a batch of chains in directions, in lanes: the
//! states stay in their lanes from a run's first step to its last and go out only to be
//! sampled.

use std::ops::ControlFlow;

use nalgebra::{DVector, DefaultAllocator, DimName, Dyn, allocator::Allocator};

use super::directions::{Block, Scratch};
use super::lane_states::{into_lanes, nan_unless_finite, out_of_lanes};
use super::{
    Blocks, Failure, WIDTH, WIDTH_AVX512, block_chains, for_blocks_of, non_finite, one_of, simd_kernel,
};
use crate::drive::Drive;
use crate::error::{Error, Result};
use crate::integrate::check_step_size;
use crate::integrate::{State, kahan_add, rk4_weighted};
use crate::lanes::{Lane, Lanes, Masked, one_row_at_a_time};
use crate::models::directions::project_link;

use super::DirectionsBatch;

/// The steps of a run in lanes: `steps` of size `h` (s), sampled every `every`.
#[derive(Debug, Clone, Copy)]
pub(super) struct Plan {
    pub h: f64,
    pub steps: u64,
    pub every: u64,
}

/// How a chain's run in lanes ended: steps taken and samples after the first before it
/// stopped or finished, whether a sample stopped it, and a failure with the step that
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

impl<S: DimName, Dr: Drive<S> + Sync> DirectionsBatch<S, Dr>
where
    DefaultAllocator: Allocator<S>,
{
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
        check_step_size(h)?;
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
        super::check_states(states, self.len(), self.state_len())
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
        match &self.blocks {
            Blocks::Four(blocks) => {
                let step = |block: &Block<WIDTH>, ids, alive, s: &mut Scratch<C, WIDTH>| {
                    self.rk4_step_simd::<C, WIDTH>(block, ids, plan.h, alive, s)
                };
                self.rk4_blocks(blocks, states, observers, (plan, sample), step)
            }
            #[cfg(target_arch = "x86_64")]
            Blocks::Eight(blocks) => {
                let step = |block: &Block<WIDTH_AVX512>, ids, alive, s: &mut Scratch<C, WIDTH_AVX512>| {
                    // SAFETY: eight-lane blocks exist only where the CPU has AVX-512.
                    unsafe { self.rk4_step_avx512::<C, WIDTH_AVX512>(block, ids, plan.h, alive, s) }
                };
                self.rk4_blocks(blocks, states, observers, (plan, sample), step)
            }
            #[cfg(not(target_arch = "x86_64"))]
            Blocks::Never(_) => unreachable!("eight lanes only with AVX-512"),
        }
    }

    /// [`rk4`](Self::rk4) in blocks of `W` chains with constants `blocks`, `one_step`
    /// making one step of a block's alive lanes.
    fn rk4_blocks<const C: usize, const W: usize, T: Send, F>(
        &self,
        blocks: &[Block<W>],
        states: &mut [State<Dyn>],
        observers: &mut [T],
        (plan, sample): (Plan, Option<&F>),
        one_step: impl Fn(&Block<W>, [usize; W], [u64; W], &mut Scratch<C, W>) -> [u64; W] + Sync + Send,
    ) -> Vec<(usize, End)>
    where
        F: Fn(&mut T, f64, &DVector<f64>) -> ControlFlow<()> + Sync,
    {
        let (n, m) = (self.links(), self.state_len());
        let mut chains: Vec<(&mut State<Dyn>, &mut T)> =
            states.iter_mut().zip(observers.iter_mut()).collect();
        let solves = n.saturating_mul(4).saturating_mul(plan.steps.min(usize::MAX as u64) as usize);
        // Tasks of whole runs: a block's states stay in lanes from the first step to the
        // last, and go out only to be sampled.
        for_blocks_of::<W, _, _, _>(
            &mut chains,
            1,
            solves,
            || self.rooms.take(|| Scratch::<C, W>::new(n, self.state_len())),
            |room, b, block| {
                let s = &mut **room;
                let ids = block_chains::<W>(b, self.len());
                let lanes: [usize; W] = std::array::from_fn(|k| k.min(block.len() - 1));
                let mut ends: Vec<End> = block.iter().map(|_| End::default()).collect();
                let mut alive = [0u64; W];
                let carry = (&mut s.carry[..], s.carry_zero);
                let arrival = into_lanes(lanes.map(|k| &*block[k].0), m, &mut s.t, &mut s.x, carry);
                s.carry_zero = arrival.uncompensated;
                // Each step clears a lane's compensation or leaves it (a failed lane): those
                // of states that arrive without one stay zero, and the states' own stand.
                let carried = !arrival.uncompensated;
                for ((k, (state, _)), suspect) in block.iter().enumerate().zip(arrival.suspect) {
                    // The entry named only where the lanes found one.
                    match (suspect != 0).then(|| non_finite("x", state.x().as_slice())).flatten() {
                        Some(error) => ends[k].failure = Some((error, 0)),
                        None => alive[k] = 1,
                    }
                }
                let ran = alive;
                // The chains of the block flagged in `which` out of their lanes into their
                // states, by one transpose of the block (lane by lane, with a stride of a
                // row, this was a tenth of an atlas), then each sampled: the lanes whose
                // observer stops the run.
                let take_samples =
                    |which: [u64; W], s: &Scratch<C, W>, block: &mut [(&mut State<Dyn>, &mut T)]| {
                        let mut stopped = [false; W];
                        let Some(sample) = sample else { return stopped };
                        let states = block.iter_mut().map(|(state, _)| &mut **state);
                        out_of_lanes(states, which, m, (&s.t, &s.x, carried.then_some(&s.carry[..])));
                        for ((stopped, (state, observer)), _) in
                            stopped.iter_mut().zip(block.iter_mut()).zip(which).filter(|(_, k)| *k != 0)
                        {
                            *stopped = sample(observer, state.t(), state.x()).is_break();
                        }
                        stopped
                    };
                let stopped = take_samples(alive, s, block);
                for ((end, alive), stopped) in ends.iter_mut().zip(&mut alive).zip(stopped) {
                    if stopped {
                        end.stopped = true;
                        *alive = 0;
                    }
                }
                let mut done = 0u64;
                while done < plan.steps && alive != [0; W] {
                    // Up to the next sample: every `every` steps, and the last.
                    let chunk = plan.every.min(plan.steps - done);
                    for step in done..done + chunk {
                        let failed = one_step(one_of(blocks, b), ids, alive, s);
                        for (k, end) in ends.iter_mut().enumerate() {
                            if failed[k] != 0 {
                                end.failure =
                                    Some((Error::NonFiniteState { t: s.t[0].0[k], h: plan.h }, step));
                                alive[k] = 0;
                            }
                        }
                        if alive == [0; W] {
                            break;
                        }
                    }
                    done += chunk;
                    for (end, _) in ends.iter_mut().zip(alive).filter(|(_, alive)| *alive != 0) {
                        (end.steps, end.samples) = (done, end.samples + u64::from(sample.is_some()));
                    }
                    let stopped = take_samples(alive, s, block);
                    for ((end, alive), stopped) in ends.iter_mut().zip(&mut alive).zip(stopped) {
                        if stopped {
                            end.stopped = done < plan.steps;
                            *alive = 0;
                        }
                    }
                }
                let states = block.iter_mut().map(|(state, _)| &mut **state);
                out_of_lanes(states, ran, m, (&s.t, &s.x, carried.then_some(&s.carry[..])));
                ids.into_iter().zip(ends).collect()
            },
        )
    }

    simd_kernel! {
        /// One step of `Projected<Rk4>` in lanes, applied only in the `alive` lanes: the
        /// stages ([`rk4_stages`](Self::rk4_stages)), then `t += h` and the new state
        /// ([`rk4_advance`](Self::rk4_advance)) and the compensation cleared, as `Projected`
        /// does. Returns the alive lanes whose increment was not finite (left as they were).
        fn rk4_step<const C: usize, const W: usize>(
            &self,
            block: &Block<W>,
            chains: [usize; W],
            h: f64,
            alive: [u64; W],
            s: &mut Scratch<C, W>,
        ) -> [u64; W] {
            self.rk4_stages::<C, W>(block, chains, s.t[0].0, h, s);
            let bad = self.rk4_advance::<C, W>(h, s);
            let keep: [u64; W] = std::array::from_fn(|k| alive[k] & !bad[k]);
            let [t, t_carry] = &mut s.t;
            let (new_t, new_carry) = kahan_add(*t, *t_carry, Lanes([h; W]));
            (*t, *t_carry) = (Lanes::select(keep, new_t, *t), Lanes::select(keep, new_carry, *t_carry));
            let zero = Lanes([0.0; W]);
            if keep.iter().all(|&k| k != 0) {
                // Every lane steps (the common case): the next state, in k1, becomes the
                // state, no copy (k1 is overwritten by the next step either way).
                std::mem::swap(&mut s.x, &mut s.k[0]);
                if !s.carry_zero {
                    s.carry.fill(zero);
                    s.carry_zero = true;
                }
            } else {
                for ((x, carry), next) in s.x.iter_mut().zip(&mut s.carry).zip(&s.k[0]) {
                    *x = Lanes::select(keep, *next, *x);
                    *carry = Lanes::select(keep, zero, *carry);
                    one_row_at_a_time();
                }
            }
            std::array::from_fn(|k| alive[k] & bad[k])
        }
        dispatch fn rk4_step_simd, rk4_step_avx2, avx512 rk4_step_avx512
    }
    /// The RK4 stages of [`Rk4`](crate::integrate::Rk4) in lanes, from `s.x` at times `t`,
    /// into `s.k`.
    #[inline(always)]
    fn rk4_stages<const C: usize, const W: usize>(
        &self,
        block: &Block<W>,
        chains: [usize; W],
        t: [f64; W],
        h: f64,
        s: &mut Scratch<C, W>,
    ) {
        let half = 0.5 * h;
        let (x, y, rows) = (&s.x, &mut s.y, &mut s.solve);
        let [k1, k2, k3, k4] = &mut s.k;
        let (half_lanes, h_lanes) = (Lanes([half; W]), Lanes([h; W]));
        let at = |dt: f64| -> [f64; W] { std::array::from_fn(|k| t[k] + dt) };
        // `Accounted`'s right-hand side when the states carry the ledger (which needs the
        // pivots' velocities too).
        let accounted = self.is_accounted();
        let (pivot, velocity) = self.pivot_motion::<C, W>(chains, t, accounted);
        self.flow::<C, W>(block, pivot, x, rows, k1);
        if let Some(velocity) = velocity {
            self.ledger_rates::<C, W>(block, x, (velocity, pivot), k1);
        }
        // k_{j+1} = f(t + c h, y) at y = x + a k_j, y formed in the stage's pass; the two
        // stages at t + h/2 ask the drives once.
        let middle = self.pivot_motion::<C, W>(chains, at(half), accounted);
        let end = self.pivot_motion::<C, W>(chains, at(h), accounted);
        let stages = [(middle, half_lanes), (middle, half_lanes), (end, h_lanes)];
        let mut ks = [&mut **k1, &mut **k2, &mut **k3, &mut **k4];
        for (j, ((pivot, velocity), a)) in stages.into_iter().enumerate() {
            let [.., before, next] = &mut ks[..j + 2] else { unreachable!("two stages") };
            self.stage::<C, W>(block, pivot, (x, a, before), y, rows, next);
            if let Some(velocity) = velocity {
                self.ledger_rates::<C, W>(block, y, (velocity, pivot), next);
            }
        }
    }

    /// The end of a step of `Projected<Rk4>`, row by row in one pass: the increment
    /// `y = (h/6)·(k1 + 2 (k2 + k3) + k4)` ([`rk4_weighted`]), the sum `x + y` with the
    /// state's compensation ([`State`]'s; the compensation it leaves is dropped, as
    /// `Projected` clears it) and each link projected as soon as its rows are summed
    /// ([`project_link`]), into `k1`. Returns the lanes whose increment is not finite.
    /// (In passes of their own, the increment, its finiteness, the sum and the projection
    /// went over the block's rows five times.)
    #[inline(always)]
    fn rk4_advance<const C: usize, const W: usize>(&self, h: f64, s: &mut Scratch<C, W>) -> [u64; W] {
        let half = C * self.links();
        let sixth = Lanes([h / 6.0; W]);
        let zero = Lanes([0.0; W]);
        let [k1, k2, k3, k4] = &mut s.k;
        let (x, carry) = (&s.x[..], &s.carry[..]);
        let (k1_motion, k1_rest) = k1.split_at_mut(2 * half);
        let (k1u, k1w) = k1_motion.split_at_mut(half);
        let links = (k1u.chunks_exact_mut(C).zip(k1w.chunks_exact_mut(C)))
            .zip(link_rows::<_, C>(k2, half))
            .zip(link_rows::<_, C>(k3, half).zip(link_rows::<_, C>(k4, half)))
            .zip(link_rows::<_, C>(x, half).zip(link_rows::<_, C>(carry, half)));
        let mut sums = [zero; C];
        for ((((k1u, k1w), (k2u, k2w)), ((k3u, k3w), (k4u, k4w))), ((xu, xw), (cu, cw))) in links {
            let (mut u, mut w) = ([zero; C], [zero; C]);
            for c in 0..C {
                let y = rk4_weighted(sixth, [k1u[c], k2u[c], k3u[c], k4u[c]]);
                (u[c], _) = kahan_add(xu[c], cu[c], y);
                let z = rk4_weighted(sixth, [k1w[c], k2w[c], k3w[c], k4w[c]]);
                (w[c], _) = kahan_add(xw[c], cw[c], z);
                sums[c] += nan_unless_finite(y) + nan_unless_finite(z);
            }
            project_link(&mut u, &mut w);
            k1u.copy_from_slice(&u);
            k1w.copy_from_slice(&w);
            one_row_at_a_time();
        }
        let rest = (k2[2 * half..].iter().zip(&k3[2 * half..]))
            .zip(k4[2 * half..].iter().zip(&x[2 * half..]))
            .zip(&carry[2 * half..]);
        for (k1, (((k2, k3), (k4, x)), carry)) in k1_rest.iter_mut().zip(rest) {
            let y = rk4_weighted(sixth, [*k1, *k2, *k3, *k4]);
            (*k1, _) = kahan_add(*x, *carry, y);
            sums[0] += nan_unless_finite(y);
            one_row_at_a_time();
        }
        let mut total = zero;
        for sum in sums {
            total += sum;
        }
        total.not_finite()
    }
}

/// A state `[u | w | …]` (`half` = `C·n` rows of directions `u`, then as many of rates `w`)
/// link by link: each link's `C` rows of `u` beside its `C` rows of `w`.
#[inline(always)]
fn link_rows<V, const C: usize>(v: &[V], half: usize) -> LinkRows<'_, V> {
    v[..half].chunks_exact(C).zip(v[half..2 * half].chunks_exact(C))
}

/// [`link_rows`]' iterator.
type LinkRows<'a, V> = std::iter::Zip<std::slice::ChunksExact<'a, V>, std::slice::ChunksExact<'a, V>>;
