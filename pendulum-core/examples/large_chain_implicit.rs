//! Past the explicit step limit: a free 3D chain of 1000 links (L = 1 m, M = 1 kg),
//! released at rest from a straight chain tilted by 0.2 rad and twisted by π in azimuth
//! along its length, 10 s, with the implicit [`RodMidpoint`] step at steps far beyond
//! RK4's stability limit, and RK4 (with projection) at the largest step it survives.
//!
//! ```sh
//! cargo run --release -p pendulum-core --example large_chain_implicit [-- LINKS SECONDS [STEP…]]
//! ```
//! (defaults 1000 links, 10 s, implicit steps 0.0025, 0.005 and 0.01 s).
//! Prints a markdown table: method, step, step ÷ RK4's limit `2.8/ω_max`, worst relative
//! energy error (sampled every 0.01 s), rod-length error, wall time, Newton iterations per
//! step, and the tip's distance from the reference run (the smallest RK4 step) at the end.
//! Figures in `docs/large-chains.md`.

use std::time::Instant;

use nalgebra::{DVector, U3};
use pendulum_core::integrate::{Integrator, Projected, Rk4, State};
use pendulum_core::{Chain, Directions, RodMidpoint, fastest_frequency_bound};

struct Outcome {
    energy: f64,
    rods: f64,
    wall: f64,
    iterations: f64,
    halved: u64,
    tip: DVector<f64>,
}

fn run<I: Integrator<Directions<U3>>>(
    mut solver: I,
    model: &Directions<U3>,
    x0: &DVector<f64>,
    duration: f64,
    h: f64,
) -> Result<Outcome, pendulum_core::Error> {
    let e0 = model.energy(x0);
    let mut state = State::new(0.0, x0.clone());
    let steps = (duration / h).round() as usize;
    let every = ((0.01 / h).round() as usize).max(1);
    let mut worst: f64 = 0.0;
    let started = Instant::now();
    for k in 0..steps {
        solver.step(model, &mut state, h)?;
        if (k + 1) % every == 0 {
            worst = worst.max((model.energy(state.x()) - e0).abs());
        }
    }
    let wall = started.elapsed().as_secs_f64();
    let n = model.links();
    let rods = (0..n).map(|i| (model.direction(state.x(), i).norm() - 1.0).abs()).fold(0.0, f64::max);
    let tip = DVector::from_column_slice(model.relative_positions(state.x())[n - 1].as_slice());
    let iterations = solver.stats().newton_iterations as f64 / steps as f64;
    let halved = solver.stats().halved_steps;
    Ok(Outcome { energy: worst / e0.abs(), rods, wall, iterations, halved, tip })
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<f64> = std::env::args().skip(1).map(|a| a.parse()).collect::<Result<_, _>>()?;
    let n = args.first().map_or(1000, |v| *v as usize);
    let duration = args.get(1).copied().unwrap_or(10.0);
    let chain = Chain::uniform(n, 1.0 / n as f64, 1.0 / n as f64, 9.81)?;
    let limit = 2.8 / fastest_frequency_bound(&chain, 9.81);
    let model = Directions::<U3>::new(chain);
    let q: Vec<f64> = (0..2 * n)
        .map(|i| if i < n { 0.2 } else { std::f64::consts::PI * (i - n) as f64 / n as f64 })
        .collect();
    let x0 = model.from_spherical(&q, &vec![0.0; 2 * n])?;
    println!("n = {n}, {duration} s; RK4's stability limit 2.8/ω_max = {limit:.2e} s");
    println!(
        "| method | h, s | h ÷ limit | worst \\|ΔH\\|/\\|H₀\\| | rod error | wall, s | Newton iterations per step | steps halved | tip off the reference, m |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    let reference_step = limit / 4.0;
    let reference = run(Projected::new(Rk4::new(&model)), &model, &x0, duration, reference_step)?;
    let mut rows = vec![(
        "RK4 + projection",
        limit * 0.9,
        run(Projected::new(Rk4::new(&model)), &model, &x0, duration, limit * 0.9),
    )];
    let steps = if args.len() > 2 { args[2..].to_vec() } else { vec![0.0025, 0.005, 0.01] };
    for h in steps {
        rows.push(("RodMidpoint", h, run(RodMidpoint::new(), &model, &x0, duration, h)));
    }
    let row = |name: &str, h: f64, o: &Outcome| {
        println!(
            "| {name} | {h:.2e} | {:.2} | {:.1e} | {:.1e} | {:.2} | {:.2} | {} | {:.1e} |",
            h / limit,
            o.energy,
            o.rods,
            o.wall,
            o.iterations,
            o.halved,
            (&o.tip - &reference.tip).norm()
        )
    };
    row("RK4 + projection (reference)", reference_step, &reference);
    for (name, h, result) in rows {
        match result {
            Ok(o) => row(name, h, &o),
            Err(e) => println!("| {name} | {h:.2e} | {:.1} | failed: {e} | | | | | |", h / limit),
        }
    }
    Ok(())
}
