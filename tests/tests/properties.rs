//! Property tests (proptest) over random valid chains and states.
//!
//! Each property is an identity the physics guarantees, so a failure is a bug in the
//! model code, not in a tolerance. Why each one catches real bugs is said at each test;
//! case counts are in `CASES_*` and in `docs/reliability.md`. Parameters: masses and
//! lengths log-uniform over [0.1, 10] (kg, m), g in [0, 20] m/s², damping in [0, 2];
//! planar θ anywhere in (−π, π), spatial θ_i in ±[0.2, π − 0.2] (off the sin θ = 0
//! singularity), rates in ±5 rad/s, torques ±10 N·m, pivot accelerations ±20 m/s².
//! Every failing case is shrunk by proptest and printed with its parameters.

use std::f64::consts::PI;

use nalgebra::{Const, DMatrix, DVector, Dyn, U2, U3, Vector2, Vector3};
use pendulum_core::integrate::{GaussLegendre, GaussOptions, Integrator, State};
use pendulum_core::{Canonical, Chain, Directions, Inputs, Model, Planar, PlanarTension, Spatial};
use proptest::prelude::*;
use proptest::test_runner::Config;

pendulum_macros::model! {
    struct Planar4 { kind: planar, links: 4 }
    struct Spatial3 { kind: spatial, links: 3 }
}

/// Cases per cheap property (one or two model evaluations each).
const CASES_CHEAP: u32 = 1024;
/// Cases per property that integrates (a few hundred implicit steps each).
const CASES_RUN: u32 = 64;

/// Relative agreement expected between two evaluations of the same quantity by different
/// routes: round-off amplified by the condition of the mass matrix (mass and length
/// ratios up to 100 give condition numbers up to ~1e6).
const ROUTE_TOLERANCE: f64 = 1e-8;

/// Chain parameters of `n` links: (masses, lengths, g, damping).
#[derive(Debug, Clone)]
struct Params {
    masses: Vec<f64>,
    lengths: Vec<f64>,
    gravity: f64,
    damping: Vec<f64>,
}

impl Params {
    fn chain<L: nalgebra::Dim>(&self) -> Chain<L>
    where
        nalgebra::DefaultAllocator: nalgebra::allocator::Allocator<L>,
    {
        Chain::new(&self.masses, &self.lengths, self.gravity)
            .and_then(|c| c.with_damping(&self.damping))
            .expect("generated parameters are valid")
    }

    fn undamped(mut self) -> Self {
        self.damping.iter_mut().for_each(|d| *d = 0.0);
        self
    }
}

fn log_uniform() -> impl Strategy<Value = f64> {
    (-1.0f64..1.0).prop_map(|e| 10f64.powf(e))
}

fn params(n: usize) -> impl Strategy<Value = Params> {
    (
        prop::collection::vec(log_uniform(), n),
        prop::collection::vec(log_uniform(), n),
        0.0f64..20.0,
        prop::collection::vec(0.0f64..2.0, n),
    )
        .prop_map(|(masses, lengths, gravity, damping)| Params { masses, lengths, gravity, damping })
}

fn values(n: usize, range: std::ops::Range<f64>) -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec(range, n)
}

/// Spatial coordinates (θ_1..θ_n, φ_1..φ_n) off the singularity.
fn spatial_q(n: usize) -> impl Strategy<Value = Vec<f64>> {
    (prop::collection::vec((0.2f64..PI - 0.2, any::<bool>()), n), values(n, -PI..PI)).prop_map(
        |(theta, phi)| theta.into_iter().map(|(t, neg)| if neg { -t } else { t }).chain(phi).collect(),
    )
}

/// A planar case: parameters, θ, θ̇, torques, pivot acceleration.
fn planar_case(n: usize) -> impl Strategy<Value = (Params, Vec<f64>, Vec<f64>, Vec<f64>, [f64; 2])> {
    (
        params(n),
        values(n, -PI..PI),
        values(n, -5.0..5.0),
        values(n, -10.0..10.0),
        [-20.0f64..20.0, -20.0..20.0],
    )
}

/// A spatial case: parameters, q, q̇, torques, pivot acceleration.
fn spatial_case(n: usize) -> impl Strategy<Value = (Params, Vec<f64>, Vec<f64>, Vec<f64>, [f64; 3])> {
    (
        params(n),
        spatial_q(n),
        values(2 * n, -5.0..5.0),
        values(2 * n, -10.0..10.0),
        [-20.0f64..20.0, -20.0..20.0, -20.0..20.0],
    )
}

fn dv(v: &[f64]) -> DVector<f64> {
    DVector::from_column_slice(v)
}

/// max |a − b| / (max |b| + 1).
fn relative(a: &DVector<f64>, b: &DVector<f64>) -> f64 {
    (a - b).amax() / (b.amax() + 1.0)
}

fn planar_accelerations(
    model: &impl Model<Links = Dyn, Dof = Dyn, Space = U2>,
    q: &[f64],
    qd: &[f64],
    s: &[f64],
    a: [f64; 2],
) -> DVector<f64> {
    let inputs = Inputs { torque: dv(s), pivot_acceleration: Vector2::new(a[0], a[1]) };
    let mut out = DVector::zeros(q.len());
    model.accelerations(&dv(q), &dv(qd), &inputs, &mut out).expect("regular state");
    out
}

fn spatial_accelerations(
    model: &Spatial<Dyn>,
    q: &[f64],
    qd: &[f64],
    s: &[f64],
    a: [f64; 3],
) -> DVector<f64> {
    let inputs = Inputs { torque: dv(s), pivot_acceleration: Vector3::new(a[0], a[1], a[2]) };
    let mut out = DVector::zeros(q.len());
    model.accelerations(&dv(q), &dv(qd), &inputs, &mut out).expect("off the singularity");
    out
}

/// `T = ½ Σ_k m_k |v_k|²` from the masses' velocities `v_k = Σ_{i≤k} l_i u̇_i`, written
/// here apart from the models (no tail masses, no weights `W_ij`): planar
/// `u_i = (sin θ_i, −cos θ_i)`, spatial `u_i = (sin θ_i cos φ_i, sin θ_i sin φ_i, −cos θ_i)`.
fn kinetic_energy_from_velocities(p: &Params, q: &[f64], qd: &[f64]) -> f64 {
    let n = p.masses.len();
    let spatial = q.len() == 2 * n;
    let mut v = Vector3::zeros();
    let mut t = 0.0;
    for i in 0..n {
        let (st, ct) = q[i].sin_cos();
        let u_dot = if spatial {
            let (sp, cp) = q[n + i].sin_cos();
            let (td, pd) = (qd[i], qd[n + i]);
            Vector3::new(ct * cp * td - st * sp * pd, ct * sp * td + st * cp * pd, st * td)
        } else {
            Vector3::new(ct * qd[i], st * qd[i], 0.0)
        };
        v += p.lengths[i] * u_dot;
        t += 0.5 * p.masses[i] * v.norm_squared();
    }
    t
}

/// Checks that `m` is symmetric and positive definite, and that the model's `T` and
/// `½ q̇ᵀ M q̇` both equal the kinetic energy of the masses' velocities
/// ([`kinetic_energy_from_velocities`]).
fn check_mass_matrix(
    m: &DMatrix<f64>,
    p: &Params,
    q: &[f64],
    qd: &[f64],
    kinetic: f64,
) -> Result<(), TestCaseError> {
    let scale = m.amax();
    let asymmetry = (m - m.transpose()).amax() / scale;
    prop_assert!(asymmetry < 1e-14, "asymmetry {asymmetry:e}");
    prop_assert!(m.clone().cholesky().is_some(), "not positive definite: {m}");
    let qd_v = dv(qd);
    let quadratic = 0.5 * qd_v.dot(&(m * &qd_v));
    let independent = kinetic_energy_from_velocities(p, q, qd);
    let tolerance = 1e-12 * (independent.abs() + scale * qd_v.amax().powi(2));
    prop_assert!((quadratic - independent).abs() <= tolerance, "½q̇ᵀMq̇ = {quadratic}, Σ½m v² = {independent}");
    prop_assert!((kinetic - independent).abs() <= tolerance, "model T = {kinetic}, Σ½m v² = {independent}");
    Ok(())
}

/// `q̇ᵀ c(q, q̇) − ½ q̇ᵀ Ṁ q̇` relative to `½ |q̇|ᵀ|Ṁ||q̇| + |q̇|ᵀ|c| + ‖M‖_max ‖q̇‖³_∞`, with
/// `Ṁ = Σ_a ∂M/∂q_a q̇_a` by a central difference of `mass` along q̇ (a step of 1e-5 rad in
/// the largest coordinate). Zero for the velocity terms of any Lagrangian
/// `T = ½ q̇ᵀ M q̇`: `c = Ṁ q̇ − ∂T/∂q` and `q̇ᵀ ∂T/∂q = ½ q̇ᵀ Ṁ q̇`. A Coriolis or
/// centrifugal term with a wrong factor breaks it.
fn power_identity_defect(
    mass: impl Fn(&DVector<f64>) -> DMatrix<f64>,
    q: &[f64],
    qd: &[f64],
    c: &DVector<f64>,
) -> f64 {
    let (q, qd) = (dv(q), dv(qd));
    let rate = qd.amax();
    if rate == 0.0 {
        return if c.amax() == 0.0 { 0.0 } else { f64::INFINITY };
    }
    let h = 1e-5 / rate;
    let m_dot = (mass(&(&q + h * &qd)) - mass(&(&q - h * &qd))) / (2.0 * h);
    let defect = qd.dot(c) - 0.5 * qd.dot(&(&m_dot * &qd));
    let scale = 0.5 * qd.abs().dot(&(m_dot.abs() * qd.abs()))
        + qd.abs().dot(&c.abs())
        + mass(&q).amax() * rate.powi(3);
    defect.abs() / scale
}

/// Largest [`power_identity_defect`] of correct code: the central difference's error,
/// ~1e-10 relative for a step of 1e-5 rad, and its round-off, ~1e-16 / 1e-5.
const POWER_IDENTITY_TOLERANCE: f64 = 1e-7;

/// `M(q)` of `model`.
fn mass_matrix<M: Model<Links = Dyn, Dof = Dyn>>(model: &M, q: &DVector<f64>) -> DMatrix<f64>
where
    nalgebra::DefaultAllocator: pendulum_core::ModelAlloc<Dyn, Dyn, M::Space>,
{
    let mut m = DMatrix::zeros(q.len(), q.len());
    model.mass_matrix(q, &mut m);
    m
}

proptest! {
    #![proptest_config(Config { cases: CASES_CHEAP, ..Config::default() })]

    /// M(q) symmetric positive definite, and M and the model's T both give the kinetic
    /// energy of the masses' velocities computed here from scratch, planar. Catches: a
    /// wrong cos(θ_i − θ_j) entry or tail-mass weight in M or in T (the two share
    /// `Chain::weight`, so only the independent energy can tell), a sign error making M
    /// indefinite at some angles.
    #[test]
    fn planar_mass_matrix_is_spd_and_gives_the_kinetic_energy(case in (1usize..=6).prop_flat_map(planar_case)) {
        let (p, q, qd, _, _) = case;
        let n = p.masses.len();
        let model = Planar::new(p.chain::<Dyn>());
        let mut m = DMatrix::zeros(n, n);
        model.mass_matrix(&dv(&q), &mut m);
        check_mass_matrix(&m, &p, &q, &qd, model.kinetic_energy(&dv(&q), &dv(&qd)))?;
    }

    /// The same for the spatial model off the singularity (its φ block scales with
    /// sin θ_i sin θ_j: a wrong factor shows against the independent energy).
    #[test]
    fn spatial_mass_matrix_is_spd_and_gives_the_kinetic_energy(case in (1usize..=5).prop_flat_map(spatial_case)) {
        let (p, q, qd, _, _) = case;
        let n = p.masses.len();
        let model = Spatial::new(p.chain::<Dyn>());
        let mut m = DMatrix::zeros(2 * n, 2 * n);
        model.mass_matrix(&dv(&q), &mut m);
        check_mass_matrix(&m, &p, &q, &qd, model.kinetic_energy(&dv(&q), &dv(&qd)))?;
    }

    /// The unrolled generated models (`pendulum_macros::model!`) give the generic models'
    /// accelerations and energies. Catches: a codegen slip in one term of one size
    /// (the generated code is a different implementation of every term).
    #[test]
    fn generated_models_agree_with_generic(
        planar in planar_case(4), spatial in spatial_case(3)
    ) {
        let (p, q, qd, s, a) = planar;
        let generic = planar_accelerations(&Planar::new(p.chain::<Dyn>()), &q, &qd, &s, a);
        let generated = Planar4::new(p.chain::<Const<4>>());
        let inputs = Inputs {
            torque: nalgebra::Vector4::from_column_slice(&s),
            pivot_acceleration: Vector2::new(a[0], a[1]),
        };
        let (q4, qd4) = (nalgebra::Vector4::from_column_slice(&q), nalgebra::Vector4::from_column_slice(&qd));
        let mut out = nalgebra::Vector4::zeros();
        generated.accelerations(&q4, &qd4, &inputs, &mut out).unwrap();
        let err = relative(&dv(out.as_slice()), &generic);
        prop_assert!(err < ROUTE_TOLERANCE, "planar: {err:e}");
        let e_gen = generated.energy(&q4, &qd4);
        let e_dyn = Planar::new(p.chain::<Dyn>()).energy(&dv(&q), &dv(&qd));
        prop_assert!((e_gen - e_dyn).abs() <= 1e-12 * (e_dyn.abs() + 1.0), "planar energy {e_gen} vs {e_dyn}");

        let (p, q, qd, s, a) = spatial;
        let generic = spatial_accelerations(&Spatial::new(p.chain::<Dyn>()), &q, &qd, &s, a);
        let generated = Spatial3::new(p.chain::<Const<3>>());
        let inputs = Inputs {
            torque: nalgebra::Vector6::from_column_slice(&s),
            pivot_acceleration: Vector3::new(a[0], a[1], a[2]),
        };
        let mut out = nalgebra::Vector6::zeros();
        generated
            .accelerations(&nalgebra::Vector6::from_column_slice(&q), &nalgebra::Vector6::from_column_slice(&qd), &inputs, &mut out)
            .unwrap();
        let err = relative(&dv(out.as_slice()), &generic);
        prop_assert!(err < ROUTE_TOLERANCE, "spatial: {err:e}");
    }

    /// A spatial chain in the x–z plane (φ = 0, φ̇ = 0, no y forcing) moves as the planar
    /// chain: θ̈ equal, φ̈ = 0. Catches: sign or axis conventions differing between the
    /// two models (θ from −z, φ from +x), a spatial term that does not reduce correctly.
    #[test]
    fn planar_is_spatial_restricted_to_a_vertical_plane(case in (1usize..=5).prop_flat_map(spatial_case)) {
        let (p, q, qd, s, a) = case;
        let n = p.masses.len();
        let pad = |v: &[f64]| -> Vec<f64> { v[..n].iter().copied().chain(std::iter::repeat_n(0.0, n)).collect() };
        let planar = planar_accelerations(&Planar::new(p.chain::<Dyn>()), &q[..n], &qd[..n], &s[..n], [a[0], a[2]]);
        let spatial =
            spatial_accelerations(&Spatial::new(p.chain::<Dyn>()), &pad(&q), &pad(&qd), &pad(&s), [a[0], 0.0, a[2]]);
        let scale = planar.amax() + 1.0;
        let theta = (spatial.rows(0, n) - &planar).amax() / scale;
        let phi = spatial.rows(n, n).amax() / scale;
        prop_assert!(theta < ROUTE_TOLERANCE && phi < ROUTE_TOLERANCE, "θ̈ {theta:e}, φ̈ {phi:e}");
    }

    /// The O(n) routes (rod tensions in angles, `PlanarTension`; unit directions,
    /// `Directions<U2>`) give the dense model's accelerations. Catches: a wrong
    /// tridiagonal coefficient, a tension sign, a damping or drive term missing from one
    /// route.
    #[test]
    fn planar_o_n_routes_equal_the_dense_model(case in (1usize..=8).prop_flat_map(planar_case)) {
        let (p, q, qd, s, a) = case;
        let dense = planar_accelerations(&Planar::new(p.chain::<Dyn>()), &q, &qd, &s, a);
        let tension = planar_accelerations(&PlanarTension::new(p.chain::<Dyn>()), &q, &qd, &s, a);
        let err = relative(&tension, &dense);
        prop_assert!(err < ROUTE_TOLERANCE, "PlanarTension: {err:e}");

        // Directions: no torques, pivot at rest (its drive is part of the system).
        let zero = vec![0.0; q.len()];
        let dense = planar_accelerations(&Planar::new(p.chain::<Dyn>()), &q, &qd, &zero, [0.0, 0.0]);
        let directions = Directions::<U2>::new(p.chain::<Dyn>());
        let x = directions.from_angles(&q, &qd).unwrap();
        let via = directions.angle_accelerations(0.0, &x).unwrap();
        let err = relative(&via, &dense);
        prop_assert!(err < ROUTE_TOLERANCE, "Directions<U2>: {err:e}");
    }

    /// The 3D direction model's accelerations, mapped to spherical angles, equal the
    /// spherical model's off the singularity. Catches: an axis or sign slip in the 3D
    /// O(n) route that the planar comparison cannot see (out-of-plane motion).
    #[test]
    fn spatial_o_n_route_equals_the_dense_model(case in (1usize..=5).prop_flat_map(spatial_case)) {
        let (p, q, qd, _, _) = case;
        let zero = vec![0.0; q.len()];
        let dense = spatial_accelerations(&Spatial::new(p.chain::<Dyn>()), &q, &qd, &zero, [0.0; 3]);
        let directions = Directions::<U3>::new(p.chain::<Dyn>());
        let via = directions.spherical_accelerations(0.0, &q, &qd).unwrap();
        let err = relative(&via, &dense);
        prop_assert!(err < ROUTE_TOLERANCE, "Directions<U3>: {err:e}");
    }

    /// Scaling every mass and every torque by k leaves the accelerations unchanged
    /// (with damping ×k: all forces and inertias are linear in the masses). Catches: a
    /// term with a missing or extra mass factor (e.g. gravity written as g·l instead of
    /// g·m·l), which no test at unit masses can see.
    #[test]
    fn uniform_mass_scaling_leaves_accelerations_unchanged(
        case in (1usize..=6).prop_flat_map(planar_case), k in log_uniform()
    ) {
        let (p, q, qd, s, a) = case;
        let base = planar_accelerations(&Planar::new(p.chain::<Dyn>()), &q, &qd, &s, a);
        let mut scaled = p.clone();
        scaled.masses.iter_mut().for_each(|m| *m *= k);
        scaled.damping.iter_mut().for_each(|d| *d *= k);
        let s_k: Vec<f64> = s.iter().map(|x| x * k).collect();
        let other = planar_accelerations(&Planar::new(scaled.chain::<Dyn>()), &q, &qd, &s_k, a);
        let err = relative(&other, &base);
        prop_assert!(err < ROUTE_TOLERANCE, "{err:e}");
    }

    /// Time rescaling t → t/σ: rates ×σ, g, pivot acceleration and torque/mass ×σ²,
    /// damping ×σ gives accelerations ×σ². Catches: a term of the wrong power in the
    /// rates (θ̇ instead of θ̇², a damping term in θ̇²), gravity or a drive term that does
    /// not scale with g or p̈. Not a wrong coefficient of a quadratic term (a Coriolis
    /// factor 2 scales as σ² too): the power identity below catches that.
    #[test]
    fn time_rescaling_scales_accelerations_by_sigma_squared(
        case in (1usize..=6).prop_flat_map(spatial_case), sigma in 0.3f64..3.0
    ) {
        let (p, q, qd, s, a) = case;
        let base = spatial_accelerations(&Spatial::new(p.chain::<Dyn>()), &q, &qd, &s, a);
        let mut scaled = p.clone();
        scaled.gravity *= sigma * sigma;
        scaled.damping.iter_mut().for_each(|d| *d *= sigma);
        let qd_s: Vec<f64> = qd.iter().map(|x| x * sigma).collect();
        let s_s: Vec<f64> = s.iter().map(|x| x * sigma * sigma).collect();
        let a_s = a.map(|x| x * sigma * sigma);
        let other = spatial_accelerations(&Spatial::new(scaled.chain::<Dyn>()), &q, &qd_s, &s_s, a_s);
        let err = relative(&other, &(base * sigma * sigma));
        prop_assert!(err < ROUTE_TOLERANCE, "{err:e}");
    }

    /// The velocity terms do no work beyond what the changing inertia takes:
    /// `q̇ᵀ c = ½ q̇ᵀ Ṁ q̇` ([`power_identity_defect`]), planar and spatial. Catches: a
    /// Coriolis or centrifugal term with a wrong factor or sign (e.g. the spatial
    /// `2 W l² sin θ cos θ θ̇ φ̇` at half size: `a_halved_coriolis_term_breaks_the_power_identity`).
    #[test]
    fn velocity_terms_satisfy_the_power_identity(
        planar in (1usize..=6).prop_flat_map(planar_case), spatial in (1usize..=5).prop_flat_map(spatial_case)
    ) {
        let (p, q, qd, _, _) = planar;
        let model = Planar::new(p.chain::<Dyn>());
        let mut c = DVector::zeros(q.len());
        model.velocity_terms(&dv(&q), &dv(&qd), &mut c);
        let defect = power_identity_defect(|q| mass_matrix(&model, q), &q, &qd, &c);
        prop_assert!(defect < POWER_IDENTITY_TOLERANCE, "planar: {defect:e}");
        let (p, q, qd, _, _) = spatial;
        let model = Spatial::new(p.chain::<Dyn>());
        let mut c = DVector::zeros(q.len());
        model.velocity_terms(&dv(&q), &dv(&qd), &mut c);
        let defect = power_identity_defect(|q| mass_matrix(&model, q), &q, &qd, &c);
        prop_assert!(defect < POWER_IDENTITY_TOLERANCE, "spatial: {defect:e}");
    }

    /// Rotating the whole spatial chain about the vertical (φ_i → φ_i + α, pivot
    /// acceleration rotated by α) leaves θ̈ and φ̈ unchanged. Catches: φ entering as an
    /// absolute angle where only differences φ_i − φ_j may appear.
    #[test]
    fn rotation_about_the_vertical_leaves_accelerations_unchanged(
        case in (1usize..=5).prop_flat_map(spatial_case), alpha in -PI..PI
    ) {
        let (p, q, qd, s, a) = case;
        let n = p.masses.len();
        let model = Spatial::new(p.chain::<Dyn>());
        let base = spatial_accelerations(&model, &q, &qd, &s, a);
        let q_r: Vec<f64> = q.iter().enumerate().map(|(i, x)| if i >= n { x + alpha } else { *x }).collect();
        let (c, si) = (alpha.cos(), alpha.sin());
        let a_r = [c * a[0] - si * a[1], si * a[0] + c * a[1], a[2]];
        let other = spatial_accelerations(&model, &q_r, &qd, &s, a_r);
        let err = relative(&other, &base);
        prop_assert!(err < ROUTE_TOLERANCE, "{err:e}");
    }

    /// Mirror symmetry of the planar chain: (θ, θ̇, σ, a_x) → −(θ, θ̇, σ, a_x) gives
    /// θ̈ → −θ̈. Catches: an odd term with an even sign (sin ↔ cos slips, |θ̇| instead of θ̇).
    #[test]
    fn planar_mirror_symmetry(case in (1usize..=6).prop_flat_map(planar_case)) {
        let (p, q, qd, s, a) = case;
        let model = Planar::new(p.chain::<Dyn>());
        let base = planar_accelerations(&model, &q, &qd, &s, a);
        let neg = |v: &[f64]| -> Vec<f64> { v.iter().map(|x| -x).collect() };
        let mirrored = planar_accelerations(&model, &neg(&q), &neg(&qd), &neg(&s), [-a[0], a[1]]);
        let err = relative(&(-mirrored), &base);
        prop_assert!(err < ROUTE_TOLERANCE, "{err:e}");
    }

    /// A massless-limit tail link (mass 1e-9 of the chain's smallest) does not change
    /// the accelerations of the links above it beyond O(1e-9). Catches: a tail-mass sum
    /// running over the wrong range (the new link's rod would then weigh on the others).
    #[test]
    fn a_massless_tail_link_does_not_disturb_the_chain(
        case in (1usize..=5).prop_flat_map(planar_case), extra in (-PI..PI, -5.0f64..5.0)
    ) {
        let (p, q, qd, s, a) = case;
        let n = p.masses.len();
        let base = planar_accelerations(&Planar::new(p.chain::<Dyn>()), &q, &qd, &s, a);
        let mut longer = p.clone();
        longer.masses.push(1e-9 * p.masses.iter().copied().fold(f64::INFINITY, f64::min));
        longer.lengths.push(1.0);
        longer.damping.push(0.0);
        let push = |v: &[f64], x: f64| -> Vec<f64> { v.iter().copied().chain([x]).collect() };
        let other = planar_accelerations(
            &Planar::new(longer.chain::<Dyn>()),
            &push(&q, extra.0),
            &push(&qd, extra.1),
            &push(&s, 0.0),
            a,
        );
        let err = relative(&other.rows(0, n).into_owned(), &base);
        prop_assert!(err < 1e-6, "{err:e}");
    }
}

proptest! {
    #![proptest_config(Config { cases: CASES_RUN, ..Config::default() })]

    /// Gauss–Legendre s = 2 in canonical variables, no drive and no damping: 300 steps
    /// keep H within 1e-6 of the energy scale (GL is symplectic: the error is bounded,
    /// not drifting). The step is 2e-3 / (1 + ω) with ω a bound on the fastest rate of
    /// the case, `(√(g/l_min) + max|θ̇|)·√(m_max/m_min)·√(l_max/l_min)`: a light link
    /// on a heavy one whips round far faster than its own θ̇ (a fixed h = 1 ms failed at
    /// 1.5e-4 on masses 0.1 and 8.6, found by this test). Catches: a broken stage solve accepted as converged, a
    /// wrong tableau, a canonical-gradient error (these all drift the energy by far more).
    #[test]
    fn gauss_legendre_conserves_energy_without_drive_or_damping(
        case in (1usize..=4).prop_flat_map(planar_case)
    ) {
        let (p, q, qd, _, _) = case;
        let p = p.undamped();
        let model = Planar::new(p.chain::<Dyn>());
        let system = Canonical::new(model.clone());
        let (q, qd) = (dv(&q), dv(&qd));
        let e0 = model.energy(&q, &qd);
        let potential_scale: f64 =
            p.gravity * p.masses.iter().sum::<f64>() * p.lengths.iter().sum::<f64>();
        let scale = potential_scale + model.kinetic_energy(&q, &qd) + 1e-3;
        let mut solver = GaussLegendre::<_, U2>::new(&system, GaussOptions::default());
        let mut state = State::new(0.0, system.from_velocities(&q, &qd));
        let fold = |v: &[f64], f: fn(f64, f64) -> f64, init: f64| v.iter().copied().fold(init, f);
        let (m_min, m_max) = (fold(&p.masses, f64::min, f64::INFINITY), fold(&p.masses, f64::max, 0.0));
        let (l_min, l_max) = (fold(&p.lengths, f64::min, f64::INFINITY), fold(&p.lengths, f64::max, 0.0));
        let rate = qd.amax();
        let omega = ((p.gravity / l_min).sqrt() + rate) * (m_max / m_min).sqrt() * (l_max / l_min).sqrt();
        let h = 2e-3 / (1.0 + omega);
        let mut worst = 0.0f64;
        for _ in 0..300 {
            solver.step(&system, &mut state, h).unwrap();
            let e = system.energy(state.x()).unwrap();
            worst = worst.max((e - e0).abs() / scale);
        }
        prop_assert!(worst < 1e-6, "relative energy error {worst:e}");
    }
}

/// The power identity is not vacuous: the spatial velocity terms with the Coriolis term
/// `2 W_ii l_i² sin θ_i cos θ_i θ̇_i φ̇_i` of `c_φ_i` at half size (a slip that time
/// rescaling cannot see) break it by far more than its tolerance.
#[test]
fn a_halved_coriolis_term_breaks_the_power_identity() {
    let p = Params { masses: vec![1.3, 0.4], lengths: vec![0.7, 1.9], gravity: 9.81, damping: vec![0.0; 2] };
    let (q, qd) = (vec![0.9, 2.1, 0.3, -1.2], vec![1.5, -0.8, 2.2, 0.6]);
    let model = Spatial::new(p.chain::<Dyn>());
    let mut c = DVector::zeros(4);
    model.velocity_terms(&dv(&q), &dv(&qd), &mut c);
    let correct = power_identity_defect(|q| mass_matrix(&model, q), &q, &qd, &c);
    assert!(correct < POWER_IDENTITY_TOLERANCE, "{correct:e}");
    let n = 2;
    let tail = [p.masses[0] + p.masses[1], p.masses[1]];
    for i in 0..n {
        let w = tail[i] * p.lengths[i] * p.lengths[i];
        c[n + i] -= w * q[i].sin() * q[i].cos() * qd[i] * qd[n + i];
    }
    let wrong = power_identity_defect(|q| mass_matrix(&model, q), &q, &qd, &c);
    assert!(wrong > 1e3 * POWER_IDENTITY_TOLERANCE, "{wrong:e}");
}
