//! The flagship run: a 3D chain of 100 equal links hanging at rest, its pivot moved on a
//! small horizontal circle, 30 s of physical time with light damping; the positions of
//! every mass are written to a CSV file. Then the same chain with the drive off and no
//! damping, released from a tilted, twisted shape, for the energy error at the same step.
//!
//! ```sh
//! cargo run --release -p pendulum-core --example swing_chain -- [--step H] [--omega W] [--tilt A] [OUT.csv]
//! ```
//! Defaults: `H = 2.5e-4` s, the free chain tilted by `A = 0.2` rad, `ω = 5` rad/s (between the first two critical speeds of a 1 m
//! chain, 3.77 and 8.65 rad/s), `OUT = target/swing_chain.csv`. Figures in
//! `docs/large-chains.md`.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::time::Instant;

use nalgebra::{DVector, U3};
use pendulum_core::integrate::{Integrator, Projected, Rk4, State};
use pendulum_core::{Chain, Circle, Directions};

const LINKS: usize = 100;
const LENGTH: f64 = 1.0; // m, whole chain
const MASS: f64 = 1.0; // kg, whole chain
const DAMPING: f64 = 1e-6; // N·m·s per link
const RADIUS: f64 = 0.02; // m, pivot circle
const DURATION: f64 = 30.0; // s
const SAMPLE: f64 = 0.05; // s between written frames

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut step = 2.5e-4;
    let mut omega = 5.0;
    let mut tilt = 0.2;
    let mut out = String::from("target/swing_chain.csv");
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--step" => step = args.next().ok_or("--step needs a value")?.parse()?,
            "--omega" => omega = args.next().ok_or("--omega needs a value")?.parse()?,
            "--tilt" => tilt = args.next().ok_or("--tilt needs a value")?.parse()?,
            _ => out = arg,
        }
    }
    if !(step > 0.0 && step <= SAMPLE) {
        return Err(format!("--step must be in (0, {SAMPLE}] s, got {step}").into());
    }
    let steps = (DURATION / step).round() as usize;
    let every = (SAMPLE / step).round().max(1.0) as usize;
    let link = LENGTH / LINKS as f64;

    // Driven and lightly damped, from rest hanging straight down.
    let chain = Chain::uniform(LINKS, MASS / LINKS as f64, link, 9.81)?.with_damping(&[DAMPING; LINKS])?;
    let driven = Directions::<U3>::new(chain).with_drive(Circle::new(RADIUS, omega)?);
    let mut state = State::new(0.0, driven.hanging());
    let mut solver = Projected::new(Rk4::new(&driven));
    let mut file = BufWriter::new(File::create(&out)?);
    write!(file, "t")?;
    for i in 1..=LINKS {
        write!(file, ",x{i},y{i},z{i}")?;
    }
    writeln!(file)?;
    let mut worst_rod: f64 = 0.0;
    let started = Instant::now();
    for k in 0..=steps {
        if k % every == 0 {
            write!(file, "{}", state.t())?;
            for r in driven.positions(state.t(), state.x()) {
                write!(file, ",{},{},{}", r.x, r.y, r.z)?;
            }
            writeln!(file)?;
            worst_rod = worst_rod.max(rod_error(&driven, state.x()));
        }
        if k < steps {
            solver.step(&driven, &mut state, step)?;
        }
    }
    file.flush()?;
    let wall = started.elapsed().as_secs_f64();
    let tip = driven.relative_positions(state.x())[LINKS - 1];
    println!(
        "driven: n = {LINKS}, ω = {omega} rad/s, R = {RADIUS} m, λ = {DAMPING} N·m·s, h = {step} s, {steps} steps (RK4 + projection)"
    );
    println!(
        "  {DURATION} s physical in {wall:.3} s wall (ratio {:.1}, writing included); {} rhs evaluations",
        DURATION / wall,
        solver.inner().stats().rhs_evaluations
    );
    println!("  tip relative to the pivot at t = {DURATION} s: ({:.4}, {:.4}, {:.4}) m", tip.x, tip.y, tip.z);
    println!("  worst rod length error |l_i' / l_i − 1| over the written frames: {worst_rod:.1e}");
    println!("  positions written to {out}");

    // Undriven, undamped, released from a tilted, twisted shape.
    let free = Directions::<U3>::new(Chain::uniform(LINKS, MASS / LINKS as f64, link, 9.81)?);
    let q: Vec<f64> = (0..2 * LINKS)
        .map(|i| if i < LINKS { tilt } else { std::f64::consts::PI * (i - LINKS) as f64 / LINKS as f64 })
        .collect();
    let x0 = free.from_spherical(&q, &vec![0.0; 2 * LINKS])?;
    let e0 = free.energy(&x0);
    let scale = MASS * 9.81 * LENGTH; // J
    let mut state = State::new(0.0, x0);
    let mut solver = Projected::new(Rk4::new(&free));
    let mut worst_energy: f64 = 0.0;
    let started = Instant::now();
    for k in 0..steps {
        solver.step(&free, &mut state, step)?;
        if k % every == 0 {
            worst_energy = worst_energy.max((free.energy(state.x()) - e0).abs());
        }
    }
    let wall = started.elapsed().as_secs_f64();
    let last = (free.energy(state.x()) - e0).abs();
    println!("free: tilted {tilt} rad, twisted by π along the chain, released at rest; same h");
    println!("  {DURATION} s physical in {wall:.3} s wall (ratio {:.1})", DURATION / wall);
    println!(
        "  energy error: worst {:.2e}, final {:.2e}, relative to |H0| = {e0:.4} J (and {:.2e} relative to m g L)",
        worst_energy / e0.abs(),
        last / e0.abs(),
        worst_energy / scale
    );
    println!("  worst rod length error at the end: {:.1e}", rod_error(&free, state.x()));
    Ok(())
}

/// `max_i |(|r_i − r_{i−1}|) / l_i − 1|` from the positions of the masses.
fn rod_error<D: pendulum_core::Drive<U3>>(model: &Directions<U3, D>, x: &DVector<f64>) -> f64 {
    let r = model.relative_positions(x);
    let l = model.chain().lengths();
    (0..r.len())
        .map(|i| {
            let d = if i == 0 { r[0].norm() } else { (r[i] - r[i - 1]).norm() };
            (d / l[i] - 1.0).abs()
        })
        .fold(0.0, f64::max)
}
