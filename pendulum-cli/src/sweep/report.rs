//! What `pendulum sweep` says while and after it runs: the header line, a line per
//! finished point (with the energy balance's warning), sweep.json rewritten after each,
//! and the closing line with the error of an interrupted (exit 130) or failed (exit 1)
//! sweep.

use std::path::Path;
use std::sync::atomic::Ordering;
use std::time::Instant;

use pendulum_experiment::sweep::{Point, Status, Sweep};

use crate::error::{CliError, CliResult};
use crate::interrupt::INTERRUPTED;

/// The line on stderr before the runs.
pub fn header(sweep: &Sweep, jobs: usize) {
    let (c, derived) = (sweep.config(), sweep.derived());
    let (speeds, kinds) = (c.omegas.len(), c.kinds.len());
    eprintln!(
        "pendulum: sweep of {speeds} speed{} × {kinds} kind{} = {} runs of {} s each \
         (RK4 + projection, h = {} s, {} steps) on {} thread{}{}; {}, pivot on a circle of \
         radius {} m",
        if speeds == 1 { "" } else { "s" },
        if kinds == 1 { "" } else { "s" },
        sweep.points().len(),
        c.duration,
        c.step,
        derived.steps_per_point,
        jobs,
        if jobs == 1 { "" } else { "s" },
        if sweep.has_ramp_down() { "; the ramp-down points run one after the other" } else { "" },
        pendulum_experiment::words::chain_words(&c.masses, &c.lengths, c.gravity, &c.damping),
        c.radius,
    );
}

/// After point `i` finished: its balance warning and (unless `quiet`) its line on
/// stderr, then sweep.json in `out` rewritten.
pub fn point_done(
    sweep: &Sweep,
    out: &Path,
    quiet: bool,
    started: Instant,
    (points, i, finished): (&[Point], usize, usize),
) -> CliResult<()> {
    let point = &points[i];
    if let Some(warning) = point.result.as_ref().and_then(|r| r.balance).and_then(|b| b.warning()) {
        eprintln!("pendulum: warning: {} at ω = {} rad/s: {warning}", point.kind.name(), point.omega);
    }
    if !quiet {
        let elapsed = started.elapsed().as_secs_f64();
        eprintln!(
            "pendulum: [{finished}/{}] {} ({elapsed:.0} s elapsed)",
            points.len(),
            progress_line(point)
        );
    }
    sweep.file(points).write_atomic(&out.join("sweep.json"))
}

/// After the files are written: the final sweep.json, the closing line, and the error
/// for an interrupted (exit 130) or failed (exit 1) sweep.
pub fn conclude(
    sweep: &Sweep,
    points: &[Point],
    out: &Path,
    (jobs, quiet): (usize, bool),
    started: Instant,
) -> CliResult<()> {
    let count = |s: Status| points.iter().filter(|p| p.status == s).count();
    let (done, failed) = (count(Status::Completed), count(Status::Failed));
    let cut = count(Status::Interrupted) + count(Status::NotRun);
    let interrupted = cut > 0 && INTERRUPTED.load(Ordering::SeqCst);
    let mut file = sweep.file(points);
    file.status = if interrupted {
        "interrupted"
    } else if failed > 0 {
        "failed"
    } else {
        "completed"
    }
    .into();
    file.write_atomic(&out.join("sweep.json"))?;
    let total = points.len();
    let dir = out.display();
    if !quiet {
        eprintln!(
            "pendulum: {done} of {total} points done in {:.1} s on {} thread{}; files in {dir} \
                 (sweep.csv, sweep.json, sweep.png)",
            started.elapsed().as_secs_f64(),
            jobs,
            if jobs == 1 { "" } else { "s" }
        );
    }
    if interrupted {
        return Err(CliError::interrupted(format!(
            "interrupted: {done} of {total} points finished; {dir} holds them (sweep.csv, sweep.json, \
                 sweep.png; the {cut} unfinished are marked interrupted or not-run)"
        )));
    }
    if let Some(p) = points.iter().find(|p| p.status == Status::Failed) {
        return Err(CliError::failed(format!(
            "{failed} of {total} points failed (first: {} at ω = {} rad/s: {}); files in {dir} hold the others",
            p.kind.name(),
            p.omega,
            p.error.as_deref().unwrap_or("unknown error")
        )));
    }
    Ok(())
}

/// `1 node`, `3 nodes`.
pub fn nodes_name(k: usize) -> String {
    format!("{k} node{}", if k == 1 { "" } else { "s" })
}

/// One line about a finished point: kind, speed, nodes, tip radius, settled, nearest.
fn progress_line(p: &Point) -> String {
    let head = format!("{} ω = {:.4} rad/s ({:.3} √(g/L))", p.kind.name(), p.omega, p.omega_scaled);
    match (&p.result, p.status) {
        (Some(r), _) => {
            let settled = if r.settled { "settled" } else { "not settled" };
            let nearest = match &r.nearest {
                Some(n) => format!(
                    "nearest steady shape {:.1e} m away, {}, {}",
                    n.distance,
                    nodes_name(n.nodes),
                    if n.stable { "stable" } else { "unstable" }
                ),
                None => "no steady shape found nearby".into(),
            };
            format!(
                "{head}: {}, tip radius {:.4} m, {settled} (drift {:.1e} m); {nearest}{}",
                nodes_name(r.nodes),
                r.tip_radius,
                r.drift,
                r.wall_seconds.map_or(String::new(), |w| format!("; {w:.1} s"))
            )
        }
        (None, status) => match &p.error {
            Some(e) => format!("{head}: {}: {e}", status.name()),
            None => format!("{head}: {}", status.name()),
        },
    }
}
