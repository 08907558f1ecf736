//! `Chain.integrate`: RK4 steps of many planar chains in lanes, their torques and pivot
//! accelerations held (`PlanarBatch::integrate_rk4` in double precision, bit for bit each
//! state alone; `integrate_rk4_f32` in single), in chunks of steps between which Ctrl-C is
//! looked at.

use std::sync::atomic::{AtomicBool, Ordering};

use nalgebra::{DVector, Dyn};
use pendulum_core::batch::{Failure, PlanarBatch};
use pendulum_core::integrate::State;
use pendulum_experiment::Error;

/// Rods' solves per chunk of a batched integration: Ctrl-C is looked at between chunks
/// (a few milliseconds each).
pub const SOLVES_PER_CHUNK: usize = 1 << 20;

/// The numbers of one integration: the rows of `q`, `q̇`, the torques (`n` each) and the
/// pivot accelerations (2) of every state, with the leading shape that named them.
pub struct Rows<'a> {
    pub lead: &'a [usize],
    pub q: &'a [f64],
    pub qd: &'a [f64],
    pub torque: &'a [f64],
    pub pivot: &'a [f64],
}

/// `steps` RK4 steps of `h` (s) of the planar chain from each state with its inputs held:
/// [`PlanarBatch::integrate_rk4`] on every core, in chunks (the same bits as one call).
/// The new `(q, q̇)`; a failed state is an error naming its index.
pub fn planar_rk4(
    chain: &pendulum_core::Chain<Dyn>,
    rows: &Rows<'_>,
    (h, steps): (f64, usize),
    stop: &AtomicBool,
) -> pendulum_experiment::Result<(Vec<f64>, Vec<f64>)> {
    let n = chain.links();
    let batch = PlanarBatch::repeated(chain.clone(), rows.q.len() / n).map_err(core)?;
    let mut states: Vec<State<Dyn>> = rows
        .q
        .chunks_exact(n)
        .zip(rows.qd.chunks_exact(n))
        .map(|(q, qd)| State::new(0.0, DVector::from_iterator(2 * n, q.iter().chain(qd).copied())))
        .collect();
    in_chunks(n, rows, steps, stop, |now| {
        batch.integrate_rk4(&mut states, Some(rows.torque), Some(rows.pivot), h, now)
    })?;
    Ok(split(n, states.iter().map(|s| s.x().as_slice())))
}

/// [`planar_rk4`] in single precision ([`PlanarBatch::integrate_rk4_f32`]): the numbers
/// rounded to `f32` (one past its range is an error), the rounding compensation kept from
/// chunk to chunk (the same numbers as one call).
pub fn planar_rk4_f32(
    chain: &pendulum_core::Chain<Dyn>,
    rows: &Rows<'_>,
    (h, steps): (f64, usize),
    stop: &AtomicBool,
) -> pendulum_experiment::Result<(Vec<f32>, Vec<f32>)> {
    let n = chain.links();
    let narrow = |v: &[f64]| -> pendulum_experiment::Result<Vec<f32>> {
        let out: Vec<f32> = v.iter().map(|&x| x as f32).collect();
        match out.iter().all(|x| x.is_finite()) {
            true => Ok(out),
            false => Err(core(pendulum_core::Error::SinglePrecisionOverflow)),
        }
    };
    let (torque, pivot) = (narrow(rows.torque)?, narrow(rows.pivot)?);
    let mut x = Vec::with_capacity(2 * rows.q.len());
    for (q, qd) in rows.q.chunks_exact(n).zip(rows.qd.chunks_exact(n)) {
        x.extend(narrow(q)?);
        x.extend(narrow(qd)?);
    }
    let mut carry = vec![0.0f32; x.len()];
    let batch = PlanarBatch::repeated(chain.clone(), rows.q.len() / n).map_err(core)?;
    in_chunks(n, rows, steps, stop, |now| {
        batch.integrate_rk4_f32((&mut x, &mut carry), Some(&torque), Some(&pivot), h, now)
    })?;
    Ok(split(n, x.chunks_exact(2 * n)))
}

/// `run(steps)` over the chunks of `steps` (about [`SOLVES_PER_CHUNK`] rods' solves each),
/// `stop` looked at before each; the first failure as the error naming its state.
fn in_chunks(
    n: usize,
    rows: &Rows<'_>,
    steps: usize,
    stop: &AtomicBool,
    mut run: impl FnMut(usize) -> pendulum_core::Result<Vec<Failure>>,
) -> pendulum_experiment::Result<()> {
    let chunk = (SOLVES_PER_CHUNK / (4 * rows.q.len()).max(1)).max(1);
    debug_assert!(n > 0);
    let mut done = 0;
    while done < steps {
        if stop.load(Ordering::Relaxed) {
            return Err(Error::interrupted("integrate: interrupted"));
        }
        let now = chunk.min(steps - done);
        let failures = run(now).map_err(core)?;
        if let Some(first) = failures.first() {
            let more = match failures.len() {
                1 => String::new(),
                k => format!(" ({} more states failed too)", k - 1),
            };
            let (index, error) = (numpy_index(first.chain, rows.lead), &first.error);
            return Err(Error::failed(format!("integrate: state {index}: {error}{more}")));
        }
        done += now;
    }
    Ok(())
}

/// Rows of `(θ, θ̇)` as the tables of `θ` and of `θ̇`.
fn split<'a, T: Copy + 'a>(n: usize, rows: impl Iterator<Item = &'a [T]>) -> (Vec<T>, Vec<T>) {
    let (mut q, mut qd) = (Vec::new(), Vec::new());
    for row in rows {
        q.extend_from_slice(&row[..n]);
        qd.extend_from_slice(&row[n..2 * n]);
    }
    (q, qd)
}

fn core(e: pendulum_core::Error) -> Error {
    Error::invalid(e.to_string())
}

/// Row `row` of a C-ordered array with leading shape `lead`, as numpy writes its index:
/// `(1, 2)`; a single leading axis as `4`, none as `0`.
fn numpy_index(mut row: usize, lead: &[usize]) -> String {
    let mut index = vec![0; lead.len()];
    for (i, &extent) in lead.iter().enumerate().rev() {
        (index[i], row) = (row % extent.max(1), row / extent.max(1));
    }
    match index.as_slice() {
        [] => "0".to_string(),
        [i] => i.to_string(),
        more => format!("({})", more.iter().map(usize::to_string).collect::<Vec<_>>().join(", ")),
    }
}
