//! Ctrl-C in every command.
//!
//! A phase that can stop itself and leave valid files (`simulate`'s run loop, `sweep`'s
//! runs, `view`'s server, `steady`'s judging of the branch points) holds a [`StopsItself`]
//! guard: a Ctrl-C then sets [`INTERRUPTED`] and the phase ends at its next check.
//! Anywhere else (plotting, GIF encoding, `steady`'s continuation, `render`) a Ctrl-C exits
//! at once with status 130, after removing the
//! partial files registered as [`Partial`]: what was finished before stays, nothing
//! half-written does. A second Ctrl-C always exits at once.

use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// Set by the first Ctrl-C; a phase holding [`StopsItself`] stops at its next check.
pub static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// How many [`StopsItself`] guards are alive.
static STOPPING_ITSELF: AtomicUsize = AtomicUsize::new(0);

/// Files being written that are not yet valid.
static PARTIAL: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// The process exits with status 130 (the shell's convention after Ctrl-C).
pub const EXIT_STATUS: i32 = 130;

/// Output cut off by the reader (`pendulum modes … | head -1`) ends the process quietly,
/// as it does any Unix tool (SIGPIPE's default action), instead of a panic in the next
/// `println!`. Not for `view`, whose server writes to sockets the browser may close.
pub fn quiet_on_broken_pipe() {
    #[cfg(unix)]
    // SAFETY: restores a signal's default disposition at the start of `main`, before any
    // thread that could be writing exists.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

/// Installs the Ctrl-C handler (once, at the start of every command).
pub fn install_handler() {
    let installed = ctrlc::set_handler(|| {
        let first = !INTERRUPTED.swap(true, Ordering::SeqCst);
        if first && STOPPING_ITSELF.load(Ordering::SeqCst) > 0 {
            return;
        }
        let partial = PARTIAL.lock().unwrap_or_else(|e| e.into_inner());
        for path in partial.iter() {
            let _ = std::fs::remove_file(path);
        }
        eprintln!("error: interrupted; the files written before Ctrl-C are complete");
        std::process::exit(EXIT_STATUS);
    });
    if let Err(e) = installed {
        eprintln!("pendulum: warning: Ctrl-C will end the program without cleaning up ({e})");
    }
}

/// While alive, a Ctrl-C asks the current phase to stop at its next check of
/// [`INTERRUPTED`] instead of ending the process.
#[must_use = "the phase stops itself only while the guard lives"]
pub struct StopsItself(());

impl StopsItself {
    /// Enters a phase that checks [`INTERRUPTED`] at least once a second.
    pub fn enter() -> Self {
        STOPPING_ITSELF.fetch_add(1, Ordering::SeqCst);
        Self(())
    }
}

impl Drop for StopsItself {
    fn drop(&mut self) {
        STOPPING_ITSELF.fetch_sub(1, Ordering::SeqCst);
    }
}

/// A file being written: removed if Ctrl-C ends the process before the guard drops.
pub struct Partial(PathBuf);

impl Partial {
    /// Registers `path` until the guard drops.
    pub fn register(path: &Path) -> Self {
        PARTIAL.lock().unwrap_or_else(|e| e.into_inner()).push(path.to_path_buf());
        Self(path.to_path_buf())
    }
}

impl Drop for Partial {
    fn drop(&mut self) {
        let mut partial = PARTIAL.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(i) = partial.iter().position(|p| *p == self.0) {
            partial.swap_remove(i);
        }
    }
}
