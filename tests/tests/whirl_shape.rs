//! Whirling a 3D chain by its top end (`docs/rotating-chain.md` §4): a uniform chain hanging
//! at rest, its pivot driven on a small horizontal circle with light damping, settles into a
//! steady shape — the one `ShapeTracker` finds it on, with the node count the speed calls for
//! when the drive is switched on at full speed, and the large one-node shape when the speed
//! is ramped up slowly instead.
//!
//! n = 20, L = 1 m, M = 1 kg, R = 0.02 m, RK4 + projection with h = 2 ms (the same figures
//! as with 1 ms, `examples/whirl.rs`), the analysis fed every step.

use nalgebra::{Dyn, U3};
use pendulum_core::integrate::{Integrator, Projected, Rk4, State};
use pendulum_core::{
    Chain, Circle, Directions, RampedCircle, ShapeOptions, ShapeReport, ShapeTracker, SteadyRotation, Turning,
};

const LINKS: usize = 20;
const LENGTH: f64 = 1.0;
const RADIUS: f64 = 0.02;
const STEP: f64 = 2e-3;

/// The uniform chain with damping `λ` per link (N·m·s).
fn chain(damping: f64) -> Chain<Dyn> {
    let n = LINKS as f64;
    Chain::<Dyn>::uniform(LINKS, 1.0 / n, LENGTH / n, 9.81).unwrap().with_damping(&[damping; LINKS]).unwrap()
}

/// From hanging at rest for `duration` s; the report at the end.
fn run<Dr: Turning>(model: &Directions<U3, Dr>, duration: f64) -> ShapeReport {
    let mut tracker = ShapeTracker::new(model, ShapeOptions::default()).unwrap();
    let mut state = State::new(0.0, model.hanging());
    let mut solver = Projected::new(Rk4::new(model));
    for _ in 0..(duration / STEP).round() as usize {
        solver.step(model, &mut state, STEP).unwrap();
        tracker.push(state.t(), state.x()).unwrap();
    }
    let report = tracker.report().unwrap();
    let nearest = report.nearest.as_ref().unwrap();
    println!(
        "ω = {:.2} rad/s: {} nodes, tip radius {:.3} m, plane {:+.3} rad, lag {:.2e} m, drift {:.2e} m over \
         {:.1} s; nearest damped steady shape: {} nodes, distance {:.2e} m, growth {:+.3e} 1/s",
        report.omega,
        report.shape.nodes,
        report.shape.tip_radius,
        report.shape.plane_azimuth,
        report.shape.out_of_plane,
        report.settling.drift,
        report.settling.window,
        nearest.shape.nodes,
        nearest.distance,
        nearest.growth_rate
    );
    report
}

/// Settled (drift ≤ 1e-3 L over the last 5 periods) within 1e-3 L of a damped steady shape
/// with the same nodes, which is stable.
fn assert_settled_on_a_stable_steady_shape(report: &ShapeReport, nodes: usize) {
    assert_eq!(report.shape.nodes, nodes, "{:?}", report.shape.radial);
    assert_eq!(report.shape.axis_crossings, nodes - 1);
    assert!(report.settling.settled, "{:?}", report.settling);
    let nearest = report.nearest.as_ref().unwrap();
    assert!(nearest.distance <= 1e-3 * LENGTH, "distance {} m", nearest.distance);
    assert_eq!(nearest.shape.nodes, nodes);
    assert!(nearest.stable && nearest.growth_rate < 0.0, "growth {} 1/s", nearest.growth_rate);
}

#[test]
fn a_sudden_start_settles_into_one_two_and_three_nodes() {
    // λ = 6e-3: the first mode at rest decays at ≈ 0.2 1/s, settling within 60 s.
    let chain = chain(6e-3);
    let critical = SteadyRotation::new(&chain, 0.0).unwrap().bifurcation_speeds(3).unwrap();
    // Below ω_1, between ω_1 and ω_2, between ω_2 and ω_3 (≈ 3.72, 8.54, 13.41 rad/s).
    for (omega, nodes) in [(3.0, 1), (6.0, 2), (11.0, 3)] {
        assert!(critical.iter().filter(|&&w| w < omega).count() == nodes - 1, "{critical:?}");
        let model = Directions::<U3>::new(chain.clone()).with_drive(Circle::new(RADIUS, omega).unwrap());
        let report = run(&model, 60.0);
        assert_settled_on_a_stable_steady_shape(&report, nodes);
        // The small forced response: its masses stay near the axis.
        assert!(report.shape.tip_radius < 0.1 * LENGTH, "{}", report.shape.tip_radius);
    }
}

#[test]
fn at_the_same_speed_a_slow_ramp_ends_on_the_large_one_node_shape() {
    // λ = 1.5e-3 (the acceptance run's 3e-4 at n = 100, scaled with 1/n: the first mode at
    // rest decays at ≈ 0.05 1/s), ω = 5 rad/s between ω_1 and ω_2.
    let chain = chain(1.5e-3);
    let omega = 5.0;
    // Switched on at full speed: the small two-node response.
    let sudden = Directions::<U3>::new(chain.clone()).with_drive(Circle::new(RADIUS, omega).unwrap());
    let report = run(&sudden, 150.0);
    assert_settled_on_a_stable_steady_shape(&report, 2);
    assert!(report.shape.tip_radius < 0.1 * LENGTH, "{}", report.shape.tip_radius);
    // Ramped from rest over 150 s, then held 250 s: through the first resonance onto the
    // large in-phase shape.
    let ramp = RampedCircle::new(RADIUS, 0.0, omega, 150.0).unwrap();
    let ramped = Directions::<U3>::new(chain).with_drive(ramp);
    let report = run(&ramped, 400.0);
    assert_eq!(report.omega, omega);
    assert_settled_on_a_stable_steady_shape(&report, 1);
    assert!(report.shape.tip_radius > 0.8 * LENGTH, "{}", report.shape.tip_radius);
}
