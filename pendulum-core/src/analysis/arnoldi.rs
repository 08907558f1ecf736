//! The Arnoldi process for the dominant eigenvalues of a real linear operator `T` given
//! only by its action (with a shift-and-invert `T = (A − σ)⁻¹`, the eigenvalues of `A`
//! nearest `σ`).
//!
//! After `m` steps `T V_m = V_m H_m + h_{m+1,m} v_{m+1} e_mᵀ` with orthonormal `V_m`
//! (Gram–Schmidt twice) and Hessenberg `H_m`. A Ritz pair `(θ, x = V_m y)`, `H_m y = θ y`,
//! `|y| = 1`, has the residual `|T x − θ x| = |h_{m+1,m}| |y_m|` exactly; the eigenvector
//! `y` comes from inverse iteration on the Hessenberg `H_m − θ` (`O(m²)`), and its own
//! error is added to the residual reported. At `m = N` (or when `h_{m+1,m}` vanishes) the
//! Krylov space is invariant and every Ritz value is an eigenvalue.

use nalgebra::{Complex, DMatrix};

/// One Ritz pair of the operator (its vector from [`Arnoldi::vector`]).
#[derive(Debug, Clone)]
pub(crate) struct Ritz {
    /// The Ritz value `θ`.
    pub value: Complex<f64>,
    /// Its coordinates `y` in the Krylov basis, unit length.
    pub coefficients: Vec<Complex<f64>>,
    /// `|T x − θ x| / |θ|`, relative.
    pub residual: f64,
}

/// The Arnoldi process (module docs).
pub(crate) struct Arnoldi {
    dim: usize,
    basis: Vec<Vec<f64>>,
    /// `(m + 1) × m` Hessenberg, grown column by column.
    hessenberg: Vec<Vec<f64>>,
    invariant: bool,
    /// The operator returned a non-finite vector: nothing more is computed.
    broken: bool,
}

impl Arnoldi {
    /// Starts in dimension `dim` from a fixed pseudo-random vector (the same every time, so
    /// results do not depend on anything but the operator).
    pub fn new(dim: usize) -> Self {
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut start: Vec<f64> = (0..dim)
            .map(|_| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            })
            .collect();
        let norm = start.iter().map(|v| v * v).sum::<f64>().sqrt();
        start.iter_mut().for_each(|v| *v /= norm);
        Self { dim, basis: vec![start], hessenberg: Vec::new(), invariant: dim == 0, broken: false }
    }

    /// The number of steps taken.
    pub fn steps(&self) -> usize {
        self.hessenberg.len()
    }

    /// The Krylov space is invariant: the Ritz values are eigenvalues, nothing to add.
    pub fn complete(&self) -> bool {
        self.invariant
    }

    /// The operator gave a non-finite vector (a singular or overflowing solve): the caller
    /// must not trust the Ritz values and should take another route.
    pub fn broken(&self) -> bool {
        self.broken
    }

    /// Up to `steps` more steps with `apply(x, y)`: `y = T x`; stops early when complete
    /// or broken.
    pub fn extend(&mut self, steps: usize, apply: &mut impl FnMut(&[f64], &mut [f64])) {
        let mut w = vec![0.0; self.dim];
        for _ in 0..steps {
            if self.invariant || self.broken {
                return;
            }
            let j = self.hessenberg.len();
            apply(&self.basis[j], &mut w);
            if w.iter().any(|v| !v.is_finite()) {
                self.broken = true;
                return;
            }
            let scale = w.iter().map(|v| v * v).sum::<f64>().sqrt();
            let mut column = vec![0.0; j + 2];
            for _ in 0..2 {
                for (k, v) in self.basis.iter().enumerate() {
                    let c: f64 = v.iter().zip(&w).map(|(a, b)| a * b).sum();
                    column[k] += c;
                    w.iter_mut().zip(v).for_each(|(a, b)| *a -= c * b);
                }
            }
            let norm = w.iter().map(|v| v * v).sum::<f64>().sqrt();
            column[j + 1] = norm;
            self.hessenberg.push(column);
            if norm <= 1e-13 * scale || j + 1 == self.dim {
                self.invariant = true;
                self.hessenberg[j][j + 1] = 0.0;
            } else {
                self.basis.push(w.iter().map(|v| v / norm).collect());
            }
        }
    }

    /// The Ritz pairs of the steps so far, largest `|θ|` first, up to and including the
    /// first whose residual is above `tolerance` unless `keep(θ)` says to go on past it
    /// (the rest are not worth their eigenvectors).
    pub fn ritz(&self, tolerance: f64, keep: impl Fn(Complex<f64>) -> bool) -> Vec<Ritz> {
        let m = self.steps();
        if m == 0 || self.broken {
            return Vec::new();
        }
        let h = DMatrix::from_fn(m, m, |i, j| self.hessenberg[j].get(i).copied().unwrap_or(0.0));
        let last = self.hessenberg[m - 1][m];
        let mut values: Vec<Complex<f64>> = h.clone().complex_eigenvalues().iter().copied().collect();
        values.sort_by(|a, b| b.norm().total_cmp(&a.norm()));
        let size = h.amax();
        let mut found = Vec::new();
        for value in values {
            let (y, error) = eigenvector(&h, value, size);
            let residual = (last.abs() * y[m - 1].norm() + error) / value.norm().max(f64::MIN_POSITIVE);
            found.push(Ritz { value, coefficients: y, residual });
            if residual > tolerance && !keep(value) {
                break;
            }
        }
        found
    }

    /// The Ritz vector `V_m y` of a Ritz pair, unit length.
    pub fn vector(&self, ritz: &Ritz) -> Vec<Complex<f64>> {
        let mut vector = vec![Complex::new(0.0, 0.0); self.dim];
        for (y, v) in ritz.coefficients.iter().zip(&self.basis) {
            vector.iter_mut().zip(v).for_each(|(x, b)| *x += y * b);
        }
        let norm = vector.iter().map(|x| x.norm_sqr()).sum::<f64>().sqrt();
        vector.iter_mut().for_each(|x| *x /= norm);
        vector
    }
}

/// A unit eigenvector `y` of the Hessenberg `h` for `value` by two steps of inverse
/// iteration (Gaussian elimination with adjacent-row pivoting, `O(m²)`), and `|h y − θ y|`.
fn eigenvector(h: &DMatrix<f64>, value: Complex<f64>, size: f64) -> (Vec<Complex<f64>>, f64) {
    let m = h.nrows();
    let shift = value + Complex::new(1e-14 * size.max(value.norm()), 0.0);
    let mut y = vec![Complex::new(1.0, 0.0); m];
    for _ in 0..2 {
        let mut a: Vec<Vec<Complex<f64>>> = (0..m)
            .map(|i| {
                (0..m)
                    .map(|j| Complex::new(h[(i, j)], 0.0) - if i == j { shift } else { 0.0.into() })
                    .collect()
            })
            .collect();
        let mut b = y.clone();
        for k in 0..m.saturating_sub(1) {
            if a[k + 1][k].norm() > a[k][k].norm() {
                a.swap(k, k + 1);
                b.swap(k, k + 1);
            }
            if a[k][k].norm() == 0.0 {
                a[k][k] = Complex::new(f64::EPSILON * size.max(1e-300), 0.0);
            }
            let factor = a[k + 1][k] / a[k][k];
            if factor.norm() != 0.0 {
                let (upper, lower) = a.split_at_mut(k + 1);
                for j in k..m {
                    lower[0][j] -= factor * upper[k][j];
                }
                b[k + 1] = b[k + 1] - factor * b[k];
            }
        }
        for k in (0..m).rev() {
            if a[k][k].norm() == 0.0 {
                a[k][k] = Complex::new(f64::EPSILON * size.max(1e-300), 0.0);
            }
            let mut sum = b[k];
            for j in k + 1..m {
                sum -= a[k][j] * b[j];
            }
            b[k] = sum / a[k][k];
        }
        let norm = b.iter().map(|x| x.norm_sqr()).sum::<f64>().sqrt();
        y = b.into_iter().map(|x| x / norm).collect();
    }
    let error = (0..m)
        .map(|i| {
            let row: Complex<f64> = (0..m).map(|j| y[j] * h[(i, j)]).sum();
            (row - value * y[i]).norm_sqr()
        })
        .sum::<f64>()
        .sqrt();
    (y, error)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_dominant_eigenvalues_of_a_matrix_converge_first_and_all_at_full_size() {
        // A nonsymmetric matrix with known eigenvalues 1..40 and a complex pair 60 ± 5i.
        let n = 42;
        let mut d = DMatrix::<f64>::zeros(n, n);
        for i in 0..40 {
            d[(i, i)] = (i + 1) as f64;
        }
        d[(40, 40)] = 60.0;
        d[(41, 41)] = 60.0;
        d[(40, 41)] = 5.0;
        d[(41, 40)] = -5.0;
        let s =
            DMatrix::from_fn(
                n,
                n,
                |i, j| if i == j { 1.0 } else { 0.3 * ((i * 7 + j * 3) % 5) as f64 / n as f64 },
            );
        let a = &s * d * s.clone().try_inverse().unwrap();
        let mut apply = |x: &[f64], y: &mut [f64]| {
            let r = &a * nalgebra::DVector::from_column_slice(x);
            y.copy_from_slice(r.as_slice());
        };
        let mut arnoldi = Arnoldi::new(n);
        arnoldi.extend(20, &mut apply);
        let ritz = arnoldi.ritz(1e-8, |_| false);
        assert!((ritz[0].value.norm() - (3625.0f64).sqrt()).abs() < 1e-8, "{:?}", ritz[0].value);
        assert!(ritz[0].residual < 1e-8 && ritz[1].residual < 1e-8);
        assert!((ritz[0].value.im.abs() - 5.0).abs() < 1e-8);
        arnoldi.extend(100, &mut apply);
        assert!(arnoldi.complete() && arnoldi.steps() == n);
        let ritz = arnoldi.ritz(0.0, |_| true);
        for k in 1..=40 {
            let found = ritz
                .iter()
                .any(|r| (r.value - Complex::new(k as f64, 0.0)).norm() < 1e-9 && r.residual < 1e-9);
            assert!(found, "eigenvalue {k}");
        }
    }

    #[test]
    fn a_non_finite_operator_breaks_the_process_instead_of_giving_ritz_values() {
        let mut arnoldi = Arnoldi::new(6);
        arnoldi.extend(4, &mut |x: &[f64], y: &mut [f64]| {
            y.copy_from_slice(x);
            y[2] = f64::NAN;
        });
        assert!(arnoldi.broken() && arnoldi.steps() == 0 && arnoldi.ritz(1e-8, |_| true).is_empty());
    }
}
