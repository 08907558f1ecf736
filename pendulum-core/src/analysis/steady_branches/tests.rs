//! Tests of `steady_branches`.

use super::*;
use approx::assert_relative_eq;
use nalgebra::Dyn;

fn uniform(n: usize, radius: f64) -> SteadyRotation {
    SteadyRotation::new(&Chain::<Dyn>::uniform(n, 0.5, 1.0 / n as f64, 9.81).unwrap(), radius).unwrap()
}

#[test]
fn one_link_is_the_conical_pendulum() {
    let (l, g) = (0.8, 9.81);
    let p = SteadyRotation::new(&Chain::<Dyn>::new(&[1.3], &[l], g).unwrap(), 0.0).unwrap();
    let speeds = p.bifurcation_speeds(1).unwrap();
    assert_relative_eq!(speeds[0], (g / l).sqrt(), max_relative = 1e-12);
    for omega in [4.0, 5.0, 10.0, 40.0] {
        let shape = p.solve(omega, &DVector::from_element(1, 1.0)).unwrap();
        assert_relative_eq!(shape.theta[0].cos(), g / (l * omega * omega), max_relative = 1e-13);
        assert_eq!(shape.nodes(), 1);
    }
    let branch = p.branch(1, 20.0, &ContinuationOptions::default()).unwrap();
    assert_eq!(branch.end, BranchEnd::ReachedOmega);
    for s in &branch.points[1..] {
        assert_relative_eq!(s.theta[0].cos(), g / (l * s.omega * s.omega), max_relative = 1e-9);
        assert!(s.theta[0] > 0.0);
    }
}

#[test]
fn hessian_is_the_jacobian_of_the_residual() {
    let p = SteadyRotation::new(&Chain::<Dyn>::new(&[0.3, 1.2, 0.7], &[0.5, 0.2, 0.9], 9.81).unwrap(), 0.1)
        .unwrap();
    let theta = DVector::from_vec(vec![0.4, -0.9, 1.3]);
    let omega2 = 7.5;
    let h = p.hessian(&theta, omega2);
    let eps = 1e-6;
    for e in 0..3 {
        let mut tp = theta.clone();
        tp[e] += eps;
        let mut tm = theta.clone();
        tm[e] -= eps;
        let col = (p.residual(&tp, omega2) - p.residual(&tm, omega2)) / (2.0 * eps);
        for d in 0..3 {
            assert_relative_eq!(h[(d, e)], col[d], epsilon = 1e-7);
        }
    }
    assert_relative_eq!(h.clone(), h.transpose(), epsilon = 1e-14);
    let fd = (p.residual(&theta, omega2 + eps) - p.residual(&theta, omega2 - eps)) / (2.0 * eps);
    assert_relative_eq!(p.speed_derivative(&theta), fd, epsilon = 1e-7);
}

#[test]
fn bifurcation_speeds_are_the_mode_frequencies() {
    let chain = Chain::<Dyn>::new(&[0.3, 1.2, 0.7, 2.0], &[0.5, 0.2, 0.9, 0.4], 9.81).unwrap();
    let p = SteadyRotation::new(&chain, 0.0).unwrap();
    let speeds = p.bifurcation_speeds(4).unwrap();
    let modes = crate::analysis::modes::normal_modes(&chain);
    for (speed, mode) in speeds.iter().zip(modes.frequencies.iter()) {
        assert_relative_eq!(*speed, *mode, max_relative = 1e-11);
    }
}

#[test]
fn branch_k_has_k_nodes_and_solves_the_equations() {
    let p = uniform(8, 0.0);
    let speeds = p.bifurcation_speeds(3).unwrap();
    for k in 1..=3 {
        let branch = p.branch(k, 3.0 * speeds[2], &ContinuationOptions::default()).unwrap();
        assert_eq!(branch.end, BranchEnd::ReachedOmega, "k = {k}");
        for s in &branch.points[1..] {
            assert!(s.omega > speeds[k - 1], "k = {k}: ω = {} below ω_k", s.omega);
            assert_eq!(s.nodes(), k, "k = {k} at ω = {}", s.omega);
            assert!(p.residual(&s.theta, s.omega * s.omega).norm() < 1e-9);
        }
    }
}

#[test]
fn forced_small_radius_matches_the_linear_response() {
    // Far from resonance and for small R: (K − ω² W) θ = ω² R M l (linearised F).
    let p = uniform(5, 1e-6);
    let omega = 0.5 * p.reference_speed();
    let s = p.solve(omega, &DVector::zeros(5)).unwrap();
    let (_, l, tails) = p.parameters();
    let h0 = p.hessian(&DVector::zeros(5), omega * omega);
    let rhs = DVector::from_fn(5, |d, _| omega * omega * 1e-6 * tails[d] * l[d]);
    let linear = h0.lu().solve(&rhs).unwrap();
    assert_relative_eq!(s.theta, linear, max_relative = 1e-5);
}

#[test]
fn forced_branch_from_rest_runs_to_high_speed_in_phase() {
    let p = uniform(6, 0.01);
    let start = p.solve(0.0, &DVector::zeros(6)).unwrap();
    let omega_max = 10.0 * p.reference_speed();
    let branch = p.continue_from(&start, true, omega_max, &ContinuationOptions::default()).unwrap();
    assert_eq!(branch.end, BranchEnd::ReachedOmega);
    let last = branch.points.last().unwrap();
    assert_eq!(last.nodes(), 1);
    assert!(last.displacements.iter().all(|&x| x > 0.0));
}

#[test]
fn solutions_at_finds_each_branch_once() {
    let p = uniform(6, 0.0);
    let speeds = p.bifurcation_speeds(2).unwrap();
    let opts = ContinuationOptions::default();
    let branches: Vec<Branch> = (1..=2).map(|k| p.branch(k, 2.0 * speeds[1], &opts).unwrap()).collect();
    // Between ω_1 and ω_2 only the one-node branch; above ω_2 both (the vertical
    // itself is the first point of each branch and lies below).
    let mid = p.solutions_at(&branches, 0.5 * (speeds[0] + speeds[1]));
    assert_eq!(mid.iter().map(SteadyShape::nodes).collect::<Vec<_>>(), vec![1]);
    let top =
        p.solutions_at(&[branches[0].clone(), branches[1].clone(), branches[1].clone()], 1.5 * speeds[1]);
    assert_eq!(top.iter().map(SteadyShape::nodes).collect::<Vec<_>>(), vec![1, 2]);
    for s in &top {
        assert!(p.residual(&s.theta, s.omega * s.omega).norm() < 1e-10);
    }
}

#[test]
fn bad_requests_are_named() {
    let chain = Chain::<Dyn>::uniform(2, 1.0, 1.0, 9.81).unwrap();
    assert!(matches!(
        SteadyRotation::new(&chain, -1.0),
        Err(Error::InvalidSteady { what: "pivot radius", .. })
    ));
    let flat = Chain::<Dyn>::uniform(2, 1.0, 1.0, 0.0).unwrap();
    assert!(matches!(SteadyRotation::new(&flat, 0.0), Err(Error::InvalidSteady { what: "gravity", .. })));
    let p = SteadyRotation::new(&chain, 0.0).unwrap();
    assert!(matches!(p.bifurcation_speeds(3), Err(Error::InvalidSteady { .. })));
    assert!(matches!(p.solve(f64::NAN, &DVector::zeros(2)), Err(Error::InvalidSteady { .. })));
    assert!(matches!(
        p.solve(1.0, &DVector::zeros(3)),
        Err(Error::LengthMismatch { what: "theta", expected: 2, got: 3 })
    ));
    assert!(matches!(p.branch(0, 1.0, &ContinuationOptions::default()), Err(Error::InvalidSteady { .. })));
    let forced = SteadyRotation::new(&chain, 0.1).unwrap();
    assert!(matches!(forced.bifurcation_speeds(1), Err(Error::InvalidSteady { .. })));
}
