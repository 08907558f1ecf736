//! Batches of chains (`pendulum_core::batch`): every chain of a batch gets exactly the
//! single-chain result, whatever the thread count and however the chains are split into
//! calls, and a failing chain is reported by its index while the others finish.

use std::ops::ControlFlow;

use nalgebra::{DVector, Dyn, U2, U3};
use pendulum_core::RodMidpoint;
use pendulum_core::batch::{DirectionsBatch, PlanarBatch};
use pendulum_core::integrate::{Integrator, Projected, Rk4, State};
use pendulum_core::{
    Accounted, Chain, Circle, ConstantTorque, Derivatives, Directions, Driven, Error, FirstOrder, Harmonic,
    Inputs, Jacobians, Model, PlanarTension, trajectory,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A chain of `n` links with masses, lengths and damping log-uniform over two decades and
/// gravity between 1 and 20 m/s².
fn random_chain(n: usize, r: &mut ChaCha8Rng) -> Chain<Dyn> {
    let mut decades = |lo: f64| (0..n).map(|_| 10f64.powf(lo + 2.0 * r.random::<f64>())).collect::<Vec<_>>();
    let (masses, lengths, damping) = (decades(-2.0), decades(-2.0), decades(-5.0));
    let g = r.random_range(1.0..20.0);
    Chain::new(&masses, &lengths, g).and_then(|c| c.with_damping(&damping)).expect("chain")
}

/// Every entry equal bit for bit (NaN only where NaN).
fn assert_bits(batch: &[f64], single: &[f64], what: &str) {
    assert_eq!(batch.len(), single.len(), "{what}");
    for (i, (a, b)) in batch.iter().zip(single).enumerate() {
        assert_eq!(a.to_bits(), b.to_bits(), "{what}[{i}]: batch {a:e} single {b:e}");
    }
}

fn pools() -> [rayon::ThreadPool; 2] {
    [1, 2].map(|threads| rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool"))
}

/// The planar batch as built (eight lanes where the CPU has AVX-512) and held to four
/// lanes, each with a pool of one and of two threads.
fn widths_and_pools(batch: &PlanarBatch) -> Vec<(PlanarBatch, rayon::ThreadPool)> {
    [true, false]
        .into_iter()
        .flat_map(|avx512| pools().map(|pool| (batch.clone().with_avx512(avx512), pool)))
        .collect()
}

#[test]
fn batches_run_eight_lanes_exactly_where_the_cpu_has_avx512() {
    let chain = Chain::uniform(3, 0.1, 0.2, 9.81).expect("chain");
    let planar = PlanarBatch::new(vec![chain.clone(); 5]).expect("batch");
    let spatial = DirectionsBatch::new(vec![Directions::<U3>::new(chain); 5]).expect("batch");
    #[cfg(target_arch = "x86_64")]
    for uses in [planar.uses_avx512(), spatial.uses_avx512()] {
        assert_eq!(uses, std::arch::is_x86_feature_detected!("avx512f"));
    }
    assert!(!planar.clone().with_avx512(false).uses_avx512());
    assert!(!spatial.clone().with_avx512(false).uses_avx512());
    assert_eq!(planar.clone().with_avx512(false).with_avx512(true).uses_avx512(), planar.uses_avx512());
    assert_eq!(spatial.clone().with_avx512(false).with_avx512(true).uses_avx512(), spatial.uses_avx512());
}

#[test]
fn planar_batch_equals_each_chain_alone_bit_for_bit() {
    let mut r = ChaCha8Rng::seed_from_u64(31);
    for (chains, n) in [(1, 1), (3, 2), (9, 8), (13, 20), (64, 8), (5, 100), (6, 40)] {
        let chain: Vec<_> = (0..chains).map(|_| random_chain(n, &mut r)).collect();
        let batch = PlanarBatch::new(chain.clone()).expect("batch");
        // Angles over several turns (some beyond the sine kernel's range), rates, pivots.
        let q: Vec<f64> = (0..chains * n)
            .map(|i| if i % 17 == 5 { r.random_range(-1e5..1e5) } else { r.random_range(-20.0..20.0) })
            .collect();
        let qd: Vec<f64> = (0..chains * n).map(|_| r.random_range(-10.0..10.0)).collect();
        let pivot: Vec<f64> = (0..chains * 2).map(|_| r.random_range(-30.0..30.0)).collect();
        let mut single = vec![0.0; chains * n];
        for (k, c) in chain.iter().enumerate() {
            let model = PlanarTension::new(c.clone());
            let rows = k * n..(k + 1) * n;
            let mut inputs = Inputs::<Dyn, U2>::zeros(Dyn(n));
            inputs.pivot_acceleration = nalgebra::Vector2::new(pivot[2 * k], pivot[2 * k + 1]);
            let mut out = DVector::zeros(n);
            model
                .accelerations(
                    &DVector::from_column_slice(&q[rows.clone()]),
                    &DVector::from_column_slice(&qd[rows.clone()]),
                    &inputs,
                    &mut out,
                )
                .expect("single");
            single[rows].copy_from_slice(out.as_slice());
        }
        for (batch, pool) in widths_and_pools(&batch) {
            let mut out = vec![0.0; chains * n];
            let failures =
                pool.install(|| batch.accelerations(&q, &qd, None, Some(&pivot), &mut out)).expect("batch");
            assert!(failures.is_empty(), "{failures:?}");
            let (threads, avx512) = (pool.current_num_threads(), batch.uses_avx512());
            assert_bits(
                &out,
                &single,
                &format!("{chains} chains of {n}, {threads} threads, AVX-512 {avx512}"),
            );
        }
        // Split into two calls at every block boundary and off it: the same numbers.
        let cut = chains / 2;
        if cut > 0 {
            let (a, b) = (PlanarBatch::new(chain[..cut].to_vec()), PlanarBatch::new(chain[cut..].to_vec()));
            let mut out = vec![0.0; chains * n];
            let (low, high) = out.split_at_mut(cut * n);
            a.expect("a")
                .accelerations(&q[..cut * n], &qd[..cut * n], None, Some(&pivot[..2 * cut]), low)
                .expect("a");
            b.expect("b")
                .accelerations(&q[cut * n..], &qd[cut * n..], None, Some(&pivot[2 * cut..]), high)
                .expect("b");
            assert_bits(&out, &single, "split");
        }
    }
}

#[test]
fn one_chain_repeated_is_that_chain_at_every_state() {
    let mut r = ChaCha8Rng::seed_from_u64(13);
    let (count, n) = (11, 7);
    let chain = random_chain(n, &mut r);
    let q: Vec<f64> = (0..count * n).map(|_| r.random_range(-4.0..4.0)).collect();
    let qd: Vec<f64> = (0..count * n).map(|_| r.random_range(-4.0..4.0)).collect();
    let (mut a, mut b) = (vec![0.0; count * n], vec![0.0; count * n]);
    PlanarBatch::repeated(chain.clone(), count)
        .expect("repeated")
        .accelerations(&q, &qd, None, None, &mut a)
        .expect("a");
    PlanarBatch::new(vec![chain; count])
        .expect("copies")
        .accelerations(&q, &qd, None, None, &mut b)
        .expect("b");
    assert_bits(&a, &b, "repeated");
}

#[test]
fn the_scratch_a_batch_keeps_between_calls_changes_no_result() {
    // A batch lends each call's tasks the scratch of its earlier calls: a call with torques,
    // pivots and failing chains, then one with none of them, must give what a new batch
    // gives, on one and two threads, in eight lanes and four, in f64 and f32.
    let mut r = ChaCha8Rng::seed_from_u64(17);
    let (chains, n) = (21, 30);
    let chain: Vec<_> = (0..chains).map(|_| random_chain(n, &mut r)).collect();
    let mut rows = |scale: f64| (0..chains * n).map(|_| r.random_range(-scale..scale)).collect::<Vec<f64>>();
    let (mut q1, qd1, torque, q2, qd2) = (rows(3.0), rows(5.0), rows(0.1), rows(3.0), rows(5.0));
    q1[4 * n + 3] = f64::NAN;
    let pivot: Vec<f64> = (0..2 * chains).map(|_| r.random_range(-30.0..30.0)).collect();
    let fresh = PlanarBatch::new(chain.clone()).expect("batch");
    for (batch, pool) in widths_and_pools(&fresh) {
        let mut out = vec![0.0; chains * n];
        let first = pool.install(|| batch.accelerations(&q1, &qd1, Some(&torque), Some(&pivot), &mut out));
        assert_eq!(first.expect("first").iter().map(|f| f.chain).collect::<Vec<_>>(), [4]);
        assert!(pool.install(|| batch.accelerations(&q2, &qd2, None, None, &mut out)).expect("b").is_empty());
        let mut new = vec![0.0; chains * n];
        let unused = fresh.clone().with_avx512(batch.uses_avx512());
        assert!(unused.accelerations(&q2, &qd2, None, None, &mut new).expect("new").is_empty());
        assert_bits(&out, &new, &format!("{} threads", pool.current_num_threads()));
    }
    let single = |v: &[f64]| v.iter().map(|&x| x as f32).collect::<Vec<f32>>();
    let (q1, qd1, q2, qd2) = (single(&q1), single(&qd1), single(&q2), single(&qd2));
    let (mut out, mut new) = (vec![0.0f32; chains * n], vec![0.0f32; chains * n]);
    let batch = fresh.clone();
    assert_eq!(batch.accelerations_f32(&q1, &qd1, None, &mut out).expect("first").len(), 1);
    assert!(batch.accelerations_f32(&q2, &qd2, None, &mut out).expect("second").is_empty());
    assert!(fresh.clone().accelerations_f32(&q2, &qd2, None, &mut new).expect("new").is_empty());
    assert_eq!(
        out.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
        new.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
    );
    // The whirls' accelerations at two states, against a new batch at the second.
    let (models, x): (Vec<_>, Vec<_>) = (0..chains).map(|_| whirl(8, &mut r)).unzip();
    let spatial = DirectionsBatch::new(models).expect("batch");
    let flat = |k: usize| {
        x.iter().flat_map(|x| x.iter().map(move |v| v * (1.0 + 0.1 * k as f64))).collect::<Vec<f64>>()
    };
    let half = chains * spatial.state_len() / 2;
    let (mut out, mut new) = (vec![0.0; half], vec![0.0; half]);
    for (t, k) in [(0.1, 0), (0.7, 1)] {
        assert!(spatial.accelerations(t, &flat(k), &mut out).expect("batch").is_empty());
    }
    assert!(spatial.clone().accelerations(0.7, &flat(1), &mut new).expect("new").is_empty());
    assert_bits(&out, &new, "directions");
}

#[test]
fn a_failing_chain_is_named_and_the_others_finish() {
    let mut r = ChaCha8Rng::seed_from_u64(7);
    let (chains, n) = (10, 6);
    let batch = PlanarBatch::new((0..chains).map(|_| random_chain(n, &mut r)).collect()).expect("batch");
    let mut q: Vec<f64> = (0..chains * n).map(|_| r.random_range(-3.0..3.0)).collect();
    let qd = vec![0.5; chains * n];
    for batch in [batch.clone(), batch.with_avx512(false)] {
        a_failing_chain_in(&batch, &mut q, &qd);
    }
}

/// [`a_failing_chain_is_named_and_the_others_finish`] for one batch of 10 chains of 6.
fn a_failing_chain_in(batch: &PlanarBatch, q: &mut [f64], qd: &[f64]) {
    let (chains, n) = (10, 6);
    let mut clean = vec![0.0; chains * n];
    let (nan, inf) = (q[5 * n + 2], q[9 * n]);
    assert!(batch.accelerations(q, qd, None, None, &mut clean).expect("clean").is_empty());
    q[5 * n + 2] = f64::NAN;
    q[9 * n] = f64::INFINITY;
    let mut out = vec![0.0; chains * n];
    let failures = batch.accelerations(q, qd, None, None, &mut out).expect("batch");
    (q[5 * n + 2], q[9 * n]) = (nan, inf);
    let said: Vec<_> = failures.iter().map(|f| f.to_string()).collect();
    assert_eq!(said, ["chain 5: q[2] must be finite, got NaN", "chain 9: q[0] must be finite, got inf"]);
    assert_eq!(failures.iter().map(|f| f.chain).collect::<Vec<_>>(), [5, 9]);
    for k in 0..chains {
        let row = k * n..(k + 1) * n;
        if k == 5 || k == 9 {
            assert!(out[row].iter().all(|v| v.is_nan()));
        } else {
            assert_bits(&out[row.clone()], &clean[row], &format!("chain {k}"));
        }
    }
}

#[test]
fn batches_need_chains_of_one_length_and_whole_rows() {
    let mut r = ChaCha8Rng::seed_from_u64(3);
    let err = PlanarBatch::new(vec![random_chain(4, &mut r), random_chain(5, &mut r)]).unwrap_err();
    assert_eq!(err.to_string(), "chain 1 of the batch has 5 links, chain 0 has 4");
    assert_eq!(PlanarBatch::new(vec![]).unwrap_err(), Error::EmptyBatch);
    let batch = PlanarBatch::new(vec![random_chain(4, &mut r); 3]).expect("batch");
    let err = batch.accelerations(&[0.0; 11], &[0.0; 12], None, None, &mut [0.0; 12]).unwrap_err();
    assert_eq!(err.to_string(), "q has 11 entries, expected 12");
}

/// A whirl-like 3D chain: uniform random links, its pivot on a circle of random radius and
/// speed, from a tilted swinging state.
fn whirl(n: usize, r: &mut ChaCha8Rng) -> (Directions<U3, Circle>, DVector<f64>) {
    let chain = random_chain(n, r);
    let drive = Circle::new(r.random_range(0.0..0.05), r.random_range(1.0..10.0)).expect("drive");
    let model = Directions::<U3>::new(chain).with_drive(drive);
    let x = whirl_state(&model, n, r);
    (model, x)
}

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

/// A state of `model` (a whirl of `n` links) at random spherical angles and rates.
fn whirl_state(model: &Directions<U3, Circle>, n: usize, r: &mut ChaCha8Rng) -> DVector<f64> {
    let q: Vec<f64> =
        (0..2 * n).map(|i| if i < n { r.random_range(0.1..1.0) } else { r.random_range(0.0..6.0) }).collect();
    let qd: Vec<f64> = (0..2 * n).map(|_| r.random_range(-1.0..1.0)).collect();
    model.from_spherical(&q, &qd).expect("state")
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
                    assert_eq!(s.t().to_bits(), b.t().to_bits());
                    assert_bits(s.x().as_slice(), b.x().as_slice(), &format!("chain {k} of {chains}×{n}"));
                    assert_bits(s.compensation().as_slice(), b.compensation().as_slice(), "compensation");
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

/// `steps` steps of RK4 of the planar chain alone with `inputs` held (none: free), from
/// `start`: the state, and the time of the step that failed.
fn planar_rk4_alone(
    chain: &Chain<Dyn>,
    inputs: Option<Inputs<Dyn, U2>>,
    start: &State<Dyn>,
    h: f64,
    steps: usize,
) -> (State<Dyn>, Option<f64>) {
    let inputs = inputs.unwrap_or_else(|| Inputs::zeros(Dyn(chain.links())));
    let system = FirstOrder::with_inputs(PlanarTension::new(chain.clone()), inputs);
    let (mut state, mut rk4) = (start.clone(), Rk4::new(&system));
    for _ in 0..steps {
        let t = state.t();
        if rk4.step(&system, &mut state, h).is_err() {
            return (state, Some(t));
        }
    }
    (state, None)
}

#[test]
fn planar_rk4_runs_of_a_batch_equal_each_chain_alone_bit_for_bit() {
    let mut r = ChaCha8Rng::seed_from_u64(41);
    for (chains, n) in [(1, 1), (6, 3), (9, 20), (5, 100)] {
        let chain: Vec<_> = (0..chains).map(|_| random_chain(n, &mut r)).collect();
        let batch = PlanarBatch::new(chain.clone()).expect("batch");
        // Chains at different times, swinging from angles over several turns.
        let start: Vec<State<Dyn>> = (0..chains)
            .map(|k| {
                let x = (0..2 * n)
                    .map(|i| if i < n { r.random_range(-8.0..8.0) } else { r.random_range(-3.0..3.0) });
                State::new(0.1 * k as f64, DVector::from_iterator(2 * n, x))
            })
            .collect();
        // Torques on two chains in three (both kinds in one block), pivots accelerating.
        let torque: Vec<f64> =
            (0..chains * n).map(|i| if (i / n) % 3 == 1 { 0.0 } else { r.random_range(-0.1..0.1) }).collect();
        let pivot: Vec<f64> = (0..chains * 2).map(|_| r.random_range(-30.0..30.0)).collect();
        let inputs = |k: usize| {
            let mut inputs = Inputs::<Dyn, U2>::zeros(Dyn(n));
            inputs.torque.copy_from_slice(&torque[k * n..(k + 1) * n]);
            inputs.pivot_acceleration = nalgebra::Vector2::new(pivot[2 * k], pivot[2 * k + 1]);
            inputs
        };
        let h = 1e-4;
        let driven: Vec<_> =
            (0..chains).map(|k| planar_rk4_alone(&chain[k], Some(inputs(k)), &start[k], h, 30)).collect();
        let free: Vec<_> = (0..chains).map(|k| planar_rk4_alone(&chain[k], None, &start[k], h, 30)).collect();
        let (torque, pivot) = (Some(&torque[..]), Some(&pivot[..]));
        for (batch, pool) in widths_and_pools(&batch) {
            // 30 steps in one call, 10 calls of 3, the batch split in two; and free chains.
            let mut run = start.clone();
            assert!(
                pool.install(|| batch.integrate_rk4(&mut run, torque, pivot, h, 30))
                    .expect("batch")
                    .is_empty()
            );
            let mut calls = start.clone();
            for _ in 0..10 {
                let failures =
                    pool.install(|| batch.integrate_rk4(&mut calls, torque, pivot, h, 3)).expect("batch");
                assert!(failures.is_empty(), "{failures:?}");
            }
            let mut halves = start.clone();
            let cut = chains / 2;
            let (first, second) = halves.split_at_mut(cut);
            for (range, states) in [(0..cut, first), (cut..chains, second)] {
                if !range.is_empty() {
                    let half = PlanarBatch::new(chain[range.clone()].to_vec())
                        .expect("half")
                        .with_avx512(batch.uses_avx512());
                    let (t, p) = (
                        &torque.unwrap()[range.start * n..range.end * n],
                        &pivot.unwrap()[2 * range.start..2 * range.end],
                    );
                    assert!(
                        pool.install(|| half.integrate_rk4(states, Some(t), Some(p), h, 30))
                            .expect("batch")
                            .is_empty()
                    );
                }
            }
            let mut unforced = start.clone();
            assert!(
                pool.install(|| batch.integrate_rk4(&mut unforced, None, None, h, 30))
                    .expect("batch")
                    .is_empty()
            );
            for k in 0..chains {
                assert_eq!((driven[k].1, free[k].1), (None, None), "chain {k}");
                for (s, alone) in [
                    (&run[k], &driven[k].0),
                    (&calls[k], &driven[k].0),
                    (&halves[k], &driven[k].0),
                    (&unforced[k], &free[k].0),
                ] {
                    assert_eq!(s.t().to_bits(), alone.t().to_bits(), "chain {k}");
                    assert_bits(
                        s.x().as_slice(),
                        alone.x().as_slice(),
                        &format!("chain {k} of {chains}×{n}"),
                    );
                    assert_bits(s.compensation().as_slice(), alone.compensation().as_slice(), "compensation");
                }
            }
        }
    }
}

#[test]
fn driven_planar_runs_of_a_batch_equal_each_chain_alone_bit_for_bit() {
    // Each chain's pivot shaken along its own line (Kapitza's vertical among them), read at
    // every stage's time, against `Rk4` on `FirstOrder::with_inputs(PlanarTension, Driven)`.
    let mut r = ChaCha8Rng::seed_from_u64(43);
    let (h, steps) = (1e-4, 30);
    for (chains, n) in [(1, 2), (7, 5), (10, 30)] {
        let chain: Vec<_> = (0..chains).map(|_| random_chain(n, &mut r)).collect();
        let drives: Vec<Harmonic<U2>> = (0..chains)
            .map(|k| {
                let direction =
                    nalgebra::Vector2::new(if k % 3 == 0 { 0.0 } else { r.random_range(-1.0..1.0) }, 1.0);
                let (a, w, phase) =
                    (r.random_range(0.0..0.01), r.random_range(10.0..400.0), r.random::<f64>());
                Harmonic::new(direction, a, w, phase).expect("drive")
            })
            .collect();
        let start: Vec<State<Dyn>> = (0..chains)
            .map(|k| {
                let x = (0..2 * n)
                    .map(|i| if i < n { r.random_range(-3.0..3.0) } else { r.random_range(-2.0..2.0) });
                State::new(0.013 * k as f64, DVector::from_iterator(2 * n, x))
            })
            .collect();
        let torque: Vec<f64> = (0..chains * n)
            .map(|i| if (i / n) % 2 == 1 { 0.0 } else { r.random_range(-0.05..0.05) })
            .collect();
        for with_torque in [false, true] {
            let alone: Vec<State<Dyn>> = (0..chains)
                .map(|k| {
                    let q = DVector::from_column_slice(&torque[k * n..(k + 1) * n]);
                    let q = if with_torque { q } else { DVector::zeros(n) };
                    let inputs = Driven::new(drives[k].clone(), ConstantTorque(q));
                    let system = FirstOrder::with_inputs(PlanarTension::new(chain[k].clone()), inputs);
                    let (mut state, mut rk4) = (start[k].clone(), Rk4::new(&system));
                    for _ in 0..steps {
                        rk4.step(&system, &mut state, h).expect("alone");
                    }
                    state
                })
                .collect();
            let torque = with_torque.then_some(&torque[..]);
            let batch = PlanarBatch::new(chain.clone()).expect("batch");
            for (batch, pool) in widths_and_pools(&batch) {
                let what = format!(
                    "{chains} chains of {n}, torques {with_torque}, {} threads",
                    pool.current_num_threads()
                );
                // One call of 30 steps, and three of 10.
                let mut once = start.clone();
                let failures =
                    pool.install(|| batch.integrate_rk4_driven(&mut once, &drives, torque, h, steps));
                assert!(failures.expect("run").is_empty(), "{what}");
                let mut thrice = start.clone();
                for _ in 0..3 {
                    let failures =
                        pool.install(|| batch.integrate_rk4_driven(&mut thrice, &drives, torque, h, 10));
                    assert!(failures.expect("run").is_empty(), "{what}");
                }
                for ((a, b), c) in once.iter().zip(&thrice).zip(&alone) {
                    for s in [a, b] {
                        assert_eq!(s.t().to_bits(), c.t().to_bits(), "{what}: t");
                        assert_bits(s.x().as_slice(), c.x().as_slice(), &format!("{what}: x"));
                    }
                }
            }
        }
    }
    // A drive whose acceleration is not finite fails its chain alone; too few drives is an
    // error.
    let chain: Vec<_> = (0..3).map(|_| random_chain(4, &mut r)).collect();
    let batch = PlanarBatch::new(chain).expect("batch");
    let drives: Vec<Harmonic<U2>> = [1e300, 0.01, 0.01]
        .into_iter()
        .map(|w| Harmonic::new(nalgebra::Vector2::new(0.0, 1.0), 1.0, w, 0.3).expect("drive"))
        .collect();
    let mut states: Vec<State<Dyn>> =
        (0..3).map(|_| State::new(0.0, DVector::from_element(8, 0.5))).collect();
    let failures = batch.integrate_rk4_driven(&mut states, &drives, None, 1e-3, 5).expect("run");
    assert_eq!(failures.iter().map(|f| f.chain).collect::<Vec<_>>(), [0]);
    assert!(matches!(failures[0].error, Error::NonFiniteState { .. }), "{:?}", failures[0]);
    assert_eq!(states[0].x().as_slice(), &[0.5; 8], "the failed chain stays at its start");
    assert!(states[1].t() > 0.0 && states[2].x()[0] != 0.5);
    assert!(matches!(
        batch.integrate_rk4_driven(&mut states, &drives[..2], None, 1e-3, 5),
        Err(Error::LengthMismatch { what: "drives", expected: 3, got: 2 })
    ));
}

#[test]
fn a_planar_chain_that_fails_stops_at_its_last_good_state_and_the_others_run_on() {
    let mut r = ChaCha8Rng::seed_from_u64(43);
    let n = 6;
    let chain: Vec<_> = (0..7).map(|_| random_chain(n, &mut r)).collect();
    let x = |rate: f64| State::new(0.0, DVector::from_fn(2 * n, |i, _| if i < n { 0.4 } else { rate }));
    let mut start: Vec<State<Dyn>> = (0..7).map(|_| x(0.5)).collect();
    // Chain 1 starts with a NaN, chain 3 with an infinite torque; chain 5 spins so fast that
    // RK4 at this step diverges.
    let mut bad = start[1].x().clone();
    bad[n + 2] = f64::NAN;
    start[1] = State::new(0.0, bad.clone());
    start[5] = x(1e150);
    let mut torque = vec![0.0; 7 * n];
    torque[3 * n + 4] = f64::INFINITY;
    let h = 1e-3;
    for avx512 in [true, false] {
        let batch = PlanarBatch::new(chain.clone()).expect("batch").with_avx512(avx512);
        a_planar_chain_that_fails_in(&batch, &chain, (&start, &bad, &torque), h);
    }
}

/// [`a_planar_chain_that_fails_stops_at_its_last_good_state_and_the_others_run_on`] for one
/// batch of 7 chains of 6, from `start` (chain 1's state is `bad`).
fn a_planar_chain_that_fails_in(
    batch: &PlanarBatch,
    chain: &[Chain<Dyn>],
    (start, bad, torque): (&[State<Dyn>], &DVector<f64>, &[f64]),
    h: f64,
) {
    let n = 6;
    let mut states = start.to_vec();
    let failures = batch.integrate_rk4(&mut states, Some(torque), None, h, 40).expect("batch");
    assert_eq!(failures.iter().map(|f| f.chain).collect::<Vec<_>>(), [1, 3, 5], "{failures:?}");
    let said = |k: usize| failures[k].error.to_string();
    assert_eq!(said(0), Error::NonFinite { what: "x", index: n + 2, value: f64::NAN }.to_string());
    assert_eq!(said(1), Error::NonFinite { what: "torque", index: 4, value: f64::INFINITY }.to_string());
    assert_bits(states[1].x().as_slice(), bad.as_slice(), "the chain that never started");
    assert_bits(states[3].x().as_slice(), start[3].x().as_slice(), "the chain that never started");
    let Error::NonFiniteState { t, .. } = failures[2].error else { panic!("{failures:?}") };
    let (alone, failed) = planar_rk4_alone(&chain[5], None, &start[5], h, 40);
    assert_eq!(failed.map(f64::to_bits), Some(t.to_bits()), "the same step fails alone");
    assert_bits(states[5].x().as_slice(), alone.x().as_slice(), "the blown chain");
    for k in [0, 2, 4, 6] {
        let (alone, _) = planar_rk4_alone(&chain[k], None, &start[k], h, 40);
        assert_bits(states[k].x().as_slice(), alone.x().as_slice(), &format!("chain {k}"));
    }
    let nan = batch.integrate_rk4(&mut states, None, None, f64::NAN, 1).unwrap_err();
    assert_eq!(nan.to_string(), Error::InvalidStepSize { h: f64::NAN }.to_string());
    assert_eq!(
        batch.integrate_rk4(&mut states[..3], None, None, h, 1).unwrap_err(),
        Error::LengthMismatch { what: "states", expected: 7, got: 3 }
    );
    assert_eq!(
        batch.integrate_rk4(&mut states, Some(&torque[1..]), None, h, 1).unwrap_err(),
        Error::LengthMismatch { what: "torque", expected: 7 * n, got: 7 * n - 1 }
    );
}

#[test]
fn batched_jacobians_are_each_chains_own_bit_for_bit_and_a_failure_stays_in_its_chain() {
    let mut r = ChaCha8Rng::seed_from_u64(77);
    for (chains, n) in [(1, 1), (5, 8), (37, 20)] {
        let chain: Vec<_> = (0..chains).map(|_| random_chain(n, &mut r)).collect();
        let batch = PlanarBatch::new(chain.clone()).expect("batch");
        let mut q: Vec<f64> = (0..chains * n).map(|_| r.random_range(-20.0..20.0)).collect();
        let qd: Vec<f64> = (0..chains * n).map(|_| r.random_range(-10.0..10.0)).collect();
        let pivot: Vec<f64> = (0..chains * 2).map(|_| r.random_range(-30.0..30.0)).collect();
        let bad = chains / 2;
        q[bad * n] = f64::NAN;
        let (mut single_q, mut single_qd) = (vec![0.0; chains * n * n], vec![0.0; chains * n * n]);
        for (k, c) in chain.iter().enumerate() {
            let model = PlanarTension::new(c.clone());
            let rows = k * n..(k + 1) * n;
            let mut inputs = Inputs::<Dyn, U2>::zeros(Dyn(n));
            inputs.pivot_acceleration = nalgebra::Vector2::new(pivot[2 * k], pivot[2 * k + 1]);
            let mut out = Jacobians::zeros(&model);
            let result = model.state_jacobians(
                &DVector::from_column_slice(&q[rows.clone()]),
                &DVector::from_column_slice(&qd[rows]),
                &inputs,
                &mut out,
            );
            assert_eq!(result.is_err(), k == bad, "chain {k}");
            let block = k * n * n..(k + 1) * n * n;
            if k == bad {
                single_q[block.clone()].fill(f64::NAN);
                single_qd[block].fill(f64::NAN);
                continue;
            }
            for a in 0..n {
                for b in 0..n {
                    single_q[block.start + a * n + b] = out.q[(a, b)];
                    single_qd[block.start + a * n + b] = out.qd[(a, b)];
                }
            }
        }
        for pool in pools() {
            let (mut dq, mut dqd) = (vec![0.0; chains * n * n], vec![0.0; chains * n * n]);
            let failures = pool
                .install(|| batch.state_jacobians(&q, &qd, Some(&pivot), &mut dq, &mut dqd))
                .expect("batch");
            let what = format!("{chains} chains of {n}, {} threads", pool.current_num_threads());
            assert_eq!(failures.len(), 1, "{what}");
            assert_eq!(failures[0].chain, bad, "{what}");
            assert_eq!(failures[0].error.to_string(), "q[0] must be finite, got NaN", "{what}");
            assert_bits(&dq, &single_q, &format!("{what}: ∂θ̈/∂θ"));
            assert_bits(&dqd, &single_qd, &format!("{what}: ∂θ̈/∂θ̇"));
        }
    }
}

#[test]
fn batched_direction_jacobians_are_each_models_own_bit_for_bit_and_failures_stay_in_their_chain() {
    let mut r = ChaCha8Rng::seed_from_u64(78);
    for (chains, n) in [(1, 1), (6, 4), (23, 12)] {
        let (models, x): (Vec<_>, Vec<_>) = (0..chains).map(|_| whirl(n, &mut r)).unzip();
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
        for pool in pools() {
            let what = format!("{chains} chains of {n}, {} threads", pool.current_num_threads());
            let (mut du, mut dw) = (vec![0.0; chains * block], vec![0.0; chains * block]);
            let failures =
                pool.install(|| batch.state_jacobians(t, &joined, &mut du, &mut dw)).expect("joined");
            assert_bits(&du, &single_u, &format!("{what}: ∂ü/∂u"));
            assert_bits(&dw, &single_w, &format!("{what}: ∂ü/∂w"));
            if chains > 2 {
                assert_eq!(failures.iter().map(|f| f.chain).collect::<Vec<_>>(), [nan, huge], "{what}");
                assert_eq!(failures[0].error.to_string(), format!("x[{}] must be finite, got NaN", half + 1));
                assert!(matches!(failures[1].error, Error::NotPositiveDefinite), "{:?}", failures[1]);
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
                assert_eq!(a.t().to_bits(), b.t().to_bits(), "{what}: chain {k}'s t");
                assert_bits(a.x().as_slice(), b.x().as_slice(), &format!("{what}: chain {k}"));
                assert_bits(a.compensation().as_slice(), b.compensation().as_slice(), "compensation");
            }
        }
    }
}

/// `chains` whirls of `n` links whose masses, lengths and damping span `decades` decades
/// (`spread_chain`), each pivot on its own circle of 0.5–5 cm at 1–10 rad/s, and their
/// states as rows of `(u, w)`: random tilts, azimuths and rates (±5 rad/s).
fn spread_whirls(
    n: usize,
    decades: f64,
    chains: usize,
    r: &mut ChaCha8Rng,
) -> (Vec<Directions<U3, Circle>>, Vec<f64>) {
    let models: Vec<_> = (0..chains)
        .map(|_| {
            let chain = spread_chain(n, decades, r);
            let drive = Circle::new(r.random_range(0.005..0.05), r.random_range(1.0..10.0)).expect("drive");
            Directions::<U3>::new(chain).with_drive(drive)
        })
        .collect();
    let x: Vec<f64> = models
        .iter()
        .flat_map(|m| {
            let q: Vec<f64> = (0..2 * n)
                .map(|i| if i < n { r.random_range(0.1..3.0) } else { r.random_range(0.0..6.3) })
                .collect();
            let qd: Vec<f64> = (0..2 * n).map(|_| r.random_range(-5.0..5.0)).collect();
            m.from_spherical(&q, &qd).expect("state").as_slice().to_vec()
        })
        .collect();
    (models, x)
}

/// `max |ü₃₂ − ü₆₄| / max |ü₆₄|` of each chain of whirls of `n` links whose masses, lengths
/// and damping span `decades` decades, at random states: the worst of `chains`.
fn single_precision_error(n: usize, decades: f64, chains: usize, r: &mut ChaCha8Rng) -> f64 {
    let (models, x) = spread_whirls(n, decades, chains, r);
    let batch = DirectionsBatch::new(models).expect("batch");
    let t = r.random_range(0.0..10.0);
    let (mut out64, mut out32) = (vec![0.0; chains * 3 * n], vec![0.0f32; chains * 3 * n]);
    assert!(batch.accelerations(t, &x, &mut out64).expect("f64").is_empty());
    let x32: Vec<f32> = x.iter().map(|&v| v as f32).collect();
    assert!(batch.accelerations_f32(t, &x32, &mut out32).expect("f32").is_empty());
    worst_relative_error(&out64, &out32, 3 * n)
}

#[test]
fn single_precision_directions_are_within_their_documented_error() {
    // The bounds of docs/ensembles.md ("Single precision"); `--nocapture` prints the errors.
    let mut r = ChaCha8Rng::seed_from_u64(47);
    for (decades, bound) in [(0.3, 5e-6), (1.0, 5e-6), (2.0, 1e-5), (3.0, 1e-4)] {
        for n in [8, 20, 100] {
            let error = single_precision_error(n, decades, 200, &mut r);
            println!("spread 10^{decades}, n = {n}: {error:.1e}");
            assert!(error < bound, "spread 10^{decades}, n = {n}: {error:e} ≥ {bound:e}");
        }
    }
}

#[test]
fn single_precision_directions_fail_by_chain_and_change_with_no_thread_count_or_split() {
    let mut r = ChaCha8Rng::seed_from_u64(48);
    let (n, chains) = (12, 19);
    let (models, x): (Vec<_>, Vec<_>) = (0..chains).map(|_| whirl(n, &mut r)).unzip();
    let mut x: Vec<f32> = x.iter().flat_map(|x| x.iter().map(|&v| v as f32)).collect();
    let m = 6 * n;
    x[3 * m + 5] = f32::NAN;
    // A rate whose square leaves f32: finite input, overflow in the solve.
    x[11 * m + 3 * n + 1] = 3e19;
    let batch = DirectionsBatch::new(models.clone()).expect("batch");
    let mut runs = Vec::new();
    for pool in pools() {
        let mut out = vec![0.0f32; chains * 3 * n];
        let failures = pool.install(|| batch.accelerations_f32(1.5, &x, &mut out)).expect("f32");
        assert_eq!(failures.iter().map(|f| f.chain).collect::<Vec<_>>(), [3, 11]);
        // NaN is not equal to itself: the error named by its fields.
        assert!(matches!(failures[0].error, Error::NonFinite { what: "x", index: 5, .. }));
        assert_eq!(failures[1].error, Error::SinglePrecisionOverflow);
        for (k, row) in out.chunks_exact(3 * n).enumerate() {
            assert_eq!(row.iter().all(|v| v.is_nan()), k == 3 || k == 11, "chain {k}");
        }
        runs.push(out);
    }
    assert_eq!(
        runs[0].iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
        runs[1].iter().map(|v| v.to_bits()).collect::<Vec<_>>()
    );
    // Each chain alone in a batch of its own: the same bits.
    for k in [0, 7, 18] {
        let alone = DirectionsBatch::new(vec![models[k].clone()]).expect("batch");
        let mut out = vec![0.0f32; 3 * n];
        assert!(alone.accelerations_f32(1.5, &x[k * m..(k + 1) * m], &mut out).expect("f32").is_empty());
        let row = &runs[0][k * 3 * n..(k + 1) * 3 * n];
        assert_eq!(
            out.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            row.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            "chain {k}"
        );
    }
}

#[test]
fn single_precision_direction_runs_follow_the_f64_ones_and_fail_by_chain() {
    // Whirls of 10 g, 1 cm links spread by up to a factor of 2, each pivot circling at
    // 0.5–5 cm and 1–10 rad/s, from random swinging states: steps of 0.1 ms from
    // t0 = 1.3 s in f32 against `integrate_rk4` (the bounds of docs/ensembles.md;
    // `--nocapture` prints the errors), the rods of unit length to f32's rounding, one
    // thread or two and one chain alone the same bits.
    let mut r = ChaCha8Rng::seed_from_u64(54);
    let (chains, h, t0) = (64, 1e-4, 1.3);
    for (steps, bound) in [(100, 5e-6), (1000, 3e-5)] {
        for n in [8, 20, 100] {
            let (models, x) = spread_whirls(n, 0.3, chains, &mut r);
            let m = 6 * n;
            let batch = DirectionsBatch::new(models.clone()).expect("batch");
            let mut states: Vec<State<Dyn>> =
                x.chunks_exact(m).map(|x| State::new(t0, DVector::from_column_slice(x))).collect();
            assert!(batch.integrate_rk4(&mut states, h, steps).expect("f64").is_empty());
            let f64s: Vec<f64> = states.iter().flat_map(|s| s.x().iter().copied()).collect();
            let start: Vec<f32> = x.iter().map(|&v| v as f32).collect();
            let mut runs = Vec::new();
            for pool in pools() {
                let mut x32 = start.clone();
                assert!(
                    pool.install(|| batch.integrate_rk4_f32(&mut x32, t0, h, steps)).expect("f32").is_empty()
                );
                runs.push(x32);
            }
            assert!(
                runs[0].iter().zip(&runs[1]).all(|(a, b)| a.to_bits() == b.to_bits()),
                "one thread or two"
            );
            let error = worst_relative_error(&f64s, &runs[0], m);
            let unit = runs[0]
                .chunks_exact(m)
                .flat_map(|x| x[..3 * n].chunks_exact(3))
                .map(|u| (u.iter().map(|&v| f64::from(v) * f64::from(v)).sum::<f64>().sqrt() - 1.0).abs())
                .fold(0.0, f64::max);
            println!(
                "directions run in f32, {steps} steps of {h} s, n = {n}: {error:.1e}, |u| − 1 ≤ {unit:.1e}"
            );
            assert!(error < bound, "{steps} steps, n = {n}: {error:e} ≥ {bound:e}");
            assert!(unit < 1e-6, "n = {n}: |u| − 1 = {unit:e}");
            let k = 29;
            let alone = DirectionsBatch::new(vec![models[k].clone()]).expect("batch");
            let mut x32 = start[k * m..(k + 1) * m].to_vec();
            assert!(alone.integrate_rk4_f32(&mut x32, t0, h, steps).expect("f32").is_empty());
            assert!(
                x32.iter().zip(&runs[0][k * m..]).all(|(a, b)| a.to_bits() == b.to_bits()),
                "chain {k} alone"
            );
        }
    }
    // A NaN state fails before any step, a pivot whose acceleration leaves f32's range at
    // its first step; the others run on; bad arguments are errors.
    let n = 5;
    let models: Vec<_> = [0.02, 1e30, 0.02, 0.02]
        .into_iter()
        .map(|radius| {
            let drive = Circle::new(radius, 3.0).expect("drive");
            Directions::<U3>::new(spread_chain(n, 0.3, &mut r)).with_drive(drive)
        })
        .collect();
    let batch = DirectionsBatch::new(models).expect("batch");
    let m = 6 * n;
    let mut x: Vec<f32> =
        (0..4).flat_map(|_| [[0.0, 0.6, -0.8]; 5].concat().into_iter().chain([0.1; 15])).collect();
    x[2 * m + 4] = f32::NAN;
    let before = x.clone();
    let failures = batch.integrate_rk4_f32(&mut x, 0.5, 1e-3, 10).expect("run");
    assert_eq!(failures.iter().map(|f| f.chain).collect::<Vec<_>>(), [1, 2]);
    assert_eq!(failures[0].error, Error::NonFiniteState { t: 0.5, h: 1e-3 });
    assert!(matches!(failures[1].error, Error::NonFinite { what: "x", index: 4, .. }));
    for k in [1, 2] {
        let same =
            x[k * m..(k + 1) * m].iter().zip(&before[k * m..]).all(|(a, b)| a.to_bits() == b.to_bits());
        assert!(same, "chain {k} is left where it was");
    }
    assert!(x[..m] != before[..m] && x[3 * m..] != before[3 * m..]);
    assert!(matches!(
        batch.integrate_rk4_f32(&mut x[..m], 0.0, 1e-3, 1),
        Err(Error::LengthMismatch { what: "x", .. })
    ));
    assert!(matches!(batch.integrate_rk4_f32(&mut x, 0.0, 0.0, 1), Err(Error::InvalidStepSize { .. })));
    assert!(matches!(
        batch.integrate_rk4_f32(&mut x, f64::INFINITY, 1e-3, 1),
        Err(Error::NonFinite { what: "t0", .. })
    ));
}

/// Chains of `n` links whose masses, lengths and damping are spread over `decades`
/// decades around 10 g, 1 cm and 1e-4 N·m·s, with gravity 9.81 m/s².
fn spread_chain(n: usize, decades: f64, r: &mut ChaCha8Rng) -> Chain<Dyn> {
    let mut spread =
        |lo: f64| (0..n).map(|_| 10f64.powf(lo + decades * r.random::<f64>())).collect::<Vec<_>>();
    let (masses, lengths, damping) = (spread(-2.0), spread(-2.0), spread(-4.0));
    Chain::new(&masses, &lengths, 9.81).and_then(|c| c.with_damping(&damping)).expect("chain")
}

/// The worst over rows of `max |a₃₂ − a₆₄| / max |a₆₄|` (rows of `m`).
fn worst_relative_error(f64s: &[f64], f32s: &[f32], m: usize) -> f64 {
    f64s.chunks_exact(m)
        .zip(f32s.chunks_exact(m))
        .map(|(a, b)| {
            let scale = a.iter().fold(0.0f64, |s, v| s.max(v.abs()));
            a.iter().zip(b).fold(0.0f64, |e, (a, &b)| e.max((a - f64::from(b)).abs())) / scale
        })
        .fold(0.0, f64::max)
}

#[test]
fn single_precision_planar_chains_are_within_their_documented_error() {
    // The bounds of docs/ensembles.md ("Single precision"); `--nocapture` prints the errors.
    let mut r = ChaCha8Rng::seed_from_u64(49);
    let chains = 200;
    for (decades, bound) in [(0.3, 1e-5), (1.0, 1e-5), (2.0, 5e-5)] {
        for n in [8, 20, 100] {
            let batch = PlanarBatch::new((0..chains).map(|_| spread_chain(n, decades, &mut r)).collect())
                .expect("batch");
            let q: Vec<f64> = (0..chains * n).map(|_| r.random_range(-3.0..3.0)).collect();
            let qd: Vec<f64> = (0..chains * n).map(|_| r.random_range(-5.0..5.0)).collect();
            let pivot: Vec<f64> = (0..chains * 2).map(|_| r.random_range(-30.0..30.0)).collect();
            let (mut out64, mut out32) = (vec![0.0; chains * n], vec![0.0f32; chains * n]);
            assert!(batch.accelerations(&q, &qd, None, Some(&pivot), &mut out64).expect("f64").is_empty());
            let narrow = |v: &[f64]| v.iter().map(|&x| x as f32).collect::<Vec<_>>();
            let (q, qd, pivot) = (narrow(&q), narrow(&qd), narrow(&pivot));
            assert!(batch.accelerations_f32(&q, &qd, Some(&pivot), &mut out32).expect("f32").is_empty());
            let error = worst_relative_error(&out64, &out32, n);
            println!("planar, spread 10^{decades}, n = {n}: {error:.1e}");
            assert!(error < bound, "spread 10^{decades}, n = {n}: {error:e} ≥ {bound:e}");
        }
    }
}

#[test]
fn single_precision_planar_chains_fail_by_chain_and_change_with_no_thread_count_or_split() {
    let mut r = ChaCha8Rng::seed_from_u64(50);
    let (n, chains) = (10, 21);
    let list: Vec<_> = (0..chains).map(|_| spread_chain(n, 1.0, &mut r)).collect();
    let mut q: Vec<f32> = (0..chains * n).map(|_| r.random_range(-3.0..3.0)).collect();
    let mut qd: Vec<f32> = (0..chains * n).map(|_| r.random_range(-5.0..5.0)).collect();
    q[4 * n + 2] = f32::INFINITY;
    qd[13 * n + 7] = 3e19;
    let batch = PlanarBatch::new(list.clone()).expect("batch");
    let mut runs = Vec::new();
    for pool in pools() {
        let mut out = vec![0.0f32; chains * n];
        let failures = pool.install(|| batch.accelerations_f32(&q, &qd, None, &mut out)).expect("f32");
        assert_eq!(failures.iter().map(|f| f.chain).collect::<Vec<_>>(), [4, 13]);
        assert_eq!(failures[0].error, Error::NonFinite { what: "q", index: 2, value: f64::INFINITY });
        assert_eq!(failures[1].error, Error::SinglePrecisionOverflow);
        for (k, row) in out.chunks_exact(n).enumerate() {
            assert_eq!(row.iter().all(|v| v.is_nan()), k == 4 || k == 13, "chain {k}");
        }
        runs.push(out.iter().map(|v| v.to_bits()).collect::<Vec<_>>());
    }
    assert_eq!(runs[0], runs[1]);
    for k in [0, 9, 20] {
        let alone = PlanarBatch::new(vec![list[k].clone()]).expect("batch");
        let mut out = vec![0.0f32; n];
        let row = |v: &[f32]| v[k * n..(k + 1) * n].to_vec();
        assert!(alone.accelerations_f32(&row(&q), &row(&qd), None, &mut out).expect("f32").is_empty());
        assert_eq!(
            out.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            runs[0][k * n..(k + 1) * n],
            "chain {k}"
        );
    }
}

/// States of `chains` chains of `n` links as rows of `(θ, θ̇)`: angles within ±1 rad,
/// rates within ±1 rad/s.
fn planar_rows(chains: usize, n: usize, r: &mut ChaCha8Rng) -> Vec<f64> {
    (0..chains * 2 * n).map(|_| r.random_range(-1.0..1.0)).collect()
}

#[test]
fn single_precision_planar_runs_are_within_their_documented_error() {
    // The bounds of docs/ensembles.md ("Single precision"): 100 and 1000 RK4 steps of
    // 0.1 ms from the same states, the f32 run against the f64 one; `--nocapture` prints them.
    let mut r = ChaCha8Rng::seed_from_u64(51);
    let (chains, h) = (64, 1e-4);
    for (decades, steps, bound) in [(0.3, 100, 5e-6), (0.3, 1000, 3e-4), (1.0, 100, 5e-6), (2.0, 100, 1e-5)] {
        for n in [8, 20, 100] {
            let batch = PlanarBatch::new((0..chains).map(|_| spread_chain(n, decades, &mut r)).collect())
                .expect("batch");
            let rows = planar_rows(chains, n, &mut r);
            let mut states: Vec<State<Dyn>> =
                rows.chunks_exact(2 * n).map(|x| State::new(0.0, DVector::from_column_slice(x))).collect();
            assert!(batch.integrate_rk4(&mut states, None, None, h, steps).expect("f64").is_empty());
            let f64s: Vec<f64> = states.iter().flat_map(|s| s.x().iter().copied()).collect();
            let (mut f32s, mut carry): (Vec<f32>, _) =
                (rows.iter().map(|&v| v as f32).collect(), vec![0.0; rows.len()]);
            let run = batch.integrate_rk4_f32((&mut f32s, &mut carry), None, None, h, steps);
            assert!(run.expect("f32").is_empty());
            let error = worst_relative_error(&f64s, &f32s, 2 * n);
            println!("planar run, spread 10^{decades}, {steps} steps of {h} s, n = {n}: {error:.1e}");
            assert!(error < bound, "spread 10^{decades}, {steps} × {h} s, n = {n}: {error:e} ≥ {bound:e}");
        }
    }
}

#[test]
fn single_precision_driven_planar_runs_follow_the_f64_ones_and_fail_by_chain() {
    // Each chain's pivot shaken along its own line from t0 = 0.37 s (up to 0.01 m at up to
    // 400 rad/s: 160 g): the f32 run against the f64 driven run (the bound of
    // docs/ensembles.md; `--nocapture` prints it), a pivot that
    // stands still against the held run bit for bit, one chain alone and thread counts bit
    // for bit, a drive past f32's range failing its chain alone, and bad arguments.
    let mut r = ChaCha8Rng::seed_from_u64(53);
    let (chains, h, steps, t0) = (64, 1e-4, 100, 0.37);
    let shake = |r: &mut ChaCha8Rng, k: usize| {
        let direction =
            nalgebra::Vector2::new(if k.is_multiple_of(2) { 0.0 } else { r.random_range(-1.0..1.0) }, 1.0);
        let (a, w) = (r.random_range(0.0..0.01), r.random_range(10.0..400.0));
        Harmonic::new(direction, a, w, r.random::<f64>()).expect("drive")
    };
    for n in [8, 20, 100] {
        let list: Vec<_> = (0..chains).map(|_| spread_chain(n, 0.3, &mut r)).collect();
        let batch = PlanarBatch::new(list.clone()).expect("batch");
        let drives: Vec<Harmonic<U2>> = (0..chains).map(|k| shake(&mut r, k)).collect();
        let rows = planar_rows(chains, n, &mut r);
        let mut states: Vec<State<Dyn>> =
            rows.chunks_exact(2 * n).map(|x| State::new(t0, DVector::from_column_slice(x))).collect();
        assert!(batch.integrate_rk4_driven(&mut states, &drives, None, h, steps).expect("f64").is_empty());
        let f64s: Vec<f64> = states.iter().flat_map(|s| s.x().iter().copied()).collect();
        let start: Vec<f32> = rows.iter().map(|&v| v as f32).collect();
        let mut runs = Vec::new();
        for pool in pools() {
            let (mut x, mut carry) = (start.clone(), vec![0.0; rows.len()]);
            let run = pool.install(|| {
                batch.integrate_rk4_driven_f32((&mut x, &mut carry), (t0, &drives), None, h, steps)
            });
            assert!(run.expect("f32").is_empty());
            runs.push(x);
        }
        assert!(runs[0].iter().zip(&runs[1]).all(|(a, b)| a.to_bits() == b.to_bits()), "one thread or two");
        let error = worst_relative_error(&f64s, &runs[0], 2 * n);
        println!("driven planar run in f32, {steps} steps of {h} s, n = {n}: {error:.1e}");
        assert!(error < 1e-4, "n = {n}: {error:e}");
        let k = 37;
        let alone = PlanarBatch::new(vec![list[k].clone()]).expect("batch");
        let (mut x, mut carry) = (start[k * 2 * n..(k + 1) * 2 * n].to_vec(), vec![0.0; 2 * n]);
        let run = alone.integrate_rk4_driven_f32((&mut x, &mut carry), (t0, &drives[k..=k]), None, h, steps);
        assert!(run.expect("f32").is_empty());
        assert!(
            x.iter().zip(&runs[0][k * 2 * n..]).all(|(a, b)| a.to_bits() == b.to_bits()),
            "chain {k} alone"
        );
        // No amplitude: the pivot at rest, as the held run has it.
        let still: Vec<Harmonic<U2>> = (0..chains)
            .map(|_| Harmonic::new(nalgebra::Vector2::new(0.3, 1.0), 0.0, 50.0, 0.1).expect("drive"))
            .collect();
        let (mut driven, mut carry) = (start.clone(), vec![0.0; rows.len()]);
        let run = batch.integrate_rk4_driven_f32((&mut driven, &mut carry), (t0, &still), None, h, steps);
        assert!(run.expect("f32").is_empty());
        let (mut held, mut carry) = (start.clone(), vec![0.0; rows.len()]);
        assert!(
            batch.integrate_rk4_f32((&mut held, &mut carry), None, None, h, steps).expect("f32").is_empty()
        );
        assert!(driven.iter().zip(&held).all(|(a, b)| a.to_bits() == b.to_bits()), "n = {n}: at rest");
    }
    // A drive whose acceleration leaves f32's range (finite in f64) fails its chain alone at
    // its first step; too few drives and a non-finite t0 are errors.
    let batch = PlanarBatch::new((0..3).map(|_| spread_chain(4, 0.3, &mut r)).collect()).expect("batch");
    let drives: Vec<Harmonic<U2>> = [1e30, 10.0, 10.0]
        .into_iter()
        .map(|w| Harmonic::new(nalgebra::Vector2::new(0.0, 1.0), 1.0, w, 0.3).expect("drive"))
        .collect();
    let (mut x, mut carry) = (vec![0.5f32; 24], vec![0.0f32; 24]);
    let failures =
        batch.integrate_rk4_driven_f32((&mut x, &mut carry), (t0, &drives), None, 1e-3, 5).expect("run");
    assert_eq!(failures.iter().map(|f| f.chain).collect::<Vec<_>>(), [0]);
    assert_eq!(failures[0].error, Error::NonFiniteState { t: t0, h: 1e-3 });
    assert_eq!(&x[..8], &[0.5; 8], "the failed chain stays at its start");
    assert!(x[8..].iter().any(|v| *v != 0.5));
    assert!(matches!(
        batch.integrate_rk4_driven_f32((&mut x, &mut carry), (t0, &drives[..2]), None, 1e-3, 5),
        Err(Error::LengthMismatch { what: "drives", expected: 3, got: 2 })
    ));
    assert!(matches!(
        batch.integrate_rk4_driven_f32((&mut x, &mut carry), (f64::NAN, &drives), None, 1e-3, 5),
        Err(Error::NonFinite { what: "t0", .. })
    ));
}

#[test]
fn single_precision_planar_runs_fail_by_chain_and_change_with_no_thread_count_or_split() {
    let mut r = ChaCha8Rng::seed_from_u64(52);
    let (n, chains) = (6, 19);
    let list: Vec<_> = (0..chains).map(|_| spread_chain(n, 1.0, &mut r)).collect();
    let batch = PlanarBatch::new(list.clone()).expect("batch");
    let mut start: Vec<f32> = planar_rows(chains, n, &mut r).iter().map(|&v| v as f32).collect();
    let torque: Vec<f32> = (0..chains * n).map(|i| if (i / n) % 2 == 0 { 0.0 } else { 1e-3 }).collect();
    start[3 * 2 * n + 1] = f32::NAN;
    start[11 * 2 * n + n] = 1e30; // spins so fast that the first step overflows
    let mut runs = Vec::new();
    for pool in pools() {
        let (mut x, mut carry) = (start.clone(), vec![0.0; start.len()]);
        let failures = pool
            .install(|| batch.integrate_rk4_f32((&mut x, &mut carry), Some(&torque), None, 1e-3, 20))
            .expect("f32");
        assert_eq!(failures.iter().map(|f| f.chain).collect::<Vec<_>>(), [3, 11], "{failures:?}");
        assert_eq!(failures[0].error.to_string(), "x[1] must be finite, got NaN");
        assert_eq!(failures[1].error, Error::NonFiniteState { t: 0.0, h: 1e-3 });
        for k in [3, 11] {
            let row = k * 2 * n..(k + 1) * 2 * n;
            let same = x[row.clone()].iter().zip(&start[row]).all(|(a, b)| a.to_bits() == b.to_bits());
            assert!(same, "chain {k} is left where it was");
        }
        runs.push(x.iter().map(|v| v.to_bits()).collect::<Vec<_>>());
        // Twenty calls of one step, the compensation kept: the same numbers.
        let (mut y, mut carry) = (start.clone(), vec![0.0; start.len()]);
        for _ in 0..20 {
            pool.install(|| batch.integrate_rk4_f32((&mut y, &mut carry), Some(&torque), None, 1e-3, 1))
                .expect("f32");
        }
        assert_eq!(y.iter().map(|v| v.to_bits()).collect::<Vec<_>>(), runs[0], "one step per call");
    }
    assert_eq!(runs[0], runs[1], "one thread or two");
    for k in [0, 8, 18] {
        let alone = PlanarBatch::new(vec![list[k].clone()]).expect("batch");
        let (mut x, mut carry) = (start[k * 2 * n..(k + 1) * 2 * n].to_vec(), vec![0.0; 2 * n]);
        let t = &torque[k * n..(k + 1) * n];
        let run = alone.integrate_rk4_f32((&mut x, &mut carry), Some(t), None, 1e-3, 20);
        assert!(run.expect("f32").is_empty());
        let bits: Vec<u32> = x.iter().map(|v| v.to_bits()).collect();
        assert_eq!(bits, runs[0][k * 2 * n..(k + 1) * 2 * n], "chain {k} alone");
    }
}
