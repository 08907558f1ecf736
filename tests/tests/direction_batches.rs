//! Batches of chains in unit link directions (`DirectionsBatch`): evaluations, projected
//! RK4 steps and runs (with the energy ledger too), the implicit rod midpoint steps and the
//! Jacobians of every chain equal the single chain's bit for bit, whatever the thread count
//! and however the chains are split into calls, and a failing chain is reported by its
//! index while the others finish.

use std::ops::ControlFlow;

use nalgebra::{DVector, Dyn, U2, U3};
use pendulum_core::RodMidpoint;
use pendulum_core::batch::DirectionsBatch;
use pendulum_core::integrate::{Integrator, Projected, Rk4, State};
use pendulum_core::{Accounted, Circle, Directions, Error, Harmonic, trajectory};
use pendulum_tests::batches::{assert_bits, assert_same_state, pools, random_chain, whirl, whirl_state};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

#[test]
fn one_direction_model_repeated_is_that_model_at_every_state() {
    // One block of constants for all (`repeated`) against a model per chain: the same
    // accelerations in f64 and f32, the same RK4 steps, in eight lanes and four.
    let mut r = ChaCha8Rng::seed_from_u64(17);
    let (count, n) = (19, 6);
    let (model, _) = whirl(n, &mut r);
    let x: Vec<DVector<f64>> = (0..count).map(|_| whirl_state(&model, n, &mut r)).collect();
    let flat: Vec<f64> = x.iter().flat_map(|x| x.iter().copied()).collect();
    let repeated = DirectionsBatch::repeated(model.clone(), count).expect("repeated");
    let copies = DirectionsBatch::new(vec![model.clone(); count]).expect("copies");
    assert_eq!((repeated.len(), repeated.links()), (count, n));
    for avx512 in [true, false] {
        let (a, b) = (repeated.clone().with_avx512(avx512), copies.clone().with_avx512(avx512));
        let half = a.state_len() / 2;
        let (mut ua, mut ub) = (vec![0.0; count * half], vec![0.0; count * half]);
        assert!(a.accelerations(0.7, &flat, &mut ua).expect("a").is_empty());
        assert!(b.accelerations(0.7, &flat, &mut ub).expect("b").is_empty());
        assert_bits(&ua, &ub, "ü");
        let narrow: Vec<f32> = flat.iter().map(|&v| v as f32).collect();
        let (mut fa, mut fb) = (vec![0.0f32; count * half], vec![0.0f32; count * half]);
        assert!(a.accelerations_f32(0.7, &narrow, &mut fa).expect("a").is_empty());
        assert!(b.accelerations_f32(0.7, &narrow, &mut fb).expect("b").is_empty());
        assert_eq!(
            fa.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            fb.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
        );
        let start: Vec<State<Dyn>> =
            x.iter().enumerate().map(|(k, x)| State::new(0.01 * k as f64, x.clone())).collect();
        let (mut sa, mut sb) = (start.clone(), start);
        assert!(a.integrate_rk4(&mut sa, 1e-3, 7).expect("a").is_empty());
        assert!(b.integrate_rk4(&mut sb, 1e-3, 7).expect("b").is_empty());
        for (p, q) in sa.iter().zip(&sb) {
            assert_bits(p.x().as_slice(), q.x().as_slice(), "RK4 state");
        }
    }
    assert!(matches!(DirectionsBatch::repeated(model, 0), Err(Error::EmptyBatch)));
}

#[test]
fn directions_and_rates_given_apart_give_the_joined_states_numbers() {
    let mut r = ChaCha8Rng::seed_from_u64(19);
    let (count, n) = (13, 5);
    let (models, x): (Vec<_>, Vec<_>) = (0..count).map(|_| whirl(n, &mut r)).unzip();
    let batch = DirectionsBatch::new(models).expect("batch");
    let half = 3 * n;
    let joined: Vec<f64> = x.iter().flat_map(|x| x.iter().copied()).collect();
    let mut u: Vec<f64> = x.iter().flat_map(|x| x.as_slice()[..half].to_vec()).collect();
    let mut w: Vec<f64> = x.iter().flat_map(|x| x.as_slice()[half..].to_vec()).collect();
    for batch in [batch.clone(), batch.with_avx512(false)] {
        let (mut a, mut b) = (vec![0.0; count * half], vec![0.0; count * half]);
        assert!(batch.accelerations(0.4, &joined, &mut a).expect("joined").is_empty());
        assert!(batch.accelerations_split(0.4, &u, &w, &mut b).expect("split").is_empty());
        assert_bits(&b, &a, "ü from u and w apart");
        // A NaN rate is named in `w`, in its chain only.
        let kept = w[4 * half + 2];
        w[4 * half + 2] = f64::NAN;
        let failures = batch.accelerations_split(0.4, &u, &w, &mut b).expect("split");
        assert_eq!(failures.len(), 1);
        assert_eq!(failures[0].chain, 4);
        assert!(
            matches!(failures[0].error, Error::NonFinite { what: "w", index: 2, .. }),
            "{:?}",
            failures[0]
        );
        assert!(b[4 * half..5 * half].iter().all(|v| v.is_nan()));
        assert_bits(&b[..4 * half], &a[..4 * half], "the chains before");
        assert_bits(&b[5 * half..], &a[5 * half..], "the chains after");
        w[4 * half + 2] = kept;
        // In single precision too.
        let narrow = |v: &[f64]| v.iter().map(|&v| v as f32).collect::<Vec<_>>();
        let (mut a32, mut b32) = (vec![0.0f32; count * half], vec![0.0f32; count * half]);
        assert!(batch.accelerations_f32(0.4, &narrow(&joined), &mut a32).expect("joined").is_empty());
        assert!(
            batch.accelerations_split_f32(0.4, &narrow(&u), &narrow(&w), &mut b32).expect("split").is_empty()
        );
        assert!(a32.iter().zip(&b32).all(|(a, b)| a.to_bits() == b.to_bits()), "f32 ü from u and w apart");
    }
    u.pop();
    let mut out = vec![0.0; count * half];
    assert!(matches!(
        DirectionsBatch::new(vec![whirl(n, &mut r).0; count])
            .expect("batch")
            .accelerations_split(0.0, &u, &w, &mut out),
        Err(Error::LengthMismatch { what: "u", .. })
    ));
}

#[test]
fn rk4_steps_of_a_batch_equal_each_chain_alone_bit_for_bit() {
    let mut r = ChaCha8Rng::seed_from_u64(11);
    for (chains, n) in [(1, 3), (7, 10), (9, 100)] {
        let (models, x): (Vec<_>, Vec<_>) = (0..chains).map(|_| whirl(n, &mut r)).unzip();
        let batch = DirectionsBatch::new(models.clone()).expect("batch");
        let h = 1e-3;
        // Chains at different times, so that each drive is evaluated at its own.
        let start: Vec<State<Dyn>> =
            x.iter().enumerate().map(|(k, x)| State::new(0.1 * k as f64, x.clone())).collect();
        let mut single = start.clone();
        for (model, state) in models.iter().zip(&mut single) {
            let mut rk4 = Projected::new(Rk4::new(model));
            for _ in 0..20 {
                rk4.step(model, state, h).expect("single");
            }
        }
        let pools_and_widths = [true, false]
            .into_iter()
            .flat_map(|avx512| pools().map(|pool| (batch.clone().with_avx512(avx512), pool)));
        for (batch, pool) in pools_and_widths {
            // Step by step, and 20 steps in one call; in eight lanes (AVX-512) and four.
            let mut states = start.clone();
            for _ in 0..20 {
                let failures = pool.install(|| batch.step_rk4(&mut states, h)).expect("batch");
                assert!(failures.is_empty(), "{failures:?}");
            }
            let mut run = start.clone();
            assert!(pool.install(|| batch.integrate_rk4(&mut run, h, 20)).expect("batch").is_empty());
            for (k, ((a, b), c)) in states.iter().zip(&single).zip(&run).enumerate() {
                for s in [a, c] {
                    assert_same_state(s, b, &format!("chain {k} of {chains}×{n}"));
                }
            }
        }
        // The accelerations alone, too.
        let m = batch.state_len();
        let flat: Vec<f64> = x.iter().flat_map(|x| x.iter().copied()).collect();
        for batch in [batch.clone(), batch.with_avx512(false)] {
            let mut out = vec![0.0; chains * m / 2];
            assert!(batch.accelerations(0.3, &flat, &mut out).expect("batch").is_empty());
            for (k, (model, x)) in models.iter().zip(&x).enumerate() {
                let mut one = vec![0.0; m / 2];
                model.accelerations(0.3, x, &mut one, None).expect("single");
                let what = format!("ü of chain {k}, AVX-512 {}", batch.uses_avx512());
                assert_bits(&out[k * m / 2..(k + 1) * m / 2], &one, &what);
            }
        }
    }
}

#[test]
fn rk4_steps_from_states_that_carry_a_compensation_equal_each_chain_alone() {
    // The batch skips the compensations of states that arrive with none; here some chains
    // of a block bring one (left by RK4 steps without projection) and others none, then
    // all arrive cleared in the same batch (whose kept lanes still hold the old ones).
    let mut r = ChaCha8Rng::seed_from_u64(23);
    let (chains, n, h) = (11, 12, 1e-3);
    let (models, x): (Vec<_>, Vec<_>) = (0..chains).map(|_| whirl(n, &mut r)).unzip();
    let batch = DirectionsBatch::new(models.clone()).expect("batch");
    let mut start: Vec<State<Dyn>> = x.iter().map(|x| State::new(0.0, x.clone())).collect();
    for (model, state) in models.iter().zip(&mut start).step_by(2) {
        let mut rk4 = Rk4::new(model);
        for _ in 0..3 {
            rk4.step(model, state, h).expect("unprojected");
        }
        assert!(state.compensation().iter().any(|&c| c != 0.0), "a compensation to carry");
    }
    let single = |start: &[State<Dyn>], steps: usize| -> Vec<State<Dyn>> {
        let mut states = start.to_vec();
        for (model, state) in models.iter().zip(&mut states) {
            let mut rk4 = Projected::new(Rk4::new(model));
            (0..steps).for_each(|_| rk4.step(model, state, h).expect("single"));
        }
        states
    };
    let cleared: Vec<State<Dyn>> = start.iter().map(|s| State::new(s.t(), s.x().clone())).collect();
    for avx512 in [true, false] {
        let batch = batch.clone().with_avx512(avx512);
        for pool in pools() {
            for start in [&start, &cleared, &start] {
                let expected = single(start, 3);
                let mut states = start.clone();
                for _ in 0..3 {
                    assert!(pool.install(|| batch.step_rk4(&mut states, h)).expect("batch").is_empty());
                }
                let mut run = start.clone();
                assert!(pool.install(|| batch.integrate_rk4(&mut run, h, 3)).expect("batch").is_empty());
                for (k, ((a, b), c)) in states.iter().zip(&expected).zip(&run).enumerate() {
                    for s in [a, c] {
                        assert_same_state(s, b, &format!("chain {k}"));
                    }
                }
            }
        }
    }
}

/// The states `x` of `models` with empty energy ledgers, at t = 0.
fn accounted_states(models: &[Directions<U3, Circle>], x: &[DVector<f64>]) -> Vec<State<Dyn>> {
    models
        .iter()
        .zip(x)
        .map(|(m, x)| State::new(0.0, Accounted::of(m.clone()).state(x).expect("state")))
        .collect()
}

#[test]
fn with_their_energy_ledgers_the_steps_equal_the_accounted_chain_bit_for_bit() {
    let mut r = ChaCha8Rng::seed_from_u64(17);
    let n = 30;
    let (models, x): (Vec<_>, Vec<_>) = (0..6).map(|_| whirl(n, &mut r)).unzip();
    let batch = DirectionsBatch::accounted(models.clone()).expect("batch");
    let start = accounted_states(&models, &x);
    let h = 5e-4;
    let mut states = start.clone();
    assert!(batch.integrate_rk4(&mut states, h, 40).expect("batch").is_empty());
    let mut four_lanes = start.clone();
    assert!(
        batch.clone().with_avx512(false).integrate_rk4(&mut four_lanes, h, 40).expect("batch").is_empty()
    );
    for (k, state) in four_lanes.iter().enumerate() {
        assert_bits(state.x().as_slice(), states[k].x().as_slice(), &format!("chain {k} in four lanes"));
    }
    for (k, (model, state)) in models.iter().zip(&states).enumerate() {
        let system = Accounted::of(model.clone());
        let mut alone = start[k].clone();
        let mut rk4 = Projected::new(Rk4::new(&system));
        for _ in 0..40 {
            rk4.step(&system, &mut alone, h).expect("single");
        }
        assert_bits(state.x().as_slice(), alone.x().as_slice(), &format!("chain {k} with its ledger"));
        // The ledger moved: the drive did work and the damping took some.
        let ledger = &state.x().as_slice()[batch.state_len() - 3..];
        assert!(ledger[0] != 0.0 && ledger[2] > 0.0, "{ledger:?}");
    }
}

/// The samples of a run: times (s) and states.
type Samples = Vec<(f64, Vec<f64>)>;

#[test]
fn a_batched_run_is_each_chain_run_alone_samples_and_summaries_included() {
    let mut r = ChaCha8Rng::seed_from_u64(23);
    let n = 12;
    let (models, x): (Vec<_>, Vec<_>) = (0..7).map(|_| whirl(n, &mut r)).unzip();
    let batch = DirectionsBatch::accounted(models.clone()).expect("batch");
    for batch in [batch.clone(), batch.with_avx512(false)] {
        a_batched_run_in(&batch, &models, &x);
    }
}

/// [`a_batched_run_is_each_chain_run_alone_samples_and_summaries_included`] for one batch
/// of 7 whirls from `x`.
fn a_batched_run_in(
    batch: &DirectionsBatch<U3, Circle>,
    models: &[Directions<U3, Circle>],
    x: &[DVector<f64>],
) {
    let start = accounted_states(models, x);
    // Chain 3 stops itself after its fourth sample; the others run to the end.
    let stop_after = |k: usize| if k == 3 { 4 } else { usize::MAX };
    let (t1, h, every) = (0.1037, 1e-3, 7);
    let mut states = start.clone();
    let mut seen: Vec<(usize, Samples)> = (0..7).map(|k| (k, Vec::new())).collect();
    let ends = batch
        .run_rk4(&mut states, &mut seen, t1, h, every, |(k, samples), t, x| {
            samples.push((t, x.as_slice().to_vec()));
            if samples.len() >= stop_after(*k) { ControlFlow::Break(()) } else { ControlFlow::Continue(()) }
        })
        .expect("batch");
    for (k, model) in models.iter().enumerate() {
        let system = Accounted::of(model.clone());
        let mut alone = start[k].clone();
        let mut samples = Vec::new();
        let summary = trajectory::run(
            &mut Projected::new(Rk4::new(&system)),
            &system,
            &mut alone,
            t1,
            h,
            every,
            |t, x| {
                samples.push((t, x.as_slice().to_vec()));
                if samples.len() >= stop_after(k) {
                    ControlFlow::Break(())
                } else {
                    ControlFlow::Continue(())
                }
            },
        )
        .expect("alone");
        assert_eq!(ends[k].as_ref().expect("ran"), &summary, "chain {k}");
        assert_eq!(seen[k].1.len(), samples.len(), "chain {k}");
        for ((ta, xa), (tb, xb)) in seen[k].1.iter().zip(&samples) {
            assert_eq!(ta.to_bits(), tb.to_bits());
            assert_bits(xa, xb, &format!("chain {k} at t = {ta}"));
        }
        assert_bits(states[k].x().as_slice(), alone.x().as_slice(), "the end");
    }
    assert!(ends[3].as_ref().expect("ran").stopped_early && !ends[0].as_ref().expect("ran").stopped_early);
}

#[test]
fn a_planar_directions_batch_matches_too_and_a_blown_chain_stays_put() {
    let mut r = ChaCha8Rng::seed_from_u64(5);
    let n = 12;
    let models: Vec<_> = (0..6).map(|_| Directions::<U2>::new(random_chain(n, &mut r))).collect();
    let batch = DirectionsBatch::new(models.clone()).expect("batch");
    let start: Vec<State<Dyn>> = models
        .iter()
        .map(|m| {
            let theta: Vec<f64> = (0..n).map(|_| r.random_range(-2.0..2.0)).collect();
            State::new(0.0, m.from_angles(&theta, &vec![0.3; n]).expect("state"))
        })
        .collect();
    let mut states = start.clone();
    let mut bad = states[3].x().clone();
    bad[4] = f64::NAN;
    states[3] = State::new(0.0, bad.clone());
    let failures = batch.step_rk4(&mut states, 2e-3).expect("batch");
    assert_eq!(failures.len(), 1);
    assert_eq!(failures[0].chain, 3);
    assert_bits(states[3].x().as_slice(), bad.as_slice(), "the failed chain's state");
    for k in [0, 1, 2, 4, 5] {
        let mut one = start[k].clone();
        Projected::new(Rk4::new(&models[k])).step(&models[k], &mut one, 2e-3).expect("single");
        assert_bits(states[k].x().as_slice(), one.x().as_slice(), &format!("chain {k}"));
    }
    assert_eq!(batch.step_rk4(&mut states, 0.0).unwrap_err(), Error::InvalidStepSize { h: 0.0 });
}

#[test]
fn a_chain_that_blows_up_mid_run_stops_at_its_last_good_state() {
    let mut r = ChaCha8Rng::seed_from_u64(9);
    let n = 10;
    let models: Vec<_> = (0..5).map(|_| Directions::<U3>::new(random_chain(n, &mut r))).collect();
    let batch = DirectionsBatch::new(models.clone()).expect("batch");
    let mut start: Vec<State<Dyn>> = models
        .iter()
        .map(|m| {
            let q: Vec<f64> = (0..2 * n).map(|i| if i < n { 0.5 } else { 1.0 }).collect();
            State::new(0.0, m.from_spherical(&q, &vec![0.2; 2 * n]).expect("state"))
        })
        .collect();
    // Chain 2 spins so fast that RK4 at this step size diverges to infinity.
    let fast: Vec<f64> = (0..2 * n).map(|i| if i < n { 0.0 } else { 1e150 }).collect();
    let q: Vec<f64> = (0..2 * n).map(|i| if i < n { 0.5 } else { 1.0 }).collect();
    start[2] = State::new(0.0, models[2].from_spherical(&q, &fast).expect("state"));
    let h = 1e-3;
    let mut states = start.clone();
    let failures = batch.integrate_rk4(&mut states, h, 50).expect("batch");
    assert_eq!(failures.len(), 1, "{failures:?}");
    assert_eq!(failures[0].chain, 2);
    let Error::NonFiniteState { t, .. } = failures[0].error else { panic!("{failures:?}") };
    // Chain 2 alone, step by step, fails at the same step and stops where the batch left it.
    let mut alone = start[2].clone();
    let mut rk4 = Projected::new(Rk4::new(&models[2]));
    while rk4.step(&models[2], &mut alone, h).is_ok() {}
    assert_eq!(alone.t().to_bits(), t.to_bits());
    assert_bits(states[2].x().as_slice(), alone.x().as_slice(), "the blown chain");
    for k in [0, 1, 3, 4] {
        assert!((states[k].t() - 0.05).abs() < 1e-12, "chain {k} ran all 50 steps");
    }
}

#[test]
fn batched_direction_jacobians_are_each_models_own_bit_for_bit_and_failures_stay_in_their_chain() {
    let mut r = ChaCha8Rng::seed_from_u64(78);
    for (chains, n) in [(1, 1), (6, 4), (23, 12), (11, 20)] {
        let (mut models, x): (Vec<_>, Vec<_>) = (0..chains).map(|_| whirl(n, &mut r)).unzip();
        if chains > 2 {
            // Chain 1's masses of 1e-150 kg take its solve's continuants out of their range:
            // its lane alone redoes the pivots the classical way.
            let lengths = models[1].chain().lengths().as_slice().to_vec();
            let tiny = pendulum_core::Chain::new(&vec![1e-150; n], &lengths, 9.81).expect("tiny");
            models[1] = Directions::<U3>::new(tiny).with_drive(Circle::new(0.03, 4.0).expect("drive"));
        }
        let batch = DirectionsBatch::new(models.clone()).expect("batch");
        let (half, t) = (3 * n, 0.83);
        let mut joined: Vec<f64> = x.iter().flat_map(|x| x.iter().copied()).collect();
        // One chain with a NaN rate, one whose rates overflow the solve (finite input, no
        // finite Jacobian): each fails alone.
        let (nan, huge) = (chains / 2, chains - 1);
        if chains > 2 {
            joined[2 * half * nan + half + 1] = f64::NAN;
            joined[2 * half * huge + half..2 * half * (huge + 1)].fill(1e200);
        }
        let block = half * half;
        let (mut single_u, mut single_w) = (vec![f64::NAN; chains * block], vec![f64::NAN; chains * block]);
        for (k, model) in models.iter().enumerate() {
            let x = DVector::from_column_slice(&joined[2 * half * k..2 * half * (k + 1)]);
            let mut jacobian = nalgebra::DMatrix::zeros(2 * half, 2 * half);
            let result = model.analytic_jacobian(t, &x, &mut jacobian);
            assert_eq!(result.is_err(), chains > 2 && k == nan, "chain {k}");
            if chains > 2 && (k == nan || k == huge) {
                continue;
            }
            for a in 0..half {
                for b in 0..half {
                    single_u[k * block + a * half + b] = jacobian[(half + a, b)];
                    single_w[k * block + a * half + b] = jacobian[(half + a, half + b)];
                }
            }
        }
        let u: Vec<f64> = joined.chunks(2 * half).flat_map(|x| x[..half].to_vec()).collect();
        let w: Vec<f64> = joined.chunks(2 * half).flat_map(|x| x[half..].to_vec()).collect();
        let pools = pools();
        for (pool, avx512) in pools.iter().flat_map(|p| [true, false].map(|a| (p, a))) {
            let batch = batch.clone().with_avx512(avx512);
            let lanes = if batch.uses_avx512() { 8 } else { 4 };
            let what =
                format!("{chains} chains of {n}, {} threads, {lanes} lanes", pool.current_num_threads());
            let (mut du, mut dw) = (vec![0.0; chains * block], vec![0.0; chains * block]);
            let failures =
                pool.install(|| batch.state_jacobians(t, &joined, &mut du, &mut dw)).expect("joined");
            assert_bits(&du, &single_u, &format!("{what}: ∂ü/∂u"));
            assert_bits(&dw, &single_w, &format!("{what}: ∂ü/∂w"));
            if chains > 2 {
                assert_eq!(failures.iter().map(|f| f.chain).collect::<Vec<_>>(), [nan, huge], "{what}");
                assert_eq!(failures[0].error.to_string(), format!("x[{}] must be finite, got NaN", half + 1));
                assert!(matches!(failures[1].error, Error::NonFiniteAccelerations), "{:?}", failures[1]);
            } else {
                assert!(failures.is_empty(), "{what}: {failures:?}");
            }
            let (mut du2, mut dw2) = (vec![0.0; chains * block], vec![0.0; chains * block]);
            let split =
                pool.install(|| batch.state_jacobians_split(t, &u, &w, &mut du2, &mut dw2)).expect("split");
            assert_bits(&du2, &du, &format!("{what}: ∂ü/∂u from u and w apart"));
            assert_bits(&dw2, &dw, &format!("{what}: ∂ü/∂w from u and w apart"));
            assert_eq!(
                split.iter().map(|f| f.chain).collect::<Vec<_>>(),
                failures.iter().map(|f| f.chain).collect::<Vec<_>>()
            );
        }
    }
    // Planar chains in directions, and arrays of the wrong size.
    let planar: Vec<_> = (0..3).map(|_| Directions::<U2>::new(random_chain(5, &mut r))).collect();
    let x: Vec<f64> = (0..3 * 20)
        .map(|i| if i % 20 < 10 { if i % 2 == 0 { 0.6 } else { -0.8 } } else { r.random_range(-2.0..2.0) })
        .collect();
    let batch = DirectionsBatch::new(planar.clone()).expect("planar");
    let (mut du, mut dw) = (vec![0.0; 300], vec![0.0; 300]);
    assert!(batch.state_jacobians(0.0, &x, &mut du, &mut dw).expect("planar").is_empty());
    let mut jacobian = nalgebra::DMatrix::zeros(20, 20);
    planar[2].analytic_jacobian(0.0, &DVector::from_column_slice(&x[40..]), &mut jacobian).expect("alone");
    assert_eq!(du[200 + 3 * 10 + 7].to_bits(), jacobian[(13, 7)].to_bits());
    assert_eq!(dw[200 + 9 * 10 + 2].to_bits(), jacobian[(19, 12)].to_bits());
    assert!(matches!(
        batch.state_jacobians(0.0, &x, &mut du[1..], &mut dw),
        Err(Error::LengthMismatch { what: "du", expected: 300, got: 299 })
    ));
    assert!(matches!(
        batch.state_jacobians(0.0, &x[1..], &mut du, &mut dw),
        Err(Error::LengthMismatch { what: "x", .. })
    ));
}

/// The rod midpoint helpers for chains in `$dim` dimensions driven by `$drive`s.
macro_rules! midpoint_helpers {
    ($alone:ident, $as_alone:ident, $dim:ty, $drive:ty) => {
        /// `steps` rod midpoint steps of `h` of each state alone, with the ledger when
        /// `accounted`: the states after them, the first error of each, and how many steps each
        /// took halved (by the step's own stats).
        fn $alone(
            models: &[Directions<$dim, $drive>],
            start: &[State<Dyn>],
            accounted: bool,
            (h, steps): (f64, usize),
        ) -> (Vec<State<Dyn>>, Vec<Option<Error>>, Vec<u64>) {
            let mut states = start.to_vec();
            let mut errors = Vec::new();
            let mut halved = Vec::new();
            for (model, state) in models.iter().zip(&mut states) {
                let mut step = RodMidpoint::new();
                let error = if accounted {
                    let system = Accounted::of(model.clone());
                    (0..steps).find_map(|_| step.step(&system, state, h).err())
                } else {
                    (0..steps).find_map(|_| step.step(model, state, h).err())
                };
                errors.push(error);
                halved.push(step.stats().halved_steps);
            }
            (states, errors, halved)
        }

        /// The batch's rod midpoint steps of `start` equal each chain's own, bit for bit, in eight
        /// lanes and in four, on one thread and two, whole and split in two batches; the failures
        /// are the chains' own errors.
        fn $as_alone(
            models: &[Directions<$dim, $drive>],
            start: &[State<Dyn>],
            accounted: bool,
            (h, steps): (f64, usize),
        ) -> Vec<u64> {
            let (single, errors, halved) = $alone(models, start, accounted, (h, steps));
            let expected: Vec<(usize, String)> = errors
                .iter()
                .enumerate()
                .filter_map(|(k, e)| e.as_ref().map(|e| (k, e.to_string())))
                .collect();
            let batch_of = |models: &[Directions<$dim, $drive>]| {
                let batch = if accounted {
                    DirectionsBatch::accounted(models.to_vec())
                } else {
                    DirectionsBatch::new(models.to_vec())
                };
                batch.expect("batch")
            };
            let cut = models.len() / 3;
            for avx512 in [true, false] {
                for pool in pools() {
                    let what = format!(
                        "accounted {accounted}, AVX-512 {avx512}, {} threads",
                        pool.current_num_threads()
                    );
                    let mut states = start.to_vec();
                    let batch = batch_of(models).with_avx512(avx512);
                    let failures =
                        pool.install(|| batch.integrate_rod_midpoint(&mut states, h, steps)).expect("batch");
                    let failed: Vec<(usize, String)> =
                        failures.iter().map(|f| (f.chain, f.error.to_string())).collect();
                    assert_eq!(failed, expected, "{what}");
                    // Split in two batches at `cut`.
                    let mut parts = start.to_vec();
                    let (front, back) = parts.split_at_mut(cut);
                    let (first, second) = (batch_of(&models[..cut]), batch_of(&models[cut..]));
                    pool.install(|| first.with_avx512(avx512).integrate_rod_midpoint(front, h, steps))
                        .expect("front");
                    pool.install(|| second.with_avx512(avx512).integrate_rod_midpoint(back, h, steps))
                        .expect("back");
                    for (k, ((a, b), c)) in states.iter().zip(&single).zip(&parts).enumerate() {
                        for (state, whose) in [(a, "batch"), (c, "split")] {
                            assert_same_state(state, b, &format!("{what}: chain {k}, {whose}"));
                        }
                    }
                }
            }
            halved
        }
    };
}

midpoint_helpers!(midpoint_alone_3d, midpoint_as_alone_3d, U3, Circle);
midpoint_helpers!(midpoint_alone_2d, midpoint_as_alone_2d, U2, Harmonic<U2>);

#[test]
fn rod_midpoint_steps_in_lanes_are_each_chains_own_even_where_some_chains_halve_or_fail() {
    let mut r = ChaCha8Rng::seed_from_u64(23);
    // 3D whirls of 12 links: three blocks of eight, the last one short. A step of 20 ms
    // is halved for the chains that spin fastest and taken whole in lanes for the others.
    let (models, x): (Vec<_>, Vec<_>) = (0..19).map(|_| whirl(12, &mut r)).unzip();
    for accounted in [false, true] {
        let mut start: Vec<State<Dyn>> = if accounted {
            accounted_states(&models, &x)
        } else {
            x.iter().map(|x| State::new(0.0, x.clone())).collect()
        };
        // Chains 2, 7, 13 and 17 turn by 0.95 rad in the first step, just below the most
        // a step may turn before it is halved untried: their Newton iterations fail in
        // lanes, and the chains' own integrators halve the step.
        for k in [2, 7, 13, 17] {
            let mut x = start[k].x().clone();
            let rates = 36..72;
            let fastest = x.as_slice()[rates.clone()]
                .chunks(3)
                .map(|w| w.iter().map(|v| v * v).sum::<f64>())
                .fold(0.0, f64::max);
            x.as_mut_slice()[rates].iter_mut().for_each(|w| *w *= 0.95 / (0.02 * fastest.sqrt()));
            start[k] = State::new(0.0, x);
        }
        // Chain 5 starts from a NaN; chain 11 from rates that overflow.
        let mut bad = start[5].x().clone();
        bad[7] = f64::NAN;
        start[5] = State::new(0.25, bad);
        let mut fast = start[11].x().clone();
        let half = fast.len() / 2 - if accounted { 1 } else { 0 };
        fast[half + 4] = 1e200;
        start[11] = State::new(0.5, fast);
        let halved = midpoint_as_alone_3d(&models, &start, accounted, (0.02, 6));
        let halving = halved.iter().filter(|&&h| h > 0).count();
        assert!((4..14).contains(&halving), "chains halving: {halved:?}");
    }
    // Planar chains in directions, shaken along random directions and swinging, at a
    // step of 1 ms.
    let planar: Vec<Directions<U2, Harmonic<U2>>> = (0..11)
        .map(|_| {
            let along = nalgebra::Vector2::new(r.random_range(-1.0..1.0), r.random_range(0.1..1.0));
            let (amplitude, frequency) = (r.random_range(0.0..0.05), r.random_range(1.0..10.0));
            let drive = Harmonic::new(along, amplitude, frequency, r.random_range(0.0..6.0)).expect("drive");
            Directions::<U2>::new(random_chain(7, &mut r)).with_drive(drive)
        })
        .collect();
    let start: Vec<State<Dyn>> = planar
        .iter()
        .map(|m| {
            let q: Vec<f64> = (0..7).map(|_| r.random_range(-1.0..1.0)).collect();
            let qd: Vec<f64> = (0..7).map(|_| r.random_range(-3.0..3.0)).collect();
            State::new(r.random_range(0.0..1.0), m.from_angles(&q, &qd).expect("state"))
        })
        .collect();
    for accounted in [false, true] {
        let start: Vec<State<Dyn>> = if accounted {
            let ledger = |(m, s): (&Directions<U2, Harmonic<U2>>, &State<Dyn>)| {
                State::new(s.t(), Accounted::of(m.clone()).state(s.x()).expect("state"))
            };
            planar.iter().zip(&start).map(ledger).collect()
        } else {
            start.clone()
        };
        midpoint_as_alone_2d(&planar, &start, accounted, (1e-3, 8));
    }
}

#[test]
fn rod_midpoint_runs_of_a_batch_are_each_chains_own_and_a_failure_stays_in_its_chain() {
    let mut r = ChaCha8Rng::seed_from_u64(19);
    let (chains, n, h, steps) = (6, 12, 1e-3, 10);
    let (models, x): (Vec<_>, Vec<_>) = (0..chains).map(|_| whirl(n, &mut r)).unzip();
    for accounted in [false, true] {
        let batch = if accounted {
            DirectionsBatch::accounted(models.clone())
        } else {
            DirectionsBatch::new(models.clone())
        }
        .expect("batch");
        let mut start = if accounted {
            accounted_states(&models, &x)
        } else {
            x.iter().map(|x| State::new(0.0, x.clone())).collect()
        };
        // Chain 4 starts from a NaN.
        let mut bad = start[4].x().clone();
        bad[0] = f64::NAN;
        start[4] = State::new(0.0, bad);
        let mut single = start.clone();
        let errors: Vec<Option<Error>> = models
            .iter()
            .zip(&mut single)
            .map(|(model, state)| {
                let mut step = RodMidpoint::new();
                if accounted {
                    let system = Accounted::of(model.clone());
                    (0..steps).find_map(|_| step.step(&system, state, h).err())
                } else {
                    (0..steps).find_map(|_| step.step(model, state, h).err())
                }
            })
            .collect();
        assert!(errors[4].is_some() && errors.iter().filter(|e| e.is_some()).count() == 1, "{errors:?}");
        for pool in pools() {
            let mut states = start.clone();
            let failures =
                pool.install(|| batch.integrate_rod_midpoint(&mut states, h, steps)).expect("batch");
            let what = format!("accounted {accounted}, {} threads", pool.current_num_threads());
            assert_eq!(failures.len(), 1, "{what}");
            // As text: the errors carry the NaN they found.
            let expected = errors[4].as_ref().map(ToString::to_string);
            assert_eq!((failures[0].chain, Some(failures[0].error.to_string())), (4, expected), "{what}");
            for (k, (a, b)) in states.iter().zip(&single).enumerate() {
                assert_same_state(a, b, &format!("{what}: chain {k}"));
            }
        }
    }
}
