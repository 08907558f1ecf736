//! One force evaluation of long chains: the O(n) tension routes against the dense route
//! (mass matrix + Cholesky, O(n³)) and against the floor of n `sin_cos` calls; and one
//! integrator step of the whirl and of a free chain of 1000 links (group `step`); one
//! simulated second of the live viewer's chain, steered by hand (group `live`).
//!
//! ```sh
//! cargo bench -p pendulum-core --bench large_chains
//! ```
//! Figures and their reading in `docs/large-chains.md`.

use std::hint::black_box;
use std::time::Duration;

use criterion::{
    BatchSize, BenchmarkGroup, BenchmarkId, Criterion, criterion_group, criterion_main, measurement::WallTime,
};
use nalgebra::{DVector, U2, U3, Vector3};
use pendulum_core::integrate::{Integrator, Projected, Rk4, State, System};
use pendulum_core::{
    Accounted, Chain, Circle, Directions, Model, Planar, PlanarTension, RodMidpoint, Spatial, Steered,
};

const SIZES: [usize; 10] = [8, 16, 32, 64, 100, 128, 256, 1000, 1024, 4096];
/// The dense route costs O(n³): measured up to here.
const DENSE_UP_TO: usize = 128;

/// `n` equal links making a 1 m, 1 kg chain, lightly damped.
fn chain(n: usize) -> Chain {
    let link = 1.0 / n as f64;
    Chain::uniform(n, link, link, 9.81).and_then(|c| c.with_damping(&vec![1e-6; n])).expect("valid chain")
}

/// A smooth, non-singular state: angles in (0.3, 2.8), rates in (−3, 3).
fn angles(n: usize) -> (DVector<f64>, DVector<f64>) {
    let q = DVector::from_fn(n, |i, _| 0.3 + (i as f64 * 0.77) % 2.5);
    let qd = DVector::from_fn(n, |i, _| (i as f64 * 1.3).sin() * 3.0);
    (q, qd)
}

fn planar_model<M: Model<Links = nalgebra::Dyn, Dof = nalgebra::Dyn, Space = U2>>(
    group: &mut BenchmarkGroup<'_, WallTime>,
    name: &str,
    n: usize,
    model: &M,
) {
    let (q, qd) = angles(n);
    let inputs = model.zero_inputs();
    let mut out = DVector::zeros(n);
    group.bench_with_input(BenchmarkId::new(name, n), &n, |b, _| {
        b.iter(|| model.accelerations(black_box(&q), black_box(&qd), black_box(&inputs), &mut out).unwrap())
    });
}

fn planar(c: &mut Criterion) {
    let mut group = c.benchmark_group("planar");
    group.warm_up_time(Duration::from_millis(300)).measurement_time(Duration::from_secs(1)).sample_size(30);
    for n in SIZES {
        planar_model(&mut group, "tension", n, &PlanarTension::new(chain(n)));
        if n <= DENSE_UP_TO {
            planar_model(&mut group, "dense", n, &Planar::new(chain(n)));
        }
        let system = Directions::<U2>::new(chain(n));
        let (q, qd) = angles(n);
        let x = system.from_angles(q.as_slice(), qd.as_slice()).unwrap();
        let mut f = DVector::zeros(x.len());
        group.bench_with_input(BenchmarkId::new("directions", n), &n, |b, _| {
            b.iter(|| system.rhs(0.0, black_box(&x), &mut f).unwrap())
        });
        // The floor: n sin_cos calls writing 2n outputs.
        let mut sc = vec![0.0; 2 * n];
        group.bench_with_input(BenchmarkId::new("sin_cos", n), &n, |b, _| {
            b.iter(|| {
                for (i, &angle) in black_box(&q).iter().enumerate() {
                    let (s, co) = angle.sin_cos();
                    sc[2 * i] = s;
                    sc[2 * i + 1] = co;
                }
                black_box(&sc);
            })
        });
        // The same with each pair stored together: LLVM then merges the two into one libm
        // `sincos` call (above it calls `sin` and `cos` apart), the floor a model pays.
        group.bench_with_input(BenchmarkId::new("sincos", n), &n, |b, _| {
            b.iter(|| {
                for (pair, &angle) in sc.chunks_exact_mut(2).zip(black_box(&q).iter()) {
                    let (s, co) = angle.sin_cos();
                    pair[0] = s;
                    pair[1] = co;
                }
                black_box(&sc);
            })
        });
    }
    group.finish();
}

fn spatial(c: &mut Criterion) {
    let mut group = c.benchmark_group("spatial");
    group.warm_up_time(Duration::from_millis(300)).measurement_time(Duration::from_secs(1)).sample_size(30);
    for n in SIZES {
        let system = Directions::<U3>::new(chain(n));
        let (theta, _) = angles(n);
        let q: Vec<f64> = (0..2 * n).map(|i| if i < n { theta[i] } else { 0.5 * i as f64 }).collect();
        let qd: Vec<f64> = (0..2 * n).map(|i| (i as f64 * 0.9).cos()).collect();
        let x = system.from_spherical(&q, &qd).unwrap();
        let mut f = DVector::zeros(x.len());
        group.bench_with_input(BenchmarkId::new("directions", n), &n, |b, _| {
            b.iter(|| system.rhs(0.0, black_box(&x), &mut f).unwrap())
        });
        if n <= DENSE_UP_TO {
            let model = Spatial::new(chain(n));
            let (q, qd) = (DVector::from_vec(q), DVector::from_vec(qd));
            let inputs = model.zero_inputs();
            let mut out = DVector::zeros(2 * n);
            group.bench_with_input(BenchmarkId::new("dense", n), &n, |b, _| {
                b.iter(|| {
                    model.accelerations(black_box(&q), black_box(&qd), black_box(&inputs), &mut out).unwrap()
                })
            });
        }
    }
    group.finish();
}

/// One step of the whirl of `docs/large-chains.md` §7 (3D, n = 100, 1 m, 1 kg, λ = 3e-4,
/// pivot on a 2 cm circle at 6 rad/s, ledger carried), from its state after 20 s: the
/// implicit midpoint step at the default h = T/20 and RK4 with projection at 1 ms; and a
/// free 3D chain of 1000 links swinging from a 0.2 rad tilt (after 1 s), midpoint at
/// 0.01 s and RK4 at 4e-4 s (just inside its stability limit 4.5e-4 s).
fn step(c: &mut Criterion) {
    let mut group = c.benchmark_group("step");
    group.warm_up_time(Duration::from_millis(300)).measurement_time(Duration::from_secs(2)).sample_size(30);
    let whirl =
        Chain::uniform(100, 0.01, 0.01, 9.81).and_then(|c| c.with_damping(&[3e-4; 100])).expect("chain");
    let system =
        Accounted::of(Directions::<U3>::new(whirl).with_drive(Circle::new(0.02, 6.0).expect("drive")));
    let h = std::f64::consts::TAU / 6.0 / 20.0;
    let mut state = State::new(0.0, system.state(&system.chain().hanging()).expect("state"));
    RodMidpoint::new().integrate(&system, &mut state, 20.0, (20.0 / h).round() as usize).expect("spin-up");
    let mut midpoint = RodMidpoint::new();
    group.bench_function("whirl_100/midpoint_T_over_20", |b| {
        b.iter_batched_ref(|| state.clone(), |s| midpoint.step(&system, s, h).unwrap(), BatchSize::SmallInput)
    });
    let mut rk4 = Projected::new(Rk4::new(&system));
    group.bench_function("whirl_100/rk4_1ms", |b| {
        b.iter_batched_ref(|| state.clone(), |s| rk4.step(&system, s, 1e-3).unwrap(), BatchSize::SmallInput)
    });
    let n = 1000;
    let free = Directions::<U3>::new(Chain::uniform(n, 1e-3, 1e-3, 9.81).expect("chain"));
    let q: Vec<f64> = (0..2 * n)
        .map(|i| if i < n { 0.2 } else { std::f64::consts::PI * (i - n) as f64 / n as f64 })
        .collect();
    let mut state = State::new(0.0, free.from_spherical(&q, &vec![0.0; 2 * n]).expect("state"));
    RodMidpoint::new().integrate(&free, &mut state, 1.0, 100).expect("swing");
    let mut midpoint = RodMidpoint::new();
    group.bench_function("free_1000/midpoint_10ms", |b| {
        b.iter_batched_ref(
            || state.clone(),
            |s| midpoint.step(&free, s, 0.01).unwrap(),
            BatchSize::SmallInput,
        )
    });
    let mut rk4 = Projected::new(Rk4::new(&free));
    group.bench_function("free_1000/rk4_0.4ms", |b| {
        b.iter_batched_ref(|| state.clone(), |s| rk4.step(&free, s, 4e-4).unwrap(), BatchSize::SmallInput)
    });
    group.finish();
}

/// One simulated second of `pendulum view --live` at its defaults: the whirl's chain, the
/// pivot [`Steered`] (hand rate 20/s, circle rate 2/s) toward a 2 cm circle at 6 rad/s
/// about a hand that swings ±0.2 m along x at 1.5 Hz (a new target every 4 steps, as a
/// 60 Hz pointer gives), midpoint steps of 1/240 s, from the state 5 s in. Real time
/// needs this under 1 s.
fn live(c: &mut Criterion) {
    const STEP: f64 = 1.0 / 240.0;
    fn second(
        system: &mut Directions<U3, Steered>,
        state: &mut State<nalgebra::Dyn>,
        midpoint: &mut RodMidpoint,
    ) {
        for k in 0..240 {
            if k % 4 == 0 {
                let t = state.t();
                let hand = 0.2 * (std::f64::consts::TAU * 1.5 * t).sin();
                system.drive_mut().steer(t, Vector3::new(hand, 0.0, 0.0)).unwrap();
            }
            midpoint.step(system, state, STEP).unwrap();
        }
    }
    let mut group = c.benchmark_group("live");
    group.warm_up_time(Duration::from_millis(300)).measurement_time(Duration::from_secs(5)).sample_size(20);
    let whirl =
        Chain::uniform(100, 0.01, 0.01, 9.81).and_then(|c| c.with_damping(&[3e-4; 100])).expect("chain");
    let mut drive = Steered::new(20.0, 2.0).expect("drive");
    drive.set_radius(0.0, 0.02).and_then(|_| drive.set_speed(0.0, 6.0)).expect("circle");
    let mut system = Directions::<U3>::new(whirl).with_drive(drive);
    let mut state = State::new(0.0, system.hanging());
    let mut midpoint = RodMidpoint::new();
    for _ in 0..5 {
        second(&mut system, &mut state, &mut midpoint);
    }
    group.bench_function("whirl_100/one_second_steered", |b| {
        b.iter_batched_ref(
            || (system.clone(), state.clone()),
            |(system, state)| second(system, state, &mut midpoint),
            BatchSize::SmallInput,
        )
    });
    group.finish();
}

criterion_group!(benches, planar, spatial, step, live);
criterion_main!(benches);
