//! Fixtures of the batch tests (`ensembles.rs`, `single_precision.rs`,
//! `unrolled_spatial_ensembles.rs`, …): random chains and whirls, thread pools of one and two
//! threads, and the comparison bit for bit.

use nalgebra::{Const, DVector, DimMul, Dyn, U2, U3};
use nalgebra::{DefaultAllocator, Dim, allocator::Allocator};
use pendulum_core::batch::Failure;
use pendulum_core::integrate::{Integrator, Rk4, State, SystemAlloc};
use pendulum_core::{Chain, Circle, Directions, Error, FirstOrder, InputsAt, Model, ModelAlloc};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

/// A chain of `n` links with masses, lengths and damping log-uniform over two decades and
/// gravity between 1 and 20 m/s².
pub fn random_chain(n: usize, r: &mut ChaCha8Rng) -> Chain<Dyn> {
    let mut decades = |lo: f64| (0..n).map(|_| 10f64.powf(lo + 2.0 * r.random::<f64>())).collect::<Vec<_>>();
    let (masses, lengths, damping) = (decades(-2.0), decades(-2.0), decades(-5.0));
    let g = r.random_range(1.0..20.0);
    Chain::new(&masses, &lengths, g).and_then(|c| c.with_damping(&damping)).expect("chain")
}

/// [`random_chain`] of `N` links, as a fixed-size chain (the same draws).
pub fn random_fixed_chain<const N: usize>(r: &mut ChaCha8Rng) -> Chain<Const<N>> {
    let chain = random_chain(N, r);
    Chain::new(chain.masses().as_slice(), chain.lengths().as_slice(), chain.gravity())
        .and_then(|c| c.with_damping(chain.damping().as_slice()))
        .expect("chain")
}

/// Chains of `n` links whose masses, lengths and damping are spread over `decades`
/// decades around 10 g, 1 cm and 1e-4 N·m·s, with gravity 9.81 m/s².
pub fn spread_chain(n: usize, decades: f64, r: &mut ChaCha8Rng) -> Chain<Dyn> {
    let mut spread =
        |lo: f64| (0..n).map(|_| 10f64.powf(lo + decades * r.random::<f64>())).collect::<Vec<_>>();
    let (masses, lengths, damping) = (spread(-2.0), spread(-2.0), spread(-4.0));
    Chain::new(&masses, &lengths, 9.81).and_then(|c| c.with_damping(&damping)).expect("chain")
}

/// A whirl-like 3D chain: uniform random links, its pivot on a circle of random radius and
/// speed, from a tilted swinging state.
pub fn whirl(n: usize, r: &mut ChaCha8Rng) -> (Directions<U3, Circle>, DVector<f64>) {
    let chain = random_chain(n, r);
    let drive = Circle::new(r.random_range(0.0..0.05), r.random_range(1.0..10.0)).expect("drive");
    let model = Directions::<U3>::new(chain).with_drive(drive);
    let x = whirl_state(&model, n, r);
    (model, x)
}

/// A state of `model` (a whirl of `n` links) at random spherical angles and rates.
pub fn whirl_state(model: &Directions<U3, Circle>, n: usize, r: &mut ChaCha8Rng) -> DVector<f64> {
    let q: Vec<f64> =
        (0..2 * n).map(|i| if i < n { r.random_range(0.1..1.0) } else { r.random_range(0.0..6.0) }).collect();
    let qd: Vec<f64> = (0..2 * n).map(|_| r.random_range(-1.0..1.0)).collect();
    model.from_spherical(&q, &qd).expect("state")
}

/// Thread pools of one and of two threads.
pub fn pools() -> [rayon::ThreadPool; 2] {
    [1, 2].map(|threads| rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool"))
}

/// Every entry equal bit for bit (NaN only where NaN).
pub fn assert_bits(batch: &[f64], single: &[f64], what: &str) {
    assert_eq!(batch.len(), single.len(), "{what}");
    for (i, (a, b)) in batch.iter().zip(single).enumerate() {
        assert_eq!(a.to_bits(), b.to_bits(), "{what}[{i}]: batch {a:e} single {b:e}");
    }
}

/// Time, state and compensation equal bit for bit.
pub fn assert_same_state(batch: &State<Dyn>, single: &State<Dyn>, what: &str) {
    assert_eq!(batch.t().to_bits(), single.t().to_bits(), "{what}: t");
    assert_bits(batch.x().as_slice(), single.x().as_slice(), what);
    assert_bits(
        batch.compensation().as_slice(),
        single.compensation().as_slice(),
        &format!("{what}: compensation"),
    );
}

/// A batch's rows `out` (`m` a chain) and its `failures` against each chain alone
/// (`single`: its row, or its error): equal bit for bit, and failing exactly where the
/// chain alone fails, with the same error (as text: errors carry the NaN they found), its
/// row NaN.
pub fn assert_rows(
    out: &[f64],
    m: usize,
    single: &[Result<Vec<f64>, Error>],
    failures: &[Failure],
    what: &str,
) {
    let mut failed = failures.iter();
    for (k, alone) in single.iter().enumerate() {
        let row = &out[k * m..(k + 1) * m];
        match alone {
            Ok(expected) => assert_bits(row, expected, &format!("{what}, chain {k}")),
            Err(error) => {
                let failure = failed.next().unwrap_or_else(|| panic!("{what}: chain {k} not reported"));
                assert_eq!((failure.chain, failure.error.to_string()), (k, error.to_string()), "{what}");
                assert!(row.iter().all(|x| x.is_nan()), "{what}: chain {k}'s row is NaN");
            }
        }
    }
    assert!(failed.next().is_none(), "{what}: only the failing chains are reported");
}

/// A batch's states after a run (`batched`) and its `failures` against each chain's own
/// run (`alone`: its state and its error): time, state and compensation equal bit for bit,
/// and the failures the chains' own.
pub fn assert_runs<D: Dim>(
    batched: &[State<D>],
    alone: &[(State<D>, Option<Error>)],
    failures: &[Failure],
    what: &str,
) where
    DefaultAllocator: Allocator<D>,
{
    let mut failed = failures.iter();
    for (k, (state, (single, error))) in batched.iter().zip(alone).enumerate() {
        assert_eq!(state.t().to_bits(), single.t().to_bits(), "{what}: chain {k}'s t");
        assert_bits(state.x().as_slice(), single.x().as_slice(), &format!("{what}: chain {k}'s x"));
        assert_bits(
            state.compensation().as_slice(),
            single.compensation().as_slice(),
            &format!("{what}: chain {k}'s compensation"),
        );
        if let Some(error) = error {
            let failure = failed.next().unwrap_or_else(|| panic!("{what}: chain {k} not reported"));
            assert_eq!((failure.chain, failure.error.to_string()), (k, error.to_string()), "{what}");
        }
    }
    assert!(failed.next().is_none(), "{what}: only the failing chains are reported");
}

/// Each chain's state after `steps` steps of size `h` of `Rk4` on
/// `FirstOrder::with_inputs(models[k], inputs(k))`, alone, from `states[k]`, and its error
/// (the state left where it failed).
pub fn stepped_alone<M, I, D>(
    models: &[M],
    states: &[State<D>],
    inputs: impl Fn(usize) -> I,
    h: f64,
    steps: usize,
) -> Vec<(State<D>, Option<Error>)>
where
    M: Model + Clone,
    I: InputsAt<M::Dof, M::Space>,
    M::Dof: DimMul<U2, Output = D>,
    D: Dim,
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space> + SystemAlloc<D>,
{
    models
        .iter()
        .zip(states)
        .enumerate()
        .map(|(k, (model, state))| {
            let system = FirstOrder::with_inputs(model.clone(), inputs(k));
            let mut rk4 = Rk4::new(&system);
            let mut state = state.clone();
            let error = (0..steps).find_map(|_| rk4.step(&system, &mut state, h).err());
            (state, error)
        })
        .collect()
}

/// A batch's run: `steps` steps of every chain of `states`, and its failures.
pub type Run<'a, D> = &'a (dyn Fn(&mut [State<D>], usize) -> Result<Vec<Failure>, Error> + Sync);

/// A batch's `run` of `steps` steps from `states` against each chain's own run (`alone`,
/// [`assert_runs`]): on 1 and 2 threads, and in two calls of half the steps each (the
/// failures of both calls together). `what` names the batch.
pub fn check_runs<D: Dim>(
    run: Run<'_, D>,
    states: &[State<D>],
    alone: &[(State<D>, Option<Error>)],
    steps: usize,
    what: &str,
) where
    DefaultAllocator: Allocator<D>,
    State<D>: Clone + Send,
{
    let chains = states.len();
    for pool in pools() {
        let mut batched = states.to_vec();
        let failures = pool.install(|| run(&mut batched, steps)).expect("batch");
        let threads = pool.current_num_threads();
        assert_runs(&batched, alone, &failures, &format!("{what}: {chains} chains, {threads} threads"));
    }
    let mut batched = states.to_vec();
    let first = run(&mut batched, steps / 2).expect("batch");
    let mut failures = run(&mut batched, steps - steps / 2).expect("batch");
    failures.retain(|f| !first.iter().any(|g| g.chain == f.chain));
    failures.extend(first);
    failures.sort_by_key(|f| f.chain);
    assert_runs(&batched, alone, &failures, &format!("{what}: {chains} chains in two calls"));
}

/// A chain of `N` links whose masses and lengths go from 10 g and 1 cm up by a factor of up
/// to `spread`, damping 1e-4 N·m·s, gravity 9.81 m/s².
pub fn spread_fixed_chain<const N: usize>(spread: f64, r: &mut ChaCha8Rng) -> Chain<Const<N>> {
    let mut up = |x: f64| (0..N).map(|_| x * r.random_range(1.0..spread)).collect::<Vec<_>>();
    let (masses, lengths) = (up(0.01), up(0.01));
    Chain::new(&masses, &lengths, 9.81).and_then(|c| c.with_damping(&[1e-4; N])).expect("chain")
}

/// A batch's `f64` run: `steps` steps of `states` with torques and pivot accelerations
/// (`None`: none) held.
pub type Run64<'a, D> =
    &'a dyn Fn(&mut [State<D>], Option<&[f64]>, Option<&[f64]>, usize) -> Result<Vec<Failure>, Error>;

/// A batch's run in single precision: `steps` steps of rows `x = (q, q̇)` and their
/// compensations `carry`, with torques and pivot accelerations held.
pub type Run32<'a> = &'a (
        dyn Fn(&mut [f32], &mut [f32], Option<&[f32]>, Option<&[f32]>, usize) -> Result<Vec<Failure>, Error>
            + Sync
    );

/// A batch's run in single precision (`run32`) against its `f64` run (`run64`) of `steps`
/// steps from `states`, free and with small random torques and pivot accelerations held
/// (`[torques, pivots]` a chain: up to 1e-5 N·m and 1 m/s²): the worst
/// `max |x₃₂ − x₆₄| / max |x₆₄|` over the chains and the two. On the way, checks that the
/// `f32` run gives the same bits on 1 and 2 threads and in two calls of half the steps
/// each (the compensations kept), and fails no chain.
pub fn f32_run_error<D: Dim>(
    run64: Run64<'_, D>,
    run32: Run32<'_>,
    states: &[State<D>],
    [torques, pivots]: [usize; 2],
    steps: usize,
    r: &mut ChaCha8Rng,
) -> f64
where
    DefaultAllocator: Allocator<D>,
    State<D>: Clone,
{
    let chains = states.len();
    let torque: Vec<f64> = (0..chains * torques).map(|_| r.random_range(-1e-5..1e-5)).collect();
    let pivot: Vec<f64> = (0..chains * pivots).map(|_| r.random_range(-1.0..1.0)).collect();
    let to32 = |v: &[f64]| v.iter().map(|&x| x as f32).collect::<Vec<f32>>();
    let (torque32, pivot32) = (to32(&torque), to32(&pivot));
    let mut worst = 0.0f64;
    for held in [false, true] {
        let mut exact = states.to_vec();
        let (t, p) = if held { (Some(&torque[..]), Some(&pivot[..])) } else { (None, None) };
        assert!(run64(&mut exact, t, p, steps).expect("f64").is_empty());
        let (t, p) = if held { (Some(&torque32[..]), Some(&pivot32[..])) } else { (None, None) };
        let run = |x: &mut [f32], carry: &mut [f32], steps| run32(x, carry, t, p, steps);
        worst = worst.max(f32_error_of(run, states, &exact, (steps, true)));
    }
    worst
}

/// A batch's run in single precision of rows `x = (q, q̇)` and their compensations `carry`:
/// `steps` steps, and its failures.
pub type RowRun<'a> = &'a (dyn Fn(&mut [f32], &mut [f32], usize) -> Result<Vec<Failure>, Error> + Sync);

/// A batch's driven run in single precision, `run32(x, carry, steps)` from the states'
/// time (`t0`), against its `f64` driven run (`run64`) of `steps` steps from `states` (all
/// at the same time): the worst `max |x₃₂ − x₆₄| / max |x₆₄|` over the chains; on the way,
/// that the `f32` run gives the same bits on 1 and 2 threads, and fails no chain.
pub fn f32_driven_error<D: Dim>(
    run64: Run<'_, D>,
    run32: RowRun<'_>,
    states: &[State<D>],
    steps: usize,
) -> f64
where
    DefaultAllocator: Allocator<D>,
    State<D>: Clone,
{
    let mut exact = states.to_vec();
    assert!(run64(&mut exact, steps).expect("f64").is_empty());
    f32_error_of(run32, states, &exact, (steps, false))
}

/// [`f32_run_error`] of one run, `run32(x, carry, steps)`, against the `f64` states it
/// should reach (`exact`); with `split`, also in two calls of half the steps each.
fn f32_error_of<D: Dim>(
    run32: impl Fn(&mut [f32], &mut [f32], usize) -> Result<Vec<Failure>, Error> + Sync,
    states: &[State<D>],
    exact: &[State<D>],
    (steps, split): (usize, bool),
) -> f64
where
    DefaultAllocator: Allocator<D>,
{
    let rows: Vec<f32> = states.iter().flat_map(|s| s.x().iter().map(|&x| x as f32)).collect();
    let runs: Vec<Vec<f32>> = pools()
        .iter()
        .map(|pool| {
            let (mut x, mut carry) = (rows.clone(), vec![0.0f32; rows.len()]);
            let failures = pool.install(|| run32(&mut x, &mut carry, steps)).expect("f32 run");
            assert!(failures.is_empty(), "{failures:?}");
            x
        })
        .collect();
    let bits = |x: &[f32]| x.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&runs[0]), bits(&runs[1]), "1 and 2 threads");
    if split {
        let (mut x, mut carry) = (rows.clone(), vec![0.0f32; rows.len()]);
        assert!(run32(&mut x, &mut carry, steps / 2).expect("f32 run").is_empty());
        assert!(run32(&mut x, &mut carry, steps - steps / 2).expect("f32 run").is_empty());
        assert_eq!(bits(&runs[0]), bits(&x), "one call and two");
    }
    let m = rows.len() / states.len();
    exact
        .iter()
        .zip(runs[0].chunks(m))
        .map(|(exact, x32)| {
            let scale = exact.x().iter().fold(0.0f64, |s, x| s.max(x.abs()));
            let worst = exact.x().iter().zip(x32).fold(0.0f64, |w, (&a, &b)| w.max((a - f64::from(b)).abs()));
            worst / scale
        })
        .fold(0.0, f64::max)
}
