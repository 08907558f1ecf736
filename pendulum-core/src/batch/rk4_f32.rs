//! Runs of projected RK4 in single precision for a batch of chains in directions: eight
//! chains per AVX2 register, the states in lanes from a run's first step to its last, each
//! chain's constants rounded to `f32` and its pivot acceleration computed in `f64` at every
//! stage's time and then rounded. Not bit for bit anything: its error against the `f64`
//! run is measured in `docs/ensembles.md`.

use nalgebra::{DefaultAllocator, DimName, allocator::Allocator};

use super::directions::{Solve, gravity};
use super::lane_states::{finite_rows, non_finite_lanes_f32};
use super::{
    DirectionsBatch, F32x8, Failure, WIDTH_F32, block_chains, check_len, for_blocks_of, gather, one_of,
    scatter, simd_kernel,
};
use crate::batch::check_t0;
use crate::drive::Drive;
use crate::error::{Error, Result};
use crate::integrate::{check_step_size, rk4_weighted};
use crate::lanes::{Aligned, Lane, Lanes32, one_row_at_a_time};
use crate::models::directions::project_link;
use crate::rods::Rods;

/// A block's run in single precision: the solve's rows, the states `x`, the stage state `y`
/// (then the increment) and the stages `k1 … k4`, each `2·C·n` lanes.
pub(super) struct Scratch32<const C: usize> {
    solve: Solve<C, F32x8>,
    x: Aligned<F32x8>,
    y: Aligned<F32x8>,
    k: [Aligned<F32x8>; 4],
}

impl<const C: usize> Scratch32<C> {
    fn new(links: usize) -> Self {
        let lanes = || Aligned::filled(F32x8::splat(0.0), 2 * C * links);
        Self { solve: Solve::new(links), x: lanes(), y: lanes(), k: [lanes(), lanes(), lanes(), lanes()] }
    }
}

impl<S: DimName, Dr: Drive<S> + Sync> DirectionsBatch<S, Dr>
where
    DefaultAllocator: Allocator<S>,
{
    /// `steps` steps of RK4 with projection (`Projected<Rk4>`: every rod put back to unit
    /// length and its rate made perpendicular to it after each step) of size `h` (s) for
    /// every chain in single precision, from the time `t0` (s; step `j` at `t0 + j h`): the
    /// states as `B` rows of `(u, w)` (`2·S·n` numbers of `f32`, numpy's `(B, 2·S·n)`),
    /// overwritten; eight chains per AVX2 register, each chain's constants rounded to
    /// `f32` and its pivot acceleration computed in `f64` at every stage's time and then
    /// rounded. The motion only: an [`accounted`](Self::accounted) batch's ledger is not
    /// kept. Not bit for bit anything: its error against
    /// [`integrate_rk4`](Self::integrate_rk4) is measured in `docs/ensembles.md`.
    ///
    /// Returns the chains that failed, in order: a non-finite state (by its entry, before
    /// any step), or a step whose increment is not finite ([`Error::NonFiniteState`] with
    /// that step's time; a pivot acceleration past `f32`'s range fails so); a failed
    /// chain is left at its last good state and the others go on. Errors:
    /// [`Error::LengthMismatch`] when `x` does not hold `B` rows of `2·S·n`,
    /// [`Error::InvalidStepSize`] for a non-finite or zero `h`, [`Error::NonFinite`] for
    /// a non-finite `t0`.
    pub fn integrate_rk4_f32(&self, x: &mut [f32], t0: f64, h: f64, steps: usize) -> Result<Vec<Failure>> {
        check_step_size(h)?;
        check_t0(t0)?;
        check_len("x", x, self.len(), 2 * S::DIM * self.links())?;
        Ok(match S::DIM {
            2 => self.runs_f32::<2>(x, t0, h, steps),
            _ => self.runs_f32::<3>(x, t0, h, steps),
        })
    }

    /// [`integrate_rk4_f32`](Self::integrate_rk4_f32), the arguments checked: block after
    /// block of [`WIDTH_F32`] chains, each from its first step to its last.
    fn runs_f32<const C: usize>(&self, x: &mut [f32], t0: f64, h: f64, steps: usize) -> Vec<Failure> {
        let (n, m) = (self.links(), 2 * C * self.links());
        let solves = n.saturating_mul(4).saturating_mul(steps);
        for_blocks_of::<WIDTH_F32, _, _, _>(
            x,
            m,
            solves,
            || self.rooms.take(|| Scratch32::<C>::new(n)),
            |room, b, rows| {
                let s = &mut **room;
                let (ids, count) = (block_chains::<WIDTH_F32>(b, self.len()), rows.len() / m);
                let (mut failures, mut alive) = finite_rows(rows, m, ids);
                let lanes: [usize; WIDTH_F32] = std::array::from_fn(|k| k.min(count - 1));
                gather(rows, lanes, m, Lanes32::flatten_mut(&mut s.x));
                let block = one_of(&self.blocks_f32, b);
                for step in 0..steps {
                    if alive == [0; WIDTH_F32] {
                        break;
                    }
                    let t = t0 + step as f64 * h;
                    let failed = self.rk4_step_f32_simd::<C>(block, ids, (t, h), alive, s);
                    for (k, _) in failed.iter().enumerate().filter(|(_, f)| **f != 0) {
                        failures.push(Failure { chain: ids[k], error: Error::NonFiniteState { t, h } });
                    }
                    alive = std::array::from_fn(|k| alive[k] & !failed[k]);
                }
                // Every row back (lanes that did not step hold the numbers they came with).
                scatter::<_, WIDTH_F32>(Lanes32::flatten(&s.x), m, rows);
                failures.sort_by_key(|f| f.chain);
                failures
            },
        )
    }

    simd_kernel! {
        /// One step of `Projected<Rk4>` in `f32` lanes from `s.x` at time `t` (s), size `h`
        /// (s), applied only in the `alive` lanes: the stages, the increment
        /// `h (k1 + 2 k2 + 2 k3 + k4) / 6`, `x + increment`, every link projected
        /// ([`project_link`]). Returns the alive lanes whose increment was not finite (left
        /// as they were).
        fn rk4_step_f32<const C: usize>(
            &self,
            block: &(Rods<F32x8>, F32x8),
            chains: [usize; WIDTH_F32],
            time: (f64, f64),
            alive: [u32; WIDTH_F32],
            s: &mut Scratch32<C>,
        ) -> [u32; WIDTH_F32] {
            let ((rods, down), (t, h)) = (block, time);
            let Scratch32 { solve, x, y, k: [k1, k2, k3, k4] } = s;
            let (g, half) = (gravity::<C, F32x8>(*down), C * self.links());
            let at = |dt: f64| [t + dt; WIDTH_F32];
            let start = self.pivot_lanes::<C, WIDTH_F32, _>(chains, at(0.0), Dr::acceleration, Lanes32::rounded);
            let middle = self.pivot_lanes::<C, WIDTH_F32, _>(chains, at(0.5 * h), Dr::acceleration, Lanes32::rounded);
            let end = self.pivot_lanes::<C, WIDTH_F32, _>(chains, at(h), Dr::acceleration, Lanes32::rounded);
            // k1 = (w, ü(x)); k_{j+1} = f(y) at y = x + a k_j, y formed in the stage's pass.
            k1[..half].copy_from_slice(&x[half..2 * half]);
            solve.accelerations(rods, g, start, x, &mut k1[half..2 * half]);
            let (a_half, a_full) = (F32x8::splat(0.5 * h), F32x8::splat(h));
            solve.stage(rods, g, middle, x, a_half, k1, y, k2);
            solve.stage(rods, g, middle, x, a_half, k2, y, k3);
            solve.stage(rods, g, end, x, a_full, k3, y, k4);
            let sixth = F32x8::splat(h / 6.0);
            for (((y, k1), (k2, k3)), k4) in y.iter_mut().zip(&**k1).zip(k2.iter().zip(&**k3)).zip(&**k4) {
                *y = rk4_weighted(sixth, [*k1, *k2, *k3, *k4]);
                one_row_at_a_time();
            }
            let bad = non_finite_lanes_f32(y);
            let keep: [u32; WIDTH_F32] = std::array::from_fn(|k| alive[k] & !bad[k]);
            // k1 is spent: the next state goes there, projected link by link.
            for ((next, x), y) in k1.iter_mut().zip(&**x).zip(&**y) {
                *next = *x + *y;
                one_row_at_a_time();
            }
            let (u, w) = k1[..2 * half].split_at_mut(half);
            for (u, w) in u.chunks_exact_mut(C).zip(w.chunks_exact_mut(C)) {
                project_link(u, w);
                one_row_at_a_time();
            }
            if keep.iter().all(|&k| k != 0) {
                // Every lane steps (the common case): the next state becomes the state.
                std::mem::swap(x, k1);
            } else {
                for (x, next) in x.iter_mut().zip(&**k1) {
                    *x = F32x8::select(keep, *next, *x);
                    one_row_at_a_time();
                }
            }
            std::array::from_fn(|k| alive[k] & bad[k])
        }
        dispatch fn rk4_step_f32_simd, rk4_step_f32_avx2
    }
}
