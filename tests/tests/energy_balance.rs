//! With a moving pivot, damping and torques, the inertial-frame energy changes by exactly
//! the work of the drive and the torques minus the energy the damping dissipates:
//! `H_in(t) − H_in(t0) = W_drive + W_torque − E_damped`. Checked at random states
//! (derivative along the flow) and over whole Gauss–Legendre runs of `Accounted`.

use std::ops::ControlFlow;

use nalgebra::{DVector, DefaultAllocator, Dyn, OVector, U1, U2, U3, Vector2, Vector3};
use pendulum_core::integrate::{GaussLegendre, GaussOptions, State, SystemAlloc};
use pendulum_core::{
    Accounted, Chain, Circle, ConstantTorque, Drive, Driven, FirstOrder, FnDrive, Harmonic, Model,
    ModelAlloc, Planar, Sampled, Spatial, TorqueAt, trajectory,
};
use pendulum_tests::{random_chain, random_vector, rng};
use rand::Rng;

pendulum_macros::model! {
    struct Planar3 { kind: planar, links: 3 }
    struct Spatial2 { kind: spatial, links: 2 }
}

/// Worst |dH_in/dt − (P_drive + P_torque − P_damping)| over random states, relative to
/// the size of the powers and the energy; dH_in/dt by extrapolated central differences
/// along the flow.
fn worst_power_mismatch<M: Model, Dr: Drive<M::Space>>(model: M, drive: Dr, seed: u64, spatial: bool) -> f64
where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space> + SystemAlloc<Dyn>,
{
    let mut rng = rng(seed);
    let sigma = random_vector(&mut rng, &model, -5.0..5.0);
    let n = model.chain().links();
    let system = Accounted::new(model, drive, ConstantTorque(sigma));
    let mut worst: f64 = 0.0;
    for _ in 0..30 {
        let mut q = random_vector(&mut rng, system.model(), -3.0..3.0);
        if spatial {
            q.iter_mut().take(n).for_each(|t| *t = rng.random_range(0.3..2.8));
        }
        let qd = random_vector(&mut rng, system.model(), -3.0..3.0);
        let t = rng.random_range(0.0..10.0);
        let x = system.state(&q, &qd);
        let mut f = x.clone();
        pendulum_core::integrate::System::rhs(&system, t, &x, &mut f).unwrap();
        // Central differences with Richardson extrapolation: error O(eps⁴) + round-off.
        let h = |s: f64| system.energy(t + s, &(&x + &f * s));
        let central = |eps: f64| (h(eps) - h(-eps)) / (2.0 * eps);
        let eps = 1e-4;
        let rate = (4.0 * central(eps / 2.0) - central(eps)) / 3.0;
        let p = system.powers(t, &x).unwrap();
        assert!(p.damping >= 0.0, "damping power {p:?} must not be negative");
        let scale = p.drive.abs() + p.torque.abs() + p.damping + system.energy(t, &x).abs() + 1.0;
        worst = worst.max((rate - p.net()).abs() / scale);
    }
    worst
}

// Measured worst ~6e-11 (round-off ε·H/eps of the differences); a wrong or missing
// term is an O(1) mismatch.
const BOUND: f64 = 1e-9;

#[test]
fn drive_power_is_the_rate_of_the_inertial_energy() {
    for n in 1..=4 {
        let model = Planar::new(random_chain::<Dyn>(&mut rng(n), n as usize, true));
        let drive = Harmonic::new(Vector2::new(0.4, 1.0), 0.1, 7.0, 0.3).unwrap();
        let worst = worst_power_mismatch(model, drive, 10 + n, false);
        assert!(worst < BOUND, "planar n={n}: {worst:e}");

        let model = Spatial::new(random_chain::<Dyn>(&mut rng(n), n as usize, true));
        let worst = worst_power_mismatch(model, Circle::new(0.2, -5.0).unwrap(), 20 + n, true);
        assert!(worst < BOUND, "spatial circle n={n}: {worst:e}");

        let model = Spatial::new(random_chain::<Dyn>(&mut rng(n), n as usize, true));
        let drive = Harmonic::new(Vector3::new(1.0, -2.0, 0.5), 0.1, 9.0, -1.0).unwrap();
        let worst = worst_power_mismatch(model, drive, 30 + n, true);
        assert!(worst < BOUND, "spatial harmonic n={n}: {worst:e}");
    }
    // Generated fixed-size models, through the same generic accounting.
    let chain = || random_chain(&mut rng(5), 3, true);
    let worst = worst_power_mismatch(Planar3::new(chain()), Circle2D, 40, false);
    assert!(worst < BOUND, "generated planar: {worst:e}");
    let worst = worst_power_mismatch(
        Spatial2::new(random_chain(&mut rng(6), 2, true)),
        Circle::new(0.3, 4.0).unwrap(),
        41,
        true,
    );
    assert!(worst < BOUND, "generated spatial: {worst:e}");
}

/// A user-defined drive: the pivot on a vertical circle, planar.
struct Circle2D;

impl Drive<U2> for Circle2D {
    fn position(&self, t: f64) -> Vector2<f64> {
        Vector2::new((3.0 * t).cos(), (3.0 * t).sin()) * 0.2
    }
    fn velocity(&self, t: f64) -> Vector2<f64> {
        Vector2::new(-(3.0 * t).sin(), (3.0 * t).cos()) * 0.6
    }
    fn acceleration(&self, t: f64) -> Vector2<f64> {
        Vector2::new((3.0 * t).cos(), (3.0 * t).sin()) * -1.8
    }
}

/// Runs `system` from `(q, q̇)` over `[0, t1]` with Gauss–Legendre s = 3 and step `h`,
/// checking the balance at every sample; returns the worst relative closure and the
/// final balance.
fn closure<M: Model, Dr: Drive<M::Space>, T: TorqueAt<M::Dof>>(
    system: &Accounted<FirstOrder<M, Driven<Dr, T>>>,
    q: &[f64],
    qd: &[f64],
    t1: f64,
    h: f64,
) -> (f64, pendulum_core::Balance)
where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space> + SystemAlloc<Dyn>,
{
    let dof = system.model().dof();
    let vector = |v: &[f64]| OVector::<f64, M::Dof>::from_row_slice_generic(dof, U1, v);
    let x0 = system.state(&vector(q), &vector(qd));
    let mut solver = GaussLegendre::<Dyn, U3>::new(system, GaussOptions::default());
    let mut state = State::new(0.0, x0.clone());
    let mut worst: f64 = 0.0;
    trajectory::run(&mut solver, system, &mut state, t1, h, 50, |t, x| {
        worst = worst.max(system.balance(0.0, &x0, t, x).relative);
        ControlFlow::Continue(())
    })
    .unwrap();
    (worst, system.balance(0.0, &x0, state.t(), state.x()))
}

#[test]
fn planar_balance_closes_with_drive_torque_and_damping() {
    let chain = Chain::<Dyn>::new(&[1.0, 0.6, 0.8], &[0.5, 0.4, 0.3], 9.81).unwrap();
    let model = Planar::new(chain.with_damping(&[0.05, 0.08, 0.03]).unwrap());
    let drive = Harmonic::new(Vector2::new(0.5, 1.0), 0.05, 9.0, 0.2).unwrap();
    let torque = |t: f64| DVector::from_vec(vec![0.4 * (2.0 * t).sin(), -0.1, 0.2 * (1.0 + t).cos()]);
    let system = Accounted::new(model, drive, torque);
    let (worst, end) = closure(&system, &[1.0, -0.5, 2.0], &[0.0, 1.0, -1.0], 3.0, 2e-3);
    println!("planar n=3: worst relative closure {worst:e}, final {end:?}");
    // Every ledger term matters here.
    assert!(
        end.ledger.drive.abs() > 0.1 && end.ledger.torque.abs() > 0.01 && end.ledger.damped > 0.1,
        "{end:?}"
    );
    assert!(worst < 1e-8, "relative closure {worst:e}");
}

#[test]
fn spatial_balance_closes_on_a_circling_pivot() {
    let chain = Chain::<Dyn>::new(&[1.0, 0.7], &[0.5, 0.4], 9.81).unwrap();
    let model = Spatial::new(chain.with_damping(&[0.05, 0.1]).unwrap());
    let sigma = ConstantTorque(DVector::from_vec(vec![0.0, 0.1, 0.2, -0.1]));
    let system = Accounted::new(model, Circle::new(0.1, 5.0).unwrap(), sigma);
    let (worst, end) = closure(&system, &[1.0, 1.4, 0.0, 0.5], &[0.0, 0.5, 3.0, 2.0], 2.0, 2e-3);
    println!("spatial n=2: worst relative closure {worst:e}, final {end:?}");
    assert!(end.ledger.drive.abs() > 0.1 && end.ledger.damped > 0.1, "{end:?}");
    assert!(worst < 1e-8, "relative closure {worst:e}");
}

#[test]
fn a_user_drive_from_closures_balances_too() {
    // p(t) = (0, 0.05 t² e^{−t}) planar, a single damped pendulum with constant torque.
    let p = |t: f64| Vector2::new(0.0, 0.05 * t * t * (-t).exp());
    let v = |t: f64| Vector2::new(0.0, 0.05 * (2.0 * t - t * t) * (-t).exp());
    let a = |t: f64| Vector2::new(0.0, 0.05 * (2.0 - 4.0 * t + t * t) * (-t).exp());
    let model = Planar::new(Chain::<Dyn>::new(&[2.0], &[0.7], 9.81).unwrap().with_damping(&[0.3]).unwrap());
    let system = Accounted::new(model, FnDrive::new(p, v, a), ConstantTorque(DVector::from_vec(vec![0.5])));
    let (worst, end) = closure(&system, &[2.0], &[0.0], 2.0, 2e-3);
    assert!(end.ledger.drive.abs() > 1e-3, "{end:?}");
    assert!(worst < 1e-8, "relative closure {worst:e}");
}

#[test]
fn a_pivot_on_sampled_positions_balances_too() {
    // A Lissajous path sampled every 50 ms, a whole number of the run's steps: the spline's
    // kinks in p̈ fall between steps.
    let path = |t: f64| Vector3::new(0.1 * (3.0 * t).sin(), 0.05 * (5.0 * t).cos(), 0.03 * (4.0 * t).sin());
    let times: Vec<f64> = (0..=50).map(|k| k as f64 * 0.05).collect();
    let drive = Sampled::new(times.clone(), times.iter().map(|&t| path(t)).collect()).unwrap();
    let chain = Chain::<Dyn>::new(&[1.0, 0.7], &[0.5, 0.4], 9.81).unwrap();
    let model = Spatial::new(chain.with_damping(&[0.05, 0.1]).unwrap());
    let system = Accounted::new(model, drive, ConstantTorque(DVector::zeros(4)));
    let (worst, end) = closure(&system, &[1.0, 1.4, 0.0, 0.5], &[0.0, 0.5, 3.0, 2.0], 2.0, 2e-3);
    println!("sampled path: worst relative closure {worst:e}, final {end:?}");
    assert!(end.ledger.drive.abs() > 1e-3 && end.ledger.damped > 0.1, "{end:?}");
    assert!(worst < 1e-8, "relative closure {worst:e}");
}
