//! The derivatives of a model's accelerations: the [`Derivatives`] trait the generic and
//! the generated models implement, and [`Jacobians`], what it computes.
//!
//! With the force side `F = Q − c − k − d` of `M(q) q̈ = F(q, q̇, σ, p̈)`, differentiating
//! the equation itself (not `M⁻¹`) gives
//!
//! ```text
//! ∂q̈/∂q  = M⁻¹ (∂F/∂q − ∂(M v)/∂q |_{v = q̈})
//! ∂q̈/∂q̇ = M⁻¹ ∂F/∂q̇
//! ∂q̈/∂σ  = M⁻¹                    (Q = σ − ∂D/∂q̇, so ∂F/∂σ = I)
//! ∂q̈/∂p̈ = M⁻¹ ∂F/∂p̈ = −M⁻¹ ∂d/∂p̈
//! ```
//!
//! A model supplies the two building blocks, `∂(M v)/∂q` at a given `v` and the Jacobians
//! of `F`; the trait's [`Derivatives::acceleration_jacobians`] factors `M` once and solves.
//! For fixed-size models every matrix is a stack array: nothing is allocated.

use nalgebra::{DefaultAllocator, OMatrix, OVector, U1, allocator::Allocator};

use crate::error::Result;
use crate::model::{Inputs, Model, ModelAlloc};

/// The partial derivatives of `q̈(q, q̇, σ, p̈)` at one state, and `q̈` itself.
#[derive(Debug, Clone, PartialEq)]
pub struct Jacobians<M: Model + ?Sized>
where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space> + Allocator<M::Dof, M::Space>,
{
    /// `q̈` (rad/s²).
    pub accelerations: OVector<f64, M::Dof>,
    /// `∂q̈/∂q` (1/s²): entry `(a, b)` is `∂q̈_a/∂q_b`.
    pub q: OMatrix<f64, M::Dof, M::Dof>,
    /// `∂q̈/∂q̇` (1/s).
    pub qd: OMatrix<f64, M::Dof, M::Dof>,
    /// `∂q̈/∂σ = M⁻¹` (1/(kg·m²)).
    pub torque: OMatrix<f64, M::Dof, M::Dof>,
    /// `∂q̈/∂p̈` (1/m): entry `(a, k)` is `∂q̈_a/∂p̈_k`.
    pub pivot: OMatrix<f64, M::Dof, M::Space>,
}

impl<M: Model + ?Sized> Jacobians<M>
where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space> + Allocator<M::Dof, M::Space>,
{
    /// Zeros, sized for `model`.
    pub fn zeros(model: &M) -> Self {
        let dof = model.dof();
        Self {
            accelerations: OVector::zeros_generic(dof, U1),
            q: OMatrix::zeros_generic(dof, dof),
            qd: OMatrix::zeros_generic(dof, dof),
            torque: OMatrix::zeros_generic(dof, dof),
            pivot: OMatrix::zeros_generic(dof, <M::Space as nalgebra::DimName>::name()),
        }
    }
}

impl<M: Model + ?Sized> Jacobians<M>
where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space> + Allocator<M::Dof, M::Space>,
{
    /// The Jacobian `[[0, I], [∂q̈/∂q, ∂q̈/∂q̇]]` of the first-order system `x = (q, q̇)`,
    /// `x' = (q̇, q̈)`, written into `out` (`2·dof` square).
    pub fn first_order<D: nalgebra::Dim>(&self, out: &mut OMatrix<f64, D, D>)
    where
        DefaultAllocator: Allocator<D, D>,
    {
        let n = self.accelerations.len();
        out.as_mut_slice().fill(0.0);
        for i in 0..n {
            out[(i, n + i)] = 1.0;
            for j in 0..n {
                out[(n + i, j)] = self.q[(i, j)];
                out[(n + i, n + j)] = self.qd[(i, j)];
            }
        }
    }
}

/// A [`Model`] whose accelerations can be differentiated analytically.
///
/// The building blocks write into `&mut` outputs and, like the model's, assume sizes that
/// match; [`acceleration_jacobians`](Derivatives::acceleration_jacobians) is the checked
/// entry point.
pub trait Derivatives: Model
where
    DefaultAllocator: ModelAlloc<Self::Links, Self::Dof, Self::Space> + Allocator<Self::Dof, Self::Space>,
{
    /// `∂(M(q) v)/∂q` at fixed `v` (kg·m² times the unit of `v`): entry `(a, x)` is `Σ_b ∂M_ab/∂q_x v_b`.
    fn mass_matrix_partials(
        &self,
        q: &OVector<f64, Self::Dof>,
        v: &OVector<f64, Self::Dof>,
        out: &mut OMatrix<f64, Self::Dof, Self::Dof>,
    );

    /// The Jacobians of the force side `F = Q − c − k − d` by `q` (N·m), by `q̇` (N·m·s)
    /// and by the pivot acceleration `p̈` (kg·m); `∂F/∂σ` is the identity and not asked.
    fn force_jacobians(
        &self,
        q: &OVector<f64, Self::Dof>,
        qd: &OVector<f64, Self::Dof>,
        inputs: &Inputs<Self::Dof, Self::Space>,
        dq: &mut OMatrix<f64, Self::Dof, Self::Dof>,
        dqd: &mut OMatrix<f64, Self::Dof, Self::Dof>,
        dp: &mut OMatrix<f64, Self::Dof, Self::Space>,
    );

    /// `q̈` and its Jacobians by `q`, `q̇`, `σ` and `p̈` (module docs), from one Cholesky
    /// factorisation of `M` (`q̈` by [`Model::factor_and_solve`], the default route of
    /// the accelerations, whatever route the model's own `accelerations` takes).
    ///
    /// Errors: those of [`Model::accelerations`].
    fn acceleration_jacobians(
        &self,
        q: &OVector<f64, Self::Dof>,
        qd: &OVector<f64, Self::Dof>,
        inputs: &Inputs<Self::Dof, Self::Space>,
        out: &mut Jacobians<Self>,
    ) -> Result<()> {
        // q̈ by the default route, whose factorisation of M the solves below reuse.
        let cholesky = self.factor_and_solve(q, qd, inputs, &mut out.accelerations)?;
        self.force_jacobians(q, qd, inputs, &mut out.q, &mut out.qd, &mut out.pivot);
        // out.torque is scratch for ∂(M q̈)/∂q until it receives M⁻¹.
        self.mass_matrix_partials(q, &out.accelerations, &mut out.torque);
        out.q -= &out.torque;
        cholesky.solve_mut(&mut out.q);
        cholesky.solve_mut(&mut out.qd);
        cholesky.solve_mut(&mut out.pivot);
        out.torque.fill_with_identity();
        cholesky.solve_mut(&mut out.torque);
        Ok(())
    }

    /// `q̈`, `∂q̈/∂q` and `∂q̈/∂q̇` into `out.accelerations`, `out.q` and `out.qd`: what
    /// an implicit integrator's Newton iteration needs. The rest of `out` is unspecified:
    /// the default computes it too (it is
    /// [`acceleration_jacobians`](Derivatives::acceleration_jacobians)); the planar
    /// tension routes skip it.
    ///
    /// Errors: those of [`Model::accelerations`].
    fn state_jacobians(
        &self,
        q: &OVector<f64, Self::Dof>,
        qd: &OVector<f64, Self::Dof>,
        inputs: &Inputs<Self::Dof, Self::Space>,
        out: &mut Jacobians<Self>,
    ) -> Result<()> {
        self.acceleration_jacobians(q, qd, inputs, out)
    }
}

/// Which of the Jacobians a route computes (`planar_tension_jacobians`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Parts {
    /// `∂q̈/∂q`, `∂q̈/∂q̇`, `∂q̈/∂σ` and `∂q̈/∂p̈`.
    All,
    /// `∂q̈/∂q` and `∂q̈/∂q̇` only ([`Derivatives::state_jacobians`]).
    State,
}

#[cfg(test)]
mod tests {
    use nalgebra::{DMatrix, DVector, Dim, DimName, Dyn};

    use super::*;
    use crate::chain::Chain;
    use crate::models::{Planar, Spatial};

    /// The central-difference Jacobian of `q̈` by the entries of the vector `pick` selects
    /// (0 = q, 1 = q̇, 2 = σ, 3 = p̈), step `h`.
    fn numeric<M: Model>(
        model: &M,
        q: &OVector<f64, M::Dof>,
        qd: &OVector<f64, M::Dof>,
        inputs: &Inputs<M::Dof, M::Space>,
        pick: usize,
    ) -> DMatrix<f64>
    where
        DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>,
    {
        let dof = model.dof().value();
        let cols = if pick == 3 { M::Space::dim() } else { dof };
        let h = 1e-6;
        let mut out = DMatrix::zeros(dof, cols);
        for x in 0..cols {
            let eval = |step: f64| {
                let (mut q, mut qd, mut inputs) = (q.clone(), qd.clone(), inputs.clone());
                match pick {
                    0 => q[x] += step,
                    1 => qd[x] += step,
                    2 => inputs.torque[x] += step,
                    _ => inputs.pivot_acceleration[x] += step,
                }
                let mut a = OVector::zeros_generic(model.dof(), U1);
                model.accelerations(&q, &qd, &inputs, &mut a).unwrap();
                a
            };
            let column = (eval(h) - eval(-h)) / (2.0 * h);
            out.column_mut(x).copy_from_slice(column.as_slice());
        }
        out
    }

    fn agrees<M>(model: &M, q: &[f64], qd: &[f64], torque: &[f64], pivot: &[f64])
    where
        M: Derivatives + Model<Dof = Dyn>,
        DefaultAllocator: ModelAlloc<M::Links, Dyn, M::Space> + Allocator<Dyn, M::Space>,
    {
        let (q, qd) = (DVector::from_row_slice(q), DVector::from_row_slice(qd));
        let inputs = Inputs::<Dyn, M::Space> {
            torque: DVector::from_row_slice(torque),
            pivot_acceleration: OVector::from_iterator_generic(M::Space::name(), U1, pivot.iter().copied()),
        };
        let mut jac = Jacobians::zeros(model);
        model.acceleration_jacobians(&q, &qd, &inputs, &mut jac).unwrap();
        let analytic: [DMatrix<f64>; 4] = [
            DMatrix::from_column_slice(q.len(), q.len(), jac.q.as_slice()),
            DMatrix::from_column_slice(q.len(), q.len(), jac.qd.as_slice()),
            DMatrix::from_column_slice(q.len(), q.len(), jac.torque.as_slice()),
            DMatrix::from_column_slice(q.len(), M::Space::dim(), jac.pivot.as_slice()),
        ];
        for (pick, a) in analytic.iter().enumerate() {
            let n = numeric(model, &q, &qd, &inputs, pick);
            let scale = n.amax().max(1.0);
            assert!((a - &n).amax() < 1e-6 * scale, "by {pick}: analytic {a} numeric {n}");
        }
    }

    #[test]
    fn planar_jacobians_agree_with_central_differences() {
        let chain = Chain::<Dyn>::new(&[1.0, 0.5, 2.0], &[0.7, 1.2, 0.4], 9.81)
            .unwrap()
            .with_damping(&[0.1, 0.2, 0.3])
            .unwrap();
        let model = Planar::new(chain);
        agrees(&model, &[0.4, -1.3, 2.2], &[1.5, -0.7, 2.1], &[0.3, -0.2, 0.5], &[1.1, -2.0]);
    }

    #[test]
    fn spatial_jacobians_agree_with_central_differences() {
        let chain = Chain::<Dyn>::new(&[1.0, 0.5, 2.0], &[0.7, 1.2, 0.4], 9.81)
            .unwrap()
            .with_damping(&[0.1, 0.2, 0.3])
            .unwrap();
        let model = Spatial::new(chain);
        agrees(
            &model,
            &[0.9, 1.7, 2.3, 0.2, -1.0, 2.8],
            &[1.5, -0.7, 2.1, 0.4, 1.2, -0.9],
            &[0.3, -0.2, 0.5, 0.1, 0.0, -0.4],
            &[1.1, -2.0, 0.6],
        );
    }
}
