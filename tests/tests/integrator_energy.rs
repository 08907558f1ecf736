//! Energy behaviour of the integrators on the chaotic double pendulum, short runs: the
//! Gauss–Legendre energy error stays bounded (s = 2: at its O(h⁴) level; s = 3: at
//! round-off), RK4's grows; and the canonical form `(q, p)` and the velocity form
//! `(q, q̇)` follow the same motion.
//!
//! Unit masses and lengths, g = 9.81 m/s², released from rest at θ = (π/2, π/2); energy
//! errors relative to m g l = 9.81 J (the start has H ≈ 0). The long runs (10⁶–10⁷ steps)
//! are `cargo run --release -p pendulum-core --example energy_long_run`, discussed in
//! `docs/integrators.md`, which also gives the numbers these bounds come from.

use std::f64::consts::FRAC_PI_2;

use nalgebra::{Const, DVector, DimMul, Dyn, SVector, U2, U3, Vector2};
use pendulum_core::integrate::{
    GaussAlloc, GaussLegendre, GaussOptions, GaussStages, Integrator, Rk4, State, System,
};
use pendulum_core::{Canonical, Chain, FirstOrder, Model, Planar, Spatial};

const SCALE: f64 = 9.81;

fn model() -> Planar<Const<2>> {
    Planar::new(Chain::<Const<2>>::uniform(2, 1.0, 1.0, 9.81).unwrap())
}

fn start() -> (Vector2<f64>, Vector2<f64>) {
    (Vector2::new(FRAC_PI_2, FRAC_PI_2), Vector2::zeros())
}

fn gauss<S: System<Dim = Const<4>>, St: GaussStages>(system: &S) -> GaussLegendre<Const<4>, St>
where
    Const<4>: DimMul<St>,
    nalgebra::DefaultAllocator: GaussAlloc<Const<4>, St>,
{
    GaussLegendre::new(system, GaussOptions::default())
}

/// `|ΔH|/(m g l)` after each of `steps` steps of `h`.
fn errors<S: System<Dim = Const<4>>, I: Integrator<S>>(
    system: &S,
    mut integrator: I,
    x0: SVector<f64, 4>,
    h: f64,
    steps: usize,
    energy: impl Fn(&SVector<f64, 4>) -> f64,
) -> Vec<f64> {
    let e0 = energy(&x0);
    let mut state = State::new(0.0, x0);
    (0..steps)
        .map(|_| {
            integrator.step(system, &mut state, h).unwrap();
            ((energy(state.x()) - e0) / SCALE).abs()
        })
        .collect()
}

fn velocity_form<St: GaussStages>(h: f64, steps: usize) -> Vec<f64>
where
    Const<4>: DimMul<St>,
    nalgebra::DefaultAllocator: GaussAlloc<Const<4>, St>,
{
    let system = FirstOrder::new(model());
    let (q, qd) = start();
    errors(&system, gauss::<_, St>(&system), system.state(&q, &qd), h, steps, |x| system.energy(x))
}

fn canonical_form<St: GaussStages>(h: f64, steps: usize) -> Vec<f64>
where
    Const<4>: DimMul<St>,
    nalgebra::DefaultAllocator: GaussAlloc<Const<4>, St>,
{
    let system = Canonical::new(model());
    let (q, qd) = start();
    errors(&system, gauss::<_, St>(&system), system.from_velocities(&q, &qd), h, steps, |x| {
        system.energy(x).unwrap()
    })
}

fn max(v: &[f64]) -> f64 {
    v.iter().copied().fold(0.0, f64::max)
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

/// Gauss s = 2, h = 0.01, 2·10⁴ steps (200 s, about 60 swings of the upper link): the
/// error stays at its O(h⁴) level (the 10⁷-step runs peak at 8.3e-6 canonical, 1.6e-5
/// velocity form), and the second half does not exceed the first by more than chaos'
/// wandering (measured ratio of maxima near 1); RK4 at the same step loses energy
/// steadily (about 5.9e-6 per second, so ~1e-3 by the end) and its second half averages
/// far above its first.
#[test]
fn gauss_2_energy_error_is_bounded_and_rk4_drifts() {
    let (h, steps) = (0.01, 20_000);
    let rk4 = {
        let system = FirstOrder::new(model());
        let (q, qd) = start();
        errors(&system, Rk4::new(&system), system.state(&q, &qd), h, steps, |x| system.energy(x))
    };
    let half = steps / 2;
    for (form, e) in
        [("velocity", velocity_form::<U2>(h, steps)), ("canonical", canonical_form::<U2>(h, steps))]
    {
        let (first, second) = (max(&e[..half]), max(&e[half..]));
        eprintln!("Gauss 2 {form}: max |ΔH| first half {first:.3e}, second half {second:.3e}");
        assert!(max(&e) < 2e-5, "{form}: {:e}", max(&e));
        assert!(second < 2.0 * first, "{form}: {second:e} vs {first:e}");
        assert!(rk4[steps - 1] > 30.0 * max(&e), "RK4 {:e} vs Gauss {form} {:e}", rk4[steps - 1], max(&e));
    }
    let (first, second) = (mean(&rk4[..half]), mean(&rk4[half..]));
    eprintln!("RK4: mean |ΔH| first half {first:.3e}, second half {second:.3e}, end {:.3e}", rk4[steps - 1]);
    assert!(second > 2.0 * first, "RK4 should drift: {second:e} vs {first:e}");
    assert!(rk4[steps - 1] > 5e-4, "{:e}", rk4[steps - 1]);
}

/// Gauss s = 3, h = 0.001, 2·10⁴ steps (20 s): the O(h⁶) error is below round-off, so
/// the energy error is round-off only (measured: about 3e-14 for both forms; the
/// 10⁶-step runs stay below 1.1e-13). RK4 at the same step has lost about 6e-10 by then
/// (6e-11 per second).
#[test]
fn gauss_3_energy_error_is_round_off() {
    let (h, steps) = (0.001, 20_000);
    let rk4 = {
        let system = FirstOrder::new(model());
        let (q, qd) = start();
        errors(&system, Rk4::new(&system), system.state(&q, &qd), h, steps, |x| system.energy(x))
    };
    eprintln!("RK4 h = {h}: |ΔH| at the end {:.3e}", rk4[steps - 1]);
    assert!(rk4[steps - 1] > 3e-10, "{:e}", rk4[steps - 1]);
    for (form, e) in
        [("velocity", velocity_form::<U3>(h, steps)), ("canonical", canonical_form::<U3>(h, steps))]
    {
        eprintln!("Gauss 3 {form}: max |ΔH| {:.3e}", max(&e));
        assert!(max(&e) < 2e-13, "{form}: {:e}", max(&e));
    }
}

/// Both forms integrate the same motion: over 1 s (Gauss s = 2, h = 10⁻³, errors
/// ~1e-11 each) the canonical run converted back to `(q, q̇)` agrees with the velocity
/// run to integration accuracy.
#[test]
fn canonical_and_velocity_forms_follow_the_same_motion() {
    let (h, steps) = (0.001, 1000);
    let velocity = FirstOrder::new(model());
    let canonical = Canonical::new(model());
    let (q, qd) = start();
    let mut a = State::new(0.0, velocity.state(&q, &qd));
    let mut b = State::new(0.0, canonical.from_velocities(&q, &qd));
    gauss::<_, U2>(&velocity).integrate(&velocity, &mut a, h * steps as f64, steps).unwrap();
    gauss::<_, U2>(&canonical).integrate(&canonical, &mut b, h * steps as f64, steps).unwrap();
    let (qa, qda) = velocity.split(a.x());
    let (qb, qdb) = canonical.to_velocities(b.x()).unwrap();
    let difference = (qa - qb).amax().max((qda - qdb).amax());
    eprintln!("planar, after 1 s: max |Δ(q, q̇)| = {difference:.3e}");
    assert!(difference < 1e-9, "{difference:e}");
}

/// The same for a spatial double pendulum (dynamic size), away from `sin θ = 0`:
/// checks the spatial kinetic gradient inside the dynamics.
#[test]
fn spatial_canonical_and_velocity_forms_follow_the_same_motion() {
    let model = Spatial::new(Chain::<Dyn>::new(&[1.0, 0.5], &[1.0, 0.8], 9.81).unwrap());
    let velocity = FirstOrder::new(model.clone());
    let canonical = Canonical::new(model.clone());
    let q = DVector::from_vec(vec![1.2, 1.9, 0.3, -0.8]);
    let qd = DVector::from_vec(vec![0.4, -0.6, 1.5, 2.0]);
    let (h, steps) = (0.001, 500);
    let mut a = State::new(0.0, velocity.state(&q, &qd));
    let mut b = State::new(0.0, canonical.from_velocities(&q, &qd));
    let mut ga = GaussLegendre::<_, U2>::new(&velocity, GaussOptions::default());
    let mut gb = GaussLegendre::<_, U2>::new(&canonical, GaussOptions::default());
    for _ in 0..steps {
        ga.step(&velocity, &mut a, h).unwrap();
        gb.step(&canonical, &mut b, h).unwrap();
        let (qa, _) = velocity.split(a.x());
        assert!(model.check_configuration(&qa).is_ok(), "stay away from the singularity");
    }
    let (qa, qda) = velocity.split(a.x());
    let (qb, qdb) = canonical.to_velocities(b.x()).unwrap();
    let difference = (qa - qb).amax().max((qda - qdb).amax());
    eprintln!("spatial, after 0.5 s: max |Δ(q, q̇)| = {difference:.3e}");
    assert!(difference < 1e-9, "{difference:e}");
    let energy_drift = (canonical.energy(b.x()).unwrap() - velocity.energy(&velocity.state(&q, &qd))).abs();
    assert!(energy_drift < 1e-9, "{energy_drift:e}");
}
