//! Ctrl-C: a flag the long runs (`simulate`, `sweep`) look at between samples, so that
//! they stop, write valid files and exit 130; and that stops `pendulum view`'s server.

use std::sync::atomic::{AtomicBool, Ordering};

/// Set by the Ctrl-C handler; a run stops at its next sample and writes its files.
pub static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// Ctrl-C once: the run stops at its next sample and writes valid files. Twice: exit at
/// once (status 130).
pub fn install_handler() {
    let installed = ctrlc::set_handler(|| {
        if INTERRUPTED.swap(true, Ordering::SeqCst) {
            std::process::exit(130);
        }
    });
    if let Err(e) = installed {
        eprintln!("pendulum: warning: Ctrl-C will end the run without writing files ({e})");
    }
}
