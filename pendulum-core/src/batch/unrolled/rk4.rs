//! Runs of RK4 for a batch of generated planar models, in lanes: each chain's
//! [`Rk4`](crate::integrate::Rk4) on [`FirstOrder::new`](crate::FirstOrder::new) of its
//! model (pivot at rest, no torques), the states in lanes from the first step to the last.

use nalgebra::{DefaultAllocator, Dim, SVector, allocator::Allocator};

use super::precision::{KernelLanes, convert};
use super::{LinkConstants, PlanarKernel, UnrolledBatch};
use crate::batch::{F64x4, Failure, WIDTH, for_blocks};
use crate::error::{Error, Result};
use crate::integrate::{State, kahan_add};
use crate::lanes::{Lane, Lanes};

/// A block's states in lanes: `θ`, `θ̇` and their compensations, `t` and its compensation.
struct Block<const N: usize> {
    q: [F64x4; N],
    qd: [F64x4; N],
    q_carry: [F64x4; N],
    qd_carry: [F64x4; N],
    t: F64x4,
    t_carry: F64x4,
}

/// `θ̈(θ, θ̇)` for [`increment`]: a type of its own rather than a closure, for the lanes'
/// kernel must be inlined into its caller to run with the caller's target features, and a
/// closure called four times was compiled as a function of its own, without them (SSE2 in
/// the AVX2 run, half its time).
trait Accelerations<V, const N: usize> {
    /// `θ̈` (rad/s²) at angles `q` (rad) and rates `qd` (rad/s).
    fn at(&mut self, q: &[V; N], qd: &[V; N]) -> [V; N];
}

/// A model's kernel on a block of lanes of type `V`, pivot at rest and no torques.
struct Kernel<'a, M, V, const N: usize>(&'a LinkConstants<V, N>, std::marker::PhantomData<M>);

impl<M: PlanarKernel<N>, V: KernelLanes<f64>, const N: usize> Accelerations<V, N> for Kernel<'_, M, V, N> {
    #[inline(always)]
    fn at(&mut self, q: &[V; N], qd: &[V; N]) -> [V; N] {
        let zero = V::splat(0.0);
        M::kernel(self.0, &V::sin_cos(q), qd, &[zero; N], [zero; 2])
    }
}

/// Any closure `θ̈(θ, θ̇)` (out of the hot path: a closure is compiled apart).
impl<V, const N: usize, F: FnMut(&[V; N], &[V; N]) -> [V; N]> Accelerations<V, N> for F {
    fn at(&mut self, q: &[V; N], qd: &[V; N]) -> [V; N] {
        self(q, qd)
    }
}

/// The increment `h (k1 + 2 k2 + 2 k3 + k4) / 6` of one step of
/// [`Rk4`](crate::integrate::Rk4) from `(θ, θ̇)`, for the first-order system
/// `(θ, θ̇)' = (θ̇, θ̈)` with `θ̈ = accelerations(θ, θ̇)`, rounded as `Rk4` rounds it: lane by
/// lane (`V = Lanes`) or for one chain (`V = f64`).
#[inline(always)]
fn increment<V: Lane, const N: usize>(
    q: &[V; N],
    qd: &[V; N],
    h: f64,
    mut accelerations: impl Accelerations<V, N>,
) -> ([V; N], [V; N]) {
    let (half, whole, sixth, two) = (V::splat(0.5 * h), V::splat(h), V::splat(h / 6.0), V::splat(2.0));
    // `y = x + a k` as `Rk4`'s `axpy` rounds it.
    let axpy = |x: &[V; N], a: V, k: &[V; N]| -> [V; N] { std::array::from_fn(|i| a * k[i] + x[i]) };
    // k_s = (θ̇_s, θ̈_s), the stages of `Rk4::stages`.
    let a1 = accelerations.at(q, qd);
    let (q2, qd2) = (axpy(q, half, qd), axpy(qd, half, &a1));
    let a2 = accelerations.at(&q2, &qd2);
    let (q3, qd3) = (axpy(q, half, &qd2), axpy(qd, half, &a2));
    let a3 = accelerations.at(&q3, &qd3);
    let (q4, qd4) = (axpy(q, whole, &qd3), axpy(qd, whole, &a3));
    let a4 = accelerations.at(&q4, &qd4);
    let sum = |k1: &[V; N], k2: &[V; N], k3: &[V; N], k4: &[V; N]| -> [V; N] {
        std::array::from_fn(|i| sixth * (k1[i] + two * (k2[i] + k3[i]) + k4[i]))
    };
    (sum(qd, &qd2, &qd3, &qd4), sum(&a1, &a2, &a3, &a4))
}

impl<M: PlanarKernel<N>, const N: usize> UnrolledBatch<M, N> {
    /// `steps` steps of RK4 of size `h` (s) for every chain, each from its own state
    /// `x = (θ, θ̇)` (`2N` entries: rad, rad/s) and time: exactly what `steps` calls of
    /// [`Rk4`](crate::integrate::Rk4)'s `step` on `FirstOrder::new(model)` give for each
    /// chain alone, bit for bit (compensated time and state included), with the states
    /// kept in lanes from the first step to the last.
    ///
    /// Returns the chains that failed, in order, each with the error its own step gave (a
    /// non-finite state or acceleration); a failed chain is left at the start of the step
    /// that failed and the others go on. Errors: [`Error::InvalidStepSize`] for a zero or
    /// non-finite `h`, [`Error::LengthMismatch`] for a number of states other than `B` or a
    /// state of the wrong length.
    pub fn integrate_rk4<D: Dim>(&self, states: &mut [State<D>], h: f64, steps: usize) -> Result<Vec<Failure>>
    where
        DefaultAllocator: Allocator<D>,
        State<D>: Send,
    {
        if !h.is_finite() || h == 0.0 {
            return Err(Error::InvalidStepSize { h });
        }
        if states.len() != self.len() {
            return Err(Error::LengthMismatch { what: "states", expected: self.len(), got: states.len() });
        }
        if let Some(s) = states.iter().find(|s| s.x().len() != 2 * N) {
            return Err(Error::LengthMismatch { what: "x", expected: 2 * N, got: s.x().len() });
        }
        let solves = (4 * N).saturating_mul(steps);
        let failures = for_blocks(
            states,
            1,
            solves,
            || (),
            |_, b, block| {
                let parts: [_; WIDTH] = std::array::from_fn(|k| block[k.min(block.len() - 1)].parts());
                let entries = |j: usize, carry: bool| {
                    Lanes::from_fn(|k| if carry { parts[k].3[j] } else { parts[k].2[j] })
                };
                let mut s = Block {
                    q: std::array::from_fn(|i| entries(i, false)),
                    qd: std::array::from_fn(|i| entries(N + i, false)),
                    q_carry: std::array::from_fn(|i| entries(i, true)),
                    qd_carry: std::array::from_fn(|i| entries(N + i, true)),
                    t: Lanes::from_fn(|k| parts[k].0),
                    t_carry: Lanes::from_fn(|k| parts[k].1),
                };
                let alive = self.rk4_run_simd(b, h, steps, &mut s);
                let mut failures = Vec::new();
                for (k, state) in block.iter_mut().enumerate() {
                    let x = (s.q.iter().zip(&s.q_carry)).chain(s.qd.iter().zip(&s.qd_carry));
                    state.set_parts(s.t.0[k], s.t_carry.0[k], x.map(|(x, carry)| (x.0[k], carry.0[k])));
                    if !alive[k] {
                        let chain = WIDTH * b + k;
                        failures.push(Failure {
                            chain,
                            error: self.step_error(chain, state.t(), state.x().as_slice(), h),
                        });
                    }
                }
                failures
            },
        );
        Ok(failures)
    }

    /// The error of chain `chain`'s own RK4 step from `state` (out of the hot path): the
    /// first stage's whose accelerations fail, else a non-finite increment.
    #[cold]
    fn step_error(&self, chain: usize, t: f64, x: &[f64], h: f64) -> Error {
        let model = &self.models[chain];
        let inputs = model.zero_inputs();
        let mut first = None;
        let (q, qd) = (x[..N].try_into().expect("N"), x[N..].try_into().expect("N"));
        increment::<f64, N>(q, qd, h, |q: &[f64; N], qd: &[f64; N]| {
            let mut out = SVector::<f64, N>::zeros();
            let (q, qd) = (SVector::<f64, N>::from_column_slice(q), SVector::<f64, N>::from_column_slice(qd));
            match model.accelerations(&q, &qd, &inputs, &mut out) {
                Ok(()) => out.data.0[0],
                Err(error) => {
                    first.get_or_insert(error);
                    [f64::NAN; N]
                }
            }
        });
        first.unwrap_or(Error::NonFiniteState { t, h })
    }

    /// `steps` RK4 steps of block `b` in lanes of type `V`; a lane whose increment is not
    /// finite stops at the start of that step. Returns the lanes that ran to the end.
    #[inline(always)]
    fn rk4_run<V: KernelLanes<f64>>(
        &self,
        b: usize,
        h: f64,
        steps: usize,
        s: &mut Block<N>,
    ) -> [bool; WIDTH] {
        let c = self.blocks[b].in_lanes::<V>();
        let (mut q, mut qd): ([V; N], [V; N]) = (convert(&s.q), convert(&s.qd));
        let (mut q_carry, mut qd_carry): ([V; N], [V; N]) = (convert(&s.q_carry), convert(&s.qd_carry));
        let (mut t, mut t_carry) = (V::from(s.t), V::from(s.t_carry));
        let zero = V::splat(0.0);
        let mut stopped = V::none();
        for _ in 0..steps {
            let (dq, dqd) = increment(&q, &qd, h, Kernel::<M, V, N>(&c, std::marker::PhantomData));
            // Σ (δ − δ): +0 in a lane whose increment is finite, NaN otherwise.
            let mut probe = zero;
            for d in dq.iter().chain(&dqd) {
                #[allow(clippy::eq_op)]
                let nan_if_not_finite = *d - *d;
                probe += nan_if_not_finite;
            }
            stopped = V::or(stopped, probe.outside(0, 0));
            let advance = |x: &mut V, carry: &mut V, delta: V| {
                let (new, new_carry) = kahan_add(*x, *carry, delta);
                (*x, *carry) = (V::select(stopped, *x, new), V::select(stopped, *carry, new_carry));
            };
            advance(&mut t, &mut t_carry, V::splat(h));
            for i in 0..N {
                advance(&mut q[i], &mut q_carry[i], dq[i]);
                advance(&mut qd[i], &mut qd_carry[i], dqd[i]);
            }
            if V::all(stopped) {
                break;
            }
        }
        let back = |v: &[V; N], to: &mut [F64x4; N]| {
            for (to, v) in to.iter_mut().zip(v) {
                *to = (*v).into();
            }
        };
        back(&q, &mut s.q);
        back(&qd, &mut s.qd);
        back(&q_carry, &mut s.q_carry);
        back(&qd_carry, &mut s.qd_carry);
        (s.t, s.t_carry) = (t.into(), t_carry.into());
        V::select(stopped, zero, V::splat(1.0)).into().0.map(|alive| alive == 1.0)
    }

    /// [`rk4_run`](Self::rk4_run) in AVX2 registers when the CPU has them, else in
    /// [`Lanes`].
    fn rk4_run_simd(&self, b: usize, h: f64, steps: usize, s: &mut Block<N>) -> [bool; WIDTH] {
        #[cfg(target_arch = "x86_64")]
        if crate::lanes::has_avx2() {
            // SAFETY: the CPU has AVX2, checked just above.
            return unsafe { self.rk4_run_avx2(b, h, steps, s) };
        }
        self.rk4_run::<F64x4>(b, h, steps, s)
    }

    /// [`rk4_run`](Self::rk4_run) compiled for AVX2, in [`Avx4`](crate::lanes::Avx4) registers.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn rk4_run_avx2(&self, b: usize, h: f64, steps: usize, s: &mut Block<N>) -> [bool; WIDTH] {
        self.rk4_run::<crate::lanes::Avx4>(b, h, steps, s)
    }
}
