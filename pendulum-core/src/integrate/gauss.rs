//! Gauss–Legendre implicit Runge–Kutta methods (s = 1, 2, 3 stages, order 2s): stage
//! equations solved by simplified Newton, falling back to full Newton, to round-off.

use nalgebra::{DefaultAllocator, Dim, DimMul, DimProd, OMatrix, OVector, U1, allocator::Allocator};

use super::{GaussStages, Integrator, State, Stats, System, SystemAlloc, check_step, lu};
use crate::error::{Error, Result};

/// The allocator bounds of a [`GaussLegendre`] method with `S` stages on a system of
/// dimension `D`, in one name: the system's own, the `D × S` stage matrices and the
/// `(S·D) × (S·D)` Newton matrix.
pub trait GaussAlloc<D: DimMul<S>, S: Dim>:
    SystemAlloc<D> + Allocator<D, S> + Allocator<DimProd<D, S>> + Allocator<DimProd<D, S>, DimProd<D, S>>
{
}

impl<D: DimMul<S>, S: Dim, A> GaussAlloc<D, S> for A where
    A: SystemAlloc<D> + Allocator<D, S> + Allocator<DimProd<D, S>> + Allocator<DimProd<D, S>, DimProd<D, S>>
{
}

/// Tuning of the stage solve of [`GaussLegendre`]. The defaults suit non-stiff problems
/// such as conservative pendulums.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GaussOptions {
    /// Most Newton iterations of one attempt (simplified Newton, then, if it fails, full
    /// Newton) before it counts as failed. Default `30`: a healthy simplified iteration
    /// contracts by 10⁻² or better per iteration and reaches round-off in under 10, full
    /// Newton converges quadratically.
    pub max_iterations: usize,
    /// The iteration stops when the increment `‖ΔZ_k‖∞` stops decreasing
    /// (`‖ΔZ_k‖ ≥ ‖ΔZ_{k−1}‖`, the round-off level reached) or is exactly zero; a stall
    /// counts as convergence only if `‖ΔZ_{k−1}‖∞ ≤ stall_threshold · max(‖x‖∞, ‖Z‖∞)`,
    /// and as failure above it. Default `1e-10`, far above round-off (`~1e-16`) and far
    /// below any useful accuracy.
    pub stall_threshold: f64,
    /// The Jacobian (and the LU factors of the Newton matrix while `h` is unchanged) are
    /// reused from step to step while the simplified Newton iteration contracts by at most
    /// this factor per iteration (`‖ΔZ₁‖/‖ΔZ₀‖`); above it, the next step evaluates a
    /// fresh Jacobian. `0` evaluates one every step. Default `0.01`: the stale Jacobian
    /// then costs at most a few extra iterations, cheaper than the `2·dim` rhs
    /// evaluations of a finite-difference Jacobian.
    pub jacobian_refresh_rate: f64,
    /// Start the iteration from the previous step's collocation polynomial, extrapolated
    /// (when the step continues the previous one and `0 < h/h_prev ≤ 2`); otherwise, and
    /// when `false`, from `Z_i = c_i h f(t, x)`. Default `true`.
    pub extrapolate: bool,
}

impl Default for GaussOptions {
    fn default() -> Self {
        Self { max_iterations: 30, stall_threshold: 1e-10, jacobian_refresh_rate: 0.01, extrapolate: true }
    }
}

/// The Gauss–Legendre Runge–Kutta method with `S` stages (`U1`, `U2`, `U3`: orders 2, 4,
/// 6) for a system of dimension `D`.
///
/// One step from `(t, x)` solves the stage equations for the increments `Z_i`,
/// ```text
/// Z_i = h Σ_j a_ij f(t + c_j h, x + Z_j),   i = 1..s,
/// ```
/// (the document's eqs 53–54 with `Z_i = h Σ_j a_ij k_j`, `k_i = f(x + Z_i)`), then
/// updates `x ← x + h Σ_i b_i k_i` (eq 55) with compensated summation ([`State`]). The
/// methods are A-stable, symmetric and symplectic, and conserve quadratic invariants
/// exactly, so their energy error does not drift once the stage equations are solved to
/// round-off. Tableaux: [`GAUSS_1`](super::GAUSS_1), [`GAUSS_2`](super::GAUSS_2),
/// [`GAUSS_3`](super::GAUSS_3).
///
/// **Stage solve.** Newton's method on `G(Z) = Z − h (A ⊗ I) F(Z) = 0` (`s·dim`
/// unknowns), in up to three attempts:
/// 1. simplified Newton: the matrix `I − h A ⊗ J` with one Jacobian `J`, kept from an
///    earlier step while the iteration contracted well ([`GaussOptions`]), factored once
///    per step size;
/// 2. if that fails with a kept Jacobian: the same with `J` evaluated at `(t, x)`;
/// 3. if that fails: full Newton, with `∂G_i/∂Z_j = δ_ij I − h a_ij J(t + c_j h, x + Z_j)`
///    re-evaluated and refactored every iteration.
///
/// Each attempt iterates until the increment stops shrinking (round-off), not a fixed
/// count; see [`GaussOptions::stall_threshold`]. When all attempts fail the step returns
/// [`Error::StageSolveFailed`] with the time, the step size and the iterations spent.
/// A non-finite stage value or right-hand side counts as a failed attempt, so a step
/// never returns NaN.
///
/// All buffers are allocated in [`new`](GaussLegendre::new); for `Const<N>` systems they
/// are nalgebra stack arrays and a step allocates nothing (the Jacobian default
/// [`central_difference_jacobian`](super::central_difference_jacobian) included).
#[derive(Debug, Clone)]
pub struct GaussLegendre<D, S>
where
    D: DimMul<S>,
    S: GaussStages,
    DefaultAllocator: GaussAlloc<D, S>,
{
    options: GaussOptions,
    stats: Stats,
    dim: D,
    /// Stage increments `Z_i`, one column per stage.
    z: OMatrix<f64, D, S>,
    /// Stage derivatives `k_i = f(t + c_i h, x + Z_i)`, one column per stage.
    k: OMatrix<f64, D, S>,
    jacobian: OMatrix<f64, D, D>,
    /// The Newton matrix, or its LU factors.
    newton: OMatrix<f64, DimProd<D, S>, DimProd<D, S>>,
    pivots: OVector<usize, DimProd<D, S>>,
    /// The residual `−G(Z)`, then the Newton increment `ΔZ` (stage-major: entry
    /// `i·dim + r` is component `r` of stage `i`).
    delta: OVector<f64, DimProd<D, S>>,
    /// A stage value `x + Z_i`.
    y: OVector<f64, D>,
    /// `f` at a stage value.
    fy: OVector<f64, D>,
    /// `f(t, x)` at the start of the step.
    f0: OVector<f64, D>,
    increment: OVector<f64, D>,
    /// The last successful step, to recognise a continuation.
    last: LastStep<D>,
    /// `jacobian` holds the Jacobian at some earlier state of this run.
    jacobian_valid: bool,
    /// The last simplified iteration contracted too slowly: evaluate a fresh Jacobian.
    refresh_jacobian: bool,
    /// `newton` holds the LU factors of `I − h A ⊗ J` for this `h` and the current `J`.
    factored_h: Option<f64>,
}

impl<D, S> GaussLegendre<D, S>
where
    D: DimMul<S>,
    S: GaussStages,
    DefaultAllocator: GaussAlloc<D, S>,
{
    /// A solver for `system`, its buffers sized from `system.dim()`.
    pub fn new<Sys: System<Dim = D>>(system: &Sys, options: GaussOptions) -> Self {
        Self::with_dim(system.dim(), options)
    }

    /// A solver for systems of dimension `dim`.
    pub fn with_dim(dim: D, options: GaussOptions) -> Self {
        let stages = S::name();
        let total = dim.mul(stages);
        let vector = || OVector::<f64, D>::zeros_generic(dim, U1);
        Self {
            options,
            stats: Stats::default(),
            dim,
            z: OMatrix::zeros_generic(dim, stages),
            k: OMatrix::zeros_generic(dim, stages),
            jacobian: OMatrix::zeros_generic(dim, dim),
            newton: OMatrix::zeros_generic(total, total),
            pivots: OVector::from_element_generic(total, U1, 0),
            delta: OVector::zeros_generic(total, U1),
            y: vector(),
            fy: vector(),
            f0: vector(),
            increment: vector(),
            last: LastStep::new(dim),
            jacobian_valid: false,
            refresh_jacobian: true,
            factored_h: None,
        }
    }

    /// The options in use.
    pub fn options(&self) -> &GaussOptions {
        &self.options
    }

    /// What the solver has done so far (also [`Integrator::stats`]).
    pub fn stats(&self) -> &Stats {
        &self.stats
    }

    /// Forgets the kept Jacobian and the previous step (call after switching to another
    /// system; results do not depend on it, only the cost of the next step does).
    pub fn reset(&mut self) {
        self.jacobian_valid = false;
        self.factored_h = None;
        self.last.forget();
    }

    /// Solves the stage equations of the step `(t, x, h)` into `z` and `k`.
    fn solve_stages<Sys: System<Dim = D>>(
        &mut self,
        system: &Sys,
        t: f64,
        x: &OVector<f64, D>,
        h: f64,
    ) -> Result<()> {
        let continued = self.last.continued_by(t, x, h);
        let mut iterations = 0;
        let mut have_f0 = false;
        match continued {
            Some(ratio) if self.options.extrapolate => self.extrapolate(ratio),
            _ => self.simple_guess(system, t, x, h, &mut have_f0)?,
        }

        let mut fresh = false;
        if !self.jacobian_valid || self.refresh_jacobian {
            self.evaluate_jacobian(system, t, x)?;
            fresh = true;
        }
        let mut rate = self.newton(system, t, x, h, false, &mut iterations)?;
        if rate.is_none() && !fresh {
            self.evaluate_jacobian(system, t, x)?;
            self.simple_guess(system, t, x, h, &mut have_f0)?;
            rate = self.newton(system, t, x, h, false, &mut iterations)?;
        }
        if let Some(rate) = rate {
            self.refresh_jacobian = rate > self.options.jacobian_refresh_rate;
            return Ok(());
        }

        self.stats.full_newton_steps += 1;
        self.jacobian_valid = false;
        self.factored_h = None;
        self.simple_guess(system, t, x, h, &mut have_f0)?;
        match self.newton(system, t, x, h, true, &mut iterations)? {
            Some(_) => Ok(()),
            None => Err(Error::StageSolveFailed { t, h, iterations }),
        }
    }

    /// `Z_i = c_i h f(t, x)`: the stage increments of the Euler step, error `O(h²)`.
    fn simple_guess<Sys: System<Dim = D>>(
        &mut self,
        system: &Sys,
        t: f64,
        x: &OVector<f64, D>,
        h: f64,
        have_f0: &mut bool,
    ) -> Result<()> {
        if !*have_f0 {
            system.rhs(t, x, &mut self.f0)?;
            self.stats.rhs_evaluations += 1;
            *have_f0 = true;
        }
        let c = S::TABLEAU.c;
        for (i, ci) in c.iter().enumerate().take(S::dim()) {
            self.z.column_mut(i).zip_apply(&self.f0, |z, f| *z = ci * h * f);
        }
        Ok(())
    }

    /// Continues the previous step's collocation polynomial ([`extrapolate_stages`]).
    fn extrapolate(&mut self, ratio: f64) {
        extrapolate_stages::<D, S>(&mut self.z, &mut self.k, ratio);
    }

    fn evaluate_jacobian<Sys: System<Dim = D>>(
        &mut self,
        system: &Sys,
        t: f64,
        x: &OVector<f64, D>,
    ) -> Result<()> {
        self.jacobian_valid = false;
        self.factored_h = None;
        system.jacobian(t, x, &mut self.jacobian)?;
        self.stats.jacobian_evaluations += 1;
        self.jacobian_valid = true;
        self.refresh_jacobian = false;
        Ok(())
    }

    /// Writes the block column `j` of the Newton matrix, `δ_ij I − h a_ij J` for all `i`,
    /// from the current `jacobian`.
    fn fill_block_column(&mut self, j: usize, h: f64) {
        let a = S::TABLEAU.a;
        let n = self.dim.value();
        for (i, row) in a.iter().enumerate().take(S::dim()) {
            let factor = -h * row[j];
            for col in 0..n {
                for row in 0..n {
                    let identity = if i == j && row == col { 1.0 } else { 0.0 };
                    self.newton[(i * n + row, j * n + col)] = identity + factor * self.jacobian[(row, col)];
                }
            }
        }
    }

    /// Makes `newton` hold the LU factors of `I − h A ⊗ J`; `false` if it is singular.
    fn ensure_factored(&mut self, h: f64) -> bool {
        if self.factored_h == Some(h) {
            return true;
        }
        self.factored_h = None;
        for j in 0..S::dim() {
            self.fill_block_column(j, h);
        }
        self.stats.factorizations += 1;
        let ok = lu::factor(&mut self.newton, &mut self.pivots);
        if ok {
            self.factored_h = Some(h);
        }
        ok
    }

    /// One Newton attempt from the current `z`: simplified (`full = false`, the matrix of
    /// [`ensure_factored`](Self::ensure_factored)) or full. Returns the contraction rate
    /// `‖ΔZ₁‖/‖ΔZ₀‖` (0 when not measurable above round-off) on convergence, `None` on
    /// divergence, a stall above the threshold, a singular matrix, non-finite values or
    /// too many iterations. System errors pass through.
    fn newton<Sys: System<Dim = D>>(
        &mut self,
        system: &Sys,
        t: f64,
        x: &OVector<f64, D>,
        h: f64,
        full: bool,
        iterations: &mut usize,
    ) -> Result<Option<f64>> {
        let tableau = S::TABLEAU;
        let (s, n) = (S::dim(), self.dim.value());
        if !full && !self.ensure_factored(h) {
            return Ok(None);
        }
        let x_scale = x.amax();
        let mut previous_norm = f64::INFINITY;
        let mut rate = 0.0;
        for iteration in 0..self.options.max_iterations {
            *iterations += 1;
            self.stats.newton_iterations += 1;
            for i in 0..s {
                self.y.copy_from(x);
                self.y += self.z.column(i);
                if !self.y.iter().all(|v| v.is_finite()) {
                    return Ok(None);
                }
                let stage_time = t + tableau.c[i] * h;
                system.rhs(stage_time, &self.y, &mut self.fy)?;
                self.stats.rhs_evaluations += 1;
                if !self.fy.iter().all(|v| v.is_finite()) {
                    return Ok(None);
                }
                self.k.set_column(i, &self.fy);
                if full {
                    system.jacobian(stage_time, &self.y, &mut self.jacobian)?;
                    self.stats.jacobian_evaluations += 1;
                    self.fill_block_column(i, h);
                }
            }
            if full {
                self.stats.factorizations += 1;
                if !lu::factor(&mut self.newton, &mut self.pivots) {
                    return Ok(None);
                }
            }
            // −G_i = h Σ_j a_ij k_j − Z_i
            for i in 0..s {
                for r in 0..n {
                    let sum: f64 = (0..s).map(|j| tableau.a[i][j] * self.k[(r, j)]).sum();
                    self.delta[i * n + r] = h * sum - self.z[(r, i)];
                }
            }
            lu::solve(&self.newton, &self.pivots, &mut self.delta);
            let norm = self.delta.amax();
            if !norm.is_finite() {
                return Ok(None);
            }
            for i in 0..s {
                for r in 0..n {
                    self.z[(r, i)] += self.delta[i * n + r];
                }
            }
            let scale = x_scale.max(self.z.amax()).max(f64::MIN_POSITIVE);
            // An increment below the round-off of the largest value can change nothing
            // that matters; it may still shrink geometrically for ever (entries far
            // smaller than the rest, e.g. the differences of a straight chain's equal
            // angles), so it counts as converged rather than waiting for a stall.
            if norm <= f64::EPSILON * scale {
                return Ok(Some(rate));
            }
            if norm >= previous_norm {
                let converged = previous_norm <= self.options.stall_threshold * scale;
                return Ok(converged.then_some(rate));
            }
            if iteration == 1 && norm > 100.0 * f64::EPSILON * scale {
                rate = norm / previous_norm;
            }
            previous_norm = norm;
        }
        Ok(None)
    }
}

/// The end of the last successful step of a Gauss solver, to recognise a step that
/// continues it (and start its stage solve from the extrapolated collocation polynomial).
#[derive(Debug, Clone)]
pub(super) struct LastStep<D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    /// The state after the step.
    x_end: OVector<f64, D>,
    /// Its end time and size, `None` before the first step or after [`Self::forget`].
    end: Option<(f64, f64)>,
}

impl<D: Dim> LastStep<D>
where
    DefaultAllocator: Allocator<D>,
{
    /// No step yet, for states of dimension `dim`.
    pub(super) fn new(dim: D) -> Self {
        Self { x_end: OVector::zeros_generic(dim, U1), end: None }
    }

    /// `h / h_prev` when the step `(t, x, h)` starts where the last one ended and
    /// `0 < h / h_prev ≤ 2` (extrapolation further out guesses worse than Euler). Forgets
    /// the last step either way: a failed step must not be continued.
    pub(super) fn continued_by(&mut self, t: f64, x: &OVector<f64, D>, h: f64) -> Option<f64> {
        let (t_end, h_prev) = self.end.take()?;
        let ratio = h / h_prev;
        (t_end == t && *x == self.x_end && ratio > 0.0 && ratio <= 2.0).then_some(ratio)
    }

    /// Forgets the last step.
    pub(super) fn forget(&mut self) {
        self.end = None;
    }

    /// Records a successful step of size `h` that ended at `state`.
    fn record(&mut self, state: &State<D>, h: f64) {
        self.x_end.copy_from(state.x());
        self.end = Some((state.t(), h));
    }
}

/// Completes a Gauss step from its stage derivatives `k` (one column per stage):
/// `x_{n+1} − x_n = h Σ_i b_i k_i` (eq 55), added to `state` with compensated summation,
/// and records it in `last`. A non-finite increment leaves the state unchanged and is
/// [`Error::NonFiniteState`]; the step is counted either way.
pub(super) fn complete_step<D: Dim, S: GaussStages>(
    k: &OMatrix<f64, D, S>,
    h: f64,
    increment: &mut OVector<f64, D>,
    state: &mut State<D>,
    stats: &mut Stats,
    last: &mut LastStep<D>,
) -> Result<()>
where
    DefaultAllocator: Allocator<D> + Allocator<D, S>,
{
    let b = S::TABLEAU.b;
    for r in 0..increment.len() {
        increment[r] = h * (0..S::dim()).map(|i| b[i] * k[(r, i)]).sum::<f64>();
    }
    if !increment.iter().all(|v| v.is_finite()) {
        stats.failed_steps += 1;
        return Err(Error::NonFiniteState { t: state.t(), h });
    }
    state.advance(h, increment);
    stats.steps += 1;
    last.record(state, h);
    Ok(())
}

/// Continues a Gauss step's collocation polynomial `u(τ)` (degree `s`, `u(0) = 0`,
/// `u(c_i) = Z_i^prev`, `τ` in units of the previous step) to the nodes of the next step,
/// `h = ratio · h_prev`: `Z_j = u(1 + c_j ratio) − u(1)`, error `O(h^{s+1})`. `z` holds the
/// previous increments on entry and the guess on return; `scratch` is overwritten.
pub(super) fn extrapolate_stages<D: Dim, S: GaussStages>(
    z: &mut OMatrix<f64, D, S>,
    scratch: &mut OMatrix<f64, D, S>,
    ratio: f64,
) where
    DefaultAllocator: Allocator<D, S>,
{
    let c = S::TABLEAU.c;
    let s = S::dim();
    // Lagrange basis on the nodes (0, c_1, …, c_s); the node 0 carries the value 0.
    let basis = |i: usize, tau: f64| {
        let mut v = tau / c[i];
        for m in (0..s).filter(|&m| m != i) {
            v *= (tau - c[m]) / (c[i] - c[m]);
        }
        v
    };
    // weights[j][i] = ℓ_i(1 + c_j h/h_prev) − ℓ_i(1).
    let mut weights = [[0.0; 3]; 3];
    for (row, cj) in weights.iter_mut().zip(c).take(s) {
        for (i, w) in row.iter_mut().enumerate().take(s) {
            *w = basis(i, 1.0 + cj * ratio) - basis(i, 1.0);
        }
    }
    scratch.copy_from(z);
    for (j, w) in weights.iter().enumerate().take(s) {
        for r in 0..z.nrows() {
            z[(r, j)] = (0..s).map(|i| scratch[(r, i)] * w[i]).sum();
        }
    }
}

impl<D, S, Sys> Integrator<Sys> for GaussLegendre<D, S>
where
    Sys: System<Dim = D>,
    D: DimMul<S>,
    S: GaussStages,
    DefaultAllocator: GaussAlloc<D, S>,
{
    fn step(&mut self, system: &Sys, state: &mut State<D>, h: f64) -> Result<()> {
        check_step(self.dim.value(), state.x(), h)?;
        let t = state.t();
        if let Err(e) = self.solve_stages(system, t, state.x(), h) {
            self.stats.failed_steps += 1;
            return Err(e);
        }
        complete_step::<D, S>(&self.k, h, &mut self.increment, state, &mut self.stats, &mut self.last)
    }

    fn stats(&self) -> &Stats {
        &self.stats
    }
}

#[cfg(test)]
mod tests;
