//! The generated fixed-N models agree with the generic `Planar<Dyn>` / `Spatial<Dyn>` in
//! every `Model` method, at random states, to round-off of each entry's scale.

use nalgebra::{DMatrix, DefaultAllocator, Dim, DimName, Dyn, OVector, U1};
use pendulum_core::{Chain, Error, Inputs, Model, ModelAlloc, Planar, Spatial};

pendulum_macros::model! {
    /// A single planar pendulum.
    pub struct Planar1 { kind: planar, links: 1 }
    pub struct Planar2 { kind: planar, links: 2 }
    pub struct Planar3 { kind: planar, links: 3 }
    pub struct Planar4 { kind: planar, links: 4 }
    pub struct Planar8 { kind: planar, links: 8 }
    /// The largest model the macro makes.
    pub struct Planar16 { kind: planar, links: 16 }
    pub struct Spatial1 { kind: spatial, links: 1 }
    pub struct Spatial2 { kind: spatial, links: 2 }
    pub struct Spatial3 { kind: spatial, links: 3 }
    pub struct Spatial4 { kind: spatial, links: 4 }
    pub struct Spatial16 { kind: spatial, links: 16 }
    // Each algorithm at each size, whatever the default.
    pub struct DensePlanar16 { kind: planar, links: 16, algorithm: dense }
    pub struct TensionPlanar1 { kind: planar, links: 1, algorithm: tension }
    pub struct TensionPlanar2 { kind: planar, links: 2, algorithm: tension }
    pub struct TensionPlanar3 { kind: planar, links: 3, algorithm: tension }
    pub struct DensePlanar8 { kind: planar, links: 8, algorithm: dense }
    pub struct TensionPlanar8 { kind: planar, links: 8, algorithm: tension }
    pub struct TensionPlanar16 { kind: planar, links: 16, algorithm: tension }
    pub struct DenseSpatial3 { kind: spatial, links: 3, algorithm: dense }
    pub struct DenseSpatial16 { kind: spatial, links: 16, algorithm: dense }
    pub struct TensionSpatial1 { kind: spatial, links: 1, algorithm: tension }
    pub struct TensionSpatial2 { kind: spatial, links: 2, algorithm: tension }
    pub struct TensionSpatial3 { kind: spatial, links: 3, algorithm: tension }
    pub struct TensionSpatial16 { kind: spatial, links: 16, algorithm: tension }
}

/// Round-off allowed, relative to each entry's scale.
const TOLERANCE: f64 = 1e-12;
const TRIALS: usize = 100;

/// SplitMix64: a small seeded generator, so every run draws the same states.
struct Rng(u64);

impl Rng {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `[lo, hi)`.
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        let unit = (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        lo + (hi - lo) * unit
    }

    /// Log-uniform in `[0.1, 10]`.
    fn positive(&mut self) -> f64 {
        10f64.powf(self.uniform(-1.0, 1.0))
    }

    fn many(&mut self, n: usize, f: impl Fn(&mut Self) -> f64) -> Vec<f64> {
        (0..n).map(|_| f(self)).collect()
    }
}

/// One random chain, state and inputs, as plain numbers.
struct Case {
    masses: Vec<f64>,
    lengths: Vec<f64>,
    damping: Vec<f64>,
    gravity: f64,
    q: Vec<f64>,
    qd: Vec<f64>,
    torque: Vec<f64>,
    pivot: Vec<f64>,
}

impl Case {
    fn random(rng: &mut Rng, links: usize, dof: usize, space: usize) -> Self {
        use std::f64::consts::PI;
        Case {
            masses: rng.many(links, Rng::positive),
            lengths: rng.many(links, Rng::positive),
            damping: rng.many(links, |r| r.uniform(0.0, 2.0)),
            gravity: rng.uniform(0.0, 20.0),
            q: rng.many(dof, |r| r.uniform(-PI, PI)),
            qd: rng.many(dof, |r| r.uniform(-10.0, 10.0)),
            torque: rng.many(dof, |r| r.uniform(-10.0, 10.0)),
            pivot: rng.many(space, |r| r.uniform(-20.0, 20.0)),
        }
    }

    fn chain<L: Dim>(&self) -> Chain<L>
    where
        DefaultAllocator: nalgebra::allocator::Allocator<L>,
    {
        Chain::new(&self.masses, &self.lengths, self.gravity).unwrap().with_damping(&self.damping).unwrap()
    }

    /// `W_ij = M_max(i,j) l_i l_j` for the coordinates `a` and `b`.
    fn weight(&self, a: usize, b: usize) -> f64 {
        let n = self.masses.len();
        let (i, j) = (a % n, b % n);
        let tail: f64 = self.masses[i.max(j)..].iter().sum();
        tail * self.lengths[i] * self.lengths[j]
    }
}

fn vector<D: Dim>(dim: D, values: &[f64]) -> OVector<f64, D>
where
    DefaultAllocator: nalgebra::allocator::Allocator<D>,
{
    OVector::from_iterator_generic(dim, U1, values.iter().copied())
}

/// What `write` writes into a NaN-filled vector (so an entry it skips shows).
fn output<D: Dim>(dim: D, write: impl FnOnce(&mut OVector<f64, D>)) -> Vec<f64>
where
    DefaultAllocator: nalgebra::allocator::Allocator<D>,
{
    let mut out = OVector::from_element_generic(dim, U1, f64::NAN);
    write(&mut out);
    out.as_slice().to_vec()
}

/// Every `Model` method of one model at one state, as plain numbers.
#[derive(Debug)]
struct Evaluation {
    mass: DMatrix<f64>,
    velocity: Vec<f64>,
    gravity: Vec<f64>,
    pivot: Vec<f64>,
    forces: Vec<f64>,
    kinetic: f64,
    potential: f64,
    energy: f64,
    accelerations: Vec<f64>,
}

fn evaluate<M: Model>(model: &M, case: &Case) -> Evaluation
where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>,
{
    let dof = model.dof();
    let n = dof.value();
    let q = vector(dof, &case.q);
    let qd = vector(dof, &case.qd);
    let torque = vector(dof, &case.torque);
    let pivot = vector(M::Space::name(), &case.pivot);
    let mut mass = nalgebra::OMatrix::<f64, M::Dof, M::Dof>::from_element_generic(dof, dof, f64::NAN);
    model.mass_matrix(&q, &mut mass);
    let velocity = output(dof, |out| model.velocity_terms(&q, &qd, out));
    let gravity = output(dof, |out| model.gravity_terms(&q, out));
    let pivot_terms = output(dof, |out| model.pivot_terms(&q, &pivot, out));
    let forces = output(dof, |out| model.generalized_forces(&q, &qd, &torque, out));
    let inputs = Inputs { torque: torque.clone(), pivot_acceleration: pivot.clone() };
    let accelerations = output(dof, |out| model.accelerations(&q, &qd, &inputs, out).unwrap());
    Evaluation {
        mass: DMatrix::from_iterator(n, n, mass.iter().copied()),
        velocity,
        gravity,
        pivot: pivot_terms,
        forces,
        kinetic: model.kinetic_energy(&q, &qd),
        potential: model.potential_energy(&q),
        energy: model.energy(&q, &qd),
        accelerations,
    }
}

#[track_caller]
fn close(what: &str, got: f64, want: f64, scale: f64, case: &str) {
    let err = (got - want).abs();
    assert!(
        err <= TOLERANCE * scale,
        "{case}: {what}: generated {got:e}, generic {want:e}, error {err:e} > {TOLERANCE:e} × scale {scale:e}"
    );
}

/// Compares every method of `fixed` with `generic` at [`TRIALS`] random states.
fn agree<F, G>(make_generic: impl Fn(Chain<Dyn>) -> G, seed: u64)
where
    F: Model + From<Chain<F::Links>>,
    G: Model,
    DefaultAllocator: ModelAlloc<F::Links, F::Dof, F::Space> + ModelAlloc<G::Links, G::Dof, G::Space>,
{
    let mut rng = Rng(seed);
    for trial in 0..TRIALS {
        let trial = format!("{} case {trial}", std::any::type_name::<F>());
        let trial = trial.as_str();
        let links = F::Links::try_to_usize().expect("generated models have a fixed size");
        let dof = F::Dof::try_to_usize().unwrap();
        let spatial = dof == 2 * links;
        let case = Case::random(&mut rng, links, dof, F::Space::dim());
        let fixed = F::from(case.chain());
        let generic = make_generic(case.chain());
        assert_eq!(fixed.chain().masses().as_slice(), generic.chain().masses().as_slice());
        if spatial && (0..links).any(|i| case.q[i].sin().abs() < 1e-3) {
            continue; // near the coordinate singularity the solve is ill-conditioned: tested apart
        }
        let (f, g) = (evaluate(&fixed, &case), evaluate(&generic, &case));
        let rate = |j: usize| case.qd[j].abs() + if spatial { case.qd[j + links].abs() } else { 0.0 };
        let p = case.pivot.iter().map(|x| x.abs()).sum::<f64>();
        let mut kinetic_scale = 0.0;
        for a in 0..dof {
            for b in 0..dof {
                let w = case.weight(a, b);
                close(&format!("M[({a}, {b})]"), f.mass[(a, b)], g.mass[(a, b)], w, trial);
                kinetic_scale += 0.5 * w * case.qd[a].abs() * case.qd[b].abs();
            }
            let i = a % links;
            let velocity_scale: f64 = (0..links).map(|j| 2.0 * case.weight(i, j) * rate(j).powi(2)).sum();
            close(&format!("c[{a}]"), f.velocity[a], g.velocity[a], velocity_scale, trial);
            let ml = case.weight(i, i) / case.lengths[i];
            close(&format!("k[{a}]"), f.gravity[a], g.gravity[a], ml * case.gravity, trial);
            close(&format!("d[{a}]"), f.pivot[a], g.pivot[a], ml * p, trial);
            let force_scale = case.torque[a].abs() + case.damping[i] * case.qd[a].abs();
            close(&format!("Q[{a}]"), f.forces[a], g.forces[a], force_scale, trial);
        }
        let potential_scale: f64 =
            (0..links).map(|i| case.weight(i, i) / case.lengths[i] * case.gravity).sum();
        close("T", f.kinetic, g.kinetic, kinetic_scale, trial);
        close("U", f.potential, g.potential, potential_scale, trial);
        close("H", f.energy, g.energy, kinetic_scale + potential_scale, trial);
        // The generated `energy` shares the lets of T and U and sums each as its own method
        // does, so it is T + U to the bit.
        let (sum, energy) = (f.kinetic + f.potential, f.energy);
        assert_eq!(energy.to_bits(), sum.to_bits(), "{trial}: H = {energy:e}, T + U = {sum:e}");
        // The solve amplifies round-off by up to the condition number κ of M; both sides
        // are backward stable, so allow max(TOLERANCE, κ ε) of the largest |q̈|.
        let singular = g.mass.clone().singular_values();
        let condition = singular.max() / singular.min();
        let size = g.accelerations.iter().map(|x| x.abs()).fold(0.0, f64::max);
        let scale = size * 1f64.max(condition * f64::EPSILON / TOLERANCE);
        for a in 0..dof {
            close(&format!("q̈[{a}]"), f.accelerations[a], g.accelerations[a], scale, trial);
        }
    }
}

#[test]
fn planar_models_agree_with_the_generic_planar_model() {
    agree::<Planar1, _>(Planar::new, 1);
    agree::<Planar2, _>(Planar::new, 2);
    agree::<Planar3, _>(Planar::new, 3);
    agree::<Planar4, _>(Planar::new, 4);
    agree::<Planar8, _>(Planar::new, 8);
    agree::<Planar16, _>(Planar::new, 16);
    agree::<DensePlanar16, _>(Planar::new, 116);
    agree::<TensionPlanar1, _>(Planar::new, 101);
    agree::<TensionPlanar2, _>(Planar::new, 102);
    agree::<TensionPlanar3, _>(Planar::new, 103);
    agree::<TensionPlanar8, _>(Planar::new, 108);
    agree::<TensionPlanar16, _>(Planar::new, 216);
}

#[test]
fn spatial_models_agree_with_the_generic_spatial_model() {
    agree::<Spatial1, _>(Spatial::new, 11);
    agree::<Spatial2, _>(Spatial::new, 12);
    agree::<Spatial3, _>(Spatial::new, 13);
    agree::<Spatial4, _>(Spatial::new, 14);
    agree::<Spatial16, _>(Spatial::new, 16);
    agree::<DenseSpatial16, _>(Spatial::new, 316);
    agree::<TensionSpatial1, _>(Spatial::new, 111);
    agree::<TensionSpatial2, _>(Spatial::new, 112);
    agree::<TensionSpatial3, _>(Spatial::new, 113);
    agree::<TensionSpatial16, _>(Spatial::new, 416);
}

fn uniform<L: Dim>(n: usize) -> Chain<L>
where
    DefaultAllocator: nalgebra::allocator::Allocator<L>,
{
    Chain::new(&vec![1.0; n], &vec![0.5; n], 9.81).unwrap()
}

#[test]
fn spatial_model_reports_the_singular_link() {
    reports_the_singular_link(&Spatial3::new(uniform(3)));
    reports_the_singular_link(&DenseSpatial3::new(uniform(3)));
    reports_the_singular_link(&TensionSpatial3::new(uniform(3)));
}

fn reports_the_singular_link<
    M: Model<Links = nalgebra::Const<3>, Dof = nalgebra::Const<6>, Space = nalgebra::U3>,
>(
    model: &M,
) {
    let mut a = nalgebra::SVector::<f64, 6>::zeros();
    let qd = nalgebra::SVector::<f64, 6>::repeat(0.5);
    for link in 1..=3 {
        for theta in [0.0, 1e-9, std::f64::consts::PI] {
            let mut q = nalgebra::SVector::<f64, 6>::from([0.3, 1.0, 2.0, 0.1, 0.2, 0.3]);
            q[link - 1] = theta;
            let err = model.accelerations(&q, &qd, &model.zero_inputs(), &mut a).unwrap_err();
            assert!(matches!(err, Error::SingularAngle { link: l, .. } if l == link), "{err}");
            assert_eq!(model.check_configuration(&q), Err(err));
        }
    }
    let q = nalgebra::SVector::<f64, 6>::from([1e-3, 1.0, 2.0, 0.1, 0.2, 0.3]);
    assert!(model.accelerations(&q, &qd, &model.zero_inputs(), &mut a).is_ok());
    assert!(model.check_configuration(&q).is_ok());
}

#[test]
fn non_finite_inputs_are_named() {
    let planar = Planar2::new(uniform(2));
    let mut a = nalgebra::Vector2::zeros();
    let q = nalgebra::Vector2::new(0.1, f64::NAN);
    let err =
        planar.accelerations(&q, &nalgebra::Vector2::zeros(), &planar.zero_inputs(), &mut a).unwrap_err();
    assert!(matches!(err, Error::NonFinite { what: "q", index: 1, .. }), "{err}");

    let spatial = Spatial2::new(uniform(2));
    let mut a = nalgebra::Vector4::zeros();
    let q = nalgebra::Vector4::new(0.3, 0.4, 0.0, 0.0);
    let qd = nalgebra::Vector4::new(0.0, 0.0, f64::INFINITY, 0.0);
    let err = spatial.accelerations(&q, &qd, &spatial.zero_inputs(), &mut a).unwrap_err();
    assert!(matches!(err, Error::NonFinite { what: "qd", index: 2, .. }), "{err}");
    let mut inputs = spatial.zero_inputs();
    inputs.pivot_acceleration[2] = f64::NAN;
    let err = spatial.accelerations(&q, &nalgebra::Vector4::zeros(), &inputs, &mut a).unwrap_err();
    assert!(matches!(err, Error::NonFinite { what: "pivot_acceleration", index: 2, .. }), "{err}");
}

#[test]
fn an_underflowing_mass_matrix_is_not_positive_definite_in_both_models() {
    // W_00 = m l² = 1e-200 · 1e-200 underflows to 0.
    let chain = |n| Chain::<Dyn>::new(&vec![1e-200; n], &vec![1e-100; n], 9.81).unwrap();
    let fixed = Planar2::new(Chain::new(&[1e-200; 2], &[1e-100; 2], 9.81).unwrap());
    let q = nalgebra::Vector2::new(0.3, 0.4);
    let mut a = nalgebra::Vector2::zeros();
    let err = fixed.accelerations(&q, &q, &fixed.zero_inputs(), &mut a);
    assert_eq!(err, Err(Error::NotPositiveDefinite));
    let generic = Planar::new(chain(2));
    let q = nalgebra::DVector::from_row_slice(&[0.3, 0.4]);
    let mut a = nalgebra::DVector::zeros(2);
    assert_eq!(
        generic.accelerations(&q, &q, &generic.zero_inputs(), &mut a),
        Err(Error::NotPositiveDefinite)
    );
}

#[test]
fn generated_types_have_the_expected_shape_and_derives() {
    let chain = uniform::<nalgebra::Const<3>>(3);
    let model = Planar3::from(chain.clone());
    assert_eq!(model.clone(), Planar3::new(chain.clone()));
    assert_eq!(model.chain(), &chain);
    assert_eq!(model.dof(), nalgebra::Const::<3>);
    assert!(format!("{model:?}").starts_with("Planar3 { chain: Chain {"));
    let spatial = Spatial3::new(chain);
    assert_eq!(spatial.dof(), nalgebra::Const::<6>);
    assert_eq!(spatial.zero_inputs().pivot_acceleration.len(), 3);
    // The default algorithm by size (the crossover measured in docs/bench.md), and the
    // one asked for.
    assert_eq!([Planar1::ALGORITHM, Planar3::ALGORITHM, Planar4::ALGORITHM], ["dense", "dense", "tension"]);
    assert_eq!([Spatial1::ALGORITHM, Spatial2::ALGORITHM], ["dense", "tension"]);
    assert_eq!([DensePlanar16::ALGORITHM, TensionPlanar1::ALGORITHM], ["dense", "tension"]);
}

/// Sets entry `index` of `what` (`q`, `qd`, `torque` or `pivot_acceleration`) to `bad` in
/// states built from `q0`, `qd0` (torques 0.5, pivot acceleration (0.3, −0.2[, 0.1])) and
/// checks that `accelerations` names exactly that entry: the generated models check their
/// inputs only on the way to an error, so every entry must reach one.
fn every_bad_entry_is_named<M: Model>(model: &M, q0: &[f64], qd0: &[f64], label: &str)
where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>,
{
    let dof = model.dof();
    let space = <M::Space as DimName>::dim();
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        for (what, len) in
            [("q", dof.value()), ("qd", dof.value()), ("torque", dof.value()), ("pivot_acceleration", space)]
        {
            for index in 0..len {
                let mut q = OVector::<f64, M::Dof>::from_iterator_generic(dof, U1, q0.iter().copied());
                let mut qd = OVector::<f64, M::Dof>::from_iterator_generic(dof, U1, qd0.iter().copied());
                let mut inputs: Inputs<M::Dof, M::Space> = model.zero_inputs();
                inputs.torque.fill(0.5);
                for (k, p) in inputs.pivot_acceleration.iter_mut().enumerate() {
                    *p = [0.3, -0.2, 0.1][k];
                }
                match what {
                    "q" => q[index] = bad,
                    "qd" => qd[index] = bad,
                    "torque" => inputs.torque[index] = bad,
                    _ => inputs.pivot_acceleration[index] = bad,
                }
                let mut out = OVector::<f64, M::Dof>::zeros_generic(dof, U1);
                let err = model.accelerations(&q, &qd, &inputs, &mut out);
                let named = matches!(
                    err,
                    Err(Error::NonFinite { what: w, index: i, value })
                        if w == what && i == index && value.to_bits() == bad.to_bits()
                );
                assert!(named, "{label}: {what}[{index}] = {bad} gave {err:?}");
            }
        }
    }
}

#[test]
fn every_non_finite_entry_is_named_even_where_it_is_multiplied_by_zero() {
    // Zero angles, rates, damping and gravity: many products with a bad entry are ∞·0.
    fn still<L: Dim>(n: usize) -> Chain<L>
    where
        DefaultAllocator: nalgebra::allocator::Allocator<L>,
    {
        Chain::new(&vec![1.0; n], &vec![0.5; n], 0.0).unwrap()
    }
    fn moving<L: Dim>(n: usize) -> Chain<L>
    where
        DefaultAllocator: nalgebra::allocator::Allocator<L>,
    {
        let damping: Vec<f64> = (0..n).map(|i| 0.1 * (i + 1) as f64).collect();
        uniform::<L>(n).with_damping(&damping).unwrap()
    }
    let angles = |n: usize| (0..n).map(|i| 0.3 + 0.4 * i as f64).collect::<Vec<_>>();
    let rates = |n: usize| (0..n).map(|i| 0.7 - 0.5 * i as f64).collect::<Vec<_>>();
    every_bad_entry_is_named(&Planar1::new(still(1)), &[0.0], &[0.0], "planar 1 still");
    every_bad_entry_is_named(&Planar2::new(still(2)), &[0.0; 2], &[0.0; 2], "planar 2 still");
    every_bad_entry_is_named(&Planar3::new(still(3)), &[0.0; 3], &[0.0; 3], "planar 3 still");
    every_bad_entry_is_named(&Planar2::new(moving(2)), &angles(2), &rates(2), "planar 2");
    every_bad_entry_is_named(&Planar4::new(moving(4)), &angles(4), &rates(4), "planar 4");
    every_bad_entry_is_named(&Planar16::new(moving(16)), &angles(16), &rates(16), "planar 16");
    // Spatial: θ away from the poles, φ = 0.
    let spatial_still = |n: usize| [vec![0.5; n], vec![0.0; n]].concat();
    every_bad_entry_is_named(&Spatial1::new(still(1)), &spatial_still(1), &[0.0; 2], "spatial 1 still");
    every_bad_entry_is_named(&Spatial2::new(still(2)), &spatial_still(2), &[0.0; 4], "spatial 2 still");
    every_bad_entry_is_named(&Spatial3::new(still(3)), &spatial_still(3), &[0.0; 6], "spatial 3 still");
    every_bad_entry_is_named(&Spatial3::new(moving(3)), &angles(6), &rates(6), "spatial 3");
    // The tension route, which reads every entry through other operations.
    every_bad_entry_is_named(&TensionPlanar3::new(still(3)), &[0.0; 3], &[0.0; 3], "tension planar 3 still");
    every_bad_entry_is_named(&TensionPlanar16::new(moving(16)), &angles(16), &rates(16), "tension planar 16");
    every_bad_entry_is_named(
        &TensionSpatial2::new(still(2)),
        &spatial_still(2),
        &[0.0; 4],
        "tension spatial 2 still",
    );
    every_bad_entry_is_named(&TensionSpatial3::new(moving(3)), &angles(6), &rates(6), "tension spatial 3");
    every_bad_entry_is_named(&DenseSpatial3::new(moving(3)), &angles(6), &rates(6), "dense spatial 3");
    // A singular angle too: the input error comes first.
    let singular = [0.0, 0.5, 0.0, 0.0];
    every_bad_entry_is_named(&Spatial2::new(moving(2)), &singular, &rates(4), "spatial 2 singular");
}

#[test]
fn extreme_mass_ratios_take_the_classical_pivots_and_still_agree() {
    // Masses of 1e-150 kg: the continuants pass 2⁸⁰⁰ within two rods and the tension
    // route redoes the elimination by pivots; the accelerations stay the dense ones.
    let masses = [1e-150, 3e-150, 2e-150, 1e-150, 5e-151, 1e-150, 2e-150, 4e-150];
    let chain = || {
        Chain::<nalgebra::Const<8>>::new(&masses, &[1.0, 0.5, 2.0, 1.0, 0.3, 0.7, 1.1, 0.9], 9.81).unwrap()
    };
    let (dense, tension) = (DensePlanar8::new(chain()), TensionPlanar8::new(chain()));
    let q = nalgebra::SVector::<f64, 8>::from_fn(|i, _| 0.4 * i as f64 - 1.0);
    let qd = nalgebra::SVector::<f64, 8>::from_fn(|i, _| 0.3 - 0.1 * i as f64);
    let (mut a, mut b) = (nalgebra::SVector::<f64, 8>::zeros(), nalgebra::SVector::<f64, 8>::zeros());
    dense.accelerations(&q, &qd, &dense.zero_inputs(), &mut a).unwrap();
    tension.accelerations(&q, &qd, &tension.zero_inputs(), &mut b).unwrap();
    assert!((a - b).amax() < 1e-10 * a.amax(), "dense {a}, tension {b}");
}
