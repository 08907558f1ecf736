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
mod tests {
    use nalgebra::{Const, DVector, Dyn, Matrix1, U2, U3, Vector1, Vector2};

    use super::*;

    /// `x' = λ x`, scalar.
    struct Linear(f64);

    impl System for Linear {
        type Dim = Const<1>;
        fn dim(&self) -> Const<1> {
            Const
        }
        fn rhs(&self, _t: f64, x: &Vector1<f64>, out: &mut Vector1<f64>) -> Result<()> {
            *out = x * self.0;
            Ok(())
        }
        fn jacobian(&self, _t: f64, _x: &Vector1<f64>, out: &mut Matrix1<f64>) -> Result<()> {
            out[0] = self.0;
            Ok(())
        }
    }

    /// The harmonic oscillator `q' = p`, `p' = −ω² q`, dynamic size so the `Dyn` path runs.
    struct Oscillator(f64);

    impl System for Oscillator {
        type Dim = Dyn;
        fn dim(&self) -> Dyn {
            Dyn(2)
        }
        fn rhs(&self, _t: f64, x: &DVector<f64>, out: &mut DVector<f64>) -> Result<()> {
            out[0] = x[1];
            out[1] = -self.0 * self.0 * x[0];
            Ok(())
        }
    }

    /// The (s, s) Padé approximant of `e^z`, the stability function of `s`-stage Gauss.
    fn pade(s: usize, z: f64) -> f64 {
        let (num, den) = match s {
            1 => (1.0 + z / 2.0, 1.0 - z / 2.0),
            2 => (1.0 + z / 2.0 + z * z / 12.0, 1.0 - z / 2.0 + z * z / 12.0),
            3 => (
                1.0 + z / 2.0 + z * z / 10.0 + z * z * z / 120.0,
                1.0 - z / 2.0 + z * z / 10.0 - z * z * z / 120.0,
            ),
            _ => unreachable!(),
        };
        num / den
    }

    fn linear_step<S: GaussStages>(lambda: f64, h: f64) -> f64
    where
        Const<1>: DimMul<S>,
        DefaultAllocator: GaussAlloc<Const<1>, S>,
    {
        let system = Linear(lambda);
        let mut solver = GaussLegendre::<_, S>::new(&system, GaussOptions::default());
        let mut state = State::new(0.0, Vector1::new(1.0));
        solver.step(&system, &mut state, h).unwrap();
        state.x()[0]
    }

    #[test]
    fn linear_problem_gives_the_pade_approximant() {
        for (lambda, h) in [(-1.3, 0.7), (2.0, 0.1), (-50.0, 1.0)] {
            let z = lambda * h;
            let got =
                [linear_step::<U1>(lambda, h), linear_step::<U2>(lambda, h), linear_step::<U3>(lambda, h)];
            for (s, got) in (1..=3).zip(got) {
                let exact = pade(s, z);
                // The update h Σ b_i k_i multiplies the round-off of the stages by |z|.
                let tolerance = (4.0 + z.abs()) * f64::EPSILON * exact.abs();
                assert!((got - exact).abs() <= tolerance, "s = {s}, z = {z}: {got} vs {exact}");
            }
        }
    }

    fn oscillator_invariant_drift<S: GaussStages>(steps: usize) -> (f64, Stats)
    where
        Dyn: DimMul<S>,
        DefaultAllocator: GaussAlloc<Dyn, S>,
    {
        let system = Oscillator(3.0);
        let invariant = |x: &DVector<f64>| 9.0 * x[0] * x[0] + x[1] * x[1];
        let x0 = DVector::from_vec(vec![0.4, 1.7]);
        let mut solver = GaussLegendre::<_, S>::new(&system, GaussOptions::default());
        let mut state = State::new(0.0, x0.clone());
        let mut worst: f64 = 0.0;
        for _ in 0..steps {
            solver.step(&system, &mut state, 0.05).unwrap();
            worst = worst.max((invariant(state.x()) / invariant(&x0) - 1.0).abs());
        }
        (worst, *solver.stats())
    }

    /// Gauss methods conserve quadratic invariants exactly; with the stages solved to
    /// round-off and the update compensated, `9 q² + p²` stays within a few ulps over
    /// 2000 steps (about 48 periods).
    #[test]
    fn harmonic_oscillator_invariant_is_conserved_to_round_off() {
        for (s, (drift, stats)) in [
            (1, oscillator_invariant_drift::<U1>(2000)),
            (2, oscillator_invariant_drift::<U2>(2000)),
            (3, oscillator_invariant_drift::<U3>(2000)),
        ] {
            assert!(drift < 2e-14, "s = {s}: relative drift {drift:e}");
            // A linear problem: one Jacobian for the whole run, one factorisation.
            assert_eq!(
                (stats.jacobian_evaluations, stats.factorizations, stats.full_newton_steps),
                (1, 1, 0)
            );
            assert_eq!(stats.steps, 2000);
        }
    }

    /// `x' = NaN` after `t = 0`: every stage value is NaN, so the step must fail, not
    /// return NaN.
    struct NanAfterZero;

    impl System for NanAfterZero {
        type Dim = Const<2>;
        fn dim(&self) -> Const<2> {
            Const
        }
        fn rhs(&self, t: f64, x: &Vector2<f64>, out: &mut Vector2<f64>) -> Result<()> {
            *out = if t > 0.0 { Vector2::repeat(f64::NAN) } else { -x };
            Ok(())
        }
    }

    #[test]
    fn nan_right_hand_side_fails_the_stage_solve() {
        let system = NanAfterZero;
        let mut solver = GaussLegendre::<_, U2>::new(&system, GaussOptions::default());
        let x0 = Vector2::new(1.0, 2.0);
        let mut state = State::new(0.0, x0);
        let err = solver.step(&system, &mut state, 0.1).unwrap_err();
        assert!(matches!(err, Error::StageSolveFailed { t: 0.0, h: 0.1, .. }), "{err}");
        assert_eq!(state.x(), &x0, "a failed step leaves the state alone");
        assert_eq!(solver.stats().failed_steps, 1);
    }

    /// `x' = x²` from `x = 1` blows up at `t = 1`. The implicit midpoint equation for
    /// `h = 2` is `Z = (1 + Z/2)² · 2`, i.e. `Z² + 2 = 0`: no real solution, Newton cannot
    /// converge.
    struct Quadratic;

    impl System for Quadratic {
        type Dim = Const<1>;
        fn dim(&self) -> Const<1> {
            Const
        }
        fn rhs(&self, _t: f64, x: &Vector1<f64>, out: &mut Vector1<f64>) -> Result<()> {
            out[0] = x[0] * x[0];
            Ok(())
        }
    }

    #[test]
    fn step_without_a_solution_reports_time_step_and_iterations() {
        let system = Quadratic;
        let mut solver = GaussLegendre::<_, U1>::new(&system, GaussOptions::default());
        let mut state = State::new(0.25, Vector1::new(1.0));
        match solver.step(&system, &mut state, 2.0) {
            Err(Error::StageSolveFailed { t, h, iterations }) => {
                assert_eq!((t, h), (0.25, 2.0));
                assert!(iterations > 0);
            }
            other => panic!("expected StageSolveFailed, got {other:?}"),
        }
        assert_eq!(solver.stats().full_newton_steps, 1);
        // The same problem with a step it can take still works afterwards.
        solver.step(&system, &mut state, 0.01).unwrap();
        assert!(state.x()[0].is_finite());
    }

    #[test]
    fn invalid_steps_and_sizes_are_refused() {
        let system = Oscillator(1.0);
        let mut solver = GaussLegendre::<_, U2>::new(&system, GaussOptions::default());
        let mut state = State::new(0.0, DVector::from_vec(vec![1.0, 0.0]));
        for h in [0.0, f64::NAN, f64::INFINITY] {
            assert!(matches!(solver.step(&system, &mut state, h), Err(Error::InvalidStepSize { .. })));
        }
        let mut wrong = State::new(0.0, DVector::from_vec(vec![1.0, 0.0, 0.0]));
        assert_eq!(
            solver.step(&system, &mut wrong, 0.1),
            Err(Error::LengthMismatch { what: "x", expected: 2, got: 3 })
        );
    }

    /// Extrapolating the previous collocation polynomial makes the first iterate nearly
    /// exact, so steady stepping needs few iterations.
    #[test]
    fn straight_chain_converges_in_few_iterations() {
        // Regression: from an exactly straight chain (equal angles) some increments keep
        // shrinking geometrically far below round-off; they must count as converged, not
        // run out of iterations (this failed every step after the first for n ≥ 6).
        use crate::chain::Chain;
        use crate::models::planar::Planar;
        use crate::systems::first_order::FirstOrder;
        let n = 8;
        let system = FirstOrder::new(Planar::new(Chain::<Dyn>::uniform(n, 1.0, 0.5, 9.81).unwrap()));
        let mut state = State::new(0.0, system.state(&DVector::from_element(n, 1.0), &DVector::zeros(n)));
        let mut solver = GaussLegendre::<Dyn, U2>::new(&system, GaussOptions::default());
        solver.integrate(&system, &mut state, 0.1, 20).unwrap();
        let per_step = solver.stats().newton_iterations as f64 / 20.0;
        assert!(per_step <= 8.0, "{per_step} iterations per step, {:?}", solver.stats());
        assert_eq!(solver.stats().full_newton_steps, 0);
    }

    #[test]
    fn extrapolated_guess_saves_iterations() {
        // A nonlinear system: on a linear one with its exact Jacobian Newton converges in
        // one iteration from any guess.
        use crate::chain::Chain;
        use crate::models::planar::Planar;
        use crate::systems::first_order::FirstOrder;
        let run = |extrapolate: bool| {
            let system =
                FirstOrder::new(Planar::new(Chain::<Dyn>::new(&[1.0, 0.7], &[1.0, 0.6], 9.81).unwrap()));
            let options = GaussOptions { extrapolate, ..GaussOptions::default() };
            let mut solver = GaussLegendre::<_, U3>::new(&system, options);
            let mut state = State::new(0.0, DVector::from_vec(vec![1.2, -0.4, 0.3, 2.0]));
            solver.integrate(&system, &mut state, 1.0, 100).unwrap();
            (solver.stats().newton_iterations, state.into_x())
        };
        let (with, x_with) = run(true);
        let (without, x_without) = run(false);
        assert!(with < without, "{with} vs {without} iterations");
        assert!((x_with - x_without).amax() < 1e-13);
    }
}
