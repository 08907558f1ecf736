//! Runs of RK4 for a batch of planar chains in link angles, in lanes: [`Rk4`] on each
//! chain's first-order system `x = (θ, θ̇)` with its torques and pivot acceleration held,
//! the states in lanes from the first step to the last.
//!
//! [`Rk4`]: crate::integrate::Rk4

use nalgebra::Dyn;

use super::lane_states::{into_lanes, non_finite_lanes, out_of_lanes};
use super::planar::{Block, Scratch, gather_torques};
use super::{
    F64x4, Failure, PlanarBatch, WIDTH, block_chains, check_len, check_states, for_blocks, non_finite,
    simd_kernel,
};
use crate::error::{Error, Result};
use crate::integrate::{State, kahan_add};
use crate::kinematics::trig::sin_cos_split;
use crate::lanes::{Lane, Lanes};

/// A block's run: the solve's scratch (with the joint torques), the pivot accelerations and
/// the lanes with torques, the times and states with their compensations, the stage state
/// `y` (then the increment) and the stages `k1 … k4`, each `2n` lanes.
struct Run {
    solve: Scratch,
    pivot: [F64x4; 2],
    torqued: [u64; WIDTH],
    t: [F64x4; 2],
    x: Vec<F64x4>,
    carry: Vec<F64x4>,
    y: Vec<F64x4>,
    k: [Vec<F64x4>; 4],
}

impl Run {
    fn new(links: usize) -> Self {
        let lanes = || vec![Lanes([0.0; WIDTH]); 2 * links];
        Self {
            solve: Scratch::new(links),
            pivot: [Lanes([0.0; WIDTH]); 2],
            torqued: [0; WIDTH],
            t: [Lanes([0.0; WIDTH]); 2],
            x: lanes(),
            carry: lanes(),
            y: lanes(),
            k: [lanes(), lanes(), lanes(), lanes()],
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
        if !h.is_finite() || h == 0.0 {
            return Err(Error::InvalidStepSize { h });
        }
        let (n, m) = (self.links, 2 * self.links);
        check_states(states, self.len(), m)?;
        if let Some(torque) = torque {
            check_len("torque", torque, self.len(), n)?;
        }
        if let Some(pivot) = pivot {
            check_len("pivot", pivot, self.len(), 2)?;
        }
        let solves = n.saturating_mul(4).saturating_mul(steps);
        Ok(for_blocks(
            states,
            1,
            solves,
            || Run::new(n),
            |s, b, block| {
                let ids = block_chains::<WIDTH>(b, self.len());
                let lanes: [usize; WIDTH] = std::array::from_fn(|k| k.min(block.len() - 1));
                let mut failures = Vec::new();
                let mut alive = [0u64; WIDTH];
                for (k, state) in block.iter().enumerate() {
                    let c = ids[k];
                    let bad = non_finite("x", state.x().as_slice())
                        .or_else(|| torque.and_then(|t| non_finite("torque", &t[c * n..(c + 1) * n])))
                        .or_else(|| {
                            pivot.and_then(|p| non_finite("pivot_acceleration", &p[2 * c..2 * c + 2]))
                        });
                    match bad {
                        Some(error) => failures.push(Failure { chain: c, error }),
                        None => alive[k] = 1,
                    }
                }
                s.torqued = torque.map_or([0; WIDTH], |t| gather_torques(t, ids, n, &mut s.solve.torque));
                s.pivot = match pivot {
                    Some(p) => [Lanes::from_fn(|k| p[2 * ids[k]]), Lanes::from_fn(|k| p[2 * ids[k] + 1])],
                    None => [Lanes([0.0; WIDTH]); 2],
                };
                let ran = alive;
                into_lanes(lanes.map(|k| &block[k]), m, &mut s.t, &mut s.x, &mut s.carry);
                for _ in 0..steps {
                    if alive == [0; WIDTH] {
                        break;
                    }
                    let t = s.t[0];
                    let failed = self.rk4_step_simd(b, h, alive, s);
                    for k in (0..block.len()).filter(|&k| failed[k] != 0) {
                        let error = Error::NonFiniteState { t: t.0[k], h };
                        failures.push(Failure { chain: ids[k], error });
                        alive[k] = 0;
                    }
                }
                out_of_lanes(block.iter_mut(), ran, m, (&s.t, &s.x, &s.carry));
                failures.sort_by_key(|f| f.chain);
                failures
            },
        ))
    }

    simd_kernel! {
        /// One step of [`Rk4`](crate::integrate::Rk4) in lanes, applied only in the `alive`
        /// lanes: the stages, the increment `h (k1 + 2 k2 + 2 k3 + k4) / 6`, then `t += h`
        /// and `x += increment` by compensated summation ([`State`]'s). Returns the alive
        /// lanes whose increment was not finite (left as they were).
        fn rk4_step(&self, b: usize, h: f64, alive: [u64; WIDTH], s: &mut Run) -> [u64; WIDTH] {
            let block = &self.blocks[b.min(self.blocks.len() - 1)];
            let Run { solve, pivot, torqued, t: [t, t_carry], x, carry, y, k: [k1, k2, k3, k4] } = s;
            let inputs = (*pivot, *torqued);
            let half = 0.5 * h;
            rates(block, inputs, x, solve, k1);
            // k_{j+1} = f(y) at y = x + a k_j, as nalgebra's `axpy(a, k_j, 1.0)` forms it.
            let a_half = Lanes([half; WIDTH]);
            for ((y, x), k) in y.iter_mut().zip(&*x).zip(&*k1) {
                *y = a_half * *k + *x;
            }
            rates(block, inputs, y, solve, k2);
            for ((y, x), k) in y.iter_mut().zip(&*x).zip(&*k2) {
                *y = a_half * *k + *x;
            }
            rates(block, inputs, y, solve, k3);
            let a_full = Lanes([h; WIDTH]);
            for ((y, x), k) in y.iter_mut().zip(&*x).zip(&*k3) {
                *y = a_full * *k + *x;
            }
            rates(block, inputs, y, solve, k4);
            let (sixth, two) = (Lanes([h / 6.0; WIDTH]), Lanes([2.0; WIDTH]));
            for (((y, k1), (k2, k3)), k4) in y.iter_mut().zip(&*k1).zip(k2.iter().zip(&*k3)).zip(&*k4) {
                *y = sixth * (*k1 + two * (*k2 + *k3) + *k4);
            }
            let bad = non_finite_lanes(y);
            let keep: [u64; WIDTH] = std::array::from_fn(|k| alive[k] & !bad[k]);
            let (new_t, new_carry) = kahan_add(*t, *t_carry, Lanes([h; WIDTH]));
            (*t, *t_carry) = (F64x4::select(keep, new_t, *t), F64x4::select(keep, new_carry, *t_carry));
            for ((x, carry), y) in x.iter_mut().zip(carry.iter_mut()).zip(&*y) {
                let (new, new_carry) = kahan_add(*x, *carry, *y);
                (*x, *carry) = (F64x4::select(keep, new, *x), F64x4::select(keep, new_carry, *carry));
            }
            std::array::from_fn(|k| alive[k] & bad[k])
        }
        dispatch fn rk4_step_simd, rk4_step_avx2
    }
}

/// `x' = (θ̇, θ̈)` of the block's chains at `x = (θ, θ̇)` (`2n` lanes each), into `out`:
/// [`Block::accelerations`] with the pivot accelerations and torqued lanes `inputs` (the
/// torques in `s`).
#[inline(always)]
fn rates(
    block: &Block,
    (pivot, torqued): ([F64x4; 2], [u64; WIDTH]),
    x: &[F64x4],
    s: &mut Scratch,
    out: &mut [F64x4],
) {
    let n = x.len() / 2;
    let (angles, rates) = x.split_at(n);
    sin_cos_split(Lanes::flatten(angles), Lanes::flatten_mut(&mut s.sin), Lanes::flatten_mut(&mut s.cos));
    s.rates.copy_from_slice(rates);
    block.accelerations(pivot, torqued, s);
    let (velocities, accelerations) = out.split_at_mut(n);
    velocities.copy_from_slice(rates);
    accelerations.copy_from_slice(&s.accelerations);
}
