//! The branches of `pendulum steady` ([`pendulum_experiment::steady::follow`]), with a
//! progress line on stderr and Ctrl-C stopping the judging of their points.

use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use pendulum_core::SteadyRotation;
pub use pendulum_experiment::steady::{Family, Labelled};

use crate::error::CliResult;
use crate::interrupt::{INTERRUPTED, StopsItself};

/// The family of `problem` up to `omega_max` (rad/s), `count` branches for a fixed pivot
/// ([`pendulum_experiment::steady::follow`]), its notes on stderr; with `(judged, total)`
/// points when Ctrl-C cut the judging.
pub fn follow(
    problem: &SteadyRotation,
    free: &SteadyRotation,
    omega_max: f64,
    count: Option<usize>,
) -> CliResult<(Family, Option<(usize, usize)>)> {
    let progress = Progress::new();
    // Ctrl-C while judging stops the judging; the points judged so far are kept.
    let stops = StopsItself::enter();
    let family = pendulum_experiment::steady::follow(problem, free, omega_max, count, &|total| {
        progress.tick(total);
        !INTERRUPTED.load(Ordering::SeqCst)
    })?;
    drop(stops);
    if family.skipped > 0 {
        let below = family.skipped + family.branches.len();
        eprintln!(
            "pendulum: note: {} more branch{} leave{} the vertical below ω = {omega_max} rad/s \
             (--branches {below} follows them)",
            family.skipped,
            if family.skipped == 1 { "" } else { "es" },
            if family.skipped == 1 { "s" } else { "" },
        );
    }
    for note in &family.notes {
        eprintln!("pendulum: note: {}", note.replace("short of ω_max", "short of --omega-max"));
    }
    let cut = INTERRUPTED
        .load(Ordering::SeqCst)
        .then(|| (progress.done.load(Ordering::SeqCst), progress.total.load(Ordering::SeqCst)));
    Ok((family, cut))
}

/// How far the stability of the branches' points is: nothing in the first 2 s, then a
/// line on stderr every 5 s with the points judged and the time to go.
struct Progress {
    /// The points to judge (known at the first tick).
    total: AtomicUsize,
    done: AtomicUsize,
    started: Instant,
    /// When the last line was printed (the start: the first after 2 s).
    last: Mutex<Instant>,
}

impl Progress {
    fn new() -> Self {
        let started = Instant::now();
        let first = started.checked_sub(Duration::from_secs(3)).unwrap_or(started);
        Self { total: AtomicUsize::new(0), done: AtomicUsize::new(0), started, last: Mutex::new(first) }
    }

    /// One more point judged, of `total`.
    fn tick(&self, total: usize) {
        self.total.store(total, Ordering::SeqCst);
        let done = self.done.fetch_add(1, Ordering::SeqCst) + 1;
        let mut last = self.last.lock().unwrap_or_else(|e| e.into_inner());
        if last.elapsed() < Duration::from_secs(5) || done >= total {
            return;
        }
        *last = Instant::now();
        let elapsed = self.started.elapsed().as_secs_f64();
        let to_go = elapsed * (total - done) as f64 / done as f64;
        eprintln!(
            "pendulum: stability: {done} of {total} steady shapes judged, {elapsed:.0} s elapsed, about {to_go:.0} s to go"
        );
    }
}
