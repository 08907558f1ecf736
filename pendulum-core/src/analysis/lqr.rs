//! The continuous-time linear-quadratic regulator: the gain `K = R⁻¹ Bᵀ P` minimising
//! `∫ (xᵀ Q x + uᵀ R u) dt` for `x' = A x + B u`, with `P` the stabilising solution of the
//! algebraic Riccati equation `Aᵀ P + P A − P B R⁻¹ Bᵀ P + Q = 0`.
//!
//! `P` comes from the stable invariant subspace of the Hamiltonian matrix
//! `H = [[A, −B R⁻¹ Bᵀ], [−Q, −Aᵀ]]`, found by the matrix sign function (Newton's iteration
//! `Z ← (c Z + (c Z)⁻¹)/2` with determinant scaling `c = |det Z|^{−1/2n}`): the subspace is
//! the null space of `sign(H) + I`, spanned by `[I; P]`.

use nalgebra::{Complex, DMatrix};

use super::state_space::spectrum;

use crate::error::{Error, Result};

/// The LQR design of [`lqr`].
#[derive(Debug, Clone, PartialEq)]
pub struct Lqr {
    /// The gain `K` (inputs × states): the control is `u = −K x`.
    pub gain: DMatrix<f64>,
    /// The Riccati solution `P` (states × states), symmetric positive semi-definite.
    pub riccati: DMatrix<f64>,
    /// `max |Aᵀ P + P A − P B R⁻¹ Bᵀ P + Q|` relative to `max |Q|`.
    pub residual: f64,
    /// The eigenvalues of the closed loop `A − B K` (1/s), by decreasing real part.
    pub closed_loop: Vec<Complex<f64>>,
}

fn fail(reason: impl Into<String>) -> Error {
    Error::Riccati { reason: reason.into() }
}

/// The LQR gain for `(A, B)` with weights `Q` (states) and `R` (inputs).
///
/// Errors ([`Error::Riccati`]) for mismatched sizes, an `R` that is not positive definite,
/// and a pair `(A, B)` with no stabilising solution (not stabilisable, or modes on the
/// imaginary axis that `Q` does not see): the sign iteration then does not converge or the
/// closed loop is not stable.
pub fn lqr(a: &DMatrix<f64>, b: &DMatrix<f64>, q: &DMatrix<f64>, r: &DMatrix<f64>) -> Result<Lqr> {
    let n = a.nrows();
    let m = b.ncols();
    if a.ncols() != n || b.nrows() != n || q.shape() != (n, n) || r.shape() != (m, m) {
        return Err(fail(format!(
            "sizes do not fit: A {:?}, B {:?}, Q {:?}, R {:?}",
            a.shape(),
            b.shape(),
            q.shape(),
            r.shape()
        )));
    }
    let r_inverse = r.clone().cholesky().ok_or_else(|| fail("R is not positive definite"))?.inverse();
    let s = b * &r_inverse * b.transpose();
    let mut z = DMatrix::zeros(2 * n, 2 * n);
    z.view_mut((0, 0), (n, n)).copy_from(a);
    z.view_mut((0, n), (n, n)).copy_from(&-&s);
    z.view_mut((n, 0), (n, n)).copy_from(&-q);
    z.view_mut((n, n), (n, n)).copy_from(&-a.transpose());
    let mut converged = false;
    for _ in 0..100 {
        let lu = z.clone().lu();
        let det = lu.determinant();
        let inverse =
            lu.try_inverse().ok_or_else(|| fail("the Hamiltonian has eigenvalues on the imaginary axis"))?;
        let c = if det.is_finite() && det != 0.0 { det.abs().powf(-1.0 / (2 * n) as f64) } else { 1.0 };
        let next = (&z * c + inverse / c) * 0.5;
        let change = (&next - &z).amax() / next.amax().max(1.0);
        z = next;
        if change < 1e-13 {
            converged = true;
            break;
        }
    }
    if !converged || !z.iter().all(|x| x.is_finite()) {
        return Err(fail(
            "the sign iteration did not converge: (A, B) is not stabilisable with these weights",
        ));
    }
    // [W12; W22 + I] P = −[W11 + I; W21], least squares (the system is consistent).
    let mut lhs = DMatrix::zeros(2 * n, n);
    lhs.view_mut((0, 0), (n, n)).copy_from(&z.view((0, n), (n, n)));
    lhs.view_mut((n, 0), (n, n)).copy_from(&(z.view((n, n), (n, n)) + DMatrix::identity(n, n)));
    let mut rhs = DMatrix::zeros(2 * n, n);
    rhs.view_mut((0, 0), (n, n)).copy_from(&-(z.view((0, 0), (n, n)) + DMatrix::identity(n, n)));
    rhs.view_mut((n, 0), (n, n)).copy_from(&-z.view((n, 0), (n, n)));
    let p = lhs.svd(true, true).solve(&rhs, 1e-14).map_err(|e| fail(e.to_string()))?;
    let p = (&p + p.transpose()) * 0.5;
    let gain = &r_inverse * b.transpose() * &p;
    let care = a.transpose() * &p + &p * a - &p * &s * &p + q;
    let residual = care.amax() / q.amax().max(f64::MIN_POSITIVE);
    let closed_loop = spectrum(&(a - b * &gain));
    let unstable = closed_loop.first().map_or(f64::NEG_INFINITY, |e| e.re);
    let stabilised = unstable < 0.0 && residual < 1e-6;
    if !stabilised {
        return Err(fail(format!(
            "no stabilising solution (closed-loop growth rate {unstable:e} 1/s, Riccati residual {residual:e})"
        )));
    }
    Ok(Lqr { gain, riccati: p, residual, closed_loop })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_double_integrator_has_its_textbook_gain() {
        // x'' = u with Q = I, R = 1: K = (1, √3).
        let a = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, 0.0, 0.0]);
        let b = DMatrix::from_row_slice(2, 1, &[0.0, 1.0]);
        let design = lqr(&a, &b, &DMatrix::identity(2, 2), &DMatrix::identity(1, 1)).unwrap();
        assert!((design.gain[(0, 0)] - 1.0).abs() < 1e-10, "{}", design.gain);
        assert!((design.gain[(0, 1)] - 3f64.sqrt()).abs() < 1e-10, "{}", design.gain);
        assert!(design.residual < 1e-12);
    }

    #[test]
    fn an_uncontrollable_unstable_mode_is_refused() {
        let a = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, -1.0]);
        let b = DMatrix::from_row_slice(2, 1, &[0.0, 1.0]);
        let err = lqr(&a, &b, &DMatrix::identity(2, 2), &DMatrix::identity(1, 1)).unwrap_err();
        assert!(matches!(err, Error::Riccati { .. }), "{err}");
        let err = lqr(&a, &b, &DMatrix::identity(2, 2), &DMatrix::from_element(1, 1, -1.0)).unwrap_err();
        assert!(err.to_string().contains("R is not positive definite"), "{err}");
    }
}
