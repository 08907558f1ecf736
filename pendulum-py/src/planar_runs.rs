//! `Chain.integrate` and `Chain.trajectory`: RK4 steps of many planar chains in lanes, their
//! torques and pivot accelerations held (`PlanarBatch::integrate_rk4` in double precision,
//! bit for bit each state alone; `integrate_rk4_f32` in single), in chunks of steps between
//! which Ctrl-C is looked at, the states sampled every so many steps if asked. The chunks
//! and samples (`run_as`, `in_chunks`) serve the directions' runs too.

use std::sync::atomic::{AtomicBool, Ordering};

use crate::drives::PlanarPivot;
use nalgebra::{DVector, Dyn};
use numpy::PyArray1;
use pendulum_core::batch::{Failure, PlanarBatch};
use pendulum_core::integrate::State;
use pendulum_experiment::Error;
use pyo3::prelude::*;

use crate::arrays::{Rows, array};
use crate::errors::{StatesError, StatesResult, numpy_index, run_error, unknown_precision};
use crate::interrupt::interruptible;
use crate::results;

/// Rods' solves per chunk of a batched integration: Ctrl-C is looked at between chunks
/// (a few milliseconds each).
const SOLVES_PER_CHUNK: usize = 1 << 20;

/// The steps of a run: `steps` of `h` (s) from the time `t0` (s), the states sampled at the
/// start, after every `every`-th step and after the last (`None`: only after the last).
#[derive(Debug, Clone, Copy)]
pub struct Plan {
    pub h: f64,
    pub steps: usize,
    pub every: Option<usize>,
    pub t0: f64,
}

impl Plan {
    /// The steps after which the states are sampled (0 for the start).
    fn samples(&self) -> Vec<usize> {
        match self.every {
            None => vec![self.steps],
            Some(every) => {
                let mut at: Vec<usize> = (0..self.steps).step_by(every).collect();
                at.push(self.steps);
                at
            }
        }
    }
}

/// A run's states `q`, `q̇` at its samples, one block of `count × n` numbers after another.
pub struct Samples<T> {
    pub q: Vec<T>,
    pub qd: Vec<T>,
}

/// The run of `Chain.integrate` (`plan.every` `None`: `(q, qd)` shaped as `q`) or
/// `Chain.trajectory` (`(t, q, qd)`, the samples along a first axis) of the states and
/// inputs `rows` (`q`, `qd`, torques, pivot accelerations) in `precision`: `double` for
/// `"float64"`, `single` for `"float32"`, each handed the `drives` (of the pivots, when
/// given): here for a few milliseconds' work, on a thread of its own that Ctrl-C can stop
/// otherwise. The planar runs are [`planar_rk4`] and [`planar_rk4_f32`].
pub fn run_as<'py, D: Send + 'static>(
    py: Python<'py>,
    chain: &pendulum_core::Chain<Dyn>,
    rows: [Rows; 4],
    (plan, drives): (Plan, D),
    precision: &str,
    double: RunOf<D, f64>,
    single: RunOf<D, f32>,
) -> PyResult<Bound<'py, PyAny>> {
    match precision {
        "float64" => {
            run_in(py, chain, rows, plan, move |c, rows, plan, stop| double(c, rows, drives, plan, stop))
        }
        "float32" => {
            run_in(py, chain, rows, plan, move |c, rows, plan, stop| single(c, rows, drives, plan, stop))
        }
        _ => Err(unknown_precision(precision)),
    }
}

/// A run in one precision from the rows (`q`, `qd`, torques, pivot accelerations) with the
/// drives `D`: [`planar_rk4`], [`planar_rk4_f32`], the directions' `rk4` and `rk4_f32`.
pub type RunOf<D, T> = fn(
    &pendulum_core::Chain<Dyn>,
    [&Rows; 4],
    D,
    Plan,
    &AtomicBool,
) -> pendulum_experiment::Result<Samples<T>>;

/// One precision's `run` of [`run_as`].
fn run_in<'py, T: numpy::Element + Copy + Send + 'static>(
    py: Python<'py>,
    chain: &pendulum_core::Chain<Dyn>,
    [q, qd, torque, pivot]: [Rows; 4],
    plan: Plan,
    run: impl FnOnce(
        &pendulum_core::Chain<Dyn>,
        [&Rows; 4],
        Plan,
        &AtomicBool,
    ) -> pendulum_experiment::Result<Samples<T>>
    + Send
    + 'static,
) -> PyResult<Bound<'py, PyAny>> {
    let (lead, width, count) = (q.lead.clone(), q.width, q.count());
    let times = plan.samples();
    let samples = if count == 0 {
        Samples { q: Vec::new(), qd: Vec::new() }
    } else {
        let chain = chain.clone();
        let work = move |stop: &AtomicBool| run(&chain, [&q, &qd, &torque, &pivot], plan, stop);
        let solves = count.saturating_mul(width).saturating_mul(4).saturating_mul(plan.steps);
        if solves <= SOLVES_PER_CHUNK {
            // A few milliseconds at most: here, without a thread of its own.
            work(&AtomicBool::new(false)).map_err(run_error)?
        } else {
            interruptible(py, "the integration", work)?.map_err(run_error)?
        }
    };
    let (q, qd) = (samples.q, samples.qd);
    if plan.every.is_none() {
        return Ok((array(py, q, &lead, &[width])?, array(py, qd, &lead, &[width])?)
            .into_pyobject(py)?
            .into_any());
    }
    let shape: Vec<usize> = std::iter::once(times.len()).chain(lead.iter().copied()).collect();
    let t = PyArray1::from_vec(py, times.iter().map(|&k| plan.t0 + k as f64 * plan.h).collect());
    let (q, qd) = (array(py, q, &shape, &[width])?, array(py, qd, &shape, &[width])?);
    Ok((t, q, qd).into_pyobject(py)?.into_any())
}

/// `plan` for the planar chain from each state of `q`, `qd` with its torques held and its
/// pivot acceleration held ([`PlanarBatch::integrate_rk4`]) or, given `drives` (one per
/// state), its pivot moved ([`PlanarBatch::integrate_rk4_driven`]): on every core, in
/// chunks (the same bits as one call). A failed state is an error naming its index.
pub fn planar_rk4(
    chain: &pendulum_core::Chain<Dyn>,
    [q, qd, torque, pivot]: [&Rows; 4],
    drives: Option<Vec<PlanarPivot>>,
    plan: Plan,
    stop: &AtomicBool,
) -> pendulum_experiment::Result<Samples<f64>> {
    let n = chain.links();
    let batch = PlanarBatch::repeated(chain.clone(), q.count()).map_err(core)?;
    let mut states: Vec<State<Dyn>> = q
        .data
        .chunks_exact(n)
        .zip(qd.data.chunks_exact(n))
        .map(|(q, qd)| State::new(plan.t0, DVector::from_iterator(2 * n, q.iter().chain(qd).copied())))
        .collect();
    let torque = Some(&torque.data[..]);
    in_chunks(
        (&q.lead, n, plan, stop),
        &mut states,
        |states, _, now| match drives.as_deref() {
            Some(drives) => batch.integrate_rk4_driven(states, drives, torque, plan.h, now),
            None => batch.integrate_rk4(states, torque, Some(&pivot.data), plan.h, now),
        },
        |states, samples| split(n, states.iter().map(|s| s.x().as_slice()), samples),
    )
}

/// [`planar_rk4`] in single precision ([`PlanarBatch::integrate_rk4_f32`], or
/// [`PlanarBatch::integrate_rk4_driven_f32`] given `drives`): the numbers rounded to `f32`
/// (one past its range is an error), the rounding compensation kept from chunk to chunk
/// (the same numbers as one call when held; driven, each chunk starts from its own time).
pub fn planar_rk4_f32(
    chain: &pendulum_core::Chain<Dyn>,
    [q, qd, torque, pivot]: [&Rows; 4],
    drives: Option<Vec<PlanarPivot>>,
    plan: Plan,
    stop: &AtomicBool,
) -> pendulum_experiment::Result<Samples<f32>> {
    let n = chain.links();
    let (torque, pivot) = (narrow(&torque.data)?, narrow(&pivot.data)?);
    let mut x = Vec::with_capacity(2 * q.data.len());
    for (q, qd) in q.data.chunks_exact(n).zip(qd.data.chunks_exact(n)) {
        x.extend(narrow(q)?);
        x.extend(narrow(qd)?);
    }
    let carry = vec![0.0f32; x.len()];
    let batch = PlanarBatch::repeated(chain.clone(), q.count()).map_err(core)?;
    in_chunks(
        (&q.lead, n, plan, stop),
        &mut (x, carry),
        |(x, carry), t, now| match drives.as_deref() {
            Some(drives) => {
                batch.integrate_rk4_driven_f32((x, carry), (t, drives), Some(&torque), plan.h, now)
            }
            None => batch.integrate_rk4_f32((x, carry), Some(&torque), Some(&pivot), plan.h, now),
        },
        |(x, _), samples| split(n, x.chunks_exact(2 * n), samples),
    )
}

/// `run(states, t, k)` of `k` steps from the time `t = t0 + j·h` (`j` steps before) over
/// the chunks of `plan` (about [`SOLVES_PER_CHUNK`] rods' solves each, ending at the
/// samples; the `f64` runs' states carry their own times), `stop` looked at before each, and
/// `sample(states, samples)` at the plan's samples; the first failure as the error naming
/// its state by its index in the leading shape `lead`.
pub fn in_chunks<S, T>(
    (lead, n, plan, stop): (&[usize], usize, Plan, &AtomicBool),
    states: &mut S,
    mut run: impl FnMut(&mut S, f64, usize) -> pendulum_core::Result<Vec<Failure>>,
    mut sample: impl FnMut(&S, &mut Samples<T>),
) -> pendulum_experiment::Result<Samples<T>> {
    let count: usize = lead.iter().product();
    let chunk = (SOLVES_PER_CHUNK / (4 * n * count).max(1)).max(1);
    let mut samples = Samples { q: Vec::new(), qd: Vec::new() };
    let mut done = 0;
    let times = plan.samples();
    for (k, &next) in times.iter().enumerate() {
        while done < next {
            if stop.load(Ordering::Relaxed) {
                return Err(Error::interrupted("the integration was interrupted"));
            }
            let now = chunk.min(next - done);
            let failures = run(states, plan.t0 + done as f64 * plan.h, now).map_err(core)?;
            if let Some(first) = failures.first() {
                let more = match failures.len() {
                    1 => String::new(),
                    k => format!(" ({} more states failed too)", k - 1),
                };
                let (index, error) = (numpy_index(first.chain, lead), &first.error);
                return Err(Error::failed(format!("integrate: state {index}: {error}{more}")));
            }
            done += now;
        }
        sample(states, &mut samples);
        if k == 0 {
            // Room for every sample at once, as large results are kept (`results`).
            results::reserve_times(&mut samples.q, times.len());
            results::reserve_times(&mut samples.qd, times.len());
        }
    }
    Ok(samples)
}

/// Rows of `(q, q̇)` (`n` numbers each) appended to the samples' `q` and `q̇`.
pub fn split<'a, T: Copy + 'a>(n: usize, rows: impl Iterator<Item = &'a [T]>, samples: &mut Samples<T>) {
    for row in rows {
        samples.q.extend_from_slice(&row[..n]);
        samples.qd.extend_from_slice(&row[n..2 * n]);
    }
}

/// `v` rounded to `f32`; a number past its range is an error
/// ([`SinglePrecisionOverflow`](pendulum_core::Error::SinglePrecisionOverflow)).
pub fn narrow(v: &[f64]) -> pendulum_experiment::Result<Vec<f32>> {
    rounded_rows(v, 1).map_err(|_| core(pendulum_core::Error::SinglePrecisionOverflow))
}

/// `v`, the rows of `count` states, rounded to `f32`: the one rounding of every `f32` call.
/// A number past `f32`'s range is its state's error
/// ([`SinglePrecisionOverflow`](pendulum_core::Error::SinglePrecisionOverflow)).
pub fn rounded_rows(v: &[f64], count: usize) -> StatesResult<Vec<f32>> {
    let out: Vec<f32> = v.iter().map(|&x| x as f32).collect();
    match out.iter().position(|x| !x.is_finite()) {
        None => Ok(out),
        Some(i) => {
            let row = i / (v.len() / count.max(1)).max(1);
            Err(StatesError::of_state(row, pendulum_core::Error::SinglePrecisionOverflow))
        }
    }
}

pub fn core(e: pendulum_core::Error) -> Error {
    Error::invalid(e.to_string())
}
