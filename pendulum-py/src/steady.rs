//! `pendulum.steady`: the steady shapes of a chain turning about the vertical, as
//! `pendulum steady` finds them (`pendulum_experiment::steady`): the branches up to
//! exactly `omega_max` with every point's node count and verdict, and every shape at the
//! asked speeds, as numpy arrays in dicts.

use std::sync::atomic::Ordering;

use numpy::PyArray1;
use pendulum_core::{SteadyRotation, SteadyShape};
use pendulum_experiment::options::expand;
use pendulum_experiment::steady::{Family, Judged, follow, requested_omega_max, shapes_at};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::arrays::{array, per_link};
use crate::chain::Chain;
use crate::errors::{core_error, invalid, run_error};
use crate::interrupt::interruptible;

/// The steady shapes of ``chain`` turning at ω about the vertical through its pivot, the
/// pivot fixed (``radius = 0``) or driven round a horizontal circle of ``radius`` (m).
///
/// Follows the branches up to exactly ``omega_max`` (rad/s; default 1.25 times the third
/// critical speed, rounded up, or the largest of ``omega`` if higher): for a fixed pivot
/// the ``branches`` lowest leaving the vertical (default: all below ``omega_max``), for a
/// circling pivot the branch from rest and the folded ones. Every point gets its node
/// count and undamped verdict (``"stable"``, ``"gyroscopic"``, ``"unstable"``, with the
/// index of the amended potential and the growth rate, 1/s). ``omega`` (a speed or a
/// sequence, rad/s; default ``omega_max``) lists every shape at those speeds.
///
/// Returns a dict: ``omega_max``; ``critical_speeds`` (the chain's on a fixed pivot below
/// ``omega_max``, rad/s); ``branches``, a list of dicts (``name``, ``critical``: the speed
/// it leaves the vertical or None, ``omega`` (P,), ``nodes`` (P,) with 0 for the vertical,
/// ``stability`` (list of P), ``index`` (P,), ``growth_rate`` (P,), ``theta`` (P, n) rad,
/// ``x`` (P, n) m: the distance of each mass from the axis); ``vertical`` (fixed pivot: a
/// list of ``(from, to, stability, index)`` stretches); ``shapes``, a list of dicts
/// (``omega``, ``branch`` (0: the vertical), ``name``, ``nodes`` (None: the vertical),
/// ``tip_radius`` m, ``stability``, ``index``, ``growth_rate``, ``theta``, ``x``). With
/// ``damping`` (N·m·s, one value or one per link) every listed shape also gets
/// ``damped_stability``, ``damped_growth_rate`` (1/s) and ``damped_shift`` (m), as
/// ``pendulum steady --damping``: on a fixed pivot damping of the link rates in the turning
/// frame, on a circling one the chain's own damping of the inertial rates (the damped shape
/// lags out of the plane by the shift). The GIL is released while it computes; Ctrl-C
/// raises KeyboardInterrupt.
#[pyfunction]
#[pyo3(signature = (chain, *, radius = 0.0, omega = None, omega_max = None, branches = None, damping = None))]
pub fn steady<'py>(
    py: Python<'py>,
    chain: &Chain,
    radius: f64,
    omega: Option<&Bound<'py, PyAny>>,
    omega_max: Option<f64>,
    branches: Option<usize>,
    damping: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let listed: Option<Vec<f64>> = match omega {
        None => None,
        Some(value) => Some(match value.extract::<f64>() {
            Ok(w) => vec![w],
            Err(_) => value
                .extract::<Vec<f64>>()
                .map_err(|_| invalid("omega: a speed or a sequence of speeds, rad/s"))?,
        }),
    };
    if let Some(&bad) = listed.iter().flatten().find(|w| !(w.is_finite() && **w >= 0.0)) {
        return Err(invalid(format!("omega: {bad} rad/s is not a finite, non-negative speed")));
    }
    let n = chain.inner.links();
    let damping = match damping {
        None => None,
        Some(value) => {
            let d = expand("damping", per_link("damping", value)?, n).map_err(run_error)?;
            // Validated by the chain (finite, non-negative, named by link).
            chain.inner.clone().with_damping(&d).map_err(core_error)?;
            d.iter().any(|&v| v > 0.0).then_some(d)
        }
    };
    let problem = SteadyRotation::new(&chain.inner, radius).map_err(core_error)?;
    let base = chain.inner.clone();
    let free = SteadyRotation::new(&chain.inner, 0.0).map_err(core_error)?;
    let omega_max =
        requested_omega_max(&free, radius, listed.as_deref(), omega_max, branches).map_err(run_error)?;
    let speeds = listed.unwrap_or_else(|| vec![omega_max]);
    // Ctrl-C returns at once: the worker stops judging at its next point and its result
    // is dropped.
    let outcome = interruptible(py, "the steady computation", move |stop| {
        let family = follow(&problem, &free, omega_max, branches, &|_| !stop.load(Ordering::SeqCst))?;
        let shapes = shapes_at(&problem, &base, &family, &speeds, damping.as_deref())?;
        Ok((family, shapes))
    })?;
    let (family, shapes) = outcome.map_err(run_error)?;
    let out = PyDict::new(py);
    out.set_item("omega_max", omega_max)?;
    out.set_item("critical_speeds", PyArray1::from_slice(py, &family.critical))?;
    out.set_item("branches", branch_dicts(py, &family, n)?)?;
    let vertical: Vec<(f64, f64, &str, usize)> =
        family.vertical.iter().map(|(a, b, j)| (*a, *b, j.verdict.label(), j.index)).collect();
    out.set_item("vertical", vertical)?;
    let shapes: Vec<Bound<'py, PyDict>> = shapes
        .iter()
        .map(|s| {
            let d = PyDict::new(py);
            d.set_item("omega", s.shape.omega)?;
            d.set_item("branch", s.branch)?;
            d.set_item("name", &s.name)?;
            d.set_item("nodes", s.nodes)?;
            d.set_item("tip_radius", s.tip_radius())?;
            verdict_items(&d, &s.judged)?;
            d.set_item("theta", PyArray1::from_slice(py, s.shape.theta.as_slice()))?;
            d.set_item("x", PyArray1::from_slice(py, &s.shape.displacements))?;
            if let Some(damped) = &s.damped {
                d.set_item("damped_stability", damped.verdict.label())?;
                d.set_item("damped_growth_rate", damped.growth_rate)?;
                d.set_item("damped_shift", damped.shift)?;
            }
            Ok(d)
        })
        .collect::<PyResult<_>>()?;
    out.set_item("shapes", shapes)?;
    Ok(out)
}

/// `stability`, `index`, `growth_rate` of one verdict.
fn verdict_items(d: &Bound<'_, PyDict>, judged: &Judged) -> PyResult<()> {
    d.set_item("stability", judged.verdict.label())?;
    d.set_item("index", judged.index)?;
    d.set_item("growth_rate", judged.growth_rate)
}

/// The branches of `family` as dicts of arrays, one entry per point.
fn branch_dicts<'py>(py: Python<'py>, family: &Family, n: usize) -> PyResult<Vec<Bound<'py, PyDict>>> {
    family
        .branches
        .iter()
        .map(|b| {
            let points: &[SteadyShape] = &b.branch.points;
            let p = points.len();
            let d = PyDict::new(py);
            d.set_item("name", &b.name)?;
            d.set_item("critical", b.critical)?;
            d.set_item("omega", PyArray1::from_vec(py, points.iter().map(|s| s.omega).collect()))?;
            let nodes: Vec<usize> = b.nodes.iter().map(|k| k.unwrap_or(0)).collect();
            d.set_item("nodes", PyArray1::from_vec(py, nodes))?;
            d.set_item("stability", b.judged.iter().map(|j| j.verdict.label()).collect::<Vec<_>>())?;
            d.set_item("index", PyArray1::from_vec(py, b.judged.iter().map(|j| j.index).collect()))?;
            d.set_item(
                "growth_rate",
                PyArray1::from_vec(py, b.judged.iter().map(|j| j.growth_rate).collect()),
            )?;
            let theta = points.iter().flat_map(|s| s.theta.iter().copied()).collect();
            d.set_item("theta", array(py, theta, &[p], &[n])?)?;
            let x = points.iter().flat_map(|s| s.displacements.iter().copied()).collect();
            d.set_item("x", array(py, x, &[p], &[n])?)?;
            Ok(d)
        })
        .collect()
}
