//! Runs of the implicit rod midpoint step ([`RodMidpoint`]) in single precision for a
//! batch of chains in directions: eight chains per AVX2 register, the states in lanes from
//! a run's first step to its last, the Newton iteration of `rod_midpoint::iteration` (the
//! one the single chain and the `f64` lanes run) in `f32` lanes, stopped at a tolerance
//! `f32` can reach. A step the lanes cannot take whole (a link turning by more than a
//! radian, an iteration that does not converge) is taken by the chain's own `f64`
//! integrator, which halves it, from its state widened to `f64`, and rounded back. Not bit
//! for bit anything: its error against the `f64` run is measured in `docs/ensembles.md`.

use nalgebra::{DVector, DefaultAllocator, DimName, OVector, allocator::Allocator};

use super::directions::{Solve, gravity};
use super::lane_states::finite_rows;
use super::rod_midpoint::single_step;
use super::{
    DirectionsBatch, F32x8, Failure, WIDTH_F32, block_chains, check_len, for_blocks_of, gather, one_of,
    scatter, simd_kernel,
};
use crate::batch::check_t0;
use crate::chain::Chain;
use crate::drive::Drive;
use crate::error::{Error, Result};
use crate::integrate::{State, check_step_size};
use crate::lanes::{Aligned, Lane, Lanes32, Masked, one_row_at_a_time};
use crate::rod_midpoint::iteration::{self, Chains, Ends, Limits, Work};
use crate::rod_midpoint::{RodMidpoint, turns_too_far};
use crate::rods::Rods;

/// The Newton iteration's stopping rule in `f32`: `|δx| ≤ 2⁻²⁶ ≈ 1.5e-8` of the chain's
/// reach per position. The iteration corrects the masses' displacements over the step,
/// far shorter than the reach, and their round-off lies below this. (Set to `2⁻¹⁶`, the
/// test `single_precision_rod_midpoint_runs_follow_the_f64_ones_and_fail_by_chain` printed
/// 1.1e-4 instead of 3.9e-5 at n = 20 and 50 ms.)
const TOLERANCE_F32: f64 = 1.0 / (1u64 << 26) as f64;

/// A block's run: the tension solve, the iteration's buffers, the chains' masses (kg),
/// lengths (m) and rod damping (N·m·s) per link, the states `x` and the new motion `out`
/// (`2·C·n` each), and the rod tensions (N), all in `f32` lanes.
struct Room32<const C: usize> {
    solve: Solve<C, F32x8>,
    work: Work<C, F32x8>,
    masses: Aligned<F32x8>,
    lengths: Aligned<F32x8>,
    damping: Aligned<F32x8>,
    x: Aligned<F32x8>,
    out: Aligned<F32x8>,
    tensions: Aligned<F32x8>,
}

impl<const C: usize> Room32<C> {
    fn new(n: usize) -> Self {
        let zeros = |len| Aligned::filled(F32x8::splat(0.0), len);
        Self {
            solve: Solve::new(n),
            work: Work::default(),
            masses: zeros(n),
            lengths: zeros(n),
            damping: zeros(n),
            x: zeros(2 * C * n),
            out: zeros(2 * C * n),
            tensions: zeros(n),
        }
    }

    /// The chains' masses, lengths and damping into their lanes, rounded to `f32`.
    fn set_chains(&mut self, chains: [&Chain<nalgebra::Dyn>; WIDTH_F32]) {
        let per_link = |out: &mut Aligned<F32x8>, of: fn(&Chain<nalgebra::Dyn>) -> &[f64]| {
            for (i, lane) in out.iter_mut().enumerate() {
                *lane = Lanes32::rounded(chains.map(|c| of(c)[i]));
            }
        };
        per_link(&mut self.masses, |c| c.masses().as_slice());
        per_link(&mut self.lengths, |c| c.lengths().as_slice());
        per_link(&mut self.damping, |c| c.damping().as_slice());
    }

    /// Lane `k`'s state at time `t` (s), widened to `f64`.
    fn lane_out(&self, k: usize, t: f64) -> State<nalgebra::Dyn> {
        State::new(t, DVector::from_iterator(self.x.len(), self.x.iter().map(|v| f64::from(v.0[k]))))
    }

    /// `state` rounded into lane `k`; whether every number stayed finite (else the lane
    /// is left as it was).
    fn lane_in(&mut self, k: usize, state: &State<nalgebra::Dyn>) -> bool {
        let rounded: Vec<f32> = state.x().iter().map(|&v| v as f32).collect();
        if !rounded.iter().all(|v| v.is_finite()) {
            return false;
        }
        for (lane, v) in self.x.iter_mut().zip(rounded) {
            lane.0[k] = v;
        }
        true
    }
}

impl<S: DimName, Dr: Drive<S> + Clone + Sync> DirectionsBatch<S, Dr>
where
    DefaultAllocator: Allocator<S>,
{
    /// `steps` steps of the implicit rod midpoint ([`RodMidpoint`]) of size `h` (s) for
    /// every chain in single precision, from the time `t0` (s; step `j` at `t0 + j h`):
    /// the states as `B` rows of `(u, w)` (`2·S·n` numbers of `f32`, numpy's
    /// `(B, 2·S·n)`), overwritten. Eight chains per AVX2 register, each chain's constants
    /// rounded to `f32`, its pivot's positions and velocities at the step's ends and its
    /// acceleration at the start computed in `f64` and then rounded; the Newton iteration
    /// stops at `1.5e-8` of the chain's reach per position. A step the lanes cannot take
    /// whole (a link turning by more than a radian, an iteration that does not converge)
    /// is taken by the chain's own `f64` [`RodMidpoint`], which halves it, and rounded
    /// back. The motion only: an [`accounted`](Self::accounted) batch's ledger is not kept.
    /// Not bit for bit anything: its error against
    /// [`integrate_rod_midpoint`](Self::integrate_rod_midpoint) is measured in
    /// `docs/ensembles.md`. Each step adds its rounding, so the error grows as the steps
    /// shrink: whirls of 8 to 100 links ended about 1e-2 (relative) from the `f64` run
    /// after 2000 steps of 1 ms, 5e-5 after 80 steps of 50 ms. This is a step for long
    /// steps, where its own error is far larger than that.
    ///
    /// Returns the chains that failed, in order: a non-finite state (by its entry, before
    /// any step), a step the chain's own integrator could not take either (its error), or
    /// one whose result leaves `f32`'s range ([`Error::SinglePrecisionOverflow`]); a failed
    /// chain is left at the start of the step that failed and the others go on. Errors:
    /// [`Error::LengthMismatch`] when `x` does not hold `B` rows of `2·S·n`,
    /// [`Error::InvalidStepSize`] for a non-finite or zero `h`, [`Error::NonFinite`] for
    /// a non-finite `t0`.
    pub fn integrate_rod_midpoint_f32(
        &self,
        x: &mut [f32],
        t0: f64,
        h: f64,
        steps: usize,
    ) -> Result<Vec<Failure>> {
        check_step_size(h)?;
        check_t0(t0)?;
        check_len("x", x, self.len(), 2 * S::DIM * self.links())?;
        Ok(match S::DIM {
            2 => self.midpoint_runs_f32::<2>(x, t0, h, steps),
            _ => self.midpoint_runs_f32::<3>(x, t0, h, steps),
        })
    }

    /// [`integrate_rod_midpoint_f32`](Self::integrate_rod_midpoint_f32), the arguments
    /// checked: block after block of [`WIDTH_F32`] chains, each from its first step to its
    /// last.
    fn midpoint_runs_f32<const C: usize>(
        &self,
        x: &mut [f32],
        t0: f64,
        h: f64,
        steps: usize,
    ) -> Vec<Failure> {
        let (n, m) = (self.links(), 2 * C * self.links());
        let limits = Limits { tolerance: TOLERANCE_F32, ..RodMidpoint::new().limits() };
        // A step is a tension solve and a few iterations, each a few solves' work.
        let solves = n.saturating_mul(8).saturating_mul(steps);
        for_blocks_of::<WIDTH_F32, _, _, _>(
            x,
            m,
            solves,
            || self.rooms.take(|| Room32::<C>::new(n)),
            |room, b, rows| {
                let room = &mut **room;
                let (ids, count) = (block_chains::<WIDTH_F32>(b, self.len()), rows.len() / m);
                let (mut failures, mut alive) = finite_rows(rows, m, ids);
                room.set_chains(ids.map(|k| self.model(k).chain()));
                let lanes: [usize; WIDTH_F32] = std::array::from_fn(|k| k.min(count - 1));
                gather(rows, lanes, m, Lanes32::flatten_mut(&mut room.x));
                let block = one_of(&self.blocks_f32, b);
                // Each step's pivots at its end are the next step's at its start.
                let mut start = self.pivots_f32::<C>(ids, t0);
                for step in 0..steps {
                    if alive == [0; WIDTH_F32] {
                        break;
                    }
                    let t = t0 + step as f64 * h;
                    let end = self.pivots_f32::<C>(ids, t + h);
                    let ends = [start[0], end[0], start[1], end[1]];
                    start = end;
                    let pivot = self.pivot_lanes::<C, WIDTH_F32, _>(
                        ids,
                        [t; WIDTH_F32],
                        Dr::acceleration,
                        Lanes32::rounded,
                    );
                    let stepped =
                        self.midpoint_step_f32_simd::<C>(block, (ends, pivot), (h, &limits), alive, room);
                    let fallen: [bool; WIDTH_F32] = std::array::from_fn(|k| alive[k] != 0 && stepped[k] == 0);
                    for k in (0..WIDTH_F32).filter(|&k| fallen[k]) {
                        let mut state = room.lane_out(k, t);
                        let error = match single_step(self.model(ids[k]), false, &mut state, h) {
                            Ok(()) if room.lane_in(k, &state) => continue,
                            Ok(()) => Error::SinglePrecisionOverflow,
                            Err(error) => error,
                        };
                        failures.push(Failure { chain: ids[k], error });
                        alive[k] = 0;
                    }
                }
                // Every row back (lanes that failed hold the numbers of their last good state).
                scatter::<_, WIDTH_F32>(Lanes32::flatten(&room.x), m, rows);
                failures.sort_by_key(|f| f.chain);
                failures
            },
        )
    }

    /// Each lane's pivot at `t` (s): its position (m) and velocity (m/s), from one
    /// evaluation of its drive ([`Drive::position_and_velocity`]), rounded to `f32`.
    fn pivots_f32<const C: usize>(&self, chains: [usize; WIDTH_F32], t: f64) -> [[F32x8; C]; 2] {
        let each: [_; WIDTH_F32] =
            std::array::from_fn(|k| self.model(chains[k]).drive().position_and_velocity(t));
        let lanes = |v: [&OVector<f64, S>; WIDTH_F32]| {
            std::array::from_fn(|c| Lanes32::rounded(std::array::from_fn(|k| v[k][c])))
        };
        [lanes(each.each_ref().map(|pv| &pv.0)), lanes(each.each_ref().map(|pv| &pv.1))]
    }

    simd_kernel! {
        /// One step of size `h` (s) in `f32` lanes for the lanes flagged in `alive` of
        /// `room` (chains with the rods and `−g` of `block`, pivots at `ends`, accelerating
        /// by `pivot` at the start) that can take it whole: no link would turn too far. The rod tensions at its start, the Newton iteration
        /// (`rod_midpoint::iteration::iterate`), and the new motion in each lane whose
        /// iteration converged. Returns those lanes.
        fn midpoint_step_f32<const C: usize>(
            &self,
            block: &(Rods<F32x8>, F32x8),
            pivot: (Ends<C, F32x8>, [F32x8; C]),
            step: (f64, &Limits),
            alive: [u32; WIDTH_F32],
            room: &mut Room32<C>,
        ) -> [u32; WIDTH_F32] {
            let ((rods, down), (ends, acceleration), (h, limits)) = (block, pivot, step);
            let half = C * self.links();
            let Room32 { solve, work, masses, lengths, damping, x, out, tensions } = room;
            // The alive lanes' numbers are finite: checked before the first step, and only
            // finite numbers are written (a failed iteration's are not; `lane_in` checks).
            let go = F32x8::and_not(alive, turns_too_far(&x[half..], C, h));
            if go == [0; WIDTH_F32] {
                return go;
            }
            solve.tensions(rods, gravity(*down), acceleration, &x[..], tensions);
            let chains = Chains { masses, lengths, damping, down: *down };
            let it = iteration::iterate::<C, F32x8, true>(work, &chains, tensions, ends, (&x[..], h, &mut out[..]), go, limits);
            let stepped = F32x8::and_not(go, it.failed);
            if stepped == [1; WIDTH_F32] {
                // Every lane steps (the common case): the new motion becomes the state.
                std::mem::swap(x, out);
            } else {
                for (x, next) in x.iter_mut().zip(&**out) {
                    *x = F32x8::select(stepped, *next, *x);
                    one_row_at_a_time();
                }
            }
            stepped
        }
        dispatch fn midpoint_step_f32_simd, midpoint_step_f32_avx2
    }
}
