//! The steady shapes of a chain as a front end shows them: the branches up to exactly
//! `ω_max`, each point with its node count and undamped verdict (for a fixed pivot also the
//! vertical), the verdict of one shape ([`judge`]), the shapes at asked speeds with their
//! damped verdicts ([`shapes_at`], [`damped_verdict`]). `pendulum steady` and the Python
//! package draw, tabulate and write these.

use std::sync::atomic::{AtomicBool, Ordering};

use nalgebra::{DVector, Dyn, U3, Vector3};
use pendulum_core::{
    Branch, BranchEnd, Chain, Circle, ContinuationOptions, Directions, SteadyRotation, SteadyShape, Verdict,
    relative_equilibrium, relative_spectrum_near_origin, stability,
};
use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::spelling::{opt, opt_is};

/// Margin of the default `ω_max` over the third critical speed (below the fourth for
/// uniform chains: ω_4/ω_3 = 1.37 at n = 12, 1.36 in the continuum).
pub const DEFAULT_MARGIN: f64 = 1.25;

/// `x > 0` rounded up to three significant digits (`15.2268 → 15.3`), the nearest `f64`
/// to that decimal.
pub fn round_up(x: f64) -> f64 {
    let decimals = 2 - x.log10().floor() as i32;
    let scale = 10f64.powi(decimals);
    let up = (x * scale * (1.0 - 1e-15)).ceil();
    if decimals >= 0 { (up / scale).max(x) } else { (up * 10f64.powi(-decimals)).max(x) }
}

/// The default `ω_max` (rad/s): [`DEFAULT_MARGIN`] times the third critical speed of
/// `free` (the chain on a fixed pivot; the n-th if n < 3), [`round_up`], or the largest of
/// `listed` if higher.
///
/// Errors: those of [`SteadyRotation::bifurcation_speeds`].
pub fn default_omega_max(free: &SteadyRotation, listed: &[f64]) -> Result<f64> {
    let speeds = free.bifurcation_speeds(free.links().min(3))?;
    let default = round_up(DEFAULT_MARGIN * speeds[speeds.len() - 1]);
    Ok(listed.iter().fold(default, |a, &b| a.max(b)))
}

/// Checks a given `ω_max` (rad/s): finite and positive.
///
/// Errors: [`Error::Invalid`] naming it.
pub fn check_omega_max(omega_max: f64) -> Result<()> {
    if omega_max.is_finite() && omega_max > 0.0 {
        Ok(())
    } else {
        Err(Error::invalid(format!("{} must be finite and positive, got {omega_max}", opt("omega-max"))))
    }
}

/// Checks what a front end asked of the steady shapes of a chain of `n` links on a pivot
/// circle of `radius` (m) — the `listed` speeds (rad/s, already finite and non-negative),
/// `omega_max` and the number of `branches` — and returns `ω_max`: the one given, or
/// [`default_omega_max`] of `free` (the chain on a fixed pivot).
///
/// Errors: [`Error::Invalid`] naming the option: `branches` for a circling pivot or
/// outside `1..=n`, a bad `omega_max`, a listed speed above it.
pub fn requested_omega_max(
    free: &SteadyRotation,
    radius: f64,
    listed: Option<&[f64]>,
    omega_max: Option<f64>,
    branches: Option<usize>,
) -> Result<f64> {
    let n = free.links();
    if radius != 0.0 && branches.is_some() {
        return Err(Error::invalid(format!(
            "{} applies to a fixed pivot ({}) only",
            opt("branches"),
            opt_is("radius", 0)
        )));
    }
    if let Some(count) = branches
        && (count == 0 || count > n)
    {
        return Err(Error::invalid(format!(
            "{} must be between 1 and n = {n}, got {count}",
            opt("branches")
        )));
    }
    match omega_max {
        Some(w) => {
            check_omega_max(w)?;
            if let Some(&above) = listed.into_iter().flatten().find(|&&v| v > w) {
                return Err(Error::invalid(format!(
                    "{}: {above} rad/s is above {} = {w} rad/s (the branches end there)",
                    opt("omega"),
                    opt("omega-max")
                )));
            }
            Ok(w)
        }
        None => default_omega_max(free, listed.unwrap_or(&[])),
    }
}

/// The node count of a shape, `None` for the vertical (every mass on the axis).
pub fn nodes(shape: &SteadyShape) -> Option<usize> {
    (shape.amplitude() > 0.0).then(|| shape.nodes())
}

/// `"1 node"`, `"3 nodes"`.
pub fn nodes_name(k: usize) -> String {
    format!("{k} node{}", if k == 1 { "" } else { "s" })
}

/// The undamped verdict of one shape and the numbers behind it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Judged {
    /// Stable, gyroscopic (index) or unstable (growth rate).
    pub verdict: Verdict,
    /// Negative eigenvalues of the amended potential's Hessian `H`, in and out of the plane.
    pub index: usize,
    /// Largest real part of the eigenvalues found, 1/s (round-off when not unstable;
    /// without the rotational symmetry's zeros for a fixed pivot).
    pub growth_rate: f64,
}

/// [`stability`] of `shape`, undamped, as a [`Judged`].
///
/// Errors: [`Error::Failed`] naming the speed when the stability cannot be computed.
pub fn judge(problem: &SteadyRotation, shape: &SteadyShape) -> Result<Judged> {
    let st = stability(problem, shape, None).map_err(|e| {
        Error::failed(format!("stability of the steady shape at ω = {} rad/s: {e}", shape.omega))
    })?;
    Ok(Judged { verdict: st.verdict(), index: st.index, growth_rate: st.growth_rate })
}

/// One branch, named and judged.
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

/// Everything [`follow`] follows.
#[derive(Debug, Clone)]
pub struct Family {
    /// The branches, numbered from 1 in the tables and CSV files.
    pub branches: Vec<Labelled>,
    /// Fixed pivot: the vertical `θ = 0` on the stretches between consecutive critical
    /// speeds, `(from, to, verdict)` in rad/s (it is a solution at every ω).
    pub vertical: Vec<(f64, f64, Judged)>,
    /// The critical speeds of the chain on a fixed pivot below `ω_max`, rad/s.
    pub critical: Vec<f64>,
    /// Fixed pivot: branches leaving the vertical below `ω_max` not followed (a `count`
    /// below their number).
    pub skipped: usize,
    /// What the following noticed (a branch ending short of `ω_max`), one line each.
    pub notes: Vec<String>,
}

/// Follows the branches of `problem` up to exactly `omega_max` (rad/s): for a fixed pivot
/// the `count` lowest from the vertical (default: every one leaving it below
/// `omega_max`); for a circling pivot the branch from rest (`ω = 0`) and those through the
/// free chain's shapes at `omega_max` (`free`, the same chain on a fixed pivot) on either
/// side of the axis, followed downward (they fold back up). Every point gets its node
/// count and undamped verdict ([`judge`]), in parallel on all cores; `judged(total)` is
/// called after each (from any thread, `total` the points to judge) and returning `false`
/// stops the judging: each branch then
/// keeps its points up to the first one not judged (a front end's progress and Ctrl-C).
///
/// Errors: [`Error::Invalid`] for a `count` outside `1..=n`; those of the continuation and
/// of [`judge`].
pub fn follow(
    problem: &SteadyRotation,
    free: &SteadyRotation,
    omega_max: f64,
    count: Option<usize>,
    judged: &(dyn Fn(usize) -> bool + Sync),
) -> Result<Family> {
    let n = problem.links();
    let options = ContinuationOptions::default();
    let below = free.unstable_directions_at_vertical(omega_max).min(n);
    let critical = free.bifurcation_speeds(below)?;
    let mut raw: Vec<(String, Option<f64>, Branch)> = Vec::new();
    let mut notes = Vec::new();
    let mut skipped = 0;
    let mut vertical = Vec::new();
    if problem.radius() == 0.0 {
        if let Some(count) = count
            && (count == 0 || count > n)
        {
            return Err(Error::invalid(format!(
                "the number of branches must be between 1 and n = {n}, got {count}"
            )));
        }
        let count = count.unwrap_or(below);
        skipped = below.saturating_sub(count);
        for (k, &speed) in problem.bifurcation_speeds(count)?.iter().enumerate() {
            if speed >= omega_max {
                continue;
            }
            let branch =
                end_exactly(problem, problem.branch(k + 1, omega_max, &options)?, omega_max, &mut notes);
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
        let mut found = vec![end_exactly(problem, from_rest, omega_max, &mut notes)];
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
                    found.push(end_exactly(problem, branch, omega_max, &mut notes));
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
    let total = raw.iter().map(|(_, _, b)| b.points.len()).sum();
    let judged_one = || judged(total);
    // One flag for all branches: once the hook says stop, no branch judges another point.
    let stop = AtomicBool::new(false);
    let branches = raw
        .into_iter()
        .map(|(name, critical, branch)| labelled(problem, name, critical, branch, &judged_one, &stop))
        .collect::<Result<_>>()?;
    Ok(Family { branches, vertical, critical, skipped, notes })
}

/// Node counts and verdicts of every point of `branch` (each verdict `O(n)` work per
/// Arnoldi step, [`pendulum_core::stability`]: about 1 ms at n = 100), the points judged in
/// parallel on all cores (each on its own: the same verdicts whatever the threads).
fn labelled(
    problem: &SteadyRotation,
    name: String,
    critical: Option<f64>,
    branch: Branch,
    judged_one: &(dyn Fn() -> bool + Sync),
    stop: &AtomicBool,
) -> Result<Labelled> {
    let judged: Vec<Option<Judged>> = branch
        .points
        .par_iter()
        .map(|p| {
            if stop.load(Ordering::SeqCst) {
                return Ok(None);
            }
            let verdict = judge(problem, p)?;
            if !judged_one() {
                stop.store(true, Ordering::SeqCst);
            }
            Ok(Some(verdict))
        })
        .collect::<Result<_>>()?;
    // Stopped: the points up to the first one not judged.
    let kept = judged.iter().take_while(|j| j.is_some()).count();
    let mut branch = branch;
    branch.points.truncate(kept);
    let judged: Vec<Judged> = judged.into_iter().take(kept).flatten().collect();
    let nodes = branch.points.iter().map(nodes).collect();
    Ok(Labelled { name, critical, branch, nodes, judged })
}

/// One steady shape at one asked speed.
#[derive(Debug, Clone)]
pub struct AtSpeed {
    /// The branch's number (from 1, in the family's order), 0 for the vertical.
    pub branch: usize,
    /// Its name (`"vertical"` for the vertical).
    pub name: String,
    /// The shape, at exactly the asked speed.
    pub shape: SteadyShape,
    /// Node count (`None`: the vertical).
    pub nodes: Option<usize>,
    /// Undamped verdict.
    pub judged: Judged,
    /// With damping: the damped verdict ([`damped_verdict`]), `None` if no damped steady
    /// shape was found or none was asked.
    pub damped: Option<Damped>,
}

impl AtSpeed {
    /// Tip radius `|x_n|`, m: the free end's distance from the axis.
    pub fn tip_radius(&self) -> f64 {
        self.shape.displacements.last().map_or(0.0, |x| x.abs())
    }
}

/// Every steady shape at each of `speeds` (rad/s) on the branches of `family` (and the
/// vertical for a fixed pivot), speeds in the order given, branches in their order, each
/// judged undamped and, with `damping` (N·m·s per link, of `chain`), damped
/// ([`damped_verdict`]). For a fixed pivot the mirror image `θ → −θ` of a shape is the
/// same shape turned by π about the axis and is not listed again.
///
/// Errors: those of [`judge`] and [`damped_verdict`].
pub fn shapes_at(
    problem: &SteadyRotation,
    chain: &Chain<Dyn>,
    family: &Family,
    speeds: &[f64],
    damping: Option<&[f64]>,
) -> Result<Vec<AtSpeed>> {
    let n = problem.links();
    let mut found = Vec::new();
    for &omega in speeds {
        let mut here: Vec<(usize, String, SteadyShape)> = Vec::new();
        if problem.radius() == 0.0 {
            here.push((0, "vertical".into(), problem.shape(omega, DVector::zeros(n))));
        }
        for (b, labelled) in family.branches.iter().enumerate() {
            for shape in problem.solutions_at(std::slice::from_ref(&labelled.branch), omega) {
                if here.iter().all(|(_, _, s)| (&s.theta - &shape.theta).amax() > 1e-8) {
                    here.push((b + 1, labelled.name.clone(), shape));
                }
            }
        }
        for (branch, name, shape) in here {
            let judged = judge(problem, &shape)?;
            let damped = match damping {
                Some(d) => damped_verdict(problem, chain, &shape, d)?,
                None => None,
            };
            found.push(AtSpeed { branch, name, nodes: nodes(&shape), shape, judged, damped });
        }
    }
    Ok(found)
}

/// The damped verdict of one shape.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Damped {
    /// Stable (every eigenvalue decays) or unstable.
    pub verdict: Verdict,
    /// Largest real part of the damped eigenvalues, 1/s.
    pub growth_rate: f64,
    /// Largest distance between corresponding masses of the damped and the undamped
    /// shape, m (the damped shape lags out of the plane; 0 for a fixed pivot).
    pub shift: f64,
}

/// The damped verdict of `shape` with damping `d` (N·m·s per link of `chain`); `None` when
/// Newton finds no damped relative equilibrium near it.
///
/// Damped, for a fixed pivot (`R = 0`): [`stability`] with the damping `λ_i` on the link
/// rates in the turning frame; the steady shape is unchanged, and by Kelvin–Tait–Chetaev
/// only index-0 shapes stay stable. A fixed pivot cannot drive the rotation against a drag
/// of the inertial rates, so that damping has no steady shape to ask about. For a circling
/// pivot (`R > 0`): the chain's own damping of the inertial rates (`½ Σ λ_i |u̇_i|²`, as in
/// `pendulum simulate`); the damped steady shape is the relative equilibrium of the 3D
/// chain in unit directions on the circling pivot ([`relative_equilibrium`], Newton from
/// the undamped planar shape), and its verdict is that of the eigenvalues that can grow
/// ([`relative_spectrum_near_origin`]), growth counted above `1e-6` times the spectrum's
/// size ([`SteadyRotation::spectrum_scale`]).
///
/// Errors: [`Error::Failed`] naming the speed when a spectrum cannot be computed; those of
/// the chain's damping.
pub fn damped_verdict(
    problem: &SteadyRotation,
    chain: &Chain<Dyn>,
    shape: &SteadyShape,
    d: &[f64],
) -> Result<Option<Damped>> {
    let omega = shape.omega;
    if problem.radius() == 0.0 {
        let st = stability(problem, shape, Some(d))
            .map_err(|e| Error::failed(format!("damped stability at ω = {omega} rad/s: {e}")))?;
        return Ok(Some(Damped { verdict: st.verdict(), growth_rate: st.growth_rate, shift: 0.0 }));
    }
    let radius = problem.radius();
    let Ok(circle) = Circle::new(radius, omega) else { return Ok(None) };
    let model = Directions::<U3>::new(chain.clone().with_damping(d)?).with_drive(circle);
    let guess: Vec<(f64, f64)> = shape.theta.iter().map(|&t| (t, 0.0)).collect();
    let Ok(eq) = relative_equilibrium(&model, &guess) else { return Ok(None) };
    let spectrum = relative_spectrum_near_origin(&model, &eq)
        .map_err(|e| Error::failed(format!("damped spectrum at ω = {omega} rad/s: {e}")))?;
    let tolerance = 1e-6 * problem.spectrum_scale(shape);
    let verdict = Verdict::of_spectrum(&spectrum, None, tolerance);
    let growth_rate = spectrum.iter().map(|z| z.re).fold(f64::NEG_INFINITY, f64::max);
    // Masses of the damped shape, r_i = (R, 0, 0) + Σ_{j≤i} l_j u_j, against (x_i, 0, z_i).
    let (mut r, mut z, mut shift) = (Vector3::new(radius, 0.0, 0.0), 0.0, 0.0_f64);
    for (i, (&l, &theta)) in chain.lengths().iter().zip(shape.theta.iter()).enumerate() {
        r += l * eq.state.fixed_rows::<3>(3 * i).into_owned();
        z -= l * theta.cos();
        shift = shift.max((r - Vector3::new(shape.displacements[i], 0.0, z)).norm());
    }
    Ok(Some(Damped { verdict, growth_rate, shift }))
}

/// The branch with its last point at exactly `omega_max`: a branch that reached it ends
/// one step past it, and that point is replaced by Newton's solution at `omega_max` from
/// the linear interpolation of the last two points' angles (dropped, with a note, if
/// Newton fails or lands on another shape).
fn end_exactly(
    problem: &SteadyRotation,
    mut branch: Branch,
    omega_max: f64,
    notes: &mut Vec<String>,
) -> Branch {
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
            notes.push(format!(
                "a branch ends at ω = {} rad/s, short of ω_max (no shape solved at {omega_max})",
                branch.points[len - 2].omega
            ));
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
