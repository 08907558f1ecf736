//! Normal modes of a chain hanging at rest: small oscillations about `θ = 0`.
//!
//! Linearising the planar equations (eqs 18–26) at `θ = θ̇ = 0` gives
//!
//! ```text
//! W θ̈ + K θ = 0,   W_ij = M_max(i,j) l_i l_j  (Chain::weight),   K = diag(g M_i l_i),
//! ```
//!
//! so the modes solve the generalized symmetric eigenproblem `K v = ω² W v`. In 3D the
//! chain at rest linearises into two identical, uncoupled copies of this problem (x–z and
//! y–z planes), so the same frequencies and shapes serve both.
//!
//! The tail-mass matrix has a tridiagonal inverse: `W = Λ E diag(m) Eᵀ Λ` with
//! `Λ = diag(l)` and `E_ik = [i ≤ k]`, so
//!
//! ```text
//! (W⁻¹)_ii = (1/m_i + 1/m_{i−1}) / l_i²   (1/m_0 := 0),   (W⁻¹)_{i,i+1} = −1 / (m_i l_i l_{i+1}),
//! ```
//!
//! and with `v = K^{−1/2} z` the problem becomes the standard symmetric tridiagonal one
//! `A z = ω² z`, `A = K^{1/2} W⁻¹ K^{1/2}`:
//!
//! ```text
//! A_ii = g M_i (1/m_i + 1/m_{i−1}) / l_i,   A_{i,i+1} = −g sqrt(M_i M_{i+1} / (l_i l_{i+1})) / m_i.
//! ```
//!
//! `A` is built in O(n) and diagonalised by nalgebra's `SymmetricEigen`.

use nalgebra::{DefaultAllocator, Dim, DimDiff, DimSub, OMatrix, OVector, U1, allocator::Allocator};

use crate::analysis::bessel::bessel_j0_zero;
use crate::analysis::laguerre::laguerre_zeros;
use crate::chain::Chain;

/// The normal modes of a chain hanging at rest.
///
/// Column `k` of [`shapes`](Self::shapes) is the angle pattern `v_k` (rad per unit of
/// modal coordinate) of the mode with angular frequency `frequencies[k]` (rad/s); the
/// frequencies ascend. Shapes are mass-normalised, `v_kᵀ W v_k = Σ_i m_i x_i² = 1` (kg·m²
/// per unit modal coordinate squared, `x_i = Σ_{j≤i} l_j v_j` the horizontal displacement
/// of mass i), and signed so the free end moves to `+x` (`x_n > 0`).
#[derive(Debug, Clone, PartialEq)]
pub struct NormalModes<L: Dim>
where
    DefaultAllocator: Allocator<L> + Allocator<L, L>,
{
    /// Angular frequencies `ω_k`, rad/s, ascending.
    pub frequencies: OVector<f64, L>,
    /// Mode shapes as columns, in link angles, mass-normalised.
    pub shapes: OMatrix<f64, L, L>,
}

impl<L: Dim> NormalModes<L>
where
    DefaultAllocator: Allocator<L> + Allocator<L, L>,
{
    /// Horizontal displacements `x_i = Σ_{j≤i} l_j v_{jk}` (m per unit modal coordinate)
    /// of the masses in mode `k` (0-based).
    ///
    /// Panics if `k` is not below the number of links (an index, like nalgebra's).
    pub fn displacements(&self, chain: &Chain<L>, k: usize) -> Vec<f64> {
        let mut x = 0.0;
        (0..chain.links())
            .map(|i| {
                x += chain.lengths()[i] * self.shapes[(i, k)];
                x
            })
            .collect()
    }
}

/// The symmetric tridiagonal matrix `A = K^{1/2} W⁻¹ K^{1/2}` of the module docs with
/// `g = 1` (1/s² per m/s² of gravity): its eigenvalues times `g` are `ω_k²`.
fn unit_gravity_matrix<L: Dim>(chain: &Chain<L>) -> OMatrix<f64, L, L>
where
    DefaultAllocator: Allocator<L> + Allocator<L, L>,
{
    let n = chain.links();
    let (m, l, tail) = (chain.masses(), chain.lengths(), chain.tail_masses());
    let dim = chain.link_dim();
    let mut a = OMatrix::<f64, L, L>::zeros_generic(dim, dim);
    for i in 0..n {
        let above = if i == 0 { 0.0 } else { 1.0 / m[i - 1] };
        a[(i, i)] = tail[i] * (1.0 / m[i] + above) / l[i];
        if i + 1 < n {
            let off = -(tail[i] * tail[i + 1] / (l[i] * l[i + 1])).sqrt() / m[i];
            a[(i, i + 1)] = off;
            a[(i + 1, i)] = off;
        }
    }
    a
}

/// The normal modes of `chain` hanging at rest: `K v = ω² W v` (module docs).
///
/// Works for any masses, lengths and `g ≥ 0` (with `g = 0` every frequency is zero and
/// the shapes are those the chain would have under any gravity). Cost O(n³) for the
/// eigenvectors (O(n) to build the tridiagonal matrix).
pub fn normal_modes<L>(chain: &Chain<L>) -> NormalModes<L>
where
    L: Dim + DimSub<U1>,
    DefaultAllocator: Allocator<L> + Allocator<L, L> + Allocator<DimDiff<L, U1>>,
{
    let n = chain.links();
    let dim = chain.link_dim();
    let eigen = unit_gravity_matrix(chain).symmetric_eigen();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| eigen.eigenvalues[a].total_cmp(&eigen.eigenvalues[b]));
    let g = chain.gravity();
    let mut frequencies = OVector::<f64, L>::zeros_generic(dim, U1);
    let mut shapes = OMatrix::<f64, L, L>::zeros_generic(dim, dim);
    let (m, l, tail) = (chain.masses(), chain.lengths(), chain.tail_masses());
    for (k, &src) in order.iter().enumerate() {
        // Round-off can leave the smallest eigenvalue of a positive-definite A at −ε.
        frequencies[k] = (g * eigen.eigenvalues[src].max(0.0)).sqrt();
        // v = K^{−1/2} z with K = diag(M_i l_i) at g = 1 (the scale is fixed below).
        let mut x = 0.0;
        let mut norm2 = 0.0;
        for i in 0..n {
            let v = eigen.eigenvectors[(i, src)] / (tail[i] * l[i]).sqrt();
            shapes[(i, k)] = v;
            x += l[i] * v;
            norm2 += m[i] * x * x;
        }
        let sign = if x < 0.0 { -1.0 } else { 1.0 };
        let scale = sign / norm2.sqrt();
        for i in 0..n {
            shapes[(i, k)] *= scale;
        }
    }
    NormalModes { frequencies, shapes }
}

/// The number of sign changes in a sequence, ignoring exact zeros: for the horizontal
/// displacements of the masses, the number of times the chain crosses the vertical axis
/// below the pivot.
pub fn sign_changes(values: &[f64]) -> usize {
    let mut last = 0.0_f64;
    let mut count = 0;
    for &v in values {
        if v != 0.0 {
            if last != 0.0 && (v > 0.0) != (last > 0.0) {
                count += 1;
            }
            last = v;
        }
    }
    count
}

/// Bernoulli's frequency of mode `k` (k ≥ 1) of the uniform hanging chain of length `L` (m)
/// in the continuum limit, `ω_k = (j_{0,k}/2) √(g/L)` (rad/s), `j_{0,k}` the k-th zero of
/// the Bessel function J0 ([`bessel_j0_zero`]). A uniform chain of n links approaches it
/// from below as n grows (`docs/rotating-chain.md`).
pub fn bernoulli_frequency(k: usize, gravity: f64, length: f64) -> f64 {
    0.5 * bessel_j0_zero(k) * (gravity / length).sqrt()
}

/// The exact angular frequencies (rad/s, ascending) of small oscillations of a chain of
/// `n` equal masses on equal rods of length `l` (m) about the hanging rest:
/// `ω_k = √((g/l) x_k)`, `x_k` the zeros of the Laguerre polynomial `L_n`
/// ([`laguerre_zeros`]). Independent of the mass; they approach [`bernoulli_frequency`]
/// with `L = n l` as n grows. Also the speeds at which the equal-link chain turning about
/// the vertical leaves it (the linearised shape equations are the same eigenproblem).
pub fn equal_link_frequencies(n: usize, gravity: f64, link_length: f64) -> Vec<f64> {
    laguerre_zeros(n).into_iter().map(|x| (gravity / link_length * x).sqrt()).collect()
}

/// An estimate of a chain's fastest angular frequency (rad/s) about the hanging rest under
/// the effective gravity `g_eff` (m/s²: `g` plus what a drive adds, e.g. `R ω²` on a
/// circle): the largest `√(2 (T_i/l_i + T_{i+1}/l_{i+1}) / m_i)` with the hanging tensions
/// `T_i = M_i g_eff` (`M_i` the tail mass, eq 10; `T_{n+1} = 0`), a Gershgorin bound of the
/// tension-stiffness matrix; `2n √(g/L)` for a long uniform chain. What limits an
/// explicit step (RK4: `h ω ≲ 2.8`) and a fixed-point stage solve (`h ω ≲ 1`).
pub fn fastest_frequency_bound<L: Dim>(chain: &Chain<L>, effective_gravity: f64) -> f64
where
    DefaultAllocator: Allocator<L>,
{
    let (m, l, tail) = (chain.masses(), chain.lengths(), chain.tail_masses());
    let n = chain.links();
    let stiffness = |i: usize| if i < n { tail[i] * effective_gravity / l[i] } else { 0.0 };
    (0..n).map(|i| (2.0 * (stiffness(i) + stiffness(i + 1)) / m[i]).sqrt()).fold(0.0, f64::max)
}

/// The same bound for the damping (1/s): the largest `2 (λ_i/l_i² + λ_{i+1}/l_{i+1}²) / m_i`,
/// the fastest decay rate; RK4 is stable to `h ν ≈ 2.8` on decaying modes.
pub fn fastest_decay_bound<L: Dim>(chain: &Chain<L>) -> f64
where
    DefaultAllocator: Allocator<L>,
{
    let (m, l, lambda) = (chain.masses(), chain.lengths(), chain.damping());
    let n = chain.links();
    let damping = |i: usize| if i < n { lambda[i] / (l[i] * l[i]) } else { 0.0 };
    (0..n).map(|i| 2.0 * (damping(i) + damping(i + 1)) / m[i]).fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use nalgebra::{Const, DMatrix, Dyn};

    /// `K v = ω² W v` and `vᵀ W v = 1` checked with dense matrices built here apart from
    /// `Chain::weight` and the tail masses: `W = Jᵀ diag(m) J` with `J_ki = l_i` (i ≤ k),
    /// the masses' horizontal displacements `x_k = Σ_{i≤k} l_i θ_i` to first order, and
    /// `K_ii = ∂²U/∂θ_i²` at rest, `U = −g Σ_k m_k Σ_{i≤k} l_i cos θ_i`.
    fn check_eigenpairs<L>(chain: &Chain<L>, modes: &NormalModes<L>)
    where
        L: Dim,
        DefaultAllocator: Allocator<L> + Allocator<L, L>,
    {
        let n = chain.links();
        let (m, l, g) = (chain.masses(), chain.lengths(), chain.gravity());
        let jacobian = DMatrix::from_fn(n, n, |k, i| if i <= k { l[i] } else { 0.0 });
        let masses = DMatrix::from_fn(n, n, |a, b| if a == b { m[a] } else { 0.0 });
        let w = jacobian.transpose() * masses * &jacobian;
        let k =
            DMatrix::from_fn(
                n,
                n,
                |i, j| if i == j { g * l[i] * (i..n).map(|k| m[k]).sum::<f64>() } else { 0.0 },
            );
        for c in 0..n {
            let v = nalgebra::DVector::from_fn(n, |i, _| modes.shapes[(i, c)]);
            let w2 = modes.frequencies[c].powi(2);
            let residual = &k * &v - w2 * (&w * &v);
            assert!(residual.norm() < 1e-10 * (k.norm() * v.norm()), "mode {c}: residual {residual}");
            assert_relative_eq!(v.dot(&(&w * &v)), 1.0, epsilon = 1e-12);
        }
    }

    #[test]
    fn two_links_match_the_closed_form() {
        // m1 = m2 = m, l1 = l2 = l: ω² = (2 ∓ √2) g / l.
        let chain = Chain::<Const<2>>::uniform(2, 0.7, 0.5, 9.81).unwrap();
        let modes = normal_modes(&chain);
        let g_l = 9.81 / 0.5;
        assert_relative_eq!(modes.frequencies[0], ((2.0 - 2f64.sqrt()) * g_l).sqrt(), max_relative = 1e-13);
        assert_relative_eq!(modes.frequencies[1], ((2.0 + 2f64.sqrt()) * g_l).sqrt(), max_relative = 1e-13);
        // Shapes: θ2/θ1 = √2 (in phase) and −√2 (out of phase).
        assert_relative_eq!(modes.shapes[(1, 0)] / modes.shapes[(0, 0)], 2f64.sqrt(), max_relative = 1e-12);
        assert_relative_eq!(
            modes.shapes[(1, 1)] / modes.shapes[(0, 1)],
            -(2f64.sqrt()),
            max_relative = 1e-12
        );
        check_eigenpairs(&chain, &modes);
    }

    #[test]
    fn two_unequal_links_match_the_characteristic_polynomial() {
        // det(K − ω² W) = 0 for masses m1, m2 and lengths l1, l2:
        // m1 l1 l2 ω⁴ − g (m1 + m2)(l1 + l2) ω² + g² (m1 + m2) = 0.
        let (m1, m2, l1, l2, g) = (1.3, 0.4, 0.8, 1.7, 9.81);
        let chain = Chain::<Dyn>::new(&[m1, m2], &[l1, l2], g).unwrap();
        let modes = normal_modes(&chain);
        let (a, b, c) = (m1 * l1 * l2, -g * (m1 + m2) * (l1 + l2), g * g * (m1 + m2));
        let disc = (b * b - 4.0 * a * c).sqrt();
        assert_relative_eq!(modes.frequencies[0].powi(2), (-b - disc) / (2.0 * a), max_relative = 1e-12);
        assert_relative_eq!(modes.frequencies[1].powi(2), (-b + disc) / (2.0 * a), max_relative = 1e-12);
        check_eigenpairs(&chain, &modes);
    }

    #[test]
    fn one_link_is_the_simple_pendulum() {
        let chain = Chain::<Dyn>::new(&[2.0], &[0.3], 9.81).unwrap();
        let modes = normal_modes(&chain);
        assert_relative_eq!(modes.frequencies[0], (9.81f64 / 0.3).sqrt(), max_relative = 1e-14);
        assert_relative_eq!(modes.displacements(&chain, 0)[0], 1.0 / 2f64.sqrt(), max_relative = 1e-14);
    }

    #[test]
    fn irregular_chain_solves_the_generalized_problem() {
        let chain = Chain::<Dyn>::new(&[0.3, 2.0, 0.05, 1.1, 0.7], &[0.2, 1.5, 0.4, 0.05, 0.9], 3.7).unwrap();
        let modes = normal_modes(&chain);
        check_eigenpairs(&chain, &modes);
        assert!(modes.frequencies.as_slice().windows(2).all(|w| w[0] <= w[1]));
    }

    #[test]
    fn mode_k_crosses_the_axis_k_minus_one_times() {
        let chain = Chain::<Dyn>::uniform(12, 1.0, 0.1, 9.81).unwrap();
        let modes = normal_modes(&chain);
        for k in 0..12 {
            assert_eq!(sign_changes(&modes.displacements(&chain, k)), k, "mode {}", k + 1);
        }
    }

    #[test]
    fn zero_gravity_gives_zero_frequencies_and_valid_shapes() {
        let chain = Chain::<Dyn>::uniform(3, 1.0, 1.0, 0.0).unwrap();
        let modes = normal_modes(&chain);
        assert!(modes.frequencies.iter().all(|&w| w == 0.0));
        assert!(modes.shapes.iter().all(|v| v.is_finite()));
    }

    #[test]
    fn sign_changes_skip_zeros() {
        assert_eq!(sign_changes(&[1.0, 0.0, -1.0, -2.0, 0.0, 3.0]), 2);
        assert_eq!(sign_changes(&[]), 0);
    }
}
