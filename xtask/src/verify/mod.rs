//! `cargo xtask verify`: the models against the sympy reference at many random states.
//!
//! For every reference case and every seeded random state ([`crate::sample`]) the
//! reference's equations are evaluated ([`Case::evaluate`]) and compared, entry by
//! entry, with the generic model (`Planar<Dyn>`/`Spatial<Dyn>`) and the generated
//! fixed-N model of that size ([`models`]): mass matrix, velocity, gravity and
//! pivot terms, generalized forces, kinetic and potential energy, and accelerations.
//! The worst error per case, quantity and model is printed as a table; any error above
//! [`BOUND`] fails the run, naming the case, state, quantity and entry. The O(n) routes
//! (accelerations only) follow in their own table ([`routes`]).

pub mod document;
pub mod models;
pub mod routes;

use std::{fmt, time::Instant};

use anyhow::{Result, bail, ensure};
use nalgebra::{DMatrix, DVector, DVectorView, DefaultAllocator, Dim, DimName, OMatrix, OVector, U1};
use pendulum_core::{Error, Inputs, Model, ModelAlloc};

use crate::{
    case::{Case, Evaluated, Kind, Params, Point, load_all},
    sample,
};
use models::ModelVisitor;

/// Largest error [`verify`](run) accepts, for every entry of every quantity.
///
/// Errors are relative to each entry's absolute scale ([`Scaled`]: the entry evaluated
/// with every sum replaced by the sum of the absolute values of its terms),
/// floored as [`SCALE_FLOOR`] says. Evaluating an entry in floating point, whether as the
/// reference's expanded polynomial or as a model's factored code, errs by about one unit
/// of round-off (1.1e-16) per operation times that scale; the largest entries (planar
/// n = 8, spatial n = 5) are sums of ~200 terms, so correct code stays below ~1e-13,
/// and at most ~3e-12 where the floor applies (measured over 5000 states with the
/// default seed: generated models ≤ 2e-15; generic ≤ 1.0e-13 where the floor does not
/// apply, e.g. planar n = 5 `mass_matrix[4][3]`, and ≤ 1.3e-12 from the floor, spatial
/// n = 1 velocity terms). A wrong or missing term, on the other hand, is a whole term:
/// with masses and lengths drawn over two decades, a term's size relative to its entry's
/// scale is at least ~(0.1/10)² = 1e-4 unless it happens to vanish at that state, which
/// random states over the whole circle do not let happen at all 200 of them (the
/// planted bugs of this module's tests measure 5e-3 to 20). `1e-10` sits two decades
/// above round-off and six below a real discrepancy.
///
/// [`Scaled`]: crate::expr::Scaled
pub const BOUND: f64 = 1e-10;

/// The floor of an entry's scale, as a fraction of its quantity's natural scale.
///
/// An entry's error is `|x_impl − x_ref| / max(s, SCALE_FLOOR · N)`, `s` the entry's
/// absolute scale and `N` the largest scale among the quantity's entries (for the
/// velocity terms and the kinetic energy at least `‖S(M)‖_∞ ‖q̇‖²_∞`, see below).
///
/// The floor exists for terms the reference has cancelled symbolically but an
/// implementation computes numerically. The generic spatial model computes the entry
/// `M[θ_i][φ_i]`, identically zero, as the dot product `J_θ·J_φ` of two link
/// Jacobians, and the velocity terms with `J_θ·u θ̇² = 0` included: each leaves round-off
/// of about 1e-16 times the size of the cancelled terms, which the reference's scale of
/// that entry does not contain (it is 0 for `M[θ_i][φ_i]`). So the floor must satisfy
/// `BOUND · SCALE_FLOOR · N ≫ 1e-16 · N`, i.e. `SCALE_FLOOR ≫ 1e-6`; with 1e-12 every
/// spatial case fails at ~5e-5. The cancelled terms are no larger than the quantity's
/// natural scale `N`: mass-matrix terms are bounded by its largest entry, velocity terms
/// `W_ij u̇_i·u̇_j`-like by `‖S(M)‖_∞ ‖q̇‖²_∞` (`S(M)` the entry scales of `M`), which is
/// not always among the reference's velocity-term scales (one spatial link: the
/// reference's `c_θ = −m l² sin θ cos θ φ̇²` has no `θ̇²` term, the model's round-off does).
/// `1e-4` puts round-off at ≤ ~1e-12 and still flags any wrong term larger than
/// `BOUND · SCALE_FLOOR = 1e-14` of the natural scale.
pub const SCALE_FLOOR: f64 = 1e-4;

/// Default number of random states per case.
pub const DEFAULT_STATES: usize = 200;

/// Default seed: "pendulum" in ASCII.
pub const DEFAULT_SEED: u64 = 0x7065_6e64_756c_756d;

/// Parses `--states`: a positive count.
fn at_least_one(text: &str) -> Result<usize, String> {
    match text.parse::<usize>() {
        Ok(0) => Err("must be at least 1: a verify of no states would prove nothing".into()),
        Ok(n) => Ok(n),
        Err(e) => Err(format!("{e}")),
    }
}

/// Options of `cargo xtask verify`.
#[derive(Debug, Clone, clap::Args)]
pub struct Options {
    /// Random states per case (at least 1: a verify of no states would prove nothing).
    #[arg(long, default_value_t = DEFAULT_STATES, value_parser = at_least_one)]
    pub states: usize,
    /// Seed of the random states; state k of a case depends only on the seed and k.
    #[arg(long, default_value_t = DEFAULT_SEED)]
    pub seed: u64,
    /// Only the cases whose name contains FILTER (e.g. `spatial`, `planar_n3`).
    #[arg(long = "case", value_name = "FILTER")]
    pub case: Option<String>,
}

impl Default for Options {
    fn default() -> Self {
        Self { states: DEFAULT_STATES, seed: DEFAULT_SEED, case: None }
    }
}

/// The quantities compared, in table order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    /// `M(q)`, entry-wise.
    MassMatrix,
    /// `c(q, q̇)`.
    VelocityTerms,
    /// `k(q)`.
    GravityTerms,
    /// `d(q, p̈)`.
    PivotTerms,
    /// `Q(q, q̇, σ)`.
    GeneralizedForces,
    /// `T`.
    KineticEnergy,
    /// `U`.
    PotentialEnergy,
    /// `q̈`, by the backward error ([`acceleration_error`]).
    Accelerations,
}

impl Quantity {
    /// Every quantity, in table order.
    pub const ALL: [Quantity; 8] = [
        Quantity::MassMatrix,
        Quantity::VelocityTerms,
        Quantity::GravityTerms,
        Quantity::PivotTerms,
        Quantity::GeneralizedForces,
        Quantity::KineticEnergy,
        Quantity::PotentialEnergy,
        Quantity::Accelerations,
    ];

    /// The name used in the case files and the table.
    pub fn name(self) -> &'static str {
        match self {
            Quantity::MassMatrix => "mass_matrix",
            Quantity::VelocityTerms => "velocity_terms",
            Quantity::GravityTerms => "gravity_terms",
            Quantity::PivotTerms => "pivot_terms",
            Quantity::GeneralizedForces => "generalized_forces",
            Quantity::KineticEnergy => "kinetic_energy",
            Quantity::PotentialEnergy => "potential_energy",
            Quantity::Accelerations => "accelerations",
        }
    }
}

/// One error measurement: the worst entry of one quantity at one state.
#[derive(Debug, Clone, PartialEq)]
pub struct Measured {
    /// The error: the entry's absolute difference relative to its (floored) scale, or
    /// for accelerations the backward error, as compared with [`BOUND`]; infinite for a
    /// non-finite value or a model error.
    pub error: f64,
    /// Which entry: `[i][j]`, `[i]`, or empty for a scalar.
    pub entry: String,
    /// The implementation's value and the reference's (residual and its scale for
    /// accelerations), or the model's error message.
    pub detail: String,
}

impl Measured {
    fn zero() -> Self {
        Self { error: 0.0, entry: String::new(), detail: String::new() }
    }
}

/// The worst [`Measured`] of one model on one quantity of one case, over the states.
#[derive(Debug, Clone, PartialEq)]
pub struct Worst {
    /// The measurement.
    pub measured: Measured,
    /// The state index (see [`sample::state`]).
    pub state: usize,
}

impl Worst {
    fn update(slot: &mut Option<Worst>, measured: Measured, state: usize) {
        if slot.as_ref().is_none_or(|w| worse(measured.error, w.measured.error)) {
            *slot = Some(Worst { measured, state });
        }
    }

    /// Whether the error is within [`BOUND`] (NaN is not).
    pub fn ok(&self) -> bool {
        self.measured.error <= BOUND
    }
}

/// Which implementation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Implementation {
    /// The fixed-N model of `pendulum_macros::model!`.
    Generated,
    /// `Planar<Dyn>` or `Spatial<Dyn>`.
    Generic,
}

impl fmt::Display for Implementation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Implementation::Generated => "generated",
            Implementation::Generic => "generic",
        })
    }
}

/// One result per implementation of a case's size.
#[derive(Debug, Clone, PartialEq)]
pub struct PerModel<T> {
    /// The generated model's (`None` if there is none of that size).
    pub generated: Option<T>,
    /// The generic model's.
    pub generic: T,
}

impl<T> PerModel<T> {
    /// Every present result with its implementation, generated first.
    pub fn iter(&self) -> impl Iterator<Item = (Implementation, &T)> {
        let generated = self.generated.iter().map(|t| (Implementation::Generated, t));
        generated.chain([(Implementation::Generic, &self.generic)])
    }
}

/// One table row: a case's quantity, worst error per implementation.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// Case name.
    pub case: String,
    /// What is compared.
    pub quantity: Quantity,
    /// The worst error of each implementation.
    pub worst: PerModel<Worst>,
}

impl Row {
    /// Whether every present implementation is within [`BOUND`].
    pub fn ok(&self) -> bool {
        self.worst.iter().all(|(_, w)| w.ok())
    }
}

/// The spatial singularity check of one case: at `θ_1 = 0` (and `π`), accelerations
/// must fail with [`Error::SingularAngle`] for link 1.
#[derive(Debug, Clone, PartialEq)]
pub struct Singularity {
    /// Case name.
    pub case: String,
    /// Per implementation: `Ok` if it reported the singularity, `Err` saying what it
    /// did instead.
    pub reported: PerModel<Reported>,
}

impl Singularity {
    /// Whether every present implementation reported the singularity.
    pub fn ok(&self) -> bool {
        self.reported.iter().all(|(_, r)| r.is_ok())
    }
}

/// `Ok` if a model reported the singularity, `Err` saying what it did instead.
pub type Reported = Result<(), String>;

/// Everything [`verify_cases`] found.
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    /// The seed of the random states.
    pub seed: u64,
    /// One row per case and quantity.
    pub rows: Vec<Row>,
    /// One per spatial case.
    pub singularities: Vec<Singularity>,
    /// Kind and links per case name, to regenerate a state for a failure message.
    cases: Vec<(String, Kind, usize)>,
}

/// A failing measurement, with what is needed to reproduce it.
#[derive(Debug, Clone, PartialEq)]
pub struct Failure {
    /// Case name.
    pub case: String,
    /// Which implementation failed.
    pub implementation: Implementation,
    /// Which quantity.
    pub quantity: Quantity,
    /// The worst measurement and its state.
    pub worst: Worst,
    /// That state's parameters.
    pub params: Params,
    /// That state's point.
    pub point: Point,
}

impl fmt::Display for Failure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let m = &self.worst.measured;
        writeln!(
            f,
            "{} {}: {}{}: error {:.3e} > {BOUND:e} at state {}",
            self.case,
            self.implementation,
            self.quantity.name(),
            m.entry,
            m.error,
            self.worst.state
        )?;
        writeln!(f, "    {}", m.detail)?;
        let p = &self.params;
        writeln!(
            f,
            "    masses {:?}, lengths {:?}, g {:?}, damping {:?}",
            p.masses, p.lengths, p.gravity, p.damping
        )?;
        let x = &self.point;
        write!(
            f,
            "    q {:?}, qd {:?}, torque {:?}, pivot_acceleration {:?}",
            x.q, x.qd, x.torque, x.pivot_acceleration
        )
    }
}

impl Report {
    /// Whether every row and singularity check passed.
    pub fn ok(&self) -> bool {
        self.rows.iter().all(Row::ok) && self.singularities.iter().all(Singularity::ok)
    }

    /// Every failing (case, implementation, quantity), worst error first, with its
    /// state's values.
    pub fn failures(&self) -> Vec<Failure> {
        let mut failures = Vec::new();
        for row in &self.rows {
            for (implementation, worst) in row.worst.iter().filter(|(_, w)| !w.ok()) {
                let (_, kind, links) = self
                    .cases
                    .iter()
                    .find(|(name, ..)| *name == row.case)
                    .expect("every row's case is listed");
                let (params, point) = sample::state(self.seed, *kind, *links, worst.state);
                failures.push(Failure {
                    case: row.case.clone(),
                    implementation,
                    quantity: row.quantity,
                    worst: worst.clone(),
                    params,
                    point,
                });
            }
        }
        failures.sort_by(|a, b| b.worst.measured.error.total_cmp(&a.worst.measured.error));
        failures
    }

    /// The table: case | quantity | worst generated | worst generic | verdict.
    pub fn table(&self) -> String {
        let error = |w: &Worst| match w.measured.error {
            0.0 => "0".to_owned(),
            e => format!("{e:.1e}"),
        };
        let singular = |r: &Reported| match r {
            Ok(()) => "SingularAngle".to_owned(),
            Err(_) => "WRONG".to_owned(),
        };
        let verdict = |ok: bool| if ok { "ok" } else { "FAIL" }.to_owned();
        let mut lines = vec![[
            "case".to_owned(),
            "quantity".to_owned(),
            "generated".to_owned(),
            "generic".to_owned(),
            "verdict".to_owned(),
        ]];
        for row in &self.rows {
            lines.push([
                row.case.clone(),
                row.quantity.name().to_owned(),
                row.worst.generated.as_ref().map_or("n/a".to_owned(), error),
                error(&row.worst.generic),
                verdict(row.ok()),
            ]);
            if row.quantity == Quantity::Accelerations
                && let Some(s) = self.singularities.iter().find(|s| s.case == row.case)
            {
                lines.push([
                    s.case.clone(),
                    "singular θ1 = 0, π".to_owned(),
                    s.reported.generated.as_ref().map_or("n/a".to_owned(), singular),
                    singular(&s.reported.generic),
                    verdict(s.ok()),
                ]);
            }
        }
        let mut widths = [0; 5];
        for line in &lines {
            for (w, cell) in widths.iter_mut().zip(line) {
                *w = (*w).max(cell.chars().count());
            }
        }
        let mut out = String::new();
        for (k, line) in lines.iter().enumerate() {
            let cells: Vec<String> = line
                .iter()
                .zip(widths)
                .enumerate()
                .map(|(c, (cell, w))| {
                    let pad = w - cell.chars().count();
                    // Numbers right-aligned, names left-aligned.
                    if (2..4).contains(&c) {
                        format!("{}{cell}", " ".repeat(pad))
                    } else {
                        format!("{cell}{}", " ".repeat(pad))
                    }
                })
                .collect();
            out += cells.join(" | ").trim_end();
            out.push('\n');
            if k == 0 {
                out += &widths.iter().map(|&w| "-".repeat(w)).collect::<Vec<_>>().join("-|-");
                out.push('\n');
            }
        }
        out
    }
}

/// The reference at one state: values, entry scales, floors, and the right-hand side.
pub(crate) struct Reference {
    pub(crate) values: Evaluated,
    pub(crate) scales: Evaluated,
    /// The scale floor of each entry-wise quantity, in [`Quantity::ALL`] order.
    floors: [f64; 7],
    /// `Q − c − k − d`.
    pub(crate) rhs: DVector<f64>,
    /// Its scale `S(Q) + S(c) + S(k) + S(d)`.
    pub(crate) rhs_scale: DVector<f64>,
}

impl Reference {
    pub(crate) fn new(case: &Case, params: &Params, point: &Point) -> Self {
        let (values, scales) = case.evaluate_with_scales(params, point);
        let rate = DVectorView::from_slice(&point.qd, point.qd.len()).amax();
        // Terms of the form W u̇·u̇ are bounded by ‖S(M)‖_∞ ‖q̇‖²_∞ (SCALE_FLOOR).
        let quadratic = row_sum_norm(&scales.mass_matrix) * rate * rate;
        let floors = [
            scales.mass_matrix.amax(),
            scales.velocity_terms.amax().max(quadratic),
            scales.gravity_terms.amax(),
            scales.pivot_terms.amax(),
            scales.generalized_forces.amax(),
            scales.kinetic_energy.max(quadratic),
            scales.potential_energy,
        ]
        .map(|n| SCALE_FLOOR * n);
        let rhs_scale =
            &scales.generalized_forces + &scales.velocity_terms + &scales.gravity_terms + &scales.pivot_terms;
        Reference { rhs: values.rhs(), values, scales, floors, rhs_scale }
    }
}

/// Whether `a` is worse than `b`: larger, or NaN.
fn worse(a: f64, b: f64) -> bool {
    a > b || a.is_nan()
}

/// `difference / scale`: 0 for no difference, ∞ for a non-finite difference or a zero
/// scale.
fn ratio(difference: f64, scale: f64) -> f64 {
    if difference == 0.0 {
        0.0
    } else if difference.is_finite() && scale > 0.0 {
        difference / scale
    } else {
        f64::INFINITY
    }
}

/// `‖A‖_∞`, the largest row sum of absolute values.
fn row_sum_norm(a: &DMatrix<f64>) -> f64 {
    a.row_iter().map(|r| r.iter().map(|x| x.abs()).sum::<f64>()).fold(0.0, f64::max)
}

/// The error of `got` against `want`, entry-wise: `|got − want| / max(scale, floor)`
/// (infinite for a non-finite difference); the worst entry's index and error.
fn entry_errors(got: &[f64], want: &[f64], scales: &[f64], floor: f64) -> (usize, f64) {
    let mut worst = (0, 0.0);
    for (i, ((g, w), s)) in got.iter().zip(want).zip(scales).enumerate() {
        let error = ratio((g - w).abs(), s.max(floor));
        if worse(error, worst.1) {
            worst = (i, error);
        }
    }
    worst
}

/// The backward error of accelerations `a` for the reference system `M a = rhs`,
///
/// ```text
/// ‖M a − rhs‖_∞ / (‖S(M)‖_∞ ‖a‖_∞ + ‖S(rhs)‖_∞)
/// ```
///
/// with `S(·)` the entry scales; returns the row of the largest residual, the error and
/// that residual.
///
/// This is the smallest relative perturbation of `M` and `rhs` (relative to their
/// round-off scales) for which `a` is exact (Rigal–Gaches). Comparing `a` with the
/// reference's own solution instead (a forward error) would measure the conditioning of
/// `M` as much as the model: with masses and lengths over two decades, and spatial
/// `|sin θ|` down to 1e-3, `cond₂(M)` reaches ~1e6 planar and ~1e8–1e9 spatial at 200
/// states, so two correct solvers may differ by 1e-8 relative and more. The backward error of a correct solve is a few units of
/// round-off whatever the conditioning, while a wrong term in the model's right-hand
/// side or a wrong solve leaves a residual of the size of that term.
///
/// The scales `S(M)`, `S(rhs) = S(Q) + S(c) + S(k) + S(d)` stand where the plain norms
/// `‖M‖`, `‖rhs‖` would: `rhs = Q − c − k − d` often cancels, and a model's right-hand
/// side errs by round-off of its terms, not of their small difference (with `‖rhs‖`,
/// one planar link already reaches 4e-14 at 200 states, and the tail grows with more).
pub fn acceleration_error(
    mass_scale: &DMatrix<f64>,
    rhs_scale: &DVector<f64>,
    mass_matrix: &DMatrix<f64>,
    rhs: &DVector<f64>,
    a: &DVector<f64>,
) -> (usize, f64, f64) {
    let residual = mass_matrix * a - rhs;
    let scale = row_sum_norm(mass_scale) * a.amax() + rhs_scale.amax();
    let (row, largest) = residual
        .iter()
        .map(|r| r.abs())
        .enumerate()
        .fold((0, 0.0), |(i, m), (j, r)| if worse(r, m) { (j, r) } else { (i, m) });
    (row, ratio(largest, scale), largest)
}

/// A [`Point`] as the vectors of one model.
struct ModelPoint<M: Model>
where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>,
{
    q: OVector<f64, M::Dof>,
    qd: OVector<f64, M::Dof>,
    inputs: Inputs<M::Dof, M::Space>,
}

impl<M: Model> ModelPoint<M>
where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>,
{
    /// `point`'s coordinates, rates and inputs for `model`.
    fn new(model: &M, point: &Point) -> Self {
        let vector =
            |v: &[f64]| OVector::<f64, M::Dof>::from_iterator_generic(model.dof(), U1, v.iter().copied());
        let pivot_acceleration = OVector::<f64, M::Space>::from_iterator_generic(
            M::Space::name(),
            U1,
            point.pivot_acceleration.iter().copied(),
        );
        ModelPoint {
            q: vector(&point.q),
            qd: vector(&point.qd),
            inputs: Inputs { torque: vector(&point.torque), pivot_acceleration },
        }
    }
}

/// Compares one model with the reference at one state: the worst entry of every
/// quantity, in [`Quantity::ALL`] order.
///
/// Outputs are filled with NaN before each call, so an entry a model fails to write
/// shows up as an infinite error. Errors if the model's dimensions do not fit the case.
fn check_model<M: Model>(
    case: &Case,
    model: &M,
    point: &Point,
    reference: &Reference,
) -> Result<Vec<Measured>>
where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>,
{
    let dof = model.dof();
    let n = case.dof();
    if dof.value() != n || M::Space::dim() != case.kind.space() {
        bail!(
            "{}: the model has {} coordinates in {} dimensions, the case {n} in {}",
            case.name,
            dof.value(),
            M::Space::dim(),
            case.kind.space()
        );
    }
    let nan_vector = || OVector::<f64, M::Dof>::from_element_generic(dof, U1, f64::NAN);
    let ModelPoint { q, qd, inputs } = ModelPoint::new(model, point);
    let (values, scales) = (&reference.values, &reference.scales);

    let measure =
        |quantity: Quantity, got: &[f64], want: &[f64], scale: &[f64], entry: &dyn Fn(usize) -> String| {
            let floor = reference.floors[quantity as usize];
            let (i, error) = entry_errors(got, want, scale, floor);
            if error == 0.0 {
                return Measured::zero();
            }
            Measured {
                error,
                entry: entry(i),
                detail: format!(
                    "implementation {:?}, reference {:?}, scale {:.3e}, floor {floor:.3e}",
                    got[i], want[i], scale[i]
                ),
            }
        };
    let index = |i: usize| format!("[{i}]");
    let mut out = Vec::with_capacity(Quantity::ALL.len());

    let mut mass = OMatrix::<f64, M::Dof, M::Dof>::from_element_generic(dof, dof, f64::NAN);
    model.mass_matrix(&q, &mut mass);
    // Both are column-major.
    out.push(measure(
        Quantity::MassMatrix,
        mass.as_slice(),
        values.mass_matrix.as_slice(),
        scales.mass_matrix.as_slice(),
        &|k| format!("[{}][{}]", k % n, k / n),
    ));

    let mut v = nan_vector();
    model.velocity_terms(&q, &qd, &mut v);
    out.push(measure(
        Quantity::VelocityTerms,
        v.as_slice(),
        values.velocity_terms.as_slice(),
        scales.velocity_terms.as_slice(),
        &index,
    ));

    let mut v = nan_vector();
    model.gravity_terms(&q, &mut v);
    out.push(measure(
        Quantity::GravityTerms,
        v.as_slice(),
        values.gravity_terms.as_slice(),
        scales.gravity_terms.as_slice(),
        &index,
    ));

    let mut v = nan_vector();
    model.pivot_terms(&q, &inputs.pivot_acceleration, &mut v);
    out.push(measure(
        Quantity::PivotTerms,
        v.as_slice(),
        values.pivot_terms.as_slice(),
        scales.pivot_terms.as_slice(),
        &index,
    ));

    let mut v = nan_vector();
    model.generalized_forces(&q, &qd, &inputs.torque, &mut v);
    out.push(measure(
        Quantity::GeneralizedForces,
        v.as_slice(),
        values.generalized_forces.as_slice(),
        scales.generalized_forces.as_slice(),
        &index,
    ));

    let scalar = |_| String::new();
    let t = model.kinetic_energy(&q, &qd);
    out.push(measure(
        Quantity::KineticEnergy,
        &[t],
        &[values.kinetic_energy],
        &[scales.kinetic_energy],
        &scalar,
    ));
    let u = model.potential_energy(&q);
    out.push(measure(
        Quantity::PotentialEnergy,
        &[u],
        &[values.potential_energy],
        &[scales.potential_energy],
        &scalar,
    ));

    let mut a = nan_vector();
    out.push(match model.accelerations(&q, &qd, &inputs, &mut a) {
        Err(e) => {
            Measured { error: f64::INFINITY, entry: String::new(), detail: format!("the model failed: {e}") }
        }
        Ok(()) => {
            let a = DVector::from_column_slice(a.as_slice());
            let (row, error, residual) = acceleration_error(
                &scales.mass_matrix,
                &reference.rhs_scale,
                &values.mass_matrix,
                &reference.rhs,
                &a,
            );
            if error == 0.0 {
                Measured::zero()
            } else {
                Measured {
                    error,
                    entry: format!(" (residual row {row})"),
                    detail: format!(
                        "residual {residual:.3e} of M_ref a - rhs_ref; implementation a {:?}, reference a {}",
                        a.as_slice(),
                        values
                            .mass_matrix
                            .clone()
                            .lu()
                            .solve(&reference.rhs)
                            .map_or_else(|| "(singular)".to_owned(), |r| format!("{:?}", r.as_slice()))
                    ),
                }
            }
        }
    });
    Ok(out)
}

/// [`check_model`] as a [`ModelVisitor`].
struct Check<'a> {
    case: &'a Case,
    point: &'a Point,
    reference: &'a Reference,
}

impl ModelVisitor for Check<'_> {
    type Output = Result<Vec<Measured>>;

    fn visit<M: Model>(self, model: &M) -> Self::Output
    where
        DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>,
    {
        check_model(self.case, model, self.point, self.reference)
    }
}

/// Whether accelerations at `point` fail with [`Error::SingularAngle`] for link 1.
struct CheckSingular<'a> {
    point: &'a Point,
}

impl ModelVisitor for CheckSingular<'_> {
    type Output = Reported;

    fn visit<M: Model>(self, model: &M) -> Self::Output
    where
        DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>,
    {
        let ModelPoint { q, qd, inputs } = ModelPoint::new(model, self.point);
        let mut a = q.clone();
        match model.accelerations(&q, &qd, &inputs, &mut a) {
            Err(Error::SingularAngle { link: 1, .. }) => Ok(()),
            Err(e) => {
                Err(format!("at theta_1 = {}: expected SingularAngle for link 1, got: {e}", self.point.q[0]))
            }
            Ok(()) => Err(format!(
                "at theta_1 = {}: expected SingularAngle for link 1, got accelerations {:?}",
                self.point.q[0],
                a.as_slice()
            )),
        }
    }
}

/// Runs one case: every state, both implementations.
fn verify_case(case: &Case, states: usize, seed: u64) -> Result<(Vec<Row>, Option<Singularity>)> {
    let mut generic: Vec<Option<Worst>> = vec![None; Quantity::ALL.len()];
    let mut generated: Vec<Option<Worst>> = vec![None; Quantity::ALL.len()];
    for state in 0..states {
        let (params, point) = sample::state(seed, case.kind, case.links, state);
        let reference = Reference::new(case, &params, &point);
        let check = || Check { case, point: &point, reference: &reference };
        let measured = models::with_generic(case.kind, &params, check())??;
        for (slot, m) in generic.iter_mut().zip(measured) {
            Worst::update(slot, m, state);
        }
        if let Some(measured) = models::with_generated(case.kind, case.links, &params, check())? {
            for (slot, m) in generated.iter_mut().zip(measured?) {
                Worst::update(slot, m, state);
            }
        }
    }
    // Every state updates every generic slot, and every generated slot iff the case has a
    // generated model: with at least one state, the slots are `Some` exactly then.
    let rows = Quantity::ALL
        .iter()
        .zip(generic.into_iter().zip(generated))
        .map(|(&quantity, (generic, generated))| Row {
            case: case.name.clone(),
            quantity,
            worst: PerModel { generic: generic.expect("at least one state"), generated },
        })
        .collect();

    let singularity = match case.kind {
        Kind::Planar => None,
        Kind::Spatial => {
            let (params, mut point) = sample::state(seed, case.kind, case.links, 0);
            let mut run = |theta: f64| -> Result<(Reported, Option<Reported>)> {
                point.q[0] = theta;
                let generic = models::with_generic(case.kind, &params, CheckSingular { point: &point })?;
                let generated =
                    models::with_generated(case.kind, case.links, &params, CheckSingular { point: &point })?;
                Ok((generic, generated))
            };
            let (generic_zero, generated_zero) = run(0.0)?;
            let (generic_pi, generated_pi) = run(std::f64::consts::PI)?;
            Some(Singularity {
                case: case.name.clone(),
                reported: PerModel {
                    generic: generic_zero.and(generic_pi),
                    generated: generated_zero.zip(generated_pi).map(|(z, p)| z.and(p)),
                },
            })
        }
    };
    Ok((rows, singularity))
}

/// Verifies `cases` at `states` random states from `seed`.
///
/// Errors only when `states` is 0 or a model cannot be built or does not fit its case;
/// mismatches are in the [`Report`].
pub fn verify_cases(cases: &[Case], states: usize, seed: u64) -> Result<Report> {
    ensure!(states >= 1, "verify needs at least one state: a verify of no states would prove nothing");
    let mut report = Report {
        seed,
        rows: Vec::new(),
        singularities: Vec::new(),
        cases: cases.iter().map(|c| (c.name.clone(), c.kind, c.links)).collect(),
    };
    for case in cases {
        let (rows, singularity) = verify_case(case, states, seed)?;
        report.rows.extend(rows);
        report.singularities.extend(singularity);
    }
    Ok(report)
}

/// Loads the committed reference cases (those whose name contains `filter`, if given)
/// and verifies them: what `cargo xtask verify` and the `fast_verify` test run.
pub fn verify_all(states: usize, seed: u64, filter: Option<&str>) -> Result<(Vec<Case>, Report)> {
    let mut cases = load_all(&crate::cases_dir())?;
    if let Some(filter) = filter {
        cases.retain(|c| c.name.contains(filter));
        if cases.is_empty() {
            bail!("no reference case name contains {filter:?}");
        }
    }
    let report = verify_cases(&cases, states, seed)?;
    Ok((cases, report))
}

/// `cargo xtask verify`: prints the table and the document section; errors on any
/// failure, describing the worst.
pub fn run(options: &Options) -> Result<()> {
    let start = Instant::now();
    let (cases, report) = verify_all(options.states, options.seed, options.case.as_deref())?;
    println!(
        "verify: {} reference cases x {} random states (seed {:#x}); bound {BOUND:e} on the error \
         relative to each entry's absolute scale, backward error for accelerations",
        cases.len(),
        options.states,
        options.seed
    );
    println!();
    print!("{}", report.table());
    let failures = report.failures();
    for failure in &failures {
        println!("\nFAIL {failure}");
    }
    for s in &report.singularities {
        for (implementation, result) in s.reported.iter() {
            if let Err(message) = result {
                println!("\nFAIL {} {implementation}: spatial singularity: {message}", s.case);
            }
        }
    }
    println!("\nmodels checked in {:.2} s", start.elapsed().as_secs_f64());

    // The O(n) routes (tension solve), accelerations only, at the same states.
    println!();
    let routes =
        routes::verify_cases(&cases, options.states, options.seed).and_then(|rows| routes::report(&rows));

    // The seed document's printed equations against the reference: prints its own
    // table, errors when reference/ERRATA.md no longer matches what it finds.
    println!();
    let document = document::run(&cases, options.states, options.seed);

    if let Some(worst) = failures.first() {
        bail!(
            "verify failed: {} of {} comparisons above {BOUND:e}; the worst:\n{worst}",
            failures.len(),
            report.rows.len() * 2
        );
    }
    if !report.ok() {
        bail!("verify failed: a spatial model did not report the singularity at theta_1 = 0 or pi");
    }
    routes?;
    document
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Dyn;
    use pendulum_core::{Chain, Planar, Spatial};
    use std::path::PathBuf;

    fn fixtures() -> Vec<Case> {
        load_all(&PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests").join("fixtures")).unwrap()
    }

    /// The project's main check on the committed reference, at fewer states.
    #[test]
    fn fast_verify() {
        let (cases, report) = verify_all(20, DEFAULT_SEED, None).unwrap();
        let names: Vec<&str> = cases.iter().map(|c| c.name.as_str()).collect();
        let expected: Vec<String> =
            (1..=8).map(|n| format!("planar_n{n}")).chain((1..=5).map(|n| format!("spatial_n{n}"))).collect();
        assert_eq!(names, expected, "the committed reference cases");
        // Every case has its generated model: a case without one would pass unnoticed.
        for row in &report.rows {
            assert!(row.worst.generated.is_some(), "{}: no generated model in models.rs", row.case);
        }
        for s in &report.singularities {
            assert!(s.reported.generated.is_some(), "{}: no generated model in models.rs", s.case);
        }
        let failures = report.failures();
        assert!(
            report.ok(),
            "\n{}\n{}",
            report.table(),
            failures.iter().map(|f| f.to_string() + "\n").collect::<String>()
        );
    }

    #[test]
    fn generic_models_agree_with_the_hand_written_fixtures() {
        let report = verify_cases(&fixtures(), 30, 1).unwrap();
        assert!(report.ok(), "\n{}", report.table());
        assert_eq!(report.rows.len(), 3 * Quantity::ALL.len());
        assert_eq!(report.singularities.len(), 1);
        let worst = report.rows.iter().map(|r| r.worst.generic.measured.error).fold(0.0, f64::max);
        assert!(worst < 1e-2 * BOUND, "round-off only: {worst:e}");
    }

    #[test]
    fn the_table_is_aligned() {
        let table = verify_cases(&fixtures(), 2, 1).unwrap().table();
        let bars: Vec<Vec<usize>> = table
            .lines()
            .map(|l| {
                l.char_indices().filter(|&(_, c)| c == '|').map(|(i, _)| l[..i].chars().count()).collect()
            })
            .collect();
        assert!(bars.iter().all(|b| b.len() == 4 && *b == bars[0]), "{table}");
        assert!(table.contains("spatial_n1 | singular θ1 = 0, π |"), "{table}");
    }

    /// Bugs planted into a correct model, each of a kind the document or a hurried
    /// implementation could make.
    #[derive(Debug, Clone, Copy, PartialEq)]
    enum Bug {
        /// Planar velocity terms with the lower triangle's sign flipped (eq 23 as printed).
        DocumentVelocitySign,
        /// Gravity from the link's own mass instead of the tail mass.
        OwnMassGravity,
        /// Damping forgotten.
        NoDamping,
        /// Spatial φ damping without its `sin² θ`.
        PhiDampingWithoutSin2,
        /// Kinetic energy with a ½ on the cross terms too.
        HalfCrossTerms,
        /// Accelerations that forget the pivot terms (all building blocks correct).
        AccelerationsWithoutPivot,
        /// Mass matrix diagonal from the link's own mass instead of the tail mass.
        OwnMassDiagonal,
        /// Planar velocity terms weighted by `M_min(i,j)` instead of `M_max(i,j)`.
        MinTailMass,
        /// No bug at all.
        None,
    }

    /// A correct model with one [`Bug`].
    struct Mutant<M> {
        inner: M,
        bug: Bug,
    }

    impl<M> Mutant<M>
    where
        M: Model<Links = Dyn, Dof = Dyn>,
        DefaultAllocator: ModelAlloc<Dyn, Dyn, M::Space>,
    {
        fn weight(&self, i: usize, j: usize) -> f64 {
            let c = self.inner.chain();
            c.tail_masses()[i.max(j)] * c.lengths()[i] * c.lengths()[j]
        }
    }

    impl<M> Model for Mutant<M>
    where
        M: Model<Links = Dyn, Dof = Dyn>,
        DefaultAllocator: ModelAlloc<Dyn, Dyn, M::Space>,
    {
        type Links = Dyn;
        type Dof = Dyn;
        type Space = M::Space;

        fn chain(&self) -> &Chain<Dyn> {
            self.inner.chain()
        }
        fn dof(&self) -> Dyn {
            self.inner.dof()
        }
        fn mass_matrix(&self, q: &DVector<f64>, out: &mut DMatrix<f64>) {
            self.inner.mass_matrix(q, out);
            if self.bug == Bug::OwnMassDiagonal {
                let c = self.chain();
                for i in 0..c.links() {
                    out[(i, i)] *= c.masses()[i] / c.tail_masses()[i];
                }
            }
        }
        fn velocity_terms(&self, q: &DVector<f64>, qd: &DVector<f64>, out: &mut DVector<f64>) {
            self.inner.velocity_terms(q, qd, out);
            if self.bug == Bug::DocumentVelocitySign {
                for i in 0..out.len() {
                    for j in 0..i {
                        out[i] -= 2.0 * self.weight(i, j) * (q[i] - q[j]).sin() * qd[j] * qd[j];
                    }
                }
            }
            if self.bug == Bug::MinTailMass {
                let c = self.chain();
                for i in 0..out.len() {
                    for j in 0..out.len() {
                        let (tail, l) = (c.tail_masses(), c.lengths());
                        let change = (tail[i.min(j)] - tail[i.max(j)]) * l[i] * l[j];
                        out[i] += change * (q[i] - q[j]).sin() * qd[j] * qd[j];
                    }
                }
            }
        }
        fn gravity_terms(&self, q: &DVector<f64>, out: &mut DVector<f64>) {
            self.inner.gravity_terms(q, out);
            if self.bug == Bug::OwnMassGravity {
                let c = self.chain();
                for i in 0..c.links() {
                    out[i] *= c.masses()[i] / c.tail_masses()[i];
                }
            }
        }
        fn pivot_terms(&self, q: &DVector<f64>, a: &OVector<f64, M::Space>, out: &mut DVector<f64>) {
            self.inner.pivot_terms(q, a, out);
        }
        fn generalized_forces(
            &self,
            q: &DVector<f64>,
            qd: &DVector<f64>,
            torque: &DVector<f64>,
            out: &mut DVector<f64>,
        ) {
            self.inner.generalized_forces(q, qd, torque, out);
            let n = self.chain().links();
            match self.bug {
                Bug::NoDamping => out.copy_from(torque),
                Bug::PhiDampingWithoutSin2 => {
                    for i in 0..n {
                        out[n + i] = torque[n + i] - self.chain().damping()[i] * qd[n + i];
                    }
                }
                _ => {}
            }
        }
        fn kinetic_energy(&self, q: &DVector<f64>, qd: &DVector<f64>) -> f64 {
            let t = self.inner.kinetic_energy(q, qd);
            if self.bug != Bug::HalfCrossTerms {
                return t;
            }
            let n = q.len();
            let cross: f64 = (0..n)
                .flat_map(|i| (0..i).map(move |j| (i, j)))
                .map(|(i, j)| self.weight(i, j) * (q[i] - q[j]).cos() * qd[i] * qd[j])
                .sum();
            t - 0.5 * cross
        }
        fn potential_energy(&self, q: &DVector<f64>) -> f64 {
            self.inner.potential_energy(q)
        }
        fn check_configuration(&self, q: &DVector<f64>) -> pendulum_core::Result<()> {
            self.inner.check_configuration(q)
        }
        fn accelerations(
            &self,
            q: &DVector<f64>,
            qd: &DVector<f64>,
            inputs: &Inputs<Dyn, M::Space>,
            out: &mut DVector<f64>,
        ) -> pendulum_core::Result<()> {
            let mut inputs = inputs.clone();
            if self.bug == Bug::AccelerationsWithoutPivot {
                inputs.pivot_acceleration.fill(0.0);
            }
            // The default method, on this model's (possibly buggy) building blocks.
            let dof = self.dof();
            let mut mass = DMatrix::zeros(dof.value(), dof.value());
            self.mass_matrix(q, &mut mass);
            let mut tmp = DVector::zeros(dof.value());
            self.generalized_forces(q, qd, &inputs.torque, out);
            self.velocity_terms(q, qd, &mut tmp);
            *out -= &tmp;
            self.gravity_terms(q, &mut tmp);
            *out -= &tmp;
            self.pivot_terms(q, &inputs.pivot_acceleration, &mut tmp);
            *out -= &tmp;
            self.check_configuration(q)?;
            mass.cholesky().ok_or(Error::NotPositiveDefinite)?.solve_mut(out);
            Ok(())
        }
    }

    /// The worst error of a mutant of the generic model on each quantity of `case`.
    fn mutant_errors(case: &Case, bug: Bug, states: usize) -> Vec<f64> {
        let mut worst = vec![0.0f64; Quantity::ALL.len()];
        for state in 0..states {
            let (params, point) = sample::state(DEFAULT_SEED, case.kind, case.links, state);
            let reference = Reference::new(case, &params, &point);
            let chain = models::chain::<Dyn>(&params).unwrap();
            let measured = match case.kind {
                Kind::Planar => {
                    check_model(case, &Mutant { inner: Planar::new(chain), bug }, &point, &reference)
                }
                Kind::Spatial => {
                    check_model(case, &Mutant { inner: Spatial::new(chain), bug }, &point, &reference)
                }
            }
            .unwrap();
            for (w, m) in worst.iter_mut().zip(measured) {
                *w = w.max(m.error);
            }
        }
        worst
    }

    #[test]
    fn planted_bugs_fail_the_bound_where_they_are() {
        use Quantity::*;
        let cases = fixtures();
        let [planar1, planar2, spatial1] = [&cases[0], &cases[1], &cases[2]];
        let committed = load_all(&crate::cases_dir()).unwrap();
        let real = |name: &str| committed.iter().find(|c| c.name == name).unwrap();
        let (planar3, planar8, spatial2, spatial4) =
            (real("planar_n3"), real("planar_n8"), real("spatial_n2"), real("spatial_n4"));
        let expectations: [(&Case, Bug, &[Quantity]); 21] = [
            (planar2, Bug::DocumentVelocitySign, &[VelocityTerms, Accelerations]),
            (planar2, Bug::OwnMassGravity, &[GravityTerms, Accelerations]),
            (planar1, Bug::NoDamping, &[GeneralizedForces, Accelerations]),
            (spatial1, Bug::NoDamping, &[GeneralizedForces, Accelerations]),
            (spatial1, Bug::PhiDampingWithoutSin2, &[GeneralizedForces, Accelerations]),
            (planar2, Bug::HalfCrossTerms, &[KineticEnergy]),
            (spatial1, Bug::AccelerationsWithoutPivot, &[Accelerations]),
            (planar2, Bug::OwnMassDiagonal, &[MassMatrix, Accelerations]),
            (planar1, Bug::None, &[]),
            (planar2, Bug::None, &[]),
            (spatial1, Bug::None, &[]),
            // The same against the committed sympy reference.
            (planar3, Bug::DocumentVelocitySign, &[VelocityTerms, Accelerations]),
            (planar8, Bug::DocumentVelocitySign, &[VelocityTerms, Accelerations]),
            (planar8, Bug::MinTailMass, &[VelocityTerms, Accelerations]),
            (planar8, Bug::OwnMassGravity, &[GravityTerms, Accelerations]),
            (planar8, Bug::OwnMassDiagonal, &[MassMatrix, Accelerations]),
            (spatial2, Bug::PhiDampingWithoutSin2, &[GeneralizedForces, Accelerations]),
            (spatial4, Bug::OwnMassGravity, &[GravityTerms, Accelerations]),
            (spatial4, Bug::AccelerationsWithoutPivot, &[Accelerations]),
            (planar8, Bug::None, &[]),
            (spatial4, Bug::None, &[]),
        ];
        for (case, bug, flagged) in expectations {
            let errors = mutant_errors(case, bug, 20);
            for (quantity, error) in Quantity::ALL.iter().zip(errors) {
                if flagged.contains(quantity) {
                    assert!(error > 1e4 * BOUND, "{} {bug:?}: {} only {error:e}", case.name, quantity.name());
                } else {
                    assert!(error < 1e-2 * BOUND, "{} {bug:?}: {} {error:e}", case.name, quantity.name());
                }
            }
        }
    }

    #[test]
    fn a_model_that_leaves_an_entry_unwritten_fails() {
        // Zero-initialised outputs would hide a model that never writes the spatial φ
        // gravity entries; NaN-filled ones expose it.
        struct Lazy(Spatial<Dyn>);
        impl Model for Lazy {
            type Links = Dyn;
            type Dof = Dyn;
            type Space = nalgebra::U3;
            fn chain(&self) -> &Chain<Dyn> {
                self.0.chain()
            }
            fn dof(&self) -> Dyn {
                self.0.dof()
            }
            fn mass_matrix(&self, q: &DVector<f64>, out: &mut DMatrix<f64>) {
                self.0.mass_matrix(q, out)
            }
            fn velocity_terms(&self, q: &DVector<f64>, qd: &DVector<f64>, out: &mut DVector<f64>) {
                self.0.velocity_terms(q, qd, out)
            }
            fn gravity_terms(&self, q: &DVector<f64>, out: &mut DVector<f64>) {
                let n = self.chain().links();
                let mut full = DVector::zeros(2 * n);
                self.0.gravity_terms(q, &mut full);
                out.rows_mut(0, n).copy_from(&full.rows(0, n));
            }
            fn pivot_terms(&self, q: &DVector<f64>, a: &OVector<f64, nalgebra::U3>, out: &mut DVector<f64>) {
                self.0.pivot_terms(q, a, out)
            }
            fn generalized_forces(
                &self,
                q: &DVector<f64>,
                qd: &DVector<f64>,
                t: &DVector<f64>,
                out: &mut DVector<f64>,
            ) {
                self.0.generalized_forces(q, qd, t, out)
            }
            fn kinetic_energy(&self, q: &DVector<f64>, qd: &DVector<f64>) -> f64 {
                self.0.kinetic_energy(q, qd)
            }
            fn potential_energy(&self, q: &DVector<f64>) -> f64 {
                self.0.potential_energy(q)
            }
        }
        let case = &fixtures()[2];
        let (params, point) = sample::state(1, case.kind, case.links, 0);
        let reference = Reference::new(case, &params, &point);
        let lazy = Lazy(Spatial::new(models::chain::<Dyn>(&params).unwrap()));
        let measured = check_model(case, &lazy, &point, &reference).unwrap();
        assert_eq!(measured[2].error, f64::INFINITY);
        assert_eq!(measured[2].entry, "[1]");
        // The wrong model for the case is an error, not a comparison.
        let planar = Planar::new(models::chain::<Dyn>(&params).unwrap());
        let message = check_model(case, &planar, &point, &reference).unwrap_err().to_string();
        assert!(message.contains("1 coordinates in 2 dimensions, the case 2 in 3"), "{message}");
    }

    #[test]
    fn entry_errors_floor_the_scale() {
        // An exact zero compared with a round-off-sized value: measured against the floor.
        let (i, e) = entry_errors(&[1.0, 1e-20], &[1.0, 0.0], &[1.0, 0.0], 1e-4);
        assert_eq!((i, e), (1, 1e-20 / 1e-4));
        assert_eq!(entry_errors(&[0.0, 0.0], &[0.0, 0.0], &[0.0, 0.0], 0.0), (0, 0.0));
        assert_eq!(entry_errors(&[0.0, 1e-300], &[0.0, 0.0], &[0.0, 0.0], 0.0), (1, f64::INFINITY));
        assert_eq!(entry_errors(&[1.0, f64::NAN], &[1.0, 2.0], &[1.0, 2.0], 0.0), (1, f64::INFINITY));
        assert_eq!(entry_errors(&[1.0, 2.5], &[1.0, 2.0], &[1.0, 5.0], 1e-4), (1, 0.1));
    }

    #[test]
    fn acceleration_error_is_the_relative_residual() {
        let m = DMatrix::from_row_slice(2, 2, &[2.0, 1.0, 1.0, 3.0]);
        let rhs = DVector::from_vec(vec![1.0, 2.0]);
        let rhs_scale = DVector::from_vec(vec![3.0, 2.0]);
        let exact = m.clone().lu().solve(&rhs).unwrap();
        assert!(acceleration_error(&m, &rhs_scale, &m, &rhs, &exact).1 < 1e-16);
        let wrong = &exact + DVector::from_vec(vec![0.0, 0.1]);
        let (row, error, residual) = acceleration_error(&m, &rhs_scale, &m, &rhs, &wrong);
        assert_eq!(row, 1);
        assert!((residual - 0.3).abs() < 1e-15);
        assert!((error - 0.3 / (4.0 * wrong.amax() + 3.0)).abs() < 1e-15);
        let nan = DVector::from_vec(vec![f64::NAN, 0.0]);
        assert_eq!(acceleration_error(&m, &rhs_scale, &m, &rhs, &nan).1, f64::INFINITY);
    }
}
