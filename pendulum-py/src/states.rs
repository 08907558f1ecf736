//! The models evaluated state by state on a call's rows (`Chain`'s accelerations,
//! Jacobians, terms and energies of the angle models, the directions' Jacobians): each
//! row the same computation whatever the thread, on every core for a large batch.

use nalgebra::{DMatrix, DVector, DefaultAllocator, Dyn};
use numpy::PyArray1;
use pendulum_core::{Derivatives, Inputs, Jacobians, Model, ModelAlloc};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;

use crate::arrays::{Rows, array};
use crate::detach::PARALLEL_FROM;
use crate::errors::{StatesError, StatesResult, core_error};

/// The inputs of one call: the states and inputs as rows, checked.
pub struct Batch {
    pub q: Rows,
    pub qd: Rows,
    pub torque: Rows,
    pub pivot: Rows,
}

/// One state's vectors and inputs for model `M`, filled row by row (allocated once per
/// thread, not per state).
struct State<M: Model<Dof = Dyn>>
where
    DefaultAllocator: ModelAlloc<M::Links, Dyn, M::Space>,
{
    q: DVector<f64>,
    qd: DVector<f64>,
    inputs: Inputs<Dyn, M::Space>,
}

impl<M: Model<Dof = Dyn>> State<M>
where
    DefaultAllocator: ModelAlloc<M::Links, Dyn, M::Space>,
{
    fn new(dof: usize) -> Self {
        Self { q: DVector::zeros(dof), qd: DVector::zeros(dof), inputs: Inputs::zeros(Dyn(dof)) }
    }

    /// Row `i` of the batch.
    fn load(&mut self, b: &Batch, i: usize) -> &mut Self {
        self.q.copy_from_slice(b.q.row(i));
        self.qd.copy_from_slice(b.qd.row(i));
        self.inputs.torque.copy_from_slice(b.torque.row(i));
        self.inputs.pivot_acceleration.copy_from_slice(b.pivot.row(i));
        self
    }
}

/// `count` rows of `width` numbers, row `i` written by `f(scratch, i, row)` with a
/// scratch from `init` per thread: on every core for a large batch (each row the same
/// computation whatever the thread, so the same bits), and the first failing row's error,
/// by its index.
pub fn rows<S, F>(count: usize, width: usize, init: impl Fn() -> S + Sync, f: F) -> StatesResult<Vec<f64>>
where
    F: Fn(&mut S, usize, &mut [f64]) -> pendulum_core::Result<()> + Sync,
{
    let mut out = vec![0.0; count * width];
    if width == 0 {
        return Ok(out);
    }
    let results: Vec<pendulum_core::Result<()>> = if count * width < PARALLEL_FROM {
        let mut scratch = init();
        out.chunks_mut(width).enumerate().map(|(i, row)| f(&mut scratch, i, row)).collect()
    } else {
        out.par_chunks_mut(width)
            .enumerate()
            .map_init(&init, |scratch, (i, row)| f(scratch, i, row))
            .collect()
    };
    if let Some((state, Err(error))) = results.into_iter().enumerate().find(|(_, r)| r.is_err()) {
        return Err(StatesError::of_state(state, error));
    }
    Ok(out)
}

/// `q̈` of every state, row after row.
pub fn accelerations<M: Model<Links = Dyn, Dof = Dyn> + Sync>(model: &M, b: &Batch) -> StatesResult<Vec<f64>>
where
    DefaultAllocator: ModelAlloc<Dyn, Dyn, M::Space>,
{
    let dof = b.q.width;
    rows(
        b.q.count(),
        dof,
        || (State::<M>::new(dof), DVector::zeros(dof)),
        |(state, qdd), i, row| {
            let s = state.load(b, i);
            model.accelerations(&s.q, &s.qd, &s.inputs, qdd)?;
            row.copy_from_slice(qdd.as_slice());
            Ok(())
        },
    )
}

/// `q̈`, `∂q̈/∂q` and `∂q̈/∂q̇` of every state (each matrix row-major).
pub fn jacobians<M: Derivatives<Links = Dyn, Dof = Dyn> + Sync>(
    model: &M,
    b: &Batch,
) -> StatesResult<[Vec<f64>; 3]>
where
    DefaultAllocator: ModelAlloc<Dyn, Dyn, M::Space> + nalgebra::allocator::Allocator<Dyn, M::Space>,
{
    let (count, dof) = (b.q.count(), b.q.width);
    let width = dof + 2 * dof * dof;
    let all = rows(
        count,
        width,
        || (State::<M>::new(dof), Jacobians::zeros(model)),
        |(state, jac), i, row| {
            let s = state.load(b, i);
            model.state_jacobians(&s.q, &s.qd, &s.inputs, jac)?;
            let (qdd, matrices) = row.split_at_mut(dof);
            qdd.copy_from_slice(jac.accelerations.as_slice());
            let (dq, dqd) = matrices.split_at_mut(dof * dof);
            // nalgebra is column-major; numpy rows.
            dq.copy_from_slice(jac.q.transpose().as_slice());
            dqd.copy_from_slice(jac.qd.transpose().as_slice());
            Ok(())
        },
    )?;
    Ok(three_parts(&all, count, dof))
}

/// Rows of `(q̈, ∂q̈/∂q, ∂q̈/∂q̇)` (`dof + 2 dof²` numbers each) as three arrays.
pub fn three_parts(all: &[f64], count: usize, dof: usize) -> [Vec<f64>; 3] {
    let width = dof + 2 * dof * dof;
    let mut out = [
        Vec::with_capacity(count * dof),
        Vec::with_capacity(count * dof * dof),
        Vec::with_capacity(count * dof * dof),
    ];
    for row in all.chunks(width.max(1)).take(count) {
        out[0].extend_from_slice(&row[..dof]);
        out[1].extend_from_slice(&row[dof..dof + dof * dof]);
        out[2].extend_from_slice(&row[dof + dof * dof..]);
    }
    out
}

/// Every term of one state: M, c, k, d, Q, q̈, T, U.
pub fn terms<M: Model<Links = Dyn, Dof = Dyn>>(py: Python<'_>, model: &M, b: &Batch) -> PyResult<Py<PyDict>>
where
    DefaultAllocator: ModelAlloc<Dyn, Dyn, M::Space>,
{
    let dof = b.q.width;
    let mut state = State::<M>::new(dof);
    let s = state.load(b, 0);
    let (q, qd, inputs) = (&s.q, &s.qd, &s.inputs);
    let mut qdd = DVector::zeros(dof);
    model.accelerations(q, qd, inputs, &mut qdd).map_err(core_error)?;
    let mut mass = DMatrix::zeros(dof, dof);
    model.mass_matrix(q, &mut mass);
    let vector = |f: &dyn Fn(&mut DVector<f64>)| {
        let mut out = DVector::zeros(dof);
        f(&mut out);
        out.as_slice().to_vec()
    };
    let d = PyDict::new(py);
    d.set_item("mass_matrix", array(py, mass.transpose().as_slice().to_vec(), &[dof, dof], &[])?)?;
    d.set_item("velocity_terms", PyArray1::from_vec(py, vector(&|o| model.velocity_terms(q, qd, o))))?;
    d.set_item("gravity_terms", PyArray1::from_vec(py, vector(&|o| model.gravity_terms(q, o))))?;
    d.set_item(
        "pivot_terms",
        PyArray1::from_vec(py, vector(&|o| model.pivot_terms(q, &inputs.pivot_acceleration, o))),
    )?;
    d.set_item(
        "generalized_forces",
        PyArray1::from_vec(py, vector(&|o| model.generalized_forces(q, qd, &inputs.torque, o))),
    )?;
    d.set_item("accelerations", PyArray1::from_vec(py, qdd.as_slice().to_vec()))?;
    d.set_item("kinetic_energy", model.kinetic_energy(q, qd))?;
    d.set_item("potential_energy", model.potential_energy(q))?;
    Ok(d.unbind())
}

/// Kinetic and potential energy of every state.
pub fn energies<M: Model<Links = Dyn, Dof = Dyn>>(model: &M, b: &Batch) -> (Vec<f64>, Vec<f64>)
where
    DefaultAllocator: ModelAlloc<Dyn, Dyn, M::Space>,
{
    let mut state = State::<M>::new(b.q.width);
    (0..b.q.count())
        .map(|i| {
            let s = state.load(b, i);
            (model.kinetic_energy(&s.q, &s.qd), model.potential_energy(&s.q))
        })
        .unzip()
}

/// [`pendulum_core::linearize`] of one model at the batch's first state.
pub fn linearize_with<M: Derivatives<Links = Dyn, Dof = Dyn>>(
    model: &M,
    b: &Batch,
    tolerance: f64,
) -> pendulum_core::Result<pendulum_core::StateSpace>
where
    DefaultAllocator: ModelAlloc<Dyn, Dyn, M::Space> + nalgebra::allocator::Allocator<Dyn, M::Space>,
{
    let mut state = State::<M>::new(b.q.width);
    let s = state.load(b, 0);
    pendulum_core::linearize(model, &s.q, &s.qd, &s.inputs, tolerance)
}
