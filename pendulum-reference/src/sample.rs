//! Seeded random chain parameters and states for `verify`: reproducible from a seed.
//!
//! The ranges are wide on purpose: masses and lengths over two decades make every term
//! of the equations of motion visible at its own scale, angles over the whole circle
//! exercise every sign of every sine and cosine.

use std::f64::consts::PI;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::case::{Kind, Params, Point};

/// Default number of random states per case.
pub const DEFAULT_STATES: usize = 200;

/// Default seed: "pendulum" in ASCII.
pub const DEFAULT_SEED: u64 = 0x7065_6e64_756c_756d;

/// Masses (kg) and lengths (m) are log-uniform over `[MIN_SIZE, MAX_SIZE]`.
pub const MIN_SIZE: f64 = 0.1;
/// See [`MIN_SIZE`].
pub const MAX_SIZE: f64 = 10.0;
/// Gravity is uniform over `[0, MAX_GRAVITY]`, m/s².
pub const MAX_GRAVITY: f64 = 20.0;
/// Damping coefficients are uniform over `[0, MAX_DAMPING]`, N·m·s.
pub const MAX_DAMPING: f64 = 2.0;
/// Rates are uniform over `±MAX_RATE`, rad/s.
pub const MAX_RATE: f64 = 10.0;
/// Torques are uniform over `±MAX_TORQUE`, N·m.
pub const MAX_TORQUE: f64 = 10.0;
/// Each pivot acceleration component is uniform over `±MAX_PIVOT_ACCELERATION`, m/s².
pub const MAX_PIVOT_ACCELERATION: f64 = 20.0;
/// A spatial polar angle with `|sin θ|` below this is drawn again.
pub const MIN_SIN_THETA: f64 = 1e-3;

/// Parameters of an `n`-link chain: masses and lengths log-uniform over
/// [`MIN_SIZE`, `MAX_SIZE`], `g` uniform over `[0, MAX_GRAVITY]`, damping uniform over
/// `[0, MAX_DAMPING]`.
pub fn params(rng: &mut impl Rng, n: usize) -> Params {
    let masses = log_uniform(rng, n);
    let lengths = log_uniform(rng, n);
    let gravity = rng.random_range(0.0..MAX_GRAVITY);
    let damping = (0..n).map(|_| rng.random_range(0.0..MAX_DAMPING)).collect();
    Params { masses, lengths, gravity, damping }
}

/// A state and inputs of an `n`-link chain of `kind`: every angle uniform over
/// `[−π, π)`, rates over `±MAX_RATE`, torques over `±MAX_TORQUE`, each pivot
/// acceleration component over `±MAX_PIVOT_ACCELERATION`.
///
/// Spatial polar angles θ with `|sin θ| < MIN_SIN_THETA` are drawn again: there the
/// (θ, φ) coordinates are singular (φ is undefined, the mass matrix loses rank, and the
/// models refuse to compute accelerations), so such states say nothing about the
/// equations. The singularity itself is checked separately (`verify`).
pub fn point(rng: &mut impl Rng, kind: Kind, n: usize) -> Point {
    let dof = kind.dof(n);
    let q = (0..dof)
        .map(|a| {
            loop {
                let x = rng.random_range(-PI..PI);
                // Coordinates 0..n are the polar angles θ_i of a spatial chain.
                if kind == Kind::Planar || a >= n || x.sin().abs() >= MIN_SIN_THETA {
                    break x;
                }
            }
        })
        .collect();
    let qd = symmetric(rng, MAX_RATE, dof);
    let torque = symmetric(rng, MAX_TORQUE, dof);
    let pivot_acceleration = symmetric(rng, MAX_PIVOT_ACCELERATION, kind.space());
    Point { q, qd, torque, pivot_acceleration }
}

/// `len` values log-uniform over [`MIN_SIZE`, `MAX_SIZE`].
fn log_uniform(rng: &mut impl Rng, len: usize) -> Vec<f64> {
    (0..len).map(|_| rng.random_range(MIN_SIZE.ln()..MAX_SIZE.ln()).exp()).collect()
}

/// `len` values uniform over `±bound`.
fn symmetric(rng: &mut impl Rng, bound: f64, len: usize) -> Vec<f64> {
    (0..len).map(|_| rng.random_range(-bound..bound)).collect()
}

/// The generator of state `index` for `seed`: ChaCha8 seeded with `seed`, on stream
/// `index`. State `k` of a run is therefore reproducible on its own from the seed and
/// `k`, whatever the other states and cases.
pub fn rng(seed: u64, index: usize) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(index as u64);
    rng
}

/// Parameters and point number `index` of a run with `seed` for an `n`-link `kind`
/// chain: `params` then `point` drawn from [`rng(seed, index)`](rng).
pub fn state(seed: u64, kind: Kind, n: usize, index: usize) -> (Params, Point) {
    let (params, point, _) = state_with_rng(seed, kind, n, index);
    (params, point)
}

/// [`state`], and the generator after it, for drawing more values that belong to the
/// same state.
pub fn state_with_rng(seed: u64, kind: Kind, n: usize, index: usize) -> (Params, Point, ChaCha8Rng) {
    let mut rng = rng(seed, index);
    let params = params(&mut rng, n);
    let point = point(&mut rng, kind, n);
    (params, point, rng)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn states_are_deterministic_and_distinct() {
        assert_eq!(state(7, Kind::Spatial, 3, 5), state(7, Kind::Spatial, 3, 5));
        assert_ne!(state(7, Kind::Spatial, 3, 5), state(7, Kind::Spatial, 3, 6));
        assert_ne!(state(7, Kind::Planar, 3, 5), state(8, Kind::Planar, 3, 5));
        // The generator continues where the state left off.
        let (params, point, mut rest) = state_with_rng(7, Kind::Spatial, 3, 5);
        assert_eq!((params.clone(), point.clone()), state(7, Kind::Spatial, 3, 5));
        let mut again = rng(7, 5);
        assert_eq!(
            (super::params(&mut again, 3), super::point(&mut again, Kind::Spatial, 3)),
            (params, point)
        );
        assert_eq!(rest.random::<u64>(), again.random::<u64>());
    }

    #[test]
    fn values_lie_in_their_ranges() {
        for index in 0..500 {
            for kind in [Kind::Planar, Kind::Spatial] {
                let (p, x) = state(1, kind, 4, index);
                for v in p.masses.iter().chain(&p.lengths) {
                    assert!((MIN_SIZE..=MAX_SIZE).contains(v), "{v}");
                }
                assert!((0.0..MAX_GRAVITY).contains(&p.gravity));
                assert!(p.damping.iter().all(|d| (0.0..MAX_DAMPING).contains(d)));
                assert_eq!((x.q.len(), x.qd.len(), x.torque.len()), (kind.dof(4), kind.dof(4), kind.dof(4)));
                assert_eq!(x.pivot_acceleration.len(), kind.space());
                assert!(x.q.iter().all(|a| (-PI..PI).contains(a)));
                assert!(x.qd.iter().all(|a| a.abs() < MAX_RATE));
                assert!(x.torque.iter().all(|a| a.abs() < MAX_TORQUE));
                assert!(x.pivot_acceleration.iter().all(|a| a.abs() < MAX_PIVOT_ACCELERATION));
                if kind == Kind::Spatial {
                    assert!(x.q[..4].iter().all(|th| th.sin().abs() >= MIN_SIN_THETA));
                }
            }
        }
    }

    #[test]
    fn sizes_span_both_decades() {
        let masses: Vec<f64> = (0..200).flat_map(|i| state(3, Kind::Planar, 5, i).0.masses).collect();
        assert!(masses.iter().any(|&m| m < 0.2) && masses.iter().any(|&m| m > 5.0));
        let below_one = masses.iter().filter(|&&m| m < 1.0).count() as f64 / masses.len() as f64;
        assert!((0.4..0.6).contains(&below_one), "log-uniform puts half below 1: {below_one}");
    }
}
