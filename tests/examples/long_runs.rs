//! Long conservative runs: no NaN, bounded energy error, wall time
//! (`docs/reliability.md` records the figures).
//!
//! ```text
//! cargo run --release -p pendulum-tests --example long_runs            # both
//! cargo run --release -p pendulum-tests --example long_runs generated  # 10^7 steps
//! cargo run --release -p pendulum-tests --example long_runs chain3d    # 10^6 steps
//! cargo run --release -p pendulum-tests --example long_runs chain3d 10000   # fewer steps
//! ```
//!
//! - `generated`: the generated `Planar3` (`pendulum_macros::model!`) in canonical
//!   variables, Gauss–Legendre s = 2 (symplectic), h = 1 ms, 10^7 steps (10^4 s),
//!   released at rest from θ = (1, 0.5, −0.5) rad (chaotic). Energy sampled every 1000
//!   steps; the error is relative to the potential-energy scale `g Σm Σl`.
//! - `chain3d`: `Directions<U3>` with n = 100 links (1 m, 1 kg in all), `Projected<Rk4>`,
//!   h = 2.5e-4 s, 10^6 steps (250 s), released at rest from a straight chain tilted by
//!   0.2 rad and twisted by π in azimuth along its length (the `large_chain_energy`
//!   setup). Energy and rod constraints sampled every 1000 steps; error relative to |H₀|.

use std::time::Instant;

use nalgebra::{DVector, U2, U3, Vector3};
use pendulum_core::integrate::{Constrained, GaussLegendre, GaussOptions, Integrator, Projected, Rk4, State};
use pendulum_core::{Canonical, Chain, Directions, Model};

pendulum_macros::model! {
    struct Planar3 { kind: planar, links: 3 }
}

fn generated(steps: u64) {
    let (masses, lengths, g) = ([1.0, 0.7, 1.3], [1.0, 0.8, 0.6], 9.81);
    let model = Planar3::new(Chain::new(&masses, &lengths, g).unwrap());
    let system = Canonical::new(model.clone());
    let (q, qd) = (Vector3::new(1.0, 0.5, -0.5), Vector3::zeros());
    let e0 = model.energy(&q, &qd);
    let scale = g * masses.iter().sum::<f64>() * lengths.iter().sum::<f64>();
    let mut solver = GaussLegendre::<_, U2>::new(&system, GaussOptions::default());
    let mut state = State::new(0.0, system.from_velocities(&q, &qd));
    let h = 1e-3;
    let start = Instant::now();
    let (mut worst, mut last) = (0.0f64, 0.0);
    for i in 1..=steps {
        if let Err(e) = solver.step(&system, &mut state, h) {
            panic!("step {i} failed: {e}");
        }
        if i % 1000 == 0 || i == steps {
            assert!(state.x().iter().all(|v| v.is_finite()), "non-finite state at step {i}");
            last = (system.energy(state.x()).unwrap() - e0) / scale;
            worst = worst.max(last.abs());
        }
    }
    let wall = start.elapsed().as_secs_f64();
    println!(
        "generated Planar3, canonical GL s=2, h = {h} s, {steps} steps (t = {:.1} s): \
         worst |ΔH|/(gΣmΣl) = {worst:.2e}, final {last:.2e}, wall {wall:.1} s ({:.2} µs/step), \
         Newton iterations {}, all states finite",
        state.t(),
        wall / steps as f64 * 1e6,
        solver.stats().newton_iterations,
    );
}

fn chain3d(steps: u64) {
    let n = 100;
    let model = Directions::<U3>::new(Chain::uniform(n, 1.0 / n as f64, 1.0 / n as f64, 9.81).unwrap());
    let tilt = 0.2;
    let q: Vec<f64> = (0..2 * n)
        .map(|i| if i < n { tilt } else { std::f64::consts::PI * (i - n) as f64 / (n - 1) as f64 })
        .collect();
    let x0: DVector<f64> = model.from_spherical(&q, &vec![0.0; 2 * n]).unwrap();
    let e0 = model.energy(&x0);
    let mut solver = Projected::new(Rk4::new(&model));
    let mut state = State::new(0.0, x0);
    let h = 2.5e-4;
    let start = Instant::now();
    let (mut worst, mut last, mut constraint) = (0.0f64, 0.0, 0.0f64);
    for i in 1..=steps {
        if let Err(e) = solver.step(&model, &mut state, h) {
            panic!("step {i} failed: {e}");
        }
        if i % 1000 == 0 || i == steps {
            let x = state.x();
            assert!(x.iter().all(|v| v.is_finite()), "non-finite state at step {i}");
            last = (model.energy(x) - e0) / e0.abs();
            worst = worst.max(last.abs());
            constraint = constraint.max(model.constraint_violation(x));
        }
    }
    let wall = start.elapsed().as_secs_f64();
    let mut projected = state.x().clone();
    model.project(&mut projected);
    println!(
        "Directions<U3> n = {n}, Projected<Rk4>, h = {h} s, {steps} steps (t = {:.1} s): \
         worst |ΔH|/|H0| = {worst:.2e}, final {last:.2e}, worst constraint violation {constraint:.1e}, \
         wall {wall:.1} s ({:.1} µs/step), all states finite",
        state.t(),
        wall / steps as f64 * 1e6,
    );
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let which = args.first().map(String::as_str).unwrap_or("both");
    let steps =
        |default: u64| args.get(1).map(|s| s.parse().expect("steps: a positive integer")).unwrap_or(default);
    match which {
        "generated" => generated(steps(10_000_000)),
        "chain3d" => chain3d(steps(1_000_000)),
        "both" => {
            generated(10_000_000);
            chain3d(1_000_000);
        }
        other => {
            eprintln!("unknown run '{other}': generated, chain3d or both");
            std::process::exit(2);
        }
    }
}
