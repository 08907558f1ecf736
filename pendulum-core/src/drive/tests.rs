//! Tests of `drive`.

use nalgebra::{DVector, Dyn, U2, Vector2};

use super::*;

/// Central differences of p and ṗ match ṗ and p̈.
pub(super) fn assert_consistent<S: DimName, D: Drive<S>>(drive: &D)
where
    DefaultAllocator: Allocator<S>,
{
    let eps = 1e-5;
    for t in [0.0, 0.3, 1.7] {
        let dp = (drive.position(t + eps) - drive.position(t - eps)) / (2.0 * eps);
        let dv = (drive.velocity(t + eps) - drive.velocity(t - eps)) / (2.0 * eps);
        let (v, a) = (drive.velocity(t), drive.acceleration(t));
        assert!((&dp - &v).norm() < 1e-7 * (1.0 + v.norm()), "ṗ {v} vs {dp}");
        assert!((&dv - &a).norm() < 1e-7 * (1.0 + a.norm()), "p̈ {a} vs {dv}");
        // Both at once are the two calls, bit for bit (the batch relies on it).
        let (both_v, both_a) = drive.velocity_and_acceleration(t);
        let bits = |x: &OVector<f64, S>| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!((bits(&both_v), bits(&both_a)), (bits(&v), bits(&a)), "t = {t}");
        let (both_p, both_v) = drive.position_and_velocity(t);
        assert_eq!((bits(&both_p), bits(&both_v)), (bits(&drive.position(t)), bits(&v)), "t = {t}");
    }
}

#[test]
fn built_in_drives_are_consistent() {
    assert_consistent::<U2, _>(&Harmonic::new(Vector2::new(3.0, 4.0), 0.2, 5.0, 0.4).unwrap());
    assert_consistent(&Harmonic::new(Vector3::new(1.0, -1.0, 2.0), 0.1, 7.0, -1.0).unwrap());
    assert_consistent(&Circle::new(0.3, -4.0).unwrap());
    assert_consistent::<U3, _>(&Fixed);
}

#[test]
fn harmonic_normalizes_its_direction() {
    let h = Harmonic::new(Vector2::new(3.0, 4.0), 2.0, 1.0, std::f64::consts::FRAC_PI_2).unwrap();
    assert_eq!(h.direction(), &Vector2::new(0.6, 0.8));
    assert!((h.position(0.0) - Vector2::new(1.2, 1.6)).norm() < 1e-15);
    assert_eq!(Harmonic::<U3>::vertical(1.0, 1.0, 0.0).unwrap().direction(), &Vector3::z());
}

#[test]
fn bad_parameters_are_named() {
    let err = Harmonic::new(Vector2::zeros(), 1.0, 1.0, 0.0).unwrap_err();
    assert!(matches!(err, Error::InvalidDrive { what: "direction norm", .. }), "{err}");
    let err = Harmonic::new(Vector2::new(f64::NAN, 1.0), 1.0, 1.0, 0.0).unwrap_err();
    assert!(matches!(err, Error::InvalidDrive { what: "direction norm", .. }), "{err}");
    assert_eq!(
        Harmonic::new(Vector2::x(), -0.5, 1.0, 0.0),
        Err(Error::InvalidDrive { what: "amplitude", requirement: "finite and non-negative", value: -0.5 })
    );
    assert!(matches!(
        Harmonic::new(Vector2::x(), 0.5, f64::INFINITY, 0.0),
        Err(Error::InvalidDrive { what: "angular frequency", .. })
    ));
    assert!(matches!(
        Harmonic::new(Vector2::x(), 0.5, 1.0, f64::NAN),
        Err(Error::InvalidDrive { what: "phase", .. })
    ));
    let err = Circle::new(-1.0, 2.0).unwrap_err();
    assert_eq!(err.to_string(), "drive radius must be finite and non-negative, got -1");
    assert!(matches!(Circle::new(1.0, f64::NAN), Err(Error::InvalidDrive { what: "angular frequency", .. })));
}

#[test]
fn driven_inputs_carry_the_torque_and_the_pivot_acceleration() {
    let drive = FnDrive::new(
        |t: f64| Vector2::new(t * t, 0.0),
        |t: f64| Vector2::new(2.0 * t, 0.0),
        |_t: f64| Vector2::new(2.0, 0.0),
    );
    let torque = |t: f64| DVector::from_vec(vec![t, -t]);
    let driven = Driven::new(drive, torque);
    let inputs: Cow<'_, Inputs<Dyn, U2>> = driven.inputs_at(1.5);
    assert_eq!(inputs.torque.as_slice(), &[1.5, -1.5]);
    assert_eq!(inputs.pivot_acceleration, Vector2::new(2.0, 0.0));
    let boxed: Box<dyn Drive<U2>> = Box::new(Fixed);
    assert_eq!(boxed.velocity(3.0), Vector2::zeros());
}

/// The central differences of p and ṗ match ṗ and p̈ at each of `times` (none within
/// 1e-5 s of a jump of p̈).
fn assert_consistent_at(drive: &impl Drive<U3>, times: &[f64]) {
    let eps = 1e-5;
    for &t in times {
        let dp = (drive.position(t + eps) - drive.position(t - eps)) / (2.0 * eps);
        let dv = (drive.velocity(t + eps) - drive.velocity(t - eps)) / (2.0 * eps);
        let (v, a) = (drive.velocity(t), drive.acceleration(t));
        assert!((dp - v).norm() < 1e-7 * (1.0 + v.norm()), "t = {t}: ṗ {v} vs {dp}");
        assert!((dv - a).norm() < 1e-7 * (1.0 + a.norm()), "t = {t}: p̈ {a} vs {dv}");
        let (both_v, both_a) = drive.velocity_and_acceleration(t);
        let bits = |x: &Vector3<f64>| x.map(f64::to_bits);
        assert_eq!((bits(&both_v), bits(&both_a)), (bits(&v), bits(&a)), "t = {t}: both at once");
        let (both_p, both_v) = drive.position_and_velocity(t);
        let position = (bits(&both_p), bits(&both_v));
        assert_eq!(position, (bits(&drive.position(t)), bits(&v)), "t = {t}: position and velocity");
    }
}

/// Ramps up, down through zero, from rest and to rest.
fn ramps() -> [RampedCircle; 4] {
    [
        RampedCircle::new(0.3, 1.0, 6.0, 2.0).unwrap(),
        RampedCircle::new(0.2, 5.0, -1.5, 1.5).unwrap(),
        RampedCircle::new(0.1, 0.0, 8.0, 3.0).unwrap(),
        RampedCircle::new(0.4, 4.0, 0.0, 0.5).unwrap(),
    ]
}

#[test]
fn ramped_circle_is_consistent_before_during_and_after_the_ramp() {
    for ramp in ramps() {
        let end = ramp.duration();
        assert_consistent_at(&ramp, &[-0.4, 1e-4, 0.3 * end, end - 1e-4, end + 1e-4, end + 2.7]);
        // p and ṗ continuous across both ends of the ramp, p̈ jumping by R φ̈ e_φ there.
        let spin = (ramp.final_speed() - ramp.initial_speed()) / end;
        for t in [0.0, end] {
            let d = 1e-9;
            assert!((ramp.position(t + d) - ramp.position(t - d)).norm() < 1e-8, "p at {t}");
            assert!((ramp.velocity(t + d) - ramp.velocity(t - d)).norm() < 1e-7, "ṗ at {t}");
            let jump = (ramp.acceleration(t + d) - ramp.acceleration(t - d)).norm();
            assert!((jump - ramp.radius() * spin.abs()).abs() < 1e-6, "p̈ jump at {t}: {jump}");
        }
    }
}

#[test]
fn turning_drives_put_the_pivot_at_their_phase() {
    let circle = Circle::new(0.3, -4.0).unwrap();
    let r = ramps();
    let boxed: Box<dyn Turning> = Box::new(r[1]);
    let drives: [&dyn Turning; 6] = [&circle, &r[0], &boxed, &r[2], &r[3], &&circle];
    for drive in drives {
        for t in [-1.0, 0.0, 0.4, 1.2, 2.0, 9.0] {
            let (s, c) = drive.phase(t).sin_cos();
            let (r, rate) = (drive.radius(), drive.rate(t));
            assert!((drive.position(t) - Vector3::new(c, s, 0.0) * r).norm() < 1e-15);
            assert!((drive.velocity(t) - Vector3::new(-s, c, 0.0) * (r * rate)).norm() < 1e-14);
            let eps = 1e-6;
            let dphi = (drive.phase(t + 0.37 + eps) - drive.phase(t + 0.37 - eps)) / (2.0 * eps);
            assert!((dphi - drive.rate(t + 0.37)).abs() < 1e-7, "φ̇ at {t}");
        }
    }
    // The ramp's closed forms: mean speed over the ramp, then the final speed.
    let ramp = RampedCircle::new(0.3, 1.0, 6.0, 2.0).unwrap();
    assert_eq!((ramp.rate(-1.0), ramp.rate(1.0), ramp.rate(2.0), ramp.rate(5.0)), (1.0, 3.5, 6.0, 6.0));
    assert!((ramp.phase(2.0) - 7.0).abs() < 1e-14 && (ramp.phase(3.0) - 13.0).abs() < 1e-14);
    assert_eq!(circle.phase(0.5), -2.0);
}

#[test]
fn bad_ramp_parameters_are_named() {
    let message = |r: Result<RampedCircle>| r.unwrap_err().to_string();
    assert_eq!(
        message(RampedCircle::new(-0.1, 0.0, 5.0, 10.0)),
        "drive radius must be finite and non-negative, got -0.1"
    );
    assert_eq!(
        message(RampedCircle::new(0.1, f64::NAN, 5.0, 10.0)),
        "drive initial angular speed must be finite, got NaN"
    );
    assert_eq!(
        message(RampedCircle::new(0.1, 0.0, f64::INFINITY, 10.0)),
        "drive final angular speed must be finite, got inf"
    );
    assert_eq!(
        message(RampedCircle::new(0.1, 0.0, 5.0, 0.0)),
        "drive ramp duration must be finite and positive, got 0"
    );
    assert_eq!(
        RampedCircle::new(0.1, 0.0, 5.0, -2.0),
        Err(Error::InvalidDrive { what: "ramp duration", requirement: "finite and positive", value: -2.0 })
    );
    assert!(matches!(
        RampedCircle::new(0.1, 0.0, 5.0, f64::INFINITY),
        Err(Error::InvalidDrive { what: "ramp duration", .. })
    ));
    // Ramping to rest, from rest and not at all are fine.
    assert!(RampedCircle::new(0.0, 3.0, 0.0, 1.0).is_ok() && RampedCircle::new(0.1, 2.0, 2.0, 1e-9).is_ok());
}

/// The energy balance `H − H0 − (W_drive − E_damped)` of a damped 3D chain driven through a
/// ramp (up from rest over 1.5 s, held to 3 s; RK4 + projection). With `p`, `ṗ`, `p̈` in
/// agreement it closes to the integration error, which the jumps of `p̈` at the ramp's ends
/// make first order in `h` (a constant circle: fourth order): halving `h` halves it. With
/// `ṗ` of the final circle instead (the dynamics unchanged, the drive power wrong) it does
/// not close, at any step.
#[test]
fn the_energy_balance_of_a_ramped_run_closes() {
    use std::ops::ControlFlow;

    use crate::chain::Chain;
    use crate::energy::ledger::{Accounted, Balance};
    use crate::integrate::{Projected, Rk4, State};
    use crate::models::directions::Directions;
    use crate::trajectory;

    let chain = Chain::<Dyn>::new(&[1.0, 0.6, 1.4], &[0.5, 0.3, 0.7], 9.81)
        .unwrap()
        .with_damping(&[0.2, 0.05, 0.3])
        .unwrap();
    let balance = |drive: &dyn Drive<U3>, h: f64| -> Balance {
        let system = Accounted::of(Directions::<U3>::new(chain.clone()).with_drive(drive));
        let motion = system.chain().from_spherical(&[0.4, 1.2, 2.0, 0.3, -1.0, 2.2], &[0.0; 6]).unwrap();
        let x0 = system.state(&motion).unwrap();
        let mut integrator = Projected::new(Rk4::new(&system));
        let mut state = State::new(0.0, x0.clone());
        trajectory::run(&mut integrator, &system, &mut state, 3.0, h, 1000, |_, _| ControlFlow::Continue(()))
            .unwrap();
        system.balance(0.0, &x0, state.t(), state.x())
    };
    // Ramp ends on a step boundary and between two.
    for duration in [1.5, 1.5005] {
        let ramp = RampedCircle::new(0.1, 0.0, 5.0, duration).unwrap();
        let (coarse, fine) = (balance(&ramp, 1e-3), balance(&ramp, 5e-4));
        println!("ramp over {duration} s: h = 1 ms {coarse:?}\n  h = 0.5 ms {fine:?}");
        assert!(coarse.ledger.drive.abs() > 0.5 && coarse.ledger.damped > 10.0, "{coarse:?}");
        assert!(coarse.relative < 5e-6, "{coarse:?}");
        let ratio = coarse.residual / fine.residual;
        assert!((1.8..4.5).contains(&ratio), "residual ratio {ratio} on halving h");
    }
    let ramp = RampedCircle::new(0.1, 0.0, 5.0, 1.5).unwrap();
    let circle = Circle::new(0.1, 5.0).unwrap();
    let wrong =
        FnDrive::new(move |t| ramp.position(t), move |t| circle.velocity(t), move |t| ramp.acceleration(t));
    let (coarse, fine) = (balance(&wrong, 1e-3), balance(&wrong, 5e-4));
    println!("ṗ of the final circle: {coarse:?}");
    assert!(coarse.relative > 1e-3 && (coarse.residual / fine.residual - 1.0).abs() < 1e-2, "{coarse:?}");
}
