//! Gauss–Legendre methods with the stage equations solved by fixed-point iteration: no
//! Jacobian, no linear algebra, O(dim) memory and work per iteration. The choice for
//! large systems that are not stiff at the step size used (long chains, `docs/large-chains.md`).

use nalgebra::{DefaultAllocator, Dim, OMatrix, OVector, U1, allocator::Allocator};

use super::gauss::{LastStep, complete_step, extrapolate_stages};
use super::{GaussStages, Integrator, State, Stats, System, SystemAlloc, check_step};
use crate::error::{Error, Result};

/// The Gauss–Legendre method with `S` stages (`U1`, `U2`, `U3`: orders 2, 4, 6), its stage
/// equations
/// ```text
/// Z_i = h Σ_j a_ij f(t + c_j h, x + Z_j),   i = 1..s
/// ```
/// solved by iterating them as written (`Z ← h (A ⊗ I) F(Z)`), from the previous step's
/// collocation polynomial extrapolated (or the Euler guess on a first step), until the
/// increment stops shrinking (round-off). The same method as
/// [`GaussLegendre`](super::GaussLegendre), whose Newton solve needs the `dim × dim`
/// Jacobian and an LU of the `(s·dim)²` stage matrix: O(dim³) per factorisation and
/// O(dim²) memory, prohibitive for a chain of hundreds of links. The iteration costs `s`
/// right-hand sides per sweep and converges when `h ‖A‖ L < 1` (`L` the Lipschitz
/// constant of `f`; for a chain, its fastest angular frequency), contracting by about
/// that factor per sweep; it fails (`Error::StageSolveFailed`) when the step is too long
/// for that, never returning NaN.
#[derive(Debug, Clone)]
pub struct GaussFixedPoint<D, S>
where
    D: Dim,
    S: GaussStages,
    DefaultAllocator: SystemAlloc<D> + Allocator<D, S>,
{
    max_iterations: usize,
    stats: Stats,
    dim: D,
    z: OMatrix<f64, D, S>,
    k: OMatrix<f64, D, S>,
    y: OVector<f64, D>,
    fy: OVector<f64, D>,
    increment: OVector<f64, D>,
    last: LastStep<D>,
}

impl<D, S> GaussFixedPoint<D, S>
where
    D: Dim,
    S: GaussStages,
    DefaultAllocator: SystemAlloc<D> + Allocator<D, S>,
{
    /// A solver for `system`; at most `max_iterations` sweeps per step (e.g. 50).
    pub fn new<Sys: System<Dim = D>>(system: &Sys, max_iterations: usize) -> Self {
        let dim = system.dim();
        let stages = S::name();
        let vector = || OVector::<f64, D>::zeros_generic(dim, U1);
        Self {
            max_iterations: max_iterations.max(1),
            stats: Stats::default(),
            dim,
            z: OMatrix::zeros_generic(dim, stages),
            k: OMatrix::zeros_generic(dim, stages),
            y: vector(),
            fy: vector(),
            increment: vector(),
            last: LastStep::new(dim),
        }
    }

    /// What the solver has done so far (also [`Integrator::stats`]); its sweeps are
    /// counted as `newton_iterations`.
    pub fn stats(&self) -> &Stats {
        &self.stats
    }

    /// Iterates the stage equations of the step `(t, x, h)` into `z` and `k`.
    fn solve_stages<Sys: System<Dim = D>>(
        &mut self,
        system: &Sys,
        t: f64,
        x: &OVector<f64, D>,
        h: f64,
    ) -> Result<()> {
        let tableau = S::TABLEAU;
        let s = S::dim();
        match self.last.continued_by(t, x, h) {
            Some(ratio) => extrapolate_stages::<D, S>(&mut self.z, &mut self.k, ratio),
            None => {
                system.rhs(t, x, &mut self.fy)?;
                self.stats.rhs_evaluations += 1;
                for i in 0..s {
                    let ci = tableau.c[i];
                    self.z.column_mut(i).zip_apply(&self.fy, |z, f| *z = ci * h * f);
                }
            }
        }
        let x_scale = x.amax();
        let second_order = system.second_order().filter(|&m| 2 * m <= self.dim.value());
        let mut previous_norm = f64::INFINITY;
        let mut first_norm: Option<f64> = None;
        for _ in 0..self.max_iterations {
            self.stats.newton_iterations += 1;
            for i in 0..s {
                self.y.copy_from(x);
                self.y += self.z.column(i);
                system.rhs(t + tableau.c[i] * h, &self.y, &mut self.fy)?;
                self.stats.rhs_evaluations += 1;
                self.k.set_column(i, &self.fy);
            }
            // Z_i ← h Σ_j a_ij k_j, and the size of the change.
            let mut norm: f64 = 0.0;
            for r in 0..self.dim.value() {
                for i in 0..s {
                    let new = h * (0..s).map(|j| tableau.a[i][j] * self.k[(r, j)]).sum::<f64>();
                    let change = (new - self.z[(r, i)]).abs();
                    norm = if change.is_nan() { f64::NAN } else { norm.max(change) };
                    self.z[(r, i)] = new;
                }
            }
            if let Some(m) = second_order {
                // q' = v exactly: Z_q,i = h Σ_j a_ij (v_0 + Z_v,j) from the new Z_v.
                for r in 0..m {
                    let v0 = x[m + r];
                    for i in 0..s {
                        let new =
                            h * (0..s).map(|j| tableau.a[i][j] * (v0 + self.z[(m + r, j)])).sum::<f64>();
                        norm = norm.max((new - self.z[(r, i)]).abs());
                        self.z[(r, i)] = new;
                    }
                }
            }
            if !norm.is_finite() {
                break;
            }
            // The increments need not shrink monotonically at first (the iteration matrix
            // h A ⊗ J of a second-order system is far from normal), so the iteration
            // stops when they stop shrinking only once they are small: at round-off; an
            // increment below the round-off of the largest value ends it at once.
            let scale = x_scale.max(self.z.amax()).max(f64::MIN_POSITIVE);
            if norm <= f64::EPSILON * scale {
                return Ok(());
            }
            if norm >= previous_norm && previous_norm <= 1e-10 * scale {
                return Ok(());
            }
            if norm > 1e6 * first_norm.get_or_insert(norm).max(f64::MIN_POSITIVE) {
                break; // diverging: the step is too long for the iteration
            }
            previous_norm = norm;
        }
        Err(Error::StageSolveFailed { t, h, iterations: self.max_iterations })
    }
}

impl<D, S, Sys> Integrator<Sys> for GaussFixedPoint<D, S>
where
    Sys: System<Dim = D>,
    D: Dim,
    S: GaussStages,
    DefaultAllocator: SystemAlloc<D> + Allocator<D, S>,
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
    use nalgebra::{DVector, Dyn, U2, U3, Vector1};

    use super::*;
    use crate::chain::Chain;
    use crate::integrate::{GaussLegendre, GaussOptions};
    use crate::models::planar::Planar;
    use crate::systems::first_order::FirstOrder;

    fn double_pendulum() -> FirstOrder<Planar, crate::model::Inputs<Dyn, U2>> {
        FirstOrder::new(Planar::new(Chain::new(&[1.0, 0.7], &[1.0, 0.6], 9.81).unwrap()))
    }

    #[test]
    fn same_steps_as_the_newton_solve() {
        let system = double_pendulum();
        let x0 = DVector::from_vec(vec![1.2, -0.4, 0.3, 2.0]);
        let (mut a, mut b) = (State::new(0.0, x0.clone()), State::new(0.0, x0));
        let mut fixed = GaussFixedPoint::<Dyn, U3>::new(&system, 50);
        let mut newton = GaussLegendre::<Dyn, U3>::new(&system, GaussOptions::default());
        for _ in 0..200 {
            fixed.step(&system, &mut a, 0.01).unwrap();
            newton.step(&system, &mut b, 0.01).unwrap();
        }
        assert!((a.x() - b.x()).amax() < 1e-12, "{} vs {}", a.x(), b.x());
        // The second-order form keeps sweeps per step low.
        let sweeps = fixed.stats().newton_iterations as f64 / 200.0;
        assert!(sweeps < 8.0, "{sweeps} sweeps per step");
    }

    /// `x' = λ x`, for the iteration's convergence limit.
    struct Decay(f64);

    impl System for Decay {
        type Dim = nalgebra::U1;
        fn dim(&self) -> nalgebra::U1 {
            nalgebra::U1
        }
        fn rhs(&self, _t: f64, x: &Vector1<f64>, out: &mut Vector1<f64>) -> Result<()> {
            out[0] = self.0 * x[0];
            Ok(())
        }
    }

    #[test]
    fn too_long_a_step_fails_cleanly_and_leaves_the_state() {
        // h |λ| = 50: far outside the iteration's convergence (h ‖A‖ |λ| < 1).
        let system = Decay(-5000.0);
        let mut solver = GaussFixedPoint::<nalgebra::U1, U2>::new(&system, 50);
        let mut state = State::new(0.0, Vector1::new(1.0));
        let err = solver.step(&system, &mut state, 0.01).unwrap_err();
        assert!(matches!(err, Error::StageSolveFailed { t: 0.0, h: 0.01, .. }), "{err}");
        assert_eq!(state.x()[0], 1.0);
        assert_eq!(solver.stats().failed_steps, 1);
        // A short enough step works and matches exp(λh) to the method's order.
        solver.step(&system, &mut state, 1e-5).unwrap();
        assert!((state.x()[0] - (-0.05f64).exp()).abs() < 1e-9, "{}", state.x()[0]);
    }
}
