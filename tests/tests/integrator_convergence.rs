//! Measured convergence order of each integrator on the chaotic double pendulum.
//!
//! Unit masses and lengths, g = 9.81 m/s², released at rest from θ = (π/2, π/2) (both
//! links horizontal: enough energy for the chaotic regime). The state at t = 2 s from
//! several fixed step sizes is compared with an independent adaptive oracle, Dormand and
//! Prince's DOP853 (the `ode_solvers` crate) at tolerance 1e-13; the least-squares slope
//! of log(error) against log(h) must be within ±0.2 of the method's order: Gauss–Legendre
//! s = 1, 2, 3 → 2, 4, 6, RK4 → 4.
//!
//! The step sizes sit in the asymptotic range (below them the chaotic flow makes the
//! error erratic) and keep every error at least 30 times above the oracle's own error,
//! which is estimated by comparing it with a run at tolerance 1e-14. The same runs through
//! the fixed-size model `Planar<Const<2>>` give the same errors, which shows the generic
//! code paths agree.
//!
//! `cargo test -p pendulum-tests --test integrator_convergence -- --nocapture` prints
//! the table of errors, orders and Newton iterations per step.

use std::f64::consts::FRAC_PI_2;
use std::sync::OnceLock;

use nalgebra::{Const, DVector, DefaultAllocator, DimMul, Dyn, OVector, U1, U2, U3};
use pendulum_core::integrate::{
    GaussAlloc, GaussLegendre, GaussOptions, GaussStages, Integrator, Rk4, State, Stats, System, SystemAlloc,
};
use pendulum_core::{Chain, FirstOrder, Inputs, Planar};

const T_END: f64 = 2.0;
const ORACLE_TOLERANCE: f64 = 1e-13;

type Dynamic = FirstOrder<Planar<Dyn>, Inputs<Dyn, U2>>;
type Fixed = FirstOrder<Planar<Const<2>>, Inputs<Const<2>, U2>>;

fn dynamic_system() -> Dynamic {
    FirstOrder::new(Planar::new(Chain::<Dyn>::uniform(2, 1.0, 1.0, 9.81).unwrap()))
}

fn fixed_system() -> Fixed {
    FirstOrder::new(Planar::new(Chain::<Const<2>>::uniform(2, 1.0, 1.0, 9.81).unwrap()))
}

/// θ = (π/2, π/2), at rest.
fn initial_state<S: System>(system: &S) -> OVector<f64, S::Dim>
where
    DefaultAllocator: SystemAlloc<S::Dim>,
{
    OVector::from_iterator_generic(system.dim(), U1, [FRAC_PI_2, FRAC_PI_2, 0.0, 0.0])
}

/// DOP853 on `ode_solvers`' own vectors (it uses an older nalgebra), calling the same
/// right-hand side through slices.
struct Oracle(Dynamic);

impl ode_solvers::System<f64, ode_solvers::DVector<f64>> for Oracle {
    fn system(&self, t: f64, y: &ode_solvers::DVector<f64>, dy: &mut ode_solvers::DVector<f64>) {
        let x = DVector::from_column_slice(y.as_slice());
        let mut f = DVector::zeros(x.len());
        self.0.rhs(t, &x, &mut f).expect("the planar model has no singular states");
        dy.as_mut_slice().copy_from_slice(f.as_slice());
    }
}

/// The state at `T_END` from DOP853 with relative and absolute tolerance `tolerance`.
fn dop853(tolerance: f64) -> [f64; 4] {
    let system = dynamic_system();
    let y0 = ode_solvers::DVector::from_column_slice(initial_state(&system).as_slice());
    let mut solver = ode_solvers::Dop853::new(Oracle(system), 0.0, T_END, T_END, y0, tolerance, tolerance);
    solver.set_output(ode_solvers::OutputType::Sparse);
    solver.integrate().expect("DOP853 reaches the end");
    assert_eq!(*solver.x_out().last().unwrap(), T_END);
    let end = solver.y_out().last().unwrap();
    [end[0], end[1], end[2], end[3]]
}

/// The reference state at `T_END` and an estimate of its error (its distance from a
/// run at a tolerance ten times tighter), computed once for all tests.
fn oracle() -> &'static ([f64; 4], f64) {
    static ORACLE: OnceLock<([f64; 4], f64)> = OnceLock::new();
    ORACLE.get_or_init(|| {
        let reference = dop853(ORACLE_TOLERANCE);
        let tighter = dop853(ORACLE_TOLERANCE / 10.0);
        (reference, max_distance(&reference, &tighter))
    })
}

fn max_distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max)
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Method {
    Gauss1,
    Gauss2,
    Gauss3,
    Rk4,
}

impl Method {
    fn order(self) -> f64 {
        match self {
            Method::Gauss1 => 2.0,
            Method::Gauss2 | Method::Rk4 => 4.0,
            Method::Gauss3 => 6.0,
        }
    }

    /// Numbers of steps to `T_END`, in the asymptotic range, errors well above the
    /// oracle's (sixth order gets tiny fast, so Gauss s = 3 takes the largest steps).
    fn steps(self) -> &'static [usize] {
        match self {
            Method::Gauss1 | Method::Gauss2 => &[100, 200, 400, 800],
            Method::Gauss3 => &[80, 100, 120, 140, 160],
            Method::Rk4 => &[800, 1600, 3200],
        }
    }

    /// The state at `T_END` after `steps` equal steps, and the integrator's statistics.
    fn solve<S: System>(self, system: &S, steps: usize) -> (Vec<f64>, Stats)
    where
        S::Dim: DimMul<U1> + DimMul<U2> + DimMul<U3>,
        DefaultAllocator: GaussAlloc<S::Dim, U1> + GaussAlloc<S::Dim, U2> + GaussAlloc<S::Dim, U3>,
    {
        match self {
            Method::Gauss1 => run(system, gauss::<S, U1>(system), steps),
            Method::Gauss2 => run(system, gauss::<S, U2>(system), steps),
            Method::Gauss3 => run(system, gauss::<S, U3>(system), steps),
            Method::Rk4 => run(system, Rk4::new(system), steps),
        }
    }
}

fn gauss<S: System, St: GaussStages>(system: &S) -> GaussLegendre<S::Dim, St>
where
    S::Dim: DimMul<St>,
    DefaultAllocator: GaussAlloc<S::Dim, St>,
{
    GaussLegendre::new(system, GaussOptions::default())
}

fn run<S: System, I: Integrator<S>>(system: &S, mut integrator: I, steps: usize) -> (Vec<f64>, Stats)
where
    DefaultAllocator: SystemAlloc<S::Dim>,
{
    let mut state = State::new(0.0, initial_state(system));
    integrator.integrate(system, &mut state, T_END, steps).expect("the step sizes here are stable");
    (state.x().iter().copied().collect(), *integrator.stats())
}

/// Least-squares slope of log(error) against log(h).
fn fitted_order(steps: &[usize], errors: &[f64]) -> f64 {
    let points: Vec<(f64, f64)> =
        steps.iter().zip(errors).map(|(&n, &e)| ((T_END / n as f64).ln(), e.ln())).collect();
    let count = points.len() as f64;
    let mean_h = points.iter().map(|p| p.0).sum::<f64>() / count;
    let mean_e = points.iter().map(|p| p.1).sum::<f64>() / count;
    let covariance: f64 = points.iter().map(|p| (p.0 - mean_h) * (p.1 - mean_e)).sum();
    let variance: f64 = points.iter().map(|p| (p.0 - mean_h).powi(2)).sum();
    covariance / variance
}

/// Errors of `method` on `system` at its step counts; checks the fitted order, that the
/// errors stand clear of the oracle's, and that no step needed the full-Newton fallback.
fn check_order<S: System>(method: Method, system: &S, label: &str) -> Vec<f64>
where
    S::Dim: DimMul<U1> + DimMul<U2> + DimMul<U3>,
    DefaultAllocator: GaussAlloc<S::Dim, U1> + GaussAlloc<S::Dim, U2> + GaussAlloc<S::Dim, U3>,
{
    let (reference, oracle_error) = oracle();
    let steps = method.steps();
    let mut errors = Vec::new();
    for &n in steps {
        let (x, stats) = method.solve(system, n);
        let error = max_distance(&x, reference);
        eprintln!(
            "{label} {method:?} h = {:.5} s: error {error:.3e}, Newton iterations/step {:.2}, \
             Jacobians/step {:.3}, rhs/step {:.2}",
            T_END / n as f64,
            stats.newton_iterations as f64 / n as f64,
            stats.jacobian_evaluations as f64 / n as f64,
            stats.rhs_evaluations as f64 / n as f64,
        );
        assert_eq!((stats.steps, stats.failed_steps, stats.full_newton_steps), (n as u64, 0, 0));
        assert!(error > 30.0 * oracle_error, "{method:?} n = {n}: error {error:e} too close to the oracle's");
        errors.push(error);
    }
    let order = fitted_order(steps, &errors);
    eprintln!("{label} {method:?}: fitted order {order:.3} (expected {})", method.order());
    assert!((order - method.order()).abs() <= 0.2, "{method:?}: order {order} vs {}", method.order());
    errors
}

#[test]
fn oracle_is_accurate_to_better_than_1e_11() {
    let (_, error) = oracle();
    eprintln!("DOP853 at {ORACLE_TOLERANCE:e} vs {:e}: {error:.3e}", ORACLE_TOLERANCE / 10.0);
    assert!(*error < 1e-11, "{error:e}");
}

#[test]
fn gauss_legendre_1_stage_has_order_2() {
    check_order(Method::Gauss1, &dynamic_system(), "Planar<Dyn>");
}

#[test]
fn gauss_legendre_2_stages_has_order_4() {
    check_order(Method::Gauss2, &dynamic_system(), "Planar<Dyn>");
}

#[test]
fn gauss_legendre_3_stages_has_order_6() {
    check_order(Method::Gauss3, &dynamic_system(), "Planar<Dyn>");
}

#[test]
fn rk4_has_order_4() {
    check_order(Method::Rk4, &dynamic_system(), "Planar<Dyn>");
}

/// The fixed-size model through the same generic integrators: same orders, and the same
/// errors as the dynamic model up to round-off.
#[test]
fn fixed_size_model_converges_alike() {
    for method in [Method::Gauss1, Method::Gauss2, Method::Gauss3, Method::Rk4] {
        let fixed = check_order(method, &fixed_system(), "Planar<Const<2>>");
        let dynamic: Vec<f64> = method
            .steps()
            .iter()
            .map(|&n| max_distance(&method.solve(&dynamic_system(), n).0, &oracle().0))
            .collect();
        for (f, d) in fixed.iter().zip(&dynamic) {
            assert!((f - d).abs() <= 1e-9 * d, "{method:?}: fixed {f:e} vs dynamic {d:e}");
        }
    }
}
