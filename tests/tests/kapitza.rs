//! Kapitza's pendulum: a single pendulum whose pivot oscillates vertically,
//! `p(t) = a sin(ωt + π/2) ŷ = a cos(ωt) ŷ`, keeps its inverted position stable when `a²ω² > 2 g l`, and
//! falls from it when the drive is too slow.

use std::f64::consts::PI;
use std::ops::ControlFlow;

use nalgebra::{Const, U2, Vector1};
use pendulum_core::integrate::{Rk4, State};
use pendulum_core::{Chain, ConstantTorque, Driven, FirstOrder, Harmonic, Planar, trajectory};

const LENGTH: f64 = 0.2;
const AMPLITUDE: f64 = 0.01;
const G: f64 = 9.81;

/// The threshold `ω_c = sqrt(2 g l) / a` (rad/s), about 198 rad/s here.
fn critical() -> f64 {
    (2.0 * G * LENGTH).sqrt() / AMPLITUDE
}

/// Largest |θ − π| (rad) over `duration` seconds from θ = π − 0.1 at rest, with the pivot
/// oscillating at `omega`, starting at the top of its stroke and at rest (phase π/2, so
/// the fast motion adds no kick to the slow one); RK4 with 64 steps per drive period.
fn max_deviation(omega: f64, duration: f64) -> f64 {
    let model = Planar::new(Chain::<Const<1>>::new(&[1.0], &[LENGTH], G).unwrap());
    let drive = Harmonic::<U2>::vertical(AMPLITUDE, omega, PI / 2.0).unwrap();
    let system = FirstOrder::with_inputs(model, Driven::new(drive, ConstantTorque(Vector1::zeros())));
    let mut state = State::new(0.0, system.state(&Vector1::new(PI - 0.1), &Vector1::zeros()));
    let h = 2.0 * PI / omega / 64.0;
    let mut worst: f64 = 0.0;
    trajectory::run(&mut Rk4::new(&system), &system, &mut state, duration, h, 1, |_t, x| {
        worst = worst.max((x[0] - PI).abs());
        // Once fallen there is nothing more to learn.
        if worst > PI / 2.0 { ControlFlow::Break(()) } else { ControlFlow::Continue(()) }
    })
    .unwrap();
    worst
}

#[test]
fn fast_vertical_drive_keeps_the_pendulum_upright() {
    let deviation = max_deviation(2.0 * critical(), 1.5);
    assert!(deviation < 0.2, "at ω = 2ω_c the inverted pendulum strayed {deviation} rad");
}

#[test]
fn slow_vertical_drive_lets_the_pendulum_fall() {
    let deviation = max_deviation(0.5 * critical(), 1.5);
    assert!(deviation > PI / 2.0, "at ω = ω_c/2 the pendulum stayed within {deviation} rad of upright");
}

#[test]
fn without_drive_the_pendulum_falls() {
    // ω = 0: a plain inverted pendulum.
    let model = Planar::new(Chain::<Const<1>>::new(&[1.0], &[LENGTH], G).unwrap());
    let system = FirstOrder::new(model);
    let mut state = State::new(0.0, system.state(&Vector1::new(PI - 0.1), &Vector1::zeros()));
    let mut worst: f64 = 0.0;
    trajectory::run(&mut Rk4::new(&system), &system, &mut state, 1.5, 1e-3, 10, |_t, x| {
        worst = worst.max((x[0] - PI).abs());
        ControlFlow::Continue(())
    })
    .unwrap();
    assert!(worst > PI / 2.0, "{worst}");
}
