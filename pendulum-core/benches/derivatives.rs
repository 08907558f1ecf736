//! The analytic derivatives against what they replace.
//!
//! - `derivatives/accelerations/<n>`, `derivatives/state_jacobians/<n>` and
//!   `derivatives/jacobians/<n>`: a generated planar model's `accelerations`, its
//!   `state_jacobians` (`q̈` with `∂q̈/∂q`, `∂q̈/∂q̇`) and its `acceleration_jacobians`
//!   (also `∂q̈/∂σ`, `∂q̈/∂p̈`), n = 2, 4, 8 (dense route at 2, tension route at 4 and 8);
//!   `derivatives/jacobians_generic/<n>` the four for `Planar<Dyn>`.
//! - `linear/<what>/100`: the O(n) routes at n = 100: `PlanarTension` accelerations, a
//!   JVP (the kept solve and one tangent), one more tangent of a kept solve, the state
//!   Jacobians `∂θ̈/∂θ`, `∂θ̈/∂θ̇` and all four; `Directions` (3D) rhs, JVP and the
//!   first-order system's Jacobian.
//! - `newton/<chain>/<jacobian>`: 200 steps (h = 10 ms) of the two-stage Gauss–Legendre
//!   method from the same state, for the chaotic double pendulum (both links horizontal,
//!   released) and a planar chain of 8 links, with the Jacobian by central differences
//!   (`differences`, the default) or analytic (`analytic`; `analytic_fresh`: a fresh one
//!   every step). Before measuring, each prints its Newton iterations and Jacobian
//!   evaluations per step over the same 200 steps.
//!
//! `cargo bench -p pendulum-core --bench derivatives`.

use std::hint::black_box;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use nalgebra::U3;
use nalgebra::{DVector, Dyn, SVector};
use pendulum_core::integrate::{GaussLegendre, GaussOptions, Integrator, State, System};
use pendulum_core::{Chain, Derivatives, Directions, FirstOrder, Jacobians, Model, Planar, PlanarTension};

pendulum_macros::model! {
    /// Generated planar model, 2 links.
    pub struct Planar2 { kind: planar, links: 2 }
    /// Generated planar model, 4 links.
    pub struct Planar4 { kind: planar, links: 4 }
    /// Generated planar model, 8 links.
    pub struct Planar8 { kind: planar, links: 8 }
}

/// The benchmarked chain: masses `1 + 0.1 i` kg, lengths `0.5 + 0.05 i` m, damping 0.01.
fn chain<L: nalgebra::Dim>(n: usize) -> Chain<L>
where
    nalgebra::DefaultAllocator: nalgebra::allocator::Allocator<L>,
{
    let masses: Vec<f64> = (0..n).map(|i| 1.0 + 0.1 * i as f64).collect();
    let lengths: Vec<f64> = (0..n).map(|i| 0.5 + 0.05 * i as f64).collect();
    Chain::<L>::new(&masses, &lengths, 9.81)
        .and_then(|c| c.with_damping(&vec![0.01; n]))
        .expect("valid chain")
}

fn state<const N: usize>() -> (SVector<f64, N>, SVector<f64, N>) {
    (
        SVector::from_fn(|i, _| 0.3 + (i as f64 * 0.77) % 2.5),
        SVector::from_fn(|i, _| ((i as f64) * 1.3).sin() * 3.0),
    )
}

fn bench_size<M, const N: usize>(c: &mut Criterion, model: M)
where
    M: Derivatives + Model<Links = nalgebra::Const<N>, Dof = nalgebra::Const<N>, Space = nalgebra::U2>,
{
    let (q, qd) = state::<N>();
    let inputs = model.zero_inputs();
    let mut group = c.benchmark_group("derivatives");
    let mut qdd = SVector::<f64, N>::zeros();
    group.bench_function(BenchmarkId::new("accelerations", N), |b| {
        b.iter(|| model.accelerations(black_box(&q), black_box(&qd), &inputs, &mut qdd).unwrap())
    });
    let mut jac = Jacobians::zeros(&model);
    group.bench_function(BenchmarkId::new("state_jacobians", N), |b| {
        b.iter(|| model.state_jacobians(black_box(&q), black_box(&qd), &inputs, &mut jac).unwrap())
    });
    group.bench_function(BenchmarkId::new("jacobians", N), |b| {
        b.iter(|| model.acceleration_jacobians(black_box(&q), black_box(&qd), &inputs, &mut jac).unwrap())
    });
    let generic = Planar::new(chain::<Dyn>(N));
    let (q, qd) = (DVector::from_column_slice(q.as_slice()), DVector::from_column_slice(qd.as_slice()));
    let inputs = generic.zero_inputs();
    let mut jac = Jacobians::zeros(&generic);
    group.bench_function(BenchmarkId::new("jacobians_generic", N), |b| {
        b.iter(|| generic.acceleration_jacobians(black_box(&q), black_box(&qd), &inputs, &mut jac).unwrap())
    });
}

/// 200 steps of h = 10 ms from `x0`.
fn run<S: System>(
    system: &S,
    x0: &nalgebra::OVector<f64, S::Dim>,
    options: GaussOptions,
) -> GaussLegendre<S::Dim, nalgebra::U2>
where
    S::Dim: nalgebra::DimMul<nalgebra::U2>,
    nalgebra::DefaultAllocator: pendulum_core::integrate::GaussAlloc<S::Dim, nalgebra::U2>,
{
    let mut solver = GaussLegendre::<_, nalgebra::U2>::new(system, options);
    let mut state = State::new(0.0, x0.clone());
    for _ in 0..200 {
        solver.step(system, &mut state, 1e-2).unwrap();
    }
    solver
}

fn bench_newton<M, const N: usize>(c: &mut Criterion, name: &str, model: M, q: SVector<f64, N>)
where
    M: Derivatives
        + Model<Links = nalgebra::Const<N>, Dof = nalgebra::Const<N>, Space = nalgebra::U2>
        + Clone,
    nalgebra::Const<N>: nalgebra::DimMul<nalgebra::U2>,
    nalgebra::DimProd<nalgebra::Const<N>, nalgebra::U2>: nalgebra::DimMul<nalgebra::U2>,
    nalgebra::DefaultAllocator: pendulum_core::integrate::GaussAlloc<
            nalgebra::DimProd<nalgebra::Const<N>, nalgebra::U2>,
            nalgebra::U2,
        >,
{
    let differences = FirstOrder::new(model.clone());
    let analytic = FirstOrder::new(model).analytic();
    let x0 = differences.state(&q, &SVector::zeros());
    let fresh = GaussOptions { jacobian_refresh_rate: 0.0, ..GaussOptions::default() };
    let mut group = c.benchmark_group(format!("newton/{name}"));
    let report = |label: &str, stats: &pendulum_core::integrate::Stats| {
        println!(
            "newton/{name}/{label}: {:.2} Newton iterations/step, {:.3} Jacobians/step over {} steps",
            stats.newton_iterations as f64 / stats.steps as f64,
            stats.jacobian_evaluations as f64 / stats.steps as f64,
            stats.steps
        );
    };
    report("differences", run(&differences, &x0, GaussOptions::default()).stats());
    report("analytic", run(&analytic, &x0, GaussOptions::default()).stats());
    report("analytic_fresh", run(&analytic, &x0, fresh).stats());
    group.bench_function("differences", |b| {
        b.iter(|| black_box(run(&differences, &x0, GaussOptions::default())))
    });
    group.bench_function("analytic", |b| b.iter(|| black_box(run(&analytic, &x0, GaussOptions::default()))));
    group.bench_function("analytic_fresh", |b| b.iter(|| black_box(run(&analytic, &x0, fresh))));
}

/// The O(n) routes at n links: `PlanarTension` accelerations, one JVP (the linearised
/// solve and one tangent), one more tangent of a kept solve, and the full Jacobians;
/// `Directions` (3D) rhs, JVP and the first-order system's full Jacobian.
fn bench_linear(c: &mut Criterion, n: usize) {
    let model = PlanarTension::new(chain::<Dyn>(n));
    let q = DVector::from_fn(n, |i, _| 0.3 + (i as f64 * 0.77) % 2.5);
    let qd = DVector::from_fn(n, |i, _| ((i as f64) * 1.3).sin() * 3.0);
    let inputs = model.zero_inputs();
    let dq = DVector::from_fn(n, |i, _| ((i as f64) * 0.9).cos());
    let zero = vec![0.0; n];
    let mut out = vec![0.0; n];
    let mut group = c.benchmark_group("linear");
    let mut qdd = DVector::zeros(n);
    group.bench_function(BenchmarkId::new("tension_accelerations", n), |b| {
        b.iter(|| model.accelerations(black_box(&q), black_box(&qd), &inputs, &mut qdd).unwrap())
    });
    group.bench_function(BenchmarkId::new("tension_jvp", n), |b| {
        b.iter(|| {
            let mut t = model.tangents(black_box(&q), black_box(&qd), &inputs).unwrap();
            t.jvp(dq.as_slice(), &zero, &zero, [0.0; 2], &mut out);
            black_box(&out);
        })
    });
    let mut kept = model.tangents(&q, &qd, &inputs).unwrap();
    group.bench_function(BenchmarkId::new("tension_tangent_of_kept_solve", n), |b| {
        b.iter(|| {
            kept.jvp(black_box(dq.as_slice()), &zero, &zero, [0.0; 2], &mut out);
            black_box(&out);
        })
    });
    let (mut dqm, mut dqdm) = (vec![0.0; n * n], vec![0.0; n * n]);
    group.bench_function(BenchmarkId::new("tension_state_jacobians", n), |b| {
        b.iter(|| {
            let t = model.tangents(black_box(&q), black_box(&qd), &inputs).unwrap();
            t.state_jacobians(&mut dqm, &mut dqdm);
            black_box(&dqm);
        })
    });
    let mut jac = Jacobians::zeros(&model);
    group.bench_function(BenchmarkId::new("tension_jacobians", n), |b| {
        b.iter(|| model.acceleration_jacobians(black_box(&q), black_box(&qd), &inputs, &mut jac).unwrap())
    });
    let directions = Directions::<U3>::new(chain::<Dyn>(n));
    let qs = DVector::from_fn(2 * n, |i, _| 0.3 + (i as f64 * 0.77) % 2.5);
    let qsd = DVector::from_fn(2 * n, |i, _| ((i as f64) * 1.3).sin() * 3.0);
    let x = directions.from_spherical(qs.as_slice(), qsd.as_slice()).unwrap();
    let dx = DVector::from_fn(x.len(), |i, _| ((i as f64) * 0.9).cos());
    let mut f = DVector::zeros(x.len());
    group.bench_function(BenchmarkId::new("directions_rhs", n), |b| {
        b.iter(|| directions.rhs(0.0, black_box(&x), &mut f).unwrap())
    });
    let mut udd = vec![0.0; 3 * n];
    group.bench_function(BenchmarkId::new("directions_jvp", n), |b| {
        b.iter(|| directions.jvp(0.0, black_box(&x), &dx, &mut udd).unwrap())
    });
    let mut full = nalgebra::DMatrix::zeros(x.len(), x.len());
    group.bench_function(BenchmarkId::new("directions_jacobian", n), |b| {
        b.iter(|| directions.analytic_jacobian(0.0, black_box(&x), &mut full).unwrap())
    });
}

fn benches(c: &mut Criterion) {
    bench_linear(c, 100);
    bench_size::<_, 2>(c, Planar2::new(chain(2)));
    bench_size::<_, 4>(c, Planar4::new(chain(4)));
    bench_size::<_, 8>(c, Planar8::new(chain(8)));
    let half_pi = std::f64::consts::FRAC_PI_2;
    bench_newton(c, "double", Planar2::new(chain(2)), SVector::from([half_pi, half_pi]));
    bench_newton(c, "n8", Planar8::new(chain(8)), SVector::from_fn(|i, _| 0.4 + 0.1 * i as f64));
}

criterion_group! {
    name = derivative_benches;
    config = Criterion::default().warm_up_time(Duration::from_millis(500)).measurement_time(Duration::from_secs(2)).sample_size(30);
    targets = benches
}
criterion_main!(derivative_benches);
