//! Runs of RK4 for a batch of generated planar models, in lanes: each chain's
//! [`Rk4`](crate::integrate::Rk4) on [`FirstOrder::new`](crate::FirstOrder::new) of its
//! model (pivot at rest, no torques), the states in lanes from the first step to the last.

use nalgebra::{DefaultAllocator, Dim, SVector, allocator::Allocator};

use super::precision::{KernelLanes, join};
use super::{GROUP, LinkConstants, PlanarKernel, SineRoom, UnrolledBatch, unit_blocks};
use crate::batch::{F64x4, Failure, WIDTH, for_blocks_of};
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

impl<const N: usize> Default for Block<N> {
    fn default() -> Self {
        let zero = Lanes([0.0; WIDTH]);
        Self { q: [zero; N], qd: [zero; N], q_carry: [zero; N], qd_carry: [zero; N], t: zero, t_carry: zero }
    }
}

/// `θ̈(θ, θ̇)` for [`increment`]: a type of its own rather than a closure, for the lanes'
/// kernel must be inlined into its caller to run with the caller's target features, and a
/// closure called four times was compiled as a function of its own, without them (SSE2 in
/// the AVX2 run, half its time).
trait Accelerations<V, const N: usize, const G: usize> {
    /// `θ̈` (rad/s²) of `G` blocks at angles `q` (rad) and rates `qd` (rad/s).
    fn at(&mut self, q: &[[V; N]; G], qd: &[[V; N]; G]) -> [[V; N]; G];
}

/// A model's kernels on the first `count` blocks of a group, constants `c`, in lanes of
/// type `V`, pivot at rest and no torques: the sines and cosines of all their angles in
/// one call of the sine kernel (in `room`), then block by block the kernel.
struct Kernel<'a, M, V, const N: usize> {
    c: &'a [LinkConstants<V, N>; GROUP],
    count: usize,
    room: &'a mut SineRoom<F64x4, N>,
    model: std::marker::PhantomData<M>,
}

impl<M: PlanarKernel<N>, V: KernelLanes<f64>, const N: usize> Accelerations<V, N, GROUP>
    for Kernel<'_, M, V, N>
{
    #[inline(always)]
    fn at(&mut self, q: &[[V; N]; GROUP], qd: &[[V; N]; GROUP]) -> [[V; N]; GROUP] {
        let zero = V::splat(0.0);
        let count = self.count;
        let units = count.div_ceil(V::BLOCKS);
        for (u, q) in q.iter().enumerate().take(units) {
            let [a, b] = unit_blocks(u, V::BLOCKS, count);
            for (i, q) in q.iter().enumerate() {
                [self.room.angles[a][i], self.room.angles[b][i]] = q.split();
            }
        }
        self.room.sin_cos::<f64>(count);
        let mut out = [[zero; N]; GROUP];
        for u in 0..units {
            let mut trig = [[zero; 2]; N];
            self.room.trig(unit_blocks(u, V::BLOCKS, count), &mut trig);
            out[u] = M::kernel(&self.c[u], &trig, &qd[u], &[zero; N], [zero; 2]);
        }
        out
    }
}

/// Any closure `θ̈(θ, θ̇)` of one block (out of the hot path: a closure is compiled apart).
impl<V, const N: usize, F: FnMut(&[V; N], &[V; N]) -> [V; N]> Accelerations<V, N, 1> for F {
    fn at(&mut self, q: &[[V; N]; 1], qd: &[[V; N]; 1]) -> [[V; N]; 1] {
        [self(&q[0], &qd[0])]
    }
}

/// The increment `h (k1 + 2 k2 + 2 k3 + k4) / 6` of one step of
/// [`Rk4`](crate::integrate::Rk4) from `(θ, θ̇)`, for the first-order system
/// `(θ, θ̇)' = (θ̇, θ̈)` with `θ̈ = accelerations(θ, θ̇)`, rounded as `Rk4` rounds it: lane by
/// lane (`V = Lanes`) or for one chain (`V = f64`), for `G` blocks at once.
#[inline(always)]
fn increment<V: Lane, const N: usize, const G: usize>(
    q: &[[V; N]; G],
    qd: &[[V; N]; G],
    h: f64,
    mut accelerations: impl Accelerations<V, N, G>,
) -> ([[V; N]; G], [[V; N]; G]) {
    let (half, whole, sixth, two) = (V::splat(0.5 * h), V::splat(h), V::splat(h / 6.0), V::splat(2.0));
    // k_s = (θ̇_s, θ̈_s), the stages of `Rk4::stages`.
    let a1 = accelerations.at(q, qd);
    let (q2, qd2) = (axpy(q, half, qd), axpy(qd, half, &a1));
    let a2 = accelerations.at(&q2, &qd2);
    let (q3, qd3) = (axpy(q, half, &qd2), axpy(qd, half, &a2));
    let a3 = accelerations.at(&q3, &qd3);
    let (q4, qd4) = (axpy(q, whole, &qd3), axpy(qd, whole, &a3));
    let a4 = accelerations.at(&q4, &qd4);
    (weighted_sum(sixth, two, [qd, &qd2, &qd3, &qd4]), weighted_sum(sixth, two, [&a1, &a2, &a3, &a4]))
}

/// `y = x + a k` as `Rk4`'s `axpy` rounds it, for `G` blocks. A function, not a closure
/// in [`increment`]: called six times, a closure was compiled apart, without the kernel's
/// target features (each lane operation a call, 0.23× the run).
#[inline(always)]
fn axpy<V: Lane, const N: usize, const G: usize>(x: &[[V; N]; G], a: V, k: &[[V; N]; G]) -> [[V; N]; G] {
    let mut y = *x;
    for (y, k) in y.iter_mut().zip(k) {
        for (y, &k) in y.iter_mut().zip(k) {
            *y = a * k + *y;
        }
    }
    y
}

/// `(h/6) (k1 + 2 (k2 + k3) + k4)` as `Rk4` rounds it, for `G` blocks (`sixth` = h/6,
/// `two` = 2).
#[inline(always)]
fn weighted_sum<V: Lane, const N: usize, const G: usize>(
    sixth: V,
    two: V,
    [k1, k2, k3, k4]: [&[[V; N]; G]; 4],
) -> [[V; N]; G] {
    let mut out = *k1;
    for j in 0..G {
        for i in 0..N {
            out[j][i] = sixth * (k1[j][i] + two * (k2[j][i] + k3[j][i]) + k4[j][i]);
        }
    }
    out
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
        let failures = for_blocks_of::<{ GROUP * WIDTH }, _, _, _>(
            states,
            1,
            solves,
            SineRoom::new,
            |room, g, states| {
                let first = GROUP * g;
                let count = states.len().div_ceil(WIDTH);
                let mut s: [Block<N>; GROUP] = std::array::from_fn(|_| Block::default());
                for (s, block) in s.iter_mut().zip(states.chunks(WIDTH)) {
                    let parts: [_; WIDTH] = std::array::from_fn(|k| block[k.min(block.len() - 1)].parts());
                    let entries = |j: usize, carry: bool| {
                        Lanes::from_fn(|k| if carry { parts[k].3[j] } else { parts[k].2[j] })
                    };
                    *s = Block {
                        q: std::array::from_fn(|i| entries(i, false)),
                        qd: std::array::from_fn(|i| entries(N + i, false)),
                        q_carry: std::array::from_fn(|i| entries(i, true)),
                        qd_carry: std::array::from_fn(|i| entries(N + i, true)),
                        t: Lanes::from_fn(|k| parts[k].0),
                        t_carry: Lanes::from_fn(|k| parts[k].1),
                    };
                }
                let alive = self.rk4_run_simd(first, count, room, h, steps, &mut s);
                let mut failures = Vec::new();
                for (j, (s, block)) in s.iter().zip(states.chunks_mut(WIDTH)).enumerate() {
                    for (k, state) in block.iter_mut().enumerate() {
                        let x = (s.q.iter().zip(&s.q_carry)).chain(s.qd.iter().zip(&s.qd_carry));
                        state.set_parts(s.t.0[k], s.t_carry.0[k], x.map(|(x, carry)| (x.0[k], carry.0[k])));
                        if !alive[j][k] {
                            let chain = WIDTH * (first + j) + k;
                            failures.push(Failure {
                                chain,
                                error: self.step_error(chain, state.t(), state.x().as_slice(), h),
                            });
                        }
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
        let (q, qd): ([f64; N], [f64; N]) = (x[..N].try_into().expect("N"), x[N..].try_into().expect("N"));
        increment::<f64, N, 1>(&[q], &[qd], h, |q: &[f64; N], qd: &[f64; N]| {
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

    /// `steps` RK4 steps of the blocks `s` of the group starting at block `first` (the
    /// first `count` of them), in lanes of type `V` (holding one block each, or two); a lane
    /// whose increment is not finite stops at the start of that step. Returns the lanes
    /// that ran to the end.
    #[inline(always)]
    fn rk4_run<V: KernelLanes<f64>>(
        &self,
        (first, count): (usize, usize),
        room: &mut SineRoom<F64x4, N>,
        h: f64,
        steps: usize,
        s: &mut [Block<N>; GROUP],
    ) -> [[bool; WIDTH]; GROUP] {
        let zero = V::splat(0.0);
        let units = count.div_ceil(V::BLOCKS);
        let c: [LinkConstants<V, N>; GROUP] = std::array::from_fn(|u| {
            let [a, b] = unit_blocks(u.min(units - 1), V::BLOCKS, count);
            LinkConstants::joined([&self.blocks[first + a], &self.blocks[first + b]])
        });
        let (mut q, mut qd) = ([[zero; N]; GROUP], [[zero; N]; GROUP]);
        let (mut q_carry, mut qd_carry) = ([[zero; N]; GROUP], [[zero; N]; GROUP]);
        let (mut t, mut t_carry) = ([zero; GROUP], [zero; GROUP]);
        for u in 0..units {
            let [a, b] = unit_blocks(u, V::BLOCKS, count).map(|j| &s[j]);
            (q[u], qd[u]) = (join([&a.q, &b.q]), join([&a.qd, &b.qd]));
            (q_carry[u], qd_carry[u]) = (join([&a.q_carry, &b.q_carry]), join([&a.qd_carry, &b.qd_carry]));
            (t[u], t_carry[u]) = (V::join([a.t, b.t]), V::join([a.t_carry, b.t_carry]));
        }
        let mut stopped = [V::none(); GROUP];
        for _ in 0..steps {
            let kernel =
                Kernel::<M, V, N> { c: &c, count, room: &mut *room, model: std::marker::PhantomData };
            let (dq, dqd) = increment(&q, &qd, h, kernel);
            for u in 0..units {
                // Σ (δ − δ): +0 in a lane whose increment is finite, NaN otherwise.
                let mut probe = zero;
                for d in dq[u].iter().chain(&dqd[u]) {
                    #[allow(clippy::eq_op)]
                    let nan_if_not_finite = *d - *d;
                    probe += nan_if_not_finite;
                }
                let stop = V::or(stopped[u], probe.outside(0, 0));
                stopped[u] = stop;
                let advance = |x: &mut V, carry: &mut V, delta: V| {
                    let (new, new_carry) = kahan_add(*x, *carry, delta);
                    (*x, *carry) = (V::select(stop, *x, new), V::select(stop, *carry, new_carry));
                };
                advance(&mut t[u], &mut t_carry[u], V::splat(h));
                for i in 0..N {
                    advance(&mut q[u][i], &mut q_carry[u][i], dq[u][i]);
                    advance(&mut qd[u][i], &mut qd_carry[u][i], dqd[u][i]);
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
                let back = |v: &[V; N], to: &mut [F64x4; N]| {
                    for (to, v) in to.iter_mut().zip(v) {
                        *to = v.split()[half];
                    }
                };
                back(&q[u], &mut s[j].q);
                back(&qd[u], &mut s[j].qd);
                back(&q_carry[u], &mut s[j].q_carry);
                back(&qd_carry[u], &mut s[j].qd_carry);
                (s[j].t, s[j].t_carry) = (t[u].split()[half], t_carry[u].split()[half]);
                let ran = V::select(stopped[u], zero, V::splat(1.0)).split()[half];
                alive[j] = ran.0.map(|alive| alive == 1.0);
            }
        }
        alive
    }

    /// [`rk4_run`](Self::rk4_run) in AVX-512 registers (two blocks each) where the CPU has
    /// AVX-512 VL and the batch allows it, in AVX2 registers where it has AVX2, else in
    /// [`Lanes`].
    fn rk4_run_simd(
        &self,
        first: usize,
        count: usize,
        room: &mut SineRoom<F64x4, N>,
        h: f64,
        steps: usize,
        s: &mut [Block<N>; GROUP],
    ) -> [[bool; WIDTH]; GROUP] {
        #[cfg(target_arch = "x86_64")]
        if self.uses_avx512() {
            // SAFETY: the CPU has AVX-512 VL (and so AVX2), checked just above.
            return unsafe { self.rk4_run_avx512(first, count, room, h, steps, s) };
        }
        #[cfg(target_arch = "x86_64")]
        if crate::lanes::has_avx2() {
            // SAFETY: the CPU has AVX2, checked just above.
            return unsafe { self.rk4_run_avx2(first, count, room, h, steps, s) };
        }
        self.rk4_run::<F64x4>((first, count), room, h, steps, s)
    }

    /// [`rk4_run`](Self::rk4_run) compiled for AVX-512, two blocks in each
    /// [`Avx8`](crate::lanes::Avx8) register (1.18–1.26× four lanes, `docs/ensembles.md`).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,avx512f,avx512vl")]
    fn rk4_run_avx512(
        &self,
        first: usize,
        count: usize,
        room: &mut SineRoom<F64x4, N>,
        h: f64,
        steps: usize,
        s: &mut [Block<N>; GROUP],
    ) -> [[bool; WIDTH]; GROUP] {
        self.rk4_run::<crate::lanes::Avx8>((first, count), room, h, steps, s)
    }

    /// [`rk4_run`](Self::rk4_run) compiled for AVX2, in [`Avx4`](crate::lanes::Avx4) registers.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn rk4_run_avx2(
        &self,
        first: usize,
        count: usize,
        room: &mut SineRoom<F64x4, N>,
        h: f64,
        steps: usize,
        s: &mut [Block<N>; GROUP],
    ) -> [[bool; WIDTH]; GROUP] {
        self.rk4_run::<crate::lanes::Avx4>((first, count), room, h, steps, s)
    }
}
