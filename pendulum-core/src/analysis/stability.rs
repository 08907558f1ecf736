//! Linear stability of a steadily rotating chain in the full 3D equations, in the frame
//! turning with it.
//!
//! # Coordinates and linearisation
//!
//! Around a steady shape in the turning x–z plane, link `i` points along
//! `u_i = (cos ψ_i sin θ_i, sin ψ_i, −cos ψ_i cos θ_i)`: `θ_i` in the plane, `ψ_i` out of
//! it. The chart is regular at `ψ = 0` for every `θ`, including the vertical (unlike the
//! spherical angles of [`crate::Spatial`]). Positions `r_i = (R, 0, 0) + Σ_{j≤i} l_j u_j`.
//! The Lagrangian in the frame turning at `Ω = ω e_z` is
//! `Σ ½ m_i |ṙ_i + Ω × r_i|² − m_i g z_i`; linearised about the steady shape
//! (`q = (θ, ψ)`, `2n` coordinates) it gives
//!
//! ```text
//! M δq̈ + (G + D) δq̇ + H δq = 0,
//! M = Σ m_i J_iᵀ J_i:        M_θθ = W_ab cos(θ_a − θ_b),  M_ψψ = W_ab,       M_θψ = 0,
//! G = 2 Σ m_i J_iᵀ [Ω]× J_i: G_ψaθb = 2ω W_ab cos θ_b = −G_θbψa,  G_θθ = G_ψψ = 0,
//! H = ∇² V:                  H_θθ = E − ω² W_ab cos θ_a cos θ_b,  H_ψψ = E − ω² W_ab,
//!                            E = diag(l_a (g M_a cos θ_a + ω² sin θ_a S_a)),  H_θψ = 0,
//! ```
//!
//! (`J_i = ∂r_i/∂q`, `W_ab = M_max(a,b) l_a l_b`, `S_a = Σ_{i≥a} m_i x_i`; `H_θθ` is the
//! Jacobian of the planar shape equations of [`crate::SteadyRotation`]). `G` is the
//! gyroscopic (Coriolis) matrix, skew; `D = diag(λ, λ)` optional damping of the link
//! rates relative to the turning frame.
//!
//! # What "stable" means
//!
//! Without damping the linearisation is Hamiltonian: its eigenvalues come in quadruples
//! `±λ, ±λ̄`, so the only possible stability is **spectral stability**, every eigenvalue
//! on the imaginary axis (oscillation about the steady shape, no decay). That is necessary
//! for stability but not sufficient: under a small change of parameters two imaginary
//! pairs of opposite Krein signature can collide and leave the axis (a Hamiltonian–Hopf
//! bifurcation), while pairs of equal signature pass through each other. If `H` is
//! positive definite (index 0: the steady shape minimises the amended potential), the
//! energy is a Lyapunov function and the shape is stable outright (Lagrange–Dirichlet).
//! If `H` has negative eigenvalues but an even number of them, gyroscopic terms can still
//! make the shape spectrally stable ("gyroscopic stabilisation"); with an odd number it is
//! always unstable (a real positive eigenvalue). By Kelvin–Tait–Chetaev, **any** damping
//! (`D` positive definite) destroys gyroscopic stabilisation: with damping a shape is
//! asymptotically stable iff its index is 0, and unstable otherwise. Free steady rotation
//! with `R = 0` has a symmetry (turning the whole shape about the axis), so `H` and the
//! spectrum have an exact zero there; it is not counted.
//!
//! [`Verdict`] puts this in three classes, from a [`Stability`] ([`Verdict::of`]) or from
//! any spectrum, e.g. the damped one of [`crate::relative_spectrum`]
//! ([`Verdict::of_spectrum`]): stable (index 0), gyroscopic (spectrally stable, index > 0)
//! or unstable with its growth rate `max Re λ` (1/s).

use nalgebra::{Complex, DMatrix, DVector};

use crate::analysis::arnoldi::{Arnoldi, Ritz};
use crate::analysis::quasiseparable::Quasiseparable;
use crate::analysis::steady_branches::{SteadyRotation, SteadyShape};
use crate::analysis::turning_pencil::{Combination, combination, stiffness_index};
use crate::error::{Error, Result};

/// The linearised equations `M δq̈ + G δq̇ + H δq = 0` about a steady shape (module
/// docs), in `q = (θ_1 … θ_n, ψ_1 … ψ_n)`.
#[derive(Debug, Clone, PartialEq)]
pub struct Linearisation {
    /// Mass matrix `M`, kg·m².
    pub mass: DMatrix<f64>,
    /// Gyroscopic matrix `G` (skew), kg·m²/s.
    pub gyroscopic: DMatrix<f64>,
    /// Stiffness `H`, the Hessian of the amended potential, N·m.
    pub stiffness: DMatrix<f64>,
}

/// The verdict on one steady shape.
#[derive(Debug, Clone, PartialEq)]
pub struct Stability {
    /// Eigenvalues of the first-order linearisation (4n of them), 1/s.
    pub eigenvalues: Vec<Complex<f64>>,
    /// The largest real part, 1/s (≤ 0 up to round-off when spectrally stable), without the
    /// symmetry's zero pair.
    pub growth_rate: f64,
    /// The number of negative eigenvalues of `H` (the Morse index of the amended
    /// potential), out of and in the plane.
    pub index: usize,
    /// Spectrally stable: no eigenvalue with real part above the tolerance (module docs).
    pub spectrally_stable: bool,
}

impl Stability {
    /// Stable with any small damping in the turning frame: index 0 (Kelvin–Tait–Chetaev).
    pub fn stable_with_damping(&self) -> bool {
        self.index == 0
    }

    /// The verdict in three classes ([`Verdict::of`]).
    pub fn verdict(&self) -> Verdict {
        Verdict::of(self)
    }
}

/// The verdict on one steady shape in three classes (module docs, "What stable means").
///
/// Undamped: [`Stable`](Self::Stable) is spectral stability with index 0 (a minimum of
/// the amended potential, stable by Lagrange–Dirichlet), [`Gyroscopic`](Self::Gyroscopic)
/// spectral stability with an (even) index > 0, held by the Coriolis terms and destroyed by
/// any damping in the turning frame (Kelvin–Tait–Chetaev), [`Unstable`](Self::Unstable) an
/// eigenvalue with real part above the tolerance. Damped: every eigenvalue decays
/// (`Stable`) or one does not (`Unstable`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Verdict {
    /// Spectrally stable with index 0 (damped: every eigenvalue has `Re λ ≤` tolerance).
    Stable,
    /// Spectrally stable although the amended potential has `index` descent directions.
    Gyroscopic {
        /// The number of negative eigenvalues of `H` (in and out of the plane).
        index: usize,
    },
    /// The largest real part of the eigenvalues, `growth_rate = max Re λ > ` tolerance, 1/s:
    /// perturbations grow as `exp(growth_rate · t)`.
    Unstable {
        /// `max Re λ`, 1/s.
        growth_rate: f64,
    },
}

impl Verdict {
    /// The verdict of [`stability`]'s result: `Unstable` unless spectrally stable, then
    /// `Stable` at index 0 and `Gyroscopic` above.
    pub fn of(stability: &Stability) -> Self {
        if !stability.spectrally_stable {
            Self::Unstable { growth_rate: stability.growth_rate }
        } else if stability.index == 0 {
            Self::Stable
        } else {
            Self::Gyroscopic { index: stability.index }
        }
    }

    /// The verdict of a spectrum (1/s), e.g. [`crate::relative_spectrum`] of a
    /// damped chain: `Unstable` when `g = max Re λ > tolerance` (1/s), otherwise
    /// `Gyroscopic` if `index` (the index of `H`, when known) is positive, else `Stable`.
    /// For a damped spectrum pass `index = None`: decay is then stability, whatever the
    /// potential. An empty spectrum is `Stable`.
    pub fn of_spectrum(eigenvalues: &[Complex<f64>], index: Option<usize>, tolerance: f64) -> Self {
        let growth_rate = eigenvalues.iter().map(|z| z.re).fold(f64::NEG_INFINITY, f64::max);
        if growth_rate > tolerance {
            Self::Unstable { growth_rate }
        } else {
            match index {
                Some(index) if index > 0 => Self::Gyroscopic { index },
                _ => Self::Stable,
            }
        }
    }

    /// One word: `"stable"`, `"gyroscopic"` or `"unstable"`.
    pub fn label(&self) -> &'static str {
        match self {
            Self::Stable => "stable",
            Self::Gyroscopic { .. } => "gyroscopic",
            Self::Unstable { .. } => "unstable",
        }
    }

    /// Spectrally (undamped) or asymptotically (damped) stable: `Stable` or `Gyroscopic`.
    pub fn is_stable(&self) -> bool {
        !matches!(self, Self::Unstable { .. })
    }

    /// The growth rate of an `Unstable` verdict, 1/s.
    pub fn growth_rate(&self) -> Option<f64> {
        match self {
            Self::Unstable { growth_rate } => Some(*growth_rate),
            _ => None,
        }
    }
}

impl std::fmt::Display for Verdict {
    /// `stable`, `gyroscopic (index 2)`, `unstable (growth 0.0720 1/s)` (three significant
    /// digits, exponent form below 1e-3 and from 1e4 on).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Stable => f.write_str("stable"),
            Self::Gyroscopic { index } => write!(f, "gyroscopic (index {index})"),
            Self::Unstable { growth_rate: g } if (1e-3..1e4).contains(g) => {
                let decimals = (2 - g.log10().floor() as i32).max(0) as usize;
                write!(f, "unstable (growth {g:.decimals$} 1/s)")
            }
            Self::Unstable { growth_rate } => write!(f, "unstable (growth {growth_rate:.2e} 1/s)"),
        }
    }
}

/// The linearisation of the 3D equations in the turning frame about `shape` (module docs).
pub fn linearise(problem: &SteadyRotation, shape: &SteadyShape) -> Linearisation {
    let n = problem.links();
    let (_, l, tails) = problem.parameters();
    let omega = shape.omega;
    let w2 = omega * omega;
    let theta = &shape.theta;
    let cos: Vec<f64> = theta.iter().map(|t| t.cos()).collect();
    let w = |a: usize, b: usize| tails[a.max(b)] * l[a] * l[b];
    let e = problem.rod_stiffness(theta, &shape.displacements, w2);
    let mut mass = DMatrix::zeros(2 * n, 2 * n);
    let mut gyroscopic = DMatrix::zeros(2 * n, 2 * n);
    let mut stiffness = DMatrix::zeros(2 * n, 2 * n);
    for a in 0..n {
        for b in 0..n {
            let wab = w(a, b);
            mass[(a, b)] = wab * (theta[a] - theta[b]).cos();
            mass[(n + a, n + b)] = wab;
            gyroscopic[(n + a, b)] = 2.0 * omega * wab * cos[b];
            gyroscopic[(b, n + a)] = -2.0 * omega * wab * cos[b];
            stiffness[(a, b)] = -w2 * wab * cos[a] * cos[b];
            stiffness[(n + a, n + b)] = -w2 * wab;
        }
        stiffness[(a, a)] += e[a];
        stiffness[(n + a, n + a)] += e[a];
    }
    Linearisation { mass, gyroscopic, stiffness }
}

/// Checks damping `λ_i` (N·m·s): one per link, finite and non-negative.
fn check_damping(damping: Option<&[f64]>, n: usize) -> Result<()> {
    if let Some(d) = damping {
        if d.len() != n {
            return Err(Error::LengthMismatch { what: "damping", expected: n, got: d.len() });
        }
        if let Some((i, &v)) = d.iter().enumerate().find(|(_, v)| !(v.is_finite() && **v >= 0.0)) {
            return Err(Error::InvalidDamping { link: i + 1, value: v });
        }
    }
    Ok(())
}

/// The number of eigenvalues of the rotational symmetry set aside (module docs): for free
/// rotation (`R = 0`) off the vertical, two undamped (a Jordan block), one damped.
fn symmetry_zeros(problem: &SteadyRotation, shape: &SteadyShape, damped: bool) -> usize {
    let symmetric = problem.radius() == 0.0 && shape.theta.iter().any(|t| t.sin().abs() > 1e-12);
    match (symmetric, damped) {
        (false, _) => 0,
        (true, false) => 2,
        (true, true) => 1,
    }
}

/// The tolerance (1/s) above which a real part counts as growth: `1e-8` times the
/// spectrum's size ([`SteadyRotation::spectrum_scale`]), against which round-off in the
/// eigenvalues is measured.
fn growth_tolerance(problem: &SteadyRotation, shape: &SteadyShape) -> f64 {
    1e-8 * problem.spectrum_scale(shape)
}

/// The undamped or damped count of eigenvalues the index of `H` accounts for (see
/// [`stability`]).
fn counted(found: &[(Complex<f64>, f64)], damped: bool, tolerance: f64) -> usize {
    found
        .iter()
        .map(|&(z, energy)| {
            if damped {
                usize::from(z.re > tolerance)
            } else if z.re > tolerance {
                if z.im.abs() <= tolerance {
                    1
                } else if z.im > 0.0 {
                    2
                } else {
                    0
                }
            } else if z.re.abs() <= tolerance && z.im > tolerance && energy < 0.0 {
                2
            } else {
                0
            }
        })
        .sum()
}

/// Classify `shape` by the eigenvalues of the linearisation nearest the origin, with
/// damping `λ_i` (N·m·s, one per link, applied to `θ̇_i` and `ψ̇_i` in the turning frame)
/// or `None`, in `O(n)` per Arnoldi step.
///
/// Only eigenvalues near the origin can leave the imaginary axis: an eigenvalue with
/// `Re λ > 0` has `|λ|² = −p*Hp / p*Mp` (undamped) or less (damped), so it lies among the
/// modes the amended potential softens. The index of `H` comes from the signs of its
/// `L D Lᵀ` pivots (`analysis::turning_pencil`); the eigenvalues nearest the
/// origin from shift-and-invert Arnoldi on the quadratic pencil `λ²M + λ(G + D) + H`
/// (each step one `O(n)` quasiseparable solve), until they account for the whole index:
/// undamped, `k_r + 2 k_c + 2 k_i⁻ = index` (real, complex-quartet and imaginary
/// negative-energy eigenvalues, the Krein signature `|λ|² p*Mp + p*Hp < 0`); damped,
/// `index` eigenvalues in the right half-plane (Kelvin–Tait–Chetaev). Then no other
/// eigenvalue can grow, and the verdict is that of [`stability_dense`], which computes all
/// `4n`. `eigenvalues` holds those found (at least 8, sorted by modulus); `growth_rate`
/// is their largest real part. Falls back to the whole spectrum when the count is not
/// reached.
///
/// Errors: [`Error::LengthMismatch`] / [`Error::InvalidDamping`] for bad damping,
/// [`Error::NotPositiveDefinite`] if no shift gives a regular pencil.
pub fn stability(
    problem: &SteadyRotation,
    shape: &SteadyShape,
    damping: Option<&[f64]>,
) -> Result<Stability> {
    const MIN_FOUND: usize = 8;
    const CONVERGED: f64 = 1e-10;
    let n = problem.links();
    check_damping(damping, n)?;
    let Some(index) = stiffness_index(problem, shape, 1e-9) else {
        return stability_dense(problem, shape, damping);
    };
    let damped = damping.is_some();
    let zeros = symmetry_zeros(problem, shape, damped);
    let tolerance = growth_tolerance(problem, shape);
    let mass = combination(problem, shape, damping, Combination::MASS);
    let velocity = combination(problem, shape, damping, Combination::VELOCITY);
    let stiffness = combination(problem, shape, damping, Combination::STIFFNESS);
    let (mut sigma, mut factor) = (1e-2 * problem.reference_speed(), None);
    for _ in 0..6 {
        let q = combination(problem, shape, damping, Combination::at(sigma));
        let scale = q.diagonal.iter().fold(0.0, |a: f64, d| a.max(d.abs()));
        factor = q.factor().filter(|f| f.pivots().iter().all(|p| p.abs() > 1e-13 * scale)).map(|f| (q, f));
        if factor.is_some() {
            break;
        }
        sigma *= 1.618;
    }
    let Some((pencil, factor)) = factor else { return Err(Error::NotPositiveDefinite) };
    let size = 2 * n;
    let (mut t, mut r, mut check) = (vec![0.0; size], vec![0.0; size], vec![0.0; size]);
    // (A − σ)⁻¹ (b1, b2) = (p, b1 + σ p) with Q(σ) p = −(M (b2 + σ b1) + (G + D) b1), one
    // step of iterative refinement (the factor is unpivoted).
    let mut apply = |b: &[f64], out: &mut [f64]| {
        let (b1, b2) = b.split_at(size);
        for k in 0..size {
            t[k] = b2[k] + sigma * b1[k];
        }
        mass.mul(&t, &mut r);
        velocity.mul(b1, &mut t);
        let (p, v) = out.split_at_mut(size);
        for k in 0..size {
            r[k] = -(r[k] + t[k]);
            p[k] = r[k];
        }
        factor.solve(p);
        pencil.mul(p, &mut check);
        for k in 0..size {
            t[k] = r[k] - check[k];
        }
        factor.solve(&mut t);
        for k in 0..size {
            p[k] += t[k];
            v[k] = b1[k] + sigma * p[k];
        }
    };
    let quadratic = |q: &Quasiseparable<3>, x: &[Complex<f64>]| -> f64 {
        let (re, im): (Vec<f64>, Vec<f64>) = x.iter().map(|z| (z.re, z.im)).unzip();
        let mut y = vec![0.0; x.len()];
        q.mul(&re, &mut y);
        let mut sum: f64 = re.iter().zip(&y).map(|(a, b)| a * b).sum();
        q.mul(&im, &mut y);
        sum += im.iter().zip(&y).map(|(a, b)| a * b).sum::<f64>();
        sum
    };
    let dim = 4 * n;
    let mut arnoldi = Arnoldi::new(dim);
    let mut steps = (2 * index + 24).min(dim);
    loop {
        arnoldi.extend(steps - arnoldi.steps(), &mut apply);
        if arnoldi.broken() {
            return stability_dense(problem, shape, damping);
        }
        let complete = arnoldi.complete();
        // The symmetry's zeros form a Jordan block, whose Ritz values converge only to
        // O(sqrt(ε)): they do not end the run of converged values nearest the origin.
        let zero = |theta: Complex<f64>| {
            complete || (zeros > 0 && (Complex::new(sigma, 0.0) + theta.inv()).norm() < 100.0 * tolerance)
        };
        let ritz = arnoldi.ritz(CONVERGED, zero);
        let converged = ritz.iter().take_while(|r| r.residual <= CONVERGED || zero(r.value));
        let mut found: Vec<(Complex<f64>, &Ritz)> =
            converged.map(|r| (Complex::new(sigma, 0.0) + r.value.inv(), r)).collect();
        found.sort_by(|a, b| a.0.norm().total_cmp(&b.0.norm()));
        let counted_from = zeros.min(found.len());
        let energies: Vec<(Complex<f64>, f64)> = found[counted_from..]
            .iter()
            .map(|(z, r)| {
                let needed = !damped && z.re.abs() <= tolerance && z.im > tolerance;
                let energy = if needed {
                    let vector = arnoldi.vector(r);
                    let p = &vector[..size];
                    z.norm_sqr() * quadratic(&mass, p) + quadratic(&stiffness, p)
                } else {
                    0.0
                };
                (*z, energy)
            })
            .collect();
        let enough = found.len() >= MIN_FOUND.min(dim) && counted(&energies, damped, tolerance) >= index;
        if complete || enough {
            let eigenvalues: Vec<Complex<f64>> = found.iter().map(|(z, _)| *z).collect();
            let growth_rate =
                eigenvalues[counted_from..].iter().map(|z| z.re).fold(f64::NEG_INFINITY, f64::max);
            return Ok(Stability {
                eigenvalues,
                growth_rate,
                index,
                spectrally_stable: growth_rate <= tolerance,
            });
        }
        steps = (steps + 16 + steps / 2).min(dim);
    }
}

/// Classify `shape` by all `4n` eigenvalues of the linearisation (the reference route of
/// [`stability`]), with damping `λ_i` (N·m·s, one per link, applied to `θ̇_i` and `ψ̇_i` in
/// the turning frame) or `None`.
///
/// Eigenvalues are those of `[[0, I], [−M⁻¹H, −M⁻¹(G + D)]]` (dense Schur, O(n³)),
/// sorted by modulus; a real part counts as growth above `1e-8` times the spectrum's size
/// (see [`stability`]). For free rotation (`R = 0`) off the vertical the smallest
/// eigenvalues are the rotational symmetry's zeros (two undamped, one damped) and are
/// left out of the growth rate.
///
/// Errors: [`Error::LengthMismatch`] / [`Error::InvalidDamping`] for bad damping,
/// [`Error::NotPositiveDefinite`] if `M` fails to factor.
pub fn stability_dense(
    problem: &SteadyRotation,
    shape: &SteadyShape,
    damping: Option<&[f64]>,
) -> Result<Stability> {
    let n = problem.links();
    check_damping(damping, n)?;
    let lin = linearise(problem, shape);
    let mut friction = lin.gyroscopic.clone();
    for (i, &v) in damping.unwrap_or(&[]).iter().enumerate() {
        friction[(i, i)] += v;
        friction[(n + i, n + i)] += v;
    }
    let chol = lin.mass.clone().cholesky().ok_or(Error::NotPositiveDefinite)?;
    let k = chol.solve(&lin.stiffness);
    let c = chol.solve(&friction);
    let mut a = DMatrix::zeros(4 * n, 4 * n);
    a.view_mut((0, 2 * n), (2 * n, 2 * n)).fill_with_identity();
    a.view_mut((2 * n, 0), (2 * n, 2 * n)).copy_from(&(-k));
    a.view_mut((2 * n, 2 * n), (2 * n, 2 * n)).copy_from(&(-c));
    let mut eigenvalues: Vec<Complex<f64>> = a.complex_eigenvalues().iter().copied().collect();
    eigenvalues.sort_by(|x, y| x.norm().total_cmp(&y.norm()));
    // Free rotation off the vertical: turning the shape about the axis is an exact
    // symmetry, a double zero eigenvalue undamped (a Jordan block, split by round-off to
    // O(sqrt(ε)|A|)), a single one damped; it is set aside, not counted as growth.
    let zeros = symmetry_zeros(problem, shape, damping.is_some());
    let counted = &eigenvalues[zeros.min(eigenvalues.len())..];
    let growth_rate = counted.iter().map(|z| z.re).fold(f64::NEG_INFINITY, f64::max);
    let tolerance = growth_tolerance(problem, shape);
    let scale = lin.stiffness.amax();
    let h_eigen: DVector<f64> = lin.stiffness.symmetric_eigenvalues();
    let index = h_eigen.iter().filter(|&&v| v < -1e-9 * scale).count();
    Ok(Stability { eigenvalues, growth_rate, index, spectrally_stable: growth_rate <= tolerance })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::modes::normal_modes;
    use crate::analysis::steady_branches::{BranchEnd, ContinuationOptions};
    use crate::chain::Chain;
    use approx::assert_relative_eq;
    use nalgebra::Dyn;

    #[test]
    fn vertical_chain_turns_its_modes_by_omega() {
        // At θ = 0 the turning frame sees each mode ω_k as ±i(ω_k ± ω).
        let chain = Chain::<Dyn>::new(&[0.4, 1.0, 0.6], &[0.3, 0.5, 0.2], 9.81).unwrap();
        let p = SteadyRotation::new(&chain, 0.0).unwrap();
        let omega = 3.3;
        let shape = p.shape(omega, DVector::zeros(3));
        let st = stability(&p, &shape, None).unwrap();
        let mut found: Vec<f64> = st.eigenvalues.iter().map(|z| z.im).collect();
        found.sort_by(f64::total_cmp);
        let mut expected: Vec<f64> = normal_modes(&chain)
            .frequencies
            .iter()
            .flat_map(|w| [w + omega, w - omega, -w + omega, -w - omega])
            .collect();
        expected.sort_by(f64::total_cmp);
        for (f, e) in found.iter().zip(&expected) {
            assert_relative_eq!(*f, *e, epsilon = 1e-9);
        }
        assert!(st.spectrally_stable);
    }

    #[test]
    fn conical_pendulum_is_stable_and_damping_keeps_it() {
        let p = SteadyRotation::new(&Chain::<Dyn>::new(&[1.0], &[1.0], 9.81).unwrap(), 0.0).unwrap();
        let omega = 5.0;
        let shape = p.solve(omega, &DVector::from_element(1, 1.0)).unwrap();
        let st = stability(&p, &shape, None).unwrap();
        assert!(st.spectrally_stable);
        assert_eq!(st.index, 0);
        let damped = stability(&p, &shape, Some(&[0.05])).unwrap();
        assert!(damped.spectrally_stable);
        // Small oscillation of the conical pendulum, the in- and out-of-plane motions
        // coupled by Coriolis: λ²(λ² + ω²(sin²θ + 4 cos²θ)) = 0, ω_osc = ω sqrt(1 + 3 cos²θ).
        let expected = omega * (1.0 + 3.0 * shape.theta[0].cos().powi(2)).sqrt();
        assert!(st.eigenvalues.iter().any(|z| (z.im.abs() - expected).abs() < 1e-8), "{:?}", st.eigenvalues);
    }

    #[test]
    fn damping_destroys_gyroscopic_stabilisation_of_the_vertical() {
        // Above the first critical speed the vertical has index 2 (one direction per
        // plane) yet is spectrally stable; damping in the turning frame makes it unstable.
        let chain = Chain::<Dyn>::uniform(3, 1.0, 0.3, 9.81).unwrap();
        let p = SteadyRotation::new(&chain, 0.0).unwrap();
        let w1 = normal_modes(&chain).frequencies[0];
        let shape = p.shape(1.2 * w1, DVector::zeros(3));
        let st = stability(&p, &shape, None).unwrap();
        assert_eq!(st.index, 2);
        assert!(st.spectrally_stable);
        let damped = stability(&p, &shape, Some(&[0.01; 3])).unwrap();
        assert!(!damped.spectrally_stable);
        assert!(damped.growth_rate > 0.0);
    }

    #[test]
    fn in_plane_stiffness_is_the_shape_equations_hessian() {
        let chain = Chain::<Dyn>::uniform(4, 1.0, 0.25, 9.81).unwrap();
        let p = SteadyRotation::new(&chain, 0.05).unwrap();
        let shape = p.solve(9.0, &DVector::from_element(4, 0.8)).unwrap();
        let lin = linearise(&p, &shape);
        let h = p.hessian(&shape.theta, 81.0);
        assert_relative_eq!(lin.stiffness.view((0, 0), (4, 4)).into_owned(), h, epsilon = 1e-12);
        assert_relative_eq!(lin.gyroscopic.clone(), -lin.gyroscopic.transpose(), epsilon = 1e-14);
    }

    #[test]
    fn first_branch_is_stable_and_the_second_unstable() {
        let chain = Chain::<Dyn>::uniform(6, 1.0, 1.0 / 6.0, 9.81).unwrap();
        let p = SteadyRotation::new(&chain, 0.0).unwrap();
        let speeds = p.bifurcation_speeds(2).unwrap();
        let opts = ContinuationOptions::default();
        let b1 = p.branch(1, 1.5 * speeds[1], &opts).unwrap();
        for s in &b1.points[1..] {
            let st = stability(&p, s, None).unwrap();
            assert!(st.spectrally_stable && st.index == 0, "k=1 at ω = {}: {:?}", s.omega, st.growth_rate);
        }
        assert!(b1.points.len() >= 10, "{} points", b1.points.len());
        let b2 = p.branch(2, 1.5 * speeds[1], &opts).unwrap();
        // Not the vertical it starts from (also of index > 0 above ω_1): a two-node
        // shape of finite size, at the speed asked for.
        assert!(b2.points.len() >= 10, "{} points", b2.points.len());
        let last = b2.points.last().unwrap();
        assert_eq!(b2.end, BranchEnd::ReachedOmega);
        assert!(last.omega >= 1.5 * speeds[1], "ended at ω = {}", last.omega);
        assert_eq!(last.nodes(), 2);
        assert!(last.theta.amax() > 0.2, "{}", last.theta);
        let st = stability(&p, last, None).unwrap();
        // Index 2 and a complex quartet with growth ~0.2/s: unstable, not merely of
        // nonzero index.
        println!(
            "second branch at ω = {}: index {}, growth rate {:.3} 1/s",
            last.omega, st.index, st.growth_rate
        );
        assert_eq!(st.index, 2);
        assert!(!st.spectrally_stable && st.growth_rate > 0.1, "{st:?}");
    }

    #[test]
    fn verdicts_of_the_three_classes() {
        // One node: stable; the vertical above ω_1: gyroscopic, index 2; damped: unstable.
        let p = SteadyRotation::new(&Chain::<Dyn>::new(&[1.0], &[1.0], 9.81).unwrap(), 0.0).unwrap();
        let conical = p.solve(5.0, &DVector::from_element(1, 1.0)).unwrap();
        assert_eq!(stability(&p, &conical, None).unwrap().verdict(), Verdict::Stable);
        let chain = Chain::<Dyn>::uniform(3, 1.0, 0.3, 9.81).unwrap();
        let p = SteadyRotation::new(&chain, 0.0).unwrap();
        let vertical = p.shape(1.2 * normal_modes(&chain).frequencies[0], DVector::zeros(3));
        let st = stability(&p, &vertical, None).unwrap();
        assert_eq!(Verdict::of(&st), Verdict::Gyroscopic { index: 2 });
        let damped = stability(&p, &vertical, Some(&[0.01; 3])).unwrap();
        let verdict = damped.verdict();
        assert_eq!(verdict, Verdict::Unstable { growth_rate: damped.growth_rate });
        assert!(verdict.growth_rate().unwrap() > 0.0 && !verdict.is_stable());
        assert_eq!(verdict.label(), "unstable");
    }

    #[test]
    fn odd_index_is_unstable_with_a_real_eigenvalue() {
        // A link on a circling pivot, well above its resonance: the large shape out of
        // phase with the pivot (x < 0) is stiff in the plane but has one direction of
        // descent out of it (H_ψψ = l(g cos θ + ω² sin θ x) − ω² l² < 0): index 1.
        let (radius, omega) = (0.1, 10.0);
        let p = SteadyRotation::new(&Chain::<Dyn>::new(&[1.0], &[0.5], 9.81).unwrap(), radius).unwrap();
        // g sin θ = ω² cos θ (R + l sin θ): three roots at this ω, the large negative one
        // near −1.3 rad.
        let opposite = p.solve(omega, &DVector::from_element(1, -1.3)).unwrap();
        assert!(opposite.displacements[0] < -0.3, "{:?}", opposite.displacements);
        let st = stability(&p, &opposite, None).unwrap();
        assert_eq!(st.index, 1);
        let Verdict::Unstable { growth_rate } = st.verdict() else { panic!("{:?}", st.verdict()) };
        let real =
            st.eigenvalues.iter().find(|z| z.im.abs() < 1e-9 && z.re > 0.0).expect("a real eigenvalue");
        assert_relative_eq!(real.re, growth_rate, epsilon = 1e-12);
    }

    #[test]
    fn verdicts_of_spectra() {
        let z = |re: f64, im: f64| Complex::new(re, im);
        let centre = [z(0.0, 2.0), z(0.0, -2.0), z(1e-10, 5.0), z(1e-10, -5.0)];
        assert_eq!(Verdict::of_spectrum(&centre, None, 1e-8), Verdict::Stable);
        assert_eq!(Verdict::of_spectrum(&centre, Some(0), 1e-8), Verdict::Stable);
        assert_eq!(Verdict::of_spectrum(&centre, Some(2), 1e-8), Verdict::Gyroscopic { index: 2 });
        let quadruple = [z(0.14, 9.0), z(0.14, -9.0), z(-0.14, 9.0), z(-0.14, -9.0)];
        assert_eq!(Verdict::of_spectrum(&quadruple, Some(2), 1e-8), Verdict::Unstable { growth_rate: 0.14 });
        let decaying = [z(-0.02, 3.0), z(-0.02, -3.0), z(-0.5, 0.0)];
        assert_eq!(Verdict::of_spectrum(&decaying, None, 1e-8), Verdict::Stable);
        assert_eq!(Verdict::of_spectrum(&[], None, 1e-8), Verdict::Stable);
        assert_eq!(Verdict::Gyroscopic { index: 4 }.to_string(), "gyroscopic (index 4)");
        assert_eq!(Verdict::Unstable { growth_rate: 0.072 }.to_string(), "unstable (growth 0.0720 1/s)");
        assert_eq!(Verdict::Unstable { growth_rate: 3.714 }.to_string(), "unstable (growth 3.71 1/s)");
        assert_eq!(Verdict::Unstable { growth_rate: 2.5e-5 }.to_string(), "unstable (growth 2.50e-5 1/s)");
        assert!(Verdict::Gyroscopic { index: 4 }.is_stable() && Verdict::Stable.growth_rate().is_none());
    }

    #[test]
    fn the_damped_forced_shape_decays_by_its_spectrum() {
        // The in-phase one-node shape of a damped chain on a circling pivot: its relative
        // equilibrium's spectrum decays, the verdict is stable; undamped, the same route
        // gives the verdict of `stability`.
        use crate::analysis::relative_equilibrium::{relative_equilibrium, relative_spectrum};
        use crate::drive::Circle;
        use crate::models::directions::Directions;
        use nalgebra::U3;
        let (radius, omega) = (0.03, 4.0);
        let chain = Chain::<Dyn>::uniform(3, 0.5, 0.3, 9.81).unwrap();
        let p = SteadyRotation::new(&chain, radius).unwrap();
        let shape = p.solve(omega, &DVector::from_element(3, 0.5)).unwrap();
        let undamped = stability(&p, &shape, None).unwrap();
        assert_eq!(undamped.verdict(), Verdict::Stable);
        let guess: Vec<(f64, f64)> = shape.theta.iter().map(|&t| (t, 0.0)).collect();
        for damping in [0.0, 0.02] {
            let c = chain.clone().with_damping(&[damping; 3]).unwrap();
            let model = Directions::<U3>::new(c).with_drive(Circle::new(radius, omega).unwrap());
            let eq = relative_equilibrium(&model, &guess).unwrap();
            let spectrum = relative_spectrum(&model, &eq).unwrap();
            let largest = spectrum.iter().map(|z| z.norm()).fold(0.0, f64::max);
            let verdict = Verdict::of_spectrum(&spectrum, (damping == 0.0).then_some(0), 1e-6 * largest);
            assert_eq!(verdict, Verdict::Stable, "λ = {damping}");
            let growth = spectrum.iter().map(|z| z.re).fold(f64::NEG_INFINITY, f64::max);
            assert!(if damping > 0.0 { growth < -1e-3 } else { growth.abs() < 1e-6 * largest }, "{growth}");
        }
    }

    #[test]
    fn bad_damping_is_named() {
        let p = SteadyRotation::new(&Chain::<Dyn>::uniform(2, 1.0, 1.0, 9.81).unwrap(), 0.0).unwrap();
        let s = p.shape(1.0, DVector::zeros(2));
        assert!(matches!(stability(&p, &s, Some(&[0.1])), Err(Error::LengthMismatch { .. })));
        assert!(matches!(stability(&p, &s, Some(&[0.1, -1.0])), Err(Error::InvalidDamping { link: 2, .. })));
    }
}
