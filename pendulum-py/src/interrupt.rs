//! Long computations that Ctrl-C can stop: the work on a thread of its own, while the
//! calling thread, without the GIL, looks for signals.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, mpsc};
use std::time::Duration;

use pyo3::prelude::*;

/// How often the waiting thread looks for Ctrl-C.
const SIGNAL_CHECK: Duration = Duration::from_millis(50);

/// Runs `work(stop)` on a thread of its own and waits for it without the GIL, looking for
/// signals every 50 ms. On Ctrl-C, sets the flag `work` is given (so that it stops at its
/// next check) and raises `KeyboardInterrupt` at once; the work's result is dropped.
/// `what` names the work in the error should its thread die.
pub fn interruptible<T: Send + 'static>(
    py: Python<'_>,
    what: &str,
    work: impl FnOnce(&AtomicBool) -> pendulum_experiment::Result<T> + Send + 'static,
) -> PyResult<pendulum_experiment::Result<T>> {
    let stop = Arc::new(AtomicBool::new(false));
    let (sender, receiver) = mpsc::channel();
    let worker_stop = Arc::clone(&stop);
    std::thread::spawn(move || {
        let _ = sender.send(work(&worker_stop));
    });
    py.detach(move || {
        loop {
            match receiver.recv_timeout(SIGNAL_CHECK) {
                Ok(outcome) => return Ok(outcome),
                Err(mpsc::RecvTimeoutError::Timeout) => {
                    if let Err(e) = Python::attach(|py| py.check_signals()) {
                        stop.store(true, Ordering::SeqCst);
                        return Err(e);
                    }
                }
                Err(mpsc::RecvTimeoutError::Disconnected) => {
                    return Ok(Err(pendulum_experiment::Error::failed(format!(
                        "{what} stopped unexpectedly"
                    ))));
                }
            }
        }
    })
}
