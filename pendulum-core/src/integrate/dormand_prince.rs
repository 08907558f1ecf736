//! Dormand–Prince 5(4): the explicit embedded pair with error control, adapting its own
//! step inside each step it is asked for.

use nalgebra::{DefaultAllocator, Dim, OVector, U1};

use super::{Constrained, Integrator, State, Stats, System, SystemAlloc, check_step};
use crate::error::{Error, Result};

/// What to do with the state after each accepted internal step: nothing
/// ([`Unprojected`]) or the system's projection onto its constraints ([`OntoConstraints`]).
pub trait Projection<S: System>
where
    DefaultAllocator: SystemAlloc<S::Dim>,
{
    /// Moves `x` as the projection does (or not at all).
    fn apply(&self, system: &S, x: &mut OVector<f64, S::Dim>);
}

/// No projection.
#[derive(Debug, Clone, Copy, Default)]
pub struct Unprojected;

impl<S: System> Projection<S> for Unprojected
where
    DefaultAllocator: SystemAlloc<S::Dim>,
{
    fn apply(&self, _: &S, _: &mut OVector<f64, S::Dim>) {}
}

/// The system's [`Constrained::project`] after every accepted internal step (rod lengths
/// kept to round-off, as [`Projected`](super::Projected) does for fixed steps).
#[derive(Debug, Clone, Copy, Default)]
pub struct OntoConstraints;

impl<S: Constrained> Projection<S> for OntoConstraints
where
    DefaultAllocator: SystemAlloc<S::Dim>,
{
    fn apply(&self, system: &S, x: &mut OVector<f64, S::Dim>) {
        system.project(x);
    }
}

/// The nodes, coefficients and weights of Dormand & Prince (1980), order 5 with an
/// embedded order-4 solution; the last stage is the first of the next step (FSAL).
const C: [f64; 7] = [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0];
const A: [[f64; 6]; 7] = [
    [0.0; 6],
    [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0, 0.0, 0.0],
    [9017.0 / 3168.0, -355.0 / 33.0, 46732.0 / 5247.0, 49.0 / 176.0, -5103.0 / 18656.0, 0.0],
    [35.0 / 384.0, 0.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0],
];
/// Order-5 weights (the last row of `A`; the seventh weight is 0).
const B: [f64; 7] = [35.0 / 384.0, 0.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0, 0.0];
/// Order-5 minus order-4 weights: the error estimate's.
const E: [f64; 7] =
    [71.0 / 57600.0, 0.0, -71.0 / 16695.0, 71.0 / 1920.0, -17253.0 / 339200.0, 22.0 / 525.0, -1.0 / 40.0];

/// Dormand–Prince 5(4) with step-size control: each [`step`](Integrator::step) of `h`
/// advances exactly to `t + h` in as many internal steps as the tolerance needs, each
/// accepted when the embedded error estimate, measured as
/// `‖e_i / (tol (1 + max(|x_i|, |x⁺_i|)))‖_rms ≤ 1`, and the next one sized by
/// `h_new = h · clamp(0.9 err^(−1/5), 0.2, 5)` (no growth right after a rejection).
/// Seven right-hand sides for the first attempt of each step asked for, six for every
/// further one inside it (the last stage is the next first; after a projection it is used
/// as is, which changes the next step by about the projection's move, a higher-order
/// term). `P` projects after every accepted internal
/// step ([`OntoConstraints`], for chains in unit directions) or not ([`Unprojected`]).
///
/// Its step sits where the error control puts it, or at its stability limit
/// (`|hλ| ≲ 3.3`) when the chain's fastest modes set it: then the controller rejects and
/// shrinks in turn, as every explicit method does there.
#[derive(Debug, Clone)]
pub struct DormandPrince<D: Dim, P = Unprojected>
where
    DefaultAllocator: SystemAlloc<D>,
{
    stats: Stats,
    tolerance: f64,
    projection: P,
    /// The next internal step's size, once known (its sign follows the step asked for).
    next: Option<f64>,
    /// `k[0]` holds `f(t, x)` of the current state when `fresh` is true (within one step).
    k: [OVector<f64, D>; 7],
    fresh: bool,
    y: OVector<f64, D>,
    increment: OVector<f64, D>,
}

impl<D: Dim, P> DormandPrince<D, P>
where
    DefaultAllocator: SystemAlloc<D>,
{
    /// A solver for `system` with the relative tolerance `tolerance` (per entry, with a
    /// floor of the same absolute size) and the projection `projection`.
    ///
    /// Errors: [`Error::InvalidTolerance`] unless `1e-14 ≤ tolerance ≤ 1e-1`.
    pub fn new<S: System<Dim = D>>(system: &S, tolerance: f64, projection: P) -> Result<Self> {
        if !(1e-14..=1e-1).contains(&tolerance) {
            return Err(Error::InvalidTolerance { tolerance });
        }
        let dim = system.dim();
        let vector = || OVector::<f64, D>::zeros_generic(dim, U1);
        Ok(Self {
            stats: Stats::default(),
            tolerance,
            projection,
            next: None,
            k: std::array::from_fn(|_| vector()),
            fresh: false,
            y: vector(),
            increment: vector(),
        })
    }

    /// The tolerance.
    pub fn tolerance(&self) -> f64 {
        self.tolerance
    }

    /// One attempt of an internal step `h` from `(t, x)`, `k[0] = f(t, x)` given: writes
    /// the increment and returns the error measure.
    fn attempt<S: System<Dim = D>>(
        &mut self,
        system: &S,
        t: f64,
        x: &OVector<f64, D>,
        h: f64,
    ) -> Result<f64> {
        for s in 1..7 {
            self.y.copy_from(x);
            for (j, a) in A[s].iter().enumerate().take(s) {
                if *a != 0.0 {
                    self.y.axpy(h * a, &self.k[j], 1.0);
                }
            }
            system.rhs(t + C[s] * h, &self.y, &mut self.k[s])?;
        }
        self.stats.rhs_evaluations += 6;
        let mut sum = 0.0;
        for i in 0..x.len() {
            let (mut inc, mut err) = (0.0, 0.0);
            for s in 0..7 {
                inc += B[s] * self.k[s][i];
                err += E[s] * self.k[s][i];
            }
            inc *= h;
            err *= h;
            self.increment[i] = inc;
            let scale = self.tolerance * (1.0 + x[i].abs().max((x[i] + inc).abs()));
            sum += (err / scale).powi(2);
        }
        Ok((sum / x.len().max(1) as f64).sqrt())
    }
}

/// Most internal steps (accepted or not) per step asked for, before it is an error.
const MAX_INTERNAL_STEPS: usize = 1_000_000;

impl<D: Dim, S: System<Dim = D>, P: Projection<S>> Integrator<S> for DormandPrince<D, P>
where
    DefaultAllocator: SystemAlloc<D>,
{
    fn step(&mut self, system: &S, state: &mut State<D>, h: f64) -> Result<()> {
        check_step(self.y.len(), state.x(), h)?;
        let end = state.t() + h;
        let saved = state.clone();
        // The first stage of the step's first attempt is evaluated afresh: the state may
        // not be the one the last call ended on. Inside the step, the last stage is reused.
        self.fresh = false;
        let mut last_rejected = false;
        for _ in 0..MAX_INTERNAL_STEPS {
            let t = state.t();
            let remaining = end - t;
            if remaining.abs() <= 4.0 * f64::EPSILON * end.abs().max(h.abs()) {
                return Ok(());
            }
            let mut sub = self.next.map_or(h, |n| n.abs().copysign(h));
            // Land on the end: take the rest whole when the step would pass it or leave less
            // than a tenth of a step.
            if sub.abs() >= remaining.abs() * 0.9 {
                sub = remaining;
            }
            if !self.fresh {
                if let Err(e) = system.rhs(t, state.x(), &mut self.k[0]) {
                    return self.fail(state, saved, e);
                }
                self.stats.rhs_evaluations += 1;
                self.fresh = true;
            }
            let error = match self.attempt(system, t, state.x(), sub) {
                Ok(e) => e,
                Err(e) => return self.fail(state, saved, e),
            };
            if sub.abs() < 1e-12 * h.abs() {
                return self.fail(
                    state,
                    saved,
                    Error::StepSizeCollapsed { t, h: sub, tolerance: self.tolerance },
                );
            }
            let factor = if error == 0.0 { 5.0 } else { (0.9 * error.powf(-0.2)).clamp(0.2, 5.0) };
            if error <= 1.0 {
                state.advance(sub, &self.increment);
                let projection = &self.projection;
                state.constrain(|x| projection.apply(system, x));
                // FSAL: the last stage, f(t + h, x⁺), is the next step's first.
                self.k.swap(0, 6);
                self.stats.steps += 1;
                let grow = if last_rejected { factor.min(1.0) } else { factor };
                self.next = Some(sub.abs() * grow);
                last_rejected = false;
            } else {
                self.stats.rejected_steps += 1;
                self.next = Some(sub.abs() * if error.is_finite() { factor } else { 0.2 });
                last_rejected = true;
            }
        }
        let t = state.t();
        self.fail(
            state,
            saved,
            Error::StepSizeCollapsed { t, h: self.next.unwrap_or(h), tolerance: self.tolerance },
        )
    }

    fn stats(&self) -> &Stats {
        &self.stats
    }
}

impl<D: Dim, P> DormandPrince<D, P>
where
    DefaultAllocator: SystemAlloc<D>,
{
    /// Restores the state of the step's start and reports `e`.
    fn fail(&mut self, state: &mut State<D>, saved: State<D>, e: Error) -> Result<()> {
        *state = saved;
        self.fresh = false;
        self.stats.failed_steps += 1;
        Err(e)
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::{U2, Vector2};

    use super::*;

    /// The harmonic oscillator `x'' = −x`.
    struct Oscillator;
    impl System for Oscillator {
        type Dim = U2;
        fn dim(&self) -> U2 {
            U2
        }
        fn rhs(&self, _: f64, x: &Vector2<f64>, out: &mut Vector2<f64>) -> Result<()> {
            *out = Vector2::new(x[1], -x[0]);
            Ok(())
        }
    }

    /// The global error follows the tolerance: over 10 periods it stays within 100× the
    /// tolerance, and a 100× tighter tolerance gives a smaller error at more steps.
    #[test]
    fn the_error_follows_the_tolerance() {
        let run = |tolerance: f64| {
            let mut solver = DormandPrince::new(&Oscillator, tolerance, Unprojected).unwrap();
            let mut state = State::new(0.0, Vector2::new(1.0, 0.0));
            let end = 20.0 * std::f64::consts::PI;
            solver.integrate(&Oscillator, &mut state, end, 100).unwrap();
            assert!((state.t() - end).abs() < 1e-12);
            ((state.x() - Vector2::new(1.0, 0.0)).amax(), solver.stats.steps)
        };
        let (loose, loose_steps) = run(1e-6);
        let (tight, tight_steps) = run(1e-8);
        assert!(loose < 1e-4 && tight < 1e-6, "{loose:e} {tight:e}");
        assert!(tight < loose / 10.0, "{loose:e} {tight:e}");
        // Order 5: 100× tighter costs about 100^(1/5) = 2.5× the steps.
        let ratio = tight_steps as f64 / loose_steps as f64;
        assert!((1.8..3.5).contains(&ratio), "{ratio}");
    }

    /// A free 3D chain in unit directions, projected after every internal step: rods to
    /// round-off, energy within a few tolerances over 2 s of swinging.
    #[test]
    fn with_the_projection_the_rods_stay_exact() {
        use crate::{Chain, Directions};
        let n = 12;
        let model = Directions::<nalgebra::U3>::new(Chain::uniform(n, 0.1, 0.1, 9.81).unwrap());
        let q: Vec<f64> = (0..2 * n).map(|i| if i < n { 0.5 } else { 0.2 * i as f64 }).collect();
        let x0 = model.from_spherical(&q, &vec![0.0; 2 * n]).unwrap();
        let e0 = model.energy(&x0);
        let mut solver = DormandPrince::new(&model, 1e-9, OntoConstraints).unwrap();
        let mut state = State::new(0.0, x0);
        solver.integrate(&model, &mut state, 2.0, 40).unwrap();
        let rods = (0..n).map(|i| (model.direction(state.x(), i).norm() - 1.0).abs()).fold(0.0, f64::max);
        assert!(rods < 1e-14, "{rods:e}");
        let drift = (model.energy(state.x()) - e0).abs() / e0.abs();
        assert!(drift < 1e-7, "{drift:e}");
        assert!(
            solver.stats.steps > 40
                && solver.stats.rhs_evaluations < 7 * (solver.stats.steps + solver.stats.rejected_steps) + 50
        );
    }

    #[test]
    fn a_bad_tolerance_is_an_error() {
        assert_eq!(
            DormandPrince::new(&Oscillator, 0.0, Unprojected).unwrap_err(),
            Error::InvalidTolerance { tolerance: 0.0 }
        );
    }
}
