//! The integrators own their buffers: once constructed, a step performs no heap
//! allocation for a fixed-size model (`Planar<Const<2>>` through `FirstOrder`, the default
//! finite-difference Jacobian included), nor for a dynamic-size system whose own
//! right-hand side and Jacobian do not allocate. Checked with a counting global allocator
//! (this test binary only), per thread so parallel tests do not interfere.

use std::alloc::{GlobalAlloc, Layout, System as SystemAllocator};
use std::cell::Cell;
use std::f64::consts::FRAC_PI_2;

use nalgebra::{Const, DMatrix, DVector, Dyn, U1, U2, U3, Vector4};
use pendulum_core::integrate::{GaussLegendre, GaussOptions, Integrator, Rk4, State, System};
use pendulum_core::{Chain, Error, FirstOrder, Planar, Result};

struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<u64> = const { Cell::new(0) };
}

// SAFETY: delegates every call to the system allocator unchanged; only counts.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|n| n.set(n.get() + 1));
        // SAFETY: same contract as the caller's.
        unsafe { SystemAllocator.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { SystemAllocator.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|n| n.set(n.get() + 1));
        // SAFETY: same contract as the caller's.
        unsafe { SystemAllocator.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Heap allocations made on this thread while running `f`.
fn allocations_in<R>(f: impl FnOnce() -> R) -> (u64, R) {
    let before = ALLOCATIONS.with(Cell::get);
    let result = f();
    (ALLOCATIONS.with(Cell::get) - before, result)
}

fn fixed_system() -> FirstOrder<Planar<Const<2>>, pendulum_core::Inputs<Const<2>, U2>> {
    FirstOrder::new(Planar::new(Chain::<Const<2>>::uniform(2, 1.0, 1.0, 9.81).unwrap()))
}

fn steps<S: System<Dim = Const<4>>, I: Integrator<S>>(system: &S, integrator: &mut I) -> Result<()> {
    let mut state = State::new(0.0, Vector4::new(FRAC_PI_2, FRAC_PI_2, 0.0, 0.0));
    integrator.integrate(system, &mut state, 1.0, 100)
}

#[test]
fn the_counter_sees_allocations() {
    let (count, v) = allocations_in(|| std::hint::black_box(DVector::<f64>::zeros(3)));
    assert_eq!((count, v.len()), (1, 3));
}

#[test]
fn fixed_size_steps_do_not_allocate() {
    let system = fixed_system();
    let options = GaussOptions::default();
    let mut gauss1 = GaussLegendre::<_, U1>::new(&system, options);
    let mut gauss2 = GaussLegendre::<_, U2>::new(&system, options);
    let mut gauss3 = GaussLegendre::<_, U3>::new(&system, options);
    let mut rk4 = Rk4::new(&system);
    let (count, results) = allocations_in(|| {
        [
            steps(&system, &mut gauss1),
            steps(&system, &mut gauss2),
            steps(&system, &mut gauss3),
            steps(&system, &mut rk4),
        ]
    });
    assert!(results.iter().all(Result::is_ok), "{results:?}");
    assert_eq!(count, 0, "heap allocations in 400 fixed-size steps");
    assert!(gauss3.stats().jacobian_evaluations > 0);
}

/// The fallback path (full Newton, Jacobians at the stages) and the error it ends in
/// allocate nothing either: two iterations per attempt are too few to converge.
#[test]
fn failing_fixed_size_step_does_not_allocate() {
    let system = fixed_system();
    let options = GaussOptions { max_iterations: 2, ..GaussOptions::default() };
    let mut gauss = GaussLegendre::<_, U2>::new(&system, options);
    let (count, result) = allocations_in(|| steps(&system, &mut gauss));
    assert!(matches!(result, Err(Error::StageSolveFailed { t: 0.0, .. })), "{result:?}");
    assert_eq!(gauss.stats().full_newton_steps, 1);
    assert_eq!(count, 0);
}

/// A damped oscillator `q' = p`, `p' = −q − p/10` on `DVector`s, writing into its outputs.
struct Oscillator;

impl System for Oscillator {
    type Dim = Dyn;
    fn dim(&self) -> Dyn {
        Dyn(2)
    }
    fn rhs(&self, _t: f64, x: &DVector<f64>, out: &mut DVector<f64>) -> Result<()> {
        out[0] = x[1];
        out[1] = -x[0] - 0.1 * x[1];
        Ok(())
    }
    fn jacobian(&self, _t: f64, _x: &DVector<f64>, out: &mut DMatrix<f64>) -> Result<()> {
        out.copy_from_slice(&[0.0, -1.0, 1.0, -0.1]);
        Ok(())
    }
}

#[test]
fn dynamic_size_buffers_are_allocated_at_construction_only() {
    let system = Oscillator;
    let mut gauss = GaussLegendre::<_, U3>::new(&system, GaussOptions::default());
    let mut rk4 = Rk4::new(&system);
    let mut state = State::new(0.0, DVector::from_vec(vec![1.0, 0.0]));
    let (count, result) = allocations_in(|| {
        gauss.integrate(&system, &mut state, 5.0, 100)?;
        rk4.integrate(&system, &mut state, 10.0, 100)
    });
    result.unwrap();
    assert_eq!(count, 0);
}
