//! `import pendulum`: the library from Python. Thin glue: chains and models evaluated on
//! numpy arrays (a leading batch axis: many states in one call), the run description of
//! `pendulum-experiment` with its run loop, the normal modes and linearisation. No physics here;
//! every long call releases the GIL and answers Ctrl-C with `KeyboardInterrupt`.

mod arrays;
mod chain;
mod errors;
mod run;

use std::path::{Path, PathBuf};

use pyo3::prelude::*;

/// The native part of the `pendulum` package (`pendulum._pendulum`); import `pendulum`.
#[pymodule]
fn _pendulum(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", pendulum_experiment::VERSION)?;
    m.add_class::<chain::Chain>()?;
    m.add_class::<run::Run>()?;
    m.add_class::<run::RunResult>()?;
    m.add_function(wrap_pyfunction!(page, m)?)?;
    Ok(())
}

/// The self-contained page of the run in `directory` (what `pendulum view --export`
/// writes), as HTML text: at most `frames` samples, longer runs thinned to every k-th.
#[pyfunction]
#[pyo3(signature = (directory, frames = pendulum_experiment::page::DEFAULT_FRAMES))]
fn page(directory: PathBuf, frames: usize) -> PyResult<String> {
    page_of(&directory, frames)
}

/// [`page`] with the library's errors as Python's.
fn page_of(directory: &Path, frames: usize) -> PyResult<String> {
    Ok(pendulum_experiment::page::page(directory, frames).map_err(errors::run_error)?.0)
}

/// `html` inside an iframe, as a notebook cell shows it.
fn iframe(html: &str) -> String {
    let escaped = html.replace('&', "&amp;").replace('"', "&quot;");
    format!(r#"<iframe srcdoc="{escaped}" style="width: 100%; height: 640px; border: 0"></iframe>"#)
}
