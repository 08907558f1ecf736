//! The adapter that turns a chain [`Model`] into a first-order [`System`]
//! `x' = f(t, x)` with `x = (q, q̇)`, for the integrators.

use nalgebra::{DefaultAllocator, Dim, DimMul, DimProd, OMatrix, OVector, U1, U2, allocator::Allocator};

use crate::error::Result;
use crate::integrate::{System, SystemAlloc};
use crate::jacobians::{Derivatives, Jacobians};
use crate::model::{Inputs, InputsAt, Model, ModelAlloc};

/// A chain model as the first-order system
/// ```text
/// x = (q, q̇),   x' = (q̇, q̈(q, q̇, inputs(t)))
/// ```
/// of dimension `2·dof` (`DimProd<M::Dof, U2>`: `Const<2N>` for fixed-size models, `Dyn`
/// otherwise), with `q̈` from [`Model::accelerations`] (the document's eqs 51–52 for the
/// double pendulum). `I` supplies the inputs at each time ([`InputsAt`]);
/// [`new`](FirstOrder::new) uses none (no torque, pivot at rest).
///
/// The Jacobian is the finite-difference default of [`System::jacobian`], or, after
/// [`analytic`](FirstOrder::analytic), the model's own [`Derivatives`]:
/// `∂x'/∂x = [[0, I], [∂q̈/∂q, ∂q̈/∂q̇]]`.
#[derive(Debug, Clone)]
pub struct FirstOrder<M, I, J = Differences> {
    model: M,
    inputs: I,
    _jacobian: J,
}

/// [`FirstOrder`]'s Jacobian by central differences of the right-hand side.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Differences;

/// [`FirstOrder`]'s Jacobian from the model's analytic [`Derivatives`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Analytic;

impl<M: Model> FirstOrder<M, Inputs<M::Dof, M::Space>>
where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>,
{
    /// The free chain: no torque, pivot at rest.
    pub fn new(model: M) -> Self {
        let inputs = model.zero_inputs();
        Self { model, inputs, _jacobian: Differences }
    }
}

impl<M, I> FirstOrder<M, I> {
    /// The chain driven by `inputs` (constant [`Inputs`] or a closure of time).
    pub fn with_inputs(model: M, inputs: I) -> Self {
        Self { model, inputs, _jacobian: Differences }
    }

    /// The same system with the model's analytic Jacobian instead of differences.
    pub fn analytic(self) -> FirstOrder<M, I, Analytic> {
        FirstOrder { model: self.model, inputs: self.inputs, _jacobian: Analytic }
    }
}

impl<M, I, J> FirstOrder<M, I, J> {
    /// The model.
    pub fn model(&self) -> &M {
        &self.model
    }

    /// The inputs.
    pub fn inputs(&self) -> &I {
        &self.inputs
    }
}

impl<M: Model, I, J> FirstOrder<M, I, J>
where
    M::Dof: DimMul<U2>,
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space> + Allocator<DimProd<M::Dof, U2>>,
{
    /// The state `x = (q, q̇)` (rad, rad/s).
    pub fn state(
        &self,
        q: &OVector<f64, M::Dof>,
        qd: &OVector<f64, M::Dof>,
    ) -> OVector<f64, DimProd<M::Dof, U2>> {
        stack(self.model.dof(), q, qd)
    }

    /// Splits a state into `(q, q̇)`.
    pub fn split(
        &self,
        x: &OVector<f64, DimProd<M::Dof, U2>>,
    ) -> (OVector<f64, M::Dof>, OVector<f64, M::Dof>) {
        unstack(self.model.dof(), x)
    }

    /// Total mechanical energy `H = T + U` (J) of a state, relative to the pivot.
    pub fn energy(&self, x: &OVector<f64, DimProd<M::Dof, U2>>) -> f64 {
        let (q, qd) = self.split(x);
        self.model.energy(&q, &qd)
    }
}

/// The state `x = (q, r)` of a chain with `dof` coordinates, `r` being the rates `q̇`
/// ([`FirstOrder`]) or the momenta `p` ([`Canonical`](crate::systems::Canonical)).
pub(crate) fn stack<D: Dim + DimMul<U2>>(
    dof: D,
    q: &OVector<f64, D>,
    r: &OVector<f64, D>,
) -> OVector<f64, DimProd<D, U2>>
where
    DefaultAllocator: Allocator<D> + Allocator<DimProd<D, U2>>,
{
    OVector::from_iterator_generic(dof.mul(U2), U1, q.iter().chain(r.iter()).copied())
}

/// Splits `x = (q, r)` back into `q` and `r`: the inverse of [`stack`].
pub(crate) fn unstack<D: Dim + DimMul<U2>>(
    dof: D,
    x: &OVector<f64, DimProd<D, U2>>,
) -> (OVector<f64, D>, OVector<f64, D>)
where
    DefaultAllocator: Allocator<D> + Allocator<DimProd<D, U2>>,
{
    let n = dof.value();
    let q = OVector::from_iterator_generic(dof, U1, x.iter().take(n).copied());
    let r = OVector::from_iterator_generic(dof, U1, x.iter().skip(n).take(n).copied());
    (q, r)
}

impl<M: Model, I: InputsAt<M::Dof, M::Space>, J> FirstOrder<M, I, J>
where
    M::Dof: DimMul<U2>,
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space> + SystemAlloc<DimProd<M::Dof, U2>>,
{
    /// `(q̇, q̈)` at `(t, x)`: both impls' [`System::rhs`].
    fn velocity_and_acceleration(
        &self,
        t: f64,
        x: &OVector<f64, DimProd<M::Dof, U2>>,
        out: &mut OVector<f64, DimProd<M::Dof, U2>>,
    ) -> Result<()> {
        let (q, qd) = self.split(x);
        let mut qdd = OVector::zeros_generic(self.model.dof(), U1);
        self.model.accelerations(&q, &qd, &self.inputs.inputs_at(t), &mut qdd)?;
        let n = qd.len();
        for i in 0..n {
            out[i] = qd[i];
            out[n + i] = qdd[i];
        }
        Ok(())
    }
}

impl<M: Model, I: InputsAt<M::Dof, M::Space>> System for FirstOrder<M, I, Differences>
where
    M::Dof: DimMul<U2>,
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space> + SystemAlloc<DimProd<M::Dof, U2>>,
{
    type Dim = DimProd<M::Dof, U2>;

    fn dim(&self) -> Self::Dim {
        self.model.dof().mul(U2)
    }

    /// `x = (q, q̇)`, `q' = q̇`.
    fn second_order(&self) -> Option<usize> {
        Some(self.model.dof().value())
    }

    /// `(q̇, q̈)`; errors of [`Model::accelerations`] pass through.
    fn rhs(&self, t: f64, x: &OVector<f64, Self::Dim>, out: &mut OVector<f64, Self::Dim>) -> Result<()> {
        self.velocity_and_acceleration(t, x, out)
    }
}

impl<M: Derivatives, I: InputsAt<M::Dof, M::Space>> System for FirstOrder<M, I, Analytic>
where
    M::Dof: DimMul<U2>,
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>
        + Allocator<M::Dof, M::Space>
        + SystemAlloc<DimProd<M::Dof, U2>>,
{
    type Dim = DimProd<M::Dof, U2>;

    fn dim(&self) -> Self::Dim {
        self.model.dof().mul(U2)
    }

    /// `x = (q, q̇)`, `q' = q̇`.
    fn second_order(&self) -> Option<usize> {
        Some(self.model.dof().value())
    }

    /// `(q̇, q̈)`; errors of [`Model::accelerations`] pass through.
    fn rhs(&self, t: f64, x: &OVector<f64, Self::Dim>, out: &mut OVector<f64, Self::Dim>) -> Result<()> {
        self.velocity_and_acceleration(t, x, out)
    }

    /// `[[0, I], [∂q̈/∂q, ∂q̈/∂q̇]]` from [`Derivatives::state_jacobians`].
    fn jacobian(
        &self,
        t: f64,
        x: &OVector<f64, Self::Dim>,
        out: &mut OMatrix<f64, Self::Dim, Self::Dim>,
    ) -> Result<()> {
        let (q, qd) = self.split(x);
        let mut jac = Jacobians::zeros(&self.model);
        self.model.state_jacobians(&q, &qd, &self.inputs.inputs_at(t), &mut jac)?;
        jac.first_order(out);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::{Const, DVector, Dyn, Vector2, Vector4};

    use super::*;
    use crate::chain::Chain;
    use crate::models::planar::Planar;

    #[test]
    fn rhs_is_velocity_then_acceleration() {
        let chain = Chain::<Const<2>>::new(&[1.0, 2.0], &[0.5, 1.5], 9.81).unwrap();
        let model = Planar::new(chain);
        let system = FirstOrder::new(model.clone());
        let (q, qd) = (Vector2::new(0.3, -1.1), Vector2::new(2.0, 0.4));
        let x: Vector4<f64> = system.state(&q, &qd);
        let mut f = Vector4::zeros();
        system.rhs(0.0, &x, &mut f).unwrap();
        let mut qdd = Vector2::zeros();
        model.accelerations(&q, &qd, &model.zero_inputs(), &mut qdd).unwrap();
        assert_eq!(f, Vector4::new(qd[0], qd[1], qdd[0], qdd[1]));
        assert_eq!(system.split(&x), (q, qd));
    }

    #[test]
    fn the_analytic_jacobian_agrees_with_central_differences() {
        let chain = Chain::<Const<2>>::new(&[1.0, 2.0], &[0.5, 1.5], 9.81)
            .unwrap()
            .with_damping(&[0.2, 0.1])
            .unwrap();
        let numeric = FirstOrder::new(Planar::new(chain));
        let analytic = numeric.clone().analytic();
        let x = Vector4::new(0.3, -1.1, 2.0, 0.4);
        let (mut a, mut b) = (nalgebra::Matrix4::zeros(), nalgebra::Matrix4::zeros());
        analytic.jacobian(0.0, &x, &mut a).unwrap();
        numeric.jacobian(0.0, &x, &mut b).unwrap();
        assert!((a - b).amax() < 1e-8 * b.amax(), "{a} {b}");
        assert_eq!(a.fixed_view::<2, 2>(0, 2), nalgebra::Matrix2::identity());
    }

    #[test]
    fn a_closure_drives_the_inputs() {
        let chain = Chain::<Dyn>::uniform(1, 1.0, 1.0, 0.0).unwrap();
        let model = Planar::new(chain);
        // σ(t) = t: the hanging pendulum without gravity accelerates as θ̈ = σ / (m l²).
        let drive = |t: f64| {
            let mut inputs = Inputs::<Dyn, U2>::zeros(Dyn(1));
            inputs.torque[0] = t;
            inputs
        };
        let system = FirstOrder::with_inputs(model, drive);
        let x = DVector::from_vec(vec![0.0, 0.0]);
        let mut f = DVector::zeros(2);
        system.rhs(2.5, &x, &mut f).unwrap();
        assert_eq!(f.as_slice(), &[0.0, 2.5]);
        assert_eq!(system.dim(), Dyn(2));
    }
}
