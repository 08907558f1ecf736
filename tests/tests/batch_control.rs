//! A controller stepping many chains at once: an LQR designed on the linearised inverted
//! triple pendulum holds 256 perturbed copies upright, applied every 10 ms as torques held
//! over the step (`PlanarBatch::integrate_rk4`). Physics: the copies fall without it, and
//! with it they approach upright at the slowest closed-loop rate the linearisation
//! predicts; every copy is what the chain alone would do under the same control, bit for
//! bit.

use std::f64::consts::PI;

use nalgebra::{DMatrix, DVector, Dyn};
use pendulum_core::batch::PlanarBatch;
use pendulum_core::integrate::{Integrator, Rk4, State};
use pendulum_core::{Chain, FirstOrder, Inputs, Model, PlanarTension, STEADY_TOLERANCE, linearize, lqr};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const N: usize = 3;
const COPIES: usize = 256;
/// The control period (s) and the RK4 steps in it.
const PERIOD: f64 = 0.01;
const STEPS: usize = 10;

fn chain() -> Chain<Dyn> {
    Chain::new(&[0.5, 0.4, 0.3], &[0.4, 0.35, 0.3], 9.81)
        .and_then(|c| c.with_damping(&[1e-3; N]))
        .expect("chain")
}

/// Distance of a state `x = (θ, θ̇)` from upright at rest (θ = π).
fn from_upright(x: &[f64]) -> f64 {
    x.iter().enumerate().map(|(i, v)| if i < N { (v - PI).powi(2) } else { v * v }).sum::<f64>().sqrt()
}

/// `σ = −K (x − x_up)` of every state, rows of `N`.
fn torques(gain: &DMatrix<f64>, states: &[State<Dyn>]) -> Vec<f64> {
    let mut torque = Vec::with_capacity(states.len() * N);
    for s in states {
        let dx = DVector::from_fn(2 * N, |i, _| if i < N { s.x()[i] - PI } else { s.x()[i] });
        torque.extend((-gain * dx).iter());
    }
    torque
}

#[test]
fn an_lqr_holds_a_batch_of_inverted_triple_pendulums_upright_at_the_predicted_rate() {
    let model = PlanarTension::new(chain());
    let up = DVector::from_element(N, PI);
    let linear =
        linearize(&model, &up, &DVector::zeros(N), &model.zero_inputs(), STEADY_TOLERANCE).expect("linear");
    assert!(linear.growth_rate() > 1.0, "upright is unstable: {}", linear.growth_rate());
    let design = lqr(&linear.a, &linear.b_torque, &DMatrix::identity(2 * N, 2 * N), &DMatrix::identity(N, N))
        .expect("lqr");
    let slowest = design.closed_loop[0].re;
    assert!(slowest < 0.0, "the closed loop is stable: {slowest}");

    let mut r = ChaCha8Rng::seed_from_u64(3);
    let start: Vec<State<Dyn>> = (0..COPIES)
        .map(|_| {
            let x = (0..2 * N)
                .map(|i| if i < N { PI + r.random_range(-0.05..0.05) } else { r.random_range(-0.1..0.1) });
            State::new(0.0, DVector::from_iterator(2 * N, x))
        })
        .collect();
    let batch = PlanarBatch::repeated(chain(), COPIES).expect("batch");

    // Without control they fall.
    let mut falling = start.clone();
    assert!(
        batch
            .integrate_rk4(&mut falling, None, None, PERIOD / STEPS as f64, 200 * STEPS)
            .expect("run")
            .is_empty()
    );
    let fallen = falling.iter().filter(|s| from_upright(s.x().as_slice()) > 1.0).count();
    assert!(fallen > COPIES * 9 / 10, "{fallen} of {COPIES} fell in 2 s");

    // With it, 6 s in periods of 10 ms; one copy alone alongside, under its own control.
    let mut states = start.clone();
    let mut alone = start[17].clone();
    let mut norms = Vec::new();
    for _ in 0..600 {
        let torque = torques(&design.gain, &states);
        let failures =
            batch.integrate_rk4(&mut states, Some(&torque), None, PERIOD / STEPS as f64, STEPS).expect("run");
        assert!(failures.is_empty(), "{failures:?}");
        let mut inputs = Inputs::<Dyn, nalgebra::U2>::zeros(Dyn(N));
        inputs.torque.copy_from_slice(&torques(&design.gain, std::slice::from_ref(&alone)));
        let system = FirstOrder::with_inputs(PlanarTension::new(chain()), inputs);
        let mut rk4 = Rk4::new(&system);
        for _ in 0..STEPS {
            rk4.step(&system, &mut alone, PERIOD / STEPS as f64).expect("alone");
        }
        norms.push(states.iter().map(|s| from_upright(s.x().as_slice())).fold(0.0, f64::max));
    }
    for (a, b) in alone.x().iter().zip(states[17].x().iter()) {
        assert_eq!(a.to_bits(), b.to_bits(), "copy 17 is the chain alone under the same control");
    }
    // Upright, and approaching it at the slowest closed-loop rate: over the last two
    // seconds the worst copy's distance shrinks by e^{σ·2 s}, σ the slowest eigenvalue's
    // real part, within the sampling's and the transients' percent or two.
    let worst = start.iter().map(|s| from_upright(s.x().as_slice())).fold(0.0, f64::max);
    let (at4, at6) = (norms[399], norms[599]);
    assert!(at6 < 1e-3 * worst, "worst copy after 6 s: {at6:e}, at the start {worst:e}");
    let rate = (at6 / at4).ln() / 2.0;
    println!(
        "fell: {fallen} of {COPIES}; worst {worst:.2e}, after 4 s {at4:.2e}, 6 s {at6:.2e}; rate {rate:.4} 1/s, predicted {slowest:.4} 1/s"
    );
    assert!((rate - slowest).abs() < 0.02 * slowest.abs(), "decay rate {rate} 1/s, predicted {slowest} 1/s");
}
