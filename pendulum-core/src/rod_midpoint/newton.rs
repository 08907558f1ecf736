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

use crate::lanes::Masked;

/// Link `i`'s row of the Newton matrix and its right-hand side, in lanes `V` (one chain's
/// numbers in each; `f64` for one chain).
#[derive(Debug, Clone, Copy)]
pub(crate) struct LinkRow<const C: usize, V = f64> {
    /// `k_i`, the position block's diagonal.
    pub stiffness: V,
    /// `a_i`: the coupling of `x_i` to `x_{i−1}` is `−a_i I` (both ways).
    pub coupling: V,
    /// `d_i`: the multiplier's column.
    pub midpoint: [V; C],
    /// `e_i`: the constraint's row.
    pub end: [V; C],
    /// `r_i`; the solution's `δx_i` after [`solve`].
    pub force: [V; C],
    /// `q_i`; the solution's `δμ_i` after [`solve`].
    pub constraint: V,
}

/// What the elimination keeps of link `i`: the inverse of its pivot (`C + 1` rows, of
/// which the first `C` columns are needed going back) and its part of the solution.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Pivot<const C: usize, V = f64> {
    /// Columns `0..C` of `D'⁻¹_i`: rows `0..C` in `top`, row `C` in `bottom`.
    top: [[V; C]; C],
    bottom: [V; C],
    /// `D'⁻¹_i y_i`: the solution before the back substitution.
    position: [V; C],
    multiplier: V,
}

impl<const C: usize, V: Masked> Pivot<C, V> {
    /// A pivot of zeros, to size the buffers with.
    pub(crate) fn zero() -> Self {
        let zero = V::splat(0.0);
        Self { top: [[zero; C]; C], bottom: [zero; C], position: [zero; C], multiplier: zero }
    }
}

/// `Σ_k a_k b_k`, summed in order `k = 0, 1, …` (as `Iterator::sum` adds them).
#[inline(always)]
pub(super) fn dot<const C: usize, V: Masked>(a: [V; C], b: [V; C]) -> V {
    let mut sum = a[0] * b[0];
    for k in 1..C {
        sum += a[k] * b[k];
    }
    sum
}

/// `M b`.
#[inline(always)]
fn times<const C: usize, V: Masked>(m: &[[V; C]; C], b: [V; C]) -> [V; C] {
    let mut out = b;
    for (o, line) in out.iter_mut().zip(m) {
        *o = dot(*line, b);
    }
    out
}

/// `Mᵀ b`.
#[inline(always)]
fn times_transposed<const C: usize, V: Masked>(m: &[[V; C]; C], b: [V; C]) -> [V; C] {
    let mut out = b;
    for (j, o) in out.iter_mut().enumerate() {
        let mut sum = m[0][j] * b[0];
        for k in 1..C {
            sum += m[k][j] * b[k];
        }
        *o = sum;
    }
    out
}

/// Solves the system in place (see the module docs), lane by lane, with `pivots` (as many
/// as `rows`) for the elimination's. Returns the lanes in which a pivot is singular or not
/// finite (their numbers are then meaningless).
#[inline(always)]
pub(crate) fn solve<const C: usize, V: Masked>(
    rows: &mut [LinkRow<C, V>],
    pivots: &mut [Pivot<C, V>],
) -> V::Mask {
    assert_eq!(rows.len(), pivots.len(), "a pivot per row");
    let zero = V::splat(0.0);
    let mut singular = V::none();
    for i in 0..rows.len() {
        let row = rows[i];
        let mut p = [[zero; C]; C];
        for (k, line) in p.iter_mut().enumerate() {
            line[k] = row.stiffness;
        }
        let (mut b, mut c, mut s) = (row.midpoint, row.end, zero);
        let (mut y, mut yq) = (row.force, row.constraint);
        if i > 0 {
            let before = &pivots[i - 1];
            let (a, w, e, d) = (row.coupling, &before.top, row.end, row.midpoint);
            let wd = times(w, d);
            let wte = times_transposed(w, e);
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
        let (pi, bad) = invert(p);
        // D'⁻¹ = [P⁻¹ + u vᵀ/σ, −u/σ; −vᵀ/σ, 1/σ], u = P⁻¹ b, vᵀ = cᵀ P⁻¹, σ = s − cᵀ u.
        let u = times(&pi, b);
        let v = times_transposed(&pi, c);
        let sigma = s - dot(c, u);
        let mut top = pi;
        for j in 0..C {
            for k in 0..C {
                top[j][k] = pi[j][k] + u[j] * v[k] / sigma;
            }
        }
        let mut bottom = v;
        for b in &mut bottom {
            *b = -*b / sigma;
        }
        let (vy, top_y) = (dot(v, y), times(&top, y));
        let mut position = top_y;
        let mut unusable = V::or(bad, V::or(sigma.not_finite(), sigma.is_zero()));
        for j in 0..C {
            position[j] = top_y[j] - u[j] / sigma * yq;
            unusable = V::or(unusable, position[j].not_finite());
        }
        let multiplier = (yq - vy) / sigma;
        singular = V::or(singular, V::or(unusable, multiplier.not_finite()));
        if V::all(singular) {
            return singular;
        }
        pivots[i] = Pivot { top, bottom, position, multiplier };
    }
    // Back: δz_i = D'⁻¹_i y_i + D'⁻¹_i [a_{i+1} δx_{i+1} + d_{i+1} δμ_{i+1}; 0].
    for i in (0..rows.len()).rev() {
        let pivot = &pivots[i];
        let (mut x, mut mu) = (pivot.position, pivot.multiplier);
        if let Some(after) = rows.get(i + 1) {
            let (dx, dmu) = (after.force, after.constraint);
            let mut g = dx;
            for k in 0..C {
                g[k] = after.coupling * dx[k] + after.midpoint[k] * dmu;
            }
            let moved = times(&pivot.top, g);
            for j in 0..C {
                x[j] += moved[j];
            }
            mu += dot(pivot.bottom, g);
        }
        rows[i].force = x;
        rows[i].constraint = mu;
    }
    singular
}

/// The inverse of a 2 × 2 or 3 × 3 matrix by its adjugate, lane by lane, and the lanes in
/// which it is singular or not finite. No pivoting: the position blocks are near `k_i I`,
/// far from singular.
#[inline(always)]
fn invert<const C: usize, V: Masked>(a: [[V; C]; C]) -> ([[V; C]; C], V::Mask) {
    let mut inverse = a;
    let det = if C == 2 {
        let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
        inverse[0][0] = a[1][1];
        inverse[0][1] = -a[0][1];
        inverse[1][0] = -a[1][0];
        inverse[1][1] = a[0][0];
        det
    } else {
        debug_assert_eq!(C, 3, "2 or 3 dimensions");
        for (i, line) in inverse.iter_mut().enumerate() {
            for (j, v) in line.iter_mut().enumerate() {
                // The cofactor of entry (j, i).
                let (r0, r1) = ((j + 1) % 3, (j + 2) % 3);
                let (c0, c1) = ((i + 1) % 3, (i + 2) % 3);
                *v = a[r0][c0] * a[r1][c1] - a[r0][c1] * a[r1][c0];
            }
        }
        a[0][0] * inverse[0][0] + a[0][1] * inverse[1][0] + a[0][2] * inverse[2][0]
    };
    for line in inverse.iter_mut() {
        for v in line.iter_mut() {
            *v = *v / det;
        }
    }
    (inverse, V::or(det.not_finite(), det.is_zero()))
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
        assert!(!solve(&mut solved, &mut vec![Pivot::zero(); n]));
        for (i, r) in solved.iter().enumerate() {
            for k in 0..C {
                assert!((r.force[k] - expected[i * b + k]).abs() < 1e-12, "{i} {k}");
            }
            assert!((r.constraint - expected[i * b + C]).abs() < 1e-12, "{i}");
        }
    }

    /// In lanes, each lane solves its own system, bit for bit as alone, and a lane with a
    /// singular pivot is flagged without touching the others.
    #[test]
    fn in_lanes_each_lane_is_its_own_system() {
        use crate::lanes::Lanes;
        const C: usize = 3;
        let n = 7;
        let value = |i: usize, k: usize, lane: usize| ((i * 13 + k * 7 + lane * 31) as f64 * 0.61).sin();
        let row = |i: usize, lane: usize| LinkRow::<C> {
            // Lane 2's third link is singular.
            stiffness: if lane == 2 && i == 3 { 0.0 } else { 50.0 + value(i, 0, lane) },
            coupling: if lane == 2 && i == 3 { 0.0 } else { 3.0 + value(i, 1, lane) },
            midpoint: std::array::from_fn(|k| value(i, k + 2, lane)),
            end: std::array::from_fn(|k| value(i, k + 5, lane)),
            force: std::array::from_fn(|k| value(i, k + 8, lane)),
            constraint: value(i, 11, lane),
        };
        let lanes = |f: &dyn Fn(usize) -> f64| Lanes::<4>(std::array::from_fn(f));
        let mut rows: Vec<LinkRow<C, Lanes<4>>> = (0..n)
            .map(|i| LinkRow {
                stiffness: lanes(&|l| row(i, l).stiffness),
                coupling: lanes(&|l| row(i, l).coupling),
                midpoint: std::array::from_fn(|k| lanes(&|l| row(i, l).midpoint[k])),
                end: std::array::from_fn(|k| lanes(&|l| row(i, l).end[k])),
                force: std::array::from_fn(|k| lanes(&|l| row(i, l).force[k])),
                constraint: lanes(&|l| row(i, l).constraint),
            })
            .collect();
        let singular = solve(&mut rows, &mut vec![Pivot::zero(); n]);
        assert_eq!(singular, [0, 0, 1, 0]);
        for lane in [0, 1, 3] {
            let mut alone: Vec<LinkRow<C>> = (0..n).map(|i| row(i, lane)).collect();
            assert!(!solve(&mut alone, &mut vec![Pivot::zero(); n]));
            for (a, b) in alone.iter().zip(&rows) {
                for k in 0..C {
                    assert_eq!(a.force[k].to_bits(), b.force[k].0[lane].to_bits(), "lane {lane}");
                }
                assert_eq!(a.constraint.to_bits(), b.constraint.0[lane].to_bits(), "lane {lane}");
            }
        }
        let mut alone: Vec<LinkRow<C>> = (0..n).map(|i| row(i, 2)).collect();
        assert!(solve(&mut alone, &mut vec![Pivot::zero(); n]));
    }

    #[test]
    fn small_inverses_are_inverses() {
        let a = [[4.0, 1.0, -2.0], [0.5, 3.0, 1.0], [-1.0, 2.0, 5.0]];
        let (b, singular) = invert(a);
        assert!(!singular);
        let product = |i: usize, j: usize| (0..3).map(|k| a[i][k] * b[k][j]).sum::<f64>();
        for i in 0..3 {
            for j in 0..3 {
                let p = product(i, j);
                assert!((p - if i == j { 1.0 } else { 0.0 }).abs() < 1e-14, "{i} {j} {p}");
            }
        }
        let (b, singular) = invert([[2.0, 1.0], [3.0, 4.0]]);
        assert_eq!((b, singular), ([[0.8, -0.2], [-0.6, 0.4]], false));
        assert!(invert([[1.0, 2.0], [2.0, 4.0]]).1);
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
        assert!(solve(&mut [row], &mut [Pivot::zero()]));
    }
}
