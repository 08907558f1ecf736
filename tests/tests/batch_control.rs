//! A controller stepping many chains at once: an LQR designed on the linearised inverted
//! triple pendulum holds 256 perturbed copies upright, applied every 10 ms as torques held
//! over the step (`PlanarBatch::integrate_rk4`). Physics: the copies fall without it, and
//! with it they approach upright at the slowest closed-loop rate the linearisation
//! predicts; every copy is what the chain alone would do under the same control, bit for
//! bit. The same controller holds a batch of the generated model (`model!`,
//! `UnrolledBatch::integrate_rk4` and `integrate_rk4_f32`) upright at the same rate; and a
//! batch of copies whose masses and lengths differ (±10%) each decays at the rate of its
//! own loop, linearised and sampled (`pendulum_tests::control::sampled_loop`).

use std::f64::consts::PI;

use nalgebra::{Const, DMatrix, DVector, Dyn, SVector};
use pendulum_core::batch::{PlanarBatch, UnrolledBatch};
use pendulum_core::integrate::{Integrator, Rk4, State};
use pendulum_core::{Chain, FirstOrder, Inputs, Model, PlanarTension, STEADY_TOLERANCE, linearize, lqr};
use pendulum_tests::control;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const N: usize = 3;
const COPIES: usize = 256;
/// The control period (s) and the RK4 steps in it.
const PERIOD: f64 = 0.01;
const STEPS: usize = 10;

pendulum_macros::model! { struct Triple { kind: planar, links: 3, algorithm: tension } }

fn chain<D: nalgebra::Dim>() -> Chain<D>
where
    nalgebra::DefaultAllocator: nalgebra::allocator::Allocator<D>,
{
    Chain::new(&[0.5, 0.4, 0.3], &[0.4, 0.35, 0.3], 9.81)
        .and_then(|c| c.with_damping(&[1e-3; N]))
        .expect("chain")
}

/// The LQR on the chain linearised upright, and its slowest closed-loop rate (1/s).
fn design() -> (DMatrix<f64>, f64) {
    let model = PlanarTension::new(chain::<Dyn>());
    let up = DVector::from_element(N, PI);
    let linear =
        linearize(&model, &up, &DVector::zeros(N), &model.zero_inputs(), STEADY_TOLERANCE).expect("linear");
    assert!(linear.growth_rate() > 1.0, "upright is unstable: {}", linear.growth_rate());
    let design = lqr(&linear.a, &linear.b_torque, &DMatrix::identity(2 * N, 2 * N), &DMatrix::identity(N, N))
        .expect("lqr");
    let slowest = design.closed_loop[0].re;
    assert!(slowest < 0.0, "the closed loop is stable: {slowest}");
    (design.gain, slowest)
}

/// `COPIES` states within 0.05 rad of upright, rates within 0.1 rad/s, as rows of `2N`.
fn starts() -> Vec<f64> {
    let mut r = ChaCha8Rng::seed_from_u64(3);
    (0..COPIES * 2 * N)
        .map(|i| if i % (2 * N) < N { PI + r.random_range(-0.05..0.05) } else { r.random_range(-0.1..0.1) })
        .collect()
}

/// The worst copy's distance from upright after 4 and 6 s of control by `gain` every
/// 10 ms from `rows`, `period(rows, torque)` running a period with the torques held.
fn controlled(
    gain: &DMatrix<f64>,
    rows: Vec<f64>,
    mut period: impl FnMut(&mut Vec<f64>, &[f64]),
) -> [f64; 2] {
    let distances = control::controlled(gain, (rows, N), 600, |rows, torque| {
        period(rows, torque);
        Ok(())
    })
    .expect("control");
    [400, 600].map(|i| distances[i].iter().copied().fold(0.0, f64::max))
}

/// Distance of a state `x = (θ, θ̇)` from upright at rest (θ = π).
fn from_upright(x: &[f64]) -> f64 {
    control::from_upright(x, N)
}

#[test]
fn an_lqr_holds_a_batch_of_inverted_triple_pendulums_upright_at_the_predicted_rate() {
    let (gain, slowest) = design();
    let rows = starts();
    let start: Vec<State<Dyn>> =
        rows.chunks(2 * N).map(|x| State::new(0.0, DVector::from_column_slice(x))).collect();
    let batch = PlanarBatch::repeated(chain(), COPIES).expect("batch");
    let h = PERIOD / STEPS as f64;

    // Without control they fall.
    let mut falling = start.clone();
    assert!(batch.integrate_rk4(&mut falling, None, None, h, 200 * STEPS).expect("run").is_empty());
    let fallen = falling.iter().filter(|s| from_upright(s.x().as_slice()) > 1.0).count();
    assert!(fallen > COPIES * 9 / 10, "{fallen} of {COPIES} fell in 2 s");

    // With it, 6 s in periods of 10 ms; one copy alone alongside, under its own control.
    let mut states = start.clone();
    let mut alone = start[17].clone();
    let rows_of =
        |states: &[State<Dyn>]| states.iter().flat_map(|s| s.x().iter().copied()).collect::<Vec<_>>();
    let [at4, at6] = controlled(&gain, rows.clone(), |rows, torque| {
        let failures = batch.integrate_rk4(&mut states, Some(torque), None, h, STEPS).expect("run");
        assert!(failures.is_empty(), "{failures:?}");
        let mut inputs = Inputs::<Dyn, nalgebra::U2>::zeros(Dyn(N));
        inputs.torque.copy_from_slice(&control::torques_of(&gain, alone.x().as_slice(), N));
        let system = FirstOrder::with_inputs(PlanarTension::new(chain()), inputs);
        let mut rk4 = Rk4::new(&system);
        for _ in 0..STEPS {
            rk4.step(&system, &mut alone, h).expect("alone");
        }
        *rows = rows_of(&states);
    });
    for (a, b) in alone.x().iter().zip(states[17].x().iter()) {
        assert_eq!(a.to_bits(), b.to_bits(), "copy 17 is the chain alone under the same control");
    }
    // Upright, and approaching it at the slowest closed-loop rate: over the last two
    // seconds the worst copy's distance shrinks by e^{σ·2 s}, σ the slowest eigenvalue's
    // real part, within the sampling's and the transients' percent or two.
    let worst = rows.chunks(2 * N).map(from_upright).fold(0.0, f64::max);
    assert!(at6 < 1e-3 * worst, "worst copy after 6 s: {at6:e}, at the start {worst:e}");
    let rate = (at6 / at4).ln() / 2.0;
    println!(
        "fell: {fallen} of {COPIES}; worst {worst:.2e}, after 4 s {at4:.2e}, 6 s {at6:.2e}; rate {rate:.4} 1/s, predicted {slowest:.4} 1/s"
    );
    assert!((rate - slowest).abs() < 0.02 * slowest.abs(), "decay rate {rate} 1/s, predicted {slowest} 1/s");
}

#[test]
fn the_same_lqr_holds_a_batch_of_the_generated_model_upright_in_f64_and_in_f32() {
    let (gain, slowest) = design();
    let start = starts();
    let worst = start.chunks(2 * N).map(from_upright).fold(0.0, f64::max);
    let batch = UnrolledBatch::new(vec![Triple::new(chain::<Const<N>>()); COPIES]).expect("batch");
    let h = PERIOD / STEPS as f64;
    let f64_run = controlled(&gain, start.clone(), |rows, torque| {
        let mut states: Vec<State<Const<6>>> =
            rows.chunks(2 * N).map(|x| State::new(0.0, SVector::<f64, 6>::from_column_slice(x))).collect();
        assert!(batch.integrate_rk4(&mut states, Some(torque), None, h, STEPS).expect("run").is_empty());
        *rows = states.iter().flat_map(|s| s.x().iter().copied()).collect();
    });
    let mut carry = vec![0.0f32; start.len()];
    let f32_run = controlled(&gain, start, |rows, torque| {
        let mut x: Vec<f32> = rows.iter().map(|&x| x as f32).collect();
        let torque: Vec<f32> = torque.iter().map(|&t| t as f32).collect();
        let failures =
            batch.integrate_rk4_f32((&mut x, &mut carry), Some(&torque), None, h, STEPS).expect("run");
        assert!(failures.is_empty());
        *rows = x.iter().map(|&x| f64::from(x)).collect();
    });
    for (what, [at4, at6]) in [("f64", f64_run), ("f32", f32_run)] {
        let rate = (at6 / at4).ln() / 2.0;
        println!(
            "{what}: worst {worst:.2e}, after 4 s {at4:.2e}, 6 s {at6:.2e}; rate {rate:.4} 1/s, predicted {slowest:.4} 1/s"
        );
        assert!(at6 < 1e-3 * worst, "{what}: worst copy after 6 s: {at6:e}, at the start {worst:e}");
        assert!(
            (rate - slowest).abs() < 0.02 * slowest.abs(),
            "{what}: decay rate {rate} 1/s, predicted {slowest} 1/s"
        );
    }
}

/// The chain with its masses and lengths scaled by `scale` (the masses', then the lengths').
fn scaled<D: nalgebra::Dim>(scale: &[f64; 2 * N]) -> Chain<D>
where
    nalgebra::DefaultAllocator: nalgebra::allocator::Allocator<D>,
{
    let nominal = chain::<Dyn>();
    let masses: Vec<f64> = (0..N).map(|i| nominal.masses()[i] * scale[i]).collect();
    let lengths: Vec<f64> = (0..N).map(|i| nominal.lengths()[i] * scale[N + i]).collect();
    Chain::new(&masses, &lengths, 9.81).and_then(|c| c.with_damping(&[1e-3; N])).expect("chain")
}

#[test]
fn each_copy_of_a_batch_of_differing_plants_decays_as_its_own_sampled_linear_loop_predicts() {
    // The nominal gain on copies whose masses and lengths are each within ±10% of nominal:
    // every copy's distance from upright over 4–6 s shrinks at the rate of its own loop
    // linearised and sampled (the torques held over each period), from its own start.
    let (gain, _) = design();
    let mut r = ChaCha8Rng::seed_from_u64(11);
    let scales: Vec<[f64; 2 * N]> =
        (0..COPIES).map(|_| std::array::from_fn(|_| r.random_range(0.9..1.1))).collect();
    let start = starts();
    let batch = UnrolledBatch::new(scales.iter().map(|s| Triple::new(scaled(s))).collect()).expect("batch");
    let h = PERIOD / STEPS as f64;
    let mut states: Vec<State<Const<{ 2 * N }>>> =
        start.chunks(2 * N).map(|x| State::new(0.0, SVector::from_column_slice(x))).collect();
    let run = control::controlled(&gain, (start.clone(), N), 600, |rows, torque| {
        assert!(batch.integrate_rk4(&mut states, Some(torque), None, h, STEPS)?.is_empty());
        *rows = states.iter().flat_map(|s| s.x().iter().copied()).collect();
        Ok(())
    })
    .expect("run");
    let mut off: Vec<f64> = scales
        .iter()
        .zip(start.chunks(2 * N))
        .enumerate()
        .map(|(k, (scale, x))| {
            let model = PlanarTension::new(scaled::<Dyn>(scale));
            let up = DVector::from_element(N, PI);
            let linear = linearize(&model, &up, &DVector::zeros(N), &model.zero_inputs(), STEADY_TOLERANCE)
                .expect("linear");
            let map = control::sampled_loop(&linear.a, &linear.b_torque, &gain, PERIOD);
            let (at4, at6) = (map.pow(400) * control::from_up(x, N), map.pow(600) * control::from_up(x, N));
            let theory = (at6.norm() / at4.norm()).ln() / 2.0;
            let measured = (run[600][k] / run[400][k]).ln() / 2.0;
            assert!(theory < -1.0, "copy {k}: the sampled loop decays at {theory} 1/s");
            (measured / theory - 1.0).abs()
        })
        .collect();
    off.sort_by(f64::total_cmp);
    let (median, worst) = (off[COPIES / 2], off[COPIES - 1]);
    println!("rates against each copy's sampled linear loop: median {median:.1e}, worst {worst:.1e} off");
    assert!(median < 1e-5 && worst < 0.02, "median {median:e}, worst {worst:e}");
}
