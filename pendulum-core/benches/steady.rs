//! Steady shapes at the chain sizes the question is about (a 1 m, 1 kg chain of equal
//! links): the verdict on one shape by the structured route (`stability`) against the dense
//! one (`stability_dense`, group `verdict`); every branch of a fixed pivot with every
//! point judged, as `pendulum steady` computes them on one core (group `branches`); the
//! nearest damped steady shape and its verdict, as every whirl gets it (group `nearest`).
//!
//! ```sh
//! cargo bench -p pendulum-core --bench steady
//! ```
//! Figures and their reading in `docs/rotating-chain.md`.

use std::hint::black_box;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use nalgebra::{DVector, Dyn, U3, Vector3};
use pendulum_core::{
    Chain, Circle, ContinuationOptions, Directions, ShapeOptions, SteadyRotation, WhirlShape, nearest_steady,
    relative_equilibrium, relative_spectrum, relative_spectrum_near_origin, stability, stability_dense,
    whirl_shape,
};

fn chain(n: usize) -> Chain<Dyn> {
    let link = 1.0 / n as f64;
    Chain::<Dyn>::uniform(n, link, link, 9.81).expect("valid chain")
}

/// The two-node shape at `omega` (rad/s) on a fixed pivot.
fn two_nodes(problem: &SteadyRotation, omega: f64) -> pendulum_core::SteadyShape {
    let branch = problem.branch(2, omega, &ContinuationOptions::default()).expect("branch");
    let last = branch.points.last().expect("points");
    problem.solve(omega, &last.theta).expect("shape")
}

fn verdict(c: &mut Criterion) {
    let mut group = c.benchmark_group("verdict");
    group.warm_up_time(Duration::from_millis(300)).measurement_time(Duration::from_secs(2)).sample_size(10);
    for n in [20, 50, 100, 200, 1000] {
        let problem = SteadyRotation::new(&chain(n), 0.0).unwrap();
        let shape = two_nodes(&problem, 14.0);
        group.bench_with_input(BenchmarkId::new("structured", n), &n, |b, _| {
            b.iter(|| stability(black_box(&problem), black_box(&shape), None).unwrap())
        });
        if n <= 100 {
            group.bench_with_input(BenchmarkId::new("dense", n), &n, |b, _| {
                b.iter(|| stability_dense(black_box(&problem), black_box(&shape), None).unwrap())
            });
        }
    }
    group.finish();
}

/// The three lowest branches up to `omega_max`, every point judged: `pendulum steady`'s
/// computation for a fixed pivot, on one core.
fn all_branches(problem: &SteadyRotation, omega_max: f64) -> usize {
    let options = ContinuationOptions::default();
    let mut unstable = 0;
    for k in 1..=3 {
        let branch = problem.branch(k, omega_max, &options).unwrap();
        for shape in &branch.points {
            unstable += usize::from(!stability(problem, shape, None).unwrap().spectrally_stable);
        }
    }
    unstable
}

fn branches(c: &mut Criterion) {
    let mut group = c.benchmark_group("branches");
    group.warm_up_time(Duration::from_millis(100)).measurement_time(Duration::from_secs(5)).sample_size(10);
    for n in [100, 1000] {
        let problem = SteadyRotation::new(&chain(n), 0.0).unwrap();
        group.bench_with_input(
            BenchmarkId::new("fixed pivot, three branches to 16.9 rad/s", n),
            &n,
            |b, _| b.iter(|| all_branches(black_box(&problem), 16.9)),
        );
    }
    group.finish();
}

/// A whirl's shape `offset` (m) out of the plane of the one-node steady shape of a damped
/// chain on a circle of 2 cm at 6 rad/s (a settled whirl is within 1e-4 m of its damped
/// steady shape, docs/rotating-chain.md §4), and the model it runs in.
fn whirl(n: usize, offset: f64) -> (Directions<U3, Circle>, WhirlShape) {
    let (radius, omega) = (0.02, 6.0);
    let damped = chain(n).with_damping(&vec![3e-4 / n as f64; n]).unwrap();
    let model = Directions::<U3>::new(damped).with_drive(Circle::new(radius, omega).unwrap());
    let problem = SteadyRotation::new(&chain(n), radius).unwrap();
    let shape = problem.solve(omega, &DVector::from_element(n, 0.8)).unwrap();
    let guess: Vec<(f64, f64)> = shape.theta.iter().map(|&t| (t, 0.0)).collect();
    let eq = relative_equilibrium(&model, &guess).unwrap();
    let positions = whirl_shape(&model, 0.0, &eq.state)
        .unwrap()
        .positions
        .iter()
        .enumerate()
        .map(|(i, r)| r + Vector3::new(0.0, offset * (i + 1) as f64 / n as f64, 0.0))
        .collect();
    (model, WhirlShape::from_positions(positions).unwrap())
}

fn nearest(c: &mut Criterion) {
    let mut group = c.benchmark_group("nearest");
    group.warm_up_time(Duration::from_millis(300)).measurement_time(Duration::from_secs(3)).sample_size(10);
    for n in [20, 100] {
        let options = ShapeOptions::default();
        for (offset, what) in [(1e-4, "settled, 0.1 mm off"), (1e-2, "1 cm off")] {
            let (model, shape) = whirl(n, offset);
            group.bench_with_input(
                BenchmarkId::new(format!("damped, circling pivot, {what}"), n),
                &n,
                |b, _| {
                    b.iter(|| nearest_steady(black_box(&model), 0.0, black_box(&shape), &options).unwrap())
                },
            );
        }
        let (model, shape) = whirl(n, 1e-4);
        let found = nearest_steady(&model, 0.0, &shape, &options).unwrap();
        group.bench_with_input(
            BenchmarkId::new("its verdict: eigenvalues near the origin", n),
            &n,
            |b, _| {
                b.iter(|| {
                    relative_spectrum_near_origin(black_box(&model), black_box(&found.equilibrium)).unwrap()
                })
            },
        );
        group.bench_with_input(BenchmarkId::new("its verdict: dense spectrum", n), &n, |b, _| {
            b.iter(|| relative_spectrum(black_box(&model), black_box(&found.equilibrium)).unwrap())
        });
    }
    group.finish();
}

criterion_group!(benches, verdict, branches, nearest);
criterion_main!(benches);
