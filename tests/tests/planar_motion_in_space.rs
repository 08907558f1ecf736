//! A spatial chain whose links all lie in the x–z plane (φ_i = 0) and move in it
//! (φ̇_i = 0) is a planar chain: its θ̈ must equal the planar model's and its φ̈ vanish.

use nalgebra::{DVector, Dyn, Vector2, Vector3};
use pendulum_core::{Inputs, Model, Planar, Spatial};
use pendulum_tests::{random_chain, rng};
use rand::Rng;

#[test]
fn spatial_chain_in_a_vertical_plane_moves_like_the_planar_chain() {
    let mut rng = rng(3);
    for n in 1..=5 {
        let chain = random_chain::<Dyn>(&mut rng, n, true);
        let planar = Planar::new(chain.clone());
        let spatial = Spatial::new(chain);
        for _ in 0..20 {
            // θ in the plane may be negative (φ = 0 then points the link to −x); stay off sin θ = 0.
            let theta: Vec<f64> = (0..n)
                .map(|_| rng.random_range(0.05..3.1) * if rng.random_bool(0.5) { 1.0 } else { -1.0 })
                .collect();
            let theta_dot: Vec<f64> = (0..n).map(|_| rng.random_range(-5.0..5.0)).collect();
            let sigma: Vec<f64> = (0..n).map(|_| rng.random_range(-5.0..5.0)).collect();
            let (ax, az) = (rng.random_range(-10.0..10.0), rng.random_range(-10.0..10.0));

            let mut a_planar = DVector::zeros(n);
            let planar_inputs =
                Inputs { torque: DVector::from_vec(sigma.clone()), pivot_acceleration: Vector2::new(ax, az) };
            planar
                .accelerations(
                    &DVector::from_vec(theta.clone()),
                    &DVector::from_vec(theta_dot.clone()),
                    &planar_inputs,
                    &mut a_planar,
                )
                .unwrap();

            let pad = |v: &[f64]| {
                DVector::from_iterator(2 * n, v.iter().copied().chain(std::iter::repeat_n(0.0, n)))
            };
            let spatial_inputs =
                Inputs { torque: pad(&sigma), pivot_acceleration: Vector3::new(ax, 0.0, az) };
            let mut a_spatial = DVector::zeros(2 * n);
            spatial.accelerations(&pad(&theta), &pad(&theta_dot), &spatial_inputs, &mut a_spatial).unwrap();

            let scale = a_planar.abs().max() + 1.0;
            let theta_error = (a_spatial.rows(0, n) - &a_planar).abs().max() / scale;
            let phi_error = a_spatial.rows(n, n).abs().max() / scale;
            assert!(theta_error < 1e-10, "n={n}: θ̈ differs from planar by {theta_error:e}");
            assert!(phi_error < 1e-10, "n={n}: φ̈ = {} instead of 0", a_spatial.rows(n, n));
        }
    }
}
