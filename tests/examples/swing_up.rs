//! Swinging into a steady shape: a 3D chain hanging at rest, its pivot moved on a small
//! horizontal circle at ω with light damping, run until it settles; the shape it settles
//! into is compared with the steady shapes of `SteadyRotation` at the same ω.
//!
//! ```text
//! cargo run --release -p pendulum-tests --example swing_up
//! ```
//!
//! prints the sweep tables (Markdown) and writes `docs/data/swing-up.csv`. Two sweeps:
//! the drive switched on at full speed ("sudden"), and its speed ramped linearly from 0
//! over `RAMP` seconds then held ("ramp"); both run `DURATION` seconds in all. The chain is
//! simulated in unit link directions (`Directions<U3, Circle>`, RK4 + projection), in
//! the inertial frame, with the damping of the chain's Rayleigh function
//! (`D = ½ Σ λ |u̇_i|²`, inertial rates). At the end the positions are turned into the
//! frame rotating with the pivot (`p(t) = R (cos ωt, sin ωt, 0)`, so the pivot sits at
//! `(R, 0, 0)`); the chain counts as settled when those positions changed by less than
//! `1e-3 L` over the last `SETTLE_WINDOW` seconds. All forced steady shapes at the same ω
//! are collected from the continuation branches (`SteadyRotation::solutions_at`), and the
//! nearest to the final shape (largest distance between corresponding masses) is the
//! matching one; the table reports both node counts, that distance, and the out-of-plane
//! lag (the inertial damping's doing: the undamped steady shape is planar). Last, the
//! exact damped relative equilibrium nearest the final shape (`relative_equilibrium`,
//! Newton on the `Directions` model's own equations in the turning frame) gives the
//! distance to the shape the damped chain should settle into, and the largest real part
//! of its spectrum with the damping (`relative_spectrum`).

use std::{error::Error, fmt::Write as _, fs, path::PathBuf};

use nalgebra::{DVector, Dyn, U3, Vector3};
use pendulum_core::integrate::{Integrator, Projected, Rk4, State};
use pendulum_core::{
    Branch, Chain, Circle, ContinuationOptions, Directions, Drive, FnDrive, SteadyRotation, SteadyShape,
    normal_modes, relative_equilibrium, relative_spectrum, stability,
};

const LINKS: usize = 20;
const LENGTH: f64 = 1.0;
const MASS: f64 = 1.0;
const GRAVITY: f64 = 9.81;
/// Pivot circle radius, m.
const RADIUS: f64 = 0.02;
/// Decay rate of the first mode at rest the damping is chosen for, 1/s.
const FIRST_MODE_DECAY: f64 = 0.02;
/// Simulated time per speed, s.
const DURATION: f64 = 600.0;
/// Settled: rotating-frame positions moved less than `1e-3 L` over this window, s.
const SETTLE_WINDOW: f64 = 10.0;
/// RK4 step, s.
const STEP: f64 = 1e-3;
/// Length of the linear speed ramp of the second sweep, s.
const RAMP: f64 = 200.0;

/// Positions in the frame turned by `angle` about z (the pivot's phase).
fn rotating_positions<Dr: Drive<U3>>(
    model: &Directions<U3, Dr>,
    t: f64,
    x: &DVector<f64>,
    angle: f64,
) -> Vec<Vector3<f64>> {
    let (s, c) = angle.sin_cos();
    model
        .positions(t, x)
        .into_iter()
        .map(|r| Vector3::new(c * r.x + s * r.y, -s * r.x + c * r.y, r.z))
        .collect()
}

/// Mass positions, m.
type Shape = Vec<Vector3<f64>>;

/// Integrate from hanging at rest for `DURATION`; the rotating-frame positions
/// `SETTLE_WINDOW` before the end and at the end (`phase(t)` the pivot's phase).
fn simulate<Dr: Drive<U3>>(
    model: &Directions<U3, Dr>,
    phase: impl Fn(f64) -> f64,
) -> Result<(Shape, Shape), Box<dyn Error>> {
    let mut state = State::new(0.0, model.hanging());
    let mut solver = Projected::new(Rk4::new(model));
    let steps = (DURATION / STEP).round() as usize;
    let window = (SETTLE_WINDOW / STEP).round() as usize;
    let mut before = Vec::new();
    for k in 0..steps {
        if k == steps - window {
            before = rotating_positions(model, state.t(), state.x(), phase(state.t()));
        }
        solver.step(model, &mut state, STEP)?;
    }
    let last = rotating_positions(model, state.t(), state.x(), phase(state.t()));
    Ok((before, last))
}

/// The pivot's phase when its angular speed ramps linearly from 0 to `omega` over `ramp`
/// seconds and then holds: `φ = ω t² / (2 T)` for `t < T`, `ω (t − T/2)` after.
fn ramp_phase(omega: f64, ramp: f64) -> impl Fn(f64) -> f64 + Copy {
    move |t| if t < ramp { 0.5 * omega * t * t / ramp } else { omega * (t - 0.5 * ramp) }
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
    ramp: Option<f64>,
) -> Result<Row, Box<dyn Error>> {
    // The model with the steady circle: simulated directly, and used for the analysis.
    let model = Directions::<U3>::new(chain.clone()).with_drive(Circle::new(RADIUS, omega)?);
    let (before, last) = match ramp {
        None => simulate(&model, |t| omega * t)?,
        Some(ramp) => {
            let phase = ramp_phase(omega, ramp);
            let rate = move |t: f64| if t < ramp { omega * t / ramp } else { omega };
            let spin = move |t: f64| if t < ramp { omega / ramp } else { 0.0 };
            let drive = FnDrive::new(
                move |t: f64| {
                    let (s, c) = phase(t).sin_cos();
                    Vector3::new(c, s, 0.0) * RADIUS
                },
                move |t: f64| {
                    let (s, c) = phase(t).sin_cos();
                    Vector3::new(-s, c, 0.0) * (RADIUS * rate(t))
                },
                move |t: f64| {
                    let (s, c) = phase(t).sin_cos();
                    (Vector3::new(-s, c, 0.0) * spin(t) - Vector3::new(c, s, 0.0) * rate(t).powi(2)) * RADIUS
                },
            );
            simulate(&Directions::<U3>::new(chain.clone()).with_drive(drive), phase)?
        }
    };
    let drift = max_distance(&before, &last) / LENGTH;
    let sim_x: Vec<f64> = last.iter().map(|r| r.x).collect();
    let nodes_sim = 1 + pendulum_core::sign_changes(&sim_x);
    let lag = last.iter().map(|r| r.y.abs()).fold(0.0, f64::max) / LENGTH;
    let amplitude = sim_x.iter().fold(0.0_f64, |a, x| if x.abs() > a.abs() { *x } else { a }) / LENGTH;
    let problem = SteadyRotation::new(chain, RADIUS)?;
    let candidates = problem.solutions_at(branches, omega);
    let steady_positions = |shape: &SteadyShape| -> Vec<Vector3<f64>> {
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
        .map(|c| (max_distance(&steady_positions(c), &last) / LENGTH, c))
        .min_by(|a, b| a.0.total_cmp(&b.0));
    let in_plane = nearest.map(|(_, shape)| max_in_plane_distance(&steady_positions(shape), &last) / LENGTH);
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
    let solutions = candidates.len();
    // The exact damped relative equilibrium nearest the final shape (Newton on the
    // Directions model's own equations in the turning frame) and its spectrum.
    let mut previous = Vector3::new(RADIUS, 0.0, 0.0);
    let guess: Vec<(f64, f64)> = last
        .iter()
        .zip(chain.lengths().iter())
        .map(|(r, l)| {
            let u = (r - previous) / *l;
            previous = *r;
            (u.x.atan2(-u.z), u.y.clamp(-1.0, 1.0).asin())
        })
        .collect();
    let (damped_distance, damped_growth) = match relative_equilibrium(&model, &guess) {
        Ok(eq) => {
            let mut r = Vector3::new(RADIUS, 0.0, 0.0);
            let positions: Vec<Vector3<f64>> = (0..LINKS)
                .map(|i| {
                    r += chain.lengths()[i] * eq.state.fixed_rows::<3>(3 * i).into_owned();
                    r
                })
                .collect();
            let growth =
                relative_spectrum(&model, &eq)?.iter().map(|z| z.re).fold(f64::NEG_INFINITY, f64::max);
            (Some(max_distance(&positions, &last) / LENGTH), Some(growth))
        }
        Err(_) => (None, None),
    };
    Ok(Row {
        omega,
        settled: drift < 1e-3,
        drift,
        nodes_sim,
        nodes_steady,
        distance,
        in_plane,
        lag,
        amplitude,
        class,
        solutions,
        damped_distance,
        damped_growth,
    })
}

fn main() -> Result<(), Box<dyn Error>> {
    let docs = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../docs");
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
        "n = {LINKS}, L = {LENGTH} m, R = {RADIUS} m, λ = {damping:.3e} N·m·s per link, {DURATION} s per run, RK4 h = {STEP} s"
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
    let fractions = [0.5, 0.9, 1.1, 1.3, 1.6, 2.0, 2.4, 2.6, 2.9, 3.2, 3.6, 4.0, 4.4, 4.8, 5.2];
    let header = String::from(
        "| ω / sqrt(g/L) | ω (rad/s) | settled (drift / L) | nodes (sim) | steady shapes at ω | nodes (nearest) | distance / L | in-plane distance / L | out-of-plane lag / L | signed amplitude / L | nearest steady shape | damped steady: distance / L | damped steady: growth (1/s) |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let mut csv = String::from(
        "start,omega_rad_s,settled,drift_over_L,nodes_sim,steady_solutions,nodes_steady,distance_over_L,in_plane_distance_over_L,lag_over_L,amplitude_over_L,steady_class,damped_distance_over_L,damped_growth_rate_1_s\n",
    );
    for ramp in [None, Some(RAMP)] {
        let start = ramp.map_or("sudden".to_string(), |t| format!("ramp {t} s"));
        let mut table = header.clone();
        for f in fractions {
            let omega = f * scale;
            let r = run(&chain, &branches, omega, ramp)?;
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
    fs::create_dir_all(docs.join("data"))?;
    fs::write(docs.join("data/swing-up.csv"), csv)?;
    println!("wrote docs/data/swing-up.csv");
    Ok(())
}
