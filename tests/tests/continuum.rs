//! The uniform chain against Kolodner's heavy rotating string (`RotatingString`): its
//! critical speeds and the tip radius of its one-node shape approach the string's as 1/n,
//! and Richardson's extrapolation of n and 2n lands on them with an O(1/n²) error
//! (`docs/rotating-chain.md` §5).

use nalgebra::{DVector, Dyn};
use pendulum_core::{Chain, RotatingString, SteadyRotation, normal_modes};

/// First critical speed (rad/s) and the tip radius (m) of the one-node shape at `omega`
/// of `n` links of 1/n m and 1/n kg on a fixed pivot.
fn chain(n: usize, omega: f64, guess_tip: f64) -> (f64, f64) {
    let link = 1.0 / n as f64;
    let chain = Chain::<Dyn>::uniform(n, link, link, 9.81).unwrap();
    let first = normal_modes(&chain).frequencies[0];
    // A straight tilted guess towards the string's tip.
    let guess = DVector::from_element(n, guess_tip.asin());
    let shape = SteadyRotation::new(&chain, 0.0).unwrap().solve(omega, &guess).unwrap();
    (first, shape.displacements.last().unwrap().abs())
}

#[test]
fn the_chain_approaches_the_heavy_string_as_one_over_n() {
    let string = RotatingString::new(1.0, 9.81, 0.0).unwrap();
    let critical = string.critical_speeds(1)[0];
    let tip = string.shapes_at(6.0).unwrap().iter().find(|s| s.nodes == 1).unwrap().tip_radius();
    let (w50, t50) = chain(50, 6.0, tip);
    let (w100, t100) = chain(100, 6.0, tip);
    // n (f − f∞)/f∞ is the same at 50 and 100 links (O(1/n)): −0.25 for the speed, +0.068
    // for the tip.
    let scaled = |f: f64, limit: f64, n: f64| n * (f - limit) / limit;
    for (a, b, expected) in [
        (scaled(w50, critical, 50.0), scaled(w100, critical, 100.0), -0.25),
        (scaled(t50, tip, 50.0), scaled(t100, tip, 100.0), 0.068),
    ] {
        assert!((a - expected).abs() < 0.01 && (b - expected).abs() < 0.01, "{a}, {b} against {expected}");
    }
    // Richardson: 2 f(100) − f(50) within 1e-4 of the string (O(1/n²)).
    assert!(((2.0 * w100 - w50) / critical - 1.0).abs() < 1e-4);
    assert!(((2.0 * t100 - t50) / tip - 1.0).abs() < 2e-5);
}
