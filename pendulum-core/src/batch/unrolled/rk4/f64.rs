//! The `f64` runs: each chain's states as [`State`]s, bit for bit its own `Rk4`, with its
//! torques and pivot acceleration held or its pivot on its own drive.

use nalgebra::{DefaultAllocator, Dim, DimName, U2, U3, allocator::Allocator};

use super::{Block, Pivot, Stages, check_run, drive_of, rk4_run_group};
use crate::batch::unrolled::{
    GROUP, Groups, PlanarKernel, SineRoom, SpatialKernel, UnrolledBatch, UnrolledSpatialBatch,
};
use crate::batch::{F64x4, Failure, WIDTH, block_chains, for_blocks_of};
use crate::drive::Drive;
use crate::error::{Error, Result};
use crate::integrate::State;

/// A run's inputs: each chain's torques (`B` rows of `C·N`, N·m; `None`: none), held over
/// the run (a zero-order hold, as a controller applies its action), and its pivot's
/// acceleration.
#[derive(Clone, Copy)]
struct RunInputs<'a> {
    torque: Option<&'a [f64]>,
    pivot: Pivot<'a>,
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
            Pivot::Driven { drive, .. } => drive(chain, t),
        };
        (torque, pivot)
    }
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
    let drive = drive_of(drives, batch.len())?;
    let pivot = Pivot::Driven { drive: &drive, t0: None };
    integrate::<_, _, D, N, C, A>(batch, states, RunInputs { torque, pivot }, h, steps)
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
    let held = match inputs.pivot {
        Pivot::Held(pivot) => (inputs.torque, pivot),
        Pivot::Driven { .. } => (inputs.torque, None),
    };
    check_run(h, chains, [m, space], held)?;
    if states.len() != chains {
        return Err(Error::LengthMismatch { what: "states", expected: chains, got: states.len() });
    }
    if let Some(s) = states.iter().find(|s| s.x().len() != 2 * m) {
        return Err(Error::LengthMismatch { what: "x", expected: 2 * m, got: s.x().len() });
    }
    let forced = inputs.torque.is_some() || !matches!(inputs.pivot, Pivot::Held(None));
    let solves = (4 * N).saturating_mul(steps);
    let failures =
        for_blocks_of::<{ GROUP * WIDTH }, _, _, _>(states, 1, solves, SineRoom::new, |room, g, states| {
            let first = GROUP * g;
            let count = states.len().div_ceil(WIDTH);
            let mut s: [Block<F64x4, N, C>; GROUP] = std::array::from_fn(|_| Block::default());
            for (j, (s, block)) in s.iter_mut().zip(states.chunks(WIDTH)).enumerate() {
                let parts: [_; WIDTH] = std::array::from_fn(|k| block[k.min(block.len() - 1)].parts());
                let rows = parts.map(|(_, _, x, carry)| (x, carry));
                let times = parts.map(|(t, t_carry, ..)| (t, t_carry));
                *s = Block::from_rows(rows, times, block_chains::<WIDTH>(first + j, chains), held, space);
            }
            let group = (&batch.blocks[..], first, count);
            let alive = rk4_run_group::<M, K, f64, N, C, A>(
                batch,
                group,
                room,
                (h, steps),
                (inputs.pivot, forced),
                &mut s,
            );
            let mut failures = Vec::new();
            for (j, (s, block)) in s.iter().zip(states.chunks_mut(WIDTH)).enumerate() {
                for (k, state) in block.iter_mut().enumerate() {
                    state.set_parts(s.t.0[k], s.t_carry.0[k], s.row::<f64>(k));
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
