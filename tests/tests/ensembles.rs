//! Batches of chains (`pendulum_core::batch`), planar ones here (`PlanarBatch`; in
//! directions: `direction_batches.rs`; in single precision: `single_precision.rs`): every
//! chain of a batch gets exactly the single-chain result, whatever the thread count and
//! however the chains are split into calls, and a failing chain is reported by its index
//! while the others finish.

use nalgebra::{DVector, Dyn, U2, U3};
use pendulum_core::batch::{DirectionsBatch, PlanarBatch};
use pendulum_core::integrate::{Integrator, Rk4, State};
use pendulum_core::{
    Chain, ConstantTorque, Derivatives, Directions, Driven, Error, FirstOrder, Harmonic, Inputs, Jacobians,
    Model, PlanarTension,
};
use pendulum_tests::batches::{assert_bits, assert_same_state, pools, random_chain, whirl};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

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
    assert_eq!(batch.accelerations_f32(&q1, &qd1, None, None, &mut out).expect("first").len(), 1);
    assert!(batch.accelerations_f32(&q2, &qd2, None, None, &mut out).expect("second").is_empty());
    assert!(fresh.clone().accelerations_f32(&q2, &qd2, None, None, &mut new).expect("new").is_empty());
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
    let (q, mut dq, mut dqd) = ([0.0; 12], [0.0; 48], [0.0; 48]);
    let err = batch.state_jacobians(&q, &q, Some(&[0.0; 13]), None, &mut dq, &mut dqd).unwrap_err();
    assert_eq!(err.to_string(), "torque has 13 entries, expected 12");
    let err = batch.state_jacobians(&q, &q, None, None, &mut dq[1..], &mut dqd).unwrap_err();
    assert_eq!(err.to_string(), "dq has 47 entries, expected 48");
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
                    assert_same_state(s, alone, &format!("chain {k} of {chains}×{n}"));
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
    // In lanes up to 48 links, one chain at a time beyond. Chain 1 has masses of 1e-40 kg: its continuants (~1e40 a row)
    // leave their range and it alone takes the classical pivots in its lanes.
    let mut r = ChaCha8Rng::seed_from_u64(77);
    for (chains, n) in [(1, 1), (5, 8), (37, 20), (11, 49)] {
        let mut chain: Vec<_> = (0..chains).map(|_| random_chain(n, &mut r)).collect();
        if chains > 1 {
            chain[1] = Chain::new(&vec![1e-40; n], &vec![0.1; n], 9.81).expect("chain");
        }
        let batch = PlanarBatch::new(chain.clone()).expect("batch");
        let mut q: Vec<f64> = (0..chains * n).map(|_| r.random_range(-20.0..20.0)).collect();
        let qd: Vec<f64> = (0..chains * n).map(|_| r.random_range(-10.0..10.0)).collect();
        let pivot: Vec<f64> = (0..chains * 2).map(|_| r.random_range(-30.0..30.0)).collect();
        // Joint torques on every chain but the first.
        let mut torque: Vec<f64> = (0..chains * n).map(|_| r.random_range(-0.1..0.1)).collect();
        torque[..n].fill(0.0);
        let bad = chains / 2;
        q[bad * n] = f64::NAN;
        let (mut single_q, mut single_qd) = (vec![0.0; chains * n * n], vec![0.0; chains * n * n]);
        for (k, c) in chain.iter().enumerate() {
            let model = PlanarTension::new(c.clone());
            let rows = k * n..(k + 1) * n;
            let mut inputs = Inputs::<Dyn, U2>::zeros(Dyn(n));
            inputs.pivot_acceleration = nalgebra::Vector2::new(pivot[2 * k], pivot[2 * k + 1]);
            inputs.torque.copy_from_slice(&torque[k * n..(k + 1) * n]);
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
            assert!(out.q.iter().chain(out.qd.iter()).all(|v| v.is_finite()), "chain {k}");
            for a in 0..n {
                for b in 0..n {
                    single_q[block.start + a * n + b] = out.q[(a, b)];
                    single_qd[block.start + a * n + b] = out.qd[(a, b)];
                }
            }
        }
        for (batch, pool) in widths_and_pools(&batch) {
            let (mut dq, mut dqd) = (vec![0.0; chains * n * n], vec![0.0; chains * n * n]);
            let failures = pool
                .install(|| batch.state_jacobians(&q, &qd, Some(&torque), Some(&pivot), &mut dq, &mut dqd))
                .expect("batch");
            let what = format!(
                "{chains} chains of {n}, {} threads, eight lanes {}",
                pool.current_num_threads(),
                batch.uses_avx512()
            );
            assert_eq!(failures.len(), 1, "{what}");
            assert_eq!(failures[0].chain, bad, "{what}");
            assert_eq!(failures[0].error.to_string(), "q[0] must be finite, got NaN", "{what}");
            assert_bits(&dq, &single_q, &format!("{what}: ∂θ̈/∂θ"));
            assert_bits(&dqd, &single_qd, &format!("{what}: ∂θ̈/∂θ̇"));
        }
        // Split into calls of 3 chains (the last shorter): the same numbers.
        let (mut dq, mut dqd) = (vec![0.0; chains * n * n], vec![0.0; chains * n * n]);
        for (part, start) in chain.chunks(3).zip((0..chains).step_by(3)) {
            let batch = PlanarBatch::new(part.to_vec()).expect("part");
            let (rows, squares) =
                (start * n..(start + part.len()) * n, start * n * n..(start + part.len()) * n * n);
            let pivot = &pivot[2 * start..2 * (start + part.len())];
            let (dq, dqd) = (&mut dq[squares.clone()], &mut dqd[squares]);
            let (q, qd, torque) = (&q[rows.clone()], &qd[rows.clone()], &torque[rows]);
            batch.state_jacobians(q, qd, Some(torque), Some(pivot), dq, dqd).expect("part");
        }
        assert_bits(&dq, &single_q, &format!("{chains} chains of {n} in calls of 3: ∂θ̈/∂θ"));
        assert_bits(&dqd, &single_qd, &format!("{chains} chains of {n} in calls of 3: ∂θ̈/∂θ̇"));
        // No torques given is zero torques.
        let zeros = vec![0.0; chains * n];
        let mut with = [vec![0.0; chains * n * n], vec![0.0; chains * n * n]];
        let mut without = with.clone();
        let [a, b] = &mut with;
        batch.state_jacobians(&q, &qd, Some(&zeros), Some(&pivot), a, b).expect("zeros");
        let [a, b] = &mut without;
        batch.state_jacobians(&q, &qd, None, Some(&pivot), a, b).expect("none");
        assert_bits(&without.concat(), &with.concat(), &format!("{chains} chains of {n}, no torques"));
    }
}
