//! Every bad input to the library: each gives an `Err` whose message names the value and
//! where it came from, never a panic, NaN or hang. The exact messages asserted here are
//! the ones listed in `docs/reliability.md` (run with `--nocapture` to print them).

use std::f64::consts::FRAC_PI_2;

use nalgebra::{DVector, Dyn, SVector, U2, U3, Vector2};
use pendulum_core::integrate::{
    GaussFixedPoint, GaussLegendre, GaussOptions, Integrator, Projected, Rk4, State,
};
use pendulum_core::{
    Canonical, Chain, Derivatives, Directions, FirstOrder, Inputs, Jacobians, Model, Planar, PlanarTension,
    Spatial, trajectory,
};

/// Asserts the exact message of an error and prints it for the docs.
fn expect_message<T: std::fmt::Debug>(what: &str, result: pendulum_core::Result<T>, message: &str) {
    let error = result.expect_err(what);
    println!("{what}: {error}");
    assert_eq!(error.to_string(), message, "{what}");
}

fn chain(n: usize) -> Chain<Dyn> {
    Chain::uniform(n, 1.0, 1.0, 9.81).unwrap()
}

#[test]
fn chain_parameters() {
    expect_message(
        "n = 0",
        Chain::<Dyn>::uniform(0, 1.0, 1.0, 9.81),
        "a chain needs at least one link, got 0",
    );
    expect_message("no masses", Chain::<Dyn>::new(&[], &[], 9.81), "a chain needs at least one link, got 0");
    for (value, text) in [(-1.0, "-1"), (0.0, "0"), (f64::NAN, "NaN"), (f64::INFINITY, "inf")] {
        expect_message(
            "mass",
            Chain::<Dyn>::new(&[1.0, value], &[1.0, 1.0], 9.81),
            &format!("mass of link 2 must be finite and positive, got {text}"),
        );
        expect_message(
            "length",
            Chain::<Dyn>::new(&[1.0, 1.0], &[value, 1.0], 9.81),
            &format!("length of link 1 must be finite and positive, got {text}"),
        );
        expect_message(
            "uniform length",
            Chain::<Dyn>::uniform(3, 1.0, value, 9.81),
            &format!("length of link 1 must be finite and positive, got {text}"),
        );
    }
    // g = 0 is valid (a chain in free fall / in space); negative, NaN or infinite is not.
    assert!(Chain::<Dyn>::uniform(2, 1.0, 1.0, 0.0).is_ok());
    for (value, text) in [(-9.81, "-9.81"), (f64::NAN, "NaN"), (f64::NEG_INFINITY, "-inf")] {
        expect_message(
            "gravity",
            Chain::<Dyn>::uniform(2, 1.0, 1.0, value),
            &format!("gravity g must be finite and non-negative, got {text}"),
        );
    }
    for (value, text) in [(-0.1, "-0.1"), (f64::NAN, "NaN"), (f64::INFINITY, "inf")] {
        expect_message(
            "damping",
            chain(3).with_damping(&[0.0, 0.0, value]),
            &format!("damping of link 3 must be finite and non-negative, got {text}"),
        );
    }
    expect_message(
        "lengths count",
        Chain::<Dyn>::new(&[1.0, 1.0], &[1.0], 9.81),
        "lengths has 1 entries, expected 2",
    );
    expect_message("damping count", chain(3).with_damping(&[0.1]), "damping has 1 entries, expected 3");
    // A fixed-size chain given the wrong number of values.
    expect_message(
        "fixed size",
        Chain::<nalgebra::U3>::new(&[1.0, 1.0], &[1.0, 1.0], 9.81),
        "masses has 2 entries, expected 3",
    );
}

#[test]
fn model_states_and_inputs() {
    let model = Planar::new(chain(2));
    let mut out = DVector::zeros(2);
    let inputs = model.zero_inputs();
    let q = DVector::from_vec(vec![0.1, 0.2]);
    let qd = DVector::zeros(2);
    expect_message(
        "q length",
        model.accelerations(&DVector::zeros(3), &qd, &inputs, &mut out),
        "q has 3 entries, expected 2",
    );
    expect_message(
        "qd length",
        model.accelerations(&q, &DVector::zeros(1), &inputs, &mut out),
        "qd has 1 entries, expected 2",
    );
    expect_message(
        "NaN q",
        model.accelerations(&DVector::from_vec(vec![0.1, f64::NAN]), &qd, &inputs, &mut out),
        "q[1] must be finite, got NaN",
    );
    expect_message(
        "inf qd",
        model.accelerations(&q, &DVector::from_vec(vec![f64::INFINITY, 0.0]), &inputs, &mut out),
        "qd[0] must be finite, got inf",
    );
    let bad = Inputs { torque: DVector::zeros(5), pivot_acceleration: Vector2::zeros() };
    expect_message(
        "torque length",
        model.accelerations(&q, &qd, &bad, &mut out),
        "torque has 5 entries, expected 2",
    );
    let bad = Inputs { torque: DVector::zeros(2), pivot_acceleration: Vector2::new(0.0, f64::NAN) };
    expect_message(
        "NaN pivot acceleration",
        model.accelerations(&q, &qd, &bad, &mut out),
        "pivot_acceleration[1] must be finite, got NaN",
    );
}

pendulum_macros::model! {
    /// A generated planar chain on the tension route, whose Jacobians come from the kept
    /// tension solve instead of the trait's default.
    struct Planar4 { kind: planar, links: 4 }
}

/// The Jacobians' checks: the generated tension route (fixed sizes: finiteness only) and
/// `PlanarTension` (sizes and finiteness), each error naming the entry.
#[test]
fn derivatives_of_bad_states() {
    let generated = Planar4::new(Chain::uniform(4, 1.0, 1.0, 9.81).unwrap());
    let mut jac = Jacobians::zeros(&generated);
    let (q, qd) = (SVector::<f64, 4>::new(0.1, 0.2, f64::NAN, 0.3), SVector::<f64, 4>::zeros());
    let inputs = generated.zero_inputs();
    expect_message(
        "NaN q, generated Jacobians",
        generated.acceleration_jacobians(&q, &qd, &inputs, &mut jac),
        "q[2] must be finite, got NaN",
    );
    let qd = SVector::<f64, 4>::new(0.0, f64::INFINITY, 0.0, 0.0);
    expect_message(
        "inf qd, generated state Jacobians",
        generated.state_jacobians(&SVector::zeros(), &qd, &inputs, &mut jac),
        "qd[1] must be finite, got inf",
    );
    let model = PlanarTension::new(chain(3));
    let mut jac = Jacobians::zeros(&model);
    let inputs = model.zero_inputs();
    expect_message(
        "q length, O(n) Jacobians",
        model.acceleration_jacobians(&DVector::zeros(2), &DVector::zeros(3), &inputs, &mut jac),
        "q has 2 entries, expected 3",
    );
    let bad = Inputs { torque: DVector::zeros(3), pivot_acceleration: Vector2::new(f64::NAN, 0.0) };
    expect_message(
        "NaN pivot acceleration, O(n) Jacobians",
        model.state_jacobians(&DVector::zeros(3), &DVector::zeros(3), &bad, &mut jac),
        "pivot_acceleration[0] must be finite, got NaN",
    );
}

#[test]
fn spherical_singularity_in_the_angle_model() {
    // Link 2 hangs straight down: φ_2 is undefined, M is singular.
    let model = Spatial::new(chain(2));
    let mut out = DVector::zeros(4);
    let q = DVector::from_vec(vec![0.5, 0.0, 0.0, 0.0]);
    expect_message(
        "sin θ = 0",
        model.accelerations(&q, &DVector::zeros(4), &model.zero_inputs(), &mut out),
        "link 2 sits at the spherical-angle singularity: theta = 0 rad (|sin theta| = 0e0 < 1e-6); \
         the (theta, phi) coordinates cannot give its phi acceleration there",
    );
    // Straight up (θ = π) is the same singularity.
    let q = DVector::from_vec(vec![std::f64::consts::PI, 0.5, 0.0, 0.0]);
    let error = model.accelerations(&q, &DVector::zeros(4), &model.zero_inputs(), &mut out).unwrap_err();
    println!("θ = π: {error}");
    assert!(error.to_string().starts_with("link 1 sits at the spherical-angle singularity"), "{error}");
    // Through an integrator the step fails with the same error and the state is kept.
    let system = FirstOrder::new(model);
    let x0 = DVector::from_vec(vec![0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    let mut state = State::new(0.0, x0.clone());
    let error = Rk4::new(&system).step(&system, &mut state, 1e-3).unwrap_err();
    assert!(error.to_string().starts_with("link 2 sits at the spherical-angle singularity"), "{error}");
    assert_eq!(state.x(), &x0);
    // The direction model has no singularity there.
    let directions = Directions::<U3>::new(chain(2));
    let x = directions.from_spherical(&[0.5, 0.0, 0.0, 0.0], &[0.0; 4]).unwrap();
    let mut state = State::new(0.0, x);
    Projected::new(Rk4::new(&directions)).step(&directions, &mut state, 1e-3).unwrap();
}

#[test]
fn integrator_steps() {
    let system = FirstOrder::new(Planar::new(chain(2)));
    let x0 = DVector::from_vec(vec![0.1, 0.2, 0.0, 0.0]);
    for (h, text) in [(0.0, "0"), (f64::NAN, "NaN"), (f64::INFINITY, "inf")] {
        let mut state = State::new(0.0, x0.clone());
        expect_message(
            "step size",
            Rk4::new(&system).step(&system, &mut state, h),
            &format!("step size h must be finite and non-zero, got {text}"),
        );
        let mut gauss = GaussLegendre::<_, U2>::new(&system, GaussOptions::default());
        expect_message(
            "step size (Gauss)",
            gauss.step(&system, &mut state, h),
            &format!("step size h must be finite and non-zero, got {text}"),
        );
    }
    let mut state = State::new(0.0, DVector::zeros(3));
    expect_message(
        "state length",
        Rk4::new(&system).step(&system, &mut state, 1e-3),
        "x has 3 entries, expected 4",
    );
    let mut state = State::new(0.0, DVector::from_vec(vec![0.1, f64::NAN, 0.0, 0.0]));
    expect_message(
        "NaN state",
        Rk4::new(&system).step(&system, &mut state, 1e-3),
        "q[1] must be finite, got NaN",
    );
    let directions = Directions::<U2>::new(chain(2));
    let mut x = directions.hanging();
    x[5] = f64::NAN;
    let mut state = State::new(0.0, x);
    expect_message(
        "NaN direction state",
        Rk4::new(&directions).step(&directions, &mut state, 1e-3),
        "x[5] must be finite, got NaN",
    );
}

/// A step far too long for the implicit stage equations: Newton (GaussLegendre) and the
/// fixed-point sweeps (GaussFixedPoint) both report `StageSolveFailed` and leave the
/// state unchanged; neither returns NaN nor loops.
#[test]
fn step_too_large_for_the_stage_solvers() {
    let model = Planar::new(Chain::<Dyn>::new(&[1.0, 0.01, 1.0], &[1.0, 0.1, 1.0], 9.81).unwrap());
    let system = Canonical::new(model);
    let q = DVector::from_vec(vec![FRAC_PI_2, FRAC_PI_2, 0.3]);
    let x0 = system.from_velocities(&q, &DVector::from_vec(vec![0.0, 20.0, 0.0]));
    let h = 2.0;

    let mut state = State::new(0.0, x0.clone());
    let error = GaussLegendre::<_, U2>::new(&system, GaussOptions::default())
        .step(&system, &mut state, h)
        .unwrap_err();
    println!("Newton, h = {h}: {error}");
    assert!(matches!(error, pendulum_core::Error::StageSolveFailed { .. }), "{error:?}");
    assert!(
        error
            .to_string()
            .starts_with("the stage equations of the step from t = 0 s with h = 2 s did not converge after")
    );
    assert!(error.to_string().ends_with("iterations; try a smaller step"));
    assert_eq!(state.x(), &x0);

    let system = FirstOrder::new(system.model().clone());
    let x0 = system.state(&q, &DVector::from_vec(vec![0.0, 20.0, 0.0]));
    let mut state = State::new(0.0, x0.clone());
    let error = GaussFixedPoint::<_, U2>::new(&system, 50).step(&system, &mut state, h).unwrap_err();
    println!("fixed point, h = {h}: {error}");
    assert!(matches!(error, pendulum_core::Error::StageSolveFailed { .. }), "{error:?}");
    assert_eq!(state.x(), &x0);

    // Large direction chains: the fixed-point route on a 3D chain with a step beyond its
    // fastest frequency.
    let directions = Directions::<U3>::new(Chain::uniform(50, 0.1, 0.01, 9.81).unwrap());
    let x = directions.from_spherical(&[0.8; 100], &[1.0; 100]).unwrap();
    let mut state = State::new(0.0, x.clone());
    let error =
        GaussFixedPoint::<_, U2>::new(&directions, 50).step(&directions, &mut state, 0.5).unwrap_err();
    println!("fixed point, directions n = 50, h = 0.5: {error}");
    assert!(matches!(error, pendulum_core::Error::StageSolveFailed { .. }), "{error:?}");
    assert_eq!(state.x(), &x);
}

#[test]
fn trajectory_runs() {
    let system = FirstOrder::new(Planar::new(chain(1)));
    let x0 = DVector::from_vec(vec![0.5, 0.0]);
    let run = |t1: f64, h: f64, every: usize| {
        let mut state = State::new(0.0, x0.clone());
        trajectory::run(&mut Rk4::new(&system), &system, &mut state, t1, h, every, |_, _| {
            std::ops::ControlFlow::Continue(())
        })
    };
    for (t1, text) in [(f64::NAN, "NaN"), (f64::INFINITY, "inf")] {
        expect_message(
            "end time",
            run(t1, 1e-3, 1),
            &format!("trajectory end time must be finite, got {text}"),
        );
    }
    for (h, text) in [(0.0, "0"), (-1e-3, "-0.001"), (f64::NAN, "NaN"), (f64::INFINITY, "inf")] {
        expect_message(
            "run step",
            run(1.0, h, 1),
            &format!("trajectory step size must be finite and positive, got {text}"),
        );
    }
    expect_message(
        "absurd step",
        run(1e300, 1e-300, 1),
        "trajectory step size must be not absurdly small, got 1e-300",
    );
    expect_message(
        "every = 0",
        run(1.0, 1e-3, 0),
        "trajectory sampling interval must be at least 1 step, got 0",
    );
    // A failing step inside a run says which step and when.
    let spatial = FirstOrder::new(Spatial::new(chain(1)));
    let mut state = State::new(0.0, DVector::from_vec(vec![0.0, 0.0, 0.0, 0.0]));
    let error = trajectory::run(&mut Rk4::new(&spatial), &spatial, &mut state, 1.0, 0.1, 1, |_, _| {
        std::ops::ControlFlow::Continue(())
    })
    .unwrap_err();
    println!("failed run step: {error}");
    assert!(
        error.to_string().starts_with("step 0 of the run, from t = 0 s, failed: link 1 sits at"),
        "{error}"
    );
}
