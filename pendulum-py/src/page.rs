//! The page of `pendulum view` for a run written to a directory: as HTML text, and inside an
//! iframe for a notebook cell.

use std::path::{Path, PathBuf};

use pyo3::prelude::*;

use crate::errors::run_error;

/// The self-contained page of the run in `directory` (what `pendulum view --export`
/// writes), as HTML text: at most `frames` samples, longer runs thinned to every k-th.
#[pyfunction]
#[pyo3(signature = (directory, frames = pendulum_experiment::page::DEFAULT_FRAMES))]
pub fn page(directory: PathBuf, frames: usize) -> PyResult<String> {
    page_of(&directory, frames)
}

/// [`page`] with the library's errors as Python's.
pub fn page_of(directory: &Path, frames: usize) -> PyResult<String> {
    Ok(pendulum_experiment::page::page(directory, frames).map_err(run_error)?.0)
}

/// `html` inside an iframe, as a notebook cell shows it.
pub fn iframe(html: &str) -> String {
    let escaped = html.replace('&', "&amp;").replace('"', "&quot;");
    format!(r#"<iframe srcdoc="{escaped}" style="width: 100%; height: 640px; border: 0"></iframe>"#)
}
