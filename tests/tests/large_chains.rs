//! The O(n) routes against the dense Lagrangian models (themselves checked against the
//! sympy reference by `cargo xtask verify`): same accelerations to round-off at random
//! states, chains up to 64 links, torques, damping and a driven pivot included; and the
//! direction representation through the vertical, where the spherical angles fail.

use nalgebra::{DVector, Dyn, U2, U3, Vector2, Vector3};
use pendulum_core::integrate::{Constrained, Integrator, Projected, Rk4, State};
use pendulum_core::{Chain, Directions, FnDrive, Model, Planar, PlanarTension, Spatial};
use pendulum_tests::{random_chain, random_inputs, random_vector, rng};
use rand::Rng;

const SIZES: [usize; 8] = [1, 2, 3, 5, 8, 16, 32, 64];
const STATES: usize = 25;

/// `‖a − b‖∞ / max(‖b‖∞, scale)`: the error relative to the size of the accelerations,
/// with `scale` (1/s²) a floor for states where they nearly vanish.
fn relative(a: &DVector<f64>, b: &DVector<f64>, scale: f64) -> f64 {
    (a - b).amax() / b.amax().max(scale)
}

/// A scale of the accelerations at a state: `g / min l` plus the rates squared.
fn scale(chain: &Chain<Dyn>, qd: &DVector<f64>) -> f64 {
    chain.gravity() / chain.lengths().min() + qd.norm_squared()
}

#[test]
fn planar_tension_route_matches_the_dense_route() {
    let mut rng = rng(81);
    let mut worst: f64 = 0.0;
    for n in SIZES {
        for _ in 0..STATES {
            let chain = random_chain::<Dyn>(&mut rng, n, true);
            let fast = PlanarTension::new(chain.clone());
            let dense = Planar::new(chain.clone());
            let q = random_vector(&mut rng, &dense, -4.0..4.0);
            let qd = random_vector(&mut rng, &dense, -3.0..3.0);
            let inputs = random_inputs(&mut rng, &dense);
            let (mut a, mut b) = (DVector::zeros(n), DVector::zeros(n));
            fast.accelerations(&q, &qd, &inputs, &mut a).unwrap();
            dense.accelerations(&q, &qd, &inputs, &mut b).unwrap();
            let e = relative(&a, &b, scale(&chain, &qd));
            assert!(e < 1e-9, "n = {n}: relative difference {e:e}\nq = {q}\nfast {a}\ndense {b}");
            worst = worst.max(e);
        }
    }
    println!(
        "planar O(n) vs dense, {} states, n ≤ 64: worst relative difference {worst:.1e}",
        STATES * SIZES.len()
    );
}

#[test]
fn planar_directions_match_the_dense_route_with_a_driven_pivot() {
    let mut rng = rng(82);
    for n in SIZES {
        for _ in 0..STATES {
            let chain = random_chain::<Dyn>(&mut rng, n, true);
            let dense = Planar::new(chain.clone());
            let pivot = Vector2::new(rng.random_range(-20.0..20.0), rng.random_range(-20.0..20.0));
            let drive =
                FnDrive::new(move |t: f64| pivot * (0.5 * t * t), move |t: f64| pivot * t, move |_| pivot);
            let model = Directions::<U2>::new(chain.clone()).with_drive(drive);
            let q = random_vector(&mut rng, &dense, -4.0..4.0);
            let qd = random_vector(&mut rng, &dense, -3.0..3.0);
            let mut inputs = dense.zero_inputs();
            inputs.pivot_acceleration = pivot;
            let mut expected = DVector::zeros(n);
            dense.accelerations(&q, &qd, &inputs, &mut expected).unwrap();

            let x = model.from_angles(q.as_slice(), qd.as_slice()).unwrap();
            let got = model.angle_accelerations(0.3, &x).unwrap();
            let e = relative(&got, &expected, scale(&chain, &qd));
            assert!(e < 1e-9, "n = {n}: relative difference {e:e}");
        }
    }
}

#[test]
fn spatial_directions_match_the_spherical_model_where_it_is_regular() {
    let mut rng = rng(83);
    let mut worst: f64 = 0.0;
    for n in [1, 2, 3, 5, 8, 16, 32] {
        for _ in 0..STATES {
            let chain = random_chain::<Dyn>(&mut rng, n, true);
            let spherical = Spatial::new(chain.clone());
            let pivot = Vector3::new(
                rng.random_range(-20.0..20.0),
                rng.random_range(-20.0..20.0),
                rng.random_range(-20.0..20.0),
            );
            let drive =
                FnDrive::new(move |t: f64| pivot * (0.5 * t * t), move |t: f64| pivot * t, move |_| pivot);
            let model = Directions::<U3>::new(chain.clone()).with_drive(drive);
            // θ well inside (0, π), so the spherical model is well conditioned.
            let q = DVector::from_fn(2 * n, |i, _| {
                if i < n {
                    rng.random_range(0.3..2.8) * if rng.random_bool(0.5) { 1.0 } else { -1.0 }
                } else {
                    rng.random_range(-3.0..3.0)
                }
            });
            let qd = random_vector(&mut rng, &spherical, -3.0..3.0);
            let mut inputs = spherical.zero_inputs();
            inputs.pivot_acceleration = pivot;
            let mut expected = DVector::zeros(2 * n);
            spherical.accelerations(&q, &qd, &inputs, &mut expected).unwrap();

            let x = model.from_spherical(q.as_slice(), qd.as_slice()).unwrap();
            let (q2, qd2) = model.to_spherical(&x).unwrap();
            // θ < 0 comes back as (−θ, φ + π): the same directions and rates.
            let x2 = model.from_spherical(q2.as_slice(), qd2.as_slice()).unwrap();
            assert!((&x2 - &x).amax() < 1e-12, "{q} -> {q2}");
            let got = model.spherical_accelerations(0.0, q.as_slice(), qd.as_slice()).unwrap();
            let e = relative(&got, &expected, scale(&chain, &qd));
            assert!(e < 1e-8, "n = {n}: relative difference {e:e}\nfast {got}\ndense {expected}");
            worst = worst.max(e);
        }
    }
    println!("spatial directions vs spherical, n ≤ 32: worst relative difference {worst:.1e}");
}

#[test]
fn chain_swings_through_the_vertical_and_keeps_its_rods_and_energy() {
    // A 3D chain released from a tilted, twisted shape swings through the vertical many
    // times; the spherical angles would fail there, the directions do not.
    let n = 12;
    let model = Directions::<U3>::new(Chain::uniform(n, 0.1, 0.1, 9.81).unwrap());
    let q: Vec<f64> = (0..2 * n).map(|i| if i < n { 0.8 } else { 0.3 * i as f64 }).collect();
    let x0 = model.from_spherical(&q, &vec![0.0; 2 * n]).unwrap();
    let e0 = model.energy(&x0);
    let mut state = State::new(0.0, x0);
    let mut solver = Projected::new(Rk4::new(&model));
    let mut lowest_sin = f64::INFINITY;
    for _ in 0..4000 {
        solver.step(&model, &mut state, 5e-4).unwrap();
        let x = state.x();
        for i in 0..n {
            lowest_sin = lowest_sin.min(model.direction(x, i).xy().norm());
        }
    }
    let x = state.x();
    let drift = (model.energy(x) - e0).abs() / e0.abs();
    assert!(model.constraint_violation(x) < 1e-13, "{}", model.constraint_violation(x));
    assert!(drift < 1e-6, "relative energy drift {drift:e}");
    assert!(lowest_sin < 0.05, "the chain should pass near the vertical, came within sin θ = {lowest_sin}");
    let mut projected = x.clone();
    model.project(&mut projected);
    assert!((&projected - x).amax() < 1e-15);
}
