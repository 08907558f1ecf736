//! Energy conservation of a free 3D chain of 100 links over 30 s, by integrator and step:
//! the undriven variant of the flagship run (`swing_chain`), released at rest from a
//! straight chain tilted by `θ₀` and twisted by π in azimuth along its length.
//!
//! ```sh
//! cargo run --release -p pendulum-core --example large_chain_energy [-- TILT ...]
//! ```
//! Prints a markdown table (worst relative energy error over the run, sampled every
//! step; wall time; right-hand sides per step). Default tilts 0.2 and 0.6 rad. Figures
//! in `docs/large-chains.md`.

use std::time::Instant;

use nalgebra::{U2, U3};
use pendulum_core::integrate::{GaussFixedPoint, Integrator, Projected, Rk4, State};
use pendulum_core::{Chain, Directions};

const LINKS: usize = 100;
const DURATION: f64 = 30.0;

fn run<I: Integrator<Directions<U3>>>(
    mut solver: Projected<I>,
    model: &Directions<U3>,
    tilt: f64,
    h: f64,
) -> Result<(f64, f64, f64), pendulum_core::Error> {
    let q: Vec<f64> = (0..2 * LINKS)
        .map(|i| if i < LINKS { tilt } else { std::f64::consts::PI * (i - LINKS) as f64 / LINKS as f64 })
        .collect();
    let x0 = model.from_spherical(&q, &[0.0; 2 * LINKS])?;
    let e0 = model.energy(&x0);
    let mut state = State::new(0.0, x0);
    let steps = (DURATION / h).round() as usize;
    let mut worst: f64 = 0.0;
    let started = Instant::now();
    for _ in 0..steps {
        solver.step(model, &mut state, h)?;
        worst = worst.max((model.energy(state.x()) - e0).abs());
    }
    let wall = started.elapsed().as_secs_f64();
    let per_step = solver.stats().rhs_evaluations as f64 / steps as f64;
    Ok((worst / e0.abs(), wall, per_step))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let tilts: Vec<f64> = std::env::args().skip(1).map(|a| a.parse()).collect::<Result<_, _>>()?;
    let tilts = if tilts.is_empty() { vec![0.2, 0.6] } else { tilts };
    let model = Directions::<U3>::new(Chain::uniform(LINKS, 0.01, 0.01, 9.81)?);
    println!("| tilt θ₀, rad | method | h, s | worst \\|ΔH\\|/\\|H₀\\| | wall, s | rhs per step |");
    println!("|---:|---|---:|---:|---:|---:|");
    for &tilt in &tilts {
        for h in [1e-3, 5e-4, 2.5e-4] {
            let rows = [
                ("RK4", run(Projected::new(Rk4::new(&model)), &model, tilt, h)),
                (
                    "GL s=2 fixed point",
                    run(Projected::new(GaussFixedPoint::<_, U2>::new(&model, 60)), &model, tilt, h),
                ),
                (
                    "GL s=3 fixed point",
                    run(Projected::new(GaussFixedPoint::<_, U3>::new(&model, 60)), &model, tilt, h),
                ),
            ];
            for (name, result) in rows {
                match result {
                    Ok((error, wall, per_step)) => {
                        println!("| {tilt} | {name} | {h:.1e} | {error:.1e} | {wall:.2} | {per_step:.1} |")
                    }
                    Err(e) => println!("| {tilt} | {name} | {h:.1e} | failed: {e} | | |"),
                }
            }
        }
    }
    Ok(())
}
