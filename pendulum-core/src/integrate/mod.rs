//! Time integrators for first-order systems `x' = f(t, x)`: Gauss–Legendre (implicit,
//! s = 1, 2, 3 stages, orders 2, 4, 6), classical RK4 (explicit) and Dormand–Prince 5(4)
//! (explicit, error-controlled).
//!
//! The pieces are separate values:
//! - the problem, a [`System`] (for a chain model, [`FirstOrder`](crate::systems::FirstOrder));
//! - the solver, a [`GaussLegendre`] or [`Rk4`], which owns every buffer a step needs,
//!   allocated once at construction from the system's dimension, and keeps [`Stats`];
//! - the [`State`]: time, state vector and the round-off compensation of both.
//!
//! Everything is generic over the dimension `D: Dim`: with `Const<N>` (fixed-size models)
//! all buffers are nalgebra stack arrays and a step performs no heap allocation; with
//! `Dyn` the buffers are allocated at construction only (a dynamic-size system's own
//! `rhs` may allocate).
//!
//! ```
//! use nalgebra::{DVector, Dyn, U2};
//! use pendulum_core::integrate::{GaussLegendre, GaussOptions, Integrator, State, System};
//! use pendulum_core::{Chain, FirstOrder, Planar};
//!
//! let chain = Chain::<Dyn>::uniform(2, 1.0, 1.0, 9.81).unwrap();
//! let system = FirstOrder::new(Planar::new(chain));
//! let mut solver = GaussLegendre::<_, U2>::new(&system, GaussOptions::default());
//! let x0 = system.state(&DVector::from_vec(vec![1.0, 0.5]), &DVector::zeros(2));
//! let mut state = State::new(0.0, x0.clone());
//! solver.integrate(&system, &mut state, 1.0, 100).unwrap();
//! let drift = system.energy(state.x()) - system.energy(&x0);
//! assert!(drift.abs() < 1e-6);
//! ```

mod dormand_prince;
mod fixed_point;
mod gauss;
mod lu;
mod projected;
mod rk4;
mod system;
mod tableau;

use nalgebra::{DefaultAllocator, Dim, OVector, U1, allocator::Allocator};

pub use dormand_prince::{DormandPrince, OntoConstraints, Projection, Unprojected};
pub use fixed_point::GaussFixedPoint;
pub use gauss::{GaussAlloc, GaussLegendre, GaussOptions};
pub use projected::{Constrained, Projected};
pub use rk4::Rk4;
pub(crate) use rk4::rk4_weighted;
pub use system::{System, SystemAlloc, central_difference_jacobian};
pub use tableau::{GAUSS_1, GAUSS_2, GAUSS_3, GaussStages, Tableau};

use crate::error::{Error, Result};

/// The time `t` (s) and state `x` of an integration, with the compensation terms of
/// Kahan's summation for both.
///
/// Each step adds a small increment to a large value; the compensation carries the bits
/// lost to rounding into the next step, so the accumulated round-off grows like `√n`
/// ulps (random walk) rather than `n` ulps. [`t`](State::t) and [`x`](State::x) are the
/// rounded values; [`set`](State::set) replaces them and clears the compensation.
#[derive(Debug, Clone)]
pub struct State<D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    t: f64,
    x: OVector<f64, D>,
    t_carry: f64,
    x_carry: OVector<f64, D>,
    /// Whether every entry of `x_carry` is known to be `+0.0` (cleared and not written
    /// since), so that the batch need not read it to know.
    cleared: bool,
}

/// Equal time, state and compensations (whether the compensation is known to be clear is
/// not compared).
impl<D: Dim> PartialEq for State<D>
where
    DefaultAllocator: Allocator<D>,
{
    fn eq(&self, other: &Self) -> bool {
        self.parts() == other.parts()
    }
}

impl<D: Dim> State<D>
where
    DefaultAllocator: Allocator<D>,
{
    /// The state `x` at time `t` (s), with no accumulated round-off.
    pub fn new(t: f64, x: OVector<f64, D>) -> Self {
        let x_carry = OVector::zeros_generic(x.shape_generic().0, U1);
        Self { t, x, t_carry: 0.0, x_carry, cleared: true }
    }

    /// Time, s.
    pub fn t(&self) -> f64 {
        self.t
    }

    /// State vector.
    pub fn x(&self) -> &OVector<f64, D> {
        &self.x
    }

    /// The rounding error carried into the next step's update of `x` (the exact sum so
    /// far is about `x + compensation`).
    pub fn compensation(&self) -> &OVector<f64, D> {
        &self.x_carry
    }

    /// Replaces time and state and clears the compensation.
    pub fn set(&mut self, t: f64, x: &OVector<f64, D>) {
        self.t = t;
        self.x.clone_from(x);
        self.t_carry = 0.0;
        self.x_carry.as_mut_slice().fill(0.0);
        self.cleared = true;
    }

    /// Applies `f` to the state vector (a projection onto a constraint manifold, say) and
    /// clears its compensation, which no longer matches the moved state; time and its
    /// compensation are kept.
    pub fn constrain(&mut self, f: impl FnOnce(&mut OVector<f64, D>)) {
        f(&mut self.x);
        // On the slice: nalgebra's `fill` goes entry by entry, 8% of a projected RK4 step
        // at n = 100.
        self.x_carry.as_mut_slice().fill(0.0);
        self.cleared = true;
    }

    /// The state vector, consuming the state.
    pub fn into_x(self) -> OVector<f64, D> {
        self.x
    }

    /// Time, its compensation, the state and its compensation, for code that advances
    /// states by [`kahan_add`] itself (the batch).
    pub(crate) fn parts(&self) -> (f64, f64, &[f64], &[f64]) {
        (self.t, self.t_carry, self.x.as_slice(), self.x_carry.as_slice())
    }

    /// [`parts`](Self::parts), to be written.
    pub(crate) fn parts_mut(&mut self) -> (&mut f64, &mut f64, &mut [f64], &mut [f64]) {
        self.cleared = false;
        (&mut self.t, &mut self.t_carry, self.x.as_mut_slice(), self.x_carry.as_mut_slice())
    }

    /// Time, its compensation and the state, to be written, the state's compensation kept.
    pub(crate) fn time_and_x_mut(&mut self) -> (&mut f64, &mut f64, &mut [f64]) {
        (&mut self.t, &mut self.t_carry, self.x.as_mut_slice())
    }

    /// Whether every entry of the state's compensation is known to be `+0.0` (cleared by
    /// [`new`](Self::new), [`set`](Self::set) or [`constrain`](Self::constrain) and not
    /// written since); `false` says nothing.
    pub(crate) fn is_cleared(&self) -> bool {
        self.cleared
    }

    /// Sets what [`parts`](Self::parts) gives; `x` and `x_carry` as long as the state.
    pub(crate) fn set_parts(&mut self, t: f64, t_carry: f64, x: impl Iterator<Item = (f64, f64)>) {
        (self.t, self.t_carry) = (t, t_carry);
        self.cleared = false;
        for ((x, carry), (new, new_carry)) in self.x.iter_mut().zip(self.x_carry.iter_mut()).zip(x) {
            (*x, *carry) = (new, new_carry);
        }
    }

    /// `t += h`, `x += increment` with compensated (Kahan) summation.
    pub(crate) fn advance(&mut self, h: f64, increment: &OVector<f64, D>) {
        debug_assert_eq!(increment.len(), self.x.len(), "an increment per entry");
        self.advance_with(h, increment.as_slice(), |_, &delta| delta);
    }

    /// [`advance`](Self::advance) by the increments `increment(x_i, d_i)`, asked in order,
    /// one per item `d_i` of `per_entry` (at least as many as entries). One loop over the
    /// slices, zipped: it vectorises where `increment` is a plain read.
    pub(crate) fn advance_with<I: IntoIterator>(
        &mut self,
        h: f64,
        per_entry: I,
        mut increment: impl FnMut(f64, I::Item) -> f64,
    ) {
        (self.t, self.t_carry) = kahan_add(self.t, self.t_carry, h);
        self.cleared = false;
        let x = self.x.as_mut_slice().iter_mut().zip(self.x_carry.as_mut_slice());
        for ((x, carry), d) in x.zip(per_entry) {
            (*x, *carry) = kahan_add(*x, *carry, increment(*x, d));
        }
    }
}

/// One step of compensated summation: returns the new sum `s + (δ + carry)` rounded,
/// and the part of `δ + carry` that the rounding lost (lane by lane for [`Lanes`](crate::lanes::Lanes)).
#[inline(always)]
pub(crate) fn kahan_add<V: crate::lanes::Lane>(sum: V, carry: V, delta: V) -> (V, V) {
    let corrected = delta + carry;
    let new = sum + corrected;
    (new, corrected - (new - sum))
}

/// What an integrator has done so far; counts only go up (use a new integrator, or
/// [`Stats::default`] to compare, for a fresh count).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Stats {
    /// Steps taken successfully.
    pub steps: u64,
    /// Steps that returned an error.
    pub failed_steps: u64,
    /// Evaluations of [`System::rhs`] by the integrator itself (those inside a
    /// finite-difference [`System::jacobian`] are not counted here: `2·dim` each for the
    /// default).
    pub rhs_evaluations: u64,
    /// Evaluations of [`System::jacobian`].
    pub jacobian_evaluations: u64,
    /// LU factorisations of a Newton matrix.
    pub factorizations: u64,
    /// Newton iterations (simplified and full), each one solve of the stage equations'
    /// linearisation.
    pub newton_iterations: u64,
    /// Steps on which simplified Newton failed and full Newton (a Jacobian at every stage,
    /// every iteration) was used.
    pub full_newton_steps: u64,
    /// Steps an implicit method split into two halves because its Newton iteration did not
    /// converge ([`RodMidpoint`](crate::RodMidpoint)).
    pub halved_steps: u64,
    /// Internal steps an error-controlled method rejected and retried smaller
    /// ([`DormandPrince`]).
    pub rejected_steps: u64,
}

/// A one-step method advancing a [`State`] of the system `S` by a given step.
pub trait Integrator<S: System>
where
    DefaultAllocator: SystemAlloc<S::Dim>,
{
    /// Advances `state` from `t` to `t + h` (`h` finite and non-zero; negative steps
    /// integrate backwards).
    ///
    /// On error the state is unchanged. Errors: [`Error::InvalidStepSize`],
    /// [`Error::LengthMismatch`] when the state does not have the system's dimension,
    /// [`Error::StageSolveFailed`] (implicit methods), [`Error::NonFiniteState`], and any
    /// error of the system's `rhs`.
    fn step(&mut self, system: &S, state: &mut State<S::Dim>, h: f64) -> Result<()>;

    /// What the integrator has done so far.
    fn stats(&self) -> &Stats;

    /// Takes `steps` equal steps from `state.t()` to `t_end`. `state.t()` ends within
    /// round-off of `t_end` (it is the compensated sum of the steps).
    fn integrate(&mut self, system: &S, state: &mut State<S::Dim>, t_end: f64, steps: usize) -> Result<()> {
        let h = (t_end - state.t()) / steps as f64;
        for _ in 0..steps {
            self.step(system, state, h)?;
        }
        Ok(())
    }
}

/// A boxed integrator is an integrator (to choose one at run time, and wrap it, e.g. in
/// [`Projected`]).
impl<S: System, I: Integrator<S> + ?Sized> Integrator<S> for Box<I>
where
    DefaultAllocator: SystemAlloc<S::Dim>,
{
    fn step(&mut self, system: &S, state: &mut State<S::Dim>, h: f64) -> Result<()> {
        (**self).step(system, state, h)
    }

    fn stats(&self) -> &Stats {
        (**self).stats()
    }
}

/// [`Error::InvalidStepSize`] unless the step size `h` (s) is finite and not zero.
pub(crate) fn check_step_size(h: f64) -> Result<()> {
    if h.is_finite() && h != 0.0 { Ok(()) } else { Err(Error::InvalidStepSize { h }) }
}

/// Checks a step size and the state's length before a step.
fn check_step<D: Dim>(expected: usize, x: &OVector<f64, D>, h: f64) -> Result<()>
where
    DefaultAllocator: Allocator<D>,
{
    check_step_size(h)?;
    if x.len() != expected {
        return Err(Error::LengthMismatch { what: "x", expected, got: x.len() });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn compensated_time_reaches_the_end_exactly() {
        // 0.1 is not representable; a million plain additions drift by ~1e-6 s.
        let (mut t, mut carry, mut plain) = (0.0, 0.0, 0.0);
        for _ in 0..1_000_000 {
            (t, carry) = kahan_add(t, carry, 0.1);
            plain += 0.1;
        }
        assert!((t - 100_000.0f64).abs() <= 1.5e-11, "{t}");
        assert!((plain - 100_000.0f64).abs() > 1e-7, "{plain}");
    }

    #[test]
    fn a_state_knows_its_compensation_clear_only_until_it_is_written() {
        use nalgebra::DVector;
        let mut state = State::new(0.0, DVector::from_vec(vec![1.0, 2.0]));
        assert!(state.is_cleared());
        state.advance(0.1, &DVector::from_vec(vec![1e-17, 0.5]));
        assert!(!state.is_cleared() && state.compensation()[0] != 0.0);
        let (_, _, x) = state.time_and_x_mut();
        x[1] = 3.0;
        assert!(!state.is_cleared(), "the compensation kept, and not known clear");
        state.constrain(|x| x[0] = 1.0);
        assert!(state.is_cleared() && state.compensation().iter().all(|&c| c.to_bits() == 0));
        let cleared = state.clone();
        let _ = state.parts_mut();
        assert!(!state.is_cleared());
        assert_eq!(state, cleared, "equal numbers are equal states, whatever is known");
        state.set_parts(0.1, 0.0, [(1.0, 0.0), (3.0, 0.0)].into_iter());
        assert!(!state.is_cleared());
        state.set(0.0, &DVector::from_vec(vec![1.0, 2.0]));
        assert!(state.is_cleared());
    }
}
