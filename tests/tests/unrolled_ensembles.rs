//! `model!`'s planar models in lanes (`pendulum_core::batch::UnrolledBatch`): every chain of
//! a batch gets exactly its generated model's `θ̈`, whatever the thread count and however
//! the chains are split into calls, the chains whose tension continuants leave their range
//! included, and a failing chain is reported by its index while the others finish.

use nalgebra::{Const, SVector, U2, Vector2};
use pendulum_core::batch::{PlanarKernel, UnrolledBatch};
use pendulum_core::integrate::State;
use pendulum_core::{Chain, ConstantTorque, Driven, Error, Harmonic, Inputs};
use pendulum_tests::batches::{self, assert_bits, assert_rows, check_runs, pools};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

pendulum_macros::model! {
    struct Planar2 { kind: planar, links: 2, algorithm: tension }
    struct Planar4 { kind: planar, links: 4 }
    struct Planar5 { kind: planar, links: 5 }
    struct Planar8 { kind: planar, links: 8 }
    struct Planar16 { kind: planar, links: 16 }
}

/// `N` links with masses, lengths and damping log-uniform over two decades, gravity
/// between 1 and 20 m/s².
fn random_chain<const N: usize>(r: &mut ChaCha8Rng) -> Chain<Const<N>> {
    let mut decades = |lo: f64| (0..N).map(|_| 10f64.powf(lo + 2.0 * r.random::<f64>())).collect::<Vec<_>>();
    let (masses, lengths, damping) = (decades(-2.0), decades(-2.0), decades(-5.0));
    let g = r.random_range(1.0..20.0);
    Chain::new(&masses, &lengths, g).and_then(|c| c.with_damping(&damping)).expect("chain")
}

/// Random states of `chains` chains: angles over several turns (one in 17 beyond the sine
/// kernel's range), rates, torques and pivot accelerations, as `(B, N)` and `(B, 2)` rows.
fn random_inputs(chains: usize, n: usize, r: &mut ChaCha8Rng) -> [Vec<f64>; 4] {
    let q = (0..chains * n)
        .map(|i| if i % 17 == 5 { r.random_range(-1e5..1e5) } else { r.random_range(-20.0..20.0) })
        .collect();
    let mut uniform =
        |len: usize, span: f64| (0..len).map(|_| r.random_range(-span..span)).collect::<Vec<_>>();
    [q, uniform(chains * n, 10.0), uniform(chains * n, 1e-3), uniform(chains * 2, 30.0)]
}

/// Each chain's generated model alone: its `θ̈` rows, or its error.
fn each_alone<M: PlanarKernel<N>, const N: usize>(
    models: &[M],
    [q, qd, torque, pivot]: &[Vec<f64>; 4],
) -> Vec<Result<Vec<f64>, Error>> {
    let row = |v: &[f64], k: usize| SVector::<f64, N>::from_column_slice(&v[k * N..(k + 1) * N]);
    models
        .iter()
        .enumerate()
        .map(|(k, model)| {
            let inputs = Inputs {
                torque: row(torque, k),
                pivot_acceleration: Vector2::new(pivot[2 * k], pivot[2 * k + 1]),
            };
            let mut out = SVector::zeros();
            model.accelerations(&row(q, k), &row(qd, k), &inputs, &mut out).map(|()| out.as_slice().to_vec())
        })
        .collect()
}

/// The batch of `models` at `inputs`, with 1 and 2 threads and split in two calls, equals
/// each model alone bit for bit, and fails exactly where they fail, with their errors.
fn check<M: PlanarKernel<N> + Clone, const N: usize>(models: Vec<M>, inputs: &[Vec<f64>; 4]) {
    let chains = models.len();
    let single = each_alone(&models, inputs);
    let [q, qd, torque, pivot] = inputs;
    let run = |batch: &UnrolledBatch<M, N>, rows: std::ops::Range<usize>, out: &mut [f64]| {
        let (a, b) = (rows.start * N, rows.end * N);
        batch
            .accelerations(
                &q[a..b],
                &qd[a..b],
                Some(&torque[a..b]),
                Some(&pivot[2 * rows.start..2 * rows.end]),
                out,
            )
            .expect("batch")
    };
    let batch = UnrolledBatch::new(models.clone()).expect("batch");
    // Both kernels where the CPU has AVX-512 (eight lanes a register, and four).
    let four = batch.clone().with_avx512(false);
    for (pool, batch) in pools().iter().flat_map(|pool| [(pool, &batch), (pool, &four)]) {
        let mut out = vec![0.0; chains * N];
        let failures = pool.install(|| run(batch, 0..chains, &mut out));
        let what = format!(
            "{chains} chains of {N}, {} threads, AVX-512 {}",
            pool.current_num_threads(),
            batch.uses_avx512()
        );
        assert_rows(&out, N, &single, &failures, &what);
    }
    // Split into two calls off a block boundary: the same numbers.
    let cut = chains / 2 + 1;
    if cut < chains {
        let mut whole = vec![0.0; chains * N];
        run(&batch, 0..chains, &mut whole);
        let mut out = vec![0.0; chains * N];
        let (low, high) = out.split_at_mut(cut * N);
        run(&UnrolledBatch::new(models[..cut].to_vec()).expect("batch"), 0..cut, low);
        let (a, b) = (cut * N, chains * N);
        UnrolledBatch::new(models[cut..].to_vec())
            .expect("batch")
            .accelerations(&q[a..b], &qd[a..b], Some(&torque[a..b]), Some(&pivot[2 * cut..]), high)
            .expect("batch");
        assert_bits(&out, &whole, &format!("{chains} chains of {N} split at {cut}"));
    }
}

fn random_models<M: From<Chain<Const<N>>>, const N: usize>(chains: usize, r: &mut ChaCha8Rng) -> Vec<M> {
    (0..chains).map(|_| M::from(random_chain::<N>(r))).collect()
}

#[test]
fn each_chain_of_a_batch_is_its_generated_model_bit_for_bit() {
    let mut r = ChaCha8Rng::seed_from_u64(47);
    for chains in [1, 3, 9, 64] {
        let inputs = random_inputs(chains, 2, &mut r);
        check::<Planar2, 2>(random_models(chains, &mut r), &inputs);
        let inputs = random_inputs(chains, 4, &mut r);
        check::<Planar4, 4>(random_models(chains, &mut r), &inputs);
        let inputs = random_inputs(chains, 5, &mut r);
        check::<Planar5, 5>(random_models(chains, &mut r), &inputs);
        let inputs = random_inputs(chains, 8, &mut r);
        check::<Planar8, 8>(random_models(chains, &mut r), &inputs);
        let inputs = random_inputs(chains, 16, &mut r);
        check::<Planar16, 16>(random_models(chains, &mut r), &inputs);
    }
}

#[test]
fn a_chain_whose_continuants_leave_their_range_falls_back_in_its_lane_alone() {
    // Masses of 1e-250 kg make the tension system's diagonal ~1e250 and its continuants
    // overflow 2⁸⁰⁰: that chain takes the classical pivots, its neighbours in the block do
    // not.
    let mut r = ChaCha8Rng::seed_from_u64(5);
    let mut models: Vec<Planar8> = random_models(7, &mut r);
    let tiny = Chain::new(&[1e-250; 8], &[0.1; 8], 9.81).expect("chain");
    models[1] = Planar8::new(tiny.clone());
    models[6] = Planar8::new(tiny);
    let inputs = random_inputs(7, 8, &mut r);
    let single = each_alone(&models, &inputs);
    assert!(single.iter().all(Result::is_ok), "{single:?}");
    check::<Planar8, 8>(models, &inputs);
}

#[test]
fn a_failing_chain_is_named_with_its_models_error_and_the_others_finish() {
    let mut r = ChaCha8Rng::seed_from_u64(9);
    let models: Vec<Planar4> = random_models(10, &mut r);
    let mut inputs = random_inputs(10, 4, &mut r);
    inputs[0][4 * 2 + 1] = f64::NAN; // chain 2: q[1]
    inputs[1][4 * 7 + 3] = f64::INFINITY; // chain 7: qd[3]
    let single = each_alone(&models, &inputs);
    assert!(matches!(single[2], Err(Error::NonFinite { index: 1, .. })), "{:?}", single[2]);
    assert!(single[7].is_err() && single.iter().filter(|s| s.is_err()).count() == 2);
    check::<Planar4, 4>(models, &inputs);
}

#[test]
fn bad_batches_and_arrays_are_one_line_errors() {
    assert_eq!(UnrolledBatch::<Planar4, 4>::new(Vec::new()).unwrap_err(), Error::EmptyBatch);
    let mut r = ChaCha8Rng::seed_from_u64(1);
    let batch = UnrolledBatch::new(random_models::<Planar4, 4>(3, &mut r)).expect("batch");
    let mut out = vec![0.0; 12];
    let error = batch.accelerations(&[0.0; 11], &[0.0; 12], None, None, &mut out).unwrap_err();
    assert_eq!(error.to_string(), "q has 11 entries, expected 12");
    let error = batch.accelerations(&[0.0; 12], &[0.0; 12], None, Some(&[0.0; 5]), &mut out).unwrap_err();
    assert_eq!(error.to_string(), "pivot has 5 entries, expected 6");
}

/// Each chain's state after `steps` steps of `Rk4` on `FirstOrder::new(model)`, alone, or
/// its error (the state left where it failed).
fn stepped_alone<M: PlanarKernel<N> + Clone, const N: usize, const D: usize>(
    models: &[M],
    states: &[State<Const<D>>],
    h: f64,
    steps: usize,
) -> Vec<(State<Const<D>>, Option<Error>)>
where
    Const<N>: nalgebra::DimMul<U2, Output = Const<D>>,
{
    batches::stepped_alone(models, states, |k| models[k].zero_inputs(), h, steps)
}

/// `chains` random states `(θ, θ̇)` at random times.
fn random_states<const D: usize>(chains: usize, r: &mut ChaCha8Rng) -> Vec<State<Const<D>>> {
    (0..chains)
        .map(|_| {
            let x = SVector::<f64, D>::from_fn(|i, _| {
                if i < D / 2 { r.random_range(-3.0..3.0) } else { r.random_range(-5.0..5.0) }
            });
            State::new(r.random_range(0.0..10.0), x)
        })
        .collect()
}

/// The batch's RK4 runs equal each chain's alone in time, state and compensation: with 1
/// and 2 threads, and in two calls of half the steps each; in eight lanes a register and in
/// four (`with_avx512(false)`).
fn check_rk4<M, const N: usize, const D: usize>(
    models: Vec<M>,
    states: Vec<State<Const<D>>>,
    h: f64,
    steps: usize,
) where
    M: PlanarKernel<N> + Clone,
    Const<N>: nalgebra::DimMul<U2, Output = Const<D>>,
{
    let alone = stepped_alone::<M, N, D>(&models, &states, h, steps);
    let eight = UnrolledBatch::new(models).expect("batch");
    let four = eight.clone().with_avx512(false);
    for batch in [&eight, &four] {
        let run = |states: &mut [State<Const<D>>], steps| batch.integrate_rk4(states, None, None, h, steps);
        check_runs(&run, &states, &alone, steps, &format!("N = {N}, AVX-512 {}", batch.uses_avx512()));
    }
}

#[test]
fn rk4_runs_of_a_batch_equal_each_chain_stepped_alone_bit_for_bit() {
    let mut r = ChaCha8Rng::seed_from_u64(61);
    // 37 chains: ten blocks of four, in groups of four blocks (the last one short), each
    // group a task of its own on two threads; 9 chains: three blocks, the last alone in its
    // pair of blocks with AVX-512.
    for chains in [1, 6, 9, 13, 37] {
        let states = random_states::<8>(chains, &mut r);
        check_rk4::<Planar4, 4, 8>(random_models(chains, &mut r), states, 1e-3, 20);
        let states = random_states::<16>(chains, &mut r);
        check_rk4::<Planar8, 8, 16>(random_models(chains, &mut r), states, 3e-4, 20);
    }
}

#[test]
fn a_chain_that_fails_in_a_run_stops_where_it_failed_with_its_own_error() {
    let mut r = ChaCha8Rng::seed_from_u64(3);
    let models: Vec<Planar4> = random_models(7, &mut r);
    let mut states = random_states::<8>(7, &mut r);
    // Chain 2 starts with a NaN angle; chain 5 spins so fast that θ̇² overflows on the way.
    let mut x = *states[2].x();
    x[1] = f64::NAN;
    states[2] = State::new(states[2].t(), x);
    let mut x = *states[5].x();
    x[4 + 3] = 1e153;
    states[5] = State::new(states[5].t(), x);
    let alone = stepped_alone::<Planar4, 4, 8>(&models, &states, 1e-3, 10);
    assert!(matches!(alone[2].1, Some(Error::NonFinite { .. })), "{:?}", alone[2].1);
    assert!(alone[5].1.is_some() && alone.iter().filter(|a| a.1.is_some()).count() == 2, "{alone:?}");
    check_rk4::<Planar4, 4, 8>(models, states, 1e-3, 10);
    let batch = UnrolledBatch::new(random_models::<Planar4, 4>(2, &mut r)).expect("batch");
    let mut two = random_states::<8>(2, &mut r);
    assert_eq!(
        batch.integrate_rk4(&mut two, None, None, 0.0, 1).unwrap_err(),
        Error::InvalidStepSize { h: 0.0 }
    );
    assert_eq!(
        batch.integrate_rk4(&mut two[..1], None, None, 1e-3, 1).unwrap_err().to_string(),
        "states has 1 entries, expected 2"
    );
    let messages = [
        batch.integrate_rk4(&mut two, Some(&[0.0; 7]), None, 1e-3, 1),
        batch.integrate_rk4(&mut two, None, Some(&[0.0; 3]), 1e-3, 1),
        batch.integrate_rk4_driven(
            &mut two,
            &[Harmonic::vertical(0.1, 1.0, 0.0).expect("drive")],
            None,
            1e-3,
            1,
        ),
    ]
    .map(|run| run.unwrap_err().to_string());
    assert_eq!(
        messages,
        [
            "torque has 7 entries, expected 8",
            "pivot has 3 entries, expected 4",
            "drives has 1 entries, expected 2"
        ]
    );
}

/// Random joint torques (`B` rows of `N`) and pivot drives: vertical and sideways
/// oscillations of random amplitude, frequency and phase.
fn random_drives(chains: usize, n: usize, r: &mut ChaCha8Rng) -> (Vec<f64>, Vec<Harmonic<U2>>) {
    let torque = (0..chains * n).map(|_| r.random_range(-1e-3..1e-3)).collect();
    let drives = (0..chains)
        .map(|_| {
            let direction = Vector2::new(r.random_range(-1.0..1.0), 1.0);
            let (a, w, phase) =
                (r.random_range(0.0..0.02), r.random_range(1.0..200.0), r.random_range(0.0..6.0));
            Harmonic::new(direction, a, w, phase).expect("drive")
        })
        .collect();
    (torque, drives)
}

#[test]
fn rk4_runs_with_torques_and_pivots_held_or_driven_equal_each_chain_with_its_inputs_alone() {
    let mut r = ChaCha8Rng::seed_from_u64(29);
    let h = 1e-3;
    for chains in [1, 9, 37] {
        let models: Vec<Planar4> = random_models(chains, &mut r);
        let states = random_states::<8>(chains, &mut r);
        let (torque, drives) = random_drives(chains, 4, &mut r);
        let pivot: Vec<f64> = (0..2 * chains).map(|_| r.random_range(-30.0..30.0)).collect();
        let row = |k: usize| SVector::<f64, 4>::from_column_slice(&torque[4 * k..4 * k + 4]);
        let held = |k: usize| Inputs {
            torque: row(k),
            pivot_acceleration: Vector2::new(pivot[2 * k], pivot[2 * k + 1]),
        };
        let driven = |k: usize| Driven::new(drives[k].clone(), ConstantTorque(row(k)));
        let alone_held = batches::stepped_alone(&models, &states, held, h, 30);
        let alone_driven = batches::stepped_alone(&models, &states, driven, h, 30);
        // The inputs change the runs: the held pivots are not the drives, nor no inputs.
        let unforced = stepped_alone(&models, &states, h, 30);
        for ((held, driven), unforced) in alone_held.iter().zip(&alone_driven).zip(&unforced) {
            assert!(
                held.0.x() != driven.0.x() && held.0.x() != unforced.0.x() && driven.0.x() != unforced.0.x()
            );
        }
        let eight = UnrolledBatch::new(models).expect("batch");
        for batch in [eight.clone(), eight.with_avx512(false)] {
            let run = |states: &mut [State<Const<8>>], steps| {
                batch.integrate_rk4(states, Some(&torque), Some(&pivot), h, steps)
            };
            check_runs(&run, &states, &alone_held, 30, &format!("AVX-512 {}", batch.uses_avx512()));
            let run = |states: &mut [State<Const<8>>], steps| {
                batch.integrate_rk4_driven(states, &drives, Some(&torque), h, steps)
            };
            check_runs(&run, &states, &alone_driven, 30, &format!("AVX-512 {}", batch.uses_avx512()));
        }
    }
}

#[test]
fn a_chain_whose_inputs_are_not_finite_fails_alone_with_its_models_error() {
    let mut r = ChaCha8Rng::seed_from_u64(30);
    let (chains, h) = (11, 1e-3);
    let models: Vec<Planar4> = random_models(chains, &mut r);
    let states = random_states::<8>(chains, &mut r);
    let (mut torque, mut drives) = random_drives(chains, 4, &mut r);
    let mut pivot: Vec<f64> = (0..2 * chains).map(|_| r.random_range(-30.0..30.0)).collect();
    // Chain 1: a NaN torque; chain 4: an infinite held pivot acceleration; chain 6: a drive
    // whose acceleration A ω² overflows (NaN across the vertical: ∞ · 0).
    torque[4 + 2] = f64::NAN;
    pivot[2 * 4 + 1] = f64::INFINITY;
    drives[6] = Harmonic::vertical(1e300, 1e10, 0.5).expect("drive");
    let row = |k: usize| SVector::<f64, 4>::from_column_slice(&torque[4 * k..4 * k + 4]);
    let held = |k: usize| Inputs {
        torque: row(k),
        pivot_acceleration: Vector2::new(pivot[2 * k], pivot[2 * k + 1]),
    };
    let driven = |k: usize| Driven::new(drives[k].clone(), ConstantTorque(row(k)));
    let alone_held = batches::stepped_alone(&models, &states, held, h, 12);
    let alone_driven = batches::stepped_alone(&models, &states, driven, h, 12);
    let failed = |alone: &[(State<Const<8>>, Option<Error>)]| -> Vec<(usize, &'static str, usize)> {
        let what = |e: &Error| match e {
            Error::NonFinite { what, index, .. } => (*what, *index),
            other => panic!("{other}"),
        };
        alone
            .iter()
            .enumerate()
            .filter_map(|(k, a)| a.1.as_ref().map(|e| (k, what(e).0, what(e).1)))
            .collect()
    };
    assert_eq!(failed(&alone_held), [(1, "torque", 2), (4, "pivot_acceleration", 1)]);
    assert_eq!(failed(&alone_driven), [(1, "torque", 2), (6, "pivot_acceleration", 0)]);
    let batch = UnrolledBatch::new(models).expect("batch");
    let run = |states: &mut [State<Const<8>>], steps| {
        batch.integrate_rk4(states, Some(&torque), Some(&pivot), h, steps)
    };
    check_runs(&run, &states, &alone_held, 12, &format!("AVX-512 {}", batch.uses_avx512()));
    let run = |states: &mut [State<Const<8>>], steps| {
        batch.integrate_rk4_driven(states, &drives, Some(&torque), h, steps)
    };
    check_runs(&run, &states, &alone_driven, 12, &format!("AVX-512 {}", batch.uses_avx512()));
}

/// The worst `max_i |θ̈32_i − θ̈64_i| / max_i |θ̈64_i|` over `chains` random chains and
/// states (masses, lengths and damping within a factor `spread` of 10 g, 1 cm and 3e-4
/// N·m·s), the `f32` batch against each chain's `f64` model.
fn f32_error<M: PlanarKernel<N> + From<Chain<Const<N>>>, const N: usize>(
    chains: usize,
    spread: f64,
    r: &mut ChaCha8Rng,
) -> f64 {
    let models: Vec<M> = (0..chains)
        .map(|_| {
            let mut around =
                |x: f64| (0..N).map(|_| x * r.random_range(1.0 / spread..spread)).collect::<Vec<_>>();
            let (masses, lengths, damping) = (around(0.01), around(0.01), around(3e-4));
            M::from(
                Chain::new(&masses, &lengths, 9.81).and_then(|c| c.with_damping(&damping)).expect("chain"),
            )
        })
        .collect();
    let q: Vec<f64> = (0..chains * N).map(|_| r.random_range(-3.0..3.0)).collect();
    let qd: Vec<f64> = (0..chains * N).map(|_| r.random_range(-5.0..5.0)).collect();
    let pivot: Vec<f64> = (0..chains * 2).map(|_| r.random_range(-30.0..30.0)).collect();
    let torque = vec![0.0; chains * N];
    let exact = each_alone(&models, &[q.clone(), qd.clone(), torque, pivot.clone()]);
    let to32 = |v: &[f64]| v.iter().map(|&x| x as f32).collect::<Vec<f32>>();
    let mut out = vec![0.0f32; chains * N];
    let batch = UnrolledBatch::new(models).expect("batch");
    let failures =
        batch.accelerations_f32(&to32(&q), &to32(&qd), None, Some(&to32(&pivot)), &mut out).expect("batch");
    assert!(failures.is_empty(), "{failures:?}");
    // The AVX2 kernel gives the same bits as the AVX-512 one.
    let mut avx2 = vec![0.0f32; chains * N];
    let four = batch.with_avx512(false);
    four.accelerations_f32(&to32(&q), &to32(&qd), None, Some(&to32(&pivot)), &mut avx2).expect("batch");
    assert_eq!(
        avx2.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
        out.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
    );
    exact
        .iter()
        .enumerate()
        .map(|(k, e)| {
            let e = e.as_ref().expect("f64");
            let scale = e.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            let row = &out[k * N..(k + 1) * N];
            row.iter().zip(e).fold(0.0f64, |m, (&a, &b)| m.max((f64::from(a) - b).abs())) / scale
        })
        .fold(0.0, f64::max)
}

#[test]
fn single_precision_is_within_its_documented_bound_of_the_f64_model() {
    let mut r = ChaCha8Rng::seed_from_u64(32);
    // Measured (`--nocapture`): 5.7e-6, 1.4e-6, 2.1e-6 within a factor 2; 2.0e-5, 8.4e-6,
    // 1.1e-5 within a factor 10; 4.4e-5, 1.5e-4, 6.3e-5 within a factor 100; the bounds in
    // `docs/ensembles.md` are about 3× those.
    for (spread, bound) in [(2.0, 2e-5), (10.0, 1e-4), (100.0, 5e-4)] {
        let errors = [
            f32_error::<Planar4, 4>(1000, spread, &mut r),
            f32_error::<Planar8, 8>(1000, spread, &mut r),
            f32_error::<Planar16, 16>(1000, spread, &mut r),
        ];
        println!(
            "spread {spread}: worst relative error n = 4, 8, 16: {:.1e} {:.1e} {:.1e}",
            errors[0], errors[1], errors[2]
        );
        assert!(errors.iter().all(|&e| e < bound), "within a factor {spread}: {errors:?}");
    }
}

#[test]
fn in_single_precision_a_failing_chain_is_named_and_the_others_finish() {
    let mut r = ChaCha8Rng::seed_from_u64(8);
    let models: Vec<Planar4> = random_models(11, &mut r);
    let batch = UnrolledBatch::new(models.clone()).expect("batch");
    let mut q: Vec<f32> = (0..44).map(|_| r.random_range(-3.0..3.0)).collect();
    let mut qd: Vec<f32> = (0..44).map(|_| r.random_range(-3.0..3.0)).collect();
    q[4 * 3 + 2] = f32::NAN; // chain 3: q[2]
    qd[4 * 9] = 1e20; // chain 9: θ̇² overflows f32, not f64
    let mut out = vec![0.0f32; 44];
    let failures = batch.accelerations_f32(&q, &qd, None, None, &mut out).expect("batch");
    let found: Vec<(usize, String)> = failures.iter().map(|f| (f.chain, f.error.to_string())).collect();
    assert_eq!(
        found,
        [
            (3, "q[2] must be finite, got NaN".to_owned()),
            (9, "the accelerations are not finite in single precision at this state (use f64)".to_owned())
        ]
    );
    for k in 0..11 {
        let row = &out[4 * k..4 * k + 4];
        assert_eq!(row.iter().all(|x| x.is_nan()), k == 3 || k == 9, "chain {k}: {row:?}");
    }
    let error = batch.accelerations_f32(&q[..40], &qd, None, None, &mut out).unwrap_err();
    assert_eq!(error.to_string(), "q has 40 entries, expected 44");
}

/// `chains` models of [`batches::spread_fixed_chain`]s.
fn spread_models<M: From<Chain<Const<N>>>, const N: usize>(
    chains: usize,
    spread: f64,
    r: &mut ChaCha8Rng,
) -> Vec<M> {
    (0..chains).map(|_| M::from(batches::spread_fixed_chain::<N>(spread, r))).collect()
}

/// [`batches::f32_run_error`] of 64 chains of `N` links (`spread` as
/// [`batches::spread_fixed_chain`]) swinging from angles and rates within ±1, `steps`
/// steps of 0.1 ms.
fn f32_run_error<M: PlanarKernel<N> + From<Chain<Const<N>>>, const N: usize, const D: usize>(
    spread: f64,
    steps: usize,
    r: &mut ChaCha8Rng,
) -> f64
where
    Const<N>: nalgebra::DimMul<U2, Output = Const<D>>,
{
    let (chains, h) = (64, 1e-4);
    let batch = UnrolledBatch::new(spread_models::<M, N>(chains, spread, r)).expect("batch");
    let states: Vec<State<Const<D>>> = (0..chains)
        .map(|_| State::new(0.0, SVector::<f64, D>::from_fn(|_, _| r.random_range(-1.0..1.0))))
        .collect();
    let run64 = |states: &mut [State<Const<D>>], t: Option<&[f64]>, p: Option<&[f64]>, steps: usize| {
        batch.integrate_rk4(states, t, p, h, steps)
    };
    let run32 = |x: &mut [f32], carry: &mut [f32], t: Option<&[f32]>, p: Option<&[f32]>, steps: usize| {
        batch.integrate_rk4_f32((x, carry), t, p, h, steps)
    };
    batches::f32_run_error(&run64, &run32, &states, [N, 2], steps, r)
}

#[test]
fn rk4_runs_in_single_precision_stay_near_the_f64_runs() {
    let mut r = ChaCha8Rng::seed_from_u64(32);
    for (spread, steps, bound) in [(2.0, 100, 5e-6), (10.0, 100, 5e-6), (100.0, 100, 1e-5), (2.0, 1000, 3e-4)]
    {
        let errors = [
            f32_run_error::<Planar4, 4, 8>(spread, steps, &mut r),
            f32_run_error::<Planar8, 8, 16>(spread, steps, &mut r),
        ];
        println!("spread {spread}, {steps} steps: n = 4 / 8 {:.1e} / {:.1e}", errors[0], errors[1]);
        assert!(errors.iter().all(|&e| e < bound), "spread {spread}, {steps} steps: {errors:?}");
    }
}

#[test]
fn in_single_precision_a_run_names_its_failing_chains_and_the_others_finish() {
    let mut r = ChaCha8Rng::seed_from_u64(33);
    let (chains, h) = (11, 1e-4);
    let batch = UnrolledBatch::new(spread_models::<Planar4, 4>(chains, 2.0, &mut r)).expect("batch");
    let mut x: Vec<f32> = (0..chains * 8).map(|_| r.random_range(-1.0..1.0)).collect();
    let mut torque = vec![0.0f32; chains * 4];
    let mut pivot = vec![0.0f32; chains * 2];
    x[8 * 2 + 5] = f32::NAN; // chain 2: θ̇[1]
    torque[4 * 5 + 3] = f32::INFINITY; // chain 5
    pivot[2 * 7] = f32::NAN; // chain 7
    x[8 * 9 + 4] = 1e20; // chain 9: θ̇² overflows f32
    let start = x.clone();
    let mut carry = vec![0.0f32; x.len()];
    let failures =
        batch.integrate_rk4_f32((&mut x, &mut carry), Some(&torque), Some(&pivot), h, 20).expect("run");
    let found: Vec<(usize, String)> = failures.iter().map(|f| (f.chain, f.error.to_string())).collect();
    let non_finite = Error::NonFiniteState { t: 0.0, h }.to_string();
    assert_eq!(
        found,
        [
            (2, "x[5] must be finite, got NaN".to_owned()),
            (5, "torque[3] must be finite, got inf".to_owned()),
            (7, "pivot_acceleration[0] must be finite, got NaN".to_owned()),
            (9, non_finite),
        ]
    );
    for k in 0..chains {
        let (now, then) = (&x[8 * k..8 * k + 8], &start[8 * k..8 * k + 8]);
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(now) == bits(then), [2, 5, 7, 9].contains(&k), "chain {k}");
    }
    let error = batch.integrate_rk4_f32((&mut x, &mut carry[1..]), None, None, h, 1).unwrap_err();
    assert_eq!(error.to_string(), "carry has 87 entries, expected 88");
}

#[test]
fn driven_runs_in_single_precision_stay_near_the_f64_driven_runs() {
    let mut r = ChaCha8Rng::seed_from_u64(34);
    let (chains, h, t0, steps) = (64, 1e-4, 0.37, 100);
    for spread in [2.0, 10.0] {
        let batch = UnrolledBatch::new(spread_models::<Planar8, 8>(chains, spread, &mut r)).expect("batch");
        let states: Vec<State<Const<16>>> = (0..chains)
            .map(|_| State::new(t0, SVector::<f64, 16>::from_fn(|_, _| r.random_range(-1.0..1.0))))
            .collect();
        // Each pivot shaken along its own line, by up to 1 cm at up to 400 rad/s.
        let drives: Vec<Harmonic<U2>> = (0..chains)
            .map(|_| {
                let direction = Vector2::new(r.random_range(-1.0..1.0), 1.0);
                let (a, w) = (r.random_range(0.0..0.01), r.random_range(50.0..400.0));
                Harmonic::new(direction, a, w, r.random_range(0.0..6.0)).expect("drive")
            })
            .collect();
        let run64 = |states: &mut [State<Const<16>>], steps: usize| {
            batch.integrate_rk4_driven(states, &drives, None, h, steps)
        };
        let run32 = |x: &mut [f32], carry: &mut [f32], steps: usize| {
            batch.integrate_rk4_driven_f32((x, carry), (t0, &drives), None, h, steps)
        };
        let error = batches::f32_driven_error(&run64, &run32, &states, steps);
        println!("spread {spread}, driven, {steps} steps: n = 8 {error:.1e}");
        assert!(error < 1e-4, "spread {spread}: {error:e}");
    }
    // A drive finite in f64 but not in f32 fails its chain alone, at its first step.
    let batch = UnrolledBatch::new(spread_models::<Planar4, 4>(3, 2.0, &mut r)).expect("batch");
    let mut drives = vec![Harmonic::<U2>::vertical(0.01, 100.0, 0.3).expect("drive"); 3];
    drives[1] = Harmonic::vertical(1e30, 1e10, 0.3).expect("drive");
    let (mut x, mut carry) = (vec![0.5f32; 24], vec![0.0f32; 24]);
    let failures =
        batch.integrate_rk4_driven_f32((&mut x, &mut carry), (t0, &drives), None, h, 5).expect("run");
    let found: Vec<(usize, String)> = failures.iter().map(|f| (f.chain, f.error.to_string())).collect();
    assert_eq!(found, [(1, Error::NonFiniteState { t: t0, h }.to_string())]);
    assert!(x[8..16].iter().all(|&v| v == 0.5), "chain 1 left at its start");
    let nan_t0 =
        batch.integrate_rk4_driven_f32((&mut x, &mut carry), (f64::NAN, &drives), None, h, 1).unwrap_err();
    assert_eq!(nan_t0.to_string(), "t0[0] must be finite, got NaN");
}
