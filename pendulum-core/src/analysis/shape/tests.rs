//! Tests of `shape`.

use std::f64::consts::PI;

use nalgebra::Dyn;

use super::*;
use crate::analysis::stability::stability;
use crate::analysis::steady_branches::SteadyRotation;
use crate::chain::Chain;
use crate::drive::RampedCircle;

fn chain() -> Chain<Dyn> {
    Chain::<Dyn>::new(&[0.3, 1.1, 0.5, 0.8], &[0.25, 0.15, 0.3, 0.2], 9.81).unwrap()
}

fn damped() -> Chain<Dyn> {
    chain().with_damping(&[0.002; 4]).unwrap()
}

/// The state `x` turned by `angle` about z (directions and rates alike).
fn rotated(x: &DVector<f64>, angle: f64) -> DVector<f64> {
    let (s, c) = angle.sin_cos();
    let mut y = x.clone();
    for k in 0..x.len() / 3 {
        let (a, b) = (x[3 * k], x[3 * k + 1]);
        y[3 * k] = c * a - s * b;
        y[3 * k + 1] = s * a + c * b;
    }
    y
}

/// The damped relative equilibrium of `chain` on `Circle(radius, omega)` continued from the
/// undamped steady shape solved from `guess` (in-plane angles).
fn equilibrium(chain: &Chain<Dyn>, radius: f64, omega: f64, guess: f64) -> RelativeEquilibrium {
    let n = chain.links();
    let problem = SteadyRotation::new(chain, radius).unwrap();
    let shape = problem.solve(omega, &DVector::from_element(n, guess)).unwrap();
    let model = Directions::<U3>::new(chain.clone()).with_drive(Circle::new(radius, omega).unwrap());
    let angles: Vec<(f64, f64)> = shape.theta.iter().map(|&t| (t, 0.0)).collect();
    relative_equilibrium(&model, &angles).unwrap()
}

/// Positions with the given horizontal coordinates `x`, `y = 0`, rods stacked 0.1 m deep.
fn planar(x: &[f64]) -> Vec<Vector3<f64>> {
    x.iter().enumerate().map(|(i, &x)| Vector3::new(x, 0.0, -0.1 * (i + 1) as f64)).collect()
}

#[test]
fn a_rigidly_turning_relative_equilibrium_is_settled_on_itself() {
    let (radius, omega) = (0.03, 9.0);
    let eq = equilibrium(&damped(), radius, omega, 0.9);
    // The same rotation behind a circle and behind a ramp that ended at t = 2 s.
    let circle = Directions::<U3>::new(damped()).with_drive(Circle::new(radius, omega).unwrap());
    let ramp =
        Directions::<U3>::new(damped()).with_drive(RampedCircle::new(radius, 3.0, omega, 2.0).unwrap());
    let period = TAU / omega;
    let times: Vec<f64> = (0..400).map(|k| 5.0 + 6.0 * period * k as f64 / 399.0).collect();
    let by_circle: Vec<_> = times.iter().map(|&t| (t, rotated(&eq.state, omega * t))).collect();
    let by_ramp: Vec<_> = times.iter().map(|&t| (t, rotated(&eq.state, ramp.drive().phase(t)))).collect();
    for report in [
        shape_report(&circle, &by_circle, &ShapeOptions::default()).unwrap(),
        shape_report(&ramp, &by_ramp, &ShapeOptions::default()).unwrap(),
    ] {
        let s = &report.settling;
        assert!(s.covered && s.settled && s.drift < 1e-14, "{s:?}");
        assert!((s.window - 5.0 * period).abs() < 1e-12 && (s.threshold - 0.9e-3).abs() < 1e-15);
        assert_eq!((report.omega, report.radius, report.t), (omega, radius, *times.last().unwrap()));
        let nearest = report.nearest.as_ref().unwrap();
        println!(
            "nodes {}, lag {:.3e} m, azimuth {:.3e} rad, distance {:.2e} m, growth {:.3e} 1/s",
            report.shape.nodes,
            report.shape.out_of_plane,
            report.shape.plane_azimuth,
            nearest.distance,
            nearest.growth_rate
        );
        assert!(nearest.distance < 1e-12, "distance {}", nearest.distance);
        assert_eq!((report.shape.nodes, nearest.shape.nodes, report.shape.axis_crossings), (1, 1, 0));
        assert!(nearest.stable && nearest.growth_rate < -1e-3, "{}", nearest.growth_rate);
        for (a, b) in eq.angles.iter().zip(&nearest.equilibrium.angles) {
            assert!((a.0 - b.0).abs() < 1e-9 && (a.1 - b.1).abs() < 1e-9);
        }
        // Damping drags the shape behind the pivot (ω > 0): the plane turns back a little,
        // and the masses are off it.
        assert!(report.shape.plane_azimuth < 0.0 && report.shape.plane_azimuth > -0.1);
        assert!(report.shape.out_of_plane > 1e-6 && report.shape.out_of_plane < 1e-2);
    }
}

#[test]
fn a_planar_two_node_shape_crosses_the_axis_once() {
    // The free (R = 0) second steady shape, its plane turned to several azimuths.
    let problem = SteadyRotation::new(&chain(), 0.0).unwrap();
    let critical = problem.bifurcation_speeds(2).unwrap();
    let omega = 1.15 * critical[1];
    let branch = problem.branch(2, omega, &Default::default()).unwrap();
    let steady = branch.points.last().unwrap();
    assert_eq!(steady.nodes(), 2);
    let mut depth = 0.0;
    let flat: Vec<Vector3<f64>> = steady
        .displacements
        .iter()
        .zip(chain().lengths().iter().zip(steady.theta.iter()))
        .map(|(x, (l, t))| {
            depth += l * t.cos();
            Vector3::new(*x, 0.0, -depth)
        })
        .collect();
    for (turn, azimuth, sign) in [(0.0, 0.0, 1.0), (0.4, 0.4, 1.0), (-1.2, -1.2, 1.0), (2.0, 2.0 - PI, -1.0)]
    {
        let (s, c) = f64::sin_cos(turn);
        let positions =
            flat.iter().map(|r| Vector3::new(c * r.x - s * r.y, s * r.x + c * r.y, r.z)).collect();
        let shape = WhirlShape::from_positions(positions).unwrap();
        assert_eq!((shape.axis_crossings, shape.nodes), (1, 2));
        assert!((shape.plane_azimuth - azimuth).abs() < 1e-12, "{turn}: {}", shape.plane_azimuth);
        assert!(shape.out_of_plane < 1e-15);
        for (s, x) in shape.radial.iter().zip(&steady.displacements) {
            assert!((s - sign * x).abs() < 1e-15);
        }
        assert!((shape.tip_radius - steady.displacements[3].abs()).abs() < 1e-15);
        assert!((shape.depth[3] - depth).abs() < 1e-15);
    }
}

#[test]
fn crossings_are_counted_from_the_axis_not_from_the_pivot() {
    let count = |x: &[f64]| WhirlShape::from_positions(planar(x)).unwrap().axis_crossings;
    // Inside the pivot's radius (R = 0.02) but never across the axis: no crossing.
    assert_eq!(count(&[0.015, 0.025, 0.01]), 0);
    // The rod from the pivot to mass 1 crossing the axis does not count.
    assert_eq!(count(&[-0.01, -0.03, -0.02]), 0);
    assert_eq!(count(&[0.01, -0.01, 0.03]), 2);
    assert_eq!(count(&[0.01, 0.0, -0.02]), 1);
    // Out of the plane: tip radius and lag; the fitted plane is the x–z plane here.
    let mut positions = planar(&[0.3, 0.5, 0.6]);
    positions[1].y = -0.02;
    positions[2].y = 0.01;
    let shape = WhirlShape::from_positions(positions.clone()).unwrap();
    assert!((shape.tip_radius - 0.6_f64.hypot(0.01)).abs() < 1e-15);
    let (s, c) = shape.plane_azimuth.sin_cos();
    let lag = positions.iter().map(|r| (c * r.y - s * r.x).abs()).fold(0.0, f64::max);
    assert!((shape.out_of_plane - lag).abs() < 1e-15 && lag > 0.015, "{}", shape.out_of_plane);
    assert!((shape.offsets[1] + 0.02).abs() < 3e-3 && shape.offsets[1] < 0.0);
    // The fit minimises the squared offsets: turning the plane either way makes them larger.
    let squares = |a: f64| positions.iter().map(|r| (r.y * a.cos() - r.x * a.sin()).powi(2)).sum::<f64>();
    let best = squares(shape.plane_azimuth);
    assert!(best < squares(shape.plane_azimuth + 1e-4) && best < squares(shape.plane_azimuth - 1e-4));
}

#[test]
fn a_moving_or_short_history_is_not_settled() {
    let (radius, omega) = (0.03, 9.0);
    let eq = equilibrium(&damped(), radius, omega, 0.9);
    let model = Directions::<U3>::new(damped()).with_drive(Circle::new(radius, omega).unwrap());
    let period = TAU / omega;
    // The shape wobbling about the axis by `amplitude` rad with a period of 3 drive periods.
    let wobbling = |amplitude: f64, span: f64| {
        let mut tracker = ShapeTracker::new(&model, ShapeOptions::default()).unwrap();
        for k in 0..=2000 {
            let t = span * k as f64 / 2000.0;
            let wobble = amplitude * (TAU * t / (3.0 * period)).sin();
            tracker.push(t, &rotated(&eq.state, omega * t + wobble)).unwrap();
        }
        tracker.settling().unwrap()
    };
    let tip = whirl_shape(&model, 0.0, &eq.state).unwrap().tip_radius;
    // A wobble of ±2e-3 rad moves the tip by up to 4e-3 · tip radius from where it is last.
    let s = wobbling(2e-3, 20.0 * period);
    println!("wobbling: {s:?}, tip radius {tip}");
    assert!(s.covered && !s.settled && s.drift > 0.8 * 4e-3 * tip && s.drift < 4e-3 * tip + 1e-12, "{s:?}");
    let s = wobbling(1e-6, 20.0 * period);
    assert!(s.settled && s.drift < 4e-6 * tip, "{s:?}");
    // At rest in the turning frame but for less than the window (5 periods).
    let s = wobbling(0.0, 4.9 * period);
    assert!(!s.covered && !s.settled && s.drift < 1e-14, "{s:?}");
    let s = wobbling(0.0, 5.0 * period);
    assert!(s.covered && s.settled, "{s:?}");
}

#[test]
fn the_history_kept_is_bounded() {
    let (radius, omega) = (0.03, 9.0);
    let eq = equilibrium(&damped(), radius, omega, 0.9);
    let options = ShapeOptions { snapshots: 16, ..ShapeOptions::default() };
    // A constant speed, and a ramp down to a tenth of it (the window grows tenfold).
    let circle = Directions::<U3>::new(damped()).with_drive(Circle::new(radius, omega).unwrap());
    let slowing = Directions::<U3>::new(damped())
        .with_drive(RampedCircle::new(radius, omega, 0.1 * omega, 50.0).unwrap());
    let mut most = 0;
    let mut tracker = ShapeTracker::new(&circle, options).unwrap();
    let mut down = ShapeTracker::new(&slowing, options).unwrap();
    for k in 0..20_000 {
        let t = 1e-2 * k as f64;
        tracker.push(t, &eq.state).unwrap();
        down.push(t, &eq.state).unwrap();
        most = most.max(tracker.kept()).max(down.kept());
        if k > 1000 {
            assert!(tracker.kept() >= 15, "{k}: {}", tracker.kept());
        }
    }
    assert!(most <= 2 * 16 + 2, "{most}");
    // Slowing down, the window outgrew the kept history for a while, then refilled.
    let s = down.settling().unwrap();
    assert!((s.window - 5.0 * TAU / (0.1 * omega)).abs() < 1e-9 && s.covered, "{s:?}");
}

#[test]
fn an_undamped_stable_shape_counts_as_stable_and_a_saddle_does_not() {
    // Undamped, the spectrum of the in-phase one-node shape lies on the imaginary axis:
    // its real parts are the round-off of the central differences, below the tolerance.
    let (radius, omega) = (0.03, 9.0);
    let eq = equilibrium(&chain(), radius, omega, 0.9);
    let model = Directions::<U3>::new(chain()).with_drive(Circle::new(radius, omega).unwrap());
    let shape = whirl_shape(&model, 0.0, &eq.state).unwrap();
    let nearest = nearest_steady(&model, 0.0, &shape, &ShapeOptions::default()).unwrap();
    println!(
        "undamped one-node shape: growth {:.3e} 1/s = {:.2e} ω",
        nearest.growth_rate,
        nearest.growth_rate / omega
    );
    assert!(nearest.stable && nearest.growth_rate.abs() < 1e-3 * 1e-6 * omega, "{}", nearest.growth_rate);
    // An odd-index shape (a saddle with one descent direction) has a real positive
    // eigenvalue, damped or not.
    let problem = SteadyRotation::new(&chain(), radius).unwrap();
    let critical = SteadyRotation::new(&chain(), 0.0).unwrap().bifurcation_speeds(1).unwrap()[0];
    let omega = 1.6 * critical;
    // The mirror image of the one-node shape, against the pivot (index 1).
    let saddle = problem.solve(omega, &DVector::from_element(4, -1.0)).unwrap();
    assert_eq!((saddle.nodes(), stability(&problem, &saddle, None).unwrap().index), (1, 1));
    let model = Directions::<U3>::new(damped()).with_drive(Circle::new(radius, omega).unwrap());
    let mut depth = 0.0;
    let positions = saddle
        .displacements
        .iter()
        .zip(chain().lengths().iter().zip(saddle.theta.iter()))
        .map(|(x, (l, t))| {
            depth += l * t.cos();
            Vector3::new(*x, 0.0, -depth)
        })
        .collect();
    let shape = WhirlShape::from_positions(positions).unwrap();
    let nearest = nearest_steady(&model, 0.0, &shape, &ShapeOptions::default()).unwrap();
    println!("saddle: growth {:.3e} 1/s, distance {:.2e} m", nearest.growth_rate, nearest.distance);
    assert!(!nearest.stable && nearest.growth_rate > 1e-2, "{}", nearest.growth_rate);
    assert!(nearest.distance < 0.05, "{}", nearest.distance);
}

#[test]
fn a_failed_newton_is_reported_not_raised() {
    // A damped chain whirling as the free one-node cone with its pivot on the axis (R = 0):
    // the pivot does no work, so nothing makes up for the damping, and no damped steady
    // shape but the vertical exists; Newton from the cone does not converge.
    let problem = SteadyRotation::new(&chain(), 0.0).unwrap();
    let omega = 1.3 * problem.bifurcation_speeds(1).unwrap()[0];
    let steady = problem.branch(1, omega, &Default::default()).unwrap().points.pop().unwrap();
    let model = Directions::<U3>::new(damped()).with_drive(Circle::new(0.0, omega).unwrap());
    let mut q = steady.theta.as_slice().to_vec();
    q.extend([0.0; 4]);
    let x = model.from_spherical(&q, &[0.0, 0.0, 0.0, 0.0, omega, omega, omega, omega]).unwrap();
    let report = shape_report(&model, &[(0.0, x)], &ShapeOptions::default()).unwrap();
    assert!(matches!(report.nearest, Err(Error::SteadyNotConverged { .. })), "{:?}", report.nearest);
    assert_eq!((report.shape.nodes, report.settling.settled), (1, false));
}

#[test]
fn bad_input_is_an_error() {
    let model = Directions::<U3>::new(damped()).with_drive(Circle::new(0.02, 5.0).unwrap());
    let options = ShapeOptions::default();
    let err = shape_report(&model, &[], &options).unwrap_err();
    assert_eq!(err.to_string(), "steady rotation: samples must be at least 1, got 0");
    let err = shape_report(&model, &[(0.0, DVector::zeros(5))], &options).unwrap_err();
    assert_eq!(err, Error::LengthMismatch { what: "x", expected: 24, got: 5 });
    let mut x = model.hanging();
    x[7] = f64::NAN;
    assert!(matches!(
        shape_report(&model, &[(0.0, x)], &options),
        Err(Error::NonFinite { what: "x", index: 7, .. })
    ));
    let x = model.hanging();
    assert!(matches!(whirl_shape(&model, f64::INFINITY, &x), Err(Error::NonFinite { what: "t", .. })));
    let err = shape_report(&model, &[(1.0, x.clone()), (1.0, x.clone())], &options).unwrap_err();
    assert_eq!(err.to_string(), "steady rotation: sample time must be later than the previous sample, got 1");
    for (bad, what) in [
        (ShapeOptions { periods: 0.0, ..options }, "settle periods"),
        (ShapeOptions { tolerance: f64::NAN, ..options }, "settle tolerance"),
        (ShapeOptions { snapshots: 0, ..options }, "snapshots per window"),
        (ShapeOptions { growth_tolerance: -1.0, ..options }, "growth tolerance"),
    ] {
        let err = ShapeTracker::new(&model, bad).unwrap_err();
        assert!(matches!(err, Error::InvalidSteady { what: w, .. } if w == what), "{err}");
    }
    let err = WhirlShape::from_positions(vec![]).unwrap_err();
    assert_eq!(err.to_string(), "steady rotation: number of masses must be at least 1, got 0");
    let err =
        WhirlShape::from_positions(vec![Vector3::zeros(), Vector3::new(0.0, f64::NAN, 0.0)]).unwrap_err();
    assert!(matches!(err, Error::NonFinite { what: "positions", index: 4, .. }), "{err}");
    let short = WhirlShape::from_positions(planar(&[0.1, 0.2])).unwrap();
    let err = nearest_steady(&model, 0.0, &short, &options).unwrap_err();
    assert_eq!(err, Error::LengthMismatch { what: "positions", expected: 4, got: 2 });
    // A refused sample leaves the tracker as it was.
    let mut tracker = ShapeTracker::new(&model, options).unwrap();
    tracker.push(0.5, &x).unwrap();
    assert!(tracker.push(0.4, &x).is_err() && tracker.push(0.6, &DVector::zeros(3)).is_err());
    assert_eq!((tracker.latest().unwrap().0, tracker.kept()), (0.5, 1));
}
