//! What a pivot drive costs a step: one `velocity_and_acceleration` (what RK4 and the
//! batches read at every stage) of the built-in drives, against the sampled path's
//! (`Sampled`, the cubic spline through 100 to a million samples 1 ms apart, each time
//! found by bisection), at 1024 times spread over the samples, and in order as a run reads
//! them (`sampled_in_order`: the piece read last, or the next, found at once).
//!
//! ```sh
//! cargo bench -p pendulum-core --bench drives
//! ```
//! Figures in `docs/python.md` ("A motion of one's own").

use std::hint::black_box;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use nalgebra::{U3, Vector3};
use pendulum_core::{Circle, Drive, Harmonic, RampedCircle, Sampled};

/// 1024 times over `[0, end)` s, scattered (a multiplicative sequence), so that the
/// bisection does not find each where the last one ended.
fn times(end: f64) -> Vec<f64> {
    (0..1024u64).map(|k| end * ((k * 677) % 1024) as f64 / 1024.0).collect()
}

/// `velocity_and_acceleration` of `drive` at each of `ts`, summed (so none is skipped).
fn read<D: Drive<U3>>(drive: &D, ts: &[f64]) -> Vector3<f64> {
    ts.iter()
        .map(|&t| {
            let (v, a) = drive.velocity_and_acceleration(black_box(t));
            v + a
        })
        .sum()
}

fn drives(c: &mut Criterion) {
    let mut group = c.benchmark_group("drive_velocity_and_acceleration");
    group.warm_up_time(Duration::from_millis(300)).measurement_time(Duration::from_secs(1)).sample_size(20);
    group.throughput(Throughput::Elements(1024));
    let ts = times(10.0);
    let circle = Circle::new(0.02, 7.0).unwrap();
    group.bench_function("circle", |b| b.iter(|| read(&circle, &ts)));
    let ramped = RampedCircle::new(0.02, 0.0, 7.0, 5.0).unwrap();
    group.bench_function("ramped_circle", |b| b.iter(|| read(&ramped, &ts)));
    let harmonic = Harmonic::<U3>::new(Vector3::new(1.0, 0.0, 1.0), 0.02, 30.0, 0.0).unwrap();
    group.bench_function("harmonic", |b| b.iter(|| read(&harmonic, &ts)));
    for samples in [100usize, 10_000, 1_000_000] {
        let sample_times: Vec<f64> = (0..samples).map(|k| k as f64 * 1e-3).collect();
        let positions = sample_times.iter().map(|&t| circle.position(t)).collect();
        let path = Sampled::new(sample_times, positions).unwrap();
        let ts = times(samples as f64 * 1e-3);
        group.bench_with_input(BenchmarkId::new("sampled", samples), &ts, |b, ts| b.iter(|| read(&path, ts)));
        // As a run reads it: in order, a sixth of a millisecond apart (RK4's stages of
        // steps of a third of the samples' spacing), within the samples.
        let in_order: Vec<f64> = (0..1024).map(|k| 0.01 + k as f64 * 1e-3 / 6.0).collect();
        group.bench_with_input(BenchmarkId::new("sampled_in_order", samples), &in_order, |b, ts| {
            b.iter(|| read(&path, ts))
        });
    }
    group.finish();
}

criterion_group!(benches, drives);
criterion_main!(benches);
