//! The linearisation about a steady shape ([`crate::analysis::stability`]'s `M`, `G`, `H`
//! and the damping `D`) as quasiseparable matrices, in the order
//! `(θ_1, ψ_1, θ_2, ψ_2, …)`: products, solves and the index of `H` in `O(n)`.
//!
//! Every entry between links `a ≥ b` carries the factor `W_ab = M_a l_a l_b` (tail mass of
//! the lower link), times a sum of products of a function of `a` and one of `b`. For
//! `αM + βG + γH` and scalar indices `i > j` (links `a ≥ b`), `Q_ij = X_i · Y_j` with
//!
//! ```text
//! Y_θb = l_b (cos θ_b, sin θ_b, 0),               Y_ψb = l_b (0, 0, 1),
//! X_θa = M_a l_a ((α − γω²) cos θ_a, α sin θ_a, −2βω cos θ_a),
//! X_ψa = M_a l_a (2βω, 0, α − γω²),
//! ```
//!
//! (`cos(θ_a − θ_b) = cos cos + sin sin`); `G` is skew and `M`, `H` symmetric, so the upper
//! part is `Q_ij = Y_i · X_j|_{β → −β}`. The diagonal is `α W_aa + γ (E_a − ω² W_aa cos² θ_a)`
//! for `θ_a`, `α W_aa + γ (E_a − ω² W_aa)` for `ψ_a`, plus `δ λ_a` for damping `D`.

use crate::analysis::quasiseparable::Quasiseparable;
use crate::analysis::steady_branches::{SteadyRotation, SteadyShape};

/// Coefficients of `α M + β G + γ H + δ D` (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Combination {
    pub mass: f64,
    pub gyroscopic: f64,
    pub stiffness: f64,
    pub damping: f64,
}

impl Combination {
    /// `M`.
    pub const MASS: Self = Self { mass: 1.0, gyroscopic: 0.0, stiffness: 0.0, damping: 0.0 };
    /// `H`.
    pub const STIFFNESS: Self = Self { mass: 0.0, gyroscopic: 0.0, stiffness: 1.0, damping: 0.0 };
    /// `G + D`: the velocity terms.
    pub const VELOCITY: Self = Self { mass: 0.0, gyroscopic: 1.0, stiffness: 0.0, damping: 1.0 };

    /// `σ² M + σ (G + D) + H`: the quadratic pencil at `λ = σ`.
    pub fn at(sigma: f64) -> Self {
        Self { mass: sigma * sigma, gyroscopic: sigma, stiffness: 1.0, damping: sigma }
    }
}

/// `α M + β G + γ H + δ D` about `shape` (module docs), damping `λ_a` (N·m·s) per link or
/// none; size `2n`.
pub(crate) fn combination(
    problem: &SteadyRotation,
    shape: &SteadyShape,
    damping: Option<&[f64]>,
    c: Combination,
) -> Quasiseparable<3> {
    let n = problem.links();
    let (_, l, tails) = problem.parameters();
    let omega = shape.omega;
    let w2 = omega * omega;
    let stiffness = problem.rod_stiffness(&shape.theta, &shape.displacements, w2);
    let size = 2 * n;
    let mut q = Quasiseparable {
        diagonal: Vec::with_capacity(size),
        lower_rows: Vec::with_capacity(size),
        lower_columns: Vec::with_capacity(size),
        upper_rows: Vec::with_capacity(size),
        upper_columns: Vec::with_capacity(size),
    };
    let soft = c.mass - c.stiffness * w2;
    for a in 0..n {
        let (sin, cos) = shape.theta[a].sin_cos();
        let tl = tails[a] * l[a];
        let waa = tl * l[a];
        let e = stiffness[a];
        let d = damping.map_or(0.0, |d| d[a]) * c.damping;
        let gyro = 2.0 * omega * c.gyroscopic;
        // θ_a
        let y = [l[a] * cos, l[a] * sin, 0.0];
        q.diagonal.push(c.mass * waa + c.stiffness * (e - w2 * waa * cos * cos) + d);
        q.lower_rows.push([tl * soft * cos, tl * c.mass * sin, -tl * gyro * cos]);
        q.lower_columns.push(y);
        q.upper_rows.push(y);
        q.upper_columns.push([tl * soft * cos, tl * c.mass * sin, tl * gyro * cos]);
        // ψ_a
        let y = [0.0, 0.0, l[a]];
        q.diagonal.push(c.mass * waa + c.stiffness * (e - w2 * waa) + d);
        q.lower_rows.push([tl * gyro, 0.0, tl * soft]);
        q.lower_columns.push(y);
        q.upper_rows.push(y);
        q.upper_columns.push([-tl * gyro, 0.0, tl * soft]);
    }
    q
}

/// The size of the stiffness `H`'s entries, N·m: `max_a (|E_a| + ω² W_aa)`.
pub(crate) fn stiffness_scale(problem: &SteadyRotation, shape: &SteadyShape) -> f64 {
    let h = combination(problem, shape, None, Combination::STIFFNESS);
    let (_, l, tails) = problem.parameters();
    let w2 = shape.omega * shape.omega;
    h.diagonal
        .iter()
        .enumerate()
        .map(|(i, d)| d.abs() + w2 * tails[i / 2] * l[i / 2] * l[i / 2])
        .fold(0.0, f64::max)
}

/// The index of `H` (its negative eigenvalues below `−tolerance · scale`,
/// [`stiffness_scale`]) from the signs of its `L D Lᵀ` pivots, in `O(n)`; `None` when a
/// pivot vanishes exactly.
pub(crate) fn stiffness_index(
    problem: &SteadyRotation,
    shape: &SteadyShape,
    tolerance: f64,
) -> Option<usize> {
    let h = combination(problem, shape, None, Combination::STIFFNESS);
    let bound = tolerance * stiffness_scale(problem, shape);
    let factor = h.factor()?;
    Some(factor.pivots().iter().filter(|&&p| p < -bound).count())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::stability::linearise;
    use crate::chain::Chain;
    use nalgebra::{DMatrix, DVector, Dyn};

    /// The dense matrix of `combination` back in the order `(θ…, ψ…)` of [`linearise`].
    fn blocked(q: &Quasiseparable<3>, n: usize) -> DMatrix<f64> {
        let dense = q.dense();
        let at = |k: usize| if k < n { 2 * k } else { 2 * (k - n) + 1 };
        DMatrix::from_fn(2 * n, 2 * n, |i, j| dense[(at(i), at(j))])
    }

    #[test]
    fn the_combinations_are_the_dense_linearisation() {
        let chain =
            Chain::<Dyn>::new(&[0.3, 1.1, 0.5, 0.8, 0.4], &[0.25, 0.15, 0.3, 0.2, 0.1], 9.81).unwrap();
        let p = SteadyRotation::new(&chain, 0.04).unwrap();
        let shape = p.solve(7.0, &DVector::from_element(5, 0.7)).unwrap();
        let lin = linearise(&p, &shape);
        let damping = [0.01, 0.02, 0.0, 0.03, 0.05];
        let d = DMatrix::from_diagonal(&DVector::from_fn(10, |i, _| damping[i % 5]));
        let (a, b, c, e) = (0.7, -1.3, 2.1, 0.4);
        let q = combination(
            &p,
            &shape,
            Some(&damping),
            Combination { mass: a, gyroscopic: b, stiffness: c, damping: e },
        );
        let expected = &lin.mass * a + &lin.gyroscopic * b + &lin.stiffness * c + d * e;
        assert!((blocked(&q, 5) - &expected).amax() < 1e-13 * expected.amax());
    }
}
