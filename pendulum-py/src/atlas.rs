//! `pendulum.atlas`'s engine: an atlas's plan ([`AtlasPlan`], the run library's
//! `AtlasConfig`: chain, axes, kinds, duration, step) that runs any chunk of its points as
//! one batch of chains and returns them as atlas.json's points (JSON text, bit for bit
//! whatever the chunk). The Python side (`pendulum/_atlas.py`) cuts the grid into chunks,
//! hands them to a Dask client or runs them here, and assembles the arrays.

use std::path::PathBuf;
use std::sync::atomic::Ordering;

use pendulum_experiment::atlas::{
    Atlas, AtlasConfig, AtlasFile, AtlasKind, AtlasPoint, AtlasRequest, Damping,
};
use pyo3::prelude::*;
use pyo3::types::PyTuple;

use crate::arrays::numbers;
use crate::chain::Chain;
use crate::errors::{invalid, run_error};
use crate::interrupt::interruptible;

/// The plan of an atlas: every parameter, checked (``pendulum.atlas`` makes and runs it).
///
/// Two of ``omega`` (rad/s, or units of √(g/L) with ``scaled``), ``radius`` (m),
/// ``damping`` (λ per link, N·m·s; None: the chain's own) and ``ramp_time`` (s) are
/// sequences of two or more values, the axes (the first in this order is x); the others
/// one number. ``kinds``: "sudden" and/or "ramp-up". ``duration`` and ``step`` (s) default
/// as ``pendulum atlas`` chooses them. Pickles as its JSON.
#[pyclass(module = "pendulum._pendulum", name = "AtlasPlan", frozen)]
pub struct AtlasPlan {
    atlas: Atlas,
}

impl AtlasPlan {
    fn config(&self) -> &AtlasConfig {
        self.atlas.config()
    }
}

#[pymethods]
impl AtlasPlan {
    #[new]
    #[pyo3(signature = (chain, *, omega, radius, damping = None, ramp_time = None, kinds = vec!["sudden".to_string()], scaled = false, duration = None, step = None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        chain: &Chain,
        omega: &Bound<'_, PyAny>,
        radius: &Bound<'_, PyAny>,
        damping: Option<&Bound<'_, PyAny>>,
        ramp_time: Option<&Bound<'_, PyAny>>,
        kinds: Vec<String>,
        scaled: bool,
        duration: Option<f64>,
        step: Option<f64>,
    ) -> PyResult<Self> {
        let c = &chain.inner;
        let kinds = kinds
            .iter()
            .map(|k| match k.as_str() {
                "sudden" => Ok(AtlasKind::Sudden),
                "ramp-up" | "ramp_up" => Ok(AtlasKind::RampUp),
                other => Err(invalid(format!("kinds: '{other}' is not a kind of start (sudden, ramp-up)"))),
            })
            .collect::<PyResult<Vec<_>>>()?;
        let request = AtlasRequest {
            masses: c.masses().as_slice().to_vec(),
            lengths: c.lengths().as_slice().to_vec(),
            gravity: c.gravity(),
            omega: numbers("omega", omega)?,
            scaled,
            radius: numbers("radius", radius)?,
            damping: match damping {
                None => Damping::PerLink(c.damping().as_slice().to_vec()),
                Some(d) => Damping::Uniform(numbers("damping", d)?),
            },
            ramp_time: ramp_time.map(|t| numbers("ramp_time", t)).transpose()?.unwrap_or_default(),
            kinds,
            duration,
            step,
        };
        let config = request.resolve().map_err(run_error)?;
        Ok(Self { atlas: Atlas::new(config).map_err(run_error)? })
    }

    /// The plan from its JSON (``to_json``).
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<Self> {
        let config: AtlasConfig =
            serde_json::from_str(text).map_err(|e| invalid(format!("not an atlas configuration: {e}")))?;
        Ok(Self { atlas: Atlas::new(config).map_err(run_error)? })
    }

    /// The configuration as JSON (atlas.json's ``config``).
    fn to_json(&self) -> PyResult<String> {
        serde_json::to_string(self.config()).map_err(|e| invalid(e.to_string()))
    }

    /// Pickles as its JSON.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let py = slf.py();
        let from_json = slf.get_type().getattr("from_json")?;
        Ok((from_json, (slf.get().to_json()?,).into_pyobject(py)?))
    }

    /// Points of the atlas: kinds × grid.
    fn __len__(&self) -> usize {
        self.config().len()
    }

    /// The numbers derived from the plan (atlas.json's ``derived``) as JSON: the chain's
    /// length, √(g/L), the critical speeds on a fixed pivot (rad/s), steps per point.
    fn derived_json(&self) -> PyResult<String> {
        let derived = self.config().derived().map_err(run_error)?;
        serde_json::to_string(&derived).map_err(|e| invalid(e.to_string()))
    }

    /// Runs the points ``indices`` (kind by kind, row by row of y, along x) as one batch
    /// of chains on ``threads`` threads (None: all cores) and returns them as a JSON list
    /// of atlas.json's points, in the order of ``indices``. Bit for bit the same however the
    /// grid is cut. The GIL is released; Ctrl-C raises KeyboardInterrupt.
    #[pyo3(signature = (indices, threads = None))]
    fn run(&self, py: Python<'_>, indices: Vec<usize>, threads: Option<usize>) -> PyResult<String> {
        if let Some(&bad) = indices.iter().find(|&&i| i >= self.config().len()) {
            return Err(invalid(format!(
                "indices: {bad} is not a point of this atlas of {}",
                self.config().len()
            )));
        }
        if threads == Some(0) {
            return Err(invalid("threads: at least 1, got 0"));
        }
        let atlas = self.atlas.clone();
        let points = interruptible(py, "the atlas", move |stop| {
            let stop = || stop.load(Ordering::SeqCst);
            let ends = match threads {
                None => atlas.run(&indices, &stop),
                Some(t) => rayon::ThreadPoolBuilder::new()
                    .num_threads(t)
                    .build()
                    .map_err(|e| {
                        pendulum_experiment::Error::failed(format!("cannot start {t} threads: {e}"))
                    })?
                    .install(|| atlas.run(&indices, &stop)),
            };
            Ok(indices
                .iter()
                .zip(ends)
                .map(|(&i, end)| {
                    let mut p = atlas.point(i);
                    p.record(end);
                    p
                })
                .collect::<Vec<AtlasPoint>>())
        })?
        .map_err(run_error)?;
        serde_json::to_string(&points).map_err(|e| invalid(e.to_string()))
    }

    /// Writes ``directory``/atlas.json (created if missing) with ``points`` (the JSON list
    /// of every point, in order), as ``pendulum atlas`` writes it: ``pendulum atlas --from
    /// DIRECTORY/atlas.json --out DIRECTORY`` then draws atlas.png and writes atlas.csv
    /// without running anything, or runs the points not completed.
    fn save(&self, directory: PathBuf, points: &str) -> PyResult<()> {
        let points: Vec<AtlasPoint> =
            serde_json::from_str(points).map_err(|e| invalid(format!("points: not atlas points: {e}")))?;
        let config = self.config().clone();
        if points.len() != config.len() {
            return Err(invalid(format!("points: {} given, the atlas has {}", points.len(), config.len())));
        }
        let derived = config.derived().map_err(run_error)?;
        let mut file = AtlasFile::new(config, derived, points);
        let finished = file.points.iter().all(|p| p.status == pendulum_experiment::points::Status::Completed);
        file.status = if finished { "completed" } else { "interrupted" }.into();
        std::fs::create_dir_all(&directory).map_err(|e| {
            run_error(pendulum_experiment::error::io_failed("create the directory", &directory, e))
        })?;
        pendulum_experiment::write_json_atomic(&directory.join("atlas.json"), &file).map_err(run_error)
    }
}
