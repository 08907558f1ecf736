//! The same physics through a generated fixed-N model (`pendulum_macros::model!`) and the
//! generic dynamic-N model gives the same trajectory to round-off.
//!
//! n = 3, planar and spatial, non-uniform chain, 1000 Gauss–Legendre s = 2 steps of
//! h = 10⁻³ s (1 s of motion; the planar start has both upper links horizontal, the
//! chaotic regime, and 1 s keeps the amplification of round-off by the chaos small).
//! Both models' right-hand sides agree to a few ulps (`pendulum-macros/tests/
//! agrees_with_generic.rs`); over the run those differences are carried and amplified by
//! the flow, so what is asserted is: at every step the state difference, relative to
//! `max(‖x‖∞, 1)`, stays below 1e-13 (measured: 3e-16 to 3e-15, printed with
//! `--nocapture`).
//! The same holds in the canonical form ([`Canonical`]), whose kinetic gradient the
//! generated models take from their chart (`Model::Chart`).

use std::f64::consts::FRAC_PI_2;

use nalgebra::{DefaultAllocator, DimMul, DimProd, Dyn, OVector, U1, U2};
use pendulum_core::integrate::{GaussLegendre, GaussOptions, Integrator, State, System};
use pendulum_core::{Canonical, Chain, FirstOrder, Model, ModelAlloc, Planar, Spatial};

pendulum_macros::model! {
    struct Planar3 { kind: planar, links: 3 }
    struct Spatial3 { kind: spatial, links: 3 }
}

const MASSES: [f64; 3] = [1.0, 0.7, 1.3];
const LENGTHS: [f64; 3] = [1.0, 0.8, 0.6];
const G: f64 = 9.81;
const STEPS: usize = 1000;
const H: f64 = 1e-3;
const TOLERANCE: f64 = 1e-13;

fn vector<D: nalgebra::Dim>(dim: D, values: &[f64]) -> OVector<f64, D>
where
    DefaultAllocator: nalgebra::allocator::Allocator<D>,
{
    OVector::from_iterator_generic(dim, U1, values.iter().copied())
}

/// The state after each step of Gauss s = 2 on `system` from `x0`, as plain numbers.
fn trajectory<S: System>(system: &S, x0: OVector<f64, S::Dim>) -> Vec<Vec<f64>>
where
    S::Dim: DimMul<U2>,
    DefaultAllocator: pendulum_core::integrate::GaussAlloc<S::Dim, U2>,
{
    let mut solver = GaussLegendre::<_, U2>::new(system, GaussOptions::default());
    let mut state = State::new(0.0, x0);
    (0..STEPS)
        .map(|_| {
            solver.step(system, &mut state, H).expect("regular states");
            state.x().iter().copied().collect()
        })
        .collect()
}

/// The largest relative state difference over the run.
fn worst_difference(a: &[Vec<f64>], b: &[Vec<f64>]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| {
            let scale = x.iter().fold(1.0f64, |m, v| m.max(v.abs()));
            x.iter().zip(y).map(|(u, v)| (u - v).abs()).fold(0.0, f64::max) / scale
        })
        .fold(0.0, f64::max)
}

/// Velocity-form and canonical-form trajectories of one model from `(q, q̇)`.
fn both_forms<M: Model + Clone>(model: &M, q: &[f64], qd: &[f64]) -> (Vec<Vec<f64>>, Vec<Vec<f64>>)
where
    M::Dof: DimMul<U2>,
    DimProd<M::Dof, U2>: DimMul<U2>,
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>
        + pendulum_core::integrate::GaussAlloc<DimProd<M::Dof, U2>, U2>,
{
    let (q, qd) = (vector(model.dof(), q), vector(model.dof(), qd));
    let velocity = FirstOrder::new(model.clone());
    let canonical = Canonical::new(model.clone());
    let a = trajectory(&velocity, velocity.state(&q, &qd));
    let b = trajectory(&canonical, canonical.from_velocities(&q, &qd));
    (a, b)
}

#[test]
fn planar_generated_and_generic_models_give_the_same_trajectory() {
    let generated = Planar3::new(Chain::new(&MASSES, &LENGTHS, G).unwrap());
    let generic = Planar::new(Chain::<Dyn>::new(&MASSES, &LENGTHS, G).unwrap());
    let (q, qd) = ([FRAC_PI_2, FRAC_PI_2, 0.3], [0.0, 0.0, 0.0]);
    let (gen_v, gen_c) = both_forms(&generated, &q, &qd);
    let (dyn_v, dyn_c) = both_forms(&generic, &q, &qd);
    let (velocity, canonical) = (worst_difference(&gen_v, &dyn_v), worst_difference(&gen_c, &dyn_c));
    eprintln!("planar n = 3: velocity form {velocity:.2e}, canonical form {canonical:.2e}");
    // The run is not trivial: the chain moves by about a radian.
    let moved = gen_v.last().unwrap().iter().zip(&q).map(|(x, q)| (x - q).abs()).fold(0.0, f64::max);
    assert!(moved > 0.5, "{moved}");
    assert!(velocity < TOLERANCE, "{velocity:e}");
    assert!(canonical < TOLERANCE, "{canonical:e}");
}

#[test]
fn spatial_generated_and_generic_models_give_the_same_trajectory() {
    let generated = Spatial3::new(Chain::new(&MASSES, &LENGTHS, G).unwrap());
    let generic = Spatial::new(Chain::<Dyn>::new(&MASSES, &LENGTHS, G).unwrap());
    // Swinging and spinning, every link well away from sin θ = 0 for the whole run.
    let q = [1.0, 1.3, 1.6, 0.0, 0.5, 1.0];
    let qd = [0.5, -0.3, 0.8, 2.0, 1.5, -1.0];
    let (gen_v, gen_c) = both_forms(&generated, &q, &qd);
    let (dyn_v, dyn_c) = both_forms(&generic, &q, &qd);
    let lowest_sin_theta =
        gen_v.iter().flat_map(|x| x[..3].iter().map(|t| t.sin().abs())).fold(f64::INFINITY, f64::min);
    let (velocity, canonical) = (worst_difference(&gen_v, &dyn_v), worst_difference(&gen_c, &dyn_c));
    eprintln!(
        "spatial n = 3: velocity form {velocity:.2e}, canonical form {canonical:.2e}, \
         lowest |sin θ| {lowest_sin_theta:.3}"
    );
    assert!(lowest_sin_theta > 0.1, "{lowest_sin_theta}");
    assert!(velocity < TOLERANCE, "{velocity:e}");
    assert!(canonical < TOLERANCE, "{canonical:e}");
}
