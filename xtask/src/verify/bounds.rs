//! The error measures of `verify` and their bound: an entry's error relative to its
//! floored absolute scale, and the backward error of accelerations.

use nalgebra::{DMatrix, DVector};

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
