//! How far a planar RK4 run in single precision (`PlanarBatch::integrate_rk4_f32`) drifts
//! from the same run in double precision, and how much of that the rounding of the
//! starting states alone explains (the `f64` run from the states rounded to `f32`): 64
//! random chains swinging from angles and rates within ±1 (rad, rad/s), masses and lengths
//! around 10 g and 1 cm spread over a factor, steps of 0.1 ms (`docs/ensembles.md`).
//!
//! ```sh
//! cargo run --release -p pendulum-core --example single_precision_runs
//! ```

use nalgebra::{DVector, Dyn};
use pendulum_core::batch::PlanarBatch;
use pendulum_core::integrate::State;
use pendulum_core::{Chain, Result};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const CHAINS: usize = 64;
const H: f64 = 1e-4;

/// A chain of `n` links, masses and lengths from 10 g and 1 cm up by a factor of up to
/// `spread`, damping from 1e-4 N·m·s likewise.
fn chain(n: usize, spread: f64, r: &mut ChaCha8Rng) -> Result<Chain<Dyn>> {
    let mut draw = |lo: f64| (0..n).map(|_| lo * spread.powf(r.random::<f64>())).collect::<Vec<_>>();
    let (masses, lengths, damping) = (draw(0.01), draw(0.01), draw(1e-4));
    Chain::new(&masses, &lengths, 9.81)?.with_damping(&damping)
}

/// The worst over chains of `max |a − b| / max |a|` (rows of `m`).
fn worst(a: &[f64], b: &[f64], m: usize) -> f64 {
    a.chunks_exact(m)
        .zip(b.chunks_exact(m))
        .map(|(a, b)| {
            let scale = a.iter().fold(0.0f64, |s, v| s.max(v.abs()));
            a.iter().zip(b).fold(0.0f64, |e, (a, b)| e.max((a - b).abs())) / scale
        })
        .fold(0.0, f64::max)
}

/// The `f64` run of `steps` steps from `rows` (rows of `(θ, θ̇)`), as rows.
fn run_f64(batch: &PlanarBatch, rows: &[f64], m: usize, steps: usize) -> Result<Vec<f64>> {
    let mut states: Vec<State<Dyn>> =
        rows.chunks_exact(m).map(|x| State::new(0.0, DVector::from_column_slice(x))).collect();
    let failures = batch.integrate_rk4(&mut states, None, None, H, steps)?;
    assert!(failures.is_empty(), "{failures:?}");
    Ok(states.iter().flat_map(|s| s.x().iter().copied()).collect())
}

fn main() -> Result<()> {
    let mut r = ChaCha8Rng::seed_from_u64(53);
    println!("| spread | steps | n | f32 run against f64 | f64 run from the f32-rounded start |");
    println!("|---:|---:|---:|---:|---:|");
    for (spread, steps) in [(2.0, 100), (2.0, 1000), (2.0, 10_000), (10.0, 100), (100.0, 100)] {
        for n in [8, 20, 100] {
            let m = 2 * n;
            let chains = (0..CHAINS).map(|_| chain(n, spread, &mut r)).collect::<Result<Vec<_>>>()?;
            let batch = PlanarBatch::new(chains)?;
            let rows: Vec<f64> = (0..CHAINS * m).map(|_| r.random_range(-1.0..1.0)).collect();
            let exact = run_f64(&batch, &rows, m, steps)?;
            let rounded: Vec<f64> = rows.iter().map(|&v| f64::from(v as f32)).collect();
            let from_rounded = run_f64(&batch, &rounded, m, steps)?;
            let (mut x, mut carry): (Vec<f32>, _) =
                (rows.iter().map(|&v| v as f32).collect(), vec![0.0; rows.len()]);
            let failures = batch.integrate_rk4_f32((&mut x, &mut carry), None, None, H, steps)?;
            assert!(failures.is_empty(), "{failures:?}");
            let single: Vec<f64> = x.iter().map(|&v| f64::from(v)).collect();
            let (error, start) = (worst(&exact, &single, m), worst(&exact, &from_rounded, m));
            println!("| {spread} | {steps} | {n} | {error:.1e} | {start:.1e} |");
        }
    }
    Ok(())
}
