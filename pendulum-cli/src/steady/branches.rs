//! The branches of `pendulum steady`, each ending exactly at `ω_max`, with the node count
//! and the undamped verdict of every point; for a fixed pivot also the vertical.

use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use nalgebra::DVector;
use pendulum_core::{Branch, BranchEnd, ContinuationOptions, SteadyRotation, SteadyShape};
use rayon::prelude::*;

use super::{Judged, judge, nodes, nodes_name};
use crate::error::{CliError, CliResult};
use crate::interrupt::{INTERRUPTED, StopsItself};

/// One branch as the command shows it.
#[derive(Debug, Clone)]
pub struct Labelled {
    /// `"2 nodes"` (fixed pivot), `"forced, 1–2 nodes"` (the node counts along it).
    pub name: String,
    /// Fixed pivot: the critical speed it leaves the vertical at, rad/s.
    pub critical: Option<f64>,
    /// The points in continuation order; the last one at exactly `ω_max` when reached.
    pub branch: Branch,
    /// Node count of every point (`None`: the vertical, the bifurcation point).
    pub nodes: Vec<Option<usize>>,
    /// Undamped verdict of every point.
    pub judged: Vec<Judged>,
}

impl Labelled {
    /// The point whose node count and verdict the tables and plots show for point `i`:
    /// `i` itself, or for the bifurcation point (the vertical at a critical speed, where
    /// `H` is singular) the next point.
    pub fn shown(&self, i: usize) -> usize {
        if self.nodes[i].is_none() && i + 1 < self.nodes.len() { i + 1 } else { i }
    }
}

/// Everything `pendulum steady` follows.
#[derive(Debug, Clone)]
pub struct Family {
    /// The branches, numbered from 1 in the tables and CSV files.
    pub branches: Vec<Labelled>,
    /// Fixed pivot: the vertical `θ = 0` on the stretches between consecutive critical
    /// speeds, `(from, to, verdict)` in rad/s (it is a solution at every ω).
    pub vertical: Vec<(f64, f64, Judged)>,
    /// The critical speeds of the chain on a fixed pivot below `ω_max`, rad/s.
    pub critical: Vec<f64>,
    /// Ctrl-C cut the judging: `(judged, total)` points; each branch holds its points up
    /// to the last one judged in a row.
    pub cut: Option<(usize, usize)>,
}

/// Follows the branches of `problem` up to exactly `omega_max` (rad/s): for a fixed pivot
/// the `count` lowest from the vertical (default: every one leaving it below
/// `omega_max`); for a circling pivot the branch from rest (`ω = 0`) and those through the
/// free chain's shapes at `omega_max` (`free`, the same chain on a fixed pivot) on either
/// side of the axis, followed downward (they fold back up).
pub fn follow(
    problem: &SteadyRotation,
    free: &SteadyRotation,
    omega_max: f64,
    count: Option<usize>,
) -> CliResult<Family> {
    let n = problem.links();
    let options = ContinuationOptions::default();
    let below = free.unstable_directions_at_vertical(omega_max).min(n);
    let critical = free.bifurcation_speeds(below)?;
    let mut raw: Vec<(String, Option<f64>, Branch)> = Vec::new();
    let mut vertical = Vec::new();
    if problem.radius() == 0.0 {
        if let Some(count) = count
            && (count == 0 || count > n)
        {
            return Err(CliError::invalid(format!("--branches must be between 1 and n = {n}, got {count}")));
        }
        let count = count.unwrap_or(below);
        if count < below {
            eprintln!(
                "pendulum: note: {} more branch{} leave{} the vertical below ω = {omega_max} rad/s \
                 (--branches {below} follows them)",
                below - count,
                if below - count == 1 { "" } else { "es" },
                if below - count == 1 { "s" } else { "" },
            );
        }
        for (k, &speed) in problem.bifurcation_speeds(count)?.iter().enumerate() {
            if speed >= omega_max {
                continue;
            }
            let branch = end_exactly(problem, problem.branch(k + 1, omega_max, &options)?, omega_max);
            raw.push((nodes_name(k + 1), Some(speed), branch));
        }
        let mut ends = vec![0.0];
        ends.extend(critical.iter().copied());
        ends.push(omega_max);
        for pair in ends.windows(2) {
            let middle = problem.shape(0.5 * (pair[0] + pair[1]), DVector::zeros(n));
            vertical.push((pair[0], pair[1], judge(problem, &middle)?));
        }
    } else {
        // The forced branch from rest: hanging below the pivot, pushed out as ω grows.
        let start = problem.solve(0.0, &DVector::zeros(n))?;
        let from_rest = problem.continue_from(&start, true, omega_max, &options)?;
        let mut found = vec![end_exactly(problem, from_rest, omega_max)];
        // The branches not connected to rest (they fold back): from the free chain's shapes
        // at omega_max, on either side of the axis, followed downward.
        for k in 1..=below {
            let Ok(free_branch) = free.branch(k, omega_max, &options) else { continue };
            let Some(shape) = free_branch.points.last() else { continue };
            for sign in [1.0, -1.0] {
                let Ok(start) = problem.solve(omega_max, &(&shape.theta * sign)) else { continue };
                if found.iter().any(|b| on_branch(b, &start, omega_max)) {
                    continue;
                }
                if let Ok(branch) = problem.continue_from(&start, false, omega_max, &options) {
                    found.push(end_exactly(problem, branch, omega_max));
                }
            }
        }
        for branch in found {
            let counts: Vec<usize> = branch.points.iter().filter_map(nodes).collect();
            let (lo, hi) = counts.iter().fold((usize::MAX, 0), |(lo, hi), &k| (lo.min(k), hi.max(k)));
            let name = if lo >= hi {
                format!("forced, {}", nodes_name(hi))
            } else {
                format!("forced, {lo}–{hi} nodes")
            };
            raw.push((name, None, branch));
        }
    }
    let progress = Progress::new(raw.iter().map(|(_, _, b)| b.points.len()).sum());
    // Ctrl-C while judging stops the judging; the points judged so far are kept.
    let stops = StopsItself::enter();
    let branches: Vec<Labelled> = raw
        .into_iter()
        .map(|(name, critical, branch)| labelled(problem, name, critical, branch, &progress))
        .collect::<CliResult<_>>()?;
    drop(stops);
    let cut =
        INTERRUPTED.load(Ordering::SeqCst).then(|| (progress.done.load(Ordering::SeqCst), progress.total));
    Ok(Family { branches, vertical, critical, cut })
}

/// Node counts and verdicts of every point of `branch` (each verdict `O(n)` work per
/// Arnoldi step, [`pendulum_core::stability`]: about 1 ms at n = 100), the points judged in
/// parallel on all cores (each on its own: the same verdicts whatever the threads).
fn labelled(
    problem: &SteadyRotation,
    name: String,
    critical: Option<f64>,
    branch: Branch,
    progress: &Progress,
) -> CliResult<Labelled> {
    let judged: Vec<Option<Judged>> = branch
        .points
        .par_iter()
        .map(|p| {
            if INTERRUPTED.load(Ordering::SeqCst) {
                return Ok(None);
            }
            let verdict = judge(problem, p)?;
            progress.tick();
            Ok(Some(verdict))
        })
        .collect::<CliResult<_>>()?;
    // After Ctrl-C: the points up to the first one not judged.
    let kept = judged.iter().take_while(|j| j.is_some()).count();
    let mut branch = branch;
    branch.points.truncate(kept);
    let judged: Vec<Judged> = judged.into_iter().take(kept).flatten().collect();
    let nodes = branch.points.iter().map(nodes).collect();
    Ok(Labelled { name, critical, branch, nodes, judged })
}

/// How far the stability of the branches' points is: nothing in the first 2 s, then a
/// line on stderr every 5 s with the points judged and the time to go.
struct Progress {
    total: usize,
    done: AtomicUsize,
    started: Instant,
    /// When the last line was printed (the start: the first after 2 s).
    last: Mutex<Instant>,
}

impl Progress {
    fn new(total: usize) -> Self {
        let started = Instant::now();
        let first = started.checked_sub(Duration::from_secs(3)).unwrap_or(started);
        Self { total, done: AtomicUsize::new(0), started, last: Mutex::new(first) }
    }

    /// One more point judged.
    fn tick(&self) {
        let done = self.done.fetch_add(1, Ordering::SeqCst) + 1;
        let mut last = self.last.lock().unwrap_or_else(|e| e.into_inner());
        if last.elapsed() < Duration::from_secs(5) || done == self.total {
            return;
        }
        *last = Instant::now();
        let elapsed = self.started.elapsed().as_secs_f64();
        let to_go = elapsed * (self.total - done) as f64 / done as f64;
        eprintln!(
            "pendulum: stability: {done} of {} steady shapes judged, {elapsed:.0} s elapsed, about {to_go:.0} s to go",
            self.total
        );
    }
}

/// The branch with its last point at exactly `omega_max`: a branch that reached it ends
/// one step past it, and that point is replaced by Newton's solution at `omega_max` from
/// the linear interpolation of the last two points' angles (dropped, with a note, if
/// Newton fails or lands on another shape).
fn end_exactly(problem: &SteadyRotation, mut branch: Branch, omega_max: f64) -> Branch {
    let len = branch.points.len();
    if branch.end != BranchEnd::ReachedOmega || len < 2 || branch.points[len - 1].omega <= omega_max {
        return branch;
    }
    let (a, b) = (&branch.points[len - 2], &branch.points[len - 1]);
    let s = (omega_max - a.omega) / (b.omega - a.omega);
    let guess = &a.theta * (1.0 - s) + &b.theta * s;
    let step = (&b.theta - &a.theta).amax();
    match problem.solve(omega_max, &guess) {
        Ok(shape) if (&shape.theta - &guess).amax() <= step + 1e-3 => branch.points[len - 1] = shape,
        _ => {
            branch.points.pop();
            eprintln!(
                "pendulum: note: a branch ends at ω = {} rad/s, short of --omega-max (no shape solved at {omega_max})",
                branch.points[len - 2].omega
            );
        }
    }
    branch
}

/// `shape` lies on `branch`: at one of its points (1e-6 rad), or on a segment between two
/// of them (same ω range, angles within 0.02 rad of the linear interpolation: continuation
/// steps are coarse, distinct branches are much farther apart).
fn on_branch(branch: &Branch, shape: &SteadyShape, omega_max: f64) -> bool {
    let at_point = |p: &SteadyShape| {
        (p.omega - shape.omega).abs() < 1e-6 * omega_max && (&p.theta - &shape.theta).amax() < 1e-6
    };
    branch.points.iter().any(at_point) || branch.points.windows(2).any(|w| near_segment(&w[0], &w[1], shape))
}

fn near_segment(a: &SteadyShape, b: &SteadyShape, shape: &SteadyShape) -> bool {
    let (lo, hi) = if a.omega <= b.omega { (a, b) } else { (b, a) };
    if !(lo.omega <= shape.omega && shape.omega <= hi.omega) || hi.omega == lo.omega {
        return false;
    }
    let s = (shape.omega - lo.omega) / (hi.omega - lo.omega);
    let interpolated = &lo.theta * (1.0 - s) + &hi.theta * s;
    (&interpolated - &shape.theta).amax() < 0.02
}
