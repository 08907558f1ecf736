//! The Newton matrix of [`RodMidpoint`](super::RodMidpoint)'s step and its elimination
//! link by link, `O(n)`, using the matrix's structure.
//!
//! Ordered link by link, the unknowns `(δx_i, δμ_i)` (mass position, `C` numbers, and rod
//! multiplier) give a block-tridiagonal matrix whose blocks are nearly empty:
//! ```text
//! row i (mass):  k_i δx_i − a_i δx_{i−1} − a_{i+1} δx_{i+1} + d_i δμ_i − d_{i+1} δμ_{i+1} = r_i
//! row i (rod):   e_i·δx_i − e_i·δx_{i−1} = q_i
//! ```
//! Block elimination keeps, per link, the pivot `D'_i = D_i − A_i D'⁻¹_{i−1} C_{i−1}`;
//! here `A_i D'⁻¹_{i−1} C_{i−1}` needs only the top-left `C × C` block `W` of
//! `D'⁻¹_{i−1}`:
//! ```text
//! D'_i = [k_i I − a_i² W,  d_i − a_i W d_i;  (e_i − a_i Wᵀ e_i)ᵀ,  −e_iᵀ W d_i]
//! ```
//! and `D'⁻¹_i` follows from the inverse of its `C × C` block and one scalar Schur
//! complement. Against a general block elimination with pivoted LU of each `(C+1)²`
//! block (commit `617ffd4`), the midpoint step of a 1000-link chain took 0.66 ms instead
//! of 1.25 ms (`cargo bench -p pendulum-core --bench large_chains -- step/free_1000` at
//! each commit, one run each).

/// Link `i`'s row of the Newton matrix and its right-hand side.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LinkRow<const C: usize> {
    /// `k_i`, the position block's diagonal.
    pub stiffness: f64,
    /// `a_i`: the coupling of `x_i` to `x_{i−1}` is `−a_i I` (both ways).
    pub coupling: f64,
    /// `d_i`: the multiplier's column.
    pub midpoint: [f64; C],
    /// `e_i`: the constraint's row.
    pub end: [f64; C],
    /// `r_i`; the solution's `δx_i` after [`solve`].
    pub force: [f64; C],
    /// `q_i`; the solution's `δμ_i` after [`solve`].
    pub constraint: f64,
}

/// What the elimination keeps of link `i`: the inverse of its pivot (`C + 1` rows, of
/// which the first `C` columns are needed going back) and its part of the solution.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Pivot<const C: usize> {
    /// Columns `0..C` of `D'⁻¹_i`: rows `0..C` in `top`, row `C` in `bottom`.
    top: [[f64; C]; C],
    bottom: [f64; C],
    /// `D'⁻¹_i y_i`: the solution before the back substitution.
    position: [f64; C],
    multiplier: f64,
}

/// Solves the system in place (see the module docs). Returns `false` when a pivot is
/// singular or not finite.
pub(crate) fn solve<const C: usize>(rows: &mut [LinkRow<C>], pivots: &mut Vec<Pivot<C>>) -> bool {
    pivots.clear();
    for &row in rows.iter() {
        let mut p = [[0.0; C]; C];
        for (k, line) in p.iter_mut().enumerate() {
            line[k] = row.stiffness;
        }
        let (mut b, mut c, mut s) = (row.midpoint, row.end, 0.0);
        let (mut y, mut yq) = (row.force, row.constraint);
        if let Some(before) = pivots.last() {
            let (a, w, e, d) = (row.coupling, &before.top, row.end, row.midpoint);
            let wd: [f64; C] = std::array::from_fn(|j| (0..C).map(|k| w[j][k] * d[k]).sum());
            let wte: [f64; C] = std::array::from_fn(|j| (0..C).map(|k| w[k][j] * e[k]).sum());
            for j in 0..C {
                for k in 0..C {
                    p[j][k] -= a * a * w[j][k];
                }
                b[j] -= a * wd[j];
                c[j] -= a * wte[j];
                s -= e[j] * wd[j];
                y[j] += a * before.position[j];
                yq += e[j] * before.position[j];
            }
        }
        let Some(pi) = invert(p) else { return false };
        // D'⁻¹ = [P⁻¹ + u vᵀ/σ, −u/σ; −vᵀ/σ, 1/σ], u = P⁻¹ b, vᵀ = cᵀ P⁻¹, σ = s − cᵀ u.
        let u: [f64; C] = std::array::from_fn(|j| (0..C).map(|k| pi[j][k] * b[k]).sum());
        let v: [f64; C] = std::array::from_fn(|j| (0..C).map(|k| c[k] * pi[k][j]).sum());
        let sigma = s - (0..C).map(|k| c[k] * u[k]).sum::<f64>();
        if !(sigma.is_finite() && sigma != 0.0) {
            return false;
        }
        let top: [[f64; C]; C] =
            std::array::from_fn(|j| std::array::from_fn(|k| pi[j][k] + u[j] * v[k] / sigma));
        let bottom: [f64; C] = std::array::from_fn(|k| -v[k] / sigma);
        let (vy, top_y): (f64, [f64; C]) = (
            (0..C).map(|k| v[k] * y[k]).sum(),
            std::array::from_fn(|j| (0..C).map(|k| top[j][k] * y[k]).sum()),
        );
        let position: [f64; C] = std::array::from_fn(|j| top_y[j] - u[j] / sigma * yq);
        let multiplier = (yq - vy) / sigma;
        if !(multiplier.is_finite() && position.iter().all(|v| v.is_finite())) {
            return false;
        }
        pivots.push(Pivot { top, bottom, position, multiplier });
    }
    // Back: δz_i = D'⁻¹_i y_i + D'⁻¹_i [a_{i+1} δx_{i+1} + d_{i+1} δμ_{i+1}; 0].
    let mut next: Option<([f64; C], f64)> = None;
    for i in (0..rows.len()).rev() {
        let pivot = &pivots[i];
        let (mut x, mut mu) = (pivot.position, pivot.multiplier);
        if let Some((dx, dmu)) = next {
            let after = &rows[i + 1];
            let g: [f64; C] = std::array::from_fn(|k| after.coupling * dx[k] + after.midpoint[k] * dmu);
            for (xj, top) in x.iter_mut().zip(&pivot.top) {
                *xj += (0..C).map(|k| top[k] * g[k]).sum::<f64>();
            }
            mu += (0..C).map(|k| pivot.bottom[k] * g[k]).sum::<f64>();
        }
        rows[i].force = x;
        rows[i].constraint = mu;
        next = Some((x, mu));
    }
    true
}

/// The inverse of a 2 × 2 or 3 × 3 matrix by its adjugate; `None` when singular or not
/// finite. No pivoting: the position blocks are near `k_i I`, far from singular.
fn invert<const C: usize>(a: [[f64; C]; C]) -> Option<[[f64; C]; C]> {
    let mut inverse = [[0.0; C]; C];
    let det = match C {
        2 => {
            let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
            inverse[0][0] = a[1][1];
            inverse[0][1] = -a[0][1];
            inverse[1][0] = -a[1][0];
            inverse[1][1] = a[0][0];
            det
        }
        3 => {
            let cofactor = |i: usize, j: usize| {
                let (r0, r1) = ((i + 1) % 3, (i + 2) % 3);
                let (c0, c1) = ((j + 1) % 3, (j + 2) % 3);
                a[r0][c0] * a[r1][c1] - a[r0][c1] * a[r1][c0]
            };
            for (i, line) in inverse.iter_mut().enumerate() {
                for (j, v) in line.iter_mut().enumerate() {
                    *v = cofactor(j, i);
                }
            }
            (0..3).map(|j| a[0][j] * inverse[j][0]).sum()
        }
        _ => return None,
    };
    if !(det.is_finite() && det != 0.0) {
        return None;
    }
    for line in inverse.iter_mut() {
        for v in line.iter_mut() {
            *v /= det;
        }
    }
    Some(inverse)
}

#[cfg(test)]
mod tests {
    use nalgebra::{DMatrix, DVector};

    use super::*;

    /// The structured elimination agrees with a dense solve of the same matrix.
    #[test]
    fn agrees_with_a_dense_solve() {
        const C: usize = 3;
        let n = 9;
        let value = |i: usize, k: usize| ((i * 13 + k * 7) as f64 * 0.61).sin();
        let rows: Vec<LinkRow<C>> = (0..n)
            .map(|i| LinkRow {
                stiffness: 50.0 + value(i, 0),
                coupling: 3.0 + value(i, 1),
                midpoint: std::array::from_fn(|k| value(i, k + 2)),
                end: std::array::from_fn(|k| value(i, k + 2) + 0.1 * value(i, k + 5)),
                force: std::array::from_fn(|k| value(i, k + 8)),
                constraint: value(i, 11),
            })
            .collect();
        let b = C + 1;
        let mut dense = DMatrix::zeros(n * b, n * b);
        let mut rhs = DVector::zeros(n * b);
        for (i, r) in rows.iter().enumerate() {
            for k in 0..C {
                dense[(i * b + k, i * b + k)] = r.stiffness;
                dense[(i * b + k, i * b + C)] = r.midpoint[k];
                dense[(i * b + C, i * b + k)] = r.end[k];
                if i > 0 {
                    dense[(i * b + k, (i - 1) * b + k)] = -r.coupling;
                    dense[(i * b + C, (i - 1) * b + k)] = -r.end[k];
                }
                if i + 1 < n {
                    dense[(i * b + k, (i + 1) * b + k)] = -rows[i + 1].coupling;
                    dense[(i * b + k, (i + 1) * b + C)] = -rows[i + 1].midpoint[k];
                }
                rhs[i * b + k] = r.force[k];
            }
            rhs[i * b + C] = r.constraint;
        }
        let expected = dense.lu().solve(&rhs).unwrap();
        let mut solved = rows.clone();
        assert!(solve(&mut solved, &mut Vec::new()));
        for (i, r) in solved.iter().enumerate() {
            for k in 0..C {
                assert!((r.force[k] - expected[i * b + k]).abs() < 1e-12, "{i} {k}");
            }
            assert!((r.constraint - expected[i * b + C]).abs() < 1e-12, "{i}");
        }
    }

    #[test]
    fn small_inverses_are_inverses() {
        let a = [[4.0, 1.0, -2.0], [0.5, 3.0, 1.0], [-1.0, 2.0, 5.0]];
        let b = invert(a).unwrap();
        let product = |i: usize, j: usize| (0..3).map(|k| a[i][k] * b[k][j]).sum::<f64>();
        for i in 0..3 {
            for j in 0..3 {
                let p = product(i, j);
                assert!((p - if i == j { 1.0 } else { 0.0 }).abs() < 1e-14, "{i} {j} {p}");
            }
        }
        let b = invert([[2.0, 1.0], [3.0, 4.0]]).unwrap();
        assert_eq!(b, [[0.8, -0.2], [-0.6, 0.4]]);
        assert!(invert([[1.0, 2.0], [2.0, 4.0]]).is_none());
    }

    #[test]
    fn a_singular_pivot_is_reported() {
        let row = LinkRow::<2> {
            stiffness: 1.0,
            coupling: 0.0,
            midpoint: [0.0; 2],
            end: [0.0; 2],
            force: [1.0; 2],
            constraint: 1.0,
        };
        assert!(!solve(&mut [row], &mut Vec::new()));
    }
}
