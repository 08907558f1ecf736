//! `import pendulum`: the library from Python. Thin glue: chains and models evaluated on
//! numpy arrays (a leading batch axis: many states in one call), the run description of
//! `pendulum-experiment` with its run loop, the normal modes and linearisation, the steady shapes and the heavy string the chain approaches. No physics here;
//! every long call releases the GIL and answers Ctrl-C with `KeyboardInterrupt`.

mod arrays;
mod atlas;
mod chain;
mod claims;
mod detach;
mod directions;
mod drives;
mod errors;
mod interrupt;
mod page;
mod planar_runs;
mod planar_states;
mod results;
mod run;
mod states;
mod steady;
mod string;
mod sweep;
mod whirls;

use pyo3::prelude::*;

/// The native part of the `pendulum` package (`pendulum._pendulum`); import `pendulum`.
#[pymodule]
fn _pendulum(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", pendulum_experiment::VERSION)?;
    m.add_class::<chain::Chain>()?;
    m.add_class::<drives::Harmonic>()?;
    m.add_class::<drives::Circle>()?;
    m.add_class::<drives::Sampled>()?;
    m.add_class::<run::Run>()?;
    m.add_class::<run::RunResult>()?;
    m.add_class::<string::HeavyString>()?;
    m.add_function(wrap_pyfunction!(page::page, m)?)?;
    m.add_function(wrap_pyfunction!(steady::steady, m)?)?;
    m.add_function(wrap_pyfunction!(whirls::whirls, m)?)?;
    m.add_class::<atlas::AtlasPlan>()?;
    m.add_function(wrap_pyfunction!(sweep::run_sweep, m)?)?;
    m.add_function(wrap_pyfunction!(claims::check_claims, m)?)?;
    Ok(())
}
