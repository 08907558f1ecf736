//! In-place LU factorisation with partial pivoting into buffers the integrator owns.
//!
//! nalgebra's `LU::new` takes its matrix by value and allocates a fresh permutation for
//! dynamic sizes on every factorisation; the Newton matrices of the implicit integrators
//! are refactored in the step loop, so this small routine factors in place instead.

use nalgebra::{DefaultAllocator, Dim, OMatrix, OVector, allocator::Allocator};

/// Factors `a` in place as `P a = L U` (unit lower `L` below the diagonal, `U` on and
/// above it), recording in `pivots[k]` the row swapped with row `k` at step `k`.
///
/// Returns `false` when a pivot column is zero or contains no finite non-zero entry
/// (singular or non-finite matrix); `a` is then garbage.
pub(crate) fn factor<N: Dim>(a: &mut OMatrix<f64, N, N>, pivots: &mut OVector<usize, N>) -> bool
where
    DefaultAllocator: Allocator<N, N> + Allocator<N>,
{
    let n = a.nrows();
    for k in 0..n {
        let (mut p, mut largest) = (k, a[(k, k)].abs());
        for i in k + 1..n {
            let v = a[(i, k)].abs();
            // Written so that a NaN never wins and a NaN `largest` is replaced.
            if v > largest || largest.is_nan() {
                (p, largest) = (i, v);
            }
        }
        if !(largest > 0.0 && largest.is_finite()) {
            return false;
        }
        pivots[k] = p;
        if p != k {
            a.swap_rows(k, p);
        }
        let inverse = 1.0 / a[(k, k)];
        for i in k + 1..n {
            a[(i, k)] *= inverse;
        }
        for j in k + 1..n {
            let akj = a[(k, j)];
            if akj != 0.0 {
                for i in k + 1..n {
                    a[(i, j)] -= a[(i, k)] * akj;
                }
            }
        }
    }
    true
}

/// Solves `A x = b` in place (`b` becomes `x`) from the factors [`factor`] left in `lu`.
pub(crate) fn solve<N: Dim>(lu: &OMatrix<f64, N, N>, pivots: &OVector<usize, N>, b: &mut OVector<f64, N>)
where
    DefaultAllocator: Allocator<N, N> + Allocator<N>,
{
    let n = lu.nrows();
    for k in 0..n {
        let p = pivots[k];
        if p != k {
            b.swap_rows(k, p);
        }
    }
    for j in 0..n {
        let bj = b[j];
        if bj != 0.0 {
            for i in j + 1..n {
                b[i] -= lu[(i, j)] * bj;
            }
        }
    }
    for j in (0..n).rev() {
        b[j] /= lu[(j, j)];
        let bj = b[j];
        for i in 0..j {
            b[i] -= lu[(i, j)] * bj;
        }
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

    use super::*;

    #[test]
    fn solves_a_system_that_needs_pivoting() {
        let a = Matrix3::new(0.0, 2.0, 1.0, 1.0, 1.0, 1.0, 4.0, -1.0, 3.0);
        let x = Vector3::new(1.0, -2.0, 0.5);
        let mut b = a * x;
        let (mut lu, mut pivots) = (a, Vector3::from_element(0usize));
        assert!(factor(&mut lu, &mut pivots));
        solve(&lu, &pivots, &mut b);
        assert!((b - x).amax() < 1e-15, "{b}");
    }

    #[test]
    fn dynamic_size_matches_nalgebra() {
        let n = 7;
        let a = DMatrix::from_fn(n, n, |i, j| {
            ((i * 7 + j * 3) % 11) as f64 - 5.0 + if i == j { 0.5 } else { 0.0 }
        });
        let b = DVector::from_fn(n, |i, _| i as f64 - 2.0);
        let expected = a.clone().lu().solve(&b).unwrap();
        let (mut lu, mut pivots, mut x) = (a, DVector::from_element(n, 0usize), b);
        assert!(factor(&mut lu, &mut pivots));
        solve(&lu, &pivots, &mut x);
        assert!((x - &expected).amax() < 1e-12 * expected.amax());
    }

    #[test]
    fn singular_and_nan_matrices_are_refused() {
        let mut pivots = Vector3::from_element(0usize);
        let mut singular = Matrix3::new(1.0, 2.0, 3.0, 2.0, 4.0, 6.0, 0.0, 1.0, 1.0);
        assert!(!factor(&mut singular, &mut pivots));
        let mut nan = Matrix3::from_element(f64::NAN);
        assert!(!factor(&mut nan, &mut pivots));
    }
}
