//! The error measures of `verify` and their bound: an entry's error relative to its
//! floored absolute scale, and the componentwise backward error of accelerations.

use nalgebra::{DMatrix, DVector};

/// Largest error [`verify`](super::run) accepts, for every entry of every quantity: the
/// entry's `|x_impl − x_ref|` over its absolute scale ([`Scaled`]) floored by
/// [`SCALE_FLOOR`], and for accelerations the componentwise backward error
/// ([`acceleration_error`]).
///
/// Round-off of correct code stays decades below it, a wrong or missing term decades
/// above: see `docs/verify.md`, "Why the bounds are what they are".
///
/// [`Scaled`]: crate::expr::Scaled
pub const BOUND: f64 = 1e-10;

/// The floor of an entry's scale, as a fraction of its quantity's natural scale `N`.
///
/// An entry's error is `|x_impl − x_ref| / max(s, SCALE_FLOOR · N)`, `s` the entry's
/// absolute scale and `N` the largest scale among the quantity's entries (for the
/// velocity terms and the kinetic energy at least `‖S(M)‖_∞ ‖q̇‖²_∞`). The floor keeps the
/// round-off of terms the reference cancels symbolically but a model computes (the zero
/// `M[θ_i][φ_i]` of the generic spatial model) from counting as an error: see
/// `docs/verify.md`, "Why the bounds are what they are".
pub const SCALE_FLOOR: f64 = 1e-4;

/// Whether `a` is worse than `b`: larger, or NaN.
pub(super) fn worse(a: f64, b: f64) -> bool {
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
pub(super) fn row_sum_norm(a: &DMatrix<f64>) -> f64 {
    a.row_iter().map(|r| r.iter().map(|x| x.abs()).sum::<f64>()).fold(0.0, f64::max)
}

/// The error of `got` against `want`, entry-wise: `|got − want| / max(scale, floor)`
/// (infinite for a non-finite difference); the worst entry's index and error.
pub(super) fn entry_errors(got: &[f64], want: &[f64], scales: &[f64], floor: f64) -> (usize, f64) {
    let mut worst = (0, 0.0);
    for (i, ((g, w), s)) in got.iter().zip(want).zip(scales).enumerate() {
        let error = ratio((g - w).abs(), s.max(floor));
        if worse(error, worst.1) {
            worst = (i, error);
        }
    }
    worst
}

/// The componentwise backward error of accelerations `a` for the reference system
/// `M a = rhs`, row by row (Oettli–Prager),
///
/// ```text
/// max_i |M a − rhs|_i / (S(M) |a| + S(rhs))_i
/// ```
///
/// with `S(·)` the entry scales, `S(rhs) = S(Q) + S(c) + S(k) + S(d)`: the smallest
/// relative perturbation of every entry of `M` and `rhs` (relative to its own scale) for
/// which `a` is exact. Each row is measured against its own scale, so an error confined
/// to a light or short link's row is not diluted by the heavy links' rows. Returns the
/// worst row, its error and its residual. Why a backward error, and scales rather than
/// values: see `docs/verify.md`, "Why the bounds are what they are".
pub fn acceleration_error(
    mass_scale: &DMatrix<f64>,
    rhs_scale: &DVector<f64>,
    mass_matrix: &DMatrix<f64>,
    rhs: &DVector<f64>,
    a: &DVector<f64>,
) -> (usize, f64, f64) {
    backward_error(mass_scale, rhs_scale, mass_matrix, rhs, a, 0.0)
}

/// [`acceleration_error`] with each row's scale floored by `floor`.
fn backward_error(
    mass_scale: &DMatrix<f64>,
    rhs_scale: &DVector<f64>,
    mass_matrix: &DMatrix<f64>,
    rhs: &DVector<f64>,
    a: &DVector<f64>,
    floor: f64,
) -> (usize, f64, f64) {
    let residual = mass_matrix * a - rhs;
    let scale = mass_scale * a.abs() + rhs_scale;
    let mut worst = (0, 0.0, 0.0);
    for (i, (r, s)) in residual.iter().zip(scale.iter()).enumerate() {
        let error = ratio(r.abs(), s.max(floor));
        if worse(error, worst.1) {
            worst = (i, error, r.abs());
        }
    }
    worst
}

/// [`acceleration_error`] of every column of a Jacobian `J` for the reference systems
/// `M J = R` (one right-hand side per column, with its own entry scales): the worst
/// column, its row, error and residual.
///
/// Each row's scale is floored by [`SCALE_FLOOR`] times the column's natural scale
/// `‖S(M)‖_∞ ‖J_x‖_∞ + ‖S(R_x)‖_∞`: a row whose reference entries all cancel
/// symbolically (the zero `M[φ_1][θ_1]` against a torque on `θ_1`) has scale zero, while a
/// model computes its zeros with round-off.
pub fn jacobian_error(
    mass_scale: &DMatrix<f64>,
    rhs_scale: &DMatrix<f64>,
    mass_matrix: &DMatrix<f64>,
    rhs: &DMatrix<f64>,
    jacobian: &DMatrix<f64>,
) -> (usize, usize, f64, f64) {
    let mut worst = (0, 0, 0.0, 0.0);
    for x in 0..jacobian.ncols() {
        let (column, column_scale) = (jacobian.column(x).into_owned(), rhs_scale.column(x).into_owned());
        let floor = SCALE_FLOOR * (row_sum_norm(mass_scale) * column.amax() + column_scale.amax());
        let (row, error, residual) = backward_error(
            mass_scale,
            &column_scale,
            mass_matrix,
            &rhs.column(x).into_owned(),
            &column,
            floor,
        );
        if worse(error, worst.2) {
            worst = (x, row, error, residual);
        }
    }
    worst
}

#[cfg(test)]
mod tests {
    use super::*;

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
    fn acceleration_error_is_the_worst_relative_row_residual() {
        let m = DMatrix::from_row_slice(2, 2, &[2.0, 1.0, 1.0, 3.0]);
        let rhs = DVector::from_vec(vec![1.0, 2.0]);
        let rhs_scale = DVector::from_vec(vec![3.0, 2.0]);
        let exact = m.clone().lu().solve(&rhs).unwrap();
        assert!(acceleration_error(&m, &rhs_scale, &m, &rhs, &exact).1 < 1e-16);
        let wrong = &exact + DVector::from_vec(vec![0.0, 0.1]);
        let (row, error, residual) = acceleration_error(&m, &rhs_scale, &m, &rhs, &wrong);
        // Residual (0.1, 0.3); row scales (2|a_0| + |a_1| + 3, |a_0| + 3|a_1| + 2).
        assert_eq!(row, 1);
        assert!((residual - 0.3).abs() < 1e-15);
        assert!((error - 0.3 / (wrong[0].abs() + 3.0 * wrong[1].abs() + 2.0)).abs() < 1e-15);
        let nan = DVector::from_vec(vec![f64::NAN, 0.0]);
        assert_eq!(acceleration_error(&m, &rhs_scale, &m, &rhs, &nan).1, f64::INFINITY);
    }

    #[test]
    fn a_light_row_is_measured_against_its_own_scale() {
        // A heavy and a light link: the light row's scale is 1e-6 of the heavy one's.
        let m = DMatrix::from_row_slice(2, 2, &[1.0, 1e-6, 1e-6, 1e-6]);
        let rhs = DVector::from_vec(vec![1.0, 2e-6]);
        let exact = m.clone().lu().solve(&rhs).unwrap();
        let mut wrong = exact.clone();
        wrong[1] *= 1.0 + 1e-6;
        let rhs_scale = rhs.abs();
        let (row, error, _) = acceleration_error(&m.abs(), &rhs_scale, &m, &rhs, &wrong);
        assert_eq!(row, 1);
        // The light row's own relative residual, ~1e-6 / 4; a normwise measure
        // (‖r‖_∞ / (‖M‖_∞ ‖a‖_∞ + ‖rhs‖_∞)) would report ~1e-12.
        assert!(error > 1e-7, "{error:e}");
        let normwise = (&m * &wrong - &rhs).amax() / (row_sum_norm(&m) * wrong.amax() + rhs.amax());
        assert!(normwise < 1e-11, "{normwise:e}");
    }
}
