//! Runs of RK4 for a batch of generated models, in lanes: each chain's
//! [`Rk4`](crate::integrate::Rk4) on [`FirstOrder::with_inputs`](crate::FirstOrder::with_inputs)
//! of its model, its torques held over the run and its pivot's acceleration held or from
//! its own drive at each stage's time; the states in lanes from the first step to the last.
//! One run serves the planar models (`C = 1` array of `N` coordinates a block, the angles
//! `θ_i`) and the spatial ones (`C = 2`: the polar angles, then the azimuths), through
//! [`Stages`].

use nalgebra::{DefaultAllocator, Dim, DimName, SVector, U2, U3, Vector2, allocator::Allocator};

use super::precision::{KernelLanes, Precision, join};
use super::spatial::near_pole;
use super::{
    GROUP, Groups, LinkConstants, PlanarKernel, SineRoom, SpatialKernel, UnrolledBatch, UnrolledSpatialBatch,
    unit_blocks,
};
use crate::batch::{F64x4, Failure, WIDTH, block_chains, check_len, for_blocks_of};
use crate::drive::Drive;
use crate::error::{Error, Result};
use crate::integrate::{State, kahan_add};
use crate::lanes::{Lane, Lanes};
use crate::model::Inputs;

/// A block's states in lanes: its `K` arrays of `N` coordinates, their rates and their
/// compensations, `t` and its compensation; and its inputs: the `K` arrays of torques
/// and the pivot acceleration (three components, the third 0 for planar chains) held.
pub(super) struct Block<L, const N: usize, const K: usize> {
    pub(super) q: [[L; N]; K],
    pub(super) qd: [[L; N]; K],
    pub(super) q_carry: [[L; N]; K],
    pub(super) qd_carry: [[L; N]; K],
    pub(super) t: L,
    pub(super) t_carry: L,
    pub(super) torque: [[L; N]; K],
    pub(super) pivot: [L; 3],
}

impl<L: Lane, const N: usize, const K: usize> Default for Block<L, N, K> {
    fn default() -> Self {
        let zero = [[L::splat(0.0); N]; K];
        let t = L::splat(0.0);
        Self { q: zero, qd: zero, q_carry: zero, qd_carry: zero, t, t_carry: t, torque: zero, pivot: [t; 3] }
    }
}

/// A run's inputs: each chain's torques (`B` rows of `C·N`, N·m; `None`: none), held over
/// the run (a zero-order hold, as a controller applies its action), and its pivot's
/// acceleration.
#[derive(Clone, Copy)]
struct RunInputs<'a> {
    torque: Option<&'a [f64]>,
    pivot: Pivot<'a>,
}

/// Each chain's pivot acceleration `p̈` (m/s²) over a run: held (`B` rows of the chain's
/// space, 2 or 3; `None`: at rest), or chain `k`'s at time `t` from `Driven(k, t)` (three
/// components, the third 0 for planar chains), asked at each stage's time.
#[derive(Clone, Copy)]
pub(super) enum Pivot<'a> {
    Held(Option<&'a [f64]>),
    Driven(&'a (dyn Fn(usize, f64) -> [f64; 3] + Sync)),
}

impl RunInputs<'_> {
    /// Chain `chain`'s torques (`m` of them) and its pivot acceleration at time `t` (`space`
    /// components of 3 read), for its own step (out of the hot path).
    fn of(&self, chain: usize, m: usize, space: usize) -> (Vec<f64>, impl Fn(f64) -> [f64; 3] + '_) {
        let torque = self.torque.map_or_else(|| vec![0.0; m], |t| t[chain * m..(chain + 1) * m].to_vec());
        let pivot = move |t: f64| match self.pivot {
            Pivot::Held(None) => [0.0; 3],
            Pivot::Held(Some(p)) => {
                std::array::from_fn(|d| if d < space { p[space * chain + d] } else { 0.0 })
            }
            Pivot::Driven(drive) => drive(chain, t),
        };
        (torque, pivot)
    }
}

/// The times of `Rk4`'s four stages from a step's start `t`, as it forms them.
fn stage_times(t: f64, h: f64) -> [f64; 4] {
    let half = t + 0.5 * h;
    [t, half, half, t + h]
}

/// `q̈(q, q̇)` for [`increment`]: a type of its own rather than a closure, for the lanes'
/// kernel must be inlined into its caller to run with the caller's target features, and a
/// closure called four times was compiled as a function of its own, without them (SSE2 in
/// the AVX2 run, half its time).
trait Accelerations<V, const N: usize, const G: usize> {
    /// `q̈` (rad/s²) of `G` arrays of coordinates `q` (rad) and rates `qd` (rad/s).
    fn at(&mut self, q: &[[V; N]; G], qd: &[[V; N]; G]) -> [[V; N]; G];
}

/// A stage's inputs in lanes: the torques (`A` arrays of `N`, as the coordinates) and the
/// pivot accelerations (three components per unit); `None`: zeros.
type StageInputs<'a, V, const N: usize, const A: usize> = Option<(&'a [[V; N]; A], &'a [[V; 3]; GROUP])>;

/// A batch of generated models as its RK4 run sees it: `A` arrays of `N` coordinates a
/// group ([`GROUP`] blocks of `A / GROUP` arrays each), and the accelerations of a group's
/// blocks in lanes.
pub(super) trait Stages<const N: usize, const A: usize>: Groups<N, A> {
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

impl<M: PlanarKernel<N>, const N: usize> Stages<N, GROUP> for UnrolledBatch<M, N> {
    #[inline(always)]
    fn at<P: Precision, V: KernelLanes<P>>(
        c: &[LinkConstants<V, N>; GROUP],
        count: usize,
        room: &mut SineRoom<P::Lanes, N, GROUP>,
        [q, qd]: [&[[V; N]; GROUP]; 2],
        inputs: StageInputs<'_, V, N, GROUP>,
    ) -> [[V; N]; GROUP] {
        let zero = V::splat(0.0);
        let units = count.div_ceil(V::BLOCKS);
        for (u, q) in q.iter().enumerate().take(units) {
            let [a, b] = unit_blocks(u, V::BLOCKS, count);
            for (i, q) in q.iter().enumerate() {
                [room.angles[a][i], room.angles[b][i]] = q.split();
            }
        }
        room.sin_cos::<P>(count);
        let mut out = [[zero; N]; GROUP];
        for u in 0..units {
            let mut trig = [[zero; 2]; N];
            room.trig(unit_blocks(u, V::BLOCKS, count), &mut trig);
            let (torque, [x, y, _]) = inputs.map_or(([zero; N], [zero; 3]), |(t, p)| (t[u], p[u]));
            out[u] = M::kernel(&c[u], &trig, &qd[u], &torque, [x, y]);
        }
        out
    }

    #[cold]
    fn step_error(
        &self,
        chain: usize,
        (t, x): (f64, &[f64]),
        h: f64,
        torque: &[f64],
        pivot: &dyn Fn(f64) -> [f64; 3],
    ) -> Error {
        let model = &self.models[chain];
        let mut first = None;
        let (q, qd): ([f64; N], [f64; N]) = (x[..N].try_into().expect("N"), x[N..].try_into().expect("N"));
        let (times, mut stage) = (stage_times(t, h), 0);
        increment::<f64, N, 1>(&[q], &[qd], h, |q: &[[f64; N]; 1], qd: &[[f64; N]; 1]| {
            let [x, y, _] = pivot(times[stage]);
            stage += 1;
            let inputs = Inputs {
                torque: SVector::<f64, N>::from_column_slice(torque),
                pivot_acceleration: Vector2::new(x, y),
            };
            let mut out = SVector::<f64, N>::zeros();
            let (q, qd) = (SVector::<f64, N>::from(q[0]), SVector::<f64, N>::from(qd[0]));
            match model.accelerations(&q, &qd, &inputs, &mut out) {
                Ok(()) => [out.data.0[0]],
                Err(error) => {
                    first.get_or_insert(error);
                    [[f64::NAN; N]]
                }
            }
        });
        first.unwrap_or(Error::NonFiniteState { t, h })
    }
}

impl<M: SpatialKernel<N>, const N: usize> Stages<N, { 2 * GROUP }> for UnrolledSpatialBatch<M, N> {
    #[inline(always)]
    fn at<P: Precision, V: KernelLanes<P>>(
        c: &[LinkConstants<V, N>; GROUP],
        count: usize,
        room: &mut SineRoom<P::Lanes, N, { 2 * GROUP }>,
        [q, qd]: [&[[V; N]; 2 * GROUP]; 2],
        inputs: StageInputs<'_, V, N, { 2 * GROUP }>,
    ) -> [[V; N]; 2 * GROUP] {
        let zero = V::splat(0.0);
        let units = count.div_ceil(V::BLOCKS);
        for u in 0..units {
            let [a, b] = unit_blocks(u, V::BLOCKS, count);
            for coordinate in 0..2 {
                for (i, q) in q[2 * u + coordinate].iter().enumerate() {
                    [room.angles[2 * a + coordinate][i], room.angles[2 * b + coordinate][i]] = q.split();
                }
            }
        }
        room.sin_cos::<P>(2 * count);
        let mut out = [[zero; N]; 2 * GROUP];
        for u in 0..units {
            let pair = unit_blocks(u, V::BLOCKS, count);
            let mut trig = [[[zero; 2]; N]; 2];
            room.trig(pair.map(|j| 2 * j), &mut trig[0]);
            room.trig(pair.map(|j| 2 * j + 1), &mut trig[1]);
            let rates = [qd[2 * u], qd[2 * u + 1]];
            let (torque, pivot) =
                inputs.map_or(([[zero; N]; 2], [zero; 3]), |(t, p)| ([t[2 * u], t[2 * u + 1]], p[u]));
            let mut accelerations = M::kernel(&c[u], &trig, &rates, &torque, pivot);
            let near = near_pole(&trig[0]);
            if V::any(near) {
                accelerations[0][0] = V::select(near, V::splat(f64::NAN), accelerations[0][0]);
            }
            [out[2 * u], out[2 * u + 1]] = accelerations;
        }
        out
    }

    #[cold]
    fn step_error(
        &self,
        chain: usize,
        (t, x): (f64, &[f64]),
        h: f64,
        torque: &[f64],
        pivot: &dyn Fn(f64) -> [f64; 3],
    ) -> Error {
        let model = &self.models[chain];
        let mut first = None;
        let arrays = |x: &[f64]| -> [[f64; N]; 2] {
            [x[..N].try_into().expect("N"), x[N..2 * N].try_into().expect("N")]
        };
        let (q, qd) = (arrays(&x[..2 * N]), arrays(&x[2 * N..]));
        let (times, mut stage) = (stage_times(t, h), 0);
        increment::<f64, N, 2>(&q, &qd, h, |q: &[[f64; N]; 2], qd: &[[f64; N]; 2]| {
            let p = pivot(times[stage]);
            stage += 1;
            let mut out = [[0.0; N]; 2];
            let (q, qd, result) = (q.as_flattened(), qd.as_flattened(), out.as_flattened_mut());
            match model.row_accelerations(q, qd, torque, p, result) {
                Ok(()) => out,
                Err(error) => {
                    first.get_or_insert(error);
                    [[f64::NAN; N]; 2]
                }
            }
        });
        first.unwrap_or(Error::NonFiniteState { t, h })
    }
}

/// Any closure `q̈(q, q̇)` (out of the hot path: a closure is compiled apart).
impl<V, const N: usize, const G: usize, F: FnMut(&[[V; N]; G], &[[V; N]; G]) -> [[V; N]; G]>
    Accelerations<V, N, G> for F
{
    fn at(&mut self, q: &[[V; N]; G], qd: &[[V; N]; G]) -> [[V; N]; G] {
        self(q, qd)
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
    /// `x = (θ, θ̇)` (`2N` entries: rad, rad/s) and time, with its joint torques `Q_i` (N·m,
    /// `B` rows of `N`; `None`: none) and pivot acceleration `p̈ = (ẍ, ÿ)` (m/s², `B` rows
    /// of 2; `None`: at rest) held over the call (a zero-order hold, as a controller
    /// applies its action): exactly what `steps` calls of [`Rk4`](crate::integrate::Rk4)'s
    /// `step` on [`FirstOrder::with_inputs`](crate::FirstOrder::with_inputs)`(model, inputs)`
    /// give for each chain alone, bit for bit (compensated time and state included), with
    /// the states kept in lanes from the first step to the last.
    ///
    /// Returns the chains that failed, in order, each with the error its own step gave (a
    /// non-finite state, input or acceleration); a failed chain is left at the start of the
    /// step that failed and the others go on. Errors: [`Error::InvalidStepSize`] for a zero
    /// or non-finite `h`, [`Error::LengthMismatch`] for a number of states other than `B`, a
    /// state of the wrong length or inputs not of `B` rows.
    pub fn integrate_rk4<D: Dim>(
        &self,
        states: &mut [State<D>],
        torque: Option<&[f64]>,
        pivot: Option<&[f64]>,
        h: f64,
        steps: usize,
    ) -> Result<Vec<Failure>>
    where
        DefaultAllocator: Allocator<D>,
        State<D>: Send,
    {
        let inputs = RunInputs { torque, pivot: Pivot::Held(pivot) };
        integrate::<_, _, D, N, 1, GROUP>(self, states, inputs, h, steps)
    }

    /// [`integrate_rk4`](Self::integrate_rk4) with chain `k`'s pivot moved by `drives[k]`
    /// (its acceleration `p̈(t)`, m/s², asked at each stage's time `t`, `t + h/2`, `t + h`
    /// as the chain's own RK4 asks) and its torques held: bit for bit `steps` steps of
    /// `Rk4` on `FirstOrder::with_inputs(model, Driven::new(drives[k], ConstantTorque(torque_k)))`
    /// ([`Driven`](crate::Driven), [`ConstantTorque`](crate::ConstantTorque)) of that chain
    /// alone. A Kapitza pendulum per chain ([`Harmonic::vertical`](crate::Harmonic::vertical)),
    /// say, each with its own amplitude and frequency.
    ///
    /// Failures and errors as [`integrate_rk4`](Self::integrate_rk4) (a drive whose
    /// acceleration is not finite fails its chain at that step), and
    /// [`Error::LengthMismatch`] for a number of drives other than `B`.
    pub fn integrate_rk4_driven<D: Dim, Dr: Drive<U2> + Sync>(
        &self,
        states: &mut [State<D>],
        drives: &[Dr],
        torque: Option<&[f64]>,
        h: f64,
        steps: usize,
    ) -> Result<Vec<Failure>>
    where
        DefaultAllocator: Allocator<D>,
        State<D>: Send,
    {
        integrate_driven::<_, _, U2, _, D, N, 1, GROUP>(self, states, drives, torque, (h, steps))
    }
}

impl<M: SpatialKernel<N>, const N: usize> UnrolledSpatialBatch<M, N> {
    /// `steps` steps of RK4 of size `h` (s) for every chain, each from its own state
    /// `x = (θ, φ, θ̇, φ̇)` (`4N` entries: rad, rad/s) and time, with its generalized torques
    /// `(σ_θ, σ_φ)` (N·m, `B` rows of `2N`; `None`: none) and pivot acceleration
    /// `p̈ = (ẍ, ÿ, z̈)` (m/s², `B` rows of 3; `None`: at rest) held over the call: exactly
    /// what `steps` calls of [`Rk4`](crate::integrate::Rk4)'s `step` on
    /// [`FirstOrder::with_inputs`](crate::FirstOrder::with_inputs)`(model, inputs)` give for
    /// each chain alone, bit for bit (compensated time and state included), with the states
    /// kept in lanes from the first step to the last.
    ///
    /// Returns the chains that failed, in order, each with the error its own step gave (a
    /// stage at a pole of the chart, `Error::SingularAngle`; a non-finite state, input or
    /// acceleration); a failed chain is left at the start of the step that failed and the
    /// others go on. Errors: [`Error::InvalidStepSize`] for a zero or non-finite `h`,
    /// [`Error::LengthMismatch`] for a number of states other than `B`, a state of the wrong
    /// length or inputs not of `B` rows.
    pub fn integrate_rk4<D: Dim>(
        &self,
        states: &mut [State<D>],
        torque: Option<&[f64]>,
        pivot: Option<&[f64]>,
        h: f64,
        steps: usize,
    ) -> Result<Vec<Failure>>
    where
        DefaultAllocator: Allocator<D>,
        State<D>: Send,
    {
        let inputs = RunInputs { torque, pivot: Pivot::Held(pivot) };
        integrate::<_, _, D, N, 2, { 2 * GROUP }>(self, states, inputs, h, steps)
    }

    /// [`integrate_rk4`](Self::integrate_rk4) with chain `k`'s pivot moved by `drives[k]`
    /// (its acceleration `p̈(t)`, m/s², asked at each stage's time as the chain's own RK4
    /// asks) and its torques held: bit for bit `steps` steps of `Rk4` on
    /// `FirstOrder::with_inputs(model, Driven::new(drives[k], ConstantTorque(torque_k)))` of
    /// that chain alone. Chains whirled by their top ends ([`Circle`](crate::Circle)), say,
    /// each with its own radius and speed.
    ///
    /// Failures and errors as [`integrate_rk4`](Self::integrate_rk4), and
    /// [`Error::LengthMismatch`] for a number of drives other than `B`.
    pub fn integrate_rk4_driven<D: Dim, Dr: Drive<U3> + Sync>(
        &self,
        states: &mut [State<D>],
        drives: &[Dr],
        torque: Option<&[f64]>,
        h: f64,
        steps: usize,
    ) -> Result<Vec<Failure>>
    where
        DefaultAllocator: Allocator<D>,
        State<D>: Send,
    {
        integrate_driven::<_, _, U3, _, D, N, 2, { 2 * GROUP }>(self, states, drives, torque, (h, steps))
    }
}

/// The run of `integrate_rk4_driven`: chain `k`'s pivot acceleration from `drives[k]` at
/// each stage's time (its `S` components, then zeros up to three).
fn integrate_driven<
    M,
    K,
    S: DimName,
    Dr: Drive<S> + Sync,
    D: Dim,
    const N: usize,
    const C: usize,
    const A: usize,
>(
    batch: &UnrolledBatch<M, N, K>,
    states: &mut [State<D>],
    drives: &[Dr],
    torque: Option<&[f64]>,
    (h, steps): (f64, usize),
) -> Result<Vec<Failure>>
where
    UnrolledBatch<M, N, K>: Stages<N, A>,
    DefaultAllocator: Allocator<D> + Allocator<S>,
    State<D>: Send,
{
    check_len("drives", drives, batch.len(), 1)?;
    let drive = |k: usize, t: f64| {
        let a = drives[k].acceleration(t);
        std::array::from_fn(|d| if d < S::DIM { a[d] } else { 0.0 })
    };
    integrate::<_, _, D, N, C, A>(batch, states, RunInputs { torque, pivot: Pivot::Driven(&drive) }, h, steps)
}

/// The run of `integrate_rk4` for a batch `batch` whose blocks hold `C`
/// arrays of `N` coordinates (`A = C · GROUP` a group): states `x = (q, q̇)` of `2CN`, the
/// torques rows of `CN`, the held pivot accelerations rows of [`Groups::SPACE`].
fn integrate<M, K, D: Dim, const N: usize, const C: usize, const A: usize>(
    batch: &UnrolledBatch<M, N, K>,
    states: &mut [State<D>],
    inputs: RunInputs<'_>,
    h: f64,
    steps: usize,
) -> Result<Vec<Failure>>
where
    UnrolledBatch<M, N, K>: Stages<N, A>,
    DefaultAllocator: Allocator<D>,
    State<D>: Send,
{
    debug_assert_eq!(A, C * GROUP);
    let (chains, m) = (batch.len(), C * N);
    let space = <UnrolledBatch<M, N, K> as Groups<N, A>>::SPACE;
    if !h.is_finite() || h == 0.0 {
        return Err(Error::InvalidStepSize { h });
    }
    if states.len() != chains {
        return Err(Error::LengthMismatch { what: "states", expected: chains, got: states.len() });
    }
    if let Some(s) = states.iter().find(|s| s.x().len() != 2 * m) {
        return Err(Error::LengthMismatch { what: "x", expected: 2 * m, got: s.x().len() });
    }
    if let Some(t) = inputs.torque {
        check_len("torque", t, chains, m)?;
    }
    if let Pivot::Held(Some(p)) = inputs.pivot {
        check_len("pivot", p, chains, space)?;
    }
    let solves = (4 * N).saturating_mul(steps);
    let failures =
        for_blocks_of::<{ GROUP * WIDTH }, _, _, _>(states, 1, solves, SineRoom::new, |room, g, states| {
            let first = GROUP * g;
            let count = states.len().div_ceil(WIDTH);
            let mut s: [Block<F64x4, N, C>; GROUP] = std::array::from_fn(|_| Block::default());
            for (j, (s, block)) in s.iter_mut().zip(states.chunks(WIDTH)).enumerate() {
                let parts: [_; WIDTH] = std::array::from_fn(|k| block[k.min(block.len() - 1)].parts());
                let entries = |j: usize, carry: bool| {
                    Lanes::from_fn(|k| if carry { parts[k].3[j] } else { parts[k].2[j] })
                };
                let arrays = |offset: usize, carry: bool| -> [[F64x4; N]; C] {
                    std::array::from_fn(|c| std::array::from_fn(|i| entries(offset + N * c + i, carry)))
                };
                let ids = block_chains::<WIDTH>(first + j, chains);
                let rows = |v: &[f64], per: usize, i: usize| Lanes::from_fn(|k| v[per * ids[k] + i]);
                *s = Block {
                    q: arrays(0, false),
                    qd: arrays(m, false),
                    q_carry: arrays(0, true),
                    qd_carry: arrays(m, true),
                    t: Lanes::from_fn(|k| parts[k].0),
                    t_carry: Lanes::from_fn(|k| parts[k].1),
                    torque: match inputs.torque {
                        Some(t) => std::array::from_fn(|c| std::array::from_fn(|i| rows(t, m, N * c + i))),
                        None => s.torque,
                    },
                    pivot: match inputs.pivot {
                        Pivot::Held(Some(p)) => {
                            std::array::from_fn(|d| if d < space { rows(p, space, d) } else { s.pivot[d] })
                        }
                        _ => s.pivot,
                    },
                };
            }
            let group = (&batch.blocks[..], first, count);
            let alive = if inputs.torque.is_some() || !matches!(inputs.pivot, Pivot::Held(None)) {
                rk4_run_simd::<M, K, f64, N, C, A, true>(batch, group, room, (h, steps), inputs.pivot, &mut s)
            } else {
                rk4_run_simd::<M, K, f64, N, C, A, false>(
                    batch,
                    group,
                    room,
                    (h, steps),
                    inputs.pivot,
                    &mut s,
                )
            };
            let mut failures = Vec::new();
            for (j, (s, block)) in s.iter().zip(states.chunks_mut(WIDTH)).enumerate() {
                for (k, state) in block.iter_mut().enumerate() {
                    let x = lane(&s.q, &s.q_carry, k).chain(lane(&s.qd, &s.qd_carry, k));
                    state.set_parts(s.t.0[k], s.t_carry.0[k], x);
                    if !alive[j][k] {
                        let chain = WIDTH * (first + j) + k;
                        let (torque, pivot) = inputs.of(chain, m, space);
                        let at = (state.t(), state.x().as_slice());
                        failures
                            .push(Failure { chain, error: batch.step_error(chain, at, h, &torque, &pivot) });
                    }
                }
            }
            failures
        });
    Ok(failures)
}

/// Lane `k`'s entries of `x` and their compensations `carry`, in order.
fn lane<'a, const N: usize, const K: usize>(
    x: &'a [[F64x4; N]; K],
    carry: &'a [[F64x4; N]; K],
    k: usize,
) -> impl Iterator<Item = (f64, f64)> + 'a {
    x.as_flattened().iter().zip(carry.as_flattened()).map(move |(x, carry)| (x.0[k], carry.0[k]))
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
    for _ in 0..steps {
        if let (true, Pivot::Driven(drive)) = (FORCED, pivot) {
            for (u, t) in t.iter().enumerate().take(units) {
                let blocks = unit_blocks(u, V::BLOCKS, count);
                let times = t.split();
                // Each block's lanes' pivot accelerations at stages 1, 2 and 4 (3 is 2's time).
                let at: [[[P::Lanes; 3]; 3]; 2] = std::array::from_fn(|half| {
                    let chains = block_chains::<WIDTH>(first + blocks[half], batch.len());
                    let t = P::flatten(std::slice::from_ref(&times[half]));
                    let p: [[[f64; 3]; 3]; WIDTH] = std::array::from_fn(|k| {
                        let times = stage_times(t[k].into(), h);
                        [0, 1, 3].map(|stage| drive(chains[k], times[stage]))
                    });
                    std::array::from_fn(|stage| {
                        std::array::from_fn(|d| P::lanes(|k| P::rounded(p[k][stage][d])))
                    })
                });
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
            // Σ (δ − δ): +0 in a lane whose increment is finite, NaN otherwise.
            let mut probe = zero;
            for d in dq[arrays.clone()].as_flattened().iter().chain(dqd[arrays.clone()].as_flattened()) {
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
pub(super) fn rk4_run_simd<
    M,
    K,
    P: Precision,
    const N: usize,
    const C: usize,
    const A: usize,
    const FORCED: bool,
>(
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
