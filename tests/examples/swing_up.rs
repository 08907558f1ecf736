//! Swinging into a steady shape: a 3D chain hanging at rest, its pivot moved on a small
//! horizontal circle at ω with light damping, run until it settles; the shape it settles
//! into is compared with the steady shapes of `SteadyRotation` at the same ω.
//!
//! ```text
//! cargo run --release -p pendulum-tests --example swing_up
//! ```
//!
//! prints the sweep tables (Markdown) and writes `docs/data/swing-up.csv`. Two sweeps:
//! the drive switched on at full speed ("sudden", `Circle`), and its speed ramped linearly
//! from 0 over `RAMP` seconds then held ("ramp", `RampedCircle`); both run `DURATION`
//! seconds in all. The chain is simulated in unit link directions (`Directions<U3, _>`,
//! RK4 + projection), in the inertial frame, with the damping of the chain's Rayleigh
//! function (`D = ½ Σ λ |u̇_i|²`, inertial rates), and every step is fed to a
//! `ShapeTracker` (`pendulum-core/src/analysis/shape.rs`), which does the analysis: the
//! positions in the frame rotating with the pivot (the pivot at `(R, 0, 0)`), the node
//! count, whether the chain settled (no mass moved more than `1e-3 L` in that frame over
//! the last `SETTLE_WINDOW` seconds, here as `ShapeOptions::periods`), and the exact damped
//! relative equilibrium nearest the final shape (`relative_equilibrium`, Newton on the
//! `Directions` model's own equations in the turning frame) with the largest real part of
//! its damped spectrum (`relative_spectrum`). On top of that, all undamped forced steady
//! shapes at the same ω are collected from the continuation branches
//! (`SteadyRotation::solutions_at`), and the nearest to the final shape (largest distance
//! between corresponding masses) is the matching one; the table reports both node counts,
//! that distance, and the out-of-plane lag `max |y_i|` from the pivot's plane (the inertial
//! damping's doing: the undamped steady shape is planar).
//!
//! A shortened run (no CSV written; the CSV printed instead) for checks:
//!
//! ```text
//! SWING_UP_DURATION=60 SWING_UP_RAMP=20 SWING_UP_SPEEDS=0.9,1.6,3.2 \
//!     cargo run --release -p pendulum-tests --example swing_up
//! ```

use std::{error::Error, f64::consts::TAU, fmt::Write as _, fs, path::PathBuf};

use nalgebra::{DVector, Dyn, U3, Vector3};
use pendulum_core::integrate::{Integrator, Projected, Rk4, State};
use pendulum_core::{
    Branch, Chain, Circle, ContinuationOptions, Directions, RampedCircle, ShapeOptions, ShapeReport,
    ShapeTracker, SteadyRotation, SteadyShape, Turning, normal_modes, stability,
};

const LINKS: usize = 20;
const LENGTH: f64 = 1.0;
const MASS: f64 = 1.0;
const GRAVITY: f64 = 9.81;
/// Pivot circle radius, m.
const RADIUS: f64 = 0.02;
/// Decay rate of the first mode at rest the damping is chosen for, 1/s.
const FIRST_MODE_DECAY: f64 = 0.02;
/// Simulated time per speed, s (`SWING_UP_DURATION` overrides).
const DURATION: f64 = 600.0;
/// Settled: rotating-frame positions moved less than `1e-3 L` over this window, s.
const SETTLE_WINDOW: f64 = 10.0;
/// RK4 step, s.
const STEP: f64 = 1e-3;
/// Length of the linear speed ramp of the second sweep, s (`SWING_UP_RAMP` overrides).
const RAMP: f64 = 200.0;
/// The speeds, in units of sqrt(g/L) (`SWING_UP_SPEEDS`, comma-separated, overrides).
const SPEEDS: [f64; 15] = [0.5, 0.9, 1.1, 1.3, 1.6, 2.0, 2.4, 2.6, 2.9, 3.2, 3.6, 4.0, 4.4, 4.8, 5.2];

/// Mass positions, m.
type Shape = Vec<Vector3<f64>>;

/// Integrate from hanging at rest for `duration` s, every step fed to the shape analysis
/// (settle window `SETTLE_WINDOW` seconds at the final speed `omega`); its report at the end.
fn simulate<Dr: Turning>(
    model: &Directions<U3, Dr>,
    omega: f64,
    duration: f64,
) -> Result<ShapeReport, Box<dyn Error>> {
    let options = ShapeOptions { periods: SETTLE_WINDOW * omega.abs() / TAU, ..ShapeOptions::default() };
    let mut tracker = ShapeTracker::new(model, options)?;
    let mut state = State::new(0.0, model.hanging());
    let mut solver = Projected::new(Rk4::new(model));
    for _ in 0..(duration / STEP).round() as usize {
        solver.step(model, &mut state, STEP)?;
        tracker.push(state.t(), state.x())?;
    }
    Ok(tracker.report()?)
}

fn max_distance(a: &[Vector3<f64>], b: &[Vector3<f64>]) -> f64 {
    a.iter().zip(b).map(|(p, q)| (p - q).norm()).fold(0.0, f64::max)
}

/// The same in the shape's plane only (x and z, out-of-plane y ignored).
fn max_in_plane_distance(a: &[Vector3<f64>], b: &[Vector3<f64>]) -> f64 {
    a.iter().zip(b).map(|(p, q)| (p.x - q.x).hypot(p.z - q.z)).fold(0.0, f64::max)
}

struct Row {
    omega: f64,
    settled: bool,
    drift: f64,
    nodes_sim: usize,
    nodes_steady: Option<usize>,
    distance: Option<f64>,
    in_plane: Option<f64>,
    lag: f64,
    amplitude: f64,
    class: String,
    solutions: usize,
    damped_distance: Option<f64>,
    damped_growth: Option<f64>,
}

fn run(
    chain: &Chain<Dyn>,
    branches: &[Branch],
    omega: f64,
    duration: f64,
    ramp: Option<f64>,
) -> Result<Row, Box<dyn Error>> {
    let plain = Directions::<U3>::new(chain.clone());
    let report = match ramp {
        None => simulate(&plain.with_drive(Circle::new(RADIUS, omega)?), omega, duration)?,
        Some(ramp) => {
            simulate(&plain.with_drive(RampedCircle::new(RADIUS, 0.0, omega, ramp)?), omega, duration)?
        }
    };
    let last: &Shape = &report.shape.positions;
    let drift = report.settling.drift / LENGTH;
    let lag = last.iter().map(|r| r.y.abs()).fold(0.0, f64::max) / LENGTH;
    let amplitude =
        last.iter().map(|r| r.x).fold(0.0_f64, |a, x| if x.abs() > a.abs() { x } else { a }) / LENGTH;
    let problem = SteadyRotation::new(chain, RADIUS)?;
    let candidates = problem.solutions_at(branches, omega);
    let steady_positions = |shape: &SteadyShape| -> Shape {
        let mut z = 0.0;
        shape
            .displacements
            .iter()
            .zip(chain.lengths().iter().zip(shape.theta.iter()))
            .map(|(x, (l, t))| {
                z -= l * t.cos();
                Vector3::new(*x, 0.0, z)
            })
            .collect()
    };
    let nearest = candidates
        .iter()
        .map(|c| (max_distance(&steady_positions(c), last) / LENGTH, c))
        .min_by(|a, b| a.0.total_cmp(&b.0));
    let in_plane = nearest.map(|(_, shape)| max_in_plane_distance(&steady_positions(shape), last) / LENGTH);
    let (nodes_steady, distance, class) = match nearest {
        Some((d, shape)) => {
            let st = stability(&problem, shape, None)?;
            let class = match (st.spectrally_stable, st.index) {
                (true, 0) => "stable".to_string(),
                (true, i) => format!("gyroscopic (index {i})"),
                (false, i) => format!("unstable (index {i}, growth {:.1e} 1/s)", st.growth_rate),
            };
            (Some(shape.nodes()), Some(d), class)
        }
        None => (None, None, "no steady shape on the branches".to_string()),
    };
    // The exact damped relative equilibrium nearest the final shape and its spectrum.
    let damped = report.nearest.as_ref().ok();
    Ok(Row {
        omega,
        settled: report.settling.settled,
        drift,
        nodes_sim: report.shape.nodes,
        nodes_steady,
        distance,
        in_plane,
        lag,
        amplitude,
        class,
        solutions: candidates.len(),
        damped_distance: damped.map(|d| d.distance / LENGTH),
        damped_growth: damped.map(|d| d.growth_rate),
    })
}

/// `name` from the environment, parsed, or `default`.
fn setting<T: std::str::FromStr>(name: &str, default: T) -> Result<T, Box<dyn Error>> {
    match std::env::var(name) {
        Ok(v) => v.parse().map_err(|_| format!("{name}={v}: not a number").into()),
        Err(_) => Ok(default),
    }
}

fn main() -> Result<(), Box<dyn Error>> {
    let docs = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../docs");
    let duration: f64 = setting("SWING_UP_DURATION", DURATION)?;
    let ramp_length: f64 = setting("SWING_UP_RAMP", RAMP)?;
    let fractions: Vec<f64> = match std::env::var("SWING_UP_SPEEDS") {
        Ok(v) => v.split(',').map(str::parse).collect::<Result<_, _>>()?,
        Err(_) => SPEEDS.to_vec(),
    };
    let shortened = duration != DURATION || ramp_length != RAMP || fractions != SPEEDS;
    let plain = Chain::<Dyn>::uniform(LINKS, MASS / LINKS as f64, LENGTH / LINKS as f64, GRAVITY)?;
    // Damping λ (same on every link) giving the first mode at rest the decay rate
    // ½ λ Σ_i v_i² = FIRST_MODE_DECAY (v mass-normalised, so vᵀ W v = 1).
    let modes = normal_modes(&plain);
    let sum_v2: f64 = modes.shapes.column(0).iter().map(|v| v * v).sum();
    let damping = 2.0 * FIRST_MODE_DECAY / sum_v2;
    let chain = plain.with_damping(&[damping; LINKS])?;
    let critical = SteadyRotation::new(&chain, 0.0)?.bifurcation_speeds(3)?;
    let scale = (GRAVITY / LENGTH).sqrt();
    println!(
        "n = {LINKS}, L = {LENGTH} m, R = {RADIUS} m, λ = {damping:.3e} N·m·s per link, {duration} s per run, RK4 h = {STEP} s"
    );
    println!(
        "critical speeds ω_k / sqrt(g/L): {:.4}, {:.4}, {:.4}",
        critical[0] / scale,
        critical[1] / scale,
        critical[2] / scale
    );
    // The forced steady shapes: from rest upwards, and down from both signs of each free
    // branch's end (the forced branches fold; see rotating_chain).
    let omega_max = 5.6 * scale;
    let opts = ContinuationOptions::default();
    let free = SteadyRotation::new(&chain, 0.0)?;
    let forced = SteadyRotation::new(&chain, RADIUS)?;
    let mut branches =
        vec![forced.continue_from(&forced.solve(0.0, &DVector::zeros(LINKS))?, true, omega_max, &opts)?];
    for k in 1..=4 {
        let end = free.branch(k, omega_max, &opts)?.points.pop().expect("branches have points");
        for sign in [1.0, -1.0] {
            let start = forced.solve(0.99 * omega_max, &(&end.theta * sign))?;
            branches.push(forced.continue_from(&start, false, omega_max, &opts)?);
        }
    }
    let header = String::from(
        "| ω / sqrt(g/L) | ω (rad/s) | settled (drift / L) | nodes (sim) | steady shapes at ω | nodes (nearest) | distance / L | in-plane distance / L | out-of-plane lag / L | signed amplitude / L | nearest steady shape | damped steady: distance / L | damped steady: growth (1/s) |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let mut csv = String::from(
        "start,omega_rad_s,settled,drift_over_L,nodes_sim,steady_solutions,nodes_steady,distance_over_L,in_plane_distance_over_L,lag_over_L,amplitude_over_L,steady_class,damped_distance_over_L,damped_growth_rate_1_s\n",
    );
    for ramp in [None, Some(ramp_length)] {
        let start = ramp.map_or("sudden".to_string(), |t| format!("ramp {t} s"));
        let mut table = header.clone();
        for &f in &fractions {
            let omega = f * scale;
            let r = run(&chain, &branches, omega, duration, ramp)?;
            let opt = |v: Option<f64>| v.map_or("–".to_string(), |d| format!("{d:.2e}"));
            let _ = writeln!(
                table,
                "| {f:.2} | {:.3} | {} ({:.1e}) | {} | {} | {} | {} | {} | {:.1e} | {:+.3} | {} | {} | {} |",
                r.omega,
                if r.settled { "yes" } else { "no" },
                r.drift,
                r.nodes_sim,
                r.solutions,
                r.nodes_steady.map_or("–".to_string(), |n| n.to_string()),
                opt(r.distance),
                opt(r.in_plane),
                r.lag,
                r.amplitude,
                r.class,
                opt(r.damped_distance),
                r.damped_growth.map_or("–".to_string(), |g| format!("{g:+.2e}"))
            );
            let _ = writeln!(
                csv,
                "{start},{:.6},{},{:.3e},{},{},{},{},{},{:.3e},{:.6},{},{},{}",
                r.omega,
                r.settled,
                r.drift,
                r.nodes_sim,
                r.solutions,
                r.nodes_steady.map_or(String::new(), |n| n.to_string()),
                r.distance.map_or(String::new(), |d| format!("{d:.3e}")),
                r.in_plane.map_or(String::new(), |d| format!("{d:.3e}")),
                r.lag,
                r.amplitude,
                r.class,
                r.damped_distance.map_or(String::new(), |d| format!("{d:.3e}")),
                r.damped_growth.map_or(String::new(), |g| format!("{g:.3e}"))
            );
            eprintln!("{start}, ω / sqrt(g/L) = {f}: done");
        }
        println!("\nstart: {start}");
        print!("{table}");
    }
    if shortened {
        println!("\nshortened run, docs/data/swing-up.csv not written:\n{csv}");
    } else {
        fs::create_dir_all(docs.join("data"))?;
        fs::write(docs.join("data/swing-up.csv"), csv)?;
        println!("wrote docs/data/swing-up.csv");
    }
    Ok(())
}
