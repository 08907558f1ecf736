//! The canonical (Hamiltonian) form of a chain model, `x = (q, p)` with `p = M(q) q̇`,
//! the variables in which Gauss–Legendre methods are symplectic.

use nalgebra::{
    Cholesky, DefaultAllocator, Dim, DimMul, DimProd, OMatrix, OVector, U1, U2, allocator::Allocator,
};

use crate::error::{Error, Result};
use crate::integrate::{System, SystemAlloc};
use crate::model::{Inputs, InputsAt, Model, ModelAlloc, check_inputs};
use crate::systems::first_order::{stack, unstack};

/// Coordinates and rates (or momenta), one vector each.
type Pair<D> = (OVector<f64, D>, OVector<f64, D>);

/// A chain model as the first-order system in canonical variables
/// ```text
/// x = (q, p),   p = M(q) q̇,
/// q̇ = M(q)⁻¹ p,
/// ṗ = ∂T/∂q|_q̇ − k(q) + Q(q, q̇, σ) − d(q, p̈)
/// ```
/// of dimension `2·dof`. Without torque, damping and drive these are Hamilton's equations
/// of `H(q, p) = ½ pᵀ M(q)⁻¹ p + U(q)` (the document's section 1.1 `H = T + U`,
/// `∂H/∂q|_p = −∂T/∂q|_q̇ + ∂U/∂q`), for which Gauss–Legendre methods are symplectic; in
/// the velocity form [`FirstOrder`](crate::systems::FirstOrder) (`x = (q, q̇)`) they are not. The
/// momentum equation is Lagrange's `d/dt(∂T/∂q̇) − ∂T/∂q = Q − k − d`, so both forms
/// describe the same motion; `docs/integrators.md` compares them on long runs.
///
/// `q̇` comes from a Cholesky solve with `M(q)`; `∂T/∂q` from [`Model::kinetic_gradient`]. The
/// Jacobian is the finite-difference default of [`System::jacobian`].
#[derive(Debug, Clone)]
pub struct Canonical<M, I> {
    model: M,
    inputs: I,
}

impl<M: Model> Canonical<M, Inputs<M::Dof, M::Space>>
where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>,
{
    /// The free chain: no torque, pivot at rest.
    pub fn new(model: M) -> Self {
        let inputs = model.zero_inputs();
        Self { model, inputs }
    }
}

impl<M: Model, I> Canonical<M, I>
where
    M::Dof: DimMul<U2>,
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space> + Allocator<DimProd<M::Dof, U2>>,
{
    /// The chain driven by `inputs` (constant [`Inputs`] or a closure of time).
    pub fn with_inputs(model: M, inputs: I) -> Self {
        Self { model, inputs }
    }

    /// The model.
    pub fn model(&self) -> &M {
        &self.model
    }

    /// The inputs.
    pub fn inputs(&self) -> &I {
        &self.inputs
    }

    /// The state `x = (q, p)` (rad, kg·m²/s).
    pub fn state(
        &self,
        q: &OVector<f64, M::Dof>,
        p: &OVector<f64, M::Dof>,
    ) -> OVector<f64, DimProd<M::Dof, U2>> {
        stack(self.model.dof(), q, p)
    }

    /// Splits a state into `(q, p)`.
    pub fn split(
        &self,
        x: &OVector<f64, DimProd<M::Dof, U2>>,
    ) -> (OVector<f64, M::Dof>, OVector<f64, M::Dof>) {
        unstack(self.model.dof(), x)
    }

    /// The momenta `p = M(q) q̇` (kg·m²/s) of rates `q̇` (rad/s).
    pub fn momenta(&self, q: &OVector<f64, M::Dof>, qd: &OVector<f64, M::Dof>) -> OVector<f64, M::Dof> {
        let dof = self.model.dof();
        let mut mass = OMatrix::<f64, M::Dof, M::Dof>::zeros_generic(dof, dof);
        self.model.mass_matrix(q, &mut mass);
        mass * qd
    }

    /// The canonical state of `(q, q̇)`: `x = (q, M(q) q̇)`.
    pub fn from_velocities(
        &self,
        q: &OVector<f64, M::Dof>,
        qd: &OVector<f64, M::Dof>,
    ) -> OVector<f64, DimProd<M::Dof, U2>> {
        self.state(q, &self.momenta(q, qd))
    }

    /// The rates `q̇ = M(q)⁻¹ p` (rad/s) of momenta `p`.
    ///
    /// Errors: [`Error::SingularAngle`] at a coordinate singularity,
    /// [`Error::NotPositiveDefinite`] if the mass matrix does not factor.
    pub fn velocities(
        &self,
        q: &OVector<f64, M::Dof>,
        p: &OVector<f64, M::Dof>,
    ) -> Result<OVector<f64, M::Dof>> {
        self.model.check_configuration(q)?;
        let dof = self.model.dof();
        let mut mass = OMatrix::<f64, M::Dof, M::Dof>::zeros_generic(dof, dof);
        self.model.mass_matrix(q, &mut mass);
        let cholesky = Cholesky::new(mass).ok_or(Error::NotPositiveDefinite)?;
        let qd = cholesky.solve(p);
        if qd.iter().all(|v| v.is_finite()) { Ok(qd) } else { Err(Error::NotPositiveDefinite) }
    }

    /// The velocity-form state `(q, q̇)` of a canonical state (errors of
    /// [`velocities`](Self::velocities)).
    pub fn to_velocities(&self, x: &OVector<f64, DimProd<M::Dof, U2>>) -> Result<Pair<M::Dof>> {
        let (q, p) = self.split(x);
        let qd = self.velocities(&q, &p)?;
        Ok((q, qd))
    }

    /// The Hamiltonian `H(q, p) = ½ pᵀ M(q)⁻¹ p + U(q) = T + U` (J), relative to the pivot,
    /// evaluated as [`Model::energy`] of `(q, M⁻¹ p)` so that it is the same function of
    /// the motion as [`FirstOrder::energy`](crate::systems::FirstOrder::energy).
    pub fn energy(&self, x: &OVector<f64, DimProd<M::Dof, U2>>) -> Result<f64> {
        let (q, qd) = self.to_velocities(x)?;
        Ok(self.model.energy(&q, &qd))
    }
}

impl<M: Model, I: InputsAt<M::Dof, M::Space>> System for Canonical<M, I>
where
    M::Dof: DimMul<U2>,
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space> + SystemAlloc<DimProd<M::Dof, U2>>,
{
    type Dim = DimProd<M::Dof, U2>;

    fn dim(&self) -> Self::Dim {
        self.model.dof().mul(U2)
    }

    /// `(M⁻¹ p, ∂T/∂q − k + Q − d)`. Errors: [`Error::NonFinite`] (`"q"`, `"p"` or an
    /// input), [`Error::SingularAngle`], [`Error::NotPositiveDefinite`].
    fn rhs(&self, t: f64, x: &OVector<f64, Self::Dim>, out: &mut OVector<f64, Self::Dim>) -> Result<()> {
        let (q, p) = self.split(x);
        let inputs = self.inputs.inputs_at(t);
        check_inputs(self.model.dof().value(), &q, &p, &inputs).map_err(|e| match e {
            Error::NonFinite { what: "qd", index, value } => Error::NonFinite { what: "p", index, value },
            Error::LengthMismatch { what: "qd", expected, got } => {
                Error::LengthMismatch { what: "p", expected, got }
            }
            other => other,
        })?;
        let qd = self.velocities(&q, &p)?;
        let dof = self.model.dof();
        let mut pd = OVector::<f64, M::Dof>::zeros_generic(dof, U1);
        let mut tmp = OVector::<f64, M::Dof>::zeros_generic(dof, U1);
        self.model.kinetic_gradient(&q, &qd, &mut pd);
        self.model.generalized_forces(&q, &qd, &inputs.torque, &mut tmp);
        pd += &tmp;
        self.model.gravity_terms(&q, &mut tmp);
        pd -= &tmp;
        self.model.pivot_terms(&q, &inputs.pivot_acceleration, &mut tmp);
        pd -= &tmp;
        let n = dof.value();
        for i in 0..n {
            out[i] = qd[i];
            out[n + i] = pd[i];
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::{Const, DVector, Dyn, SVector, Vector2};

    use super::*;
    use crate::chain::Chain;
    use crate::models::planar::Planar;
    use crate::models::spatial::Spatial;
    use crate::systems::first_order::FirstOrder;

    /// Central difference of `T` in each coordinate, step `1e-5`: error ~1e-10 · scale.
    fn numeric_gradient<M: Model>(model: &M, q: &OVector<f64, M::Dof>, qd: &OVector<f64, M::Dof>) -> Vec<f64>
    where
        DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>,
    {
        let h = 1e-5;
        (0..q.len())
            .map(|k| {
                let (mut plus, mut minus) = (q.clone(), q.clone());
                plus[k] += h;
                minus[k] -= h;
                (model.kinetic_energy(&plus, qd) - model.kinetic_energy(&minus, qd)) / (2.0 * h)
            })
            .collect()
    }

    #[test]
    fn planar_gradient_matches_a_finite_difference_of_the_kinetic_energy() {
        let model =
            Planar::new(Chain::<Dyn>::new(&[1.0, 0.3, 2.0, 0.7], &[0.5, 1.0, 0.7, 1.3], 9.81).unwrap());
        let q = DVector::from_vec(vec![0.4, -1.0, 2.5, 0.1]);
        let qd = DVector::from_vec(vec![1.0, -0.5, 2.3, -1.7]);
        let mut got = DVector::zeros(4);
        model.kinetic_gradient(&q, &qd, &mut got);
        let expected = numeric_gradient(&model, &q, &qd);
        for (g, e) in got.iter().zip(&expected) {
            assert!((g - e).abs() < 1e-8, "{got} vs {expected:?}");
        }
    }

    #[test]
    fn spatial_gradient_matches_a_finite_difference_of_the_kinetic_energy() {
        let model = Spatial::new(Chain::<Const<3>>::new(&[1.0, 0.3, 2.0], &[0.5, 1.0, 0.7], 9.81).unwrap());
        let q = SVector::<f64, 6>::from([0.4, 1.0, 2.5, 0.1, -2.0, 3.0]);
        let qd = SVector::<f64, 6>::from([1.0, -0.5, 0.3, 2.0, 0.7, -1.1]);
        let mut got = SVector::<f64, 6>::zeros();
        model.kinetic_gradient(&q, &qd, &mut got);
        let expected = numeric_gradient(&model, &q, &qd);
        for (g, e) in got.iter().zip(&expected) {
            assert!((g - e).abs() < 1e-8, "{got} vs {expected:?}");
        }
    }

    /// `ṗ = d/dt (M q̇)` along the motion: `M q̈ + Ṁ q̇`, with `Ṁ q̇` a finite difference of
    /// `M` along `q̇`; checks the whole momentum equation including damping and drive.
    #[test]
    fn momentum_rate_is_the_time_derivative_of_m_qdot() {
        let chain = Chain::<Dyn>::new(&[1.0, 2.0, 0.5], &[0.8, 0.6, 1.1], 9.81).unwrap();
        let model = Spatial::new(chain.with_damping(&[0.1, 0.2, 0.3]).unwrap());
        let mut inputs = model.zero_inputs();
        inputs.torque.copy_from_slice(&[0.3, -0.2, 0.1, 0.5, 0.0, -0.4]);
        inputs.pivot_acceleration.copy_from_slice(&[1.0, -2.0, 0.5]);
        let q = DVector::from_vec(vec![0.7, 1.9, 2.2, 0.3, -1.0, 2.0]);
        let qd = DVector::from_vec(vec![0.5, -1.2, 0.8, 1.5, 0.2, -0.9]);
        let system = Canonical::with_inputs(model.clone(), inputs.clone());
        let x = system.from_velocities(&q, &qd);
        let mut f = DVector::zeros(12);
        system.rhs(0.0, &x, &mut f).unwrap();
        let mut qdd = DVector::zeros(6);
        model.accelerations(&q, &qd, &inputs, &mut qdd).unwrap();
        let h = 1e-6;
        let (mut mp, mut mm) = (DMatrixOf::zeros(6, 6), DMatrixOf::zeros(6, 6));
        model.mass_matrix(&(&q + &qd * h), &mut mp);
        model.mass_matrix(&(&q - &qd * h), &mut mm);
        let mut mass = DMatrixOf::zeros(6, 6);
        model.mass_matrix(&q, &mut mass);
        let expected = &mass * &qdd + (mp - mm) / (2.0 * h) * &qd;
        for i in 0..6 {
            assert!((f[i] - qd[i]).abs() < 1e-13, "q̇[{i}]: {} vs {}", f[i], qd[i]);
            assert!((f[6 + i] - expected[i]).abs() < 1e-7, "ṗ[{i}]: {} vs {}", f[6 + i], expected[i]);
        }
    }

    type DMatrixOf = nalgebra::DMatrix<f64>;

    #[test]
    fn conversions_round_trip_and_energy_matches_the_velocity_form() {
        let model = Planar::new(Chain::<Const<2>>::new(&[1.0, 2.0], &[0.5, 1.5], 9.81).unwrap());
        let system = Canonical::new(model.clone());
        let velocity_form = FirstOrder::new(model);
        let (q, qd) = (Vector2::new(0.3, -1.1), Vector2::new(2.0, 0.4));
        let x = system.from_velocities(&q, &qd);
        let (q2, qd2) = system.to_velocities(&x).unwrap();
        assert_eq!(q2, q);
        assert!((qd2 - qd).amax() < 1e-14);
        let e = velocity_form.energy(&velocity_form.state(&q, &qd));
        assert!((system.energy(&x).unwrap() - e).abs() < 1e-13 * e.abs());
        // H = ½ p·q̇ + U.
        let (_, p) = system.split(&x);
        let h = 0.5 * p.dot(&qd) + system.model().potential_energy(&q);
        assert!((h - e).abs() < 1e-13 * e.abs());
    }

    #[test]
    fn singular_spatial_state_and_nan_momenta_are_errors() {
        let system = Canonical::new(Spatial::new(Chain::<Dyn>::uniform(1, 1.0, 1.0, 9.81).unwrap()));
        let mut f = DVector::zeros(4);
        let x = DVector::from_vec(vec![0.0, 0.3, 0.0, 0.0]);
        assert!(matches!(system.rhs(0.0, &x, &mut f), Err(Error::SingularAngle { link: 1, .. })));
        let x = DVector::from_vec(vec![1.0, 0.3, f64::NAN, 0.0]);
        assert!(matches!(system.rhs(0.0, &x, &mut f), Err(Error::NonFinite { what: "p", index: 0, .. })));
    }
}
