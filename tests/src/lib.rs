//! Physics-level integration tests of the workspace live in `tests/`; this library holds
//! their shared fixtures, and its doctests run the README's examples.
#![doc = include_str!("../../README.md")]

pub mod batches;
pub mod control;

use nalgebra::{DefaultAllocator, Dim, OVector, U1};
use pendulum_core::{Inputs, Model, ModelAlloc};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A seeded generator, so every test is reproducible.
pub fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}

/// Masses and lengths log-uniform over [0.1, 10], g in [0, 20], damping in [0, 2].
pub fn random_chain<L: nalgebra::Dim>(rng: &mut ChaCha8Rng, n: usize, damped: bool) -> pendulum_core::Chain<L>
where
    DefaultAllocator: nalgebra::allocator::Allocator<L>,
{
    let log_uniform = |rng: &mut ChaCha8Rng| 10f64.powf(rng.random_range(-1.0..1.0));
    let masses: Vec<f64> = (0..n).map(|_| log_uniform(rng)).collect();
    let lengths: Vec<f64> = (0..n).map(|_| log_uniform(rng)).collect();
    let damping: Vec<f64> = (0..n).map(|_| if damped { rng.random_range(0.0..2.0) } else { 0.0 }).collect();
    pendulum_core::Chain::new(&masses, &lengths, rng.random_range(0.0..20.0))
        .and_then(|c| c.with_damping(&damping))
        .expect("random parameters are valid")
}

/// A vector of `model.dof()` entries drawn uniformly from `range`.
pub fn random_vector<M: Model>(
    rng: &mut ChaCha8Rng,
    model: &M,
    range: std::ops::Range<f64>,
) -> OVector<f64, M::Dof>
where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>,
{
    OVector::from_iterator_generic(
        model.dof(),
        U1,
        (0..model.dof().value()).map(|_| rng.random_range(range.clone())),
    )
}

/// Random torques (±10 N·m) and pivot acceleration (±20 m/s² per component).
pub fn random_inputs<M: Model>(rng: &mut ChaCha8Rng, model: &M) -> Inputs<M::Dof, M::Space>
where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>,
{
    let mut inputs = model.zero_inputs();
    inputs.torque = random_vector(rng, model, -10.0..10.0);
    inputs.pivot_acceleration.iter_mut().for_each(|a| *a = rng.random_range(-20.0..20.0));
    inputs
}
