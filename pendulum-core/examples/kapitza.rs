//! Kapitza's pendulum: a single pendulum whose pivot oscillates vertically fast enough
//! stays upright.
//!
//! The pivot moves as `p(t) = a cos(ωt) ŷ` (a [`Harmonic`] drive with phase π/2: it starts
//! at the top of its stroke, at rest). Averaged over the fast oscillation, the inverted
//! position `θ = π` is stable when `a²ω² > 2 g l`, i.e. above
//! `ω_c = sqrt(2 g l) / a`. Started at `θ = π − 0.1` at rest, the pendulum stays within
//! about 0.1 rad of upright well above `ω_c` and falls below it.
//!
//! `cargo run --release -p pendulum-core --example kapitza`

use std::f64::consts::PI;
use std::ops::ControlFlow;

use nalgebra::{Const, DVector, Dyn, U2, U3, Vector1};
use pendulum_core::integrate::{GaussLegendre, GaussOptions, Rk4, State};
use pendulum_core::{Accounted, Chain, ConstantTorque, Driven, FirstOrder, Harmonic, Planar, trajectory};

const MASS: f64 = 1.0; // kg
const LENGTH: f64 = 0.2; // m
const AMPLITUDE: f64 = 0.01; // m
const G: f64 = 9.81; // m/s²
const DURATION: f64 = 5.0; // s
const START: f64 = PI - 0.1; // rad

/// Largest |θ − π| (rad) over the run at drive frequency `omega` (rad/s), and the time
/// (s) it first exceeded π/2 (fell), if it did. RK4, 64 steps per drive period.
fn run(omega: f64) -> (f64, Option<f64>) {
    let model = Planar::new(Chain::<Const<1>>::new(&[MASS], &[LENGTH], G).unwrap());
    let drive = Harmonic::<U2>::vertical(AMPLITUDE, omega, PI / 2.0).unwrap();
    let system = FirstOrder::with_inputs(model, Driven::new(drive, ConstantTorque(Vector1::zeros())));
    let mut state = State::new(0.0, system.state(&Vector1::new(START), &Vector1::zeros()));
    let h = if omega > 0.0 { 2.0 * PI / omega / 64.0 } else { 1e-4 };
    let (mut worst, mut fell): (f64, Option<f64>) = (0.0, None);
    trajectory::run(&mut Rk4::new(&system), &system, &mut state, DURATION, h, 1, |t, x| {
        worst = worst.max((x[0] - PI).abs());
        if worst > PI / 2.0 && fell.is_none() {
            fell = Some(t);
        }
        ControlFlow::Continue(())
    })
    .unwrap();
    (worst, fell)
}

fn main() {
    let critical = (2.0 * G * LENGTH).sqrt() / AMPLITUDE;
    println!("Kapitza's pendulum: m = {MASS} kg, l = {LENGTH} m, g = {G} m/s², pivot p(t) = a cos(ωt) ŷ");
    println!("  a = {AMPLITUDE} m; threshold a²ω² = 2 g l at ω_c = sqrt(2 g l)/a = {critical:.1} rad/s");
    println!("  start θ = π − 0.1 rad at rest, {DURATION} s, RK4 with 64 steps per drive period\n");
    println!("  {:>7}  {:>10}  {:>16}  outcome", "ω/ω_c", "ω (rad/s)", "max |θ − π| (rad)");
    for ratio in [0.0, 0.5, 0.8, 0.95, 1.05, 1.25, 1.5, 2.0, 3.0] {
        let omega = ratio * critical;
        let (worst, fell) = run(omega);
        let outcome = match fell {
            Some(t) => format!("falls (|θ − π| > π/2 at t = {t:.3} s)"),
            None => "stays upright".to_string(),
        };
        println!("  {ratio:>7.2}  {omega:>10.1}  {worst:>16.4}  {outcome}");
    }

    // The energy ledger of the stable run at 2 ω_c, Gauss–Legendre s = 3: the drive's
    // work is what the inertial energy gains.
    let omega = 2.0 * critical;
    let model = Planar::new(Chain::<Dyn>::new(&[MASS], &[LENGTH], G).unwrap());
    let drive = Harmonic::<U2>::vertical(AMPLITUDE, omega, PI / 2.0).unwrap();
    let system = Accounted::new(model, drive, ConstantTorque(DVector::zeros(1)));
    let x0 = system.state(&DVector::from_vec(vec![START]), &DVector::zeros(1));
    let mut state = State::new(0.0, x0.clone());
    let mut solver = GaussLegendre::<Dyn, U3>::new(&system, GaussOptions::default());
    // About 32 steps per drive period, a whole number of them per 0.25 s sample.
    let per_sample = (0.25 / (2.0 * PI / omega / 32.0)).ceil();
    let h = 0.25 / per_sample;
    println!("\nEnergy balance at ω = 2 ω_c (Gauss–Legendre s = 3, ~32 steps per period):");
    println!("  {:>5}  {:>12}  {:>12}  {:>10}", "t (s)", "H_in − H0 (J)", "W_drive (J)", "relative");
    trajectory::run(&mut solver, &system, &mut state, 1.0, h, per_sample as usize, |t, x| {
        let b = system.balance(0.0, &x0, t, x);
        println!(
            "  {t:>5.2}  {:>12.6}  {:>12.6}  {:>10.1e}",
            b.energy - b.initial_energy,
            b.ledger.drive,
            b.relative
        );
        ControlFlow::Continue(())
    })
    .unwrap();
}
