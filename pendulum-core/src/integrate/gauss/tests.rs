//! Tests of `gauss`.

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
        let got = [linear_step::<U1>(lambda, h), linear_step::<U2>(lambda, h), linear_step::<U3>(lambda, h)];
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
        assert_eq!((stats.jacobian_evaluations, stats.factorizations, stats.full_newton_steps), (1, 1, 0));
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
        let system = FirstOrder::new(Planar::new(Chain::<Dyn>::new(&[1.0, 0.7], &[1.0, 0.6], 9.81).unwrap()));
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
