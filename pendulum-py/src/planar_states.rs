//! `Chain.accelerations`' routes for many planar states: the batch of chains
//! (`PlanarBatch`), in double precision with any inputs or in single precision without
//! torques, C-ordered `(B, n)` tables read where numpy holds them (`in_place`,
//! `tables_f32`: the directions' routes use them too).

use nalgebra::Dyn;
use numpy::{PyArray1, PyArray2, PyArrayMethods, PyUntypedArrayMethods};
use pendulum_core::batch::{Failure, PlanarBatch};
use pyo3::prelude::*;

use crate::detach::maybe_detached;
use crate::errors::{StatesError, StatesResult, core_error, invalid};
use crate::planar_runs::rounded_rows;
use crate::results;

/// `θ̈` of every planar state by the batch of chains ([`PlanarBatch::repeated`]) at the
/// `count` states `q`, `qd`, joint torques `torque` and pivot accelerations `pivot`, rows of
/// `n`, `n`, `n`, 2: the same numbers as the model's row by row, and the first failing
/// row's error, by its index.
pub fn planar_batch(
    chain: &pendulum_core::Chain<Dyn>,
    count: usize,
    [q, qd, torque, pivot]: [&[f64]; 4],
) -> StatesResult<Vec<f64>> {
    let batch = PlanarBatch::repeated(chain.clone(), count)?;
    let mut out = vec![0.0; q.len()];
    first_error(&batch.accelerations(q, qd, Some(torque), Some(pivot), &mut out)?)?;
    Ok(out)
}

/// `θ̈`, `∂θ̈/∂θ` and `∂θ̈/∂θ̇` (row-major) of every planar state by the batch of chains, at
/// the states of [`planar_batch`]: [`PlanarBatch::accelerations`] and
/// [`PlanarBatch::state_jacobians`] (in SIMD lanes), each state's numbers bit for bit the
/// model's alone, and the first failing row's error, by its index.
pub fn planar_jacobians(
    chain: &pendulum_core::Chain<Dyn>,
    count: usize,
    [q, qd, torque, pivot]: [&[f64]; 4],
) -> StatesResult<[Vec<f64>; 3]> {
    let n = chain.links();
    let batch = PlanarBatch::repeated(chain.clone(), count)?;
    let mut qdd = vec![0.0; q.len()];
    first_error(&batch.accelerations(q, qd, Some(torque), Some(pivot), &mut qdd)?)?;
    let (mut dq, mut dqd) = (results::zeros(count * n * n), results::zeros(count * n * n));
    first_error(&batch.state_jacobians(q, qd, Some(torque), Some(pivot), &mut dq, &mut dqd)?)?;
    Ok([qdd, dq, dqd])
}

/// The first of a batch's `failures` as the error, the failing state's (in single precision the
/// batch names an overflow `SinglePrecisionOverflow` itself).
pub fn first_error(failures: &[Failure]) -> StatesResult<()> {
    failures.first().map_or(Ok(()), |f| Err(StatesError::of_state(f.chain, f.error.clone())))
}

/// [`planar_batch`] in single precision ([`PlanarBatch::accelerations_f32`]): the states,
/// torques and pivot accelerations rounded to `f32`, the result in `f32`.
pub fn planar_batch_f32(
    chain: &pendulum_core::Chain<Dyn>,
    count: usize,
    [q, qd, torque, pivot]: [&[f64]; 4],
) -> StatesResult<Vec<f32>> {
    let batch = PlanarBatch::repeated(chain.clone(), count)?;
    let mut out = vec![0.0f32; q.len()];
    let round = |v: &[f64]| rounded_rows(v, count);
    let (q, qd, torque, pivot) = (round(q)?, round(qd)?, round(torque)?, round(pivot)?);
    first_error(&batch.accelerations_f32(&q, &qd, Some(&torque), Some(&pivot), &mut out)?)?;
    Ok(out)
}

/// [`planar_jacobians`] in single precision ([`PlanarBatch::accelerations_f32`] and
/// [`PlanarBatch::state_jacobians_f32`]): the states, torques and pivot accelerations
/// rounded to `f32`, the results in `f32`.
pub fn planar_jacobians_f32(
    chain: &pendulum_core::Chain<Dyn>,
    count: usize,
    [q, qd, torque, pivot]: [&[f64]; 4],
) -> StatesResult<[Vec<f32>; 3]> {
    let n = chain.links();
    let batch = PlanarBatch::repeated(chain.clone(), count)?;
    let round = |v: &[f64]| rounded_rows(v, count);
    let (q, qd, torque, pivot) = (round(q)?, round(qd)?, round(torque)?, round(pivot)?);
    let (torque, pivot) = (Some(&torque[..]), Some(&pivot[..]));
    let mut qdd = vec![0.0f32; q.len()];
    let (mut dq, mut dqd) = (results::zeros(count * n * n), results::zeros(count * n * n));
    let mut failures = batch.accelerations_f32(&q, &qd, torque, pivot, &mut qdd)?;
    failures.extend(batch.state_jacobians_f32(&q, &qd, torque, pivot, &mut dq, &mut dqd)?);
    first_error(&failures)?;
    Ok([qdd, dq, dqd])
}

/// A C-contiguous `(B, n)` float64 array as its `B` and its numbers rounded to `f32`;
/// `None` for any other array, or one with a number that is infinite in `f32`.
fn table_f32(a: &Bound<'_, PyAny>, n: usize) -> Option<(usize, Vec<f32>)> {
    let a = a.cast::<PyArray2<f64>>().ok()?.readonly();
    let [count, width] = [a.shape()[0], a.shape()[1]];
    // C order only: `as_slice` of a Fortran-ordered array is contiguous too.
    (width == n && a.is_c_contiguous()).then_some(())?;
    let numbers: Vec<f32> = a.as_slice().ok()?.iter().map(|&x| x as f32).collect();
    // An infinite number (given, or past f32's range) is the general path's to name.
    numbers.iter().all(|x| !x.is_infinite()).then_some((count, numbers))
}

/// `θ̈` in single precision of the states of a C-contiguous `(B, n)` float64 table `q`,
/// `qd` the same or absent, without torques or pivot acceleration, rounded to `f32` in one
/// pass over each array (float32 tables are read in place by [`planar_in_place`]). `None`:
/// not this case.
pub fn planar_table_f32<'py>(
    py: Python<'py>,
    chain: &pendulum_core::Chain<Dyn>,
    q: &Bound<'py, PyAny>,
    qd: Option<&Bound<'py, PyAny>>,
) -> PyResult<Option<Bound<'py, PyAny>>> {
    tables_f32(py, q, qd, chain.links(), |qs, qds, out| {
        let count = qs.len() / chain.links();
        let batch = PlanarBatch::repeated(chain.clone(), count).map_err(core_error)?;
        let failures = maybe_detached(py, qs.len(), || batch.accelerations_f32(qs, qds, None, None, out))
            .map_err(core_error)?;
        first_failure(&failures, qs, qds, count)
    })
}

/// `run(q, qd, out)` in single precision on the rows of a C-contiguous `(B, width)`
/// float64 table `q`, `qd` the same or absent (zeros), each rounded to `f32` in one pass,
/// into a new float32 `(B, width)` array. `None`: not this case (an array of another kind,
/// or a number past `f32`'s range: the general path names it).
pub fn tables_f32<'py>(
    py: Python<'py>,
    q: &Bound<'py, PyAny>,
    qd: Option<&Bound<'py, PyAny>>,
    width: usize,
    run: impl FnOnce(&[f32], &[f32], &mut [f32]) -> PyResult<()>,
) -> PyResult<Option<Bound<'py, PyAny>>> {
    let Some((count, qs)) = table_f32(q, width) else { return Ok(None) };
    let qds = match qd.map(|qd| table_f32(qd, width)) {
        None => vec![0.0; qs.len()],
        Some(Some((c, qds))) if c == count => qds,
        Some(_) => return Ok(None),
    };
    if count == 0 {
        return Ok(None);
    }
    let mut out = vec![0.0f32; qs.len()];
    run(&qs, &qds, &mut out)?;
    Ok(Some(PyArray1::from_vec(py, out).reshape([count, width])?.into_any()))
}

/// `θ̈` of many planar states given as one C-contiguous array `q` of `T` (float64, or
/// float32 for single precision) of shape `(B, n)`, `qd` the same or absent, without
/// torques or pivot acceleration: read where numpy holds them and written into the result
/// array, no copies, by `run` (`PlanarBatch::accelerations` or `accelerations_f32`: then
/// [`planar_batch`]'s numbers). `None`: not this case (the general path takes it, and its
/// errors).
pub fn planar_in_place<'py, T: numpy::Element + Copy + Into<f64> + Send + Sync + Default>(
    py: Python<'py>,
    chain: &pendulum_core::Chain<Dyn>,
    q: &Bound<'py, PyAny>,
    qd: Option<&Bound<'py, PyAny>>,
    run: impl Fn(&PlanarBatch, &[T], &[T], &mut [T]) -> pendulum_core::Result<Vec<Failure>> + Send + Sync,
) -> PyResult<Option<Bound<'py, PyAny>>> {
    in_place(py, q, qd, chain.links(), |qs, qds, os| {
        let count = qs.len() / chain.links();
        let batch = PlanarBatch::repeated(chain.clone(), count).map_err(core_error)?;
        let failures = maybe_detached(py, qs.len(), || run(&batch, qs, qds, os)).map_err(core_error)?;
        first_failure(&failures, qs, qds, count)
    })
}

/// The `failures` of a batch of `count` states (rows of `q`, `qd`) as the error, if any: a
/// non-finite number of `q` or `qd` named as the general path names it
/// ([`non_finite_input`]), else the first failure ([`first_error`]), naming its state.
pub fn first_failure<T: Copy + Into<f64>>(
    failures: &[Failure],
    q: &[T],
    qd: &[T],
    count: usize,
) -> PyResult<()> {
    if failures.is_empty() {
        return Ok(());
    }
    match non_finite_input(q, qd) {
        Some(error) => Err(error),
        None => first_error(failures).map_err(|e| e.named(&[count])),
    }
}

/// The general path's error for a non-finite number in `q` or `qd` ([`Rows::read`]'s
/// message, [`Rows::read`](crate::arrays::Rows)), if there is one.
pub fn non_finite_input<T: Copy + Into<f64>>(q: &[T], qd: &[T]) -> Option<PyErr> {
    [("q", q), ("qd", qd)].into_iter().find_map(|(what, values)| {
        let v = values.iter().map(|&v| v.into()).find(|v: &f64| !v.is_finite())?;
        Some(invalid(format!("{what}: {v} is not finite")))
    })
}

/// `run(q, qd, out)` on the rows of a C-contiguous array `q` of `T` of shape `(B, width)`
/// with `B ≥ 2`, `qd` the same or absent (zeros), read where numpy holds them, into a new
/// `(B, width)` array (`run` names a non-finite number by [`non_finite_input`]). `None`:
/// not this case (the general path takes it, and its errors).
pub fn in_place<'py, T: numpy::Element + Copy + Into<f64> + Default>(
    py: Python<'py>,
    q: &Bound<'py, PyAny>,
    qd: Option<&Bound<'py, PyAny>>,
    width: usize,
    run: impl FnOnce(&[T], &[T], &mut [T]) -> PyResult<()>,
) -> PyResult<Option<Bound<'py, PyAny>>> {
    let Ok(q) = q.cast::<PyArray2<T>>() else { return Ok(None) };
    let q = q.readonly();
    let [count, columns] = [q.shape()[0], q.shape()[1]];
    // C order only: `as_slice` of a Fortran-ordered array is contiguous too, column-major.
    let Ok(qs) = q.as_slice() else { return Ok(None) };
    if columns != width || count < 2 || !q.is_c_contiguous() {
        return Ok(None);
    }
    let given = match qd {
        None => None,
        Some(qd) => {
            let Ok(qd) = qd.cast::<PyArray2<T>>() else { return Ok(None) };
            if qd.shape() != [count, width] || !qd.is_c_contiguous() {
                return Ok(None);
            }
            Some(qd.readonly())
        }
    };
    let zeros;
    let qds: &[T] = match &given {
        Some(qd) => match qd.as_slice() {
            Ok(slice) => slice,
            Err(_) => return Ok(None),
        },
        None => {
            zeros = vec![T::default(); qs.len()];
            &zeros
        }
    };
    let out = PyArray2::<T>::zeros(py, [count, width], false);
    {
        let mut written = out.readwrite();
        run(qs, qds, written.as_slice_mut().map_err(|e| invalid(e.to_string()))?)?;
    }
    Ok(Some(out.into_any()))
}
