//! Batches of chains in single precision (`pendulum_core::batch`'s `_f32` calls): their
//! error against the `f64` calls, within the bounds `docs/ensembles.md` gives, and as in
//! double precision a failing chain reported by its index while the others finish, the
//! same numbers for any thread count and split.

use nalgebra::{DVector, Dyn, U2, U3};
use pendulum_core::batch::{DirectionsBatch, Failure, PlanarBatch};
use pendulum_core::integrate::State;
use pendulum_core::{Circle, Directions, Error, Harmonic};
use pendulum_tests::batches::{pools, spread_chain, whirl};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

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
fn single_precision_direction_jacobians_are_within_their_documented_error() {
    // The bounds of docs/ensembles.md ("Single precision"); `--nocapture` prints the errors:
    // the worst chain's largest difference in `∂ü/∂u` and `∂ü/∂w` over its largest entry.
    let mut r = ChaCha8Rng::seed_from_u64(53);
    let chains = 64;
    for (decades, bound) in [(0.3, 5e-6), (1.0, 5e-6), (2.0, 1e-5), (3.0, 5e-5)] {
        for n in [8, 20, 100] {
            let (models, x) = spread_whirls(n, decades, chains, &mut r);
            let batch = DirectionsBatch::new(models).expect("batch");
            let (t, h) = (r.random_range(0.0..10.0), 3 * n);
            let (mut du64, mut dw64) = (vec![0.0; chains * h * h], vec![0.0; chains * h * h]);
            let (mut du32, mut dw32) = (vec![0.0f32; chains * h * h], vec![0.0f32; chains * h * h]);
            assert!(batch.state_jacobians(t, &x, &mut du64, &mut dw64).expect("f64").is_empty());
            let x32: Vec<f32> = x.iter().map(|&v| v as f32).collect();
            assert!(batch.state_jacobians_f32(t, &x32, &mut du32, &mut dw32).expect("f32").is_empty());
            let by_u = worst_relative_error(&du64, &du32, h * h);
            let by_w = worst_relative_error(&dw64, &dw32, h * h);
            // The entries not zero but below `f32`'s normal range, which its kernel flushes to
            // zero (`lanes::FlushSubnormals`).
            let below = |v: &&f64| **v != 0.0 && v.abs() < f64::from(f32::MIN_POSITIVE);
            let tiny = du64.iter().chain(&dw64).filter(below).count();
            let tiny = 100.0 * tiny as f64 / (2 * du64.len()) as f64;
            println!(
                "3D Jacobians, spread 10^{decades}, n = {n}: {by_u:.1e} (∂ü/∂u), {by_w:.1e} (∂ü/∂w); \
                 {tiny:.1}% of the entries below f32's normal range"
            );
            for error in [by_u, by_w] {
                assert!(error < bound, "spread 10^{decades}, n = {n}: {error:e} ≥ {bound:e}");
            }
        }
    }
}

#[test]
fn single_precision_direction_jacobians_fail_by_chain_and_change_with_no_thread_count_or_split() {
    let mut r = ChaCha8Rng::seed_from_u64(54);
    let (n, chains) = (7, 19);
    let (models, x): (Vec<_>, Vec<_>) = (0..chains).map(|_| whirl(n, &mut r)).unzip();
    let mut x: Vec<f32> = x.iter().flat_map(|x| x.iter().map(|&v| v as f32)).collect();
    let (m, h) = (6 * n, 3 * n);
    x[3 * m + 5] = f32::NAN;
    // A rate whose square leaves f32: finite input, overflow in the solve.
    x[11 * m + 3 * n + 1] = 3e19;
    let batch = DirectionsBatch::new(models.clone()).expect("batch");
    let squares = h * h;
    let mut runs = Vec::new();
    for pool in pools() {
        let (mut du, mut dw) = (vec![0.0f32; chains * squares], vec![0.0f32; chains * squares]);
        let failures = pool.install(|| batch.state_jacobians_f32(1.5, &x, &mut du, &mut dw)).expect("f32");
        assert_eq!(failures.iter().map(|f| f.chain).collect::<Vec<_>>(), [3, 11]);
        assert!(matches!(failures[0].error, Error::NonFinite { what: "x", index: 5, .. }));
        assert_eq!(failures[1].error, Error::SinglePrecisionOverflow);
        for (k, (a, b)) in du.chunks_exact(squares).zip(dw.chunks_exact(squares)).enumerate() {
            let failed = k == 3 || k == 11;
            assert_eq!(a.iter().chain(b).all(|v| v.is_nan()), failed, "chain {k}");
            assert_eq!(a.iter().chain(b).all(|v| v.is_finite()), !failed, "chain {k}");
        }
        // From the directions and rates apart: the same bits.
        let u: Vec<f32> = x.chunks_exact(m).flat_map(|x| x[..h].to_vec()).collect();
        let w: Vec<f32> = x.chunks_exact(m).flat_map(|x| x[h..].to_vec()).collect();
        let (mut du2, mut dw2) = (vec![0.0f32; chains * squares], vec![0.0f32; chains * squares]);
        let split = pool.install(|| batch.state_jacobians_split_f32(1.5, &u, &w, &mut du2, &mut dw2));
        assert_eq!(split.expect("split").iter().map(|f| f.chain).collect::<Vec<_>>(), [3, 11]);
        let bits = |v: &[f32]| v.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&[du2, dw2].concat()), bits(&[du.clone(), dw.clone()].concat()));
        runs.push(bits(&[du, dw].concat()));
    }
    assert_eq!(runs[0], runs[1]);
    for k in [0, 8, 18] {
        let alone = DirectionsBatch::new(vec![models[k].clone()]).expect("batch");
        let (mut du, mut dw) = (vec![0.0f32; squares], vec![0.0f32; squares]);
        assert!(
            alone.state_jacobians_f32(1.5, &x[k * m..(k + 1) * m], &mut du, &mut dw).expect("f32").is_empty()
        );
        let bits = |v: &[f32]| v.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&du), runs[0][k * squares..(k + 1) * squares], "chain {k}");
        let offset = chains * squares;
        assert_eq!(bits(&dw), runs[0][offset + k * squares..offset + (k + 1) * squares], "chain {k}");
    }
    let err = batch.state_jacobians_f32(1.5, &x, &mut [0.0; 5], &mut [0.0; 5]).unwrap_err();
    assert_eq!(err.to_string(), format!("du has 5 entries, expected {}", chains * squares));
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
            let run = on_one_and_two_threads(&start, |x| batch.integrate_rk4_f32(x, t0, h, steps));
            let error = worst_relative_error(&f64s, &run, m);
            let unit = worst_unit_error(&run, m, n);
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
                x32.iter().zip(&run[k * m..]).all(|(a, b)| a.to_bits() == b.to_bits()),
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

/// The worst over rows of `max |a₃₂ − a₆₄| / max |a₆₄|` (rows of `m`).
fn worst_relative_error<T: Copy + Into<f64>>(f64s: &[f64], others: &[T], m: usize) -> f64 {
    f64s.chunks_exact(m)
        .zip(others.chunks_exact(m))
        .map(|(a, b)| {
            let scale = a.iter().fold(0.0f64, |s, v| s.max(v.abs()));
            a.iter().zip(b).fold(0.0f64, |e, (a, &b)| e.max((a - b.into()).abs())) / scale
        })
        .fold(0.0, f64::max)
}

/// `run(x)` from `start` (rows of `(u, w)` in `f32`) on one thread and on two, failing no
/// chain: the same bits either way (asserted); the states it ends in.
fn on_one_and_two_threads(
    start: &[f32],
    run: impl Fn(&mut [f32]) -> pendulum_core::Result<Vec<Failure>> + Send + Sync,
) -> Vec<f32> {
    let runs: Vec<Vec<f32>> = pools()
        .iter()
        .map(|pool| {
            let mut x = start.to_vec();
            assert!(pool.install(|| run(&mut x)).expect("f32").is_empty());
            x
        })
        .collect();
    assert!(runs[0].iter().zip(&runs[1]).all(|(a, b)| a.to_bits() == b.to_bits()), "one thread or two");
    runs.into_iter().next().expect("a run")
}

/// The largest `||u_i| − 1|` of the rows of `(u, w)` (`m` each) of chains of `n` links.
fn worst_unit_error(x: &[f32], m: usize, n: usize) -> f64 {
    x.chunks_exact(m)
        .flat_map(|x| x[..3 * n].chunks_exact(3))
        .map(|u| (u.iter().map(|&v| f64::from(v) * f64::from(v)).sum::<f64>().sqrt() - 1.0).abs())
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
            // Joint torques on two chains in three: blocks of chains with and without them.
            let torque: Vec<f64> = (0..chains * n)
                .map(|i| if (i / n) % 3 == 0 { 0.0 } else { r.random_range(-1e-3..1e-3) })
                .collect();
            let (mut out64, mut out32) = (vec![0.0; chains * n], vec![0.0f32; chains * n]);
            let (t, p) = (Some(&torque[..]), Some(&pivot[..]));
            assert!(batch.accelerations(&q, &qd, t, p, &mut out64).expect("f64").is_empty());
            let narrow = |v: &[f64]| v.iter().map(|&x| x as f32).collect::<Vec<_>>();
            let (q, qd, torque, pivot) = (narrow(&q), narrow(&qd), narrow(&torque), narrow(&pivot));
            let (t, p) = (Some(&torque[..]), Some(&pivot[..]));
            assert!(batch.accelerations_f32(&q, &qd, t, p, &mut out32).expect("f32").is_empty());
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
    // Joint torques on every other chain, one of them not finite.
    let mut torque: Vec<f32> =
        (0..chains * n).map(|i| if (i / n) % 2 == 0 { 0.0 } else { r.random_range(-1e-3..1e-3) }).collect();
    torque[17 * n + 3] = f32::NEG_INFINITY;
    let batch = PlanarBatch::new(list.clone()).expect("batch");
    let mut runs = Vec::new();
    for pool in pools() {
        let mut out = vec![0.0f32; chains * n];
        let failures =
            pool.install(|| batch.accelerations_f32(&q, &qd, Some(&torque), None, &mut out)).expect("f32");
        assert_eq!(failures.iter().map(|f| f.chain).collect::<Vec<_>>(), [4, 13, 17]);
        assert_eq!(failures[0].error, Error::NonFinite { what: "q", index: 2, value: f64::INFINITY });
        assert_eq!(failures[1].error, Error::SinglePrecisionOverflow);
        assert_eq!(
            failures[2].error,
            Error::NonFinite { what: "torque", index: 3, value: f64::NEG_INFINITY }
        );
        for (k, row) in out.chunks_exact(n).enumerate() {
            assert_eq!(row.iter().all(|v| v.is_nan()), [4, 13, 17].contains(&k), "chain {k}");
        }
        runs.push(out.iter().map(|v| v.to_bits()).collect::<Vec<_>>());
    }
    assert_eq!(runs[0], runs[1]);
    for k in [0, 9, 20] {
        let alone = PlanarBatch::new(vec![list[k].clone()]).expect("batch");
        let mut out = vec![0.0f32; n];
        let row = |v: &[f32]| v[k * n..(k + 1) * n].to_vec();
        let t = row(&torque);
        assert!(
            alone.accelerations_f32(&row(&q), &row(&qd), Some(&t), None, &mut out).expect("f32").is_empty()
        );
        assert_eq!(
            out.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            runs[0][k * n..(k + 1) * n],
            "chain {k}"
        );
    }
}

#[test]
fn single_precision_planar_jacobians_are_within_their_documented_error() {
    // The bounds of docs/ensembles.md ("Single precision"); `--nocapture` prints the errors:
    // the worst chain's largest difference in `∂θ̈/∂θ` and `∂θ̈/∂θ̇` over its largest entry.
    let mut r = ChaCha8Rng::seed_from_u64(51);
    let chains = 64;
    for (decades, bound) in [(0.3, 5e-6), (1.0, 1e-5), (2.0, 3e-5)] {
        for n in [8, 20, 100] {
            let batch = PlanarBatch::new((0..chains).map(|_| spread_chain(n, decades, &mut r)).collect())
                .expect("batch");
            let q: Vec<f64> = (0..chains * n).map(|_| r.random_range(-3.0..3.0)).collect();
            let qd: Vec<f64> = (0..chains * n).map(|_| r.random_range(-5.0..5.0)).collect();
            let torque: Vec<f64> = (0..chains * n).map(|_| r.random_range(-1e-3..1e-3)).collect();
            let pivot: Vec<f64> = (0..chains * 2).map(|_| r.random_range(-30.0..30.0)).collect();
            let squares = chains * n * n;
            let (mut dq64, mut dqd64) = (vec![0.0; squares], vec![0.0; squares]);
            let (mut dq32, mut dqd32) = (vec![0.0f32; squares], vec![0.0f32; squares]);
            let (t, p) = (Some(&torque[..]), Some(&pivot[..]));
            assert!(batch.state_jacobians(&q, &qd, t, p, &mut dq64, &mut dqd64).expect("f64").is_empty());
            let narrow = |v: &[f64]| v.iter().map(|&x| x as f32).collect::<Vec<_>>();
            let (q, qd, torque, pivot) = (narrow(&q), narrow(&qd), narrow(&torque), narrow(&pivot));
            let (t, p) = (Some(&torque[..]), Some(&pivot[..]));
            assert!(batch.state_jacobians_f32(&q, &qd, t, p, &mut dq32, &mut dqd32).expect("f32").is_empty());
            let by_q = worst_relative_error(&dq64, &dq32, n * n);
            let by_qd = worst_relative_error(&dqd64, &dqd32, n * n);
            println!(
                "planar Jacobians, spread 10^{decades}, n = {n}: {by_q:.1e} (∂θ̈/∂θ), {by_qd:.1e} (∂θ̈/∂θ̇)"
            );
            for error in [by_q, by_qd] {
                assert!(error < bound, "spread 10^{decades}, n = {n}: {error:e} ≥ {bound:e}");
            }
        }
    }
}

#[test]
fn single_precision_planar_jacobians_fail_by_chain_and_change_with_no_thread_count_or_split() {
    let mut r = ChaCha8Rng::seed_from_u64(52);
    let (n, chains) = (10, 21);
    let list: Vec<_> = (0..chains).map(|_| spread_chain(n, 1.0, &mut r)).collect();
    let mut q: Vec<f32> = (0..chains * n).map(|_| r.random_range(-3.0..3.0)).collect();
    let mut qd: Vec<f32> = (0..chains * n).map(|_| r.random_range(-5.0..5.0)).collect();
    let torque: Vec<f32> = (0..chains * n).map(|_| r.random_range(-1e-3..1e-3)).collect();
    q[4 * n + 2] = f32::INFINITY;
    qd[13 * n + 7] = 3e19;
    let batch = PlanarBatch::new(list.clone()).expect("batch");
    let squares = n * n;
    let mut runs = Vec::new();
    for pool in pools() {
        let (mut dq, mut dqd) = (vec![0.0f32; chains * squares], vec![0.0f32; chains * squares]);
        let failures = pool
            .install(|| batch.state_jacobians_f32(&q, &qd, Some(&torque), None, &mut dq, &mut dqd))
            .expect("f32");
        assert_eq!(failures.iter().map(|f| f.chain).collect::<Vec<_>>(), [4, 13]);
        assert_eq!(failures[0].error, Error::NonFinite { what: "q", index: 2, value: f64::INFINITY });
        assert_eq!(failures[1].error, Error::SinglePrecisionOverflow);
        for (k, (a, b)) in dq.chunks_exact(squares).zip(dqd.chunks_exact(squares)).enumerate() {
            let failed = k == 4 || k == 13;
            assert_eq!(a.iter().chain(b).all(|v| v.is_nan()), failed, "chain {k}");
            assert_eq!(a.iter().chain(b).all(|v| v.is_finite()), !failed, "chain {k}");
        }
        runs.push([dq, dqd].concat().iter().map(|v| v.to_bits()).collect::<Vec<_>>());
    }
    assert_eq!(runs[0], runs[1]);
    for k in [0, 9, 20] {
        let alone = PlanarBatch::new(vec![list[k].clone()]).expect("batch");
        let (mut dq, mut dqd) = (vec![0.0f32; squares], vec![0.0f32; squares]);
        let row = |v: &[f32]| v[k * n..(k + 1) * n].to_vec();
        let failures =
            alone.state_jacobians_f32(&row(&q), &row(&qd), Some(&row(&torque)), None, &mut dq, &mut dqd);
        assert!(failures.expect("f32").is_empty());
        let bits = |v: &[f32]| v.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&dq), runs[0][k * squares..(k + 1) * squares], "chain {k}");
        let offset = chains * squares;
        assert_eq!(bits(&dqd), runs[0][offset + k * squares..offset + (k + 1) * squares], "chain {k}");
    }
    let err = batch.state_jacobians_f32(&q, &qd, None, None, &mut [0.0; 5], &mut [0.0; 5]).unwrap_err();
    assert_eq!(err.to_string(), format!("dq has 5 entries, expected {}", chains * squares));
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

/// `count` uniform chains of `n` links (100 g and 1 m in all, rod damping 1e-4 N·m·s)
/// whirled on circles of 1–3 cm at 2–9 rad/s, and their states hanging at rest.
fn hanging_whirls(n: usize, count: usize, r: &mut ChaCha8Rng) -> (Vec<Directions<U3, Circle>>, Vec<f64>) {
    let models = (0..count)
        .map(|_| {
            let chain = pendulum_core::Chain::new(&vec![0.1 / n as f64; n], &vec![1.0 / n as f64; n], 9.81)
                .and_then(|c| c.with_damping(&vec![1e-4; n]))
                .expect("chain");
            let drive = Circle::new(r.random_range(0.01..0.03), r.random_range(2.0..9.0)).expect("drive");
            Directions::<U3>::new(chain).with_drive(drive)
        })
        .collect();
    let hanging = [0.0, 0.0, -1.0].repeat(n).into_iter().chain(vec![0.0; 3 * n]);
    (models, hanging.cycle().take(count * 6 * n).collect())
}

#[test]
fn single_precision_rod_midpoint_runs_follow_the_f64_ones_and_fail_by_chain() {
    // Uniform chains whirled from hanging, the implicit rod midpoint in f32 against
    // `integrate_rod_midpoint` (the bounds of docs/ensembles.md; `--nocapture` prints the
    // errors): the error grows as the steps shrink (round-off in each of more steps), so
    // this step is for long steps in f32: at 10 and 50 ms a tenth of the step's own error
    // (the f64 step's against projected RK4 at 1 ms, where RK4 is stable: n = 8 and 20;
    // the 1 cm rods of n = 100 damp too fast for RK4 at 1 ms), at 1 ms larger than it. RK4
    // in f32 on the same whirls for comparison. One thread or two and one chain alone the
    // same bits; the rods of unit length.
    let mut r = ChaCha8Rng::seed_from_u64(55);
    let chains = 16;
    for (h, seconds, bound) in [(1e-3, 2.0, 3e-2), (1e-2, 2.0, 1e-3), (5e-2, 4.0, 2e-4)] {
        for n in [8, 20, 100] {
            let (models, start) = hanging_whirls(n, chains, &mut r);
            let (m, steps) = (6 * n, (seconds / h) as usize);
            let batch = DirectionsBatch::new(models.clone()).expect("batch");
            let mut states: Vec<State<Dyn>> =
                start.chunks_exact(m).map(|x| State::new(0.0, DVector::from_column_slice(x))).collect();
            assert!(batch.integrate_rod_midpoint(&mut states, h, steps).expect("f64").is_empty());
            let f64s: Vec<f64> = states.iter().flat_map(|s| s.x().iter().copied()).collect();
            let start32: Vec<f32> = start.iter().map(|&v| v as f32).collect();
            let run =
                on_one_and_two_threads(&start32, |x| batch.integrate_rod_midpoint_f32(x, 0.0, h, steps));
            let error = worst_relative_error(&f64s, &run, m);
            let unit = worst_unit_error(&run, m, n);
            let swung = f64s.chunks_exact(m).map(|x| x[3 * n - 1] + 1.0).fold(0.0, f64::max);
            println!(
                "rod midpoint in f32, {steps} steps of {h} s, n = {n}: {error:.1e}, |u| − 1 ≤ {unit:.1e}, \
                 the lowest link up by {swung:.2}"
            );
            assert!(error < bound, "{steps} steps of {h} s, n = {n}: {error:e} ≥ {bound:e}");
            if n < 100 {
                let rk4_steps = (seconds / 1e-3) as usize;
                let mut exact: Vec<State<Dyn>> =
                    start.chunks_exact(m).map(|x| State::new(0.0, DVector::from_column_slice(x))).collect();
                assert!(batch.integrate_rk4(&mut exact, 1e-3, rk4_steps).expect("rk4").is_empty());
                let exact: Vec<f64> = exact.iter().flat_map(|s| s.x().iter().copied()).collect();
                let own = worst_relative_error(&exact, &f64s, m);
                let mut rk4_32 = start32.clone();
                assert!(batch.integrate_rk4_f32(&mut rk4_32, 0.0, 1e-3, rk4_steps).expect("rk4").is_empty());
                let rk4_error = worst_relative_error(&exact, &rk4_32, m);
                println!(
                    "  the step's own error (f64, against RK4 at 1 ms) {own:.1e}; RK4 in f32 {rk4_error:.1e}"
                );
                if h >= 1e-2 {
                    assert!(error < own / 10.0, "f32 {error:e} against the step's own {own:e}");
                } else {
                    assert!(error > own, "at 1 ms f32 {error:e} exceeds the step's own {own:e}");
                }
                assert!(rk4_error < 1e-4, "RK4 in f32: {rk4_error:e}");
            }
            assert!(unit < 1e-6, "n = {n}: |u| − 1 = {unit:e}");
            let k = 11;
            let alone = DirectionsBatch::new(vec![models[k].clone()]).expect("batch");
            let mut x32 = start32[k * m..(k + 1) * m].to_vec();
            assert!(alone.integrate_rod_midpoint_f32(&mut x32, 0.0, h, steps).expect("f32").is_empty());
            assert!(
                x32.iter().zip(&run[k * m..]).all(|(a, b)| a.to_bits() == b.to_bits()),
                "chain {k} alone"
            );
        }
    }
    // A NaN state fails before any step; a step too long for the lanes (links turning by
    // more than a radian) is the f64 chain's own, halved; the others run on; bad arguments
    // are errors.
    let n = 5;
    let (models, start) = hanging_whirls(n, 4, &mut r);
    let batch = DirectionsBatch::new(models.clone()).expect("batch");
    let m = 6 * n;
    let mut x: Vec<f32> = start.iter().map(|&v| v as f32).collect();
    x[2 * m + 4] = f32::NAN;
    x[m + 3 * n..2 * m].fill(40.0);
    let before = x.clone();
    let failures = batch.integrate_rod_midpoint_f32(&mut x, 0.5, 0.05, 10).expect("run");
    assert_eq!(failures.iter().map(|f| f.chain).collect::<Vec<_>>(), [2]);
    assert!(matches!(failures[0].error, Error::NonFinite { what: "x", index: 4, .. }));
    assert!(x[2 * m..3 * m].iter().zip(&before[2 * m..]).all(|(a, b)| a.to_bits() == b.to_bits()));
    let mut whipped =
        State::new(0.5, DVector::from_iterator(m, before[m..2 * m].iter().map(|&v| f64::from(v))));
    let mut step = pendulum_core::RodMidpoint::new();
    for _ in 0..10 {
        pendulum_core::integrate::Integrator::step(&mut step, &models[1], &mut whipped, 0.05).expect("alone");
    }
    assert!(step.stats().halved_steps > 0, "the whipped chain's steps are halved");
    let whipped32 = worst_relative_error(whipped.x().as_slice(), &x[m..2 * m], m);
    assert!(whipped32 < 1e-3, "the whipped chain, halved in f64: {whipped32:e}");
    assert!(matches!(
        batch.integrate_rod_midpoint_f32(&mut x[..m], 0.0, 1e-3, 1),
        Err(Error::LengthMismatch { what: "x", .. })
    ));
    assert!(matches!(
        batch.integrate_rod_midpoint_f32(&mut x, 0.0, 0.0, 1),
        Err(Error::InvalidStepSize { .. })
    ));
    assert!(matches!(
        batch.integrate_rod_midpoint_f32(&mut x, f64::NAN, 1e-3, 1),
        Err(Error::NonFinite { what: "t0", .. })
    ));
}
