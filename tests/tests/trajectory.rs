//! `trajectory::run`: equal steps landing on `t1`, sampling every k steps, stopping early
//! from the callback, and failed steps reported with their time.

use std::ops::ControlFlow;

use nalgebra::{DVector, Dyn, U2, Vector2};
use pendulum_core::integrate::{GaussLegendre, GaussOptions, Integrator, Rk4, State};
use pendulum_core::trajectory::{self, Recorder};
use pendulum_core::{Chain, ConstantTorque, Driven, Error, FirstOrder, FnDrive, Harmonic, Planar};

fn double() -> FirstOrder<Planar, pendulum_core::Inputs<Dyn, U2>> {
    FirstOrder::new(Planar::new(Chain::<Dyn>::new(&[1.0, 0.5], &[1.0, 0.7], 9.81).unwrap()))
}

#[test]
fn a_run_is_the_same_as_integrate_and_lands_on_t1() {
    let system = double();
    let x0 = system.state(&DVector::from_vec(vec![1.2, -0.4]), &DVector::from_vec(vec![0.0, 1.0]));
    let mut a = State::new(0.0, x0.clone());
    let mut b = State::new(0.0, x0);
    let mut solver_a = GaussLegendre::<_, U2>::new(&system, GaussOptions::default());
    let mut solver_b = GaussLegendre::<_, U2>::new(&system, GaussOptions::default());
    // 0.01 is not representable; 3 / 0.01 must still be 300 steps.
    let summary =
        trajectory::run(&mut solver_a, &system, &mut a, 3.0, 0.01, 7, |_, _| ControlFlow::Continue(()))
            .unwrap();
    solver_b.integrate(&system, &mut b, 3.0, 300).unwrap();
    assert_eq!(summary.steps, 300);
    assert_eq!(summary.samples, 1 + 42 + 1);
    assert_eq!(a.x(), b.x());
    assert!((a.t() - 3.0).abs() <= 4.0 * f64::EPSILON, "t = {}", a.t());
    assert_eq!(summary.t, a.t());
}

#[test]
fn steps_are_shortened_to_fit_the_interval() {
    let system = double();
    let mut state = State::new(0.5, system.state(&DVector::from_vec(vec![0.3, 0.0]), &DVector::zeros(2)));
    let mut recorder = Recorder::new();
    let summary =
        trajectory::run(&mut Rk4::new(&system), &system, &mut state, 1.5, 0.3, 1, |t, x| recorder.push(t, x))
            .unwrap();
    assert_eq!((summary.steps, summary.h), (4, 0.25));
    assert_eq!(recorder.times(), &[0.5, 0.75, 1.0, 1.25, 1.5]);
    assert_eq!(recorder.states().last().unwrap(), state.x());
}

#[test]
fn the_callback_stops_a_driven_run_when_the_pendulum_passes_horizontal() {
    // Hanging at rest, pivot shaken horizontally near resonance: the swing grows until
    // |θ| > π/2; the run stops there, well before t1.
    let model = Planar::new(Chain::<Dyn>::new(&[1.0], &[0.5], 9.81).unwrap());
    let omega = (9.81f64 / 0.5).sqrt();
    let drive = Harmonic::new(nalgebra::Vector2::x(), 0.2, omega, 0.0).unwrap();
    let system = FirstOrder::with_inputs(model, Driven::new(drive, ConstantTorque::zeros(Dyn(1))));
    let mut state = State::new(0.0, system.state(&DVector::zeros(1), &DVector::zeros(1)));
    let mut solver = GaussLegendre::<_, U2>::new(&system, GaussOptions::default());
    let summary = trajectory::run(&mut solver, &system, &mut state, 100.0, 0.01, 1, |_, x| {
        if x[0].abs() > std::f64::consts::FRAC_PI_2 {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    })
    .unwrap();
    assert!(summary.stopped_early);
    assert!(summary.t < 100.0 && state.x()[0].abs() > std::f64::consts::FRAC_PI_2, "{summary:?}");
    assert_eq!(summary.steps, summary.samples - 1);
}

#[test]
fn a_failed_step_reports_its_time_and_step() {
    // A user drive whose acceleration turns NaN after t = 0.5 s: the model rejects it at
    // first stage past 0.5 s, in step 50 (from t = 0.5 s; step 49 ends exactly at 0.5 s).
    let bad = |t: f64| if t > 0.5 { Vector2::new(f64::NAN, 0.0) } else { Vector2::zeros() };
    let drive = FnDrive::new(|_| Vector2::zeros(), |_| Vector2::zeros(), bad);
    let model = Planar::new(Chain::<Dyn>::new(&[1.0], &[1.0], 9.81).unwrap());
    let system = FirstOrder::with_inputs(model, Driven::new(drive, ConstantTorque::zeros(Dyn(1))));
    let mut state = State::new(0.0, system.state(&DVector::from_vec(vec![0.5]), &DVector::zeros(1)));
    let err = trajectory::run(&mut Rk4::new(&system), &system, &mut state, 5.0, 1e-2, 10, |_, _| {
        ControlFlow::Continue(())
    })
    .unwrap_err();
    match &err {
        Error::StepFailed { t, step: 50, source } => {
            assert!(
                matches!(**source, Error::NonFinite { what: "pivot_acceleration", index: 0, .. }),
                "{err}"
            );
            assert!((*t - 0.5).abs() < 1e-12, "{err}");
            assert_eq!(state.t(), *t);
        }
        other => panic!("expected StepFailed at step 50, got {other}"),
    }
    assert!(err.to_string().starts_with("step 50 of the run, from t = 0.5 s"), "{err}");
}

#[test]
fn bad_arguments_are_errors_before_any_step() {
    let system = double();
    let mut state = State::new(0.0, system.state(&DVector::zeros(2), &DVector::zeros(2)));
    let mut solver = Rk4::new(&system);
    let mut run = |t1: f64, h: f64, every: usize| {
        trajectory::run(&mut solver, &system, &mut state, t1, h, every, |_, _| ControlFlow::Continue(()))
    };
    assert!(matches!(run(1.0, 0.0, 1), Err(Error::InvalidRun { what: "step size", .. })));
    assert!(matches!(run(f64::INFINITY, 0.1, 1), Err(Error::InvalidRun { what: "end time", .. })));
    assert!(matches!(run(1.0, 0.1, 0), Err(Error::InvalidRun { what: "sampling interval", .. })));
    assert_eq!(solver.stats().steps, 0);
}
