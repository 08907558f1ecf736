//! A pivot on sampled positions ([`Sampled`], the cubic spline through them) drives a chain
//! as the motion it samples does: a whirl driven by samples of its circle approaches the
//! whirl driven by the circle itself as the samples get denser, and the energy balance of
//! a chain on a sampled path closes (its `p`, `ṗ`, `p̈` agree). For any samples, the spline
//! passes through them, and `p`, `ṗ`, `p̈` are continuous, `p̈` linear between them
//! (proptest).

use std::f64::consts::TAU;

use nalgebra::{DVector, Dyn, U3, Vector3};
use pendulum_core::integrate::{Integrator, Projected, Rk4, State};
use pendulum_core::{Chain, Circle, Directions, Drive, Sampled};
use proptest::prelude::*;

/// The circle `R = 2 cm`, `ω = 7 rad/s` sampled every `spacing` (s) from 0 to 4 s, its
/// velocities at the ends given.
fn sampled_circle(circle: &Circle, spacing: f64) -> Sampled<U3> {
    let count = (4.0 / spacing).round() as usize;
    let times: Vec<f64> = (0..=count).map(|k| k as f64 * spacing).collect();
    let positions = times.iter().map(|&t| circle.position(t)).collect();
    let (start, end) = (circle.velocity(0.0), circle.velocity(times[count]));
    Sampled::with_end_velocities(times, positions, start, end).unwrap()
}

/// The directions after 3 s of projected RK4 (1 ms) of a 4-link chain from hanging at
/// rest, its pivot on `drive`.
fn whirl<Dr: Drive<U3>>(drive: Dr) -> DVector<f64> {
    let chain = Chain::<Dyn>::new(&[0.3, 0.2, 0.2, 0.1], &[0.2, 0.15, 0.15, 0.1], 9.81).unwrap();
    let model = Directions::<U3>::new(chain).with_drive(drive);
    let mut state = State::new(0.0, model.hanging());
    let mut rk4 = Projected::new(Rk4::new(&model));
    for _ in 0..3000 {
        rk4.step(&model, &mut state, 1e-3).unwrap();
    }
    state.x().rows(0, 12).into_owned()
}

#[test]
fn a_whirl_on_samples_of_its_circle_approaches_the_whirl_on_the_circle() {
    let circle = Circle::new(0.02, 7.0).unwrap();
    let exact = whirl(circle);
    // The chain swings well away from hanging: the drive matters.
    let hanging = whirl(pendulum_core::Fixed);
    assert!((&exact - &hanging).amax() > 0.1, "{}", (&exact - &hanging).amax());
    // Samples every 1/20, 1/40 and 1/80 of a turn.
    let period = TAU / 7.0;
    let errors: Vec<f64> = [20.0, 40.0, 80.0]
        .iter()
        .map(|per_turn| (whirl(sampled_circle(&circle, period / per_turn)) - &exact).amax())
        .collect();
    println!("largest direction error, 20, 40 and 80 samples a turn: {errors:?}");
    // Measured: 1.9e-6, 1.1e-7, 1.1e-8 (orders 4.1 and 3.4; the spline's p̈ errs as h²,
    // but its error changes sign within every piece).
    for pair in errors.windows(2) {
        let order = (pair[0] / pair[1]).log2();
        assert!(order > 3.0, "order {order} from {errors:?}");
    }
    assert!(errors[2] < 1e-7, "{errors:?}");
}

#[test]
fn a_sampled_drive_outside_its_samples_holds_the_pivot_where_it_ends_at_rest() {
    // Up and back down in 1 s, at rest at both ends; then the pivot stays put.
    let times = vec![0.0, 0.25, 0.5, 0.75, 1.0];
    let positions = [0.0, 0.02, 0.05, 0.02, 0.0].iter().map(|&z| Vector3::new(0.0, 0.0, z)).collect();
    let path = Sampled::with_end_velocities(times, positions, Vector3::zeros(), Vector3::zeros()).unwrap();
    for t in [-1.0, 1.5, 10.0] {
        let zero = Vector3::zeros();
        assert_eq!((path.position(t), path.velocity(t), path.acceleration(t)), (zero, zero, zero), "t = {t}");
    }
    assert!(path.acceleration(0.5).z < -1.0, "{}", path.acceleration(0.5));
}

/// Increasing times with gaps from 1 ms to 1 s, and positions within a metre.
fn samples() -> impl Strategy<Value = (Vec<f64>, Vec<Vector3<f64>>)> {
    (2usize..40).prop_flat_map(|m| {
        let gaps = prop::collection::vec(1e-3..1.0f64, m - 1);
        let points = prop::collection::vec(prop::array::uniform3(-1.0..1.0f64), m);
        (-5.0..5.0f64, gaps, points).prop_map(|(start, gaps, points)| {
            let mut times = vec![start];
            for gap in gaps {
                times.push(times.last().unwrap() + gap);
            }
            (times, points.into_iter().map(Vector3::from).collect())
        })
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn the_spline_passes_through_its_samples_with_p_v_and_a_continuous(
        (times, positions) in samples(),
        at_rest in any::<bool>(),
    ) {
        let path = if at_rest {
            Sampled::with_end_velocities(times.clone(), positions.clone(), Vector3::zeros(), Vector3::zeros())
        } else {
            Sampled::new(times.clone(), positions.clone())
        }
        .unwrap();
        // Scales: the steepest chord and its change over the shortest gap.
        let gaps: Vec<f64> = times.windows(2).map(|w| w[1] - w[0]).collect();
        let shortest = gaps.iter().copied().fold(f64::INFINITY, f64::min);
        let speed = 2.0 * 3f64.sqrt() / shortest;
        let acceleration = 2.0 * speed / shortest;
        for (k, (&t, p)) in times.iter().zip(&positions).enumerate() {
            prop_assert!((path.position(t) - p).norm() <= 1e-12 * (1.0 + speed), "sample {k}");
            if k == 0 || k + 1 == times.len() {
                continue;
            }
            // Either side of an inner sample, a nanosecond of the shortest gap away.
            let eps = 1e-9 * shortest;
            let (before, after) = (t - eps, t + eps);
            prop_assert!((path.position(after) - path.position(before)).norm() <= 1e-6 * (1.0 + speed * shortest));
            prop_assert!((path.velocity(after) - path.velocity(before)).norm() <= 1e-6 * (1.0 + speed));
            prop_assert!(
                (path.acceleration(after) - path.acceleration(before)).norm() <= 1e-6 * (1.0 + acceleration)
            );
        }
        // p̈ linear between samples: at a piece's midpoint, the mean of its ends.
        for (k, w) in times.windows(2).enumerate() {
            let middle = path.acceleration(0.5 * (w[0] + w[1]));
            let mean = (path.acceleration(w[0]) + path.acceleration(w[1])) * 0.5;
            prop_assert!((middle - mean).norm() <= 1e-9 * (1.0 + acceleration), "piece {k}");
        }
    }
}
