//! The zeros of the Laguerre polynomials `L_n`, for the exact frequencies of a chain of n
//! equal masses on equal rods: `ω_k = √((g/l) x_k)`, `x_k` the k-th zero of `L_n`.

use nalgebra::{DMatrix, SymmetricEigen};

/// `L_n(x)` and `L_n'(x)` by the three-term recurrence
/// `(k + 1) L_{k+1} = (2k + 1 − x) L_k − k L_{k−1}`, `x L_n' = n (L_n − L_{n−1})`.
fn laguerre(n: usize, x: f64) -> (f64, f64) {
    let (mut previous, mut current) = (0.0, 1.0);
    for k in 0..n {
        let next = ((2 * k + 1) as f64 - x) * current - k as f64 * previous;
        (previous, current) = (current, next / (k + 1) as f64);
    }
    (current, n as f64 * (current - previous) / x)
}

/// The n zeros of `L_n`, ascending (all positive). The eigenvalues of the Jacobi matrix
/// of the Laguerre weight (diagonal `2k + 1`, off-diagonal `k`; Golub–Welsch), each
/// polished by Newton steps on the recurrence while it stays finite (to n ≈ 250): a sign
/// change of `L_n` within 1e-12 relative of each zero (tested to n = 100).
pub fn laguerre_zeros(n: usize) -> Vec<f64> {
    let jacobi = DMatrix::from_fn(n, n, |i, j| {
        if i == j {
            (2 * i + 1) as f64
        } else if i.abs_diff(j) == 1 {
            i.max(j) as f64
        } else {
            0.0
        }
    });
    let mut zeros: Vec<f64> = SymmetricEigen::new(jacobi).eigenvalues.iter().copied().collect();
    zeros.sort_by(f64::total_cmp);
    for x in &mut zeros {
        for _ in 0..3 {
            let (value, slope) = laguerre(n, *x);
            if slope != 0.0 && value.is_finite() && slope.is_finite() {
                *x -= value / slope;
            }
        }
    }
    zeros
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_orders_match_their_closed_forms() {
        // L_1 = 1 − x; L_2 = (x² − 4x + 2)/2: 2 ∓ √2.
        assert!((laguerre_zeros(1)[0] - 1.0).abs() < 1e-15);
        let z = laguerre_zeros(2);
        assert!((z[0] - (2.0 - 2f64.sqrt())).abs() < 1e-15 && (z[1] - (2.0 + 2f64.sqrt())).abs() < 1e-14);
    }

    #[test]
    fn zeros_are_roots_and_sum_to_n_squared() {
        // Σ x_k = trace of the Jacobi matrix = n²; each zero a sign change of L_n.
        for n in [3, 10, 100] {
            let z = laguerre_zeros(n);
            assert_eq!(z.len(), n);
            let sum: f64 = z.iter().sum();
            assert!((sum - (n * n) as f64).abs() < 1e-11 * (n * n) as f64, "n = {n}: Σ = {sum}");
            for &x in &z {
                let (below, above) = (laguerre(n, x * (1.0 - 1e-12)).0, laguerre(n, x * (1.0 + 1e-12)).0);
                assert!(below * above <= 0.0, "n = {n}: no sign change at {x}");
            }
        }
    }
}
