//! `pendulum.Chain`: a chain's parameters, and its models evaluated on numpy arrays —
//! accelerations, the terms of `M q̈ + c + k + d = Q`, energies and the analytic Jacobians —
//! for one state or a leading batch of them (state by state in `states`, many planar
//! states as a batch in `planar_states`, the 3D chain in directions in `directions`);
//! their RK4 runs (`integrate`, `trajectory`, in `planar_runs`); its normal modes and
//! linearisation.

use nalgebra::{DMatrix, Dyn, Vector3};
use numpy::PyArray1;
use pendulum_core::batch::PlanarBatch;
use pendulum_core::{PlanarTension, Spatial};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use crate::arrays::{Rows, array, per_link};
use crate::detach::maybe_detached;
use crate::directions;
use crate::drives::Given;
use crate::errors::{core_error, invalid, run_error, unknown_precision};
use crate::planar_runs::{Plan, RunOf, planar_rk4, planar_rk4_f32, run_as};
use crate::planar_states::{
    planar_batch, planar_batch_f32, planar_in_place, planar_jacobians, planar_jacobians_f32, planar_table_f32,
};
use crate::states::{self, Batch};
use pendulum_experiment::options::{expand, links};

/// A chain of point masses on massless rigid rods, hung from a pivot.
///
/// `Chain(masses, lengths, gravity=9.81, damping=0.0)`: masses in kg and rod lengths in m,
/// one number for every link or one per link (`n` from the longer list); gravity g in
/// m/s²; damping λ_i in N·m·s. Models: `"planar"` (angles θ_i from the downward vertical,
/// accelerations by the O(n) rod-tension solve), `"spatial"` (spherical angles θ_i from
/// −z and azimuths φ_i, q = (θ_1..θ_n, φ_1..φ_n); singular where a link is vertical) and
/// `"directions"` (3D without angles: q = (u_1..u_n), each rod's unit direction (x, y, z)
/// with z up, qd = (u̇_1..u̇_n) in 1/s; no singularity; accelerations, integrate,
/// trajectory, jacobians and energy).
#[pyclass(module = "pendulum._pendulum", name = "Chain", frozen)]
#[derive(Clone)]
pub struct Chain {
    pub inner: pendulum_core::Chain<Dyn>,
    /// The models, built once.
    planar: PlanarTension<Dyn>,
    spatial: Spatial<Dyn>,
}

/// Which model a call evaluates.
#[derive(Clone, Copy, PartialEq)]
enum Kind {
    Planar,
    Spatial,
}

impl Kind {
    /// The angle model `name`; `"directions"` is refused here (the calls that serve it
    /// read [`Route`]).
    fn of(name: &str) -> PyResult<Self> {
        match name {
            "planar" => Ok(Self::Planar),
            "spatial" => Ok(Self::Spatial),
            "directions" => Err(invalid(
                "model: 'directions' serves accelerations, integrate, trajectory, jacobians and \
                 energy; this call takes 'planar' or 'spatial'",
            )),
            _ => Err(invalid(format!("model: '{name}' is none of 'planar', 'spatial', 'directions'"))),
        }
    }

    /// Coordinates of a chain of `n` links, and the pivot's components.
    fn sizes(self, n: usize) -> (usize, usize) {
        match self {
            Self::Planar => (n, 2),
            Self::Spatial => (2 * n, 3),
        }
    }
}

/// The model of a call that serves the chain in unit directions too.
#[derive(Clone, Copy, PartialEq)]
enum Route {
    Angles(Kind),
    /// `model="directions"` (the `directions` module).
    Directions,
}

impl Route {
    fn of(name: &str) -> PyResult<Self> {
        match name {
            "directions" => Ok(Self::Directions),
            _ => Kind::of(name).map(Self::Angles),
        }
    }
}

impl Chain {
    /// `Chain.jacobians(..., precision="float32")`: the planar model
    /// ([`planar_jacobians_f32`]) or the directions ([`directions::jacobians_f32`]) in single
    /// precision.
    fn jacobians_f32<'py>(
        &self,
        py: Python<'py>,
        route: Route,
        q: &Bound<'py, PyAny>,
        qd: Option<&Bound<'py, PyAny>>,
        torque: Option<&Bound<'py, PyAny>>,
        pivot_acceleration: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        if route == Route::Directions {
            let b = self.directions_rows(q, qd, torque, pivot_acceleration)?;
            let out =
                maybe_detached(py, b.q.data.len() * b.q.width, || directions::jacobians_f32(&self.inner, &b))
                    .map_err(|e| e.named(&b.q.lead))?;
            return jacobian_arrays(py, out, &b);
        }
        if route != Route::Angles(Kind::Planar) {
            return Err(invalid("precision: 'float32' Jacobians serve model='planar' and 'directions' only"));
        }
        let b = self.batch(Kind::Planar, q, qd, torque, pivot_acceleration)?;
        let out = maybe_detached(py, b.q.data.len() * b.q.width, || {
            planar_jacobians_f32(
                &self.inner,
                b.q.count(),
                [&b.q.data, &b.qd.data, &b.torque.data, &b.pivot.data],
            )
        })
        .map_err(|e| e.named(&b.q.lead))?;
        jacobian_arrays(py, out, &b)
    }

    /// `Chain.accelerations(..., precision="float32")`: the planar model in single
    /// precision ([`planar_batch_f32`]).
    fn accelerations_f32<'py>(
        &self,
        py: Python<'py>,
        kind: Kind,
        q: &Bound<'py, PyAny>,
        qd: Option<&Bound<'py, PyAny>>,
        torque: Option<&Bound<'py, PyAny>>,
        pivot_acceleration: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        if kind != Kind::Planar {
            return Err(invalid("precision: 'float32' serves model='planar' only"));
        }
        if torque.is_none() && pivot_acceleration.is_none() {
            let single = |b: &PlanarBatch, q: &[f32], qd: &[f32], out: &mut [f32]| {
                b.accelerations_f32(q, qd, None, None, out)
            };
            if let Some(out) = planar_in_place(py, &self.inner, q, qd, single)? {
                return Ok(out);
            }
            if let Some(out) = planar_table_f32(py, &self.inner, q, qd)? {
                return Ok(out);
            }
        }
        let b = self.batch(Kind::Planar, q, qd, torque, pivot_acceleration)?;
        let out = maybe_detached(py, b.q.data.len(), || {
            planar_batch_f32(&self.inner, b.q.count(), [&b.q.data, &b.qd.data, &b.torque.data, &b.pivot.data])
        })
        .map_err(|e| e.named(&b.q.lead))?;
        Ok(array(py, out, &b.q.lead, &[b.q.width])?.into_any())
    }

    fn batch(
        &self,
        kind: Kind,
        q: &Bound<'_, PyAny>,
        qd: Option<&Bound<'_, PyAny>>,
        torque: Option<&Bound<'_, PyAny>>,
        pivot: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Batch> {
        let (dof, space) = kind.sizes(self.inner.links());
        let q = Rows::read("q", q, dof)?;
        let qd = Rows::read_like("qd", qd, dof, &q)?;
        let torque = Rows::read_like("torque", torque, dof, &q)?;
        let pivot = Rows::read_like("pivot_acceleration", pivot, space, &q)?;
        Ok(Batch { q, qd, torque, pivot })
    }

    /// `integrate` and `trajectory`: the planar model's run of `plan` from the states `q`
    /// (`qd`, torques and pivot accelerations as for `accelerations`), in `precision`, or
    /// the directions' projected RK4 run in double precision.
    fn run<'py>(
        &self,
        py: Python<'py>,
        [q]: [&Bound<'py, PyAny>; 1],
        [qd, torque, pivot]: [Option<&Bound<'py, PyAny>>; 3],
        (plan, drive): (Plan, Option<Given>),
        (model, precision, method): (&str, &str, &str),
    ) -> PyResult<Bound<'py, PyAny>> {
        let route = Route::of(model)?;
        if route == Route::Angles(Kind::Spatial) {
            return Err(invalid("integrate: serves model='planar' and model='directions'"));
        }
        let implicit = match method {
            "rk4" => false,
            "rod_midpoint" if route != Route::Directions => {
                return Err(invalid("method: 'rod_midpoint' steps model='directions' (planar runs are RK4)"));
            }
            "rod_midpoint" => true,
            _ => return Err(invalid(format!("method: {method:?} is not 'rk4' or 'rod_midpoint'"))),
        };
        if !(plan.h.is_finite() && plan.h > 0.0) {
            return Err(invalid(format!("h: {} is not a positive time step (s)", plan.h)));
        }
        if !plan.t0.is_finite() {
            return Err(invalid(format!("t0: {} is not a finite time (s)", plan.t0)));
        }
        if drive.is_some() && pivot.is_some_and(|p| !p.is_none()) {
            return Err(invalid("pivot_acceleration: a drive moves the pivot; give one or the other"));
        }
        if route == Route::Directions {
            let b = self.directions_rows(q, qd, torque, pivot)?;
            let drives = drive.map(|d| d.spatial(&b.q.lead)).transpose()?;
            let rows = [b.q, b.qd, b.torque, b.pivot];
            let (double, single): (RunOf<_, f64>, RunOf<_, f32>) = if implicit {
                (directions::rod_midpoint, directions::rod_midpoint_f32)
            } else {
                (directions::rk4, directions::rk4_f32)
            };
            return run_as(py, &self.inner, rows, (plan, drives), precision, double, single);
        }
        let b = self.batch(Kind::Planar, q, qd, torque, pivot)?;
        let drives = drive.map(|d| d.planar(&b.q.lead)).transpose()?;
        let rows = [b.q, b.qd, b.torque, b.pivot];
        run_as(py, &self.inner, rows, (plan, drives), precision, planar_rk4, planar_rk4_f32)
    }

    /// The states of `model="directions"`: `q` unit directions and `qd` their rates, rows
    /// of `3n`; the pivot accelerations rows of 3; no torques.
    fn directions_rows(
        &self,
        q: &Bound<'_, PyAny>,
        qd: Option<&Bound<'_, PyAny>>,
        torque: Option<&Bound<'_, PyAny>>,
        pivot: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Batch> {
        if torque.is_some_and(|t| !t.is_none()) {
            return Err(invalid("torque: model='directions' takes no joint torques"));
        }
        let width = 3 * self.inner.links();
        let q = Rows::read("q", q, width)?;
        directions::check_unit(&q.data, width, &q.lead)?;
        let qd = Rows::read_like("qd", qd, width, &q)?;
        let torque = Rows::read_like("torque", None, width, &q)?;
        let pivot = Rows::read_like("pivot_acceleration", pivot, 3, &q)?;
        Ok(Batch { q, qd, torque, pivot })
    }

    /// `Chain.accelerations(..., model="directions")`: `ü` (1/s²) shaped like `q`.
    fn directions_accelerations<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        [qd, torque, pivot]: [Option<&Bound<'py, PyAny>>; 3],
        precision: &str,
    ) -> PyResult<Bound<'py, PyAny>> {
        let known = matches!(precision, "float64" | "float32");
        if known && torque.is_none_or(|t| t.is_none()) {
            // One pivot acceleration for all (or none): the states read in place.
            let pivot = match pivot.filter(|p| !p.is_none()) {
                None => Some(Vector3::zeros()),
                Some(p) => Rows::read("pivot_acceleration", p, 3)
                    .ok()
                    .filter(|p| p.lead.is_empty())
                    .map(|p| Vector3::from_column_slice(&p.data)),
            };
            if let Some(pivot) = pivot
                && let Some(out) =
                    directions::accelerations_in_place(py, &self.inner, q, qd, pivot, precision == "float32")?
            {
                return Ok(out);
            }
        }
        let b = self.directions_rows(q, qd, torque, pivot)?;
        let rows = [&b.q, &b.qd, &b.pivot];
        let (lead, width) = (&b.q.lead, [b.q.width]);
        let numbers = b.q.data.len();
        match precision {
            "float64" => {
                let out = maybe_detached(py, numbers, || directions::accelerations(&self.inner, rows));
                Ok(array(py, out.map_err(|e| e.named(lead))?, lead, &width)?.into_any())
            }
            "float32" => {
                let out = maybe_detached(py, numbers, || directions::accelerations_f32(&self.inner, rows));
                Ok(array(py, out.map_err(|e| e.named(lead))?, lead, &width)?.into_any())
            }
            _ => Err(unknown_precision(precision)),
        }
    }
}

/// Evaluates `$body` with `$m` the chain's model of `$kind` (generic over it).
macro_rules! with_model {
    ($chain:expr, $kind:expr, |$m:ident| $body:expr) => {
        match $kind {
            Kind::Planar => {
                let $m = &$chain.planar;
                $body
            }
            Kind::Spatial => {
                let $m = &$chain.spatial;
                $body
            }
        }
    };
}

#[pymethods]
impl Chain {
    #[new]
    #[pyo3(signature = (masses, lengths, gravity = 9.81, damping = None))]
    fn new(
        masses: &Bound<'_, PyAny>,
        lengths: &Bound<'_, PyAny>,
        gravity: f64,
        damping: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        // One number each: one link (a pendulum), unlike a run's default of 3.
        let (m, l) = (per_link("masses", masses)?, per_link("lengths", lengths)?);
        let n = m.len().max(l.len());
        let (n, m, l) = links(Some(n), m, l).map_err(run_error)?;
        let chain = pendulum_core::Chain::<Dyn>::new(&m, &l, gravity).map_err(core_error)?;
        let chain = match damping.filter(|d| !d.is_none()) {
            Some(d) => {
                let damping = expand("damping", per_link("damping", d)?, n).map_err(run_error)?;
                chain.with_damping(&damping).map_err(core_error)?
            }
            None => chain,
        };
        Ok(Self {
            planar: PlanarTension::new(chain.clone()),
            spatial: Spatial::new(chain.clone()),
            inner: chain,
        })
    }

    /// Number of links.
    #[getter]
    fn n(&self) -> usize {
        self.inner.links()
    }

    /// Masses m_i, kg.
    #[getter]
    fn masses<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.inner.masses().as_slice())
    }

    /// Rod lengths l_i, m.
    #[getter]
    fn lengths<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.inner.lengths().as_slice())
    }

    /// Gravity g, m/s².
    #[getter]
    fn gravity(&self) -> f64 {
        self.inner.gravity()
    }

    /// Damping λ_i, N·m·s.
    #[getter]
    fn damping<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.inner.damping().as_slice())
    }

    fn __repr__(&self) -> String {
        let c = &self.inner;
        format!(
            "Chain(n={}, length={} m, mass={} kg, gravity={} m/s²)",
            c.links(),
            c.lengths().sum(),
            c.masses().sum(),
            c.gravity()
        )
    }

    fn __eq__(&self, other: &Self) -> bool {
        self.inner == other.inner
    }

    /// Pickles as its parameters.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let py = slf.py();
        let c = &slf.get().inner;
        let args = (
            c.masses().as_slice().to_vec(),
            c.lengths().as_slice().to_vec(),
            c.gravity(),
            c.damping().as_slice().to_vec(),
        );
        Ok((slf.get_type().into_any(), args.into_pyobject(py)?))
    }

    /// The accelerations q̈ (rad/s²) of the states `q` (rad) with rates `qd` (rad/s),
    /// torques σ (N·m) and pivot acceleration p̈ (m/s²; 2 components planar, 3 spatial),
    /// by `model` ("planar", "spatial" or "directions"). `q` may hold many states along
    /// leading axes, shape `(..., dof)`; `qd`, `torque` (default zeros) are one row for
    /// all or one per state, likewise `pivot_acceleration`. Returns an array shaped like
    /// `q`. `precision="float32"` (planar, or directions) computes in
    /// single precision, eight states per SIMD register, and returns float32: within about
    /// 1e-5 of the largest acceleration (docs/ensembles.md). `model="directions"`: `q` the
    /// rods' unit directions (dof = 3n, each within 1e-6 of length 1), `qd` their rates,
    /// the result `ü` (1/s²); no torques.
    #[pyo3(signature = (q, qd = None, torque = None, pivot_acceleration = None, *, model = "planar", precision = "float64"))]
    #[allow(clippy::too_many_arguments)] // Python's keyword arguments
    fn accelerations<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        qd: Option<&Bound<'py, PyAny>>,
        torque: Option<&Bound<'py, PyAny>>,
        pivot_acceleration: Option<&Bound<'py, PyAny>>,
        model: &str,
        precision: &str,
    ) -> PyResult<Bound<'py, PyAny>> {
        let kind = match Route::of(model)? {
            Route::Angles(kind) => kind,
            Route::Directions => {
                return self.directions_accelerations(py, q, [qd, torque, pivot_acceleration], precision);
            }
        };
        match precision {
            "float64" => {}
            "float32" => return self.accelerations_f32(py, kind, q, qd, torque, pivot_acceleration),
            _ => return Err(unknown_precision(precision)),
        }
        if kind == Kind::Planar
            && torque.is_none()
            && pivot_acceleration.is_none()
            && let Some(out) = planar_in_place(py, &self.inner, q, qd, |b, q: &[f64], qd, out| {
                b.accelerations(q, qd, None, None, out)
            })?
        {
            return Ok(out);
        }
        let b = self.batch(kind, q, qd, torque, pivot_acceleration)?;
        let numbers = b.q.data.len();
        let out = maybe_detached(py, numbers, || match kind {
            // Many planar states: the SIMD batch, four states per lane group.
            Kind::Planar if b.q.count() > 1 => {
                planar_batch(&self.inner, b.q.count(), [&b.q.data, &b.qd.data, &b.torque.data, &b.pivot.data])
            }
            _ => with_model!(self, kind, |m| states::accelerations(m, &b)),
        })
        .map_err(|e| e.named(&b.q.lead))?;
        Ok(array(py, out, &b.q.lead, &[b.q.width])?.into_any())
    }

    /// `(q, qd)` after `steps` steps of classical RK4 of `h` seconds from each state, with
    /// its joint torques (N·m) and pivot acceleration (m/s²) held over the call (none: the
    /// chain free; planar model): many states at once, four per SIMD register (eight with AVX-512) and on every
    /// core, each bit for bit what the chain alone would give (docs/ensembles.md).
    /// `drive` (`pendulum.Harmonic`, or `pendulum.Circle` for directions) moves each
    /// state's pivot within the call instead, its parameters one for all or one per state,
    /// from the time `t0` (s; pass the end of one call as the start of the next).
    /// `model="directions"` steps the 3D chain in directions by RK4 with each rod put back
    /// to unit length after every step (no torques), or, with
    /// `method="rod_midpoint"`, by the implicit rod midpoint step: stable at any `h`, the
    /// rods exactly rigid, a free chain's energy kept to the Newton tolerance
    /// (docs/integrators.md), its Newton iterations four or eight states per SIMD register.
    /// `precision="float32"` steps eight states per register in single precision and
    /// returns float32 (its error against float64 in docs/ensembles.md; the rod midpoint's
    /// grows as the steps shrink, so in float32 it is for long steps). A state whose step
    /// is not finite raises RuntimeError naming it; Ctrl-C stops the call.
    #[pyo3(signature = (q, qd = None, torque = None, pivot_acceleration = None, *, h, steps = 1, model = "planar", precision = "float64", drive = None, t0 = 0.0, method = "rk4"))]
    #[allow(clippy::too_many_arguments)] // Python's keyword arguments
    fn integrate<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        qd: Option<&Bound<'py, PyAny>>,
        torque: Option<&Bound<'py, PyAny>>,
        pivot_acceleration: Option<&Bound<'py, PyAny>>,
        h: f64,
        steps: i64,
        model: &str,
        precision: &str,
        drive: Option<&Bound<'py, PyAny>>,
        t0: f64,
        method: &str,
    ) -> PyResult<Bound<'py, PyAny>> {
        let plan = Plan { h, steps: count("steps", steps)?, every: None, t0 };
        let given = (plan, Given::read(drive)?);
        self.run(py, [q], [qd, torque, pivot_acceleration], given, (model, precision, method))
    }

    /// `(t, q, qd)`: `integrate`'s run sampled at the start, after every `every`-th step and
    /// after the last: `t` (s, from `t0`) of shape `(samples,)`, `q` and `qd` of shape
    /// `(samples, ...)` with the states' own shape after the first axis.
    #[pyo3(signature = (q, qd = None, torque = None, pivot_acceleration = None, *, h, steps, every = 1, model = "planar", precision = "float64", drive = None, t0 = 0.0, method = "rk4"))]
    #[allow(clippy::too_many_arguments)] // Python's keyword arguments
    fn trajectory<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        qd: Option<&Bound<'py, PyAny>>,
        torque: Option<&Bound<'py, PyAny>>,
        pivot_acceleration: Option<&Bound<'py, PyAny>>,
        h: f64,
        steps: i64,
        every: i64,
        model: &str,
        precision: &str,
        drive: Option<&Bound<'py, PyAny>>,
        t0: f64,
        method: &str,
    ) -> PyResult<Bound<'py, PyAny>> {
        let every = match count("every", every)? {
            0 => return Err(invalid("every: 0 is not a number of steps (1 or more)")),
            every => every,
        };
        let plan = Plan { h, steps: count("steps", steps)?, every: Some(every), t0 };
        let given = (plan, Given::read(drive)?);
        self.run(py, [q], [qd, torque, pivot_acceleration], given, (model, precision, method))
    }

    /// `(qdd, dqdd_dq, dqdd_dqd)`: the accelerations (rad/s²) and their analytic Jacobians
    /// by the coordinates (1/s²) and the rates (1/s), entry `[..., a, b]` = ∂q̈_a/∂x_b; the
    /// states as for `accelerations`. Planar states go through the batch of chains, in SIMD
    /// lanes (`qdd` is `accelerations`' q̈). `model="directions"`: `ü` and its derivatives by the
    /// directions' and the rates' three components each, the Jacobian of the first-order
    /// system `(u̇, ẇ) = (w, ü)` (the constraint `|u_i| = 1` not imposed).
    /// `precision="float32"` (planar, or directions) computes in single
    /// precision, eight states per SIMD register, and returns float32: within a few parts
    /// per million of the largest entry (docs/ensembles.md).
    #[pyo3(signature = (q, qd = None, torque = None, pivot_acceleration = None, *, model = "planar", precision = "float64"))]
    #[allow(clippy::too_many_arguments)]
    fn jacobians<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        qd: Option<&Bound<'py, PyAny>>,
        torque: Option<&Bound<'py, PyAny>>,
        pivot_acceleration: Option<&Bound<'py, PyAny>>,
        model: &str,
        precision: &str,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let route = Route::of(model)?;
        match precision {
            "float64" => {}
            "float32" => return self.jacobians_f32(py, route, q, qd, torque, pivot_acceleration),
            _ => return Err(unknown_precision(precision)),
        }
        let b = match route {
            Route::Angles(kind) => self.batch(kind, q, qd, torque, pivot_acceleration)?,
            Route::Directions => self.directions_rows(q, qd, torque, pivot_acceleration)?,
        };
        let [qdd, dq, dqd] = maybe_detached(py, b.q.data.len() * b.q.width, || match route {
            // Planar states, one or many: the SIMD batch (`accelerations`' numbers for q̈).
            Route::Angles(Kind::Planar) if b.q.count() > 0 => planar_jacobians(
                &self.inner,
                b.q.count(),
                [&b.q.data, &b.qd.data, &b.torque.data, &b.pivot.data],
            ),
            Route::Angles(kind) => with_model!(self, kind, |m| states::jacobians(m, &b)),
            Route::Directions => directions::jacobians(&self.inner, &b),
        })
        .map_err(|e| e.named(&b.q.lead))?;
        jacobian_arrays(py, [qdd, dq, dqd], &b)
    }

    /// Every term of `M q̈ + c + k + d = Q` at one state (the sympy reference's form), as
    /// a dict: mass_matrix (kg·m²), velocity_terms, gravity_terms, pivot_terms,
    /// generalized_forces (N·m), accelerations (rad/s²), kinetic_energy and
    /// potential_energy (J).
    #[pyo3(signature = (q, qd = None, torque = None, pivot_acceleration = None, *, model = "planar"))]
    fn terms(
        &self,
        py: Python<'_>,
        q: &Bound<'_, PyAny>,
        qd: Option<&Bound<'_, PyAny>>,
        torque: Option<&Bound<'_, PyAny>>,
        pivot_acceleration: Option<&Bound<'_, PyAny>>,
        model: &str,
    ) -> PyResult<Py<PyDict>> {
        let kind = Kind::of(model)?;
        let b = self.batch(kind, q, qd, torque, pivot_acceleration)?;
        if !b.q.lead.is_empty() {
            return Err(invalid("terms: one state at a time (q of shape (dof,))"));
        }
        with_model!(self, kind, |m| states::terms(py, m, &b))
    }

    /// `(T, U)`: kinetic and potential energy (J) of the states, shaped like `q` without its
    /// last axis (`model="directions"`: relative to the pivot).
    #[pyo3(signature = (q, qd = None, *, model = "planar"))]
    fn energy<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        qd: Option<&Bound<'py, PyAny>>,
        model: &str,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let b;
        let (t, u) = match Route::of(model)? {
            Route::Angles(kind) => {
                b = self.batch(kind, q, qd, None, None)?;
                maybe_detached(py, b.q.data.len(), || with_model!(self, kind, |m| states::energies(m, &b)))
            }
            Route::Directions => {
                b = self.directions_rows(q, qd, None, None)?;
                maybe_detached(py, b.q.data.len(), || directions::energies(&self.inner, [&b.q, &b.qd]))
            }
        };
        Ok((array(py, t, &b.q.lead, &[])?.into_any(), array(py, u, &b.q.lead, &[])?.into_any()))
    }

    /// `(frequencies, shapes)`: the normal modes of the chain hanging at rest, angular
    /// frequencies ω_k (rad/s, ascending) and the mode shapes in link angles as columns
    /// (mass-normalised).
    fn modes<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let modes = pendulum_core::normal_modes(&self.inner);
        let n = self.inner.links();
        Ok((
            PyArray1::from_slice(py, modes.frequencies.as_slice()).into_any(),
            array(py, modes.shapes.transpose().as_slice().to_vec(), &[n, n], &[])?.into_any(),
        ))
    }

    /// The linearisation about a steady state (q̈ = 0: an equilibrium or a steady
    /// rotation), from the analytic derivatives: a dict with `A` (state x = (q, q̇)),
    /// `B_torque`, `B_pivot` and the `eigenvalues` of A (complex, 1/s, by decreasing real
    /// part). A state that is not steady (|q̈_i| > tolerance, rad/s²) raises ValueError
    /// unless `force=True`.
    #[pyo3(signature = (q, qd = None, torque = None, pivot_acceleration = None, *, model = "planar", force = false, tolerance = pendulum_core::STEADY_TOLERANCE))]
    #[allow(clippy::too_many_arguments)]
    fn linearize(
        &self,
        py: Python<'_>,
        q: &Bound<'_, PyAny>,
        qd: Option<&Bound<'_, PyAny>>,
        torque: Option<&Bound<'_, PyAny>>,
        pivot_acceleration: Option<&Bound<'_, PyAny>>,
        model: &str,
        force: bool,
        tolerance: f64,
    ) -> PyResult<Py<PyDict>> {
        let kind = Kind::of(model)?;
        let b = self.batch(kind, q, qd, torque, pivot_acceleration)?;
        if !b.q.lead.is_empty() {
            return Err(invalid("linearize: one state at a time (q of shape (dof,))"));
        }
        let tolerance = if force { f64::INFINITY } else { tolerance };
        let s = with_model!(self, kind, |m| states::linearize_with(m, &b, tolerance)).map_err(core_error)?;
        let d = PyDict::new(py);
        let matrix =
            |m: &DMatrix<f64>| array(py, m.transpose().as_slice().to_vec(), &[m.nrows(), m.ncols()], &[]);
        d.set_item("A", matrix(&s.a)?)?;
        d.set_item("B_torque", matrix(&s.b_torque)?)?;
        d.set_item("B_pivot", matrix(&s.b_pivot)?)?;
        let eig: Vec<pyo3::Bound<'_, pyo3::types::PyComplex>> =
            s.eigenvalues.iter().map(|e| pyo3::types::PyComplex::from_doubles(py, e.re, e.im)).collect();
        let np = py.import("numpy")?;
        d.set_item("eigenvalues", np.call_method1("array", (eig, "complex128"))?)?;
        d.set_item("residual", s.residual)?;
        Ok(d.unbind())
    }
}

/// A count of steps from Python: `what` is refused in one line when negative.
fn count(what: &str, value: i64) -> PyResult<usize> {
    usize::try_from(value)
        .map_err(|_| invalid(format!("{what}: {value} is not a number of steps (0 or more)")))
}

/// `(q̈, ∂q̈/∂q, ∂q̈/∂q̇)` as arrays shaped like the states of `b`: `(..., w)` and `(..., w, w)`.
fn jacobian_arrays<'py, T: numpy::Element>(
    py: Python<'py>,
    [qdd, dq, dqd]: [Vec<T>; 3],
    b: &Batch,
) -> PyResult<Bound<'py, PyTuple>> {
    let w = b.q.width;
    let items = [
        array(py, qdd, &b.q.lead, &[w])?,
        array(py, dq, &b.q.lead, &[w, w])?,
        array(py, dqd, &b.q.lead, &[w, w])?,
    ];
    PyTuple::new(py, items)
}
