//! The cost of one time step of a long 3D chain in unit directions: explicit RK4 with
//! projection (O(n) per step) against Gauss–Legendre s = 2 with its dense Newton solve
//! (a finite-difference Jacobian of the 6n-dimensional system and an LU of the 12n × 12n
//! stage matrix: O(n³) per factorisation).
//!
//! ```sh
//! cargo run --release -p pendulum-core --example step_cost
//! ```

use std::time::Instant;

use nalgebra::{Dyn, U2, U3};
use pendulum_core::integrate::{GaussLegendre, GaussOptions, Integrator, Projected, Rk4, State};
use pendulum_core::{Chain, Directions};

fn main() -> Result<(), pendulum_core::Error> {
    println!(
        "| n | h, s | RK4 + projection, µs/step | GL s=2 (dense Newton), ms/step | GL Newton iterations/step |"
    );
    println!("|---:|---:|---:|---:|---:|");
    for n in [10, 30, 100, 300, 1000] {
        let model = Directions::<U3>::new(Chain::uniform(n, 1.0 / n as f64, 1.0 / n as f64, 9.81)?);
        let q: Vec<f64> = (0..2 * n).map(|i| if i < n { 0.3 } else { 0.02 * i as f64 }).collect();
        let x0 = model.from_spherical(&q, &vec![0.0; 2 * n])?;
        // RK4's stability limit shrinks like 1/n: the highest mode of a uniform chain of
        // length L is about 2n·sqrt(g/L) rad/s. h = 0.1/n s is 1e-3 s at n = 100.
        let h = 0.1 / n as f64;

        let mut state = State::new(0.0, x0.clone());
        let mut rk4 = Projected::new(Rk4::new(&model));
        let steps = 200_000 / n;
        let started = Instant::now();
        for _ in 0..steps {
            rk4.step(&model, &mut state, h)?;
        }
        let rk4_us = started.elapsed().as_secs_f64() / steps as f64 * 1e6;

        let gl = if n <= 100 {
            let mut state = State::new(0.0, x0);
            let mut gl = Projected::new(GaussLegendre::<Dyn, U2>::new(&model, GaussOptions::default()));
            let steps = 3;
            let started = Instant::now();
            for _ in 0..steps {
                gl.step(&model, &mut state, h)?;
            }
            let ms = started.elapsed().as_secs_f64() / steps as f64 * 1e3;
            let iterations = gl.inner().stats().newton_iterations as f64 / steps as f64;
            format!("{ms:.1} | {iterations:.1}")
        } else {
            "(not run) | ".into()
        };
        println!("| {n} | {h:.0e} | {rk4_us:.2} | {gl} |");
    }
    Ok(())
}
