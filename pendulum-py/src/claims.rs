//! `pendulum.check_claims`: a claims file (equations of motion written by hand in index
//! notation, `reference/CLAIMS.md`) checked against the sympy reference built into the
//! package, as `cargo xtask verify --claims FILE` checks it.

use std::path::PathBuf;

use pendulum_reference::claims::{Outcome, check_source, parse_named, render};
use pendulum_reference::embedded;
use pendulum_reference::sample::{DEFAULT_SEED, DEFAULT_STATES};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::invalid;

/// One claim's outcome as a dict.
fn outcome<'py>(py: Python<'py>, o: &Outcome) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("title", &o.claim.title)?;
    d.set_item("line", o.claim.pos.line)?;
    d.set_item("cases", &o.cases)?;
    d.set_item("verdict", o.verdict().as_str())?;
    d.set_item("worst", o.worst())?;
    d.set_item("corrected", o.corrected().map(|(v, w)| (v.as_str(), w)))?;
    d.set_item("first_disagreement", o.first_disagreement())?;
    d.set_item("diagnosis", o.diagnosis())?;
    let fixes: Vec<(usize, String, String)> = o
        .entries
        .iter()
        .filter_map(|e| {
            e.diagnosis.as_ref().map(|d| (e.entry.pos.line, d.slip.clone(), d.corrected.render()))
        })
        .collect();
    d.set_item("fixes", fixes)?;
    Ok(d)
}

/// Checks a claims file, given by ``path`` or as ``text``, against the sympy reference
/// built into the package (the committed cases: planar chains of 1–8 links, spatial of
/// 1–5), at ``states`` random states per case from ``seed`` (the defaults of ``cargo xtask
/// verify``). Returns ``(claims, table)``: a dict per claim (``title``, ``line``,
/// ``cases``, ``verdict`` "agrees", "disagrees" or "untested", ``worst`` relative error,
/// ``corrected``: the verdict and error of the claim's corrected form or None,
/// ``first_disagreement``, ``diagnosis``, ``fixes``: (line, slip, corrected entry) per
/// diagnosed entry), and the command's table. A file with errors raises ValueError
/// listing each with its line and column. The GIL is released while it checks.
#[pyfunction]
#[pyo3(signature = (path = None, *, text = None, states = DEFAULT_STATES, seed = DEFAULT_SEED))]
pub fn check_claims<'py>(
    py: Python<'py>,
    path: Option<PathBuf>,
    text: Option<String>,
    states: usize,
    seed: u64,
) -> PyResult<(Vec<Bound<'py, PyDict>>, String)> {
    let (name, source) = match (path, text) {
        (Some(path), None) => {
            let source = std::fs::read_to_string(&path)
                .map_err(|e| invalid(format!("cannot read {}: {e}", path.display())))?;
            (path.display().to_string(), source)
        }
        (None, Some(text)) => ("<text>".to_string(), text),
        _ => return Err(invalid("give a claims file's path or its text (text=...), one of them")),
    };
    if states == 0 {
        return Err(invalid("states: at least 1, got 0"));
    }
    let outcomes = py
        .detach(|| -> anyhow::Result<Vec<Outcome>> {
            let claims = parse_named(&source, &name)?;
            check_source(&name, &source, claims, embedded::cases()?, states, seed)
        })
        .map_err(|e| invalid(format!("{e:#}")))?;
    let table = render(&outcomes);
    let claims = outcomes.iter().map(|o| outcome(py, o)).collect::<PyResult<Vec<_>>>()?;
    Ok((claims, table))
}
