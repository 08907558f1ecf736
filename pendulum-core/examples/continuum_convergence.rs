//! How a uniform chain of n links (L = 1 m, M = 1 kg, point masses at the link ends)
//! approaches Kolodner's heavy rotating string as n grows: its first three critical speeds
//! against `ω_k = (j_{0,k}/2) √(g/L)`, and the tip radius of its one-node steady shape on
//! a fixed pivot at ω = 6 rad/s against the string's; the error times n (constant for an
//! O(1/n) approach) and Richardson's extrapolation `2 f(2n) − f(n)` of each pair.
//!
//! `cargo run --release -p pendulum-core --example continuum_convergence`
//! prints the markdown table of `docs/rotating-chain.md` §5.

use nalgebra::{DVector, Dyn};
use pendulum_core::{Chain, RotatingString, SteadyRotation, normal_modes};

const G: f64 = 9.81;
const OMEGA: f64 = 6.0;

/// The chain's first three critical speeds (rad/s) and the tip radius (m) of its one-node
/// shape at [`OMEGA`], from the string's shape as the first guess.
fn chain(n: usize, string: &[f64], depth: &[f64]) -> ([f64; 3], f64) {
    let link = 1.0 / n as f64;
    let chain = Chain::<Dyn>::uniform(n, link, link, G).expect("a uniform chain");
    let modes = normal_modes(&chain);
    let critical = [modes.frequencies[0], modes.frequencies[1], modes.frequencies[2]];
    // The string's points at the link ends (it is sampled 2000 times; n divides 2000 or
    // the nearest point is taken), then the link angles between them.
    let steps = string.len() - 1;
    let at = |i: usize| {
        let k = (i * steps + n / 2) / n;
        (string[k], depth[k])
    };
    let guess = DVector::from_fn(n, |i, _| {
        let (x0, d0) = at(i);
        let (x1, d1) = at(i + 1);
        (x1 - x0).atan2(d1 - d0)
    });
    let problem = SteadyRotation::new(&chain, 0.0).expect("a fixed pivot");
    let shape = problem.solve(OMEGA, &guess).expect("the one-node shape");
    (critical, shape.displacements.last().expect("n ≥ 1").abs())
}

fn main() {
    let string = RotatingString::new(1.0, G, 0.0).expect("a string");
    let limit = string.critical_speeds(3);
    let shapes = string.shapes_at(OMEGA).expect("the string's shapes");
    let one = shapes.iter().find(|s| s.nodes == 1).expect("a one-node shape above ω_1");
    let tip = one.tip_radius();
    println!(
        "string: ω_1..3 = {:.9}, {:.9}, {:.9} rad/s; tip radius at {OMEGA} rad/s = {tip:.9} m",
        limit[0], limit[1], limit[2]
    );
    println!();
    println!(
        "| n | ω_1 (rad/s) | n·(ω_1 − ω_1∞)/ω_1∞ | ω_2 | n·Δω_2/ω_2∞ | ω_3 | n·Δω_3/ω_3∞ | tip at 6 rad/s (m) | n·Δtip/tip∞ |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    let sizes = [10, 20, 50, 100, 200, 500, 1000];
    let mut rows = Vec::new();
    for &n in &sizes {
        let (critical, chain_tip) = chain(n, &one.x, &one.depth);
        let rel = |v: f64, l: f64| n as f64 * (v - l) / l;
        println!(
            "| {n} | {:.6} | {:+.4} | {:.6} | {:+.4} | {:.6} | {:+.4} | {chain_tip:.6} | {:+.4} |",
            critical[0],
            rel(critical[0], limit[0]),
            critical[1],
            rel(critical[1], limit[1]),
            critical[2],
            rel(critical[2], limit[2]),
            rel(chain_tip, tip)
        );
        rows.push((n, critical, chain_tip));
    }
    println!("| string | {:.6} | | {:.6} | | {:.6} | | {tip:.6} | |", limit[0], limit[1], limit[2]);
    println!();
    println!("Richardson, `2 f(2n) − f(n)`, relative error against the string:");
    println!();
    println!("| pair | ω_1 | ω_2 | ω_3 | tip |");
    println!("|---|---|---|---|---|");
    for (a, b) in [(10, 20), (50, 100), (100, 200), (500, 1000)] {
        let get = |n: usize| rows.iter().find(|r| r.0 == n).expect("computed");
        let (fa, fb) = (get(a), get(b));
        let extra = |x: f64, y: f64, l: f64| (2.0 * y - x - l) / l;
        println!(
            "| {a}, {b} | {:+.2e} | {:+.2e} | {:+.2e} | {:+.2e} |",
            extra(fa.1[0], fb.1[0], limit[0]),
            extra(fa.1[1], fb.1[1], limit[1]),
            extra(fa.1[2], fb.1[2], limit[2]),
            extra(fa.2, fb.2, tip)
        );
    }
}
