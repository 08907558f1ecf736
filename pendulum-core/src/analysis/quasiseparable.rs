//! Quasiseparable matrices: an `N × N` matrix whose strictly lower and strictly upper
//! parts have rank-`R` generators,
//!
//! ```text
//! Q_ij = X_i · Y_j   (i > j),      Q_ii = d_i,      Q_ij = P_i · Z_j   (i < j),
//! ```
//!
//! (`X_i, Y_j, P_i, Z_j ∈ ℝ^R`). The chain's mass, gyroscopic and stiffness matrices in the
//! turning frame have this form with `R = 3` (`W_ab = M_max(a,b) l_a l_b`: the tail mass
//! of the lower link times a product), so products, LU factors, solves and (for a
//! symmetric matrix) the inertia cost `O(N R²)` instead of `O(N³)`.
//!
//! The LU factorisation is Gaussian elimination without pivoting, which keeps the form:
//! after eliminating `0 … k−1` the remaining matrix is the same with `Y_j → Y_j − Σ_k Z_j`,
//! `P_i → P_i − X_i Σ_k`, `d_i → d_i − X_i Σ_k Z_j` for one `R × R` matrix
//! `Σ_{k+1} = Σ_k + Ỹ_k P̃_kᵀ / p_k`. For a symmetric matrix (`P = Y`, `Z = X`) the pivots
//! `p_k` are those of `L D Lᵀ`, and by Sylvester's law their signs are the signs of the
//! eigenvalues.

/// A quasiseparable matrix of generator rank `R` (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Quasiseparable<const R: usize> {
    /// `d_i`.
    pub diagonal: Vec<f64>,
    /// `X_i` (rows of the strictly lower part).
    pub lower_rows: Vec<[f64; R]>,
    /// `Y_j` (columns of the strictly lower part).
    pub lower_columns: Vec<[f64; R]>,
    /// `P_i` (rows of the strictly upper part).
    pub upper_rows: Vec<[f64; R]>,
    /// `Z_j` (columns of the strictly upper part).
    pub upper_columns: Vec<[f64; R]>,
}

/// The LU factors of a [`Quasiseparable`] matrix (module docs).
#[derive(Debug, Clone)]
pub struct Factor<const R: usize> {
    pivots: Vec<f64>,
    lower_rows: Vec<[f64; R]>,
    reduced_columns: Vec<[f64; R]>,
    reduced_rows: Vec<[f64; R]>,
    upper_columns: Vec<[f64; R]>,
}

fn dot<const R: usize>(a: &[f64; R], b: &[f64; R]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

impl<const R: usize> Quasiseparable<R> {
    /// The size `N`.
    pub fn size(&self) -> usize {
        self.diagonal.len()
    }

    /// `y = Q x` in `O(N R)`.
    pub fn mul(&self, x: &[f64], y: &mut [f64]) {
        let n = self.size();
        let mut below = [0.0; R];
        for i in 0..n {
            y[i] = self.diagonal[i] * x[i] + dot(&self.lower_rows[i], &below);
            for (b, c) in below.iter_mut().zip(&self.lower_columns[i]) {
                *b += c * x[i];
            }
        }
        let mut above = [0.0; R];
        for i in (0..n).rev() {
            y[i] += dot(&self.upper_rows[i], &above);
            for (a, z) in above.iter_mut().zip(&self.upper_columns[i]) {
                *a += z * x[i];
            }
        }
    }

    /// The dense matrix (for tests).
    #[cfg(test)]
    pub fn dense(&self) -> nalgebra::DMatrix<f64> {
        let n = self.size();
        nalgebra::DMatrix::from_fn(n, n, |i, j| match i.cmp(&j) {
            std::cmp::Ordering::Greater => dot(&self.lower_rows[i], &self.lower_columns[j]),
            std::cmp::Ordering::Less => dot(&self.upper_rows[i], &self.upper_columns[j]),
            std::cmp::Ordering::Equal => self.diagonal[i],
        })
    }

    /// LU without pivoting in `O(N R²)`; `None` when a pivot is zero or not finite.
    pub fn factor(&self) -> Option<Factor<R>> {
        let n = self.size();
        let mut sigma = [[0.0; R]; R];
        let mut pivots = Vec::with_capacity(n);
        let mut reduced_columns = Vec::with_capacity(n);
        let mut reduced_rows = Vec::with_capacity(n);
        for k in 0..n {
            let (x, z) = (&self.lower_rows[k], &self.upper_columns[k]);
            // Σ Z_k and X_k Σ.
            let mut sz = [0.0; R];
            let mut xs = [0.0; R];
            for a in 0..R {
                for b in 0..R {
                    sz[a] += sigma[a][b] * z[b];
                    xs[b] += x[a] * sigma[a][b];
                }
            }
            let pivot = self.diagonal[k] - dot(x, &sz);
            if pivot == 0.0 || !pivot.is_finite() {
                return None;
            }
            let mut y = self.lower_columns[k];
            let mut p = self.upper_rows[k];
            for a in 0..R {
                y[a] -= sz[a];
                p[a] -= xs[a];
            }
            for a in 0..R {
                for b in 0..R {
                    sigma[a][b] += y[a] * p[b] / pivot;
                }
            }
            pivots.push(pivot);
            reduced_columns.push(y);
            reduced_rows.push(p);
        }
        Some(Factor {
            pivots,
            lower_rows: self.lower_rows.clone(),
            reduced_columns,
            reduced_rows,
            upper_columns: self.upper_columns.clone(),
        })
    }
}

impl<const R: usize> Factor<R> {
    /// The pivots `p_k` (`U`'s diagonal; `D` of `L D Lᵀ` for a symmetric matrix).
    pub fn pivots(&self) -> &[f64] {
        &self.pivots
    }

    /// Solves `Q x = b` in place in `O(N R)`.
    pub fn solve(&self, b: &mut [f64]) {
        let n = self.pivots.len();
        let mut acc = [0.0; R];
        for (i, bi) in b.iter_mut().enumerate().take(n) {
            *bi -= dot(&self.lower_rows[i], &acc);
            let scaled = *bi / self.pivots[i];
            for (a, y) in acc.iter_mut().zip(&self.reduced_columns[i]) {
                *a += y * scaled;
            }
        }
        let mut acc = [0.0; R];
        for k in (0..n).rev() {
            b[k] = (b[k] - dot(&self.reduced_rows[k], &acc)) / self.pivots[k];
            for (a, z) in acc.iter_mut().zip(&self.upper_columns[k]) {
                *a += z * b[k];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};

    fn random(n: usize, seed: u64, symmetric: bool) -> Quasiseparable<2> {
        let mut state = seed;
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let mut generators = |n: usize| -> Vec<[f64; 2]> { (0..n).map(|_| [next(), next()]).collect() };
        let (x, y) = (generators(n), generators(n));
        let (p, z) = if symmetric { (y.clone(), x.clone()) } else { (generators(n), generators(n)) };
        let diagonal =
            (0..n).map(|i| 2.0 + (i % 3) as f64 * 0.5 - if i % 4 == 0 { 4.0 } else { 0.0 }).collect();
        Quasiseparable { diagonal, lower_rows: x, lower_columns: y, upper_rows: p, upper_columns: z }
    }

    #[test]
    fn product_and_solve_match_the_dense_matrix() {
        let q = random(17, 7, false);
        let dense = q.dense();
        let x: Vec<f64> = (0..17).map(|i| (i as f64 * 0.37).sin()).collect();
        let mut y = vec![0.0; 17];
        q.mul(&x, &mut y);
        let expected = &dense * DVector::from_column_slice(&x);
        for i in 0..17 {
            assert!((y[i] - expected[i]).abs() < 1e-13, "row {i}");
        }
        let mut b = y.clone();
        q.factor().unwrap().solve(&mut b);
        for i in 0..17 {
            assert!((b[i] - x[i]).abs() < 1e-10, "{i}: {} {}", b[i], x[i]);
        }
    }

    #[test]
    fn pivots_of_a_symmetric_matrix_count_its_negative_eigenvalues() {
        for seed in 1..20 {
            let q = random(23, seed, true);
            let dense: DMatrix<f64> = q.dense();
            assert!((&dense - dense.transpose()).amax() < 1e-15);
            let negative = dense.symmetric_eigenvalues().iter().filter(|&&v| v < 0.0).count();
            let pivots = q.factor().unwrap();
            assert_eq!(pivots.pivots().iter().filter(|&&p| p < 0.0).count(), negative, "seed {seed}");
        }
    }
}
