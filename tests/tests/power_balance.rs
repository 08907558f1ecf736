//! Along the exact flow, the pivot-frame energy H = T + U changes at the rate
//! dH/dt = q̇ᵀ (Q − d): the power of the torques and damping, minus the power of the
//! fictitious force of the pivot's acceleration. This holds only if M, c, k, d, Q and
//! T, U fit together, so it checks every model independently of the sympy reference.

use nalgebra::{DefaultAllocator, Dyn, OVector};
use pendulum_core::{Chain, Model, ModelAlloc, Planar, Spatial};
use pendulum_tests::{random_chain, random_inputs, random_vector, rng};

/// Worst |dH/dt − q̇ᵀ(Q − d)| over random states, relative to the size of the power terms.
/// dH/dt is a central difference of H along (q̇, q̈) with step `eps`.
fn worst_power_mismatch<M: Model>(model: &M, seed: u64, states: usize, spatial: bool) -> f64
where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>,
{
    let mut rng = rng(seed);
    let mut worst: f64 = 0.0;
    for _ in 0..states {
        let mut q = random_vector(&mut rng, model, -std::f64::consts::PI..std::f64::consts::PI);
        if spatial {
            // Keep θ away from the coordinate singularity sin θ = 0.
            let n = model.chain().links();
            q.iter_mut().take(n).for_each(|t| *t = 0.3 + (*t + 3.2) * 0.39);
        }
        let qd = random_vector(&mut rng, model, -3.0..3.0);
        let inputs = random_inputs(&mut rng, model);
        let mut qdd = qd.clone();
        model.accelerations(&q, &qd, &inputs, &mut qdd).unwrap();

        let eps = 1e-5;
        let h = |s: f64| model.energy(&(&q + &qd * s), &(&qd + &qdd * s));
        let dh_dt = (h(eps) - h(-eps)) / (2.0 * eps);

        let (mut forces, mut pivot) = (qd.clone(), qd.clone());
        model.generalized_forces(&q, &qd, &inputs.torque, &mut forces);
        model.pivot_terms(&q, &inputs.pivot_acceleration, &mut pivot);
        let power = qd.dot(&(&forces - &pivot));
        let scale = qd.abs().dot(&(forces.abs() + pivot.abs())) + model.kinetic_energy(&q, &qd) + 1.0;
        worst = worst.max((dh_dt - power).abs() / scale);
    }
    worst
}

// A central difference with eps = 1e-5 has truncation error ~ eps² ≈ 1e-10 of the
// third derivative and round-off ~ 1e-16 / eps ≈ 1e-11 of H; 1e-6 leaves room for
// both and is still far below the O(1) mismatch a wrong term gives.
const BOUND: f64 = 1e-6;

#[test]
fn planar_power_balance_closes() {
    for n in 1..=6 {
        let model = Planar::new(random_chain::<Dyn>(&mut rng(n as u64), n, true));
        let worst = worst_power_mismatch(&model, 100 + n as u64, 50, false);
        assert!(worst < BOUND, "planar n={n}: dH/dt misses q̇ᵀ(Q − d) by {worst:e}");
    }
}

#[test]
fn spatial_power_balance_closes() {
    for n in 1..=4 {
        let model = Spatial::new(random_chain::<Dyn>(&mut rng(n as u64), n, true));
        let worst = worst_power_mismatch(&model, 200 + n as u64, 50, true);
        assert!(worst < BOUND, "spatial n={n}: dH/dt misses q̇ᵀ(Q − d) by {worst:e}");
    }
}

#[test]
fn a_conservative_chain_conserves_energy_along_the_flow() {
    // No damping, no torque, no drive: dH/dt = 0.
    let model = Planar::new(Chain::<Dyn>::uniform(5, 1.0, 1.0, 9.81).unwrap());
    let mut rng = rng(7);
    for _ in 0..20 {
        let q = random_vector(&mut rng, &model, -3.0..3.0);
        let qd = random_vector(&mut rng, &model, -3.0..3.0);
        let mut qdd = qd.clone();
        model.accelerations(&q, &qd, &model.zero_inputs(), &mut qdd).unwrap();
        let eps = 1e-5;
        let h = |s: f64| model.energy(&(&q + &qd * s), &(&qd + &qdd * s));
        let rate = (h(eps) - h(-eps)) / (2.0 * eps);
        assert!(rate.abs() < 1e-5 * (1.0 + model.kinetic_energy(&q, &qd)), "dH/dt = {rate:e}");
    }
}

#[test]
fn kinetic_energy_is_half_the_mass_matrix_quadratic_form() {
    let mut rng = rng(11);
    let model = Spatial::new(random_chain::<Dyn>(&mut rng, 3, false));
    let q = OVector::<f64, Dyn>::from_vec(vec![0.5, 1.2, 2.8, 0.0, -1.0, 2.0]);
    let qd = random_vector(&mut rng, &model, -5.0..5.0);
    let mut m = nalgebra::DMatrix::zeros(6, 6);
    model.mass_matrix(&q, &mut m);
    assert!((&m - m.transpose()).abs().max() < 1e-14 * m.abs().max(), "mass matrix not symmetric");
    assert!(m.clone().cholesky().is_some(), "mass matrix not positive definite");
    let quadratic = 0.5 * qd.dot(&(&m * &qd));
    let t = model.kinetic_energy(&q, &qd);
    assert!((quadratic - t).abs() < 1e-13 * t, "T = {t}, ½ q̇ᵀMq̇ = {quadratic}");
}
