//! When a call gives up the GIL and spreads over the cores.

use pyo3::prelude::*;

/// Rows at least this many numbers in all are computed on every core, with the GIL
/// released; smaller batches in the calling thread.
pub const PARALLEL_FROM: usize = 4096;

/// Runs `f` without the GIL when the batch is large enough to be worth it.
pub fn maybe_detached<T: Send>(py: Python<'_>, numbers: usize, f: impl FnOnce() -> T + Send) -> T {
    if numbers < PARALLEL_FROM { f() } else { py.detach(f) }
}
