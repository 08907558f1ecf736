//! The chain linearised about a steady state: the first-order system `x = (q, q̇)`,
//!
//! ```text
//! δx' = A δx + B_σ δσ + B_p δp̈,   A = [[0, I], [∂q̈/∂q, ∂q̈/∂q̇]],
//! B_σ = [[0], [M⁻¹]],   B_p = [[0], [∂q̈/∂p̈]],
//! ```
//!
//! from the model's analytic [`Derivatives`], at a state where `q̈ = 0`: an equilibrium
//! (`q̇ = 0`, the chain hanging, inverted, or held by constant torques and a constant
//! pivot acceleration) or a steady rotation (constant rates, e.g. the spatial chain
//! turning rigidly at `φ̇_i = ω`: the equations depend on the azimuths only through their
//! differences, so `A` is the same all along it).

use nalgebra::{Complex, DMatrix, DefaultAllocator, DimName, OVector, allocator::Allocator};

use crate::error::{Error, Result};
use crate::jacobians::{Derivatives, Jacobians};
use crate::model::{Inputs, ModelAlloc};

/// Default bound on `|q̈|` (rad/s²) for a state to count as steady.
pub const STEADY_TOLERANCE: f64 = 1e-8;

/// The linearisation of [`linearize`].
#[derive(Debug, Clone, PartialEq)]
pub struct StateSpace {
    /// `A`, 2·dof × 2·dof (1/s, 1/s² blocks).
    pub a: DMatrix<f64>,
    /// `B_σ`, 2·dof × dof: the torques' inputs (1/(kg·m²)).
    pub b_torque: DMatrix<f64>,
    /// `B_p`, 2·dof × space: the pivot acceleration's inputs (1/m).
    pub b_pivot: DMatrix<f64>,
    /// The eigenvalues of `A` (1/s), by decreasing real part.
    pub eigenvalues: Vec<Complex<f64>>,
    /// `max |q̈_i|` at the state (rad/s²): how far from steady it is.
    pub residual: f64,
}

impl StateSpace {
    /// The largest real part among the eigenvalues (1/s): positive means unstable.
    pub fn growth_rate(&self) -> f64 {
        self.eigenvalues.first().map_or(f64::NEG_INFINITY, |e| e.re)
    }
}

/// Linearises `model` about `(q, q̇)` with `inputs` held: [`StateSpace`].
///
/// Errors: those of the model's accelerations, and [`Error::NotSteady`] when some
/// `|q̈_i|` exceeds `tolerance` (pass `f64::INFINITY` to linearise anywhere: `A` is then
/// the Jacobian along a trajectory through the state, not of a steady motion).
pub fn linearize<M: Derivatives>(
    model: &M,
    q: &OVector<f64, M::Dof>,
    qd: &OVector<f64, M::Dof>,
    inputs: &Inputs<M::Dof, M::Space>,
    tolerance: f64,
) -> Result<StateSpace>
where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space> + Allocator<M::Dof, M::Space>,
{
    let mut jac = Jacobians::zeros(model);
    model.acceleration_jacobians(q, qd, inputs, &mut jac)?;
    let (index, residual) = jac
        .accelerations
        .iter()
        .map(|a| a.abs())
        .enumerate()
        .fold((0, 0.0), |w, (i, a)| if a > w.1 { (i, a) } else { w });
    if residual > tolerance {
        return Err(Error::NotSteady { index, value: jac.accelerations[index], tolerance });
    }
    let n = q.len();
    let mut a = DMatrix::zeros(2 * n, 2 * n);
    jac.first_order::<nalgebra::Dyn>(&mut a);
    // B = [[0], [∂q̈/∂u]] for an input u.
    let below = |m: &[f64], cols: usize| {
        let mut b = DMatrix::zeros(2 * n, cols);
        b.view_mut((n, 0), (n, cols)).copy_from_slice(m);
        b
    };
    let b_torque = below(jac.torque.as_slice(), n);
    let b_pivot = below(jac.pivot.as_slice(), M::Space::dim());
    let eigenvalues = spectrum(&a);
    Ok(StateSpace { a, b_torque, b_pivot, eigenvalues, residual })
}

/// The eigenvalues of `a` (1/s) by decreasing real part (then imaginary part).
pub fn spectrum(a: &DMatrix<f64>) -> Vec<Complex<f64>> {
    let mut eigenvalues: Vec<Complex<f64>> = a.complex_eigenvalues().iter().copied().collect();
    eigenvalues.sort_by(|x, y| y.re.total_cmp(&x.re).then(y.im.total_cmp(&x.im)));
    eigenvalues
}

#[cfg(test)]
mod tests {
    use nalgebra::{DVector, Dyn};

    use super::*;
    use crate::chain::Chain;
    use crate::model::Model;
    use crate::models::Planar;

    #[test]
    fn a_hanging_pendulum_oscillates_at_sqrt_g_over_l_and_the_inverted_one_falls() {
        let model = Planar::new(Chain::<Dyn>::new(&[2.0], &[0.5], 9.81).unwrap());
        let rest = |theta: f64| {
            linearize(
                &model,
                &DVector::from_vec(vec![theta]),
                &DVector::zeros(1),
                &model.zero_inputs(),
                STEADY_TOLERANCE,
            )
            .unwrap()
        };
        let w = (9.81f64 / 0.5).sqrt();
        let hanging = rest(0.0);
        assert!(hanging.eigenvalues.iter().all(|e| e.re.abs() < 1e-12 && (e.im.abs() - w).abs() < 1e-12));
        let inverted = rest(std::f64::consts::PI);
        assert!((inverted.growth_rate() - w).abs() < 1e-12, "{:?}", inverted.eigenvalues);
        // θ̈ = σ/(m l²) − p̈_x cos θ / l: B at the hanging rest.
        assert!((hanging.b_torque[(1, 0)] - 1.0 / (2.0 * 0.25)).abs() < 1e-15);
        assert!((hanging.b_pivot[(1, 0)] + 1.0 / 0.5).abs() < 1e-15);
        assert_eq!(hanging.b_pivot[(0, 0)], 0.0);
    }

    #[test]
    fn a_state_that_is_not_steady_is_refused_by_its_acceleration() {
        let model = Planar::new(Chain::<Dyn>::uniform(2, 1.0, 1.0, 9.81).unwrap());
        let q = DVector::from_vec(vec![0.0, 0.3]);
        let err =
            linearize(&model, &q, &DVector::zeros(2), &model.zero_inputs(), STEADY_TOLERANCE).unwrap_err();
        assert!(matches!(err, Error::NotSteady { index: 1, .. }), "{err}");
        assert!(linearize(&model, &q, &DVector::zeros(2), &model.zero_inputs(), f64::INFINITY).is_ok());
    }
}
