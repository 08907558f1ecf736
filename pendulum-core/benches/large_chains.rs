//! One force evaluation of long chains: the O(n) tension routes against the dense route
//! (mass matrix + Cholesky, O(n³)) and against the floor of n `sin_cos` calls.
//!
//! ```sh
//! cargo bench -p pendulum-core --bench large_chains
//! ```
//! Figures and their reading in `docs/large-chains.md`.

use std::hint::black_box;
use std::time::Duration;

use criterion::{
    BenchmarkGroup, BenchmarkId, Criterion, criterion_group, criterion_main, measurement::WallTime,
};
use nalgebra::{DVector, U2, U3};
use pendulum_core::integrate::System;
use pendulum_core::{Chain, Directions, Model, Planar, PlanarTension, Spatial};

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

criterion_group!(benches, planar, spatial);
criterion_main!(benches);
