//! Unrolled (generated) vs generic models: the cost of one evaluation of the equations of
//! motion, `Model::accelerations` (mass matrix, forces, Cholesky solve), per model and n.
//!
//! Run through `cargo xtask bench`, which prints the ratios; or directly with
//! `cargo bench -p xtask --bench models`.

use std::hint::black_box;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use nalgebra::{Const, DefaultAllocator, Dim, Dyn, OVector, U1};
use pendulum_core::{Chain, Model, ModelAlloc, Planar, Spatial};
use xtask::models::{Planar1, Planar2, Planar3, Planar4, Planar8, Spatial1, Spatial2, Spatial4};

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

fn chain<L: nalgebra::Dim>(n: usize) -> Chain<L>
where
    DefaultAllocator: nalgebra::allocator::Allocator<L>,
{
    let masses: Vec<f64> = (0..n).map(|i| 1.0 + 0.1 * i as f64).collect();
    let lengths: Vec<f64> = (0..n).map(|i| 0.5 + 0.05 * i as f64).collect();
    Chain::new(&masses, &lengths, 9.81).and_then(|c| c.with_damping(&vec![0.01; n])).expect("valid chain")
}

macro_rules! planar {
    ($group:expr, $n:literal, $generated:ident) => {
        bench_one($group, "generated", $n, &$generated::new(chain::<Const<$n>>($n)));
        bench_one($group, "generic_fixed", $n, &Planar::new(chain::<Const<$n>>($n)));
        bench_one($group, "generic_dyn", $n, &Planar::new(chain::<Dyn>($n)));
    };
}

macro_rules! spatial {
    ($group:expr, $n:literal, $generated:ident) => {
        bench_one($group, "generated", $n, &$generated::new(chain::<Const<$n>>($n)));
        bench_one($group, "generic_fixed", $n, &Spatial::new(chain::<Const<$n>>($n)));
        bench_one($group, "generic_dyn", $n, &Spatial::new(chain::<Dyn>($n)));
    };
}

fn accelerations(c: &mut Criterion) {
    let mut group = c.benchmark_group("planar_accelerations");
    planar!(&mut group, 1, Planar1);
    planar!(&mut group, 2, Planar2);
    planar!(&mut group, 3, Planar3);
    planar!(&mut group, 4, Planar4);
    planar!(&mut group, 8, Planar8);
    group.finish();

    let mut group = c.benchmark_group("spatial_accelerations");
    spatial!(&mut group, 1, Spatial1);
    spatial!(&mut group, 2, Spatial2);
    spatial!(&mut group, 4, Spatial4);
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().warm_up_time(Duration::from_millis(500)).measurement_time(Duration::from_secs(2));
    targets = accelerations
}
criterion_main!(benches);
