//! Runs of the implicit rod midpoint step ([`RodMidpoint`]) for a batch of chains in
//! directions, the Newton iterations in SIMD lanes: four or eight chains iterate side by
//! side, one block-tridiagonal solve an iteration for all of them, each lane doing what its
//! chain alone does (`rod_midpoint::iteration`, written once for both). A lane whose
//! iteration has converged keeps its numbers while the others go on. A chain whose step the
//! lanes cannot take as a whole (a link turning too far, an iteration that fails, a state
//! not finite) takes that step by the single chain's own code, which halves it, and gets
//! its numbers bit for bit either way. The blocks go over the cores.

use nalgebra::{DefaultAllocator, DimName, Dyn, OVector, allocator::Allocator};

use super::directions::{Block, Solve, gravity};
use super::lane_states::{into_lanes, non_finite_lanes, out_of_lanes};
use super::{
    Blocks, DirectionsBatch, Failure, WIDTH, WIDTH_AVX512, block_chains, for_blocks_of, one_of, simd_kernel,
};
use crate::chain::Chain;
use crate::drive::Drive;
use crate::energy::Accounted;
use crate::error::Result;
use crate::integrate::check_step_size;
use crate::integrate::{Integrator, State, kahan_add};
use crate::lanes::{Aligned, Lane, Lanes, Masked};
use crate::models::Directions;
use crate::rod_midpoint::iteration::{self, Chains, Limits, Work};
use crate::rod_midpoint::{RodMidpoint, increment, turns_too_far};

/// A task's room for a block of `W` chains in `C` dimensions: their masses, states (time,
/// state and their compensations), rod tensions, pivot ends and accelerations in lanes, the
/// tension solve and the iteration's buffers and new motion.
struct Room<const C: usize, const W: usize> {
    solve: Solve<C, Lanes<W>>,
    work: Work<C, Lanes<W>>,
    masses: Aligned<Lanes<W>>,
    t: [Lanes<W>; 2],
    x: Aligned<Lanes<W>>,
    carry: Aligned<Lanes<W>>,
    out: Aligned<Lanes<W>>,
    tensions: Aligned<Lanes<W>>,
    ends: [[Lanes<W>; C]; 4],
    pivot: [Lanes<W>; C],
}

impl<const C: usize, const W: usize> Room<C, W> {
    fn new(n: usize, state_len: usize) -> Self {
        let zero = Lanes([0.0; W]);
        let zeros = |len| Aligned::filled(zero, len);
        Self {
            solve: Solve::new(n),
            work: Work::default(),
            masses: zeros(n),
            t: [zero; 2],
            x: zeros(state_len),
            carry: zeros(state_len),
            out: zeros(2 * C * n),
            tensions: zeros(n),
            ends: [[zero; C]; 4],
            pivot: [zero; C],
        }
    }

    /// The chains' masses into their lanes.
    fn set_masses(&mut self, chains: [&Chain<Dyn>; W]) {
        for (k, chain) in chains.iter().enumerate() {
            for (lane, &m) in self.masses.iter_mut().zip(chain.masses().iter()) {
                lane.0[k] = m;
            }
        }
    }

    /// Lane `k`'s state out of the lanes into `state`.
    fn lane_out(&self, k: usize, state: &mut State<Dyn>) {
        let x = self.x.iter().zip(self.carry.iter()).map(|(x, carry)| (x.0[k], carry.0[k]));
        state.set_parts(self.t[0].0[k], self.t[1].0[k], x);
    }

    /// `state` into lane `k`.
    fn lane_in(&mut self, k: usize, state: &State<Dyn>) {
        let (t, t_carry, x, carry) = state.parts();
        (self.t[0].0[k], self.t[1].0[k]) = (t, t_carry);
        for ((lane, carry_lane), (&x, &carry)) in
            self.x.iter_mut().zip(self.carry.iter_mut()).zip(x.iter().zip(carry))
        {
            (lane.0[k], carry_lane.0[k]) = (x, carry);
        }
    }
}

/// One chain's step taken by its own integrator, with the ledger when `accounted`.
pub(super) fn single_step<S: DimName, Dr: Drive<S> + Clone>(
    model: &Directions<S, Dr>,
    accounted: bool,
    state: &mut State<Dyn>,
    h: f64,
) -> Result<()>
where
    DefaultAllocator: Allocator<S>,
{
    let mut integrator = RodMidpoint::new();
    if accounted {
        <RodMidpoint as Integrator<Accounted<Directions<S, Dr>>>>::step(
            &mut integrator,
            &Accounted::of(model.clone()),
            state,
            h,
        )
    } else {
        <RodMidpoint as Integrator<Directions<S, Dr>>>::step(&mut integrator, model, state, h)
    }
}

impl<S: DimName, Dr: Drive<S> + Clone + Sync> DirectionsBatch<S, Dr>
where
    DefaultAllocator: Allocator<S>,
{
    /// `steps` steps of the implicit rod midpoint of size `h` (s) for every chain, each from
    /// its own state and time (with the energy ledger when the batch is
    /// [`accounted`](Self::accounted)): exactly what `steps` calls of
    /// `RodMidpoint::new().step` give for each chain alone, bit for bit. The Newton
    /// iterations run in SIMD lanes (four or eight chains, as
    /// [`accelerations`](Self::accelerations)); a step a lane cannot take whole (a link
    /// turning by more than a radian, an iteration that does not converge) is taken, halved,
    /// by the chain's own integrator. The blocks go over the current rayon pool.
    ///
    /// Returns the chains that failed, in order, each left at the start of the step that
    /// failed, with that step's error; the others go on. Errors:
    /// [`Error::InvalidStepSize`](crate::Error::InvalidStepSize) for a zero or non-finite `h`,
    /// [`Error::LengthMismatch`](crate::Error::LengthMismatch)
    /// for a number of states other than `B` or a state of the wrong length.
    pub fn integrate_rod_midpoint(
        &self,
        states: &mut [State<Dyn>],
        h: f64,
        steps: usize,
    ) -> Result<Vec<Failure>> {
        check_step_size(h)?;
        self.check_states(states)?;
        Ok(match S::DIM {
            2 => self.midpoint_in::<2>(states, h, steps),
            _ => self.midpoint_in::<3>(states, h, steps),
        })
    }

    fn midpoint_in<const C: usize>(&self, states: &mut [State<Dyn>], h: f64, steps: usize) -> Vec<Failure> {
        let limits = RodMidpoint::new().limits();
        match &self.blocks {
            Blocks::Four(blocks) => self.midpoint_blocks::<C, WIDTH>(states, h, steps, |b, room, alive| {
                self.midpoint_lanes_simd::<C, WIDTH>(one_of(blocks, b), room, h, alive, &limits)
            }),
            #[cfg(target_arch = "x86_64")]
            Blocks::Eight(blocks) => {
                self.midpoint_blocks::<C, WIDTH_AVX512>(states, h, steps, |b, room, alive| {
                    // SAFETY: eight-lane blocks exist only where the CPU has AVX-512.
                    unsafe {
                        self.midpoint_lanes_avx512::<C, WIDTH_AVX512>(
                            one_of(blocks, b),
                            room,
                            h,
                            alive,
                            &limits,
                        )
                    }
                })
            }
            #[cfg(not(target_arch = "x86_64"))]
            Blocks::Never(_) => unreachable!("eight lanes only with AVX-512"),
        }
    }

    /// The steps in blocks of `W` chains, the states in lanes from the first step to the
    /// last; `step(b, room, alive)` steps block `b`'s lanes flagged in `alive` and returns
    /// those it stepped. The others take the step by their own integrators. The blocks go
    /// over the current rayon pool.
    fn midpoint_blocks<const C: usize, const W: usize>(
        &self,
        states: &mut [State<Dyn>],
        h: f64,
        steps: usize,
        step: impl Fn(usize, &mut Room<C, W>, [u64; W]) -> [u64; W] + Sync + Send,
    ) -> Vec<Failure> {
        let (n, m) = (self.links(), self.state_len());
        // A step is a tension solve and a few iterations, each a few solves' work.
        let solves = n.saturating_mul(8).saturating_mul(steps);
        let room = || self.rooms.take(|| Room::<C, W>::new(n, m));
        for_blocks_of::<W, _, _, _>(states, 1, solves, room, |room, b, block| {
            let room = &mut **room;
            let chains = block_chains::<W>(b, self.len());
            room.set_masses(chains.map(|k| self.model(k).chain()));
            let lanes: [usize; W] = std::array::from_fn(|k| k.min(block.len() - 1));
            // Its flags of non-finite states go unused: such a lane does not step in lanes,
            // and the chain alone reports its error (`single_step`).
            into_lanes(lanes.map(|k| &block[k]), m, &mut room.t, &mut room.x, (&mut room.carry, false));
            let mut alive = [0u64; W];
            alive[..block.len()].fill(1);
            let mut failures = Vec::new();
            for _ in 0..steps {
                if alive == [0; W] {
                    break;
                }
                let t = room.t[0].0;
                let drive = |k: usize| self.model(chains[k]).drive();
                let ends: [[OVector<f64, S>; 4]; W] = std::array::from_fn(|k| {
                    // One evaluation at each end (equal bit for bit to position and velocity
                    // apart).
                    let ((p0, v0), (p1, v1)) =
                        (drive(k).position_and_velocity(t[k]), drive(k).position_and_velocity(t[k] + h));
                    [p0, p1, v0, v1]
                });
                for (e, lanes) in room.ends.iter_mut().enumerate() {
                    for (c, lane) in lanes.iter_mut().enumerate() {
                        *lane = Lanes(std::array::from_fn(|k| ends[k][e][c]));
                    }
                }
                room.pivot = self.pivot_lanes::<C, W, _>(chains, t, Dr::acceleration, Lanes);
                let stepped = step(b, room, alive);
                for (k, state) in block.iter_mut().enumerate() {
                    if alive[k] == 0 || stepped[k] != 0 {
                        continue;
                    }
                    room.lane_out(k, state);
                    match single_step(self.model(chains[k]), self.is_accounted(), state, h) {
                        Ok(()) => room.lane_in(k, state),
                        Err(error) => {
                            failures.push(Failure { chain: chains[k], error });
                            alive[k] = 0;
                        }
                    }
                }
            }
            out_of_lanes(block.iter_mut(), alive, m, (&room.t, &room.x, Some(&room.carry)));
            failures
        })
    }

    simd_kernel! {
        /// One step of size `h` (s) for the lanes flagged in `alive` of `room` (chains with
        /// the constants `block`) that can take it whole: a finite state in which no link
        /// would turn too far. The rod tensions at its start (the single chain's tension
        /// solve), the Newton iteration (`rod_midpoint::iteration::iterate`), and the state
        /// moved to its end (`RodMidpoint`'s increment, compensated) in each lane whose
        /// iteration converged. Returns those lanes.
        fn midpoint_lanes<const C: usize, const W: usize>(
            &self,
            block: &Block<W>,
            room: &mut Room<C, W>,
            h: f64,
            alive: [u64; W],
            limits: &Limits,
        ) -> [u64; W] {
            let half = C * self.links();
            let Room { solve, work, masses, t, x, carry, out, tensions, ends, pivot } = room;
            let (lengths, damping) = block.lengths_and_damping();
            let motion = &x[..2 * half];
            let unfit = Lanes::or(non_finite_lanes(motion), turns_too_far(&motion[half..], C, h));
            let go = Lanes::and_not(alive, unfit);
            if go == [0; W] {
                return go;
            }
            solve.tensions(block.rods(), gravity(block.down()), *pivot, motion, tensions);
            let chains = Chains { masses, lengths, damping, down: block.down() };
            let it = iteration::iterate::<C, Lanes<W>, false>(work, &chains, tensions, *ends, (motion, h, out), go, limits);
            let stepped = Lanes::and_not(go, it.failed);
            let work = self.is_accounted().then_some((it.drive, it.damped));
            let (time, time_carry) = kahan_add(t[0], t[1], Lanes([h; W]));
            t[0] = Lanes::select(stepped, time, t[0]);
            t[1] = Lanes::select(stepped, time_carry, t[1]);
            for (j, (x, carry)) in x.iter_mut().zip(carry.iter_mut()).enumerate() {
                let (sum, lost) = kahan_add(*x, *carry, increment(j, *x, &out[..], work));
                *x = Lanes::select(stepped, sum, *x);
                *carry = Lanes::select(stepped, lost, *carry);
            }
            stepped
        }
        dispatch fn midpoint_lanes_simd, midpoint_lanes_avx2, avx512 midpoint_lanes_avx512
    }
}
