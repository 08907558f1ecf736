//! Runs an integrator from `t0` to `t1` with a fixed step, handing every k-th state to a
//! callback (or a [`Recorder`]) that may stop the run early.
//!
//! ```
//! use std::ops::ControlFlow;
//! use nalgebra::{DVector, Dyn, U3};
//! use pendulum_core::integrate::{GaussLegendre, GaussOptions, State};
//! use pendulum_core::{Chain, FirstOrder, Planar, trajectory};
//!
//! let system = FirstOrder::new(Planar::new(Chain::<Dyn>::uniform(2, 1.0, 1.0, 9.81).unwrap()));
//! let mut solver = GaussLegendre::<_, U3>::new(&system, GaussOptions::default());
//! let mut state = State::new(0.0, system.state(&DVector::from_vec(vec![1.0, 0.5]), &DVector::zeros(2)));
//! let mut highest = f64::NEG_INFINITY;
//! let summary = trajectory::run(&mut solver, &system, &mut state, 2.0, 0.01, 10, |_t, x| {
//!     highest = highest.max(x[0]);
//!     ControlFlow::Continue(())
//! })
//! .unwrap();
//! assert_eq!((summary.steps, summary.samples), (200, 21));
//! assert!((state.t() - 2.0).abs() < 1e-14);
//! ```

use std::ops::ControlFlow;

use nalgebra::{DefaultAllocator, OVector};

use crate::error::{Error, Result};
use crate::integrate::{Integrator, State, System, SystemAlloc};

/// What a [`run`] did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Summary {
    /// Steps taken.
    pub steps: u64,
    /// Times the callback was called.
    pub samples: u64,
    /// The step size used, s: `(t1 − t0) / n` (negative when integrating backwards).
    pub h: f64,
    /// The time reached, s (`t1` within round-off unless stopped early).
    pub t: f64,
    /// The callback returned `ControlFlow::Break`.
    pub stopped_early: bool,
}

/// The number of equal steps `n = ⌈|t1 − t0| / h⌉` and their signed size `(t1 − t0) / n`
/// that cover `[t0, t1]` with steps no longer than `h` (s).
///
/// A ratio within `1e-9` (relative) of an integer counts as that integer, so `t1 = 1`,
/// `h = 0.1` gives 10 steps, not 11. `t1 = t0` gives no steps.
///
/// Errors: [`Error::InvalidRun`] when `t0` or `t1` is not finite or `h` is not finite and
/// positive.
pub fn plan(t0: f64, t1: f64, h: f64) -> Result<(u64, f64)> {
    if !t0.is_finite() {
        return Err(Error::InvalidRun { what: "start time", requirement: "finite", value: t0 });
    }
    if !t1.is_finite() {
        return Err(Error::InvalidRun { what: "end time", requirement: "finite", value: t1 });
    }
    if !(h.is_finite() && h > 0.0) {
        return Err(Error::InvalidRun { what: "step size", requirement: "finite and positive", value: h });
    }
    let span = t1 - t0;
    if span == 0.0 {
        return Ok((0, 0.0));
    }
    let ratio = span.abs() / h;
    let nearest = ratio.round();
    let n = if nearest >= 1.0 && (ratio - nearest).abs() <= 1e-9 * nearest { nearest } else { ratio.ceil() };
    if n > u64::MAX as f64 / 2.0 {
        return Err(Error::InvalidRun { what: "step size", requirement: "not absurdly small", value: h });
    }
    Ok((n as u64, span / n))
}

/// Integrates `state` from `state.t()` to `t1` in [`plan`]`(t0, t1, h)` equal steps,
/// calling `sample(t, x)` at the start, after every `every`-th step and after the last
/// step (if not already sampled there). The run stops after a sample for which `sample`
/// returns `ControlFlow::Break(())`.
///
/// `state` ends at the last time reached; its time is the compensated sum of the steps,
/// so it lands on `t1` within round-off.
///
/// Errors: [`Error::InvalidRun`] for a bad `t1`, `h` or `every = 0` (checked before any
/// step); [`Error::StepFailed`] wrapping the integrator's or system's error, with the
/// time and number of the failed step (the state is then left at the start of that
/// step).
pub fn run<S, I, F>(
    integrator: &mut I,
    system: &S,
    state: &mut State<S::Dim>,
    t1: f64,
    h: f64,
    every: usize,
    mut sample: F,
) -> Result<Summary>
where
    S: System,
    I: Integrator<S> + ?Sized,
    F: FnMut(f64, &OVector<f64, S::Dim>) -> ControlFlow<()>,
    DefaultAllocator: SystemAlloc<S::Dim>,
{
    if every == 0 {
        let requirement = "at least 1 step";
        return Err(Error::InvalidRun { what: "sampling interval", requirement, value: 0.0 });
    }
    let (n, step) = plan(state.t(), t1, h)?;
    let mut summary = Summary { steps: 0, samples: 1, h: step, t: state.t(), stopped_early: false };
    if sample(state.t(), state.x()).is_break() {
        summary.stopped_early = true;
        return Ok(summary);
    }
    for i in 1..=n {
        let t = state.t();
        integrator.step(system, state, step).map_err(|e| Error::StepFailed {
            t,
            step: i - 1,
            source: Box::new(e),
        })?;
        summary.steps = i;
        summary.t = state.t();
        if i % every as u64 == 0 || i == n {
            summary.samples += 1;
            if sample(state.t(), state.x()).is_break() {
                summary.stopped_early = i < n;
                return Ok(summary);
            }
        }
    }
    Ok(summary)
}

/// Samples of a run: times (s) and states, in order.
///
/// ```
/// # use nalgebra::{DVector, Dyn};
/// # use pendulum_core::integrate::{Rk4, State};
/// # use pendulum_core::{Chain, FirstOrder, Planar, trajectory::{self, Recorder}};
/// let system = FirstOrder::new(Planar::new(Chain::<Dyn>::uniform(1, 1.0, 1.0, 9.81).unwrap()));
/// let mut state = State::new(0.0, system.state(&DVector::from_vec(vec![0.5]), &DVector::zeros(1)));
/// let mut recorder = Recorder::new();
/// trajectory::run(&mut Rk4::new(&system), &system, &mut state, 1.0, 0.01, 25, |t, x| recorder.push(t, x)).unwrap();
/// assert_eq!(recorder.times(), &[0.0, 0.25, 0.5, 0.75, 1.0]);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Recorder<D: nalgebra::Dim>
where
    DefaultAllocator: nalgebra::allocator::Allocator<D>,
{
    times: Vec<f64>,
    states: Vec<OVector<f64, D>>,
    limit: Option<usize>,
}

impl<D: nalgebra::Dim> Default for Recorder<D>
where
    DefaultAllocator: nalgebra::allocator::Allocator<D>,
{
    fn default() -> Self {
        Self { times: Vec::new(), states: Vec::new(), limit: None }
    }
}

impl<D: nalgebra::Dim> Recorder<D>
where
    DefaultAllocator: nalgebra::allocator::Allocator<D>,
{
    /// An empty recorder without a limit.
    pub fn new() -> Self {
        Self::default()
    }

    /// An empty recorder that stops the run once it holds `limit` samples.
    pub fn with_limit(limit: usize) -> Self {
        Self { times: Vec::with_capacity(limit), states: Vec::with_capacity(limit), limit: Some(limit) }
    }

    /// Stores a sample; `Break` once the limit (if any) is reached. Use as the callback
    /// of [`run`]: `|t, x| recorder.push(t, x)`.
    pub fn push(&mut self, t: f64, x: &OVector<f64, D>) -> ControlFlow<()> {
        self.times.push(t);
        self.states.push(x.clone());
        match self.limit {
            Some(limit) if self.times.len() >= limit => ControlFlow::Break(()),
            _ => ControlFlow::Continue(()),
        }
    }

    /// Sample times, s.
    pub fn times(&self) -> &[f64] {
        &self.times
    }

    /// Sampled states.
    pub fn states(&self) -> &[OVector<f64, D>] {
        &self.states
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.times.len()
    }

    /// No samples yet.
    pub fn is_empty(&self) -> bool {
        self.times.is_empty()
    }

    /// `(times, states)`.
    pub fn into_parts(self) -> (Vec<f64>, Vec<OVector<f64, D>>) {
        (self.times, self.states)
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::{Const, Vector1};

    use super::*;
    use crate::integrate::Rk4;

    /// `x' = 1` until `t > 1.5`, then a system error.
    struct Clock;

    impl System for Clock {
        type Dim = Const<1>;
        fn dim(&self) -> Const<1> {
            Const
        }
        fn rhs(&self, t: f64, _x: &Vector1<f64>, out: &mut Vector1<f64>) -> Result<()> {
            if t > 1.5 {
                return Err(Error::NotPositiveDefinite);
            }
            out[0] = 1.0;
            Ok(())
        }
    }

    #[test]
    fn plan_covers_the_interval_with_equal_steps() {
        assert_eq!(plan(0.0, 1.0, 0.1).unwrap().0, 10);
        assert_eq!(plan(0.0, 1.0, 0.3), Ok((4, 0.25)));
        assert_eq!(plan(1.0, 0.0, 0.5), Ok((2, -0.5)));
        assert_eq!(plan(2.0, 2.0, 0.5), Ok((0, 0.0)));
        assert!(matches!(plan(0.0, f64::NAN, 0.1), Err(Error::InvalidRun { what: "end time", .. })));
        assert!(matches!(plan(0.0, 1.0, -0.1), Err(Error::InvalidRun { what: "step size", .. })));
        assert!(matches!(plan(0.0, 1.0, 0.0), Err(Error::InvalidRun { what: "step size", .. })));
    }

    #[test]
    fn samples_start_every_k_and_end() {
        let mut solver = Rk4::new(&Clock);
        let mut state = State::new(0.0, Vector1::new(0.0));
        let mut recorder = Recorder::new();
        let summary = run(&mut solver, &Clock, &mut state, 1.0, 0.1, 4, |t, x| recorder.push(t, x)).unwrap();
        assert_eq!(summary.steps, 10);
        assert!(!summary.stopped_early);
        let times: Vec<f64> = recorder.times().iter().map(|t| (t * 10.0).round() / 10.0).collect();
        assert_eq!(times, [0.0, 0.4, 0.8, 1.0]);
        assert_eq!(summary.samples, 4);
        assert!((state.x()[0] - 1.0).abs() < 1e-15);
    }

    #[test]
    fn the_callback_stops_the_run() {
        let mut solver = Rk4::new(&Clock);
        let mut state = State::new(0.0, Vector1::new(0.0));
        let mut recorder = Recorder::with_limit(3);
        let summary = run(&mut solver, &Clock, &mut state, 1.0, 0.1, 2, |t, x| recorder.push(t, x)).unwrap();
        assert!(summary.stopped_early);
        assert_eq!((summary.steps, recorder.len()), (4, 3));
        assert!((state.t() - 0.4).abs() < 1e-15);
    }

    #[test]
    fn a_failed_step_says_when() {
        let mut solver = Rk4::new(&Clock);
        let mut state = State::new(0.0, Vector1::new(0.0));
        let err =
            run(&mut solver, &Clock, &mut state, 3.0, 0.5, 1, |_, _| ControlFlow::Continue(())).unwrap_err();
        match err {
            Error::StepFailed { t, step: 3, source } => {
                assert_eq!(t, 1.5);
                assert_eq!(*source, Error::NotPositiveDefinite);
            }
            other => panic!("{other}"),
        }
        assert_eq!(state.t(), 1.5);
        assert!(matches!(
            run(&mut solver, &Clock, &mut state, 3.0, 0.5, 0, |_, _| ControlFlow::Continue(())),
            Err(Error::InvalidRun { what: "sampling interval", .. })
        ));
    }
}
