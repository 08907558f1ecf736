//! The classical fourth-order Runge–Kutta method, the explicit baseline.

use nalgebra::{DefaultAllocator, Dim, OVector, U1};

use super::{Integrator, State, Stats, System, SystemAlloc, check_step};
use crate::error::{Error, Result};
use crate::lanes::Lane;
use crate::model::all_finite;

/// RK4's increment `h (k1 + 2 k2 + 2 k3 + k4) / 6` as every RK4 here rounds it,
/// `(h/6)·(k1 + 2 (k2 + k3) + k4)`, from `sixth` = `h/6` (lane by lane for lanes). The one
/// place it is written: the batches' increments equal the chain's alone bit for bit.
#[inline(always)]
pub(crate) fn rk4_weighted<V: Lane>(sixth: V, [k1, k2, k3, k4]: [V; 4]) -> V {
    sixth * (k1 + V::splat(2.0) * (k2 + k3) + k4)
}

/// Classical RK4 for a system of dimension `D`:
/// ```text
/// k1 = f(t, x)                  k2 = f(t + h/2, x + h/2 k1)
/// k3 = f(t + h/2, x + h/2 k2)   k4 = f(t + h, x + h k3)
/// x ← x + h (k1 + 2 k2 + 2 k3 + k4) / 6
/// ```
/// Order 4, four right-hand-side evaluations per step, no stability beyond
/// `|hλ| ≲ 2.8`, energy error drifting with time. The update uses compensated summation
/// ([`State`]) like [`GaussLegendre`](super::GaussLegendre), so the two differ only in
/// the method. Buffers are allocated in [`new`](Rk4::new); for `Const<N>` systems a step
/// allocates nothing.
#[derive(Debug, Clone)]
pub struct Rk4<D: Dim>
where
    DefaultAllocator: SystemAlloc<D>,
{
    stats: Stats,
    k1: OVector<f64, D>,
    k2: OVector<f64, D>,
    k3: OVector<f64, D>,
    k4: OVector<f64, D>,
    y: OVector<f64, D>,
}

impl<D: Dim> Rk4<D>
where
    DefaultAllocator: SystemAlloc<D>,
{
    /// A solver for `system`, its buffers sized from `system.dim()`.
    pub fn new<Sys: System<Dim = D>>(system: &Sys) -> Self {
        Self::with_dim(system.dim())
    }

    /// A solver for systems of dimension `dim`.
    pub fn with_dim(dim: D) -> Self {
        let vector = || OVector::<f64, D>::zeros_generic(dim, U1);
        Self { stats: Stats::default(), k1: vector(), k2: vector(), k3: vector(), k4: vector(), y: vector() }
    }

    /// What the solver has done so far (also [`Integrator::stats`]).
    pub fn stats(&self) -> &Stats {
        &self.stats
    }
}

impl<D: Dim> Rk4<D>
where
    DefaultAllocator: SystemAlloc<D>,
{
    /// Evaluates `k1 … k4` for the step `(t, x, h)`.
    fn stages<Sys: System<Dim = D>>(
        &mut self,
        system: &Sys,
        t: f64,
        x: &OVector<f64, D>,
        h: f64,
    ) -> Result<()> {
        let half = 0.5 * h;
        system.rhs(t, x, &mut self.k1)?;
        self.y.copy_from(x);
        self.y.axpy(half, &self.k1, 1.0);
        system.rhs(t + half, &self.y, &mut self.k2)?;
        self.y.copy_from(x);
        self.y.axpy(half, &self.k2, 1.0);
        system.rhs(t + half, &self.y, &mut self.k3)?;
        self.y.copy_from(x);
        self.y.axpy(h, &self.k3, 1.0);
        system.rhs(t + h, &self.y, &mut self.k4)?;
        self.stats.rhs_evaluations += 4;
        Ok(())
    }
}

impl<D: Dim, Sys: System<Dim = D>> Integrator<Sys> for Rk4<D>
where
    DefaultAllocator: SystemAlloc<D>,
{
    fn step(&mut self, system: &Sys, state: &mut State<D>, h: f64) -> Result<()> {
        check_step(self.k1.len(), state.x(), h)?;
        let t = state.t();
        if let Err(e) = self.stages(system, t, state.x(), h) {
            self.stats.failed_steps += 1;
            return Err(e);
        }
        // The increment, reusing y: h/6 (k1 + 2 k2 + 2 k3 + k4).
        // Slices zipped, not indexed, and the finiteness in one pass that vectorises:
        // indexed, with a bounds check per vector and the stages' pointers reloaded after
        // every store, these two loops were a sixth of a whirl of 20 links run alone (and
        // nalgebra's iterators, which follow strides, twice that).
        let sixth = h / 6.0;
        let [k1, k2, k3, k4] = [&self.k1, &self.k2, &self.k3, &self.k4].map(|k| k.as_slice());
        let stages = k1.iter().zip(k2).zip(k3.iter().zip(k4));
        for (y, ((k1, k2), (k3, k4))) in self.y.as_mut_slice().iter_mut().zip(stages) {
            *y = rk4_weighted(sixth, [*k1, *k2, *k3, *k4]);
        }
        if !all_finite(self.y.as_slice()) {
            self.stats.failed_steps += 1;
            return Err(Error::NonFiniteState { t, h });
        }
        state.advance(h, &self.y);
        self.stats.steps += 1;
        Ok(())
    }

    fn stats(&self) -> &Stats {
        &self.stats
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::{Const, Vector1};

    use super::*;

    /// `x' = λ x`, scalar; `t > 1` returns NaN.
    struct Linear(f64);

    impl System for Linear {
        type Dim = Const<1>;
        fn dim(&self) -> Const<1> {
            Const
        }
        fn rhs(&self, t: f64, x: &Vector1<f64>, out: &mut Vector1<f64>) -> Result<()> {
            out[0] = if t > 1.0 { f64::NAN } else { self.0 * x[0] };
            Ok(())
        }
    }

    #[test]
    fn one_step_is_the_taylor_polynomial_of_degree_four() {
        let (lambda, h) = (-1.3, 0.2);
        let system = Linear(lambda);
        let mut solver = Rk4::new(&system);
        let mut state = State::new(0.0, Vector1::new(1.0));
        solver.step(&system, &mut state, h).unwrap();
        let z: f64 = lambda * h;
        let taylor = 1.0 + z + z * z / 2.0 + z.powi(3) / 6.0 + z.powi(4) / 24.0;
        assert!((state.x()[0] - taylor).abs() < 4.0 * f64::EPSILON);
        assert_eq!(solver.stats().rhs_evaluations, 4);
    }

    #[test]
    fn nan_right_hand_side_is_an_error_not_a_nan_state() {
        let system = Linear(1.0);
        let mut solver = Rk4::new(&system);
        let mut state = State::new(0.9, Vector1::new(1.0));
        assert_eq!(solver.step(&system, &mut state, 0.2), Err(Error::NonFiniteState { t: 0.9, h: 0.2 }));
        assert_eq!(state.x()[0], 1.0);
    }
}
