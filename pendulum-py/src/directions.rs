//! `Chain`'s `model="directions"`: the 3D chain in unit link directions
//! ([`Directions`]), no angles and so no singularity where a link hangs straight down,
//! for many states per call through the batch of chains in SIMD lanes
//! ([`DirectionsBatch`]): accelerations in double or single precision, projected RK4 runs
//! and energies.
//!
//! A state is `q = (u_1, …, u_n)`, each rod's unit direction `(x, y, z)` from mass `i − 1`
//! to mass `i` (z up, the pivot mass 0), and `qd = (u̇_1, …, u̇_n)` (1/s); the pivot
//! acceleration `p̈` (m/s², three components) is held constant over a call, or a run's
//! pivot moved by a drive (`drives`).

use std::sync::atomic::AtomicBool;

use nalgebra::{DVector, Dyn, U3, Vector3};
use pendulum_core::Directions;
use pendulum_core::batch::DirectionsBatch;
use pendulum_core::drive::Drive;
use pendulum_core::integrate::State;
use pyo3::prelude::*;

use crate::arrays::Rows;
use crate::detach::maybe_detached;
use crate::drives::Pivot;
use crate::errors::{StatesResult, core_error, invalid, numpy_index};
use crate::planar_runs::{Plan, Samples, core, in_chunks, narrow, rounded_rows, split};
use crate::planar_states::{first_error, first_failure, in_place, tables_f32};
use crate::results;
use crate::states::Batch;

/// How far `|u_i|` may be from 1 in a state's directions: the rounding of directions made
/// from angles or positions in double precision is far inside, a state in other
/// coordinates (angles, positions) far outside.
pub const UNIT_TOLERANCE: f64 = 1e-6;

/// The pivot moving with the constant acceleration `p̈` from rest at the origin:
/// `p(t) = p̈ t²/2`, `ṗ(t) = p̈ t` (the chain feels only `p̈`).
#[derive(Debug, Clone, Copy)]
pub struct Accelerated(Vector3<f64>);

impl Accelerated {
    /// The pivot accelerated by `p̈ = (x, y, z)` (m/s², three numbers).
    pub fn new(acceleration: &[f64]) -> Self {
        Self(Vector3::from_column_slice(acceleration))
    }
}

impl Drive<U3> for Accelerated {
    fn position(&self, t: f64) -> Vector3<f64> {
        self.0 * (0.5 * t * t)
    }
    fn velocity(&self, t: f64) -> Vector3<f64> {
        self.0 * t
    }
    fn acceleration(&self, _t: f64) -> Vector3<f64> {
        self.0
    }
}

/// The batch of `chain` with one pivot acceleration per row of `pivot`: one model
/// repeated ([`DirectionsBatch::repeated`], its constants built once) when every row is
/// the same, as when none is given.
fn batch(
    chain: &pendulum_core::Chain<Dyn>,
    pivot: &Rows,
) -> pendulum_core::Result<DirectionsBatch<U3, Accelerated>> {
    let one = Directions::<U3>::new(chain.clone());
    let drive = |k: usize| Accelerated::new(pivot.row(k));
    let count = pivot.count();
    if (1..count).all(|k| pivot.row(k) == pivot.row(0)) {
        return DirectionsBatch::repeated(one.with_drive(drive(0)), count);
    }
    DirectionsBatch::new((0..count).map(|k| one.clone().with_drive(drive(k))).collect())
}

/// Checks that every link direction of `q` (rows of `width = 3n`, the states of leading
/// shape `lead`) is a unit vector to [`UNIT_TOLERANCE`]; the error names the link (from 1,
/// as the core's errors do) and the state (as numpy indexes it). A non-finite number is
/// left to the finiteness checks, which name it.
pub fn check_unit<T: Copy + Into<f64>>(q: &[T], width: usize, lead: &[usize]) -> PyResult<()> {
    for (state, row) in q.chunks_exact(width.max(1)).enumerate() {
        for (link, u) in row.chunks_exact(3).enumerate() {
            let norm = u.iter().map(|&c| c.into() * c.into()).sum::<f64>().sqrt();
            if norm.is_finite() && (norm - 1.0).abs() > UNIT_TOLERANCE {
                let (link, state) = (link + 1, numpy_index(state, lead));
                return Err(invalid(format!(
                    "q: link {link} of state {state} has |u| = {norm}, expected unit directions \
                     (model='directions': q holds each rod's direction (x, y, z), not angles)"
                )));
            }
        }
    }
    Ok(())
}

/// The states `(u, u̇)` of `q`, `qd` side by side, `6n` numbers a state (as a [`State`]
/// and the energies take them).
fn states(q: &Rows, qd: &Rows) -> Vec<f64> {
    let half = q.width;
    let mut x = Vec::with_capacity(2 * q.data.len());
    for (u, w) in q.data.chunks_exact(half.max(1)).zip(qd.data.chunks_exact(half.max(1))) {
        x.extend_from_slice(u);
        x.extend_from_slice(w);
    }
    x
}

/// `ü` (1/s²) of many states given as C-contiguous arrays `q` and `qd` (or none) of shape
/// `(B, 3n)`, one pivot acceleration `pivot` (m/s²) for all, one model repeated
/// ([`DirectionsBatch::accelerations_split`]): float64 read where numpy holds it and
/// written into the result array, the same numbers as [`accelerations`]. With `single`
/// ([`DirectionsBatch::accelerations_split_f32`]), float32 tables read in place and
/// float64 ones rounded in one pass each, float32 back. `None`: not this case.
pub fn accelerations_in_place<'py>(
    py: Python<'py>,
    chain: &pendulum_core::Chain<Dyn>,
    q: &Bound<'py, PyAny>,
    qd: Option<&Bound<'py, PyAny>>,
    pivot: Vector3<f64>,
    single: bool,
) -> PyResult<Option<Bound<'py, PyAny>>> {
    let width = 3 * chain.links();
    let model = Directions::<U3>::new(chain.clone()).with_drive(Accelerated(pivot));
    let batch =
        |numbers: usize| DirectionsBatch::repeated(model.clone(), numbers / width).map_err(core_error);
    if !single {
        return in_place(py, q, qd, width, |u, w, out| {
            check_unit(u, width, &[u.len() / width])?;
            let batch = batch(u.len())?;
            let failures = maybe_detached(py, u.len(), || batch.accelerations_split(0.0, u, w, out))
                .map_err(core_error)?;
            first_failure(&failures, u, w, u.len() / width)
        });
    }
    let run = |u: &[f32], w: &[f32], out: &mut [f32]| {
        check_unit(u, width, &[u.len() / width])?;
        let batch = batch(u.len())?;
        let failures = maybe_detached(py, u.len(), || batch.accelerations_split_f32(0.0, u, w, out))
            .map_err(core_error)?;
        first_failure(&failures, u, w, u.len() / width)
    };
    match in_place(py, q, qd, width, run)? {
        Some(out) => Ok(Some(out)),
        None => tables_f32(py, q, qd, width, run),
    }
}

/// `ü` (1/s²) of every state, rows of `3n`: [`DirectionsBatch::accelerations_split`], each
/// row bit for bit [`Directions::accelerations`] of that state alone.
pub fn accelerations(
    chain: &pendulum_core::Chain<Dyn>,
    [q, qd, pivot]: [&Rows; 3],
) -> StatesResult<Vec<f64>> {
    let mut out = vec![0.0; q.data.len()];
    if q.count() == 0 {
        return Ok(out);
    }
    first_error(&batch(chain, pivot)?.accelerations_split(0.0, &q.data, &qd.data, &mut out)?)?;
    Ok(out)
}

/// [`accelerations`] in single precision ([`DirectionsBatch::accelerations_split_f32`]):
/// the states rounded to `f32`, eight per AVX2 register.
pub fn accelerations_f32(
    chain: &pendulum_core::Chain<Dyn>,
    [q, qd, pivot]: [&Rows; 3],
) -> StatesResult<Vec<f32>> {
    let mut out = vec![0.0f32; q.data.len()];
    if q.count() == 0 {
        return Ok(out);
    }
    let (u, w) = (rounded_rows(&q.data, q.count())?, rounded_rows(&qd.data, q.count())?);
    first_error(&batch(chain, pivot)?.accelerations_split_f32(0.0, &u, &w, &mut out)?)?;
    Ok(out)
}

/// `ü`, `∂ü/∂u` and `∂ü/∂u̇` of every state in single precision:
/// [`DirectionsBatch::accelerations_split_f32`] and
/// [`DirectionsBatch::state_jacobians_split_f32`], the states rounded to `f32` (one past
/// its range is an error).
pub fn jacobians_f32(chain: &pendulum_core::Chain<Dyn>, b: &Batch) -> StatesResult<[Vec<f32>; 3]> {
    let (count, dof) = (b.q.count(), b.q.width);
    let mut udd = vec![0.0f32; count * dof];
    let (mut du, mut dw) = (results::zeros(count * dof * dof), results::zeros(count * dof * dof));
    if count > 0 {
        let (u, w) = (rounded_rows(&b.q.data, count)?, rounded_rows(&b.qd.data, count)?);
        let batch = batch(chain, &b.pivot)?;
        first_error(&batch.accelerations_split_f32(0.0, &u, &w, &mut udd)?)?;
        first_error(&batch.state_jacobians_split_f32(0.0, &u, &w, &mut du, &mut dw)?)?;
    }
    Ok([udd, du, dw])
}

/// `(T, U)` (J) of every state relative to the pivot ([`Directions::kinetic_energy`],
/// [`Directions::potential_energy`]).
pub fn energies(chain: &pendulum_core::Chain<Dyn>, [q, qd]: [&Rows; 2]) -> (Vec<f64>, Vec<f64>) {
    let model = Directions::<U3>::new(chain.clone());
    let x = states(q, qd);
    x.chunks_exact(2 * q.width.max(1))
        .map(|x| {
            let x = DVector::from_column_slice(x);
            (model.kinetic_energy(&x), model.potential_energy(&x))
        })
        .unzip()
}

/// `ü`, `∂ü/∂u` and `∂ü/∂u̇` (each row-major) of every state of `model="directions"`:
/// [`DirectionsBatch::accelerations_split`] and [`DirectionsBatch::state_jacobians_split`],
/// the lower blocks of each state's [`Directions::analytic_jacobian`](pendulum_core::Directions),
/// the Jacobian of the first-order system `(u̇, ẇ) = (w, ü)` in the directions' own three
/// components each (the constraint `|u_i| = 1` not imposed), the states on every core.
pub fn jacobians(chain: &pendulum_core::Chain<Dyn>, b: &Batch) -> StatesResult<[Vec<f64>; 3]> {
    let (count, dof) = (b.q.count(), b.q.width);
    let mut udd = vec![0.0; count * dof];
    let (mut du, mut dw) = (results::zeros(count * dof * dof), results::zeros(count * dof * dof));
    if count > 0 {
        let batch = batch(chain, &b.pivot)?;
        first_error(&batch.accelerations_split(0.0, &b.q.data, &b.qd.data, &mut udd)?)?;
        first_error(&batch.state_jacobians_split(0.0, &b.q.data, &b.qd.data, &mut du, &mut dw)?)?;
    }
    Ok([udd, du, dw])
}

/// The projected RK4 run (`Projected<Rk4>`) of `plan` from each state, its pivot
/// acceleration held or, given `drives` (one per state), its pivot moved:
/// [`DirectionsBatch::integrate_rk4`] in chunks, the states sampled as `plan` says (the
/// signature of the planar runs, the torques unused: the caller refuses them).
pub fn rk4(
    chain: &pendulum_core::Chain<Dyn>,
    rows: [&Rows; 4],
    drives: Option<Vec<Pivot>>,
    plan: Plan,
    stop: &AtomicBool,
) -> pendulum_experiment::Result<Samples<f64>> {
    runs(chain, rows, drives, (plan, Method::Rk4), stop)
}

/// [`rk4`] by the implicit rod midpoint step instead ([`DirectionsBatch::integrate_rod_midpoint`]:
/// `RodMidpoint`, its Newton iterations in SIMD lanes, each state's numbers bit for bit
/// its own).
pub fn rod_midpoint(
    chain: &pendulum_core::Chain<Dyn>,
    rows: [&Rows; 4],
    drives: Option<Vec<Pivot>>,
    plan: Plan,
    stop: &AtomicBool,
) -> pendulum_experiment::Result<Samples<f64>> {
    runs(chain, rows, drives, (plan, Method::RodMidpoint), stop)
}

/// How a run steps: [`rk4`] or [`rod_midpoint`] (in float64), [`rk4_f32`] or
/// [`rod_midpoint_f32`].
#[derive(Debug, Clone, Copy)]
enum Method {
    Rk4,
    RodMidpoint,
}

/// The run of `plan` by `method`, each pivot's acceleration held or, given `drives`, each
/// pivot moved.
fn runs(
    chain: &pendulum_core::Chain<Dyn>,
    [q, qd, _torque, pivot]: [&Rows; 4],
    drives: Option<Vec<Pivot>>,
    run: (Plan, Method),
    stop: &AtomicBool,
) -> pendulum_experiment::Result<Samples<f64>> {
    match drives {
        None => run_of(&batch(chain, pivot).map_err(core)?, [q, qd], run, stop),
        Some(drives) => run_of(&driven(chain, drives)?, [q, qd], run, stop),
    }
}

/// [`rk4`] in single precision ([`DirectionsBatch::integrate_rk4_f32`]): the numbers
/// rounded to `f32` (one past its range is an error), each chunk from its own start time.
pub fn rk4_f32(
    chain: &pendulum_core::Chain<Dyn>,
    rows: [&Rows; 4],
    drives: Option<Vec<Pivot>>,
    plan: Plan,
    stop: &AtomicBool,
) -> pendulum_experiment::Result<Samples<f32>> {
    runs_f32(chain, rows, drives, (plan, Method::Rk4), stop)
}

/// [`rod_midpoint`] in single precision ([`DirectionsBatch::integrate_rod_midpoint_f32`]:
/// the Newton iterations in `f32` lanes, a step they cannot take whole the state's own in
/// `f64`, rounded back), as [`rk4_f32`] takes and gives the numbers.
pub fn rod_midpoint_f32(
    chain: &pendulum_core::Chain<Dyn>,
    rows: [&Rows; 4],
    drives: Option<Vec<Pivot>>,
    plan: Plan,
    stop: &AtomicBool,
) -> pendulum_experiment::Result<Samples<f32>> {
    runs_f32(chain, rows, drives, (plan, Method::RodMidpoint), stop)
}

/// The run of `plan` by `method` in single precision, each pivot's acceleration held or,
/// given `drives`, each pivot moved.
fn runs_f32(
    chain: &pendulum_core::Chain<Dyn>,
    [q, qd, _torque, pivot]: [&Rows; 4],
    drives: Option<Vec<Pivot>>,
    run: (Plan, Method),
    stop: &AtomicBool,
) -> pendulum_experiment::Result<Samples<f32>> {
    match drives {
        None => run_f32_of(&batch(chain, pivot).map_err(core)?, [q, qd], run, stop),
        Some(drives) => run_f32_of(&driven(chain, drives)?, [q, qd], run, stop),
    }
}

/// The batch of `chain` with one drive per state.
fn driven(
    chain: &pendulum_core::Chain<Dyn>,
    drives: Vec<Pivot>,
) -> pendulum_experiment::Result<DirectionsBatch<U3, Pivot>> {
    let one = Directions::<U3>::new(chain.clone());
    DirectionsBatch::new(drives.into_iter().map(|d| one.clone().with_drive(d)).collect()).map_err(core)
}

/// The run of the chains of `batch`, whatever drives their pivots, by `method`.
fn run_of<Dr: Drive<U3> + Clone + Sync>(
    batch: &DirectionsBatch<U3, Dr>,
    [q, qd]: [&Rows; 2],
    (plan, method): (Plan, Method),
    stop: &AtomicBool,
) -> pendulum_experiment::Result<Samples<f64>> {
    let half = q.width;
    let mut states: Vec<State<Dyn>> = states(q, qd)
        .chunks_exact(2 * half.max(1))
        .map(|x| State::new(plan.t0, DVector::from_column_slice(x)))
        .collect();
    in_chunks(
        (&q.lead, batch.links(), plan, stop),
        &mut states,
        |states, _, now| match method {
            Method::Rk4 => batch.integrate_rk4(states, plan.h, now),
            Method::RodMidpoint => batch.integrate_rod_midpoint(states, plan.h, now),
        },
        |states, samples| split(half, states.iter().map(|s| s.x().as_slice()), samples),
    )
}

/// The single-precision run of the chains of `batch`, whatever drives their pivots, by
/// `method`.
fn run_f32_of<Dr: Drive<U3> + Clone + Sync>(
    batch: &DirectionsBatch<U3, Dr>,
    [q, qd]: [&Rows; 2],
    (plan, method): (Plan, Method),
    stop: &AtomicBool,
) -> pendulum_experiment::Result<Samples<f32>> {
    let half = q.width;
    let mut x = narrow(&states(q, qd))?;
    in_chunks(
        (&q.lead, batch.links(), plan, stop),
        &mut x,
        |x, t, now| match method {
            Method::Rk4 => batch.integrate_rk4_f32(x, t, plan.h, now),
            Method::RodMidpoint => batch.integrate_rod_midpoint_f32(x, t, plan.h, now),
        },
        |x, samples| split(half, x.chunks_exact(2 * half.max(1)), samples),
    )
}
