//! The Jacobians of a batch: each planar chain's O(n) tangents
//! ([`PlanarTangents`](crate::PlanarTangents)' solve and Jacobians) in SIMD lanes, as
//! `PlanarTension`'s `Derivatives::state_jacobians` computes them for each chain alone;
//! each chain in directions' O(n²) Jacobian
//! ([`Directions::analytic_jacobian`](crate::Directions::analytic_jacobian)) chain by chain.
//! The blocks and chains spread over the cores; every chain gets its own results bit for
//! bit.

use nalgebra::{DVector, DefaultAllocator, DimName, Dyn, U2, Vector2, allocator::Allocator};
use rayon::prelude::*;

use super::lane_states::non_finite_lanes;
use super::planar::{Block, BlockStates};
use super::rooms::Room;
use super::transpose::{scatter_matrix_row, transpose_square};
use super::{
    Blocks, DirectionsBatch, Failure, PlanarBatch, block_chains, check_len, gather, one_of, simd_kernel,
};
use crate::drive::Drive;
use crate::error::{Error, Result};
use crate::jacobians::{Derivatives, Jacobians};
use crate::lanes::{Aligned, Lane, Lanes};
use crate::model::Inputs;
use crate::models::PlanarTension;
use crate::rods::{Columns, Link, pull, solve_in_angles, state_rows};

/// The longest chains whose Jacobians a batch computes in lanes; longer ones go one at a
/// time. Measured on one thread, 64 chains, lanes against one at a time in the same
/// call: 1.6× as fast at n = 20, 1.05–1.1× at n = 32 and 48, 0.93× at n = 64 and 0.92× at
/// n = 100, in eight lanes and in four alike (`docs/ensembles.md`). A block's `G` then
/// outgrows the second-level cache, and writing the results dominates both ways.
const LANES_UP_TO: usize = 48;

/// A task's room for one chain at a time: the state's `θ`, `θ̇`, the inputs and the
/// Jacobians of a chain.
type ChainRoom = (DVector<f64>, DVector<f64>, Inputs<Dyn, U2>, Jacobians<PlanarTension<Dyn>>);

/// The states of a call, `B` rows each: angles `q` (rad), rates `qd` (rad/s), joint
/// torques (N·m; `None`: none) and pivot accelerations (m/s², rows of 2; `None`: at rest).
#[derive(Debug, Clone, Copy)]
struct States<'a> {
    q: &'a [f64],
    qd: &'a [f64],
    torque: Option<&'a [f64]>,
    pivot: Option<&'a [f64]>,
}

/// A task's room for a block of chains in lanes `V`: its states in lane order, the kept
/// solve's links, `G` (`n × n`), the columns' weights and a row of
/// each Jacobian (`rods::state_rows`).
struct BlockRoom<V: Lane> {
    states: BlockStates<V>,
    links: Aligned<Link<V>>,
    green: Aligned<V>,
    weights: Aligned<([V; 3], [V; 3])>,
    rows: Aligned<V>,
}

impl<V: Lane> BlockRoom<V> {
    fn new(n: usize) -> Self {
        let zero = V::splat(0.0);

        Self {
            states: BlockStates::new(n),
            links: Aligned::filled(Link::at(zero, zero, zero, zero), n),
            green: Aligned::filled(zero, n * n),
            weights: Aligned::filled(([zero; 3], [zero; 3]), 2 * n),
            rows: Aligned::filled(zero, 2 * n),
        }
    }
}

impl PlanarBatch {
    /// `∂θ̈/∂θ` (1/s²) and `∂θ̈/∂θ̇` (1/s) of every chain at angles `q` (rad) and rates `qd`
    /// (rad/s), `B` rows of `n`, with each chain's joint torques `Q_i` (N·m) from `torque`
    /// (`B` rows of `n`; `None`: none) and pivot acceleration from `pivot` (`B` rows of 2,
    /// m/s²; `None`: at rest), as [`accelerations`](Self::accelerations) takes them: written into `dq` and `dqd` as `B` blocks of `n × n`,
    /// row-major (`dq[k n² + a n + b] = ∂θ̈_a/∂θ_b` of chain `k`), exactly what
    /// `PlanarTension::state_jacobians` gives for each chain alone. The kept solve and the
    /// Jacobians run in SIMD lanes for chains of up to 48 links, one chain at a time for
    /// longer ones (where lanes stopped paying); the blocks or chains over the current
    /// rayon pool.
    ///
    /// Returns the chains that failed, in order, with their errors; their blocks are NaN.
    /// Errors: [`Error::LengthMismatch`](crate::Error::LengthMismatch) when an array does
    /// not hold `B` rows or blocks.
    pub fn state_jacobians(
        &self,
        q: &[f64],
        qd: &[f64],
        torque: Option<&[f64]>,
        pivot: Option<&[f64]>,
        dq: &mut [f64],
        dqd: &mut [f64],
    ) -> Result<Vec<Failure>> {
        let (chains, n) = (self.len(), self.links());
        check_len("q", q, chains, n)?;
        check_len("qd", qd, chains, n)?;
        if let Some(t) = torque {
            check_len("torque", t, chains, n)?;
        }
        check_len("dq", dq, chains, n * n)?;
        check_len("dqd", dqd, chains, n * n)?;
        if let Some(p) = pivot {
            check_len("pivot", p, chains, 2)?;
        }
        let args = States { q, qd, torque, pivot };
        Ok(match &self.blocks {
            Blocks::Four(blocks) => self.jacobians_in_lanes(args, dq, dqd, |b, lanes, room, dq, dqd| {
                self.jacobian_block_simd(blocks, b, lanes, args, room, dq, dqd)
            }),
            #[cfg(target_arch = "x86_64")]
            Blocks::Eight(blocks) => self.jacobians_in_lanes(args, dq, dqd, |b, lanes, room, dq, dqd| {
                // SAFETY: eight-lane blocks exist only where the CPU has AVX-512.
                unsafe { self.jacobian_block_avx512(blocks, b, lanes, args, room, dq, dqd) }
            }),
            #[cfg(not(target_arch = "x86_64"))]
            Blocks::Never(_) => unreachable!("eight lanes only with AVX-512"),
        })
    }

    /// Runs `kernel(b, chains, room, dq, dqd)` for every block of `W` chains with its blocks
    /// of `dq` and `dqd`, and redoes each chain whose lane it flags (a result not finite) on
    /// its own, which names the failure and leaves its blocks NaN.
    fn jacobians_in_lanes<const W: usize>(
        &self,
        states: States<'_>,
        dq: &mut [f64],
        dqd: &mut [f64],
        kernel: impl Fn(usize, [usize; W], &mut BlockRoom<Lanes<W>>, &mut [f64], &mut [f64]) -> [bool; W]
        + Sync
        + Send,
    ) -> Vec<Failure> {
        let (chains, n) = (self.len(), self.links());
        if n > LANES_UP_TO {
            let one = |room: &mut ChainRoom, k, dq: &mut [f64], dqd: &mut [f64]| {
                self.one_chain(room, k, states, dq, dqd)
            };
            return in_blocks(dq, dqd, n * n, || self.scratch(), one);
        }
        let room = || self.rooms.take(|| BlockRoom::<Lanes<W>>::new(n));
        let one = |room: &mut Room<'_, BlockRoom<Lanes<W>>>, b: usize, dq: &mut [f64], dqd: &mut [f64]| {
            let lanes = block_chains::<W>(b, chains);
            let flagged = kernel(b, lanes, room, dq, dqd);
            let blocks = dq.chunks_exact_mut(n * n).zip(dqd.chunks_exact_mut(n * n));
            let mut failures = Vec::new();
            for (k, (dq, dqd)) in blocks.enumerate().filter(|(k, _)| flagged[*k]) {
                let mut scratch = self.scratch();
                failures.extend(self.one_chain(&mut scratch, lanes[k], states, dq, dqd));
            }
            failures
        };
        in_blocks(dq, dqd, W * n * n, room, one)
    }

    simd_kernel! {
        /// One block of `W` chains (constants in `blocks`): gather, `sin θ` and `cos θ` of all
        /// its angles at once, the kept solve and its Jacobians in lanes, each Jacobian
        /// turned row-major and scattered into the block's `dq` and `dqd`. Returns the lanes
        /// whose `θ̈` is not finite (their blocks are left to the caller).
        fn jacobian_block<const W: usize>(
            &self,
            blocks: &[Block<Lanes<W>>],
            b: usize,
            lanes: [usize; W],
            states: States<'_>,
            room: &mut BlockRoom<Lanes<W>>,
            dq: &mut [f64],
            dqd: &mut [f64],
        ) -> [bool; W] {
            let (n, States { q, qd, torque, pivot }) = (self.links, states);
            let (rods, gravity) = one_of(blocks, b).constants();
            let pivot = room.states.gather([q, qd], pivot, lanes, n);
            let zero = Lanes([0.0; W]);
            // The pulls as the chain alone forms them, from zero torques if none are given.
            let t = &mut room.states;
            match torque {
                Some(torque) => gather(torque, lanes, n, Lanes::flatten_mut(&mut t.torque)),
                None => t.torque.fill(zero),
            }
            for (i, link) in room.links.iter_mut().enumerate() {
                let (rate, il, drag) = (t.rates[i], rods.inverse_length[i], rods.drag[i]);
                *link = Link::at(t.sin[i], t.cos[i], rate, pull(t.torque[i], il, drag, rate));
            }
            solve_in_angles(&mut room.links, rods, gravity, pivot);
            for (a, link) in room.rows.iter_mut().zip(room.links.iter()) {
                *a = link.acceleration;
            }
            let flagged = non_finite_lanes(&room.rows[..n]).map(|flag| flag != 0);
            room.green.fill(zero);
            let columns = Columns { links: &room.links, rods, gravity, pivot };
            let emit = |i: usize, by_q: &[Lanes<W>], by_qd: &[Lanes<W>]| {
                scatter_matrix_row::<_, W>(Lanes::flatten(by_q), n, i, dq);
                scatter_matrix_row::<_, W>(Lanes::flatten(by_qd), n, i, dqd);
            };
            state_rows(columns, &mut room.green, &mut room.weights, &mut room.rows, emit);
            flagged
        }
        dispatch fn jacobian_block_simd, jacobian_block_avx2, avx512 jacobian_block_avx512
    }

    /// A room for [`one_chain`](Self::one_chain).
    fn scratch(&self) -> ChainRoom {
        let n = self.links();
        (
            DVector::zeros(n),
            DVector::zeros(n),
            Inputs::<Dyn, U2>::zeros(Dyn(n)),
            Jacobians::zeros(self.chain(0)),
        )
    }

    /// Chain `k`'s Jacobians by `PlanarTension::state_jacobians`, transposed into its
    /// blocks `dq` and `dqd`; or, should it fail, its failure, with its blocks NaN.
    fn one_chain(
        &self,
        (x, v, inputs, out): &mut ChainRoom,
        k: usize,
        States { q, qd, torque, pivot }: States<'_>,
        dq: &mut [f64],
        dqd: &mut [f64],
    ) -> Option<Failure> {
        let n = self.links();
        x.copy_from_slice(&q[k * n..(k + 1) * n]);
        v.copy_from_slice(&qd[k * n..(k + 1) * n]);
        if let Some(t) = torque {
            inputs.torque.copy_from_slice(&t[k * n..(k + 1) * n]);
        }
        if let Some(p) = pivot {
            inputs.pivot_acceleration = Vector2::new(p[2 * k], p[2 * k + 1]);
        }
        match self.chain(k).state_jacobians(x, v, inputs, out) {
            Ok(()) => {
                // Row-major: the transposes of nalgebra's column-major blocks.
                transpose_square(out.q.as_slice(), n, dq);
                transpose_square(out.qd.as_slice(), n, dqd);
                None
            }
            Err(error) => {
                dq.fill(f64::NAN);
                dqd.fill(f64::NAN);
                Some(Failure { chain: k, error })
            }
        }
    }
}

impl<S: DimName, Dr: Drive<S> + Sync> DirectionsBatch<S, Dr>
where
    DefaultAllocator: Allocator<S>,
{
    /// `∂ü/∂u` (1/s²) and `∂ü/∂w` (1/s) of every chain at time `t` (s) and states
    /// `x = (u, w)` (`B` rows of `2·S·n`): written into `du` and `dw` as `B` blocks of
    /// `h × h`, `h = S·n`, row-major (`du[k h² + a h + b] = ∂ü_a/∂u_b` of chain `k`). They
    /// are the lower blocks of each chain's
    /// [`Directions::analytic_jacobian`](crate::Directions::analytic_jacobian), bit for bit:
    /// the Jacobian of the first-order system in the directions' own `S` components each
    /// (the constraint `|u_i| = 1` not imposed), one O(n²) pass a chain. The chains go over
    /// the current rayon pool, each on its own (not in lanes).
    ///
    /// Returns the chains that failed, in order, with their errors (a non-finite state as
    /// the chain alone names it; a non-finite result as
    /// [`Error::NotPositiveDefinite`](crate::Error::NotPositiveDefinite), as in
    /// [`accelerations`](Self::accelerations)); their blocks are NaN. Errors:
    /// [`Error::LengthMismatch`](crate::Error::LengthMismatch) when an array does not hold
    /// `B` rows or blocks.
    pub fn state_jacobians(&self, t: f64, x: &[f64], du: &mut [f64], dw: &mut [f64]) -> Result<Vec<Failure>> {
        let half = S::DIM * self.links();
        check_len("x", x, self.len(), 2 * half)?;
        self.jacobians_of(t, |k, state| state.copy_from_slice(&x[2 * half * k..2 * half * (k + 1)]), du, dw)
    }

    /// [`state_jacobians`](Self::state_jacobians) of the states given as two arrays, the
    /// directions `u` and the rates `w`, `B` rows of `S·n` each (as numpy holds `q` and
    /// `qd`): the same numbers.
    ///
    /// Errors: [`Error::LengthMismatch`](crate::Error::LengthMismatch) when an array does
    /// not hold `B` rows or blocks.
    pub fn state_jacobians_split(
        &self,
        t: f64,
        u: &[f64],
        w: &[f64],
        du: &mut [f64],
        dw: &mut [f64],
    ) -> Result<Vec<Failure>> {
        let half = S::DIM * self.links();
        check_len("u", u, self.len(), half)?;
        check_len("w", w, self.len(), half)?;
        let state = |k: usize, state: &mut DVector<f64>| {
            let rows = half * k..half * (k + 1);
            state.as_mut_slice()[..half].copy_from_slice(&u[rows.clone()]);
            state.as_mut_slice()[half..].copy_from_slice(&w[rows]);
        };
        self.jacobians_of(t, state, du, dw)
    }

    /// The Jacobians of every chain at the state `state(k, x)` writes into `x`.
    fn jacobians_of(
        &self,
        t: f64,
        state: impl Fn(usize, &mut DVector<f64>) + Sync + Send,
        du: &mut [f64],
        dw: &mut [f64],
    ) -> Result<Vec<Failure>> {
        let half = S::DIM * self.links();
        let block = half * half;
        check_len("du", du, self.len(), block)?;
        check_len("dw", dw, self.len(), block)?;
        // Per task: the state and the lower blocks, column-major, reused from chain to chain.
        let scratch = || (DVector::zeros(2 * half), vec![0.0; 2 * block]);
        let one = |(x, lower): &mut (DVector<f64>, Vec<f64>), k: usize, du: &mut [f64], dw: &mut [f64]| {
            state(k, x);
            let model = self.model(k);
            let error = match model.check_state(x) {
                Err(error) => Some(error),
                Ok(()) => {
                    model.lower_jacobian_of_valid(t, x.as_slice(), lower);
                    let finite = lower.iter().fold(true, |all, v| all & v.is_finite());
                    (!finite).then_some(Error::NotPositiveDefinite)
                }
            };
            if let Some(error) = error {
                du.fill(f64::NAN);
                dw.fill(f64::NAN);
                return Some(Failure { chain: k, error });
            }
            // Row-major: the transposes of the column-major blocks.
            transpose_square(&lower[..block], half, du);
            transpose_square(&lower[block..], half, dw);
            None
        };
        Ok(in_blocks(du, dw, block, scratch, one))
    }
}

/// Runs `one(scratch, k, a_k, b_k)` for every block `k` of `a` and `b` (`len` numbers each,
/// the last ones shorter), the blocks over the current rayon pool with a `scratch` from
/// `init` per task, and collects the failures in order.
fn in_blocks<T, F: IntoIterator<Item = Failure> + Send>(
    a: &mut [f64],
    b: &mut [f64],
    len: usize,
    init: impl Fn() -> T + Sync + Send,
    one: impl Fn(&mut T, usize, &mut [f64], &mut [f64]) -> F + Sync + Send,
) -> Vec<Failure> {
    // About a thousand entries' work a task (each chain's Jacobians are O(n²)).
    let per_task = (1024 / len.max(1)).max(1);
    let blocks = a.len().div_ceil(len.max(1));
    if blocks <= per_task || rayon::current_num_threads() == 1 {
        // One task's work, or one thread: no handing over to the pool.
        let mut scratch = init();
        let blocks = a.chunks_mut(len).zip(b.chunks_mut(len)).enumerate();
        return blocks.flat_map(|(k, (a, b))| one(&mut scratch, k, a, b)).collect();
    }
    let blocks = a.par_chunks_mut(len).zip(b.par_chunks_mut(len)).enumerate();
    let failures = blocks.with_min_len(per_task).map_init(init, |s, (k, (a, b))| one(s, k, a, b));
    failures.flat_map_iter(|f| f).collect()
}
