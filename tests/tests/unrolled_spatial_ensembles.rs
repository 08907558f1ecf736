//! `model!`'s spatial models in lanes (`pendulum_core::batch::UnrolledSpatialBatch`): every
//! chain of a batch gets exactly its generated model's `(θ̈, φ̈)`, whatever the thread count,
//! the lanes per register and however the chains are split into calls, the chains whose
//! tension continuants leave their range included; a chain at a pole of its chart, or with
//! a non-finite input, is reported by its index with its model's error while the others
//! finish.

use nalgebra::{Const, SVector, U3, Vector3};
use pendulum_core::batch::{SpatialKernel, UnrolledSpatialBatch};
use pendulum_core::{Chain, Error, Inputs, Model};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

pendulum_macros::model! {
    struct Spatial1 { kind: spatial, links: 1, algorithm: tension }
    struct Spatial2 { kind: spatial, links: 2 }
    struct Spatial3 { kind: spatial, links: 3 }
    struct Spatial4 { kind: spatial, links: 4 }
    struct Spatial8 { kind: spatial, links: 8 }
}

/// `N` links with masses, lengths and damping log-uniform over two decades, gravity
/// between 1 and 20 m/s².
fn random_chain<const N: usize>(r: &mut ChaCha8Rng) -> Chain<Const<N>> {
    let mut decades = |lo: f64| (0..N).map(|_| 10f64.powf(lo + 2.0 * r.random::<f64>())).collect::<Vec<_>>();
    let (masses, lengths, damping) = (decades(-2.0), decades(-2.0), decades(-5.0));
    let g = r.random_range(1.0..20.0);
    Chain::new(&masses, &lengths, g).and_then(|c| c.with_damping(&damping)).expect("chain")
}

fn random_models<M: From<Chain<Const<N>>>, const N: usize>(chains: usize, r: &mut ChaCha8Rng) -> Vec<M> {
    (0..chains).map(|_| M::from(random_chain::<N>(r))).collect()
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

/// Every entry equal bit for bit.
fn assert_bits(batch: &[f64], single: &[f64], what: &str) {
    for (i, (a, b)) in batch.iter().zip(single).enumerate() {
        assert_eq!(a.to_bits(), b.to_bits(), "{what}[{i}]: batch {a:e} single {b:e}");
    }
}

fn pools() -> [rayon::ThreadPool; 2] {
    [1, 2].map(|threads| rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool"))
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
        let mut failed = failures.iter();
        for (k, alone) in single.iter().enumerate() {
            let row = &out[k * D..(k + 1) * D];
            match alone {
                Ok(expected) => assert_bits(row, expected, &format!("{what}, chain {k}")),
                Err(error) => {
                    let failure = failed.next().unwrap_or_else(|| panic!("{what}: chain {k} not reported"));
                    assert_eq!((failure.chain, failure.error.to_string()), (k, error.to_string()), "{what}");
                    assert!(row.iter().all(|x| x.is_nan()), "{what}: chain {k}'s row is NaN");
                }
            }
        }
        assert!(failed.next().is_none(), "{what}: only the failing chains are reported");
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
