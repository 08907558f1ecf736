//! `pendulum.whirls`: many whirls of one chain from hanging at rest, each with its own
//! circle and speed (switched on or ramped), run as one batch of chains in SIMD lanes on
//! all cores (`pendulum_experiment::whirls`, the runs of `pendulum sweep`), the answers as
//! numpy arrays.

use std::sync::atomic::Ordering;

use numpy::PyArray1;
use pendulum_experiment::DriveConfig;
use pendulum_experiment::whirls::{
    FEED_EVERY, SETTLE_PERIODS, SETTLE_TOLERANCE, WhirlRuns, WhirlStop, default_duration, default_step,
};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::arrays::numbers;
use crate::chain::Chain;
use crate::errors::invalid;
use crate::interrupt::interruptible;

/// Many whirls of ``chain`` (3D): each from hanging at rest, its pivot on a horizontal
/// circle of radius ``radius`` (m) turning at ``omega`` (rad/s), switched on at t = 0 or,
/// with ``ramp_time`` (s, > 0), ramped linearly from rest over that time and then held;
/// RK4 with projection at ``step`` (s) for ``duration`` (s), the shape analysis fed every 4
/// steps, as ``pendulum sweep`` runs its points. ``radius``, ``omega`` and ``ramp_time`` are
/// each one number for all the whirls or a sequence, one per whirl (those given as
/// sequences must have the same length).
///
/// The whirls run together as a batch of chains, four per SIMD register (eight with AVX-512), on all cores;
/// each gives exactly what it gives alone. Defaults: ``duration`` 12 decay times of the
/// chain's first mode (200 periods undamped), ``step`` the sweep's for the fastest
/// ``omega`` and largest ``radius``. The GIL is released; Ctrl-C raises KeyboardInterrupt.
///
/// Returns a dict of arrays, one entry per whirl: ``omega``, ``radius``, ``ramp_time``
/// (0: switched on); ``nodes`` (axis crossings + 1), ``tip_radius`` (m), ``tip_signed``
/// (m, + on the pivot's side of the axis), ``settled`` (bool), ``drift`` (m);
/// ``nearest_nodes`` (−1: no steady shape found), ``nearest_distance`` (m), ``stable``
/// (bool), ``growth_rate`` (1/s); ``balance_residual`` (J); and ``error``, a list of
/// None or the reason a whirl failed (its numbers are then NaN, −1 or False); plus
/// ``duration`` and ``step``.
#[pyfunction]
#[pyo3(signature = (chain, *, radius, omega, ramp_time = None, duration = None, step = None))]
pub fn whirls<'py>(
    py: Python<'py>,
    chain: &Chain,
    radius: &Bound<'py, PyAny>,
    omega: &Bound<'py, PyAny>,
    ramp_time: Option<&Bound<'py, PyAny>>,
    duration: Option<f64>,
    step: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let radius = numbers("radius", radius)?;
    let omega = numbers("omega", omega)?;
    let ramp = match ramp_time {
        None => vec![0.0],
        Some(v) => numbers("ramp_time", v)?,
    };
    let count = [radius.len(), omega.len(), ramp.len()].into_iter().max().unwrap_or(1);
    for (what, v) in [("radius", &radius), ("omega", &omega), ("ramp_time", &ramp)] {
        if v.len() != 1 && v.len() != count {
            return Err(invalid(format!("{what}: {} values, but another sequence has {count}", v.len())));
        }
    }
    let at = |v: &[f64], i: usize| if v.len() == 1 { v[0] } else { v[i] };
    if let Some(&r) = radius.iter().find(|r| !(r.is_finite() && **r > 0.0)) {
        return Err(invalid(format!("radius: {r} m is not a finite, positive radius")));
    }
    if let Some(&w) = omega.iter().find(|w| !(w.is_finite() && **w >= 0.0)) {
        return Err(invalid(format!("omega: {w} rad/s is not a finite, non-negative speed")));
    }
    let c = &chain.inner;
    let duration = duration.unwrap_or_else(|| default_duration(c));
    if !(duration.is_finite() && duration > 0.0) {
        return Err(invalid(format!("duration: {duration} s is not a finite, positive time")));
    }
    if let Some(&t) = ramp.iter().find(|t| !(t.is_finite() && **t >= 0.0 && **t < duration)) {
        return Err(invalid(format!("ramp_time: {t} s is not within 0 … duration ({duration} s)")));
    }
    let fastest = omega.iter().copied().fold(0.0, f64::max);
    let widest = radius.iter().copied().fold(0.0, f64::max);
    let step = step.unwrap_or_else(|| default_step(c, widest, fastest));
    if !(step.is_finite() && step > 0.0 && step <= duration) {
        return Err(invalid(format!("step: {step} s is not a finite, positive step within the duration")));
    }
    let drives: Vec<DriveConfig> = (0..count)
        .map(|i| {
            let (radius, omega, ramp) = (at(&radius, i), at(&omega, i), at(&ramp, i));
            if ramp > 0.0 {
                DriveConfig::RampedCircle { radius, initial_omega: 0.0, omega, duration: ramp }
            } else {
                DriveConfig::Circle { radius, omega }
            }
        })
        .collect();
    let runs = WhirlRuns::new(c.clone(), duration, step, FEED_EVERY, (SETTLE_PERIODS, SETTLE_TOLERANCE));
    let ends = interruptible(py, "the whirls", move |stop| {
        Ok(runs.run_batch(&drives, &|| stop.load(Ordering::SeqCst)))
    })?
    .map_err(crate::errors::run_error)?;
    let column = |f: &dyn Fn(&pendulum_experiment::whirls::WhirlEnd) -> f64| -> Vec<f64> {
        ends.iter().map(|e| e.as_ref().map_or(f64::NAN, f)).collect()
    };
    let out = PyDict::new(py);
    out.set_item("omega", PyArray1::from_vec(py, (0..count).map(|i| at(&omega, i)).collect()))?;
    out.set_item("radius", PyArray1::from_vec(py, (0..count).map(|i| at(&radius, i)).collect()))?;
    out.set_item("ramp_time", PyArray1::from_vec(py, (0..count).map(|i| at(&ramp, i)).collect()))?;
    let nodes: Vec<i64> =
        ends.iter().map(|e| e.as_ref().map_or(-1, |e| e.report.shape.nodes as i64)).collect();
    out.set_item("nodes", PyArray1::from_vec(py, nodes))?;
    out.set_item("tip_radius", PyArray1::from_vec(py, column(&|e| e.report.shape.tip_radius)))?;
    let signed =
        column(&|e| e.report.shape.tip_radius.copysign(*e.report.shape.radial.last().unwrap_or(&0.0)));
    out.set_item("tip_signed", PyArray1::from_vec(py, signed))?;
    let settled: Vec<bool> =
        ends.iter().map(|e| e.as_ref().is_ok_and(|e| e.report.settling.settled)).collect();
    out.set_item("settled", PyArray1::from_vec(py, settled))?;
    out.set_item("drift", PyArray1::from_vec(py, column(&|e| e.report.settling.drift)))?;
    let nearest = |e: &pendulum_experiment::whirls::WhirlEnd| e.report.nearest.as_ref().ok().cloned();
    let nearest_nodes: Vec<i64> =
        ends.iter().map(|e| e.as_ref().ok().and_then(nearest).map_or(-1, |n| n.shape.nodes as i64)).collect();
    out.set_item("nearest_nodes", PyArray1::from_vec(py, nearest_nodes))?;
    out.set_item(
        "nearest_distance",
        PyArray1::from_vec(py, column(&|e| nearest(e).map_or(f64::NAN, |n| n.distance))),
    )?;
    let stable: Vec<bool> =
        ends.iter().map(|e| e.as_ref().ok().and_then(nearest).is_some_and(|n| n.stable)).collect();
    out.set_item("stable", PyArray1::from_vec(py, stable))?;
    out.set_item(
        "growth_rate",
        PyArray1::from_vec(py, column(&|e| nearest(e).map_or(f64::NAN, |n| n.growth_rate))),
    )?;
    out.set_item("balance_residual", PyArray1::from_vec(py, column(&|e| e.balance.residual)))?;
    let errors: Vec<Option<String>> = ends
        .iter()
        .map(|e| match e {
            Ok(_) => None,
            Err(WhirlStop::Failed(m)) => Some(m.clone()),
            // Only Ctrl-C stops a whirl, and it raised KeyboardInterrupt before this.
            Err(WhirlStop::Interrupted) => Some("interrupted".into()),
        })
        .collect();
    out.set_item("error", errors)?;
    out.set_item("duration", duration)?;
    out.set_item("step", step)?;
    Ok(out)
}
