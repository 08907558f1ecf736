//! Steady rotation (relative equilibria): the chain turning rigidly about the vertical
//! through the pivot at angular speed `ω`, its shape in a plane that turns with it.
//!
//! # The shape equations
//!
//! In the frame turning at `ω` about the vertical, take the shape's plane as x–z, the
//! pivot at `(R, 0, 0)` (`R = 0`: fixed pivot on the axis; `R > 0`: the pivot driven round
//! a horizontal circle of radius `R` at `ω`), and signed angles `θ_i` of link `i` from the
//! downward vertical. Mass `i` sits at horizontal distance
//! `x_i = R + Σ_{j≤i} l_j sin θ_j` from the axis. At rest in that frame each mass feels its
//! weight `m_i g` (down) and the centrifugal force `m_i ω² x_i` (outward); the Coriolis
//! force vanishes. Rod `d` carries the total of these forces on the masses below it, and
//! a rod can only pull along itself, so `(sin θ_d, cos θ_d) ∥ (ω² S_d, g M_d)`:
//!
//! ```text
//! F_d(θ, ω) = l_d [ g M_d sin θ_d − ω² cos θ_d S_d ] = 0,   S_d = Σ_{i≥d} m_i x_i,
//! ```
//!
//! (`M_d` the tail mass). `F = ∇V` is the gradient of the effective (amended) potential
//! `V = −g Σ m_i Σ_{j≤i} l_j cos θ_j − ½ ω² Σ m_i x_i²`, so its Jacobian is the symmetric
//! Hessian
//!
//! ```text
//! H_de = δ_de l_d (g M_d cos θ_d + ω² sin θ_d S_d) − ω² W_de cos θ_d cos θ_e,
//! ∂F_d/∂(ω²) = −l_d cos θ_d S_d,
//! ```
//!
//! with `W_de = M_max(d,e) l_d l_e` ([`Chain::weight`]). For one link this is the conical
//! pendulum: `sin θ (g − ω² l cos θ) = 0`, `cos θ = g / (l ω²)`.
//!
//! # Bifurcations from the vertical (R = 0)
//!
//! `θ = 0` solves the equations at every `ω`; there `H = K − ω² W` with
//! `K = diag(g M_d l_d)`. A branch leaves the vertical where `H` turns singular, i.e.
//! where `ω²` crosses an eigenvalue of `K v = ω² W v`: the critical speeds are the normal
//! mode frequencies ([`crate::normal_modes`]), and the branch leaving at the k-th carries
//! the k-th mode shape, with `k` nodes (the pivot and `k − 1` axis crossings).
//! [`SteadyRotation::bifurcation_speeds`] finds them without the mode solver, by counting
//! the negative eigenvalues of `H(0, ω)` and bisecting on `ω`.
//!
//! # Continuation
//!
//! Branches are followed by pseudo-arclength continuation in `y = (θ, p)`,
//! `p = ω² / ω_s²` with `ω_s = sqrt(g / L)` (`L` the chain's total length): predictor
//! `y + h t` along the unit tangent `t`, corrector Newton on `[F(y); tᵀ(y − y_prev) − h]`,
//! so the branch may fold back in `ω` (the forced case does).

use nalgebra::{DMatrix, DVector, DefaultAllocator, Dim, allocator::Allocator};

use crate::analysis::modes::sign_changes;
use crate::analysis::quasiseparable::Quasiseparable;
use crate::chain::Chain;
use crate::error::{Error, Result};

/// The steady-rotation problem of one chain: parameters and pivot radius.
#[derive(Debug, Clone, PartialEq)]
pub struct SteadyRotation {
    masses: Vec<f64>,
    lengths: Vec<f64>,
    tails: Vec<f64>,
    gravity: f64,
    radius: f64,
    scale: f64,
}

/// One steady shape: angular speed, link angles and where the masses are.
#[derive(Debug, Clone, PartialEq)]
pub struct SteadyShape {
    /// Angular speed of the rotation `ω`, rad/s.
    pub omega: f64,
    /// Signed link angles `θ_i` from the downward vertical in the turning plane, rad.
    pub theta: DVector<f64>,
    /// Horizontal distances from the rotation axis `x_i = R + Σ_{j≤i} l_j sin θ_j`
    /// (signed, m), one per mass.
    pub displacements: Vec<f64>,
}

impl SteadyShape {
    /// The number of nodes: the pivot plus the number of times the chain crosses the axis
    /// (sign changes of `x_1 … x_n`). Branch `k` leaving the vertical has `k` nodes.
    pub fn nodes(&self) -> usize {
        1 + sign_changes(&self.displacements)
    }

    /// The amplitude `max_i |x_i|`, m: the largest distance of a mass from the axis.
    pub fn amplitude(&self) -> f64 {
        self.displacements.iter().fold(0.0, |a, x| a.max(x.abs()))
    }
}

/// How a continuation run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BranchEnd {
    /// The branch passed the requested largest angular speed.
    ReachedOmega,
    /// The branch came back down to `ω = 0`.
    ReachedZeroOmega,
    /// The step size fell below [`ContinuationOptions::min_step`] (Newton kept failing).
    StepTooSmall,
    /// [`ContinuationOptions::max_points`] points were computed.
    MaxPoints,
}

/// A branch of steady shapes, in continuation order.
#[derive(Debug, Clone, PartialEq)]
pub struct Branch {
    /// The shapes along the branch.
    pub points: Vec<SteadyShape>,
    /// Why the continuation stopped.
    pub end: BranchEnd,
}

/// Step control of the pseudo-arclength continuation (arclength in `(θ [rad], p)`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContinuationOptions {
    /// First step, default 0.02.
    pub initial_step: f64,
    /// Largest step, default 0.25.
    pub max_step: f64,
    /// Smallest step before giving up, default 1e-7.
    pub min_step: f64,
    /// Most points on one branch, default 5000.
    pub max_points: usize,
}

impl Default for ContinuationOptions {
    fn default() -> Self {
        Self { initial_step: 0.02, max_step: 0.25, min_step: 1e-7, max_points: 5000 }
    }
}

const NEWTON_ITERATIONS: usize = 30;
const NEWTON_STEP_TOL: f64 = 1e-12;

impl SteadyRotation {
    /// The steady-rotation problem of `chain` with the pivot on a horizontal circle of
    /// radius `radius` (m; `0` for a fixed pivot on the rotation axis).
    ///
    /// Errors: [`Error::InvalidSteady`] when `g` is zero (no gravity: no preferred shape)
    /// or `radius` is negative or not finite.
    pub fn new<L: Dim>(chain: &Chain<L>, radius: f64) -> Result<Self>
    where
        DefaultAllocator: Allocator<L>,
    {
        if chain.gravity() <= 0.0 {
            return Err(Error::InvalidSteady {
                what: "gravity",
                requirement: "positive",
                value: chain.gravity(),
            });
        }
        if !(radius.is_finite() && radius >= 0.0) {
            return Err(Error::InvalidSteady {
                what: "pivot radius",
                requirement: "finite and non-negative",
                value: radius,
            });
        }
        let lengths: Vec<f64> = chain.lengths().iter().copied().collect();
        let total: f64 = lengths.iter().sum();
        Ok(Self {
            masses: chain.masses().iter().copied().collect(),
            tails: chain.tail_masses().iter().copied().collect(),
            lengths,
            gravity: chain.gravity(),
            radius,
            scale: (chain.gravity() / total).sqrt(),
        })
    }

    /// Number of links.
    pub fn links(&self) -> usize {
        self.masses.len()
    }

    /// Pivot radius `R`, m.
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// The reference speed `ω_s = sqrt(g / L)`, rad/s (`L` the total length).
    pub fn reference_speed(&self) -> f64 {
        self.scale
    }

    /// The chain's masses, link lengths and tail masses (kg, m, kg).
    pub fn parameters(&self) -> (&[f64], &[f64], &[f64]) {
        (&self.masses, &self.lengths, &self.tails)
    }

    /// Gravity `g`, m/s².
    pub fn gravity(&self) -> f64 {
        self.gravity
    }

    /// Horizontal distances `x_i = R + Σ_{j≤i} l_j sin θ_j`, m.
    pub fn displacements(&self, theta: &DVector<f64>) -> Vec<f64> {
        let mut x = self.radius;
        self.lengths
            .iter()
            .zip(theta.iter())
            .map(|(l, t)| {
                x += l * t.sin();
                x
            })
            .collect()
    }

    /// `S_d = Σ_{i≥d} m_i x_i`, kg·m.
    fn moments(&self, x: &[f64]) -> Vec<f64> {
        let mut s = vec![0.0; x.len()];
        let mut acc = 0.0;
        for i in (0..x.len()).rev() {
            acc += self.masses[i] * x[i];
            s[i] = acc;
        }
        s
    }

    /// `E_d = l_d (g M_d cos θ_d + ω² sin θ_d S_d)` (N·m): the tension of rod `d` times its
    /// length, the diagonal of `H` beyond the centrifugal term, for angles `theta` with
    /// horizontal distances `x` (m) at `ω² = omega2`.
    pub(crate) fn rod_stiffness(&self, theta: &DVector<f64>, x: &[f64], omega2: f64) -> Vec<f64> {
        let s = self.moments(x);
        (0..self.links())
            .map(|d| {
                let (sin, cos) = theta[d].sin_cos();
                self.lengths[d] * (self.gravity * self.tails[d] * cos + omega2 * sin * s[d])
            })
            .collect()
    }

    /// The shape equations `F_d = l_d [g M_d sin θ_d − ω² cos θ_d S_d]` (N·m), module docs.
    pub fn residual(&self, theta: &DVector<f64>, omega2: f64) -> DVector<f64> {
        let s = self.moments(&self.displacements(theta));
        DVector::from_fn(self.links(), |d, _| {
            self.lengths[d] * (self.gravity * self.tails[d] * theta[d].sin() - omega2 * theta[d].cos() * s[d])
        })
    }

    /// The Jacobian `∂F/∂θ`, the Hessian of the effective potential (N·m/rad), module docs.
    pub fn hessian(&self, theta: &DVector<f64>, omega2: f64) -> DMatrix<f64> {
        let n = self.links();
        let stiffness = self.rod_stiffness(theta, &self.displacements(theta), omega2);
        let cos: Vec<f64> = theta.iter().map(|t| t.cos()).collect();
        DMatrix::from_fn(n, n, |d, e| {
            let w = self.tails[d.max(e)] * self.lengths[d] * self.lengths[e];
            let mut h = -omega2 * w * cos[d] * cos[e];
            if d == e {
                h += stiffness[d];
            }
            h
        })
    }

    /// The Hessian `H` of [`hessian`](Self::hessian) as a quasiseparable matrix
    /// (`H_de = −ω² M_d l_d cos θ_d · l_e cos θ_e` below the diagonal, `d > e`), for
    /// `O(n)` solves and eigenvalue counts.
    pub(crate) fn hessian_quasiseparable(&self, theta: &DVector<f64>, omega2: f64) -> Quasiseparable<1> {
        let n = self.links();
        let stiffness = self.rod_stiffness(theta, &self.displacements(theta), omega2);
        let mut h = Quasiseparable {
            diagonal: Vec::with_capacity(n),
            lower_rows: Vec::with_capacity(n),
            lower_columns: Vec::with_capacity(n),
            upper_rows: Vec::with_capacity(n),
            upper_columns: Vec::with_capacity(n),
        };
        for d in 0..n {
            let c = self.lengths[d] * theta[d].cos();
            let soft = -omega2 * self.tails[d] * c;
            h.diagonal.push(stiffness[d] + soft * c);
            h.lower_rows.push([soft]);
            h.lower_columns.push([c]);
            h.upper_rows.push([c]);
            h.upper_columns.push([soft]);
        }
        h
    }

    /// Solves `H(θ, ω²) x = b` in `O(n)` ([`hessian_quasiseparable`](Self::hessian_quasiseparable),
    /// one step of iterative refinement); `None` when a pivot vanishes.
    fn solve_hessian(&self, theta: &DVector<f64>, omega2: f64, b: &DVector<f64>) -> Option<DVector<f64>> {
        let h = self.hessian_quasiseparable(theta, omega2);
        refined(&h, b)
    }

    /// Solves the bordered system `[H, ∂F/∂p; row] x = b` (`row` of length n + 1, the
    /// pseudo-arclength equation) in `O(n)`: the border is one more rank of the
    /// quasiseparable generators. `None` when a pivot vanishes.
    fn solve_bordered(
        &self,
        theta: &DVector<f64>,
        omega2: f64,
        row: &DVector<f64>,
        b: &DVector<f64>,
    ) -> Option<DVector<f64>> {
        let n = self.links();
        let h = self.hessian_quasiseparable(theta, omega2);
        let dp = self.speed_derivative(theta) * (self.scale * self.scale);
        let mut q = Quasiseparable::<2> {
            diagonal: h.diagonal,
            lower_rows: h.lower_rows.iter().map(|x| [x[0], 0.0]).collect(),
            lower_columns: h.lower_columns.iter().zip(row.iter()).map(|(y, &t)| [y[0], t]).collect(),
            upper_rows: h.upper_rows.iter().zip(dp.iter()).map(|(p, &f)| [p[0], f]).collect(),
            upper_columns: h.upper_columns.iter().map(|z| [z[0], 0.0]).collect(),
        };
        q.diagonal.push(row[n]);
        q.lower_rows.push([0.0, 1.0]);
        q.lower_columns.push([0.0, 0.0]);
        q.upper_rows.push([0.0, 0.0]);
        q.upper_columns.push([0.0, 1.0]);
        refined(&q, b)
    }

    /// The size of the spectrum of `shape`'s linearisation, 1/s, without computing it:
    /// `max(|ω| + 2 max_a sqrt(|E_a| / (m_a l_a²)), sqrt(g/L))`, with
    /// `E_a = l_a (g M_a cos θ_a + ω² sin θ_a S_a)` the tension of rod `a` times its length
    /// (`2 sqrt(E_a / m_a l_a²)` is the fastest oscillation of a link against its
    /// neighbours).
    pub fn spectrum_scale(&self, shape: &SteadyShape) -> f64 {
        let stiffness = self.rod_stiffness(&shape.theta, &shape.displacements, shape.omega * shape.omega);
        let fastest = (0..self.links())
            .map(|a| (stiffness[a].abs() / (self.masses[a] * self.lengths[a] * self.lengths[a])).sqrt())
            .fold(0.0, f64::max);
        (shape.omega.abs() + 2.0 * fastest).max(self.scale)
    }

    /// `∂F/∂(ω²) = −l_d cos θ_d S_d`, N·m·s².
    pub fn speed_derivative(&self, theta: &DVector<f64>) -> DVector<f64> {
        let s = self.moments(&self.displacements(theta));
        DVector::from_fn(self.links(), |d, _| -self.lengths[d] * theta[d].cos() * s[d])
    }

    /// The force scale `g M_1 L` (N·m) residuals are measured against.
    fn force_scale(&self) -> f64 {
        self.gravity * self.tails[0] * self.lengths.iter().sum::<f64>()
    }

    /// A [`SteadyShape`] from angles and speed.
    pub fn shape(&self, omega: f64, theta: DVector<f64>) -> SteadyShape {
        let displacements = self.displacements(&theta);
        SteadyShape { omega, theta, displacements }
    }

    fn check_speed(omega: f64) -> Result<()> {
        if omega.is_finite() && omega >= 0.0 {
            Ok(())
        } else {
            Err(Error::InvalidSteady {
                what: "angular speed",
                requirement: "finite and non-negative",
                value: omega,
            })
        }
    }

    fn check_guess(&self, theta: &DVector<f64>) -> Result<()> {
        if theta.len() != self.links() {
            return Err(Error::LengthMismatch { what: "theta", expected: self.links(), got: theta.len() });
        }
        if let Some((index, &value)) = theta.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(Error::NonFinite { what: "theta", index, value });
        }
        Ok(())
    }

    /// The steady shape at angular speed `omega` (rad/s) nearest `guess` (rad), by Newton's
    /// method on `F(θ, ω) = 0` (steps limited to 0.5 rad, halved until `|F|` decreases).
    ///
    /// Errors: [`Error::InvalidSteady`] for a negative or non-finite speed,
    /// [`Error::LengthMismatch`] / [`Error::NonFinite`] for a bad guess,
    /// [`Error::SteadyNotConverged`] when Newton fails (singular Jacobian, e.g. at a
    /// bifurcation, or no convergence in 30 iterations).
    pub fn solve(&self, omega: f64, guess: &DVector<f64>) -> Result<SteadyShape> {
        Self::check_speed(omega)?;
        self.check_guess(guess)?;
        let omega2 = omega * omega;
        let mut theta = guess.clone();
        for it in 1..=NEWTON_ITERATIONS {
            let f = self.residual(&theta, omega2);
            let fail = |theta: &DVector<f64>| Error::SteadyNotConverged {
                omega,
                iterations: it,
                residual: self.residual(theta, omega2).norm(),
            };
            let mut step = self.solve_hessian(&theta, omega2, &(-&f)).ok_or_else(|| fail(&theta))?;
            let size = step.amax();
            if !size.is_finite() {
                return Err(fail(&theta));
            }
            if size > 0.5 {
                step *= 0.5 / size;
            }
            // Backtracking: halve the step until the residual norm decreases.
            let f0 = f.norm();
            let mut trial = &theta + &step;
            for _ in 0..12 {
                if self.residual(&trial, omega2).norm() < f0 {
                    break;
                }
                step *= 0.5;
                trial = &theta + &step;
            }
            theta = trial;
            if size < NEWTON_STEP_TOL {
                return Ok(self.shape(omega, theta));
            }
        }
        let residual = self.residual(&theta, omega2).norm();
        if residual <= 1e-10 * self.force_scale() {
            return Ok(self.shape(omega, theta));
        }
        Err(Error::SteadyNotConverged { omega, iterations: NEWTON_ITERATIONS, residual })
    }

    /// The number of negative eigenvalues of the Hessian `H(0, ω) = K − ω² W` at the
    /// vertical: the number of critical speeds below `ω` (from `O(n)` pivots).
    pub fn unstable_directions_at_vertical(&self, omega: f64) -> usize {
        let zero = DVector::zeros(self.links());
        let scale = self.force_scale();
        // Sylvester: the signs of the L D Lᵀ pivots are those of the eigenvalues; a pivot
        // that vanishes exactly (ω on a critical speed) is nudged to count as zero.
        let mut h = self.hessian_quasiseparable(&zero, omega * omega);
        loop {
            if let Some(factor) = h.factor() {
                return factor.pivots().iter().filter(|&&v| v < 0.0).count();
            }
            h.diagonal.iter_mut().for_each(|d| *d += 1e-15 * scale);
        }
    }

    /// The first `count` speeds (rad/s, ascending) where a branch leaves the vertical:
    /// where `H(0, ω) = K − ω² W` gains its k-th negative eigenvalue, located by bisection
    /// on the eigenvalue count to relative width 1e-13. Needs `R = 0`.
    ///
    /// Errors: [`Error::InvalidSteady`] when `count` exceeds the number of links or the
    /// pivot is off the axis (`R > 0`: the vertical is then no solution).
    pub fn bifurcation_speeds(&self, count: usize) -> Result<Vec<f64>> {
        if count > self.links() {
            return Err(Error::InvalidSteady {
                what: "number of bifurcation speeds",
                requirement: "at most the number of links",
                value: count as f64,
            });
        }
        if self.radius != 0.0 {
            return Err(Error::InvalidSteady {
                what: "pivot radius for bifurcations from the vertical",
                requirement: "zero",
                value: self.radius,
            });
        }
        let mut speeds = Vec::with_capacity(count);
        let mut lo = 0.0_f64;
        for k in 1..=count {
            let mut hi = lo.max(self.scale);
            while self.unstable_directions_at_vertical(hi) < k {
                lo = hi;
                hi *= 2.0;
            }
            while hi - lo > 1e-13 * hi {
                let mid = 0.5 * (lo + hi);
                if self.unstable_directions_at_vertical(mid) >= k {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            speeds.push(hi);
            lo = hi;
        }
        Ok(speeds)
    }

    /// The branch with `k` nodes (1-based) of the free problem (`R = 0`): from the
    /// vertical at the k-th critical speed, along the null vector of `H(0, ω_k)` (signed so
    /// the free end moves to `+x`), up to `omega_max` (rad/s). The first point is the
    /// bifurcation point itself.
    ///
    /// Errors: those of [`bifurcation_speeds`](Self::bifurcation_speeds), and
    /// [`Error::InvalidSteady`] for `k = 0` or a bad `omega_max`.
    pub fn branch(&self, k: usize, omega_max: f64, options: &ContinuationOptions) -> Result<Branch> {
        if k == 0 {
            return Err(Error::InvalidSteady { what: "node count k", requirement: "at least 1", value: 0.0 });
        }
        Self::check_speed(omega_max)?;
        let omega_k = self.bifurcation_speeds(k)?[k - 1];
        let n = self.links();
        let zero = DVector::zeros(n);
        // The null vector by inverse iteration (H is singular to round-off at ω_k).
        let mut h = self.hessian_quasiseparable(&zero, omega_k * omega_k);
        let scale = self.force_scale();
        let factor = loop {
            match h.factor() {
                Some(f) => break f,
                None => h.diagonal.iter_mut().for_each(|d| *d += 1e-15 * scale),
            }
        };
        let mut v = DVector::from_fn(n, |i, _| 1.0 + 0.1 * (i as f64).sin());
        for _ in 0..3 {
            factor.solve(v.as_mut_slice());
            v /= v.norm();
        }
        let end_x: f64 = v.iter().zip(&self.lengths).map(|(a, l)| a * l).sum();
        if end_x < 0.0 {
            v = -v;
        }
        let mut tangent = DVector::zeros(n + 1);
        tangent.rows_mut(0, n).copy_from(&v.normalize());
        let start = self.shape(omega_k, zero);
        Ok(self.follow(start, tangent, omega_max, options))
    }

    /// Continue from a steady shape `start` (as returned by [`solve`](Self::solve)) in the
    /// direction of increasing (`increasing = true`) or decreasing `ω`, until `ω` passes
    /// `omega_max` or returns to 0. Works for any `R`; the forced branches fold.
    ///
    /// Errors: [`Error::InvalidSteady`] for a bad `omega_max`, [`Error::SteadyNotConverged`]
    /// when the tangent at `start` is undefined (a fold or bifurcation point).
    pub fn continue_from(
        &self,
        start: &SteadyShape,
        increasing: bool,
        omega_max: f64,
        options: &ContinuationOptions,
    ) -> Result<Branch> {
        Self::check_speed(omega_max)?;
        self.check_guess(&start.theta)?;
        let n = self.links();
        // Tangent: [H  F_p; e_pᵀ] τ = [0; 1], then normalised and signed.
        let mut rhs = DVector::zeros(n + 1);
        rhs[n] = 1.0;
        let tangent = self.solve_bordered(&start.theta, start.omega * start.omega, &rhs, &rhs).ok_or(
            Error::SteadyNotConverged {
                omega: start.omega,
                iterations: 0,
                residual: self.residual(&start.theta, start.omega * start.omega).norm(),
            },
        )?;
        let tangent = tangent.normalize() * if increasing { 1.0 } else { -1.0 };
        Ok(self.follow(start.clone(), tangent, omega_max, options))
    }

    /// Every steady shape at angular speed `omega` (rad/s) on the given branches: where a
    /// branch crosses `omega` between two of its points, Newton from the linear
    /// interpolation of their angles; shapes closer than 1e-8 rad to one already found are
    /// dropped (a branch traversed twice, or two branches of one component).
    pub fn solutions_at(&self, branches: &[Branch], omega: f64) -> Vec<SteadyShape> {
        let mut found: Vec<SteadyShape> = Vec::new();
        for branch in branches {
            for pair in branch.points.windows(2) {
                let (a, b) = (&pair[0], &pair[1]);
                if (a.omega - omega) * (b.omega - omega) > 0.0 || a.omega == b.omega {
                    continue;
                }
                let s = (omega - a.omega) / (b.omega - a.omega);
                let guess = &a.theta * (1.0 - s) + &b.theta * s;
                if let Ok(shape) = self.solve(omega, &guess)
                    && found.iter().all(|f| (&f.theta - &shape.theta).amax() > 1e-8)
                {
                    found.push(shape);
                }
            }
        }
        found
    }

    /// Pseudo-arclength continuation from `start` along `tangent` (unit, in `(θ, p)`).
    fn follow(
        &self,
        start: SteadyShape,
        mut tangent: DVector<f64>,
        omega_max: f64,
        o: &ContinuationOptions,
    ) -> Branch {
        let n = self.links();
        let s2 = self.scale * self.scale;
        let mut y = DVector::zeros(n + 1);
        y.rows_mut(0, n).copy_from(&start.theta);
        y[n] = start.omega * start.omega / s2;
        let mut points = vec![start];
        let mut h = o.initial_step;
        let scale = self.force_scale();
        loop {
            if points.len() >= o.max_points {
                return Branch { points, end: BranchEnd::MaxPoints };
            }
            if h < o.min_step {
                return Branch { points, end: BranchEnd::StepTooSmall };
            }
            let mut z = &y + &tangent * h;
            let mut converged = None;
            for it in 1..=10 {
                let theta = z.rows(0, n).into_owned();
                let omega2 = z[n] * s2;
                let mut g = DVector::zeros(n + 1);
                g.rows_mut(0, n).copy_from(&self.residual(&theta, omega2));
                g[n] = tangent.dot(&(&z - &y)) - h;
                let Some(step) = self.solve_bordered(&theta, omega2, &tangent, &(-g)) else { break };
                if !step.amax().is_finite() || step.amax() > 0.5 {
                    break;
                }
                z += &step;
                if step.amax() < NEWTON_STEP_TOL
                    || (step.amax() < 1e-9
                        && self.residual(&z.rows(0, n).into_owned(), z[n] * s2).norm() < 1e-12 * scale)
                {
                    // New tangent from the converged Jacobian, oriented along the old one.
                    let mut rhs = DVector::zeros(n + 1);
                    rhs[n] = 1.0;
                    if let Some(t) =
                        self.solve_bordered(&z.rows(0, n).into_owned(), z[n] * s2, &tangent, &rhs)
                    {
                        converged = Some((it, t.normalize()));
                    }
                    break;
                }
            }
            match converged {
                Some((it, t)) => {
                    y = z;
                    tangent = t;
                    if y[n] <= 0.0 {
                        return Branch { points, end: BranchEnd::ReachedZeroOmega };
                    }
                    let omega = (y[n] * s2).sqrt();
                    points.push(self.shape(omega, y.rows(0, n).into_owned()));
                    if omega > omega_max {
                        return Branch { points, end: BranchEnd::ReachedOmega };
                    }
                    if it <= 4 {
                        h = (h * 1.5).min(o.max_step);
                    }
                }
                None => h *= 0.5,
            }
        }
    }
}

/// `Q x = b` by the unpivoted quasiseparable LU and one step of iterative refinement
/// (`x += Q⁻¹ (b − Q x)`, `O(n)`); `None` when a pivot vanishes or the result is not finite.
fn refined<const R: usize>(q: &Quasiseparable<R>, b: &DVector<f64>) -> Option<DVector<f64>> {
    let factor = q.factor()?;
    let mut x = b.clone();
    factor.solve(x.as_mut_slice());
    let mut r = DVector::zeros(b.len());
    q.mul(x.as_slice(), r.as_mut_slice());
    let mut correction = b - r;
    factor.solve(correction.as_mut_slice());
    x += correction;
    x.iter().all(|v| v.is_finite()).then_some(x)
}

#[cfg(test)]
mod tests;
