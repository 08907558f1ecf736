//! `pendulum.sweep`'s engine: `pendulum sweep` from Python (the run library's
//! [`Sweep`]: sudden and ramp-up points as batches of chains, the ramp-down points one
//! after the other), its result as sweep.json's text, and the files when asked. The Python
//! side (`pendulum/_sweep.py`) turns the text into arrays.

use std::path::PathBuf;
use std::sync::atomic::Ordering;

use pendulum_experiment::sweep::{Sweep, SweepKind, SweepRequest, csv};
use pyo3::prelude::*;

use crate::chain::Chain;
use crate::errors::{invalid, run_error};
use crate::interrupt::interruptible;

/// Runs ``pendulum sweep`` for ``chain`` (3D, with its damping) at the speeds ``omega``
/// (as ``--omega`` writes them: ``"W1,W2,…"`` or ``"A:B:N"``; rad/s, or in units of
/// √(g/L) with ``scaled``) on a circle of ``radius`` (m), for the
/// ``kinds`` ("sudden", "ramp-up", "ramp-down"), on ``jobs`` threads (None: all cores);
/// ``duration``, ``ramp_time`` and ``step`` (s) default as the command's. With ``out`` (a
/// directory, created if missing) also writes sweep.json and sweep.csv there. Returns
/// sweep.json's text. The GIL is released; Ctrl-C raises KeyboardInterrupt.
#[pyfunction]
#[pyo3(signature = (chain, omega, radius, kinds, scaled, duration, ramp_time, step, jobs, out))]
#[allow(clippy::too_many_arguments)]
pub fn run_sweep(
    py: Python<'_>,
    chain: &Chain,
    omega: String,
    radius: f64,
    kinds: Vec<String>,
    scaled: bool,
    duration: Option<f64>,
    ramp_time: Option<f64>,
    step: Option<f64>,
    jobs: Option<usize>,
    out: Option<PathBuf>,
) -> PyResult<String> {
    let c = &chain.inner;
    let kinds = kinds
        .iter()
        .map(|k| match k.replace('_', "-").as_str() {
            "sudden" => Ok(SweepKind::Sudden),
            "ramp-up" => Ok(SweepKind::RampUp),
            "ramp-down" => Ok(SweepKind::RampDown),
            _ => Err(invalid(format!("kinds: '{k}' is not a kind of start (sudden, ramp-up, ramp-down)"))),
        })
        .collect::<PyResult<Vec<_>>>()?;
    if jobs == Some(0) {
        return Err(invalid("jobs: at least 1, got 0"));
    }
    let request = SweepRequest {
        masses: c.masses().as_slice().to_vec(),
        lengths: c.lengths().as_slice().to_vec(),
        gravity: c.gravity(),
        damping: c.damping().as_slice().to_vec(),
        radius,
        omega_spec: omega,
        scaled,
        kinds,
        duration,
        ramp_time,
        step,
    };
    let sweep = Sweep::new(request.resolve().map_err(run_error)?).map_err(run_error)?;
    let jobs = jobs.unwrap_or_else(pendulum_experiment::options::all_cores);
    let file = interruptible(py, "the sweep", move |stop| {
        let points = sweep.run(jobs, &|| stop.load(Ordering::SeqCst), &|_, _, _| Ok(()))?;
        let mut file = sweep.file(&points);
        let done = points.iter().all(|p| p.status == pendulum_experiment::sweep::Status::Completed);
        file.status = if done { "completed" } else { "failed" }.into();
        if let Some(dir) = &out {
            std::fs::create_dir_all(dir)
                .map_err(|e| pendulum_experiment::error::io_failed("create the directory", dir, e))?;
            file.write_atomic(&dir.join("sweep.json"))?;
            csv::write(&dir.join("sweep.csv"), &points)?;
        }
        Ok(file)
    })?
    .map_err(run_error)?;
    serde_json::to_string(&file).map_err(|e| invalid(e.to_string()))
}
