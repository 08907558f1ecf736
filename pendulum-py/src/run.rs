//! `pendulum.Run`: the library's run description (`pendulum_experiment::RunConfig`, run.json's
//! schema) as a Python object, and `RunResult`: a run's samples as numpy arrays with its
//! outcome and, for a whirled chain, the shape it took.

use std::ops::ControlFlow;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use numpy::PyArray1;
use pendulum_core::ShapeReport;
use pendulum_experiment::{
    Dimension, DriveConfig, DriveOptions, InitialSpec, PathSamples, Recorder, Report, Request, RunConfig,
    RunFile, SampleFiles, View, build, options,
};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use crate::arrays::{Numbers, array, per_link};
use crate::errors::{invalid, run_error};

/// How often a long run looks for Ctrl-C.
const SIGNAL_CHECK: Duration = Duration::from_millis(100);

/// An experiment: a chain, its pivot's motion and start, how long and how to integrate.
///
/// Keyword arguments as `pendulum simulate`'s options (SI units, angles in rad):
/// `dim` (2 or 3), `n`, `masses` (kg), `lengths` (m), `gravity` (m/s²), `damping`
/// (N·m·s), `torque` (N·m, 2D), `drive` ("fixed", "harmonic", "circle", "sampled") with
/// `amplitude` (m), `omega` (rad/s), `phase` (rad), `direction`, `radius` (m), `ramp_time`
/// (s), `ramp_from` (rad/s), `path` (rows `t, x, y[, z]`, s and m: a file, or an array)
/// and `path_at_rest`; `initial` ("hanging", "horizontal", "tilted:ANGLE", a file or a
/// previous run's directory), `spin` (rad/s, 3D), `integrator` ("gl1", "gl2", "gl3", "rk4",
/// "midpoint", "dp54"; default: chosen), `solver`, `tolerance`, `step` (s; default:
/// chosen), `end` (s), `every` (default: about 500 samples). What was chosen, and why, is
/// in `config["chosen"]`.
#[pyclass(module = "pendulum._pendulum", name = "Run", frozen)]
pub struct Run {
    config: RunConfig,
}

/// A sampled drive's rows: a file (a `str` or path), or an array of rows `t, x, y[, z]`.
fn path_samples(path: &Bound<'_, PyAny>) -> PyResult<PathSamples> {
    if let Ok(file) = path.extract::<std::path::PathBuf>() {
        return Ok(PathSamples::File(file));
    }
    let rows = Numbers::read("path", path)?;
    if rows.shape.len() != 2 {
        return Err(invalid(format!(
            "path: shape {:?}, expected rows of t, x, y[, z] (a 2-dimensional array) or a file",
            rows.shape
        )));
    }
    Ok(PathSamples::Rows { label: format!("<array of shape {:?}>", rows.shape), numbers: rows.data })
}

/// The run's samples and how it ended.
#[pyclass(module = "pendulum._pendulum", name = "RunResult", frozen)]
pub struct RunResult {
    /// `"completed"` or `"failed"`.
    #[pyo3(get)]
    status: String,
    /// The failed step's error, if it failed.
    #[pyo3(get)]
    error: Option<String>,
    /// Time reached, s.
    #[pyo3(get)]
    t_end: f64,
    /// Steps taken.
    #[pyo3(get)]
    steps: u64,
    recorder: Recorder,
    final_state: Vec<f64>,
    shape: Option<Result<ShapeReport, String>>,
    /// Where its files were written (`run(out=…)`), if anywhere.
    directory: Option<PathBuf>,
    /// The energy balance's worst error `max |H − H0 − W|` over the samples, J.
    #[pyo3(get)]
    balance_residual: f64,
    /// The energy scale the balance is judged against, J.
    #[pyo3(get)]
    energy_scale: f64,
    /// What the run should tell you (an energy balance that is off); each is also issued
    /// as a `RuntimeWarning`.
    #[pyo3(get)]
    warnings: Vec<String>,
}

#[pymethods]
impl Run {
    #[new]
    #[pyo3(signature = (*, dim = 2, n = None, masses = None, lengths = None, gravity = 9.81, damping = None,
        torque = None, drive = "fixed", amplitude = 0.05, omega = 10.0, phase = 0.0, direction = None,
        radius = 0.1, ramp_time = None, ramp_from = None, path = None, path_at_rest = false,
        initial = "tilted:1.0", spin = None,
        integrator = None, solver = "fixed-point", tolerance = None, step = None, end = 10.0, every = None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        dim: u8,
        n: Option<usize>,
        masses: Option<&Bound<'_, PyAny>>,
        lengths: Option<&Bound<'_, PyAny>>,
        gravity: f64,
        damping: Option<&Bound<'_, PyAny>>,
        torque: Option<&Bound<'_, PyAny>>,
        drive: &str,
        amplitude: f64,
        omega: f64,
        phase: f64,
        direction: Option<Vec<f64>>,
        radius: f64,
        ramp_time: Option<f64>,
        ramp_from: Option<f64>,
        path: Option<&Bound<'_, PyAny>>,
        path_at_rest: bool,
        initial: &str,
        spin: Option<f64>,
        integrator: Option<&str>,
        solver: &str,
        tolerance: Option<f64>,
        step: Option<f64>,
        end: f64,
        every: Option<usize>,
    ) -> PyResult<Self> {
        let dim = match dim {
            2 => Dimension::Two,
            3 => Dimension::Three,
            d => return Err(invalid(format!("dim: {d} is neither 2 nor 3"))),
        };
        let listed = |what: &str, v: Option<&Bound<'_, PyAny>>, default: f64| -> PyResult<Vec<f64>> {
            match v.filter(|v| !v.is_none()) {
                Some(v) => per_link(what, v),
                None => Ok(vec![default]),
            }
        };
        let (n, masses, lengths) =
            options::links(n, listed("masses", masses, 1.0)?, listed("lengths", lengths, 0.5)?)
                .map_err(run_error)?;
        let damping = options::expand("damping", listed("damping", damping, 0.0)?, n).map_err(run_error)?;
        let torque = match torque.filter(|t| !t.is_none()) {
            Some(t) => Some(options::expand("torque", per_link("torque", t)?, n).map_err(run_error)?),
            None => None,
        };
        let kind = options::by_name("drive", drive, "fixed, harmonic, circle, sampled").map_err(run_error)?;
        let path = path.filter(|p| !p.is_none()).map(|p| path_samples(p)).transpose()?;
        let drive = DriveOptions {
            kind,
            amplitude,
            omega,
            phase,
            direction,
            radius,
            ramp_time,
            ramp_from,
            path,
            path_at_rest,
        }
        .config(dim)
        .map_err(run_error)?;
        let integrator = integrator
            .map(|s| options::by_name("integrator", s, "gl1, gl2, gl3, rk4, midpoint, dp54"))
            .transpose()
            .map_err(run_error)?;
        let solver = options::by_name("solver", solver, "fixed-point, newton").map_err(run_error)?;
        let initial: InitialSpec = initial.parse().map_err(|e: String| invalid(format!("initial: {e}")))?;
        let request = Request {
            dim,
            masses,
            lengths,
            gravity,
            damping,
            torque,
            drive,
            initial,
            spin,
            integrator,
            solver,
            tolerance,
            step,
            end,
            every,
            view: View::Xz,
            frames: 150,
        };
        Ok(Self { config: request.resolve().map_err(run_error)? })
    }

    /// The run recorded in a run.json (as `pendulum simulate --from`).
    #[staticmethod]
    fn load(path: PathBuf) -> PyResult<Self> {
        Ok(Self { config: RunFile::read(&path).map_err(run_error)?.config })
    }

    /// A run from its description as JSON text (what `to_json` gives; pickling uses it).
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<Self> {
        let config: RunConfig =
            serde_json::from_str(text).map_err(|e| invalid(format!("not a run description: {e}")))?;
        config.check().map_err(run_error)?;
        Ok(Self { config })
    }

    /// The description as JSON text: run.json's `config`.
    fn to_json(&self) -> PyResult<String> {
        serde_json::to_string(&self.config).map_err(|e| invalid(e.to_string()))
    }

    /// Number of links.
    #[getter]
    fn n(&self) -> usize {
        self.config.links()
    }

    /// Integrator step, s (given or chosen).
    #[getter]
    fn step(&self) -> f64 {
        self.config.step
    }

    /// End time, s.
    #[getter]
    fn end(&self) -> f64 {
        self.config.end
    }

    /// What the run chose itself of integrator, step and sampling, and why (None when
    /// all were given).
    #[getter]
    fn chosen(&self) -> Option<String> {
        self.config.chosen.clone()
    }

    fn __repr__(&self) -> String {
        let c = &self.config;
        format!(
            "Run(dim={}, n={}, drive={}, end={} s, integrator={:?}, step={} s, every={})",
            c.dim.space(),
            c.links(),
            match c.drive {
                DriveConfig::Fixed => "fixed",
                DriveConfig::Harmonic { .. } => "harmonic",
                DriveConfig::Circle { .. } => "circle",
                DriveConfig::RampedCircle { .. } => "ramped circle",
                DriveConfig::Sampled { .. } => "sampled",
            },
            c.end,
            c.integrator,
            c.step,
            c.every
        )
    }

    /// Pickles as its description.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let py = slf.py();
        let from_json = slf.get_type().getattr("from_json")?;
        Ok((from_json, (slf.get().to_json()?,).into_pyobject(py)?))
    }

    /// Runs it: the samples as arrays in a `RunResult`, with the shape a whirled chain
    /// took. With `out` (a directory, created if missing), also writes run.json,
    /// trajectory.csv, energy.csv, final.json and (a whirl) shape.json there, as
    /// `pendulum simulate --no-plots` does; a notebook then shows the result as the
    /// interactive page of `pendulum view`. The GIL is released while it runs; Ctrl-C raises KeyboardInterrupt.
    #[pyo3(signature = (out = None))]
    fn run(&self, py: Python<'_>, out: Option<PathBuf>) -> PyResult<RunResult> {
        let config = &self.config;
        let mut recorder = Recorder::default();
        let mut interrupted: Option<PyErr> = None;
        let report = py.detach(|| -> pendulum_experiment::Result<Report> {
            let simulation = build(config)?;
            let mut files = match &out {
                Some(dir) => {
                    std::fs::create_dir_all(dir).map_err(|e| {
                        pendulum_experiment::Error::invalid(format!(
                            "out: cannot create the directory {}: {e}",
                            dir.display()
                        ))
                    })?;
                    RunFile::new(config.clone()).write_atomic(&dir.join("run.json"))?;
                    Some(SampleFiles::create(dir, &simulation.layout(config))?)
                }
                None => None,
            };
            let mut last = Instant::now();
            let mut observe = |_t: f64| {
                if last.elapsed() < SIGNAL_CHECK {
                    return ControlFlow::Continue(());
                }
                last = Instant::now();
                match Python::attach(|py| py.check_signals()) {
                    Ok(()) => ControlFlow::Continue(()),
                    Err(e) => {
                        interrupted = Some(e);
                        ControlFlow::Break(())
                    }
                }
            };
            let report = match files.as_mut() {
                Some(f) => simulation.run(config, &mut [f, &mut recorder], &mut observe),
                None => simulation.run(config, &mut [&mut recorder], &mut observe),
            };
            if let Some(f) = files {
                f.finish()?;
            }
            let report = report?;
            if let Some(dir) = &out {
                report.final_state.write(dir)?;
                if let Some(Ok(shape)) = &report.shape {
                    pendulum_experiment::whirl::write_shape_json(&dir.join("shape.json"), shape)?;
                }
                let mut file = RunFile::new(config.clone());
                file.outcome = Some(report.outcome());
                file.write_atomic(&dir.join("run.json"))?;
            }
            Ok(report)
        });
        let report = report.map_err(run_error)?;
        if let Some(e) = interrupted {
            return Err(e);
        }
        let final_state =
            report.final_state.coordinates.iter().chain(&report.final_state.rates).copied().collect();
        let warnings = report.warnings();
        for warning in &warnings {
            let category = py.get_type::<pyo3::exceptions::PyRuntimeWarning>();
            PyErr::warn(py, &category, &std::ffi::CString::new(warning.as_str())?, 1)?;
        }
        Ok(RunResult {
            balance_residual: report.balance.residual,
            energy_scale: report.balance.scale,
            warnings,
            status: report.status.name().into(),
            error: report.error.as_ref().map(ToString::to_string),
            t_end: report.t,
            steps: report.steps,
            recorder,
            final_state,
            shape: report.shape.map(|s| s.map_err(|e| e.to_string())),
            directory: out,
        })
    }
}

#[pymethods]
impl RunResult {
    /// Sample times, s.
    #[getter]
    fn t<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.recorder.times)
    }

    /// The state at each sample, shape (samples, 2·dof): 2D θ then θ̇ (rad, rad/s); 3D the
    /// unit link directions u_i then their rates w_i = u̇_i (1, 1/s), x, y, z each.
    #[getter]
    fn states<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let width = self.recorder.states.first().map_or(0, Vec::len);
        let data = self.recorder.states.concat();
        Ok(array(py, data, &[self.recorder.len(), width], &[])?.into_any())
    }

    /// Positions of the pivot then every mass at each sample, shape (samples, n + 1, 3), m
    /// (z = 0 in 2D, where y is up).
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let points = self.recorder.positions.first().map_or(0, Vec::len);
        let data: Vec<f64> = self.recorder.positions.iter().flatten().flatten().copied().collect();
        Ok(array(py, data, &[self.recorder.len(), points, 3], &[])?.into_any())
    }

    /// The energy ledger at each sample, a dict of arrays (J): energy (inertial frame
    /// H = T + U), drive_work, torque_work, damped, balance_residual
    /// (H − H0 − (W_drive + W_torque − E_damped): zero up to the integrator's error).
    #[getter]
    fn ledger(&self, py: Python<'_>) -> PyResult<Py<PyDict>> {
        let r = &self.recorder;
        let d = PyDict::new(py);
        for (name, v) in [
            ("energy", &r.energy),
            ("drive_work", &r.drive_work),
            ("torque_work", &r.torque_work),
            ("damped", &r.damped),
            ("balance_residual", &r.balance_residual),
        ] {
            d.set_item(name, PyArray1::from_slice(py, v))?;
        }
        Ok(d.unbind())
    }

    /// The last state exactly (as `states`' rows; what final.json holds).
    #[getter]
    fn final_state<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.final_state)
    }

    /// A whirled chain (3D, pivot circling the vertical): the shape at the end, in the
    /// frame turning with the pivot, as a dict — nodes (axis crossings + 1, the pivot
    /// counted), axis_crossings, tip_radius (m), settled, drift (m), omega (rad/s), and
    /// nearest: the nearest damped steady shape (nodes, distance in m, stable,
    /// growth_rate in 1/s, zero within round-off when its magnitude is at most
    /// growth_rate_bound) or None when none was found. None for other runs.
    #[getter]
    fn shape(&self, py: Python<'_>) -> PyResult<Option<Py<PyDict>>> {
        let Some(shape) = &self.shape else { return Ok(None) };
        let r = shape.as_ref().map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.clone()))?;
        let d = PyDict::new(py);
        d.set_item("t", r.t)?;
        d.set_item("omega", r.omega)?;
        d.set_item("radius", r.radius)?;
        d.set_item("nodes", r.shape.nodes)?;
        d.set_item("axis_crossings", r.shape.axis_crossings)?;
        d.set_item("tip_radius", r.shape.tip_radius)?;
        d.set_item("settled", r.settling.settled)?;
        d.set_item("drift", r.settling.drift)?;
        let nearest = match &r.nearest {
            Ok(n) => {
                let e = PyDict::new(py);
                e.set_item("nodes", n.shape.nodes)?;
                e.set_item("distance", n.distance)?;
                e.set_item("stable", n.stable)?;
                e.set_item("growth_rate", n.growth_rate)?;
                e.set_item("growth_rate_bound", n.rate_bound)?;
                e.set_item("tip_radius", n.shape.tip_radius)?;
                Some(e)
            }
            Err(_) => None,
        };
        d.set_item("nearest", nearest)?;
        Ok(Some(d.unbind()))
    }

    /// The directory its files were written to (`run(out=…)`), or None.
    #[getter]
    fn directory(&self) -> Option<PathBuf> {
        self.directory.clone()
    }

    /// In a notebook: the page of `pendulum view` (the chain under an orbit camera,
    /// playback, the co-rotating frame, the ledger) in an iframe, for a run written with
    /// `run(out=…)`; None otherwise (the notebook shows the repr).
    fn _repr_html_(&self) -> PyResult<Option<String>> {
        let Some(dir) = &self.directory else { return Ok(None) };
        Ok(Some(crate::page::iframe(&crate::page::page_of(dir, pendulum_experiment::page::DEFAULT_FRAMES)?)))
    }

    fn __repr__(&self) -> String {
        format!(
            "RunResult(status={:?}, t_end={} s, steps={}, samples={})",
            self.status,
            self.t_end,
            self.steps,
            self.recorder.len()
        )
    }
}
