//! Batches of chains against one chain per call (`docs/ensembles.md`).
//!
//! Every measurement evaluates or steps the same 64 different chains (random masses,
//! lengths and damping; random states), so per-chain cost is the time divided by 64
//! (criterion's throughput line, in chains per second):
//! - `accelerations/{planar,spatial}/…/n`: the single-chain call in a loop
//!   (`PlanarTension`, `Directions<U3>`) against the batch on one thread and on two;
//!   `accelerations/…/batch_{1,2}_threads_1024_chains/100`: one call of 1024 chains of 100
//!   links on one thread and on two;
//! - `rk4/whirl_100`: one projected RK4 step of 1 ms of 64 whirls (3D, n = 100, each pivot on
//!   its own circle) chain by chain against the batch, and 100 steps per batch call
//!   (throughput in chain-steps per second; also in `f32`, `integrate_rk4_f32`, on one
//!   thread), and 10 steps of the implicit rod midpoint
//!   chain by chain against `integrate_rod_midpoint` (in lanes) on one thread and on two,
//!   and `integrate_rod_midpoint_f32` on one, at steps of 1 ms and of 50 ms (where the
//!   chains take more Newton iterations);
//! - `rk4/planar_100_steps/…/n`: 100 RK4 steps of 0.1 ms of free planar chains swinging
//!   (n = 20, 100), `Rk4` on each chain's `FirstOrder` against `PlanarBatch::integrate_rk4`
//!   on one thread and on two, and `integrate_rk4_f32` on one (throughput in chain-steps);
//!   at n = 20 also each pivot shaken vertically, `FirstOrder::with_inputs(PlanarTension,
//!   Driven)` alone against `integrate_rk4_driven` and `integrate_rk4_driven_f32`
//!   (`…/single_driven`, `…_driven`);
//! - `generated/planar/…/n`: `model!`'s planar models (n = 4, 8, 16) called in a loop against
//!   the same models in lanes (`UnrolledBatch`), on one thread and on two (and in four lanes
//!   instead of eight on a CPU with AVX-512), and in single precision on one;
//!   `generated/spatial/…/n`: `model!`'s spatial models (n = 4, 8, in spherical angles)
//!   the same way (`UnrolledSpatialBatch`);
//!   `generated/rk4_100_steps/…/n`: 100 RK4 steps of 0.1 ms per chain, `Rk4` on each chain's
//!   `FirstOrder` against `UnrolledBatch::integrate_rk4` (throughput in chain-steps; four
//!   lanes instead of eight too, and `integrate_rk4_f32`, `…/batch_f32_1_thread`), and `…/spatial_…/4` the same for the spatial model
//!   (`UnrolledSpatialBatch::integrate_rk4`), `…/spatial_held_…/4` with torques and pivot
//!   accelerations held, `…/spatial_whirled_…/4` with each chain's
//!   pivot on a circle of its own (`FirstOrder::with_inputs(model, Driven)` against
//!   `integrate_rk4_driven` and `integrate_rk4_driven_f32`, and in four lanes,
//!   `…_four_lanes`);
//! - `jacobians/planar/…/{8,20,100}`: `∂θ̈/∂θ`, `∂θ̈/∂θ̇` of 64 chains, one at a time
//!   against `PlanarBatch::state_jacobians` (in lanes) on one thread and on two, and
//!   `state_jacobians_f32`;
//!   `jacobians/spatial/…/{8,20,100}` the same in 3D directions
//!   (`Directions::analytic_jacobian`, and kept in `(B, h, h)` arrays, against
//!   `DirectionsBatch::state_jacobians`, and `state_jacobians_f32`).
//!
//! `cargo bench -p pendulum-core --bench ensembles`

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{Bencher, BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use nalgebra::{Const, DVector, Dyn, SVector, U2, U3};
use pendulum_core::batch::{
    DirectionsBatch, PlanarBatch, PlanarKernel, SpatialKernel, UnrolledBatch, UnrolledSpatialBatch,
};
use pendulum_core::integrate::{Integrator, Projected, Rk4, State, System};
use pendulum_core::{
    Chain, Circle, ConstantTorque, Derivatives, Directions, Driven, FirstOrder, Harmonic, Inputs, Jacobians,
    Model, PlanarTension, RodMidpoint,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const CHAINS: usize = 64;

pendulum_macros::model! {
    struct Planar4 { kind: planar, links: 4 }
    struct Planar8 { kind: planar, links: 8 }
    struct Planar16 { kind: planar, links: 16 }
    struct Spatial4 { kind: spatial, links: 4 }
    struct Spatial8 { kind: spatial, links: 8 }
}

/// `n` links of about 1 cm and 10 g, each mass, length and damping within a factor `spread`.
fn random_chain(n: usize, spread: f64, r: &mut ChaCha8Rng) -> Chain<Dyn> {
    let mut around = |x: f64| (0..n).map(|_| x * r.random_range(1.0 / spread..spread)).collect::<Vec<_>>();
    let (masses, lengths, damping) = (around(0.01), around(0.01), around(3e-4));
    Chain::new(&masses, &lengths, 9.81).and_then(|c| c.with_damping(&damping)).expect("chain")
}

/// `count` random chains of `n` links ([`random_chain`], spread 2) and their angles and
/// rates, `count` rows of `n` each, uniform in [−1, 1) rad and rad/s.
fn random_batch(count: usize, n: usize, r: &mut ChaCha8Rng) -> (Vec<Chain<Dyn>>, Vec<f64>, Vec<f64>) {
    let chains = (0..count).map(|_| random_chain(n, 2.0, r)).collect();
    let q = (0..count * n).map(|_| r.random_range(-1.0..1.0)).collect();
    let qd = (0..count * n).map(|_| r.random_range(-1.0..1.0)).collect();
    (chains, q, qd)
}

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool")
}

/// Times `f` called from inside `pool`, as a program that runs in the pool would call it
/// (entering the pool once per sample, not once per call).
fn in_pool(b: &mut Bencher<'_>, pool: &rayon::ThreadPool, mut f: impl FnMut() + Send) {
    b.iter_custom(|iters| {
        pool.install(|| {
            let start = Instant::now();
            for _ in 0..iters {
                f();
            }
            start.elapsed()
        })
    })
}

/// A random state of each 3D chain of `models`: polar angles in [0.1, 1), azimuths in
/// [0, 6), rates 0.5.
fn spatial_states(models: &[Directions<U3>], r: &mut ChaCha8Rng) -> Vec<DVector<f64>> {
    models
        .iter()
        .map(|m| {
            let n = m.links();
            let angles: Vec<f64> = (0..2 * n)
                .map(|i| if i < n { r.random_range(0.1..1.0) } else { r.random_range(0.0..6.0) })
                .collect();
            m.from_spherical(&angles, &vec![0.5; 2 * n]).expect("state")
        })
        .collect()
}

/// One call of accelerations for 1024 chains of 100 links, planar and 3D, on one thread and
/// on two: the same calls as `accelerations/…/100` with sixteen times the work per call.
fn large_batches(c: &mut Criterion) {
    const LARGE: usize = 1024;
    const N: usize = 100;
    let mut group = c.benchmark_group("accelerations");
    group.warm_up_time(Duration::from_millis(300)).measurement_time(Duration::from_secs(1)).sample_size(20);
    group.throughput(Throughput::Elements(LARGE as u64));
    let mut r = ChaCha8Rng::seed_from_u64(43);
    let (chains, q, qd) = random_batch(LARGE, N, &mut r);
    let mut out = vec![0.0; LARGE * N];
    let planar = PlanarBatch::new(chains.clone()).expect("batch");
    let models: Vec<_> = chains.into_iter().map(Directions::<U3>::new).collect();
    let x: Vec<f64> = spatial_states(&models, &mut r).iter().flat_map(|x| x.iter().copied()).collect();
    let spatial = DirectionsBatch::new(models).expect("batch");
    let mut out3 = vec![0.0; LARGE * 3 * N];
    for threads in [1, 2] {
        let pool = pool(threads);
        let id = BenchmarkId::new(format!("planar/batch_{threads}_threads_{LARGE}_chains"), N);
        group.bench_with_input(id, &N, |b, _| {
            in_pool(b, &pool, || {
                planar.accelerations(&q, &qd, None, None, &mut out).expect("batch");
            })
        });
        let id = BenchmarkId::new(format!("spatial/batch_{threads}_threads_{LARGE}_chains"), N);
        group.bench_with_input(id, &N, |b, _| {
            in_pool(b, &pool, || {
                spatial.accelerations(0.0, &x, &mut out3).expect("batch");
            })
        });
    }
    group.finish();
}

fn accelerations(c: &mut Criterion) {
    let mut group = c.benchmark_group("accelerations");
    group.warm_up_time(Duration::from_millis(300)).measurement_time(Duration::from_secs(1)).sample_size(30);
    group.throughput(Throughput::Elements(CHAINS as u64));
    let mut r = ChaCha8Rng::seed_from_u64(31);
    for n in [8, 20, 100] {
        let (chains, q, qd) = random_batch(CHAINS, n, &mut r);
        let mut out = vec![0.0; CHAINS * n];

        let singles: Vec<_> = chains.iter().cloned().map(PlanarTension::new).collect();
        let states: Vec<_> = (0..CHAINS)
            .map(|k| {
                let row = k * n..(k + 1) * n;
                (DVector::from_column_slice(&q[row.clone()]), DVector::from_column_slice(&qd[row]))
            })
            .collect();
        let inputs = Inputs::<Dyn, U2>::zeros(Dyn(n));
        let mut one = DVector::zeros(n);
        group.bench_with_input(BenchmarkId::new("planar/single", n), &n, |b, _| {
            b.iter(|| {
                for (model, (q, qd)) in singles.iter().zip(&states) {
                    model.accelerations(q, qd, &inputs, &mut one).expect("single");
                    black_box(&one);
                }
            })
        });
        let batch = PlanarBatch::new(chains.clone()).expect("batch");
        thread_rows(&mut group, ("planar", n), || {
            batch.accelerations(&q, &qd, None, None, &mut out).expect("batch");
        });
        // What `with_avx512(false)` trades, on a CPU with AVX-512: four lanes instead of eight.
        let four = batch.clone().with_avx512(false);
        for threads in [1, 2].into_iter().filter(|_| n == 100 && batch.uses_avx512()) {
            let pool = pool(threads);
            let id = BenchmarkId::new(format!("planar/batch_{threads}_threads_four_lanes"), n);
            group.bench_with_input(id, &n, |b, _| {
                in_pool(b, &pool, || {
                    four.accelerations(&q, &qd, None, None, &mut out).expect("batch");
                })
            });
        }
        let narrow = |v: &[f64]| v.iter().map(|&x| x as f32).collect::<Vec<_>>();
        let (q32, qd32, mut out32) = (narrow(&q), narrow(&qd), vec![0.0f32; out.len()]);
        let pool1 = pool(1);
        group.bench_with_input(BenchmarkId::new("planar/batch_f32_1_thread", n), &n, |b, _| {
            in_pool(b, &pool1, || {
                batch.accelerations_f32(&q32, &qd32, None, None, &mut out32).expect("batch");
            })
        });

        let models: Vec<_> = chains.iter().cloned().map(Directions::<U3>::new).collect();
        let x = spatial_states(&models, &mut r);
        let mut one = vec![0.0; 3 * n];
        group.bench_with_input(BenchmarkId::new("spatial/single", n), &n, |b, _| {
            b.iter(|| {
                for (model, x) in models.iter().zip(&x) {
                    model.accelerations(0.0, x, &mut one, None).expect("single");
                    black_box(&one);
                }
            })
        });
        let batch = DirectionsBatch::new(models).expect("batch");
        let flat: Vec<f64> = x.iter().flat_map(|x| x.iter().copied()).collect();
        let mut out = vec![0.0; CHAINS * 3 * n];
        thread_rows(&mut group, ("spatial", n), || {
            batch.accelerations(0.0, &flat, &mut out).expect("batch");
        });
        let four = batch.clone().with_avx512(false);
        for threads in [1, 2].into_iter().filter(|_| n == 100 && batch.uses_avx512()) {
            let pool = pool(threads);
            let id = BenchmarkId::new(format!("spatial/batch_{threads}_threads_four_lanes"), n);
            group.bench_with_input(id, &n, |b, _| {
                in_pool(b, &pool, || {
                    four.accelerations(0.0, &flat, &mut out).expect("batch");
                })
            });
        }
        let (flat, mut out) = (flat.iter().map(|&v| v as f32).collect::<Vec<_>>(), vec![0.0f32; out.len()]);
        let pool = pool(1);
        group.bench_with_input(BenchmarkId::new("spatial/batch_f32_1_thread", n), &n, |b, _| {
            in_pool(b, &pool, || {
                batch.accelerations_f32(0.0, &flat, &mut out).expect("batch");
            })
        });
    }
    group.finish();
}

fn rk4(c: &mut Criterion) {
    let mut group = c.benchmark_group("rk4");
    group.warm_up_time(Duration::from_millis(300)).measurement_time(Duration::from_secs(2)).sample_size(20);
    group.throughput(Throughput::Elements(CHAINS as u64));
    let mut r = ChaCha8Rng::seed_from_u64(11);
    let n = 100;
    let models: Vec<_> = (0..CHAINS)
        .map(|_| {
            let drive = Circle::new(r.random_range(0.005..0.05), r.random_range(1.0..10.0)).expect("drive");
            Directions::<U3>::new(random_chain(n, 1.1, &mut r)).with_drive(drive)
        })
        .collect();
    // Each whirl 2 s into its spin-up from hanging at rest.
    let start: Vec<State<Dyn>> = models
        .iter()
        .map(|m| {
            let mut state = State::new(0.0, m.hanging());
            let mut rk4 = Projected::new(Rk4::new(m));
            for _ in 0..2000 {
                rk4.step(m, &mut state, 1e-3).expect("spin-up");
            }
            state
        })
        .collect();
    let mut solvers: Vec<_> = models.iter().map(|m| Projected::new(Rk4::new(m))).collect();
    let mut states = start.clone();
    group.bench_function("whirl_100/single", |b| {
        b.iter(|| {
            for ((model, rk4), state) in models.iter().zip(&mut solvers).zip(&mut states) {
                rk4.step(model, state, 1e-3).expect("single");
            }
        })
    });
    let batch = DirectionsBatch::new(models).expect("batch");
    for threads in [1, 2] {
        let pool = pool(threads);
        let mut states = start.clone();
        group.bench_function(format!("whirl_100/batch_{threads}_threads"), |b| {
            in_pool(b, &pool, || {
                batch.step_rk4(&mut states, 1e-3).expect("batch");
            })
        });
    }
    // 100 steps per call: the states stay in lanes between steps.
    group.throughput(Throughput::Elements(100 * CHAINS as u64));
    for threads in [1, 2] {
        let pool = pool(threads);
        let mut states = start.clone();
        group.bench_function(format!("whirl_100/batch_{threads}_threads_100_steps"), |b| {
            in_pool(b, &pool, || {
                batch.integrate_rk4(&mut states, 1e-3, 100).expect("batch");
            })
        });
    }
    // The same in single precision, eight chains per AVX2 register, the time going on.
    let (one, mut t) = (pool(1), 2.0);
    let mut rows: Vec<f32> = start.iter().flat_map(|s| s.x().iter().map(|&v| v as f32)).collect();
    group.bench_function("whirl_100/batch_f32_1_thread_100_steps", |b| {
        in_pool(b, &one, || {
            let failures = batch.integrate_rk4_f32(&mut rows, t, 1e-3, 100).expect("batch");
            assert!(failures.is_empty(), "{failures:?}");
            t += 0.1;
        })
    });
    // The implicit rod midpoint, 10 steps per call, every call from the same states (a run
    // of them went on into a whirl whose steps cost more): each chain on its own, against
    // the batch. At 1 ms, and at 50 ms, where the chains take more Newton iterations and
    // unequal numbers of them (a block of lanes iterates until its last lane converges):
    // the iterations and halvings of the chains alone are printed.
    group.throughput(Throughput::Elements(10 * CHAINS as u64));
    for (h, name) in [(1e-3, ""), (5e-2, "_of_50ms")] {
        let single = |states: &mut [State<Dyn>]| {
            let mut stats = Vec::new();
            for (k, state) in states.iter_mut().enumerate() {
                let model = batch.model(k);
                let mut step = RodMidpoint::new();
                for _ in 0..10 {
                    step.step(model, state, h).expect("single");
                }
                stats.push(*step.stats());
            }
            stats
        };
        let stats = single(&mut start.clone());
        let iterations: Vec<u64> = stats.iter().map(|s| s.newton_iterations).collect();
        let halved: u64 = stats.iter().map(|s| s.halved_steps).sum();
        let (fewest, most) = (iterations.iter().min().unwrap_or(&0), iterations.iter().max().unwrap_or(&0));
        eprintln!(
            "rod midpoint steps of {h} s: {fewest} to {most} Newton iterations in 10 steps per chain, \
             {halved} halvings in {} chain-steps",
            10 * CHAINS
        );
        let mut states = start.clone();
        group.bench_function(format!("whirl_100/rod_midpoint_single_10_steps{name}"), |b| {
            b.iter(|| {
                states.clone_from(&start);
                single(&mut states)
            })
        });
        for threads in [1, 2] {
            let pool = pool(threads);
            let mut states = start.clone();
            group.bench_function(
                format!("whirl_100/rod_midpoint_batch_{threads}_threads_10_steps{name}"),
                |b| {
                    in_pool(b, &pool, || {
                        states.clone_from(&start);
                        batch.integrate_rod_midpoint(&mut states, h, 10).expect("batch");
                    })
                },
            );
        }
        // The same in single precision (`integrate_rod_midpoint_f32`), every call from the
        // same states rounded.
        let rows32: Vec<f32> = start.iter().flat_map(|s| s.x().iter().map(|&v| v as f32)).collect();
        let mut rows = rows32.clone();
        group.bench_function(format!("whirl_100/rod_midpoint_batch_f32_1_thread_10_steps{name}"), |b| {
            in_pool(b, &one, || {
                rows.clone_from(&rows32);
                let failures = batch.integrate_rod_midpoint_f32(&mut rows, 2.0, h, 10).expect("batch");
                assert!(failures.is_empty(), "{failures:?}");
            })
        });
    }

    group.finish();
}

/// 100 RK4 steps of 0.1 ms of 64 free planar chains of `n` links swinging from random
/// angles: `Rk4` on each chain's `FirstOrder` against `PlanarBatch::integrate_rk4`.
fn planar_rk4(c: &mut Criterion) {
    const STEPS: usize = 100;
    let mut group = c.benchmark_group("rk4");
    group.warm_up_time(Duration::from_millis(300)).measurement_time(Duration::from_secs(2)).sample_size(20);
    group.throughput(Throughput::Elements((STEPS * CHAINS) as u64));
    let mut r = ChaCha8Rng::seed_from_u64(13);
    for n in [20, 100] {
        let chains: Vec<_> = (0..CHAINS).map(|_| random_chain(n, 1.1, &mut r)).collect();
        let start: Vec<State<Dyn>> = (0..CHAINS)
            .map(|_| {
                let x = (0..2 * n).map(|i| if i < n { r.random_range(-0.5..0.5) } else { 0.0 });
                State::new(0.0, DVector::from_iterator(2 * n, x))
            })
            .collect();
        let systems: Vec<_> = chains.iter().map(|c| FirstOrder::new(PlanarTension::new(c.clone()))).collect();
        let mut solvers: Vec<_> = systems.iter().map(Rk4::new).collect();
        let mut states = start.clone();
        group.bench_with_input(BenchmarkId::new("planar_100_steps/single", n), &n, |b, _| {
            b.iter(|| each_alone(&systems, &mut solvers, &mut states, STEPS))
        });
        let batch = PlanarBatch::new(chains.clone()).expect("batch");
        for threads in [1, 2] {
            let pool = pool(threads);
            let mut states = start.clone();
            group.bench_with_input(
                BenchmarkId::new(format!("planar_100_steps/batch_{threads}_threads"), n),
                &n,
                |b, _| {
                    in_pool(b, &pool, || {
                        let failures =
                            batch.integrate_rk4(&mut states, None, None, 1e-4, STEPS).expect("batch");
                        assert!(failures.is_empty(), "{failures:?}");
                    })
                },
            );
        }
        // Each chain's pivot shaken vertically (Kapitza), read at every stage: alone (`Rk4`
        // on `FirstOrder::with_inputs(PlanarTension, Driven)`) and in the batch, one thread.
        if n == 20 {
            let drives: Vec<Harmonic<U2>> = (0..CHAINS)
                .map(|k| Harmonic::vertical(0.002, 200.0 + k as f64, 0.0).expect("drive"))
                .collect();
            let driven: Vec<_> = chains
                .iter()
                .zip(&drives)
                .map(|(c, d)| {
                    let inputs = Driven::new(d.clone(), ConstantTorque(DVector::zeros(n)));
                    FirstOrder::with_inputs(PlanarTension::new(c.clone()), inputs)
                })
                .collect();
            let mut solvers: Vec<_> = driven.iter().map(Rk4::new).collect();
            let mut states = start.clone();
            group.bench_with_input(BenchmarkId::new("planar_100_steps/single_driven", n), &n, |b, _| {
                b.iter(|| each_alone(&driven, &mut solvers, &mut states, STEPS))
            });
            let (one, mut states) = (pool(1), start.clone());
            group.bench_with_input(
                BenchmarkId::new("planar_100_steps/batch_1_threads_driven", n),
                &n,
                |b, _| {
                    in_pool(b, &one, || {
                        let failures = batch
                            .integrate_rk4_driven(&mut states, &drives, None, 1e-4, STEPS)
                            .expect("batch");
                        assert!(failures.is_empty(), "{failures:?}");
                    })
                },
            );
            // The same in single precision, eight chains a register.
            let mut rows: Vec<f32> = start.iter().flat_map(|s| s.x().iter().map(|&v| v as f32)).collect();
            let mut carry = vec![0.0f32; rows.len()];
            group.bench_with_input(
                BenchmarkId::new("planar_100_steps/batch_f32_1_thread_driven", n),
                &n,
                |b, _| {
                    in_pool(b, &one, || {
                        let failures = batch
                            .integrate_rk4_driven_f32(
                                (&mut rows, &mut carry),
                                (0.0, &drives),
                                None,
                                1e-4,
                                STEPS,
                            )
                            .expect("batch");
                        assert!(failures.is_empty(), "{failures:?}");
                    })
                },
            );
        }
        // Single precision, eight chains a register, the states as rows of (θ, θ̇).
        let mut rows: Vec<f32> = start.iter().flat_map(|s| s.x().iter().map(|&v| v as f32)).collect();
        let mut carry = vec![0.0f32; rows.len()];
        let one = pool(1);
        group.bench_with_input(BenchmarkId::new("planar_100_steps/batch_f32_1_thread", n), &n, |b, _| {
            in_pool(b, &one, || {
                let failures =
                    batch.integrate_rk4_f32((&mut rows, &mut carry), None, None, 1e-4, STEPS).expect("batch");
                assert!(failures.is_empty(), "{failures:?}");
            })
        });
    }
    group.finish();
}

/// `steps` RK4 steps of 0.1 ms of each system from its state, one chain after another.
fn each_alone<Sys: System<Dim = Dyn>>(
    systems: &[Sys],
    solvers: &mut [Rk4<Dyn>],
    states: &mut [State<Dyn>],
    steps: usize,
) {
    for ((system, rk4), state) in systems.iter().zip(solvers).zip(states) {
        for _ in 0..steps {
            rk4.step(system, state, 1e-4).expect("single");
        }
    }
}

/// One generated model type: its `CHAINS` models one call each against the batch.
fn generated_one<M: PlanarKernel<N> + From<Chain<Const<N>>> + Clone, const N: usize>(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    r: &mut ChaCha8Rng,
) {
    let models: Vec<M> = (0..CHAINS).map(|_| M::from(fixed_chain::<N>(r))).collect();
    let q: Vec<f64> = (0..CHAINS * N).map(|_| r.random_range(-1.0..1.0)).collect();
    let qd: Vec<f64> = (0..CHAINS * N).map(|_| r.random_range(-1.0..1.0)).collect();
    let states: Vec<(SVector<f64, N>, SVector<f64, N>)> = (0..CHAINS)
        .map(|k| {
            let row = k * N..(k + 1) * N;
            (SVector::from_column_slice(&q[row.clone()]), SVector::from_column_slice(&qd[row]))
        })
        .collect();
    let inputs = Inputs::<Const<N>, U2>::zeros(Const::<N>);
    let mut one = SVector::<f64, N>::zeros();
    group.bench_with_input(BenchmarkId::new("planar/single", N), &N, |b, _| {
        b.iter(|| {
            for (model, (q, qd)) in models.iter().zip(&states) {
                model.accelerations(q, qd, &inputs, &mut one).expect("single");
                black_box(&one);
            }
        })
    });
    let batch = UnrolledBatch::new(models).expect("batch");
    let mut out = vec![0.0; CHAINS * N];
    for threads in [1, 2] {
        let pool = pool(threads);
        group.bench_with_input(BenchmarkId::new(format!("planar/batch_{threads}_threads"), N), &N, |b, _| {
            in_pool(b, &pool, || {
                batch.accelerations(&q, &qd, None, None, &mut out).expect("batch");
            })
        });
    }
    let pool = pool(1);
    // What `with_avx512(false)` trades, on a CPU with AVX-512: four lanes instead of eight.
    if batch.uses_avx512() {
        let four = batch.clone().with_avx512(false);
        group.bench_with_input(BenchmarkId::new("planar/batch_1_threads_four_lanes", N), &N, |b, _| {
            in_pool(b, &pool, || {
                four.accelerations(&q, &qd, None, None, &mut out).expect("batch");
            })
        });
    }
    let (q32, qd32): (Vec<f32>, Vec<f32>) = q.iter().zip(&qd).map(|(&a, &b)| (a as f32, b as f32)).unzip();
    let mut out32 = vec![0.0f32; CHAINS * N];
    group.bench_with_input(BenchmarkId::new("planar/batch_f32_1_thread", N), &N, |b, _| {
        in_pool(b, &pool, || {
            batch.accelerations_f32(&q32, &qd32, None, None, &mut out32).expect("batch");
        })
    });
}

/// One generated spatial model type: its `CHAINS` models one call each against the batch,
/// at polar angles between 0.3 and 2.8 rad.
fn generated_spatial<M, const N: usize, const D: usize>(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    r: &mut ChaCha8Rng,
) where
    M: SpatialKernel<N> + Model<Links = Const<N>, Dof = Const<D>, Space = U3> + From<Chain<Const<N>>> + Clone,
{
    let models: Vec<M> = (0..CHAINS).map(|_| M::from(fixed_chain::<N>(r))).collect();
    let q: Vec<f64> = (0..CHAINS * D)
        .map(|i| if i % D < N { r.random_range(0.3..2.8) } else { r.random_range(-3.0..3.0) })
        .collect();
    let qd: Vec<f64> = (0..CHAINS * D).map(|_| r.random_range(-1.0..1.0)).collect();
    let states: Vec<(SVector<f64, D>, SVector<f64, D>)> = (0..CHAINS)
        .map(|k| {
            let row = k * D..(k + 1) * D;
            (SVector::from_column_slice(&q[row.clone()]), SVector::from_column_slice(&qd[row]))
        })
        .collect();
    let inputs = Inputs::<Const<D>, U3>::zeros(Const::<D>);
    let mut one = SVector::<f64, D>::zeros();
    group.bench_with_input(BenchmarkId::new("spatial/single", N), &N, |b, _| {
        b.iter(|| {
            for (model, (q, qd)) in models.iter().zip(&states) {
                model.accelerations(q, qd, &inputs, &mut one).expect("single");
                black_box(&one);
            }
        })
    });
    let batch = UnrolledSpatialBatch::new(models).expect("batch");
    let four = batch.clone().with_avx512(false);
    let mut out = vec![0.0; CHAINS * D];
    batch_rows(group, ("spatial", N), [&four, &batch], |batch| {
        batch.accelerations(&q, &qd, None, None, &mut out).expect("batch");
    });
    let (q32, qd32): (Vec<f32>, Vec<f32>) = q.iter().zip(&qd).map(|(&a, &b)| (a as f32, b as f32)).unzip();
    let (mut out32, one) = (vec![0.0f32; CHAINS * D], pool(1));
    group.bench_with_input(BenchmarkId::new("spatial/batch_f32_1_thread", N), &N, |b, _| {
        in_pool(b, &one, || {
            batch.accelerations_f32(&q32, &qd32, None, None, &mut out32).expect("batch");
        })
    });
}

/// 100 RK4 steps of 0.1 ms of each of the `CHAINS` spatial models alone against the
/// batch's run (`D = 2N` coordinates, states of `X = 4N`), polar angles between 0.3 and
/// 2.8 rad.
fn generated_spatial_rk4<M, const N: usize, const D: usize, const X: usize>(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    r: &mut ChaCha8Rng,
) where
    M: SpatialKernel<N> + Model<Links = Const<N>, Dof = Const<D>, Space = U3> + From<Chain<Const<N>>> + Clone,
    Const<D>: nalgebra::DimMul<U2, Output = Const<X>>,
{
    const STEPS: usize = 100;
    const H: f64 = 1e-4;
    let models: Vec<M> = (0..CHAINS).map(|_| M::from(fixed_chain::<N>(r))).collect();
    let states: Vec<State<Const<X>>> = (0..CHAINS)
        .map(|_| {
            let x = SVector::<f64, X>::from_fn(|i, _| match i / N {
                0 => r.random_range(0.3..2.8),
                1 => r.random_range(-3.0..3.0),
                _ => r.random_range(-1.0..1.0),
            });
            State::new(0.0, x)
        })
        .collect();
    group.throughput(Throughput::Elements((CHAINS * STEPS) as u64));
    let systems: Vec<_> = models.iter().cloned().map(FirstOrder::new).collect();
    let mut rk4 = Rk4::new(&systems[0]);
    group.bench_with_input(BenchmarkId::new("rk4_100_steps/spatial_single", N), &N, |b, _| {
        b.iter(|| {
            for (system, state) in systems.iter().zip(&states) {
                let mut state = state.clone();
                for _ in 0..STEPS {
                    rk4.step(system, &mut state, H).expect("single");
                }
                black_box(&state);
            }
        })
    });
    let batch = UnrolledSpatialBatch::new(models.clone()).expect("batch");
    for threads in [1, 2] {
        let pool = pool(threads);
        let id = BenchmarkId::new(format!("rk4_100_steps/spatial_batch_{threads}_threads"), N);
        group.bench_with_input(id, &N, |b, _| {
            in_pool(b, &pool, || {
                let mut run = states.clone();
                let failures = batch.integrate_rk4(&mut run, None, None, H, STEPS).expect("batch");
                assert!(failures.is_empty());
                black_box(&run);
            })
        });
    }
    // The same run in single precision: rows of f32 and their compensations.
    let rows: Vec<f32> = states.iter().flat_map(|s| s.x().iter().map(|&x| x as f32)).collect();
    let one = pool(1);
    group.bench_with_input(BenchmarkId::new("rk4_100_steps/spatial_batch_f32_1_thread", N), &N, |b, _| {
        in_pool(b, &one, || {
            let (mut x, mut carry) = (rows.clone(), vec![0.0f32; rows.len()]);
            let failures =
                batch.integrate_rk4_f32((&mut x, &mut carry), None, None, H, STEPS).expect("batch");
            assert!(failures.is_empty());
            black_box(&x);
        })
    });
    // Each chain with its torques and pivot acceleration held (a controller's action).
    let torque: Vec<f64> = (0..CHAINS * D).map(|_| r.random_range(-1e-4..1e-4)).collect();
    let pivot: Vec<f64> = (0..CHAINS * 3).map(|_| r.random_range(-1.0..1.0)).collect();
    group.bench_with_input(BenchmarkId::new("rk4_100_steps/spatial_held_batch_1_threads", N), &N, |b, _| {
        in_pool(b, &one, || {
            let mut run = states.clone();
            let failures =
                batch.integrate_rk4(&mut run, Some(&torque), Some(&pivot), H, STEPS).expect("batch");
            assert!(failures.is_empty());
            black_box(&run);
        })
    });
    // Each chain whirled by its top end (a circle of its own radius and speed), its pivot's
    // acceleration asked at each stage's time.
    let drives: Vec<Circle> = (0..CHAINS)
        .map(|_| Circle::new(r.random_range(0.0..0.05), r.random_range(1.0..20.0)).expect("drive"))
        .collect();
    let whirled: Vec<_> = models
        .iter()
        .zip(&drives)
        .map(|(model, drive)| {
            let torque = ConstantTorque::zeros(Const::<D>);
            FirstOrder::with_inputs(model.clone(), Driven::new(*drive, torque))
        })
        .collect();
    let mut rk4 = Rk4::new(&whirled[0]);
    group.bench_with_input(BenchmarkId::new("rk4_100_steps/spatial_whirled_single", N), &N, |b, _| {
        b.iter(|| {
            for (system, state) in whirled.iter().zip(&states) {
                let mut state = state.clone();
                for _ in 0..STEPS {
                    rk4.step(system, &mut state, H).expect("single");
                }
                black_box(&state);
            }
        })
    });
    let one = pool(1);
    group.bench_with_input(
        BenchmarkId::new("rk4_100_steps/spatial_whirled_batch_1_threads", N),
        &N,
        |b, _| {
            in_pool(b, &one, || {
                let mut run = states.clone();
                let failures = batch.integrate_rk4_driven(&mut run, &drives, None, H, STEPS).expect("batch");
                assert!(failures.is_empty());
                black_box(&run);
            })
        },
    );
    // Four lanes (every CPU without AVX-512): a unit of one block asks its drives once a stage.
    let four = batch.clone().with_avx512(false);
    group.bench_with_input(
        BenchmarkId::new("rk4_100_steps/spatial_whirled_batch_1_threads_four_lanes", N),
        &N,
        |b, _| {
            in_pool(b, &one, || {
                let mut run = states.clone();
                let failures = four.integrate_rk4_driven(&mut run, &drives, None, H, STEPS).expect("batch");
                assert!(failures.is_empty());
                black_box(&run);
            })
        },
    );
    group.bench_with_input(
        BenchmarkId::new("rk4_100_steps/spatial_whirled_batch_f32_1_thread", N),
        &N,
        |b, _| {
            in_pool(b, &one, || {
                let (mut x, mut carry) = (rows.clone(), vec![0.0f32; rows.len()]);
                let run = (&mut x[..], &mut carry[..]);
                let failures =
                    batch.integrate_rk4_driven_f32(run, (0.0, &drives), None, H, STEPS).expect("batch");
                assert!(failures.is_empty());
                black_box(&x);
            })
        },
    );
    group.throughput(Throughput::Elements(CHAINS as u64));
}

/// 100 RK4 steps of each of the `CHAINS` models alone against the batch's run.
fn generated_rk4<M, const N: usize, const D: usize>(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    r: &mut ChaCha8Rng,
) where
    M: PlanarKernel<N> + From<Chain<Const<N>>> + Clone,
    Const<N>: nalgebra::DimMul<U2, Output = Const<D>>,
{
    const STEPS: usize = 100;
    // Short of the stiffest mode of 8 links of 1 cm: every chain runs all its steps.
    const H: f64 = 1e-4;
    let models: Vec<M> = (0..CHAINS).map(|_| M::from(fixed_chain::<N>(r))).collect();
    let states: Vec<State<Const<D>>> = (0..CHAINS)
        .map(|_| State::new(0.0, SVector::<f64, D>::from_fn(|_, _| r.random_range(-1.0..1.0))))
        .collect();
    group.throughput(Throughput::Elements((CHAINS * STEPS) as u64));
    let systems: Vec<_> = models.iter().cloned().map(FirstOrder::new).collect();
    let mut rk4 = Rk4::new(&systems[0]);
    group.bench_with_input(BenchmarkId::new("rk4_100_steps/single", N), &N, |b, _| {
        b.iter(|| {
            for (system, state) in systems.iter().zip(&states) {
                let mut state = state.clone();
                for _ in 0..STEPS {
                    rk4.step(system, &mut state, H).expect("single");
                }
                black_box(&state);
            }
        })
    });
    let batch = UnrolledBatch::new(models).expect("batch");
    for threads in [1, 2] {
        let pool = pool(threads);
        group.bench_with_input(
            BenchmarkId::new(format!("rk4_100_steps/batch_{threads}_threads"), N),
            &N,
            |b, _| {
                in_pool(b, &pool, || {
                    let mut run = states.clone();
                    batch.integrate_rk4(&mut run, None, None, H, STEPS).expect("batch");
                    black_box(&run);
                })
            },
        );
    }
    // The same run in single precision: rows of f32 and their compensations.
    let rows: Vec<f32> = states.iter().flat_map(|s| s.x().iter().map(|&x| x as f32)).collect();
    let one = pool(1);
    group.bench_with_input(BenchmarkId::new("rk4_100_steps/batch_f32_1_thread", N), &N, |b, _| {
        in_pool(b, &one, || {
            let (mut x, mut carry) = (rows.clone(), vec![0.0f32; rows.len()]);
            batch.integrate_rk4_f32((&mut x, &mut carry), None, None, H, STEPS).expect("batch");
            black_box(&x);
        })
    });
    // What `with_avx512(false)` trades, on a CPU with AVX-512: four lanes instead of eight.
    if batch.uses_avx512() {
        let (four, pool) = (batch.clone().with_avx512(false), pool(1));
        group.bench_with_input(
            BenchmarkId::new("rk4_100_steps/batch_1_threads_four_lanes", N),
            &N,
            |b, _| {
                in_pool(b, &pool, || {
                    let mut run = states.clone();
                    four.integrate_rk4(&mut run, None, None, H, STEPS).expect("batch");
                    black_box(&run);
                })
            },
        );
    }
    group.throughput(Throughput::Elements(CHAINS as u64));
}

/// [`random_chain`] of `N` links.
fn fixed_chain<const N: usize>(r: &mut ChaCha8Rng) -> Chain<Const<N>> {
    let chain = random_chain(N, 2.0, r);
    Chain::new(chain.masses().as_slice(), chain.lengths().as_slice(), 9.81)
        .and_then(|c| c.with_damping(chain.damping().as_slice()))
        .expect("chain")
}

fn generated(c: &mut Criterion) {
    let mut group = c.benchmark_group("generated");
    group.warm_up_time(Duration::from_millis(300)).measurement_time(Duration::from_secs(1)).sample_size(30);
    group.throughput(Throughput::Elements(CHAINS as u64));
    let mut r = ChaCha8Rng::seed_from_u64(37);
    generated_one::<Planar4, 4>(&mut group, &mut r);
    generated_one::<Planar8, 8>(&mut group, &mut r);
    generated_one::<Planar16, 16>(&mut group, &mut r);
    generated_spatial::<Spatial4, 4, 8>(&mut group, &mut r);
    generated_spatial::<Spatial8, 8, 16>(&mut group, &mut r);
    generated_rk4::<Planar4, 4, 8>(&mut group, &mut r);
    generated_rk4::<Planar8, 8, 16>(&mut group, &mut r);
    generated_spatial_rk4::<Spatial4, 4, 8, 16>(&mut group, &mut r);
    group.finish();
}

/// `∂θ̈/∂θ` and `∂θ̈/∂θ̇` of 64 planar chains of 8, 20 and 100 links: one chain at a time
/// against the batch on one thread (in four lanes too) and on two.
fn jacobians(c: &mut Criterion) {
    const N: usize = 20;
    let mut group = c.benchmark_group("jacobians");
    group.warm_up_time(Duration::from_millis(300)).measurement_time(Duration::from_secs(1)).sample_size(30);
    group.throughput(Throughput::Elements(CHAINS as u64));
    let mut r = ChaCha8Rng::seed_from_u64(41);
    for n in [8, N, 100] {
        let (chains, q, qd) = random_batch(CHAINS, n, &mut r);
        let singles: Vec<_> = chains.iter().cloned().map(PlanarTension::new).collect();
        let inputs = Inputs::<Dyn, U2>::zeros(Dyn(n));
        let mut out = Jacobians::zeros(&singles[0]);
        let (mut x, mut v) = (DVector::zeros(n), DVector::zeros(n));
        // "single_kept": the same loop copying every chain's result row by row into
        // `(B, n, n)` arrays, as the batch returns them.
        let (mut dq, mut dqd) = (vec![0.0; CHAINS * n * n], vec![0.0; CHAINS * n * n]);
        for (name, keep) in [("planar/single", false), ("planar/single_kept", true)] {
            group.bench_with_input(BenchmarkId::new(name, n), &n, |b, _| {
                b.iter(|| {
                    for (k, model) in singles.iter().enumerate() {
                        x.copy_from_slice(&q[k * n..(k + 1) * n]);
                        v.copy_from_slice(&qd[k * n..(k + 1) * n]);
                        model.state_jacobians(&x, &v, &inputs, &mut out).expect("single");
                        if keep {
                            let block = k * n * n..(k + 1) * n * n;
                            dq[block.clone()].copy_from_slice(out.q.transpose().as_slice());
                            dqd[block].copy_from_slice(out.qd.transpose().as_slice());
                        }
                        black_box(&out);
                    }
                })
            });
        }
        let batch = PlanarBatch::new(chains).expect("batch");
        let four = batch.clone().with_avx512(false);
        batch_rows(&mut group, ("planar", n), [&four, &batch], |batch| {
            batch.state_jacobians(&q, &qd, None, None, &mut dq, &mut dqd).expect("batch");
        });
    }
    // The same in single precision (eight lanes a register, at every length).
    for n in [8, N, 100] {
        let (chains, q, qd) = random_batch(CHAINS, n, &mut r);
        let (q, qd): (Vec<_>, Vec<_>) = q.iter().zip(&qd).map(|(&a, &b)| (a as f32, b as f32)).unzip();
        let batch = PlanarBatch::new(chains).expect("batch");
        let (mut dq, mut dqd) = (vec![0.0f32; CHAINS * n * n], vec![0.0f32; CHAINS * n * n]);
        let one = pool(1);
        group.bench_with_input(BenchmarkId::new("planar/batch_f32_1_thread", n), &n, |b, _| {
            in_pool(b, &one, || {
                batch.state_jacobians_f32(&q, &qd, None, None, &mut dq, &mut dqd).expect("batch");
            })
        });
    }
    // The same in 3D directions: each chain's `Directions::analytic_jacobian` (the whole
    // first-order Jacobian, as a user calls it), and kept (its lower blocks copied into
    // row-major `(B, h, h)` arrays, h = 3n, as the batch returns them), against
    // `DirectionsBatch::state_jacobians`.
    for n in [8, N, 100] {
        let models: Vec<Directions<U3>> =
            (0..CHAINS).map(|_| Directions::new(random_chain(n, 2.0, &mut r))).collect();
        let x = spatial_states(&models, &mut r);
        let h = 3 * n;
        let mut jacobian = nalgebra::DMatrix::zeros(2 * h, 2 * h);
        let (mut du, mut dw) = (vec![0.0; CHAINS * h * h], vec![0.0; CHAINS * h * h]);
        for (name, keep) in [("spatial/single", false), ("spatial/single_kept", true)] {
            group.bench_with_input(BenchmarkId::new(name, n), &n, |b, _| {
                b.iter(|| {
                    for (k, (model, x)) in models.iter().zip(&x).enumerate() {
                        model.analytic_jacobian(0.0, x, &mut jacobian).expect("single");
                        if keep {
                            let lower = jacobian.rows(h, h);
                            let block = k * h * h..(k + 1) * h * h;
                            du[block.clone()].copy_from_slice(lower.columns(0, h).transpose().as_slice());
                            dw[block].copy_from_slice(lower.columns(h, h).transpose().as_slice());
                        }
                        black_box(&jacobian);
                    }
                })
            });
        }
        let batch = DirectionsBatch::new(models).expect("batch");
        let joined: Vec<f64> = x.iter().flat_map(|x| x.iter().copied()).collect();
        let four = batch.clone().with_avx512(false);
        batch_rows(&mut group, ("spatial", n), [&four, &batch], |batch| {
            batch.state_jacobians(0.0, &joined, &mut du, &mut dw).expect("batch");
        });
        let one = pool(1);
        let narrow: Vec<f32> = joined.iter().map(|&v| v as f32).collect();
        let (mut du32, mut dw32) = (vec![0.0f32; CHAINS * h * h], vec![0.0f32; CHAINS * h * h]);
        group.bench_with_input(BenchmarkId::new("spatial/batch_f32_1_thread", n), &n, |b, _| {
            in_pool(b, &one, || {
                batch.state_jacobians_f32(0.0, &narrow, &mut du32, &mut dw32).expect("batch");
            })
        });
    }
    group.finish();
}

/// The rows `{family}/batch_1_threads_four_lanes/n`, `…/batch_1_threads/n` and
/// `…/batch_2_threads/n`: `call` of the batch in four lanes on one thread, then of the
/// batch (in eight lanes where the CPU has AVX-512) on one thread and on two.
fn batch_rows<B: Sync>(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    (family, n): (&str, usize),
    [four, batch]: [&B; 2],
    mut call: impl FnMut(&B) + Send,
) {
    let one = pool(1);
    let id = BenchmarkId::new(format!("{family}/batch_1_threads_four_lanes"), n);
    group.bench_with_input(id, &n, |b, _| in_pool(b, &one, || call(four)));
    thread_rows(group, (family, n), || call(batch));
}

/// The rows `{family}/batch_1_threads/n` and `…/batch_2_threads/n`: `call` timed from
/// inside a pool of one thread and of two.
fn thread_rows(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    (family, n): (&str, usize),
    mut call: impl FnMut() + Send,
) {
    for threads in [1, 2] {
        let pool = pool(threads);
        group.bench_with_input(
            BenchmarkId::new(format!("{family}/batch_{threads}_threads"), n),
            &n,
            |b, _| in_pool(b, &pool, &mut call),
        );
    }
}

criterion_group!(benches, accelerations, large_batches, rk4, planar_rk4, generated, jacobians);
criterion_main!(benches);
