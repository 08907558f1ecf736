//! Planted bugs and the error measures of [`check_model`](super::check_model).
use nalgebra::{DMatrix, Dyn};
use pendulum_core::{Chain, Planar, Spatial, kinematics::Chart};

use super::*;
use crate::case::{Kind, load_all};
use crate::sample;
use crate::verify::bounds::BOUND;
use crate::verify::{DEFAULT_SEED, fixtures::fixtures, models};

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
    /// Pivot terms from the link's own mass instead of the tail mass.
    OwnMassPivot,
    /// Pivot terms with the vertical pivot acceleration's sign flipped (up and down
    /// confused).
    PivotVerticalSign,
    /// Potential energy from the link's own mass instead of the tail mass.
    OwnMassPotential,
    /// Spatial `M[φ_i][φ_i] = W_ii l_i²`, without its `sin² θ_i`.
    PhiInertiaWithoutSin2,
    /// Spatial `M[θ_i][φ_i]`, identically zero, as `W_ii l_i² sin θ_i cos θ_i sin 2φ_i`:
    /// `∂u/∂φ` with the wrong sign in x. The reference's scale of this entry is 0, so
    /// only the scale floor measures it.
    ThetaPhiNotCancelled,
    /// Spatial `c_φ_i` with the Coriolis term `2 W_ii l_i² sin θ_i cos θ_i θ̇_i φ̇_i`
    /// at half its size (the factor 2 of `d/dt sin² θ` forgotten).
    PhiCoriolisFactorOne,
    /// The last coordinate's acceleration off by this relative amount (all building
    /// blocks correct).
    LastAccelerationOff(f64),
    /// Planar `∂F/∂q̇` off the diagonal without the factor 2 of `∂θ̇²/∂θ̇`.
    RateJacobianFactorOne,
    /// `∂(M v)/∂q` left out of `∂q̈/∂q` (as if `M` were constant).
    NoMassPartials,
    /// `∂F/∂p̈` with the sign of its last component flipped.
    PivotJacobianSign,
    /// No bug at all.
    None,
}

impl Bug {
    /// Whether the bug is in the derivatives only (the mutant's other building blocks are
    /// correct, so every quantity can be asserted); a bug elsewhere leaves the mutant's
    /// derivatives those of the correct model, and the Jacobian rows are not asserted.
    fn in_derivatives(self) -> bool {
        matches!(self, Bug::RateJacobianFactorOne | Bug::NoMassPartials | Bug::PivotJacobianSign | Bug::None)
    }
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

    /// `m_i / W_ii` of the link of coordinate `a` (θ_i or φ_i).
    fn own_mass_share(&self, a: usize) -> f64 {
        let c = self.inner.chain();
        let i = a % c.links();
        c.masses()[i] / c.tail_masses()[i]
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
    type Chart = M::Chart;

    fn chain(&self) -> &Chain<Dyn> {
        self.inner.chain()
    }
    fn dof(&self) -> Dyn {
        self.inner.dof()
    }
    fn mass_matrix(&self, q: &DVector<f64>, out: &mut DMatrix<f64>) {
        self.inner.mass_matrix(q, out);
        let n = self.chain().links();
        match self.bug {
            Bug::OwnMassDiagonal => {
                for i in 0..n {
                    out[(i, i)] *= self.own_mass_share(i);
                }
            }
            Bug::PhiInertiaWithoutSin2 => {
                for i in 0..n {
                    out[(n + i, n + i)] = self.weight(i, i);
                }
            }
            Bug::ThetaPhiNotCancelled => {
                for i in 0..n {
                    let slip = self.weight(i, i) * q[i].sin() * q[i].cos() * (2.0 * q[n + i]).sin();
                    out[(i, n + i)] = slip;
                    out[(n + i, i)] = slip;
                }
            }
            _ => {}
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
        if self.bug == Bug::PhiCoriolisFactorOne {
            let n = self.chain().links();
            for i in 0..n {
                out[n + i] -= self.weight(i, i) * q[i].sin() * q[i].cos() * qd[i] * qd[n + i];
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
        let mut a = a.clone();
        if self.bug == Bug::PivotVerticalSign {
            let up = a.len() - 1;
            a[up] = -a[up];
        }
        self.inner.pivot_terms(q, &a, out);
        if self.bug == Bug::OwnMassPivot {
            for k in 0..out.len() {
                out[k] *= self.own_mass_share(k);
            }
        }
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
        let u = self.inner.potential_energy(q);
        if self.bug != Bug::OwnMassPotential {
            return u;
        }
        // U = Σ_i W_ii g l_i u_i · up; the slip puts m_i where W_ii belongs.
        let c = self.chain();
        let excess: f64 = (0..c.links())
            .map(|i| {
                let u_i = <M::Chart as Chart>::direction(q.as_slice(), i);
                (c.tail_masses()[i] - c.masses()[i]) * c.gravity() * c.lengths()[i] * u_i[u_i.len() - 1]
            })
            .sum();
        u - excess
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
        if let Bug::LastAccelerationOff(relative) = self.bug {
            out[dof.value() - 1] *= 1.0 + relative;
        }
        Ok(())
    }
}

impl<M> Derivatives for Mutant<M>
where
    M: Derivatives + Model<Links = Dyn, Dof = Dyn>,
    DefaultAllocator: ModelAlloc<Dyn, Dyn, M::Space> + Allocator<Dyn, M::Space>,
{
    fn mass_matrix_partials(&self, q: &DVector<f64>, v: &DVector<f64>, out: &mut DMatrix<f64>) {
        self.inner.mass_matrix_partials(q, v, out);
        if self.bug == Bug::NoMassPartials {
            out.fill(0.0);
        }
    }

    fn force_jacobians(
        &self,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        inputs: &Inputs<Dyn, M::Space>,
        dq: &mut DMatrix<f64>,
        dqd: &mut DMatrix<f64>,
        dp: &mut OMatrix<f64, Dyn, M::Space>,
    ) {
        self.inner.force_jacobians(q, qd, inputs, dq, dqd, dp);
        match self.bug {
            Bug::RateJacobianFactorOne => {
                for a in 0..dqd.nrows() {
                    for x in (0..dqd.ncols()).filter(|&x| x != a) {
                        dqd[(a, x)] *= 0.5;
                    }
                }
            }
            Bug::PivotJacobianSign => {
                let last = dp.ncols() - 1;
                dp.column_mut(last).neg_mut();
            }
            _ => {}
        }
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
            Kind::Planar => check_model(case, &Mutant { inner: Planar::new(chain), bug }, &point, &reference),
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
    let expectations: [(&Case, Bug, &[Quantity]); 43] = [
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
        // Where the scale floors act: pivot terms, potential energy, the spatial
        // mass matrix (the zero M[θ_i][φ_i]) and velocity terms.
        (planar2, Bug::OwnMassPivot, &[PivotTerms, Accelerations]),
        (planar8, Bug::OwnMassPivot, &[PivotTerms, Accelerations]),
        (spatial4, Bug::OwnMassPivot, &[PivotTerms, Accelerations]),
        (planar1, Bug::PivotVerticalSign, &[PivotTerms, Accelerations]),
        (spatial1, Bug::PivotVerticalSign, &[PivotTerms, Accelerations]),
        (planar2, Bug::OwnMassPotential, &[PotentialEnergy]),
        (planar8, Bug::OwnMassPotential, &[PotentialEnergy]),
        (spatial4, Bug::OwnMassPotential, &[PotentialEnergy]),
        (spatial1, Bug::PhiInertiaWithoutSin2, &[MassMatrix, Accelerations]),
        (spatial4, Bug::PhiInertiaWithoutSin2, &[MassMatrix, Accelerations]),
        (spatial1, Bug::ThetaPhiNotCancelled, &[MassMatrix, Accelerations]),
        (spatial4, Bug::ThetaPhiNotCancelled, &[MassMatrix, Accelerations]),
        (spatial1, Bug::PhiCoriolisFactorOne, &[VelocityTerms, Accelerations]),
        (spatial2, Bug::PhiCoriolisFactorOne, &[VelocityTerms, Accelerations]),
        (spatial4, Bug::PhiCoriolisFactorOne, &[VelocityTerms, Accelerations]),
        (planar8, Bug::None, &[]),
        (spatial4, Bug::None, &[]),
        // Planted in the derivatives: the Jacobian rows.
        (planar2, Bug::RateJacobianFactorOne, &[JacobianQd]),
        (planar8, Bug::RateJacobianFactorOne, &[JacobianQd]),
        (planar3, Bug::NoMassPartials, &[JacobianQ]),
        (spatial1, Bug::NoMassPartials, &[JacobianQ]),
        (spatial4, Bug::NoMassPartials, &[JacobianQ]),
        (planar1, Bug::PivotJacobianSign, &[JacobianPivot]),
        (spatial2, Bug::PivotJacobianSign, &[JacobianPivot]),
    ];
    for (case, bug, flagged) in expectations {
        let errors = mutant_errors(case, bug, 20);
        // The figures of docs/verify.md's table: `cargo test -p xtask planted -- --nocapture`.
        println!(
            "{} {bug:?}: {}",
            case.name,
            Quantity::ALL
                .iter()
                .zip(&errors)
                .map(|(q, e)| format!("{} {e:.1e}", q.name()))
                .collect::<Vec<_>>()
                .join(", ")
        );
        let asserted = if bug.in_derivatives() { Quantity::ALL.len() } else { 8 };
        for (quantity, error) in Quantity::ALL.iter().zip(errors).take(asserted) {
            if flagged.contains(quantity) {
                assert!(error > 1e4 * BOUND, "{} {bug:?}: {} only {error:e}", case.name, quantity.name());
            } else {
                assert!(error < 1e-2 * BOUND, "{} {bug:?}: {} {error:e}", case.name, quantity.name());
            }
        }
    }
}

/// The componentwise and the normwise backward error of the accelerations of a
/// planar n = 8 chain whose last mass is 1e-3 of the others, at 20 states, with the
/// last link's q̈ off by `relative`.
fn light_tail_errors(relative: f64) -> Vec<(f64, f64)> {
    let committed = load_all(&crate::cases_dir()).unwrap();
    let case = committed.iter().find(|c| c.name == "planar_n8").unwrap();
    (0..20)
        .map(|state| {
            let (mut params, point) = sample::state(DEFAULT_SEED, case.kind, case.links, state);
            params.masses = vec![1.0; 8];
            params.masses[7] = 1e-3;
            let reference = Reference::new(case, &params, &point);
            let chain = models::chain::<Dyn>(&params).unwrap();
            let mutant = Mutant { inner: Planar::new(chain), bug: Bug::LastAccelerationOff(relative) };
            let measured = check_model(case, &mutant, &point, &reference).unwrap();
            for (quantity, m) in Quantity::ALL.iter().zip(&measured) {
                if *quantity != Quantity::Accelerations {
                    assert!(m.error < 1e-2 * BOUND, "{}: {:e}", quantity.name(), m.error);
                }
            }
            let accelerations = &measured[Quantity::Accelerations as usize];
            assert!(accelerations.entry.contains("row 7"), "{accelerations:?}");
            // The normwise backward error verify used before, of the same residual:
            // ‖M a − rhs‖_∞ / (‖S(M)‖_∞ ‖a‖_∞ + ‖S(rhs)‖_∞).
            let ModelPoint { q, qd, inputs } = ModelPoint::new(&mutant, &point);
            let mut a = DVector::zeros(8);
            mutant.accelerations(&q, &qd, &inputs, &mut a).unwrap();
            let residual = &reference.values.mass_matrix * &a - &reference.rhs;
            let normwise = residual.amax()
                / (crate::verify::bounds::row_sum_norm(&reference.scales.mass_matrix) * a.amax()
                    + reference.rhs_scale.amax());
            (accelerations.error, normwise)
        })
        .collect()
}

#[test]
fn a_small_error_in_a_light_tail_links_acceleration_fails() {
    // The figures of docs/verify.md: `cargo test -p xtask light_tail -- --nocapture`.
    let range = |v: &[(f64, f64)], pick: fn(&(f64, f64)) -> f64| {
        let x: Vec<f64> = v.iter().map(pick).collect();
        (x.iter().copied().fold(f64::INFINITY, f64::min), x.iter().copied().fold(0.0, f64::max))
    };
    for relative in [1e-6, 1e-8] {
        let errors = light_tail_errors(relative);
        let (c, w) = (range(&errors, |e| e.0), range(&errors, |e| e.1));
        let passed = errors.iter().filter(|e| e.1 < BOUND).count();
        println!(
            "last q̈ off by {relative:e}: componentwise {:.1e} … {:.1e}, normwise {:.1e} … {:.1e} ({passed} of 20 below the bound)",
            c.0, c.1, w.0, w.1
        );
    }
    // 1e-6 relative: every state fails now; the normwise measure passed most of them.
    let errors = light_tail_errors(1e-6);
    assert!(errors.iter().all(|&(componentwise, _)| componentwise > 100.0 * BOUND), "{errors:?}");
    let passed_before = errors.iter().filter(|&&(_, normwise)| normwise < BOUND).count();
    assert!(passed_before >= 15, "{errors:?}");
    // 1e-8 relative: every state fails now; the normwise measure passed all of them.
    let errors = light_tail_errors(1e-8);
    assert!(errors.iter().all(|&(componentwise, _)| componentwise > BOUND), "{errors:?}");
    assert!(errors.iter().all(|&(_, normwise)| normwise < 0.1 * BOUND), "{errors:?}");
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
        type Chart = pendulum_core::kinematics::SphericalAngles;
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
    impl Derivatives for Lazy {
        fn mass_matrix_partials(&self, q: &DVector<f64>, v: &DVector<f64>, out: &mut DMatrix<f64>) {
            self.0.mass_matrix_partials(q, v, out)
        }
        fn force_jacobians(
            &self,
            q: &DVector<f64>,
            qd: &DVector<f64>,
            inputs: &Inputs<Dyn, nalgebra::U3>,
            dq: &mut DMatrix<f64>,
            dqd: &mut DMatrix<f64>,
            dp: &mut OMatrix<f64, Dyn, nalgebra::U3>,
        ) {
            self.0.force_jacobians(q, qd, inputs, dq, dqd, dp)
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
