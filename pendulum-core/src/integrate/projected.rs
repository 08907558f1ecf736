//! Projection onto a constraint manifold after each step of another integrator.

use nalgebra::{DefaultAllocator, OVector};

use super::{Integrator, State, Stats, System, SystemAlloc};
use crate::error::Result;

/// A system whose exact solutions stay on a manifold (invariants such as unit link
/// directions), with a map back onto it for states a numerical method has moved off.
pub trait Constrained: System
where
    DefaultAllocator: SystemAlloc<Self::Dim>,
{
    /// Moves `x` onto the manifold (a no-op for states already on it, up to round-off).
    fn project(&self, x: &mut OVector<f64, Self::Dim>);
}

/// The integrator `I` followed, after every step, by the system's
/// [`project`](Constrained::project): the standard projection method (Hairer, Lubich &
/// Wanner, *Geometric Numerical Integration*, IV.4). The projection moves the state by
/// about the step's local error, so the method keeps its order, and the invariants hold
/// to round-off at every step instead of drifting.
#[derive(Debug, Clone)]
pub struct Projected<I> {
    inner: I,
}

impl<I> Projected<I> {
    /// `inner` with a projection after each step.
    pub fn new(inner: I) -> Self {
        Self { inner }
    }

    /// The integrator inside.
    pub fn inner(&self) -> &I {
        &self.inner
    }
}

impl<S: Constrained, I: Integrator<S>> Integrator<S> for Projected<I>
where
    DefaultAllocator: SystemAlloc<S::Dim>,
{
    fn step(&mut self, system: &S, state: &mut State<S::Dim>, h: f64) -> Result<()> {
        self.inner.step(system, state, h)?;
        state.constrain(|x| system.project(x));
        Ok(())
    }

    fn stats(&self) -> &Stats {
        self.inner.stats()
    }
}
