//! Unrolled (generated) vs generic models: the cost of one evaluation of the equations of
//! motion, `Model::accelerations` (mass matrix, forces, Cholesky solve), per model and n.
//!
//! Run through `cargo xtask bench`, which prints the ratios; or directly with
//! `cargo bench -p xtask --bench models`.

use std::hint::black_box;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use nalgebra::{Const, DefaultAllocator, Dim, Dyn, OVector, U1};
use pendulum_core::{Model, ModelAlloc, Planar, Spatial};
use xtask::case::Params;
use xtask::models::{Planar1, Planar2, Planar3, Planar4, Planar8, Spatial1, Spatial2, Spatial4, chain};

/// A fixed, non-singular state: angles spread over (0.3, 2.8) so that no sin θ vanishes.
fn state<M: Model>(model: &M) -> (OVector<f64, M::Dof>, OVector<f64, M::Dof>)
where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>,
{
    let dof = model.dof();
    let q = OVector::from_iterator_generic(dof, U1, (0..dof.value()).map(|i| 0.3 + (i as f64 * 0.77) % 2.5));
    let qd =
        OVector::from_iterator_generic(dof, U1, (0..dof.value()).map(|i| ((i as f64) * 1.3).sin() * 3.0));
    (q, qd)
}

fn bench_one<M: Model>(
    c: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    name: &str,
    n: usize,
    model: &M,
) where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>,
{
    let (q, qd) = state(model);
    let inputs = model.zero_inputs();
    let mut out = qd.clone();
    c.bench_with_input(BenchmarkId::new(name, n), &n, |b, _| {
        b.iter(|| {
            model.accelerations(black_box(&q), black_box(&qd), black_box(&inputs), &mut out).unwrap();
            black_box(&out);
        })
    });
}

/// The benchmarked chain's parameters: `n` links of slowly growing masses and lengths.
fn params(n: usize) -> Params {
    Params {
        masses: (0..n).map(|i| 1.0 + 0.1 * i as f64).collect(),
        lengths: (0..n).map(|i| 0.5 + 0.05 * i as f64).collect(),
        gravity: 9.81,
        damping: vec![0.01; n],
    }
}

/// The generated model of `n` links and the generic one (`Planar` or `Spatial`) with
/// `L = Const<n>` and `L = Dyn`.
macro_rules! bench_models {
    ($group:expr, $n:literal, $generated:ident, $generic:ident) => {
        let params = params($n);
        bench_one(
            $group,
            "generated",
            $n,
            &$generated::new(chain::<Const<$n>>(&params).expect("valid chain")),
        );
        bench_one(
            $group,
            "generic_fixed",
            $n,
            &$generic::new(chain::<Const<$n>>(&params).expect("valid chain")),
        );
        bench_one($group, "generic_dyn", $n, &$generic::new(chain::<Dyn>(&params).expect("valid chain")));
    };
}

fn accelerations(c: &mut Criterion) {
    let mut group = c.benchmark_group("planar_accelerations");
    bench_models!(&mut group, 1, Planar1, Planar);
    bench_models!(&mut group, 2, Planar2, Planar);
    bench_models!(&mut group, 3, Planar3, Planar);
    bench_models!(&mut group, 4, Planar4, Planar);
    bench_models!(&mut group, 8, Planar8, Planar);
    group.finish();

    let mut group = c.benchmark_group("spatial_accelerations");
    bench_models!(&mut group, 1, Spatial1, Spatial);
    bench_models!(&mut group, 2, Spatial2, Spatial);
    bench_models!(&mut group, 4, Spatial4, Spatial);
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().warm_up_time(Duration::from_millis(500)).measurement_time(Duration::from_secs(2));
    targets = accelerations
}
criterion_main!(benches);
