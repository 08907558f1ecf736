//! Block-tridiagonal linear systems: `n` block rows of `B × B` blocks, solved in `O(n B³)`
//! by block elimination (the block Thomas algorithm), each diagonal block factored with
//! partial pivoting.
//!
//! The Newton matrices of an implicit step of a chain are of this form when the unknowns
//! are ordered link by link (each link's mass position and rod multiplier, coupled only
//! to the neighbouring links), so an implicit step costs `O(n)` instead of the `O(n³)` of
//! a dense factorisation.

use nalgebra::{SMatrix, SVector};

/// A block-tridiagonal matrix with `B × B` blocks, row `i` holding `sub[i]` (columns of
/// block `i − 1`, unused for `i = 0`), `diag[i]` and `sup[i]` (columns of block `i + 1`,
/// unused for the last row). Fill the blocks, then [`factor`](Self::factor) and
/// [`solve`](Self::solve) as many right-hand sides as needed.
#[derive(Debug, Clone)]
pub struct BlockTridiagonal<const B: usize> {
    /// Sub-diagonal blocks.
    pub sub: Vec<SMatrix<f64, B, B>>,
    /// Diagonal blocks.
    pub diag: Vec<SMatrix<f64, B, B>>,
    /// Super-diagonal blocks.
    pub sup: Vec<SMatrix<f64, B, B>>,
    /// The factored pivots `D'_i = D_i − A_i D'⁻¹_{i−1} C_{i−1}`.
    pivots: Vec<SmallLu<B>>,
    /// `G_i = D'⁻¹_i C_i`.
    ahead: Vec<SMatrix<f64, B, B>>,
}

impl<const B: usize> BlockTridiagonal<B> {
    /// `n` block rows, all blocks zero.
    pub fn new(n: usize) -> Self {
        let zero = SMatrix::<f64, B, B>::zeros();
        Self {
            sub: vec![zero; n],
            diag: vec![zero; n],
            sup: vec![zero; n],
            pivots: Vec::with_capacity(n),
            ahead: vec![zero; n],
        }
    }

    /// Number of block rows.
    pub fn len(&self) -> usize {
        self.diag.len()
    }

    /// Whether there are no block rows.
    pub fn is_empty(&self) -> bool {
        self.diag.is_empty()
    }

    /// Eliminates the sub-diagonal, block row by block row. Returns `false` when a pivot
    /// block is singular or not finite (the system cannot be solved this way).
    pub fn factor(&mut self) -> bool {
        self.pivots.clear();
        for i in 0..self.len() {
            let mut pivot = self.diag[i];
            if i > 0 {
                pivot -= self.sub[i] * self.ahead[i - 1];
            }
            let Some(lu) = SmallLu::new(pivot) else { return false };
            if i + 1 < self.len() {
                self.ahead[i] = self.sup[i];
                lu.solve_columns(&mut self.ahead[i]);
            }
            self.pivots.push(lu);
        }
        true
    }

    /// Solves the factored system in place: `rhs` (one `B`-vector per block row) becomes
    /// the solution. Call after a successful [`factor`](Self::factor).
    pub fn solve(&self, rhs: &mut [SVector<f64, B>]) {
        let n = self.len();
        debug_assert_eq!(self.pivots.len(), n, "factor first");
        for i in 0..n {
            if i > 0 {
                let previous = rhs[i - 1];
                rhs[i] -= self.sub[i] * previous;
            }
            self.pivots[i].solve_mut(&mut rhs[i]);
        }
        for i in (0..n.saturating_sub(1)).rev() {
            let next = rhs[i + 1];
            rhs[i] -= self.ahead[i] * next;
        }
    }
}

/// A `B × B` block factored as `P A = L U` with partial pivoting (`L` unit lower, below
/// the diagonal; `U` on and above it; `swaps[k]` the row exchanged with row `k`).
#[derive(Debug, Clone)]
struct SmallLu<const B: usize> {
    lu: SMatrix<f64, B, B>,
    swaps: [usize; B],
}

impl<const B: usize> SmallLu<B> {
    /// `None` when a pivot column has no finite non-zero entry (singular or not finite).
    fn new(mut a: SMatrix<f64, B, B>) -> Option<Self> {
        let mut swaps = [0; B];
        for k in 0..B {
            let (mut p, mut largest) = (k, a[(k, k)].abs());
            for i in k + 1..B {
                let v = a[(i, k)].abs();
                if v > largest || largest.is_nan() {
                    (p, largest) = (i, v);
                }
            }
            if !(largest > 0.0 && largest.is_finite()) {
                return None;
            }
            swaps[k] = p;
            if p != k {
                a.swap_rows(k, p);
            }
            let inverse = 1.0 / a[(k, k)];
            for i in k + 1..B {
                a[(i, k)] *= inverse;
                let factor = a[(i, k)];
                for j in k + 1..B {
                    a[(i, j)] -= factor * a[(k, j)];
                }
            }
        }
        Some(Self { lu: a, swaps })
    }

    /// `X ← A⁻¹ X`, column by column in place.
    fn solve_columns(&self, x: &mut SMatrix<f64, B, B>) {
        for k in 0..B {
            x.swap_rows(k, self.swaps[k]);
        }
        for c in 0..B {
            for i in 0..B {
                let mut v = x[(i, c)];
                for j in 0..i {
                    v -= self.lu[(i, j)] * x[(j, c)];
                }
                x[(i, c)] = v;
            }
            for i in (0..B).rev() {
                let mut v = x[(i, c)];
                for j in i + 1..B {
                    v -= self.lu[(i, j)] * x[(j, c)];
                }
                x[(i, c)] = v / self.lu[(i, i)];
            }
        }
    }

    /// `b ← A⁻¹ b`.
    fn solve_mut(&self, b: &mut SVector<f64, B>) {
        for k in 0..B {
            b.swap_rows(k, self.swaps[k]);
        }
        for i in 0..B {
            for j in 0..i {
                b[i] -= self.lu[(i, j)] * b[j];
            }
        }
        for i in (0..B).rev() {
            for j in i + 1..B {
                b[i] -= self.lu[(i, j)] * b[j];
            }
            b[i] /= self.lu[(i, i)];
        }
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::{DMatrix, DVector};

    use super::*;

    /// A random-looking block-tridiagonal system with zero corners in its diagonal blocks
    /// (as the Newton matrices have: no multiplier in a constraint row) agrees with a
    /// dense solve.
    #[test]
    fn agrees_with_a_dense_solve() {
        const B: usize = 4;
        let n = 7;
        let mut m = BlockTridiagonal::<B>::new(n);
        let value = |i: usize, r: usize, c: usize, k: usize| ((i * 31 + r * 7 + c * 3 + k * 11) as f64).sin();
        let mut dense = DMatrix::zeros(n * B, n * B);
        for i in 0..n {
            for r in 0..B {
                for c in 0..B {
                    m.diag[i][(r, c)] = if r == B - 1 && c == B - 1 { 0.0 } else { value(i, r, c, 0) };
                    m.diag[i][(r, c)] += if r == c && r < B - 1 { 4.0 } else { 0.0 };
                    m.sub[i][(r, c)] = value(i, r, c, 1);
                    m.sup[i][(r, c)] = value(i, r, c, 2);
                    dense[(i * B + r, i * B + c)] = m.diag[i][(r, c)];
                    if i > 0 {
                        dense[(i * B + r, (i - 1) * B + c)] = m.sub[i][(r, c)];
                    }
                    if i + 1 < n {
                        dense[(i * B + r, (i + 1) * B + c)] = m.sup[i][(r, c)];
                    }
                }
            }
        }
        let b = DVector::from_fn(n * B, |k, _| (k as f64 * 0.7).cos());
        let expected = dense.lu().solve(&b).unwrap();
        assert!(m.factor());
        let mut x: Vec<SVector<f64, B>> = (0..n).map(|i| SVector::from_fn(|r, _| b[i * B + r])).collect();
        m.solve(&mut x);
        for i in 0..n {
            for r in 0..B {
                assert!((x[i][r] - expected[i * B + r]).abs() < 1e-12, "{i} {r}");
            }
        }
    }

    #[test]
    fn a_singular_pivot_is_reported() {
        let mut m = BlockTridiagonal::<2>::new(2);
        m.diag[0] = SMatrix::<f64, 2, 2>::new(1.0, 2.0, 2.0, 4.0);
        assert!(!m.factor());
    }
}
