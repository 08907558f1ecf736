//! Whirl a 3D chain by its top end and report the shape it takes: a uniform chain hanging at
//! rest, its pivot driven on a horizontal circle from t = 0 (speed switched on, or ramped),
//! integrated in unit directions (RK4 + projection) and analysed with `ShapeTracker`
//! (co-rotating shape, nodes, settled, nearest damped steady shape and its growth rate).
//!
//! ```text
//! cargo run --release -p pendulum-tests --example whirl                 # the issue's run
//! cargo run --release -p pendulum-tests --example whirl -- --links 20 --omega 4,6 \
//!     --damping 5.62e-4 --duration 100 --step 2e-3 --ramp 40
//! ```
//!
//! Defaults (issue #14's acceptance run): n = 100, L = 1 m, M = 1 kg, g = 9.81 m/s²,
//! R = 0.02 m, λ = 3e-4 N·m·s per link, ω = 3, 6, 11 rad/s, 150 s, h = 1 ms, sudden start,
//! the default `ShapeOptions` (settled: drift ≤ 1e-3 L over the last 5 drive periods).
//! One Markdown row per speed.

use std::{error::Error, time::Instant};

use nalgebra::{Dyn, U3};
use pendulum_core::integrate::{Integrator, Projected, Rk4, State};
use pendulum_core::{
    Chain, Circle, Directions, RampedCircle, ShapeOptions, ShapeTracker, SteadyRotation, Turning,
};

struct Args {
    links: usize,
    radius: f64,
    damping: f64,
    omegas: Vec<f64>,
    duration: f64,
    step: f64,
    ramp: Option<f64>,
}

fn parse() -> Result<Args, Box<dyn Error>> {
    let mut args = Args {
        links: 100,
        radius: 0.02,
        damping: 3e-4,
        omegas: vec![3.0, 6.0, 11.0],
        duration: 150.0,
        step: 1e-3,
        ramp: None,
    };
    let mut it = std::env::args().skip(1);
    while let Some(flag) = it.next() {
        let value = it.next().ok_or(format!("{flag} needs a value"))?;
        match flag.as_str() {
            "--links" => args.links = value.parse()?,
            "--radius" => args.radius = value.parse()?,
            "--damping" => args.damping = value.parse()?,
            "--omega" => args.omegas = value.split(',').map(str::parse).collect::<Result<_, _>>()?,
            "--duration" => args.duration = value.parse()?,
            "--step" => args.step = value.parse()?,
            "--ramp" => args.ramp = Some(value.parse()?),
            _ => return Err(format!("unknown flag {flag}").into()),
        }
    }
    Ok(args)
}

/// Runs the chain from hanging at rest for `duration` s and prints one table row.
fn run<Dr: Turning>(model: &Directions<U3, Dr>, args: &Args) -> Result<(), Box<dyn Error>> {
    let start = Instant::now();
    let mut tracker = ShapeTracker::new(model, ShapeOptions::default())?;
    let mut state = State::new(0.0, model.hanging());
    let mut solver = Projected::new(Rk4::new(model));
    let steps = (args.duration / args.step).round() as usize;
    for _ in 0..steps {
        solver.step(model, &mut state, args.step)?;
        tracker.push(state.t(), state.x())?;
    }
    let simulated = start.elapsed().as_secs_f64();
    let report = tracker.report()?;
    let analysed = start.elapsed().as_secs_f64() - simulated;
    let (s, shape) = (&report.settling, &report.shape);
    let nearest = match &report.nearest {
        Ok(n) => format!(
            "{} | {:.2e} | {:+.3e} | {}",
            n.shape.nodes,
            n.distance,
            n.growth_rate,
            if n.stable { "stable" } else { "unstable" }
        ),
        Err(e) => format!("– | – | – | {e}"),
    };
    println!(
        "| {:.3} | {} | {} ({:.1e} m, window {:.1} s) | {:.3} | {:+.2e} | {:.2e} | {nearest} | {simulated:.1} + {analysed:.1} |",
        report.omega,
        shape.nodes,
        if s.settled { "yes" } else { "no" },
        s.drift,
        s.window,
        shape.tip_radius,
        shape.plane_azimuth,
        shape.out_of_plane,
    );
    Ok(())
}

fn main() -> Result<(), Box<dyn Error>> {
    let args = parse()?;
    let n = args.links;
    let chain = Chain::<Dyn>::uniform(n, 1.0 / n as f64, 1.0 / n as f64, 9.81)?
        .with_damping(&vec![args.damping; n])?;
    let critical = SteadyRotation::new(&chain, 0.0)?.bifurcation_speeds(3)?;
    println!(
        "n = {n}, L = 1 m, M = 1 kg, R = {} m, λ = {:e} N·m·s per link, {} s, RK4 h = {} s, start: {}",
        args.radius,
        args.damping,
        args.duration,
        args.step,
        args.ramp.map_or("sudden".to_string(), |t| format!("ramp from rest over {t} s"))
    );
    println!("critical speeds ω_1..3 = {:.4}, {:.4}, {:.4} rad/s\n", critical[0], critical[1], critical[2]);
    println!(
        "| ω (rad/s) | nodes | settled (drift, window) | tip radius (m) | plane azimuth (rad) | out of plane (m) | nodes (steady) | distance (m) | growth (1/s) | steady | wall: run + analysis (s) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    for &omega in &args.omegas {
        let plain = Directions::<U3>::new(chain.clone());
        match args.ramp {
            None => run(&plain.with_drive(Circle::new(args.radius, omega)?), &args)?,
            Some(t) => run(&plain.with_drive(RampedCircle::new(args.radius, 0.0, omega, t)?), &args)?,
        }
    }
    Ok(())
}
