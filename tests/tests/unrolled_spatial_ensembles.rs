//! `model!`'s spatial models in lanes (`pendulum_core::batch::UnrolledSpatialBatch`): every
//! chain of a batch gets exactly its generated model's `(θ̈, φ̈)`, whatever the thread count,
//! the lanes per register and however the chains are split into calls, the chains whose
//! tension continuants leave their range included; a chain at a pole of its chart, or with
//! a non-finite input, is reported by its index with its model's error while the others
//! finish; and RK4 runs of a batch are each chain's own `Rk4` on `FirstOrder::new(model)`,
//! bit for bit, a chain whose stage reaches a pole stopping alone where it stopped.

use nalgebra::{Const, SVector, U2, U3, Vector3};
use pendulum_core::batch::{SpatialKernel, UnrolledSpatialBatch};
use pendulum_core::integrate::State;
use pendulum_core::{Chain, Circle, ConstantTorque, Driven, Error, Inputs, Model};
use pendulum_tests::batches::{self, assert_bits, assert_rows, check_runs, pools, random_fixed_chain};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

pendulum_macros::model! {
    struct Spatial1 { kind: spatial, links: 1, algorithm: tension }
    struct Spatial2 { kind: spatial, links: 2 }
    struct Spatial3 { kind: spatial, links: 3 }
    struct Spatial4 { kind: spatial, links: 4 }
    struct Spatial8 { kind: spatial, links: 8 }
}

fn random_models<M: From<Chain<Const<N>>>, const N: usize>(chains: usize, r: &mut ChaCha8Rng) -> Vec<M> {
    (0..chains).map(|_| M::from(random_fixed_chain::<N>(r))).collect()
}

/// Random states of `chains` chains of `n` links: rows of `2n` angles (polar angles over
/// several turns, one in 17 beyond the sine kernel's range), rates and torques, and rows
/// of 3 pivot accelerations.
fn random_inputs(chains: usize, n: usize, r: &mut ChaCha8Rng) -> [Vec<f64>; 4] {
    let q = (0..chains * 2 * n)
        .map(|i| if i % 17 == 5 { r.random_range(-1e5..1e5) } else { r.random_range(-20.0..20.0) })
        .collect();
    let mut uniform =
        |len: usize, span: f64| (0..len).map(|_| r.random_range(-span..span)).collect::<Vec<_>>();
    [q, uniform(chains * 2 * n, 10.0), uniform(chains * 2 * n, 1e-3), uniform(chains * 3, 30.0)]
}

/// Each chain's generated model alone (`Model::accelerations`): its rows, or its error.
fn each_alone<M: Model<Links = Const<N>, Dof = Const<D>, Space = U3>, const N: usize, const D: usize>(
    models: &[M],
    [q, qd, torque, pivot]: &[Vec<f64>; 4],
) -> Vec<Result<Vec<f64>, Error>> {
    let row = |v: &[f64], k: usize| SVector::<f64, D>::from_column_slice(&v[k * D..(k + 1) * D]);
    models
        .iter()
        .enumerate()
        .map(|(k, model)| {
            let inputs = Inputs {
                torque: row(torque, k),
                pivot_acceleration: Vector3::new(pivot[3 * k], pivot[3 * k + 1], pivot[3 * k + 2]),
            };
            let mut out = SVector::zeros();
            model.accelerations(&row(q, k), &row(qd, k), &inputs, &mut out).map(|()| out.as_slice().to_vec())
        })
        .collect()
}

/// The batch of `models` at `inputs`, on 1 and 2 threads, in eight lanes a register and
/// four, and split in two calls, equals each model alone bit for bit, and fails exactly
/// where they fail, with their errors.
fn check<M, const N: usize, const D: usize>(models: Vec<M>, inputs: &[Vec<f64>; 4])
where
    M: SpatialKernel<N> + Model<Links = Const<N>, Dof = Const<D>, Space = U3> + Clone,
{
    assert_eq!(D, 2 * N);
    let chains = models.len();
    let single = each_alone::<M, N, D>(&models, inputs);
    let [q, qd, torque, pivot] = inputs;
    let run = |batch: &UnrolledSpatialBatch<M, N>, rows: std::ops::Range<usize>, out: &mut [f64]| {
        let (a, b) = (rows.start * D, rows.end * D);
        let pivot = &pivot[3 * rows.start..3 * rows.end];
        batch.accelerations(&q[a..b], &qd[a..b], Some(&torque[a..b]), Some(pivot), out).expect("batch")
    };
    let batch = UnrolledSpatialBatch::new(models.clone()).expect("batch");
    let four = batch.clone().with_avx512(false);
    for (pool, batch) in pools().iter().flat_map(|pool| [(pool, &batch), (pool, &four)]) {
        let mut out = vec![0.0; chains * D];
        let failures = pool.install(|| run(batch, 0..chains, &mut out));
        let what = format!(
            "{chains} chains of {N}, {} threads, AVX-512 {}",
            pool.current_num_threads(),
            batch.uses_avx512()
        );
        assert_rows(&out, D, &single, &failures, &what);
    }
    let cut = chains / 2 + 1;
    if cut < chains {
        let mut whole = vec![0.0; chains * D];
        run(&batch, 0..chains, &mut whole);
        let mut out = vec![0.0; chains * D];
        let (low, high) = out.split_at_mut(cut * D);
        run(&UnrolledSpatialBatch::new(models[..cut].to_vec()).expect("batch"), 0..cut, low);
        let (a, b) = (cut * D, chains * D);
        UnrolledSpatialBatch::new(models[cut..].to_vec())
            .expect("batch")
            .accelerations(&q[a..b], &qd[a..b], Some(&torque[a..b]), Some(&pivot[3 * cut..]), high)
            .expect("batch");
        assert_bits(&out, &whole, &format!("{chains} chains of {N} split at {cut}"));
    }
}

#[test]
fn each_chain_of_a_batch_is_its_generated_spatial_model_bit_for_bit() {
    let mut r = ChaCha8Rng::seed_from_u64(53);
    for chains in [1, 3, 9, 64] {
        let inputs = random_inputs(chains, 1, &mut r);
        check::<Spatial1, 1, 2>(random_models(chains, &mut r), &inputs);
        let inputs = random_inputs(chains, 2, &mut r);
        check::<Spatial2, 2, 4>(random_models(chains, &mut r), &inputs);
        let inputs = random_inputs(chains, 3, &mut r);
        check::<Spatial3, 3, 6>(random_models(chains, &mut r), &inputs);
        let inputs = random_inputs(chains, 4, &mut r);
        check::<Spatial4, 4, 8>(random_models(chains, &mut r), &inputs);
        let inputs = random_inputs(chains, 8, &mut r);
        check::<Spatial8, 8, 16>(random_models(chains, &mut r), &inputs);
    }
}

#[test]
fn a_chain_whose_continuants_leave_their_range_falls_back_in_its_lane_alone() {
    // Masses of 1e-250 kg make the tension system's diagonal ~1e250 and its continuants
    // overflow 2⁸⁰⁰: those chains take the classical pivots, their neighbours do not.
    let mut r = ChaCha8Rng::seed_from_u64(5);
    let mut models: Vec<Spatial8> = random_models(11, &mut r);
    let tiny = Chain::new(&[1e-250; 8], &[0.1; 8], 9.81).expect("chain");
    models[1] = Spatial8::new(tiny.clone());
    models[9] = Spatial8::new(tiny);
    let inputs = random_inputs(11, 8, &mut r);
    let single = each_alone::<_, 8, 16>(&models, &inputs);
    assert!(single.iter().all(Result::is_ok), "{single:?}");
    check::<Spatial8, 8, 16>(models, &inputs);
}

#[test]
fn a_chain_at_a_pole_or_with_a_nan_is_named_with_its_models_error_and_the_others_finish() {
    let mut r = ChaCha8Rng::seed_from_u64(9);
    let models: Vec<Spatial4> = random_models(13, &mut r);
    let mut inputs = random_inputs(13, 4, &mut r);
    // Polar angles (entries 0..4 of a row of 8) where `check_polar_sin` refuses the state:
    // hanging straight down, sines of 1e-8 (a finite result, refused all the same) and of
    // −5e-7, and π (a sine of 1.2e-16); one just past the tolerance, accepted.
    inputs[0][8 * 2 + 1] = 0.0; // chain 2, link 2
    inputs[0][8 * 4 + 3] = 1e-8; // chain 4, link 4
    inputs[0][8 * 5] = -5e-7; // chain 5, link 1
    inputs[0][8 * 11 + 2] = std::f64::consts::PI; // chain 11, link 3
    inputs[0][8 * 6 + 2] = 1.5e-6; // chain 6: accepted
    inputs[0][8 * 8 + 6] = f64::NAN; // chain 8: an azimuth
    inputs[1][8 * 10 + 3] = f64::INFINITY; // chain 10: a rate
    let single = each_alone::<_, 4, 8>(&models, &inputs);
    let refused: Vec<usize> = (0..13).filter(|&k| single[k].is_err()).collect();
    assert_eq!(refused, [2, 4, 5, 8, 10, 11], "{single:?}");
    assert!(matches!(single[4], Err(Error::SingularAngle { link: 4, .. })), "{:?}", single[4]);
    assert!(matches!(single[8], Err(Error::NonFinite { index: 6, .. })), "{:?}", single[8]);
    check::<Spatial4, 4, 8>(models, &inputs);
}

#[test]
fn bad_batches_and_arrays_are_one_line_errors() {
    assert_eq!(UnrolledSpatialBatch::<Spatial4, 4>::new(Vec::new()).unwrap_err(), Error::EmptyBatch);
    let mut r = ChaCha8Rng::seed_from_u64(1);
    let batch = UnrolledSpatialBatch::new(random_models::<Spatial4, 4>(3, &mut r)).expect("batch");
    let mut out = vec![0.0; 24];
    let error = batch.accelerations(&[0.3; 23], &[0.0; 24], None, None, &mut out).unwrap_err();
    assert_eq!(error.to_string(), "q has 23 entries, expected 24");
    let error = batch.accelerations(&[0.3; 24], &[0.0; 24], None, Some(&[0.0; 6]), &mut out).unwrap_err();
    assert_eq!(error.to_string(), "pivot has 6 entries, expected 9");
}

/// The worst `max_i |q̈32_i − q̈64_i| / max_i |q̈64_i|` over `chains` random chains and
/// states (masses, lengths and damping within a factor `spread` of 10 g, 1 cm and 3e-4
/// N·m·s; polar angles at least 0.1 rad from the poles), the `f32` batch against each
/// chain's `f64` model.
fn f32_error<M, const N: usize, const D: usize>(chains: usize, spread: f64, r: &mut ChaCha8Rng) -> f64
where
    M: SpatialKernel<N> + Model<Links = Const<N>, Dof = Const<D>, Space = U3> + From<Chain<Const<N>>>,
{
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
    let q: Vec<f64> = (0..chains * D)
        .map(|i| if i % D < N { r.random_range(0.1..3.04) } else { r.random_range(-3.0..3.0) })
        .collect();
    let qd: Vec<f64> = (0..chains * D).map(|_| r.random_range(-5.0..5.0)).collect();
    let pivot: Vec<f64> = (0..chains * 3).map(|_| r.random_range(-30.0..30.0)).collect();
    let exact =
        each_alone::<M, N, D>(&models, &[q.clone(), qd.clone(), vec![0.0; chains * D], pivot.clone()]);
    let to32 = |v: &[f64]| v.iter().map(|&x| x as f32).collect::<Vec<f32>>();
    let mut out = vec![0.0f32; chains * D];
    let batch = UnrolledSpatialBatch::new(models).expect("batch");
    let failures =
        batch.accelerations_f32(&to32(&q), &to32(&qd), None, Some(&to32(&pivot)), &mut out).expect("batch");
    assert!(failures.is_empty(), "{failures:?}");
    let mut four = vec![0.0f32; chains * D];
    let batch = batch.with_avx512(false);
    batch.accelerations_f32(&to32(&q), &to32(&qd), None, Some(&to32(&pivot)), &mut four).expect("batch");
    assert_eq!(
        four.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
        out.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
        "the f32 kernel gives the same bits however it is dispatched"
    );
    exact
        .iter()
        .enumerate()
        .map(|(k, e)| {
            let e = e.as_ref().expect("f64");
            let scale = e.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            let row = &out[k * D..(k + 1) * D];
            row.iter().zip(e).fold(0.0f64, |m, (&a, &b)| m.max((f64::from(a) - b).abs())) / scale
        })
        .fold(0.0, f64::max)
}

#[test]
fn single_precision_is_within_its_documented_bound_of_the_f64_model() {
    let mut r = ChaCha8Rng::seed_from_u64(32);
    // Measured (`--nocapture`): 1.6e-6, 2.0e-6, 2.1e-6 within a factor 2; 1.8e-6, 3.5e-6,
    // 3.2e-6 within a factor 10; 3.7e-6, 1.9e-6, 3.5e-6 within a factor 100 (n = 2, 4, 8);
    // the bounds in `docs/ensembles.md` are about 3× those.
    for (spread, bound) in [(2.0, 1e-5), (10.0, 1e-5), (100.0, 1e-5)] {
        let errors = [
            f32_error::<Spatial2, 2, 4>(1000, spread, &mut r),
            f32_error::<Spatial4, 4, 8>(1000, spread, &mut r),
            f32_error::<Spatial8, 8, 16>(1000, spread, &mut r),
        ];
        println!(
            "spread {spread}: worst relative error n = 2, 4, 8: {:.1e} {:.1e} {:.1e}",
            errors[0], errors[1], errors[2]
        );
        assert!(errors.iter().all(|&e| e < bound), "within a factor {spread}: {errors:?}");
    }
}

#[test]
fn in_single_precision_a_failing_chain_is_named_and_the_others_finish() {
    let mut r = ChaCha8Rng::seed_from_u64(8);
    let batch = UnrolledSpatialBatch::new(random_models::<Spatial4, 4>(11, &mut r)).expect("batch");
    let mut q: Vec<f32> = (0..88).map(|_| r.random_range(0.2..3.0)).collect();
    let qd: Vec<f32> = (0..88).map(|_| r.random_range(-3.0..3.0)).collect();
    q[8 * 3 + 6] = f32::NAN; // chain 3: q[6], an azimuth
    q[8 * 7 + 1] = 0.0; // chain 7: link 2 hangs straight down
    let mut out = vec![0.0f32; 88];
    let failures = batch.accelerations_f32(&q, &qd, None, None, &mut out).expect("batch");
    let found: Vec<(usize, String)> = failures.iter().map(|f| (f.chain, f.error.to_string())).collect();
    assert_eq!(found.len(), 2, "{found:?}");
    assert_eq!(found[0], (3, "q[6] must be finite, got NaN".to_owned()));
    assert_eq!(found[1].0, 7);
    assert!(found[1].1.contains("link 2"), "{}", found[1].1);
    for k in 0..11 {
        let row = &out[8 * k..8 * k + 8];
        assert_eq!(row.iter().all(|x| x.is_nan()), k == 3 || k == 7, "chain {k}: {row:?}");
    }
}

/// Each chain's state after `steps` steps of `Rk4` on `FirstOrder::new(model)`, alone, and
/// its error (the state left where it failed).
fn stepped_alone<M, const N: usize, const Q: usize, const D: usize>(
    models: &[M],
    states: &[State<Const<D>>],
    h: f64,
    steps: usize,
) -> Vec<(State<Const<D>>, Option<Error>)>
where
    M: SpatialKernel<N> + Model<Links = Const<N>, Dof = Const<Q>, Space = U3> + Clone,
    Const<Q>: nalgebra::DimMul<U2, Output = Const<D>>,
{
    batches::stepped_alone(models, states, |k| models[k].zero_inputs(), h, steps)
}

/// `chains` random states `(θ, φ, θ̇, φ̇)` at random times, the polar angles between 0.2
/// and 2.9 rad.
fn random_states<const D: usize>(chains: usize, r: &mut ChaCha8Rng) -> Vec<State<Const<D>>> {
    (0..chains)
        .map(|_| {
            let x = SVector::<f64, D>::from_fn(|i, _| match 4 * i / D {
                0 => r.random_range(0.2..2.9),
                1 => r.random_range(-3.0..3.0),
                _ => r.random_range(-5.0..5.0),
            });
            State::new(r.random_range(0.0..10.0), x)
        })
        .collect()
}

/// The batch's RK4 runs equal each chain's alone in time, state and compensation, and fail
/// where they fail with their errors: on 1 and 2 threads, in eight lanes a register and in
/// four, and in two calls of half the steps each.
fn check_rk4<M, const N: usize, const Q: usize, const D: usize>(
    models: Vec<M>,
    states: Vec<State<Const<D>>>,
    h: f64,
    steps: usize,
) where
    M: SpatialKernel<N> + Model<Links = Const<N>, Dof = Const<Q>, Space = U3> + Clone,
    Const<Q>: nalgebra::DimMul<U2, Output = Const<D>>,
{
    let alone = stepped_alone::<M, N, Q, D>(&models, &states, h, steps);
    let eight = UnrolledSpatialBatch::new(models).expect("batch");
    let four = eight.clone().with_avx512(false);
    for batch in [&eight, &four] {
        let run = |states: &mut [State<Const<D>>], steps| batch.integrate_rk4(states, None, None, h, steps);
        check_runs(&run, &states, &alone, steps, &format!("N = {N}, AVX-512 {}", batch.uses_avx512()));
    }
}

#[test]
fn rk4_runs_of_a_batch_equal_each_chain_stepped_alone_bit_for_bit() {
    let mut r = ChaCha8Rng::seed_from_u64(61);
    // 37 chains: ten blocks of four in groups of four (the last one short), each group a
    // task of its own on two threads; 9 chains: three blocks, the last alone in its pair.
    for chains in [1, 6, 9, 13, 37] {
        let states = random_states::<8>(chains, &mut r);
        check_rk4::<Spatial2, 2, 4, 8>(random_models(chains, &mut r), states, 1e-3, 20);
        let states = random_states::<16>(chains, &mut r);
        check_rk4::<Spatial4, 4, 8, 16>(random_models(chains, &mut r), states, 3e-4, 20);
    }
}

#[test]
fn a_chain_whose_run_reaches_a_pole_stops_there_with_its_own_error() {
    let mut r = ChaCha8Rng::seed_from_u64(3);
    let models: Vec<Spatial4> = random_models(11, &mut r);
    let mut states = random_states::<16>(11, &mut r);
    let mut set = |k: usize, entries: &[(usize, f64)]| {
        let mut x = *states[k].x();
        for &(i, value) in entries {
            x[i] = value;
        }
        states[k] = State::new(states[k].t(), x);
    };
    // Chain 2: link 3 swings towards the pole, so that the second stage of the first step
    // (`θ + (h/2) θ̇`) lands 5e-7 rad from it (a finite result, which the model refuses),
    // after a first stage at 2.505e-4 rad, which it accepts. Chain 5: an azimuth is NaN.
    // Chain 9: link 1 starts at the pole.
    set(2, &[(2, 2.5e-4 + 5e-7), (8 + 2, -0.5), (8 + 4 + 2, 0.0)]);
    set(5, &[(6, f64::NAN)]);
    set(9, &[(0, 0.0)]);
    let h = 1e-3;
    let alone = stepped_alone::<Spatial4, 4, 8, 16>(&models, &states, h, 10);
    let failed: Vec<usize> = (0..11).filter(|&k| alone[k].1.is_some()).collect();
    assert_eq!(failed, [2, 5, 9], "{alone:?}");
    assert!(matches!(alone[2].1, Some(Error::SingularAngle { link: 3, .. })), "{:?}", alone[2].1);
    assert!(matches!(alone[9].1, Some(Error::SingularAngle { link: 1, .. })), "{:?}", alone[9].1);
    check_rk4::<Spatial4, 4, 8, 16>(models, states, h, 10);
}

/// Random generalized torques (`B` rows of `2N`), held pivot accelerations (`B` rows of 3)
/// and whirling pivots: circles of random radius and speed.
fn random_drives(chains: usize, n: usize, r: &mut ChaCha8Rng) -> (Vec<f64>, Vec<f64>, Vec<Circle>) {
    let torque = (0..chains * 2 * n).map(|_| r.random_range(-1e-3..1e-3)).collect();
    let pivot = (0..chains * 3).map(|_| r.random_range(-30.0..30.0)).collect();
    let drives = (0..chains)
        .map(|_| Circle::new(r.random_range(0.0..0.05), r.random_range(1.0..20.0)).expect("drive"))
        .collect();
    (torque, pivot, drives)
}

#[test]
fn rk4_runs_with_torques_and_pivots_held_or_whirled_equal_each_chain_with_its_inputs_alone() {
    let mut r = ChaCha8Rng::seed_from_u64(29);
    let h = 5e-4;
    // 11 chains: a chain whose torque is NaN (3), one whose held pivot acceleration is
    // infinite (7), one whose whirl's acceleration r ω² overflows (9).
    for chains in [1, 9, 11, 37] {
        let models: Vec<Spatial4> = random_models(chains, &mut r);
        let states = random_states::<16>(chains, &mut r);
        let (mut torque, mut pivot, mut drives) = random_drives(chains, 4, &mut r);
        if chains == 11 {
            torque[8 * 3 + 5] = f64::NAN;
            pivot[3 * 7 + 2] = f64::INFINITY;
            drives[9] = Circle::new(1e300, 1e10).expect("drive");
        }
        let row = |k: usize| SVector::<f64, 8>::from_column_slice(&torque[8 * k..8 * k + 8]);
        let held = |k: usize| Inputs {
            torque: row(k),
            pivot_acceleration: Vector3::from_column_slice(&pivot[3 * k..3 * k + 3]),
        };
        let whirled = |k: usize| Driven::new(drives[k], ConstantTorque(row(k)));
        let alone_held = batches::stepped_alone(&models, &states, held, h, 30);
        let alone_whirled = batches::stepped_alone(&models, &states, whirled, h, 30);
        let failed = |alone: &[(State<Const<16>>, Option<Error>)]| -> Vec<usize> {
            (0..chains).filter(|&k| alone[k].1.is_some()).collect()
        };
        let (held_fail, whirled_fail) =
            if chains == 11 { (vec![3, 7], vec![3, 9]) } else { (vec![], vec![]) };
        assert_eq!((failed(&alone_held), failed(&alone_whirled)), (held_fail, whirled_fail));
        // The inputs change the runs: the held pivots are not the whirls, nor no inputs.
        let unforced = stepped_alone::<Spatial4, 4, 8, 16>(&models, &states, h, 30);
        for k in (0..chains).filter(|k| ![3, 7, 9].contains(k)) {
            let [a, b, c] = [&alone_held[k].0, &alone_whirled[k].0, &unforced[k].0].map(|s| *s.x());
            assert!(a != b && a != c && b != c, "chain {k}");
        }
        let eight = UnrolledSpatialBatch::new(models).expect("batch");
        for batch in [eight.clone(), eight.with_avx512(false)] {
            let what = format!("AVX-512 {}", batch.uses_avx512());
            let run = |states: &mut [State<Const<16>>], steps| {
                batch.integrate_rk4(states, Some(&torque), Some(&pivot), h, steps)
            };
            check_runs(&run, &states, &alone_held, 30, &format!("held, {what}"));
            let run = |states: &mut [State<Const<16>>], steps| {
                batch.integrate_rk4_driven(states, &drives, Some(&torque), h, steps)
            };
            check_runs(&run, &states, &alone_whirled, 30, &format!("whirled, {what}"));
        }
    }
}

/// `chains` models of [`batches::spread_fixed_chain`]s.
fn spread_models<M: From<Chain<Const<N>>>, const N: usize>(
    chains: usize,
    spread: f64,
    r: &mut ChaCha8Rng,
) -> Vec<M> {
    (0..chains).map(|_| M::from(batches::spread_fixed_chain::<N>(spread, r))).collect()
}

/// [`batches::f32_run_error`] of 64 spatial chains of `N` links (`spread` as
/// [`batches::spread_fixed_chain`]) from polar angles between 0.3 and 2.8 rad, azimuths
/// within ±3 rad and rates within ±1 rad/s, `steps` steps of 0.1 ms.
fn f32_run_error<M, const N: usize, const X: usize>(spread: f64, steps: usize, r: &mut ChaCha8Rng) -> f64
where
    M: SpatialKernel<N> + From<Chain<Const<N>>>,
{
    let (chains, h) = (64, 1e-4);
    let batch = UnrolledSpatialBatch::new(spread_models::<M, N>(chains, spread, r)).expect("batch");
    let states: Vec<State<Const<X>>> = (0..chains)
        .map(|_| {
            let x = SVector::<f64, X>::from_fn(|i, _| match i / N {
                0 => r.random_range(0.3..2.8),
                1 => r.random_range(-3.0..3.0),
                _ => r.random_range(-1.0..1.0),
            });
            State::new(0.0, x)
        })
        .collect();
    let run64 = |states: &mut [State<Const<X>>], t: Option<&[f64]>, p: Option<&[f64]>, steps: usize| {
        batch.integrate_rk4(states, t, p, h, steps)
    };
    let run32 = |x: &mut [f32], carry: &mut [f32], t: Option<&[f32]>, p: Option<&[f32]>, steps: usize| {
        batch.integrate_rk4_f32((x, carry), t, p, h, steps)
    };
    batches::f32_run_error(&run64, &run32, &states, [2 * N, 3], steps, r)
}

#[test]
fn rk4_runs_in_single_precision_stay_near_the_f64_runs() {
    let mut r = ChaCha8Rng::seed_from_u64(32);
    for (spread, steps, bound) in [(2.0, 100, 5e-6), (10.0, 100, 5e-6), (100.0, 100, 1e-5), (2.0, 1000, 3e-4)]
    {
        let errors = [
            f32_run_error::<Spatial4, 4, 16>(spread, steps, &mut r),
            f32_run_error::<Spatial8, 8, 32>(spread, steps, &mut r),
        ];
        println!("spread {spread}, {steps} steps: n = 4 / 8 {:.1e} / {:.1e}", errors[0], errors[1]);
        assert!(errors.iter().all(|&e| e < bound), "spread {spread}, {steps} steps: {errors:?}");
    }
}

#[test]
fn in_single_precision_a_run_names_its_failing_chains_and_the_others_finish() {
    let mut r = ChaCha8Rng::seed_from_u64(33);
    let (chains, h) = (11, 1e-4);
    let batch = UnrolledSpatialBatch::new(spread_models::<Spatial4, 4>(chains, 2.0, &mut r)).expect("batch");
    let mut x: Vec<f32> = (0..chains * 16)
        .map(|i| if i % 16 < 4 { r.random_range(0.3..2.8) } else { r.random_range(-1.0..1.0) })
        .collect();
    let mut torque = vec![0.0f32; chains * 8];
    let mut pivot = vec![0.0f32; chains * 3];
    x[16 * 2 + 9] = f32::NAN; // chain 2: x[9], a polar rate
    torque[8 * 5 + 6] = f32::INFINITY; // chain 5: an azimuthal torque
    pivot[3 * 7 + 2] = f32::NAN; // chain 7
    x[16 * 8 + 1] = 0.0; // chain 8: link 2 at the pole
    x[16 * 9 + 12] = 1e20; // chain 9: φ̇² overflows f32
    let start = x.clone();
    let mut carry = vec![0.0f32; x.len()];
    let failures =
        batch.integrate_rk4_f32((&mut x, &mut carry), Some(&torque), Some(&pivot), h, 20).expect("run");
    let found: Vec<(usize, String)> = failures.iter().map(|f| (f.chain, f.error.to_string())).collect();
    assert_eq!(found.iter().map(|f| f.0).collect::<Vec<_>>(), [2, 5, 7, 8, 9], "{found:?}");
    assert_eq!(found[0].1, "x[9] must be finite, got NaN");
    assert_eq!(found[1].1, "torque[6] must be finite, got inf");
    assert_eq!(found[2].1, "pivot_acceleration[2] must be finite, got NaN");
    assert!(matches!(failures[3].error, Error::SingularAngle { link: 2, .. }), "{:?}", failures[3].error);
    assert_eq!(found[4].1, Error::NonFiniteState { t: 0.0, h }.to_string());
    for k in 0..chains {
        let (now, then) = (&x[16 * k..16 * k + 16], &start[16 * k..16 * k + 16]);
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(now) == bits(then), [2, 5, 7, 8, 9].contains(&k), "chain {k}");
    }
    let error = batch.integrate_rk4_f32((&mut x, &mut carry), None, Some(&pivot[1..]), h, 1).unwrap_err();
    assert_eq!(error.to_string(), "pivot has 32 entries, expected 33");
}

#[test]
fn whirled_runs_in_single_precision_stay_near_the_f64_whirled_runs() {
    let mut r = ChaCha8Rng::seed_from_u64(34);
    let (chains, h, t0, steps) = (64, 1e-4, 0.37, 100);
    for spread in [2.0, 10.0] {
        let batch =
            UnrolledSpatialBatch::new(spread_models::<Spatial4, 4>(chains, spread, &mut r)).expect("batch");
        let states: Vec<State<Const<16>>> = (0..chains)
            .map(|_| {
                let x = SVector::<f64, 16>::from_fn(|i, _| match i / 4 {
                    0 => r.random_range(0.3..2.8),
                    1 => r.random_range(-3.0..3.0),
                    _ => r.random_range(-1.0..1.0),
                });
                State::new(t0, x)
            })
            .collect();
        let drives: Vec<Circle> = (0..chains)
            .map(|_| Circle::new(r.random_range(0.0..0.05), r.random_range(1.0..20.0)).expect("drive"))
            .collect();
        let run64 = |states: &mut [State<Const<16>>], steps: usize| {
            batch.integrate_rk4_driven(states, &drives, None, h, steps)
        };
        let run32 = |x: &mut [f32], carry: &mut [f32], steps: usize| {
            batch.integrate_rk4_driven_f32((x, carry), (t0, &drives), None, h, steps)
        };
        let error = batches::f32_driven_error(&run64, &run32, &states, steps);
        println!("spread {spread}, whirled, {steps} steps: n = 4 {error:.1e}");
        assert!(error < 1e-4, "spread {spread}: {error:e}");
    }
}
