//! Unrolled (generated) vs generic vs closed-form models, and the physical-limit
//! baseline: the cost of the pieces of one evaluation of the equations of motion, per
//! model and number of links n.
//!
//! Groups are `<kind>_<operation>` (kind `planar` or `spatial`), benchmark ids
//! `<implementation>/<n>`:
//! - `mass_matrix`: `Model::mass_matrix` (`M(q)`, written into a preallocated matrix);
//! - `forces`: the right-hand side `Q − c − k − d` from the four building blocks;
//! - `accelerations`: `Model::accelerations` (input checks, `M`, forces, Cholesky solve);
//! - `gl2_step`: one step (h = 1 ms) of the two-stage Gauss–Legendre method through
//!   `FirstOrder`, from the same state each time;
//! - `energy`: `Model::energy` (`T + U`).
//!
//! Implementations: `generated` (`model!`, planar n = 1..8, spatial n = 1..4; planar 12
//! and 16 for the accelerations only), `generic_fixed` (`Planar`/`Spatial<Const<n>>`),
//! `generic_dyn` (`Planar`/`Spatial<Dyn>`, accelerations up to n = 256). The
//! `<kind>_accelerations` groups also hold:
//! - `closed_form`: planar n = 2, the document's eq 50 corrected (`pendulum_core::models::DoublePendulum`);
//!   `planar_input_checks/check_inputs/2` times the input validation it lacks;
//! - `tension`: the O(n) `PlanarTension<Dyn>` (also its `gl2_step` for n ≤ 8);
//! - `directions`: `System::rhs` of the O(n) `Directions` chain (2D and 3D);
//! - `baseline`: `dof` calls of `sin_cos` and `2·dof` stores, the least any evaluation in
//!   angle coordinates does (every coordinate's sine and cosine, the first-order
//!   right-hand side `(q̇, q̈)` written out).
//!
//! The O(n) routes and the baseline run at n = 1..8 and 12, 16, 64, 256, 1024, 4096.
//!
//! Run through `cargo xtask bench`, which writes `docs/bench.md` and `docs/bench.svg`;
//! `PENDULUM_BENCH_QUICK=1` selects the few sizes of `cargo xtask bench --quick`.

use std::hint::black_box;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use nalgebra::allocator::Allocator;
use nalgebra::{
    Const, DVector, DefaultAllocator, Dim, DimMul, DimName, DimProd, Dyn, OMatrix, OVector, U1, U2, U3,
};
use pendulum_core::integrate::{GaussAlloc, GaussLegendre, GaussOptions, Integrator, State, System};
use pendulum_core::{
    Chain, Directions, FirstOrder, Inputs, Model, ModelAlloc, Planar, PlanarTension, Spatial,
};

// The closed form is written once, in `pendulum-core/src/models/closed_form.rs`, where its
// unit tests check it against `Planar<Dyn>`.
use pendulum_core::models::DoublePendulum;

pendulum_macros::model! {
    /// Generated planar model, 1 link.
    pub struct Planar1 { kind: planar, links: 1 }
    /// Generated planar model, 2 links.
    pub struct Planar2 { kind: planar, links: 2 }
    /// Generated planar model, 3 links.
    pub struct Planar3 { kind: planar, links: 3 }
    /// Generated planar model, 4 links.
    pub struct Planar4 { kind: planar, links: 4 }
    /// Generated planar model, 5 links.
    pub struct Planar5 { kind: planar, links: 5 }
    /// Generated planar model, 6 links.
    pub struct Planar6 { kind: planar, links: 6 }
    /// Generated planar model, 7 links.
    pub struct Planar7 { kind: planar, links: 7 }
    /// Generated planar model, 8 links.
    pub struct Planar8 { kind: planar, links: 8 }
    /// Generated spatial model, 1 link.
    pub struct Spatial1 { kind: spatial, links: 1 }
    /// Generated spatial model, 2 links.
    pub struct Spatial2 { kind: spatial, links: 2 }
    /// Generated spatial model, 3 links.
    pub struct Spatial3 { kind: spatial, links: 3 }
    /// Generated spatial model, 4 links.
    pub struct Spatial4 { kind: spatial, links: 4 }
    /// Generated planar model, 12 links: accelerations only, to locate the crossover.
    pub struct Planar12 { kind: planar, links: 12 }
    /// Generated planar model, 16 links: accelerations only, to locate the crossover.
    pub struct Planar16 { kind: planar, links: 16 }
    /// Generated planar model, 1 link, by the mass matrix.
    pub struct PlanarDense1 { kind: planar, links: 1, algorithm: dense }
    /// Generated planar model, 1 link, by the rod tensions.
    pub struct PlanarTension1 { kind: planar, links: 1, algorithm: tension }
    /// Generated planar model, 2 links, by the mass matrix.
    pub struct PlanarDense2 { kind: planar, links: 2, algorithm: dense }
    /// Generated planar model, 2 links, by the rod tensions.
    pub struct PlanarTension2 { kind: planar, links: 2, algorithm: tension }
    /// Generated planar model, 3 links, by the mass matrix.
    pub struct PlanarDense3 { kind: planar, links: 3, algorithm: dense }
    /// Generated planar model, 3 links, by the rod tensions.
    pub struct PlanarTension3 { kind: planar, links: 3, algorithm: tension }
    /// Generated planar model, 4 links, by the mass matrix.
    pub struct PlanarDense4 { kind: planar, links: 4, algorithm: dense }
    /// Generated planar model, 4 links, by the rod tensions.
    pub struct PlanarTension4 { kind: planar, links: 4, algorithm: tension }
    /// Generated planar model, 5 links, by the mass matrix.
    pub struct PlanarDense5 { kind: planar, links: 5, algorithm: dense }
    /// Generated planar model, 5 links, by the rod tensions.
    pub struct PlanarTension5 { kind: planar, links: 5, algorithm: tension }
    /// Generated planar model, 6 links, by the mass matrix.
    pub struct PlanarDense6 { kind: planar, links: 6, algorithm: dense }
    /// Generated planar model, 6 links, by the rod tensions.
    pub struct PlanarTension6 { kind: planar, links: 6, algorithm: tension }
    /// Generated planar model, 7 links, by the mass matrix.
    pub struct PlanarDense7 { kind: planar, links: 7, algorithm: dense }
    /// Generated planar model, 7 links, by the rod tensions.
    pub struct PlanarTension7 { kind: planar, links: 7, algorithm: tension }
    /// Generated planar model, 8 links, by the mass matrix.
    pub struct PlanarDense8 { kind: planar, links: 8, algorithm: dense }
    /// Generated planar model, 8 links, by the rod tensions.
    pub struct PlanarTension8 { kind: planar, links: 8, algorithm: tension }
    /// Generated planar model, 9 links, by the mass matrix.
    pub struct PlanarDense9 { kind: planar, links: 9, algorithm: dense }
    /// Generated planar model, 9 links, by the rod tensions.
    pub struct PlanarTension9 { kind: planar, links: 9, algorithm: tension }
    /// Generated planar model, 10 links, by the mass matrix.
    pub struct PlanarDense10 { kind: planar, links: 10, algorithm: dense }
    /// Generated planar model, 10 links, by the rod tensions.
    pub struct PlanarTension10 { kind: planar, links: 10, algorithm: tension }
    /// Generated planar model, 11 links, by the mass matrix.
    pub struct PlanarDense11 { kind: planar, links: 11, algorithm: dense }
    /// Generated planar model, 11 link, by the rod tensions.
    pub struct PlanarTension11 { kind: planar, links: 11, algorithm: tension }
    /// Generated planar model, 12 links, by the mass matrix.
    pub struct PlanarDense12 { kind: planar, links: 12, algorithm: dense }
    /// Generated planar model, 12 links, by the rod tensions.
    pub struct PlanarTension12 { kind: planar, links: 12, algorithm: tension }
    /// Generated planar model, 13 links, by the mass matrix.
    pub struct PlanarDense13 { kind: planar, links: 13, algorithm: dense }
    /// Generated planar model, 13 links, by the rod tensions.
    pub struct PlanarTension13 { kind: planar, links: 13, algorithm: tension }
    /// Generated planar model, 14 links, by the mass matrix.
    pub struct PlanarDense14 { kind: planar, links: 14, algorithm: dense }
    /// Generated planar model, 14 links, by the rod tensions.
    pub struct PlanarTension14 { kind: planar, links: 14, algorithm: tension }
    /// Generated planar model, 15 links, by the mass matrix.
    pub struct PlanarDense15 { kind: planar, links: 15, algorithm: dense }
    /// Generated planar model, 15 links, by the rod tensions.
    pub struct PlanarTension15 { kind: planar, links: 15, algorithm: tension }
    /// Generated planar model, 16 links, by the mass matrix.
    pub struct PlanarDense16 { kind: planar, links: 16, algorithm: dense }
    /// Generated planar model, 16 links, by the rod tensions.
    pub struct PlanarTension16 { kind: planar, links: 16, algorithm: tension }
    /// Generated spatial model, 1 link, by the mass matrix.
    pub struct SpatialDense1 { kind: spatial, links: 1, algorithm: dense }
    /// Generated spatial model, 1 link, by the rod tensions.
    pub struct SpatialTension1 { kind: spatial, links: 1, algorithm: tension }
    /// Generated spatial model, 2 links, by the mass matrix.
    pub struct SpatialDense2 { kind: spatial, links: 2, algorithm: dense }
    /// Generated spatial model, 2 links, by the rod tensions.
    pub struct SpatialTension2 { kind: spatial, links: 2, algorithm: tension }
    /// Generated spatial model, 3 links, by the mass matrix.
    pub struct SpatialDense3 { kind: spatial, links: 3, algorithm: dense }
    /// Generated spatial model, 3 links, by the rod tensions.
    pub struct SpatialTension3 { kind: spatial, links: 3, algorithm: tension }
    /// Generated spatial model, 4 links, by the mass matrix.
    pub struct SpatialDense4 { kind: spatial, links: 4, algorithm: dense }
    /// Generated spatial model, 4 links, by the rod tensions.
    pub struct SpatialTension4 { kind: spatial, links: 4, algorithm: tension }
    /// Generated spatial model, 5 links, by the mass matrix.
    pub struct SpatialDense5 { kind: spatial, links: 5, algorithm: dense }
    /// Generated spatial model, 5 links, by the rod tensions.
    pub struct SpatialTension5 { kind: spatial, links: 5, algorithm: tension }
    /// Generated spatial model, 6 links, by the mass matrix.
    pub struct SpatialDense6 { kind: spatial, links: 6, algorithm: dense }
    /// Generated spatial model, 6 links, by the rod tensions.
    pub struct SpatialTension6 { kind: spatial, links: 6, algorithm: tension }
    /// Generated spatial model, 7 links, by the mass matrix.
    pub struct SpatialDense7 { kind: spatial, links: 7, algorithm: dense }
    /// Generated spatial model, 7 links, by the rod tensions.
    pub struct SpatialTension7 { kind: spatial, links: 7, algorithm: tension }
    /// Generated spatial model, 8 links, by the mass matrix.
    pub struct SpatialDense8 { kind: spatial, links: 8, algorithm: dense }
    /// Generated spatial model, 8 links, by the rod tensions.
    pub struct SpatialTension8 { kind: spatial, links: 8, algorithm: tension }
}

/// Whether this is the smoke run of `cargo xtask bench --quick` (few sizes).
fn quick() -> bool {
    std::env::var_os("PENDULUM_BENCH_QUICK").is_some_and(|v| v != "0")
}

/// Whether this run times chains of `n` links (the quick run only n = 1, 2, 4).
fn wanted(n: usize) -> bool {
    !quick() || matches!(n, 1 | 2 | 4)
}

/// Chain lengths beyond the generated models, for the routes that accept any n.
fn large_sizes() -> &'static [usize] {
    if quick() { &[64] } else { &[12, 16, 64, 256, 1024, 4096] }
}

/// The largest n at which the dense generic route (O(n²) build, O(n³) Cholesky) is timed.
const DENSE_MAX: usize = 256;

/// A fixed, non-singular state: angles spread over (0.3, 2.8) so that no sin θ vanishes.
fn state<D: Dim>(dof: D) -> (OVector<f64, D>, OVector<f64, D>)
where
    DefaultAllocator: nalgebra::allocator::Allocator<D>,
{
    let q = OVector::from_iterator_generic(dof, U1, (0..dof.value()).map(|i| 0.3 + (i as f64 * 0.77) % 2.5));
    let qd =
        OVector::from_iterator_generic(dof, U1, (0..dof.value()).map(|i| ((i as f64) * 1.3).sin() * 3.0));
    (q, qd)
}

/// The benchmarked chain of `n` links, with `L = Dyn` or `Const<n>`: masses
/// `1 + 0.1 (i mod 10)` kg, lengths `0.5 + 0.05 (i mod 10)` m, g = 9.81 m/s², damping
/// 0.01 N·m·s at every joint.
fn chain<L: Dim>(n: usize) -> Chain<L>
where
    DefaultAllocator: Allocator<L>,
{
    let masses: Vec<f64> = (0..n).map(|i| 1.0 + 0.1 * (i % 10) as f64).collect();
    let lengths: Vec<f64> = (0..n).map(|i| 0.5 + 0.05 * (i % 10) as f64).collect();
    Chain::<L>::new(&masses, &lengths, 9.81)
        .and_then(|c| c.with_damping(&vec![0.01; n]))
        .expect("valid chain")
}

/// `out = Q − c − k − d`, the right-hand side of `M q̈ = …`, from the building blocks.
fn forces<M: Model>(
    model: &M,
    q: &OVector<f64, M::Dof>,
    qd: &OVector<f64, M::Dof>,
    inputs: &Inputs<M::Dof, M::Space>,
    out: &mut OVector<f64, M::Dof>,
    tmp: &mut OVector<f64, M::Dof>,
) where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>,
{
    model.generalized_forces(q, qd, &inputs.torque, out);
    model.velocity_terms(q, qd, tmp);
    *out -= &*tmp;
    model.gravity_terms(q, tmp);
    *out -= &*tmp;
    model.pivot_terms(q, &inputs.pivot_acceleration, tmp);
    *out -= &*tmp;
}

/// The operations cheap at any n: mass matrix, forces, accelerations, energy.
fn bench_evaluations<M: Model>(c: &mut Criterion, kind: &str, name: &str, n: usize, model: &M)
where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>,
{
    let dof = model.dof();
    let (q, qd) = state(dof);
    let inputs = model.zero_inputs();
    let id = BenchmarkId::new(name, n);

    let mut mass = OMatrix::<f64, M::Dof, M::Dof>::zeros_generic(dof, dof);
    c.benchmark_group(format!("{kind}_mass_matrix")).bench_function(id.clone(), |b| {
        b.iter(|| {
            model.mass_matrix(black_box(&q), &mut mass);
            black_box(&mass);
        })
    });

    let (mut out, mut tmp) = (qd.clone(), qd.clone());
    c.benchmark_group(format!("{kind}_forces")).bench_function(id.clone(), |b| {
        b.iter(|| {
            forces(model, black_box(&q), black_box(&qd), black_box(&inputs), &mut out, &mut tmp);
            black_box(&out);
        })
    });

    bench_accelerations(c, kind, name, n, model);

    c.benchmark_group(format!("{kind}_energy"))
        .bench_function(id, |b| b.iter(|| black_box(model.energy(black_box(&q), black_box(&qd)))));
}

/// `Model::accelerations` of `model`.
fn bench_accelerations<M: Model>(c: &mut Criterion, kind: &str, name: &str, n: usize, model: &M)
where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>,
{
    let (q, qd) = state(model.dof());
    let inputs = model.zero_inputs();
    let mut out = qd.clone();
    c.benchmark_group(format!("{kind}_accelerations")).bench_function(BenchmarkId::new(name, n), |b| {
        b.iter(|| {
            model.accelerations(black_box(&q), black_box(&qd), black_box(&inputs), &mut out).unwrap();
            black_box(&out);
        })
    });
}

/// `System::rhs` of the O(n) `Directions` chain of `n` links (`U2` planar, `U3`
/// spatial), at the state of the same angles as the other routes, in the
/// `<kind>_accelerations` group.
fn bench_directions<S: DimName>(
    c: &mut Criterion,
    kind: &str,
    n: usize,
    to_state: impl Fn(&Directions<S>, &[f64], &[f64]) -> pendulum_core::Result<DVector<f64>>,
) where
    DefaultAllocator: nalgebra::allocator::Allocator<S>,
{
    let system = Directions::<S>::new(chain::<Dyn>(n));
    let dof = if S::DIM == 2 { n } else { 2 * n };
    let (q, qd) = state::<Dyn>(Dyn(dof));
    let x = to_state(&system, q.as_slice(), qd.as_slice()).expect("non-singular state");
    let mut f = DVector::zeros(x.len());
    c.benchmark_group(format!("{kind}_accelerations")).bench_function(
        BenchmarkId::new("directions", n),
        |b| {
            b.iter(|| {
                system.rhs(0.0, black_box(&x), &mut f).unwrap();
                black_box(&f);
            })
        },
    );
}

/// The O(n) routes at `n` links: `PlanarTension<Dyn>` accelerations (and, if `step`, its
/// Gauss–Legendre step), `Directions` rhs planar and spatial (if `spatial`).
fn bench_linear(c: &mut Criterion, n: usize, step: bool, spatial: bool) {
    let tension = PlanarTension::new(chain::<Dyn>(n));
    bench_accelerations(c, "planar", "tension", n, &tension);
    if step {
        bench_gl2_step(c, "planar", "tension", n, &tension);
    }
    bench_directions::<U2>(c, "planar", n, |s, q, qd| s.from_angles(q, qd));
    if spatial {
        bench_directions::<U3>(c, "spatial", n, |s, q, qd| s.from_spherical(q, qd));
    }
}

/// One two-stage Gauss–Legendre step (h = 1 ms) of `model` through `FirstOrder`, always
/// from the same state.
fn bench_gl2_step<M: Model + Clone>(c: &mut Criterion, kind: &str, name: &str, n: usize, model: &M)
where
    M::Dof: DimMul<U2>,
    DimProd<M::Dof, U2>: DimMul<U2>,
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space> + GaussAlloc<DimProd<M::Dof, U2>, U2>,
{
    let system = FirstOrder::new(model.clone());
    let (q, qd) = state(model.dof());
    let x0 = system.state(&q, &qd);
    let mut solver = GaussLegendre::<_, U2>::new(&system, GaussOptions::default());
    let mut state = State::new(0.0, x0.clone());
    c.benchmark_group(format!("{kind}_gl2_step")).bench_function(BenchmarkId::new(name, n), |b| {
        b.iter(|| {
            state.set(0.0, &x0);
            solver.step(&system, &mut state, black_box(1e-3)).unwrap();
            black_box(state.x());
        })
    });
}

/// All five operations of one model.
fn bench_model<M: Model + Clone>(c: &mut Criterion, kind: &str, name: &str, n: usize, model: &M)
where
    M::Dof: DimMul<U2>,
    DimProd<M::Dof, U2>: DimMul<U2>,
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space> + GaussAlloc<DimProd<M::Dof, U2>, U2>,
{
    bench_evaluations(c, kind, name, n, model);
    bench_gl2_step(c, kind, name, n, model);
}

/// The physical-limit baseline for `dof` coordinates: `dof` calls of `sin_cos` and
/// `2·dof` stores.
fn bench_baseline(c: &mut Criterion, kind: &str, n: usize, dof: usize) {
    let (q, _) = state(Dyn(dof));
    let q: Vec<f64> = q.iter().copied().collect();
    let mut out = vec![0.0; 2 * dof];
    c.benchmark_group(format!("{kind}_accelerations")).bench_function(BenchmarkId::new("baseline", n), |b| {
        b.iter(|| {
            for (x, pair) in black_box(&q).iter().zip(out.chunks_exact_mut(2)) {
                let (s, co) = x.sin_cos();
                pair[0] = s;
                pair[1] = co;
            }
            black_box(&mut out);
        })
    });
}

/// The closed-form double pendulum (eq 50, corrected): its accelerations.
fn bench_closed_form(c: &mut Criterion) {
    let p = chain::<Const<2>>(2);
    let (m, l) = (p.masses(), p.lengths());
    let model = DoublePendulum::new(m[0], m[1], l[0], l[1], p.gravity()).expect("valid parameters");
    let (q, qd) = state(Const::<2>);
    let (q, qd) = ([q[0], q[1]], [qd[0], qd[1]]);
    c.benchmark_group("planar_accelerations").bench_function(BenchmarkId::new("closed_form", 2), |b| {
        b.iter(|| black_box(model.accelerations(black_box(q), black_box(qd))))
    });
    // The part of the generated model's cost the closed form does not have: validating
    // the lengths and finiteness of q, q̇, σ and p̈.
    let (q, qd) = state(Const::<2>);
    let inputs = Inputs::<Const<2>, U2>::zeros(Const::<2>);
    c.benchmark_group("planar_input_checks").bench_function(BenchmarkId::new("check_inputs", 2), |b| {
        b.iter(|| pendulum_core::check_inputs(2, black_box(&q), black_box(&qd), black_box(&inputs)).unwrap())
    });
}

/// The generated model of `n` links, the generic one with `L = Const<n>` and with
/// `L = Dyn`, and the baseline, all five operations each.
macro_rules! bench_sizes {
    ($c:expr, $kind:literal, $generic:ident, $dof_per_link:literal, $($n:literal => $generated:ident),* $(,)?) => {
        $(
            if wanted($n) {
                bench_model($c, $kind, "generated", $n, &$generated::new(chain::<Const<$n>>($n)));
                bench_model($c, $kind, "generic_fixed", $n, &$generic::new(chain::<Const<$n>>($n)));
                bench_model($c, $kind, "generic_dyn", $n, &$generic::new(chain::<Dyn>($n)));
                bench_baseline($c, $kind, $n, $dof_per_link * $n);
            }
        )*
    };
}

fn small_chains(c: &mut Criterion) {
    bench_sizes!(c, "planar", Planar, 1,
        1 => Planar1, 2 => Planar2, 3 => Planar3, 4 => Planar4,
        5 => Planar5, 6 => Planar6, 7 => Planar7, 8 => Planar8,
    );
    bench_closed_form(c);
    bench_sizes!(c, "spatial", Spatial, 2, 1 => Spatial1, 2 => Spatial2, 3 => Spatial3, 4 => Spatial4);
    for n in (1..=8).filter(|&n| wanted(n)) {
        bench_linear(c, n, true, n <= 4);
    }
}

/// Beyond the sizes of all five operations: generated planar n = 12 and 16, the O(n)
/// routes, the dense generic route up to [`DENSE_MAX`] links and the baseline
/// (accelerations only).
fn large_chains(c: &mut Criterion) {
    if !quick() {
        bench_accelerations(c, "planar", "generated", 12, &Planar12::new(chain::<Const<12>>(12)));
        bench_accelerations(c, "planar", "generated", 16, &Planar16::new(chain::<Const<16>>(16)));
    }
    for &n in large_sizes() {
        bench_linear(c, n, false, true);
        if n <= DENSE_MAX {
            bench_accelerations(c, "planar", "generic_dyn", n, &Planar::new(chain::<Dyn>(n)));
            bench_accelerations(c, "spatial", "generic_dyn", n, &Spatial::new(chain::<Dyn>(n)));
        }
        bench_baseline(c, "planar", n, n);
        bench_baseline(c, "spatial", n, 2 * n);
    }
}

/// Both algorithms of the generated models (`algorithm: dense | tension`) at every n they
/// are made for here (planar 1..16, spatial 1..8), accelerations only, as
/// `generated_dense` and `generated_tension`; beside them the O(n) routes at the sizes the
/// other groups skip, and spatial `Directions` converted to the angles' q̈
/// (`directions_angles`: `Directions::spherical_accelerations`, which builds the direction
/// state from the angles and allocates its result).
fn algorithms(c: &mut Criterion) {
    macro_rules! both {
        ($kind:literal, $($n:literal => $dense:ident, $tension:ident),* $(,)?) => {
            $(
                if wanted($n) {
                    bench_accelerations(c, $kind, "generated_dense", $n, &$dense::new(chain::<Const<$n>>($n)));
                    bench_accelerations(c, $kind, "generated_tension", $n, &$tension::new(chain::<Const<$n>>($n)));
                }
            )*
        };
    }
    both!("planar",
        1 => PlanarDense1, PlanarTension1, 2 => PlanarDense2, PlanarTension2,
        3 => PlanarDense3, PlanarTension3, 4 => PlanarDense4, PlanarTension4,
        5 => PlanarDense5, PlanarTension5, 6 => PlanarDense6, PlanarTension6,
        7 => PlanarDense7, PlanarTension7, 8 => PlanarDense8, PlanarTension8,
        9 => PlanarDense9, PlanarTension9, 10 => PlanarDense10, PlanarTension10,
        11 => PlanarDense11, PlanarTension11, 12 => PlanarDense12, PlanarTension12,
        13 => PlanarDense13, PlanarTension13, 14 => PlanarDense14, PlanarTension14,
        15 => PlanarDense15, PlanarTension15, 16 => PlanarDense16, PlanarTension16,
    );
    both!("spatial",
        1 => SpatialDense1, SpatialTension1, 2 => SpatialDense2, SpatialTension2,
        3 => SpatialDense3, SpatialTension3, 4 => SpatialDense4, SpatialTension4,
        5 => SpatialDense5, SpatialTension5, 6 => SpatialDense6, SpatialTension6,
        7 => SpatialDense7, SpatialTension7, 8 => SpatialDense8, SpatialTension8,
    );
    if quick() {
        return;
    }
    for n in [9, 10, 11, 13, 14, 15] {
        let tension = PlanarTension::new(chain::<Dyn>(n));
        bench_accelerations(c, "planar", "tension", n, &tension);
        bench_directions::<U2>(c, "planar", n, |s, q, qd| s.from_angles(q, qd));
    }
    for n in 5..=8 {
        bench_directions::<U3>(c, "spatial", n, |s, q, qd| s.from_spherical(q, qd));
    }
    for n in 1..=8 {
        let system = Directions::<U3>::new(chain::<Dyn>(n));
        let (q, qd) = state::<Dyn>(Dyn(2 * n));
        c.benchmark_group("spatial_accelerations").bench_function(
            BenchmarkId::new("directions_angles", n),
            |b| {
                b.iter(|| {
                    black_box(
                        system
                            .spherical_accelerations(0.0, black_box(q.as_slice()), black_box(qd.as_slice()))
                            .unwrap(),
                    )
                })
            },
        );
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_millis(700))
        .sample_size(40);
    targets = small_chains, large_chains, algorithms
}
criterion_main!(benches);
