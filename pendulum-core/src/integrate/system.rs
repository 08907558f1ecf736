//! The first-order system `x' = f(t, x)` the integrators advance; it knows nothing of pendulums.

use nalgebra::{DefaultAllocator, Dim, OMatrix, OVector, U1, allocator::Allocator};

use crate::error::Result;

/// The allocator bounds a [`System`] of dimension `D` needs, in one name: vectors of `D`
/// entries and `D × D` Jacobians.
pub trait SystemAlloc<D: Dim>: Allocator<D> + Allocator<D, D> {}

impl<D: Dim, A> SystemAlloc<D> for A where A: Allocator<D> + Allocator<D, D> {}

/// A first-order ODE system `x' = f(t, x)` with state `x` of [`dim`](System::dim) entries.
///
/// The dimension is an associated type, `Const<N>` for fixed-size systems (the
/// integrators then work without heap allocation) and `Dyn` otherwise. Implementors
/// write into `&mut` outputs and may assume the vectors have `dim` entries (the
/// integrators check the state's length once per step).
pub trait System
where
    DefaultAllocator: SystemAlloc<Self::Dim>,
{
    /// Dimension of the state.
    type Dim: Dim;

    /// Dimension of the state as a value (`Const<N>` or `Dyn(n)`).
    fn dim(&self) -> Self::Dim;

    /// The right-hand side `f(t, x)`, written into `out`.
    ///
    /// Errors are the system's own (a model's coordinate singularity, say) and are passed
    /// on unchanged by the integrators. A NaN or infinite entry in `out` is not an error
    /// here; the integrators treat it as a failed step.
    fn rhs(&self, t: f64, x: &OVector<f64, Self::Dim>, out: &mut OVector<f64, Self::Dim>) -> Result<()>;

    /// `Some(m)` when the state starts with positions and velocities, `x = (q, v, …)` with
    /// `q` the first `m` entries, `v` the next `m` and `q' = v` (any further entries, such
    /// as an energy ledger, are free): [`GaussFixedPoint`](super::GaussFixedPoint) then
    /// keeps the stage positions exactly consistent with the stage velocities, which
    /// makes its iteration converge in fewer sweeps. Default `None`.
    fn second_order(&self) -> Option<usize> {
        None
    }

    /// The Jacobian `∂f/∂x (t, x)`, written into `out` (`out[(i, j)] = ∂f_i/∂x_j`).
    ///
    /// The default is [`central_difference_jacobian`]: `2·dim` evaluations of
    /// [`rhs`](System::rhs), relative accuracy about `1e-10`. Systems with an analytic
    /// Jacobian should override it. The implicit integrators use the Jacobian only to
    /// speed up their Newton iterations, so its accuracy affects the cost of a step, not
    /// its result.
    fn jacobian(
        &self,
        t: f64,
        x: &OVector<f64, Self::Dim>,
        out: &mut OMatrix<f64, Self::Dim, Self::Dim>,
    ) -> Result<()> {
        central_difference_jacobian(self, t, x, out)
    }
}

/// The Jacobian of `system` at `(t, x)` by central differences:
/// `J_ij ≈ (f_i(x + δ_j e_j) − f_i(x − δ_j e_j)) / (2 δ_j)`.
///
/// The step `δ_j = ε^{1/3} max(|x_j|, 1)` (`ε` the f64 machine epsilon, so
/// `δ_j ≈ 6·10⁻⁶` for `|x_j| ≤ 1`) balances the truncation error `O(δ²)` against the
/// round-off error `O(ε/δ)`, both then about `ε^{2/3} ≈ 4·10⁻¹¹` relative to the size of
/// `f` and its derivatives. The perturbed coordinates are formed first and the divisor
/// is taken from them, so the difference quotient uses the step actually taken.
///
/// Costs `2·dim` right-hand-side evaluations; allocates three vectors of `dim` entries
/// (on the stack for `Const<N>` dimensions).
pub fn central_difference_jacobian<S: System + ?Sized>(
    system: &S,
    t: f64,
    x: &OVector<f64, S::Dim>,
    out: &mut OMatrix<f64, S::Dim, S::Dim>,
) -> Result<()>
where
    DefaultAllocator: SystemAlloc<S::Dim>,
{
    let relative_step = f64::EPSILON.cbrt();
    let dim = system.dim();
    let mut xp = x.clone();
    let mut f_plus = OVector::<f64, S::Dim>::zeros_generic(dim, U1);
    let mut f_minus = OVector::<f64, S::Dim>::zeros_generic(dim, U1);
    for j in 0..x.len() {
        let xj = x[j];
        let step = relative_step * xj.abs().max(1.0);
        let (above, below) = (xj + step, xj - step);
        xp[j] = above;
        system.rhs(t, &xp, &mut f_plus)?;
        xp[j] = below;
        system.rhs(t, &xp, &mut f_minus)?;
        xp[j] = xj;
        let width = above - below;
        for i in 0..x.len() {
            out[(i, j)] = (f_plus[i] - f_minus[i]) / width;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use nalgebra::{Matrix2, U2, Vector2};

    use super::*;

    /// `x' = (x₁ x₂, sin x₁ + t)`.
    struct Curved;

    impl System for Curved {
        type Dim = U2;
        fn dim(&self) -> U2 {
            U2
        }
        fn rhs(&self, t: f64, x: &Vector2<f64>, out: &mut Vector2<f64>) -> Result<()> {
            *out = Vector2::new(x[0] * x[1], x[0].sin() + t);
            Ok(())
        }
    }

    #[test]
    fn central_differences_match_the_analytic_jacobian() {
        let x = Vector2::new(0.7, -2.5);
        let mut jac = Matrix2::zeros();
        Curved.jacobian(0.3, &x, &mut jac).unwrap();
        let exact = Matrix2::new(x[1], x[0], x[0].cos(), 0.0);
        assert!((jac - exact).amax() < 1e-9, "{jac} vs {exact}");
    }
}
