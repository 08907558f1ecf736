//! The Jacobians of a batch of planar chains: each chain's kept O(n) solve in its links'
//! angles and its O(n²) Jacobians ([`PlanarTangents`](crate::PlanarTangents), generic over
//! [`Lane`]) in SIMD lanes, as `PlanarTension`'s `Derivatives::state_jacobians` computes
//! them for each chain alone (in `f64`, bit for bit), or in single precision; mixed row by
//! row (`rods::state_rows`) and scattered straight into numpy's `(B, n, n)` order. The
//! blocks spread over the cores.

use nalgebra::{DVector, Dyn, U2, Vector2};

use super::jacobians::in_blocks;
use super::planar::{Block, BlockStates};
use super::rooms::Room;
use super::run_lanes::RunLane;
use super::transpose::{scatter_matrix_row, transpose_square};
use super::{
    Blocks, F32x8, Failure, PlanarBatch, WIDTH_F32, block_chains, check_len, first_bad_input, gather, one_of,
    simd_kernel,
};
use crate::error::{Error, Result};
use crate::jacobians::{Derivatives, Jacobians};
use crate::lanes::{Aligned, FlushSubnormals, Lane, Lanes};
use crate::model::Inputs;
use crate::models::PlanarTension;
use crate::rods::{Columns, Link, pull, solve_in_angles, state_rows};

/// The longest chains whose Jacobians a batch computes in lanes; longer ones go one at a
/// time. Measured on one thread, 64 chains, lanes against one at a time in the same
/// call: 1.6× as fast at n = 20, 1.05–1.1× at n = 32 and 48, 0.93× at n = 64 and 0.92× at
/// n = 100, in eight lanes and in four alike (`docs/ensembles.md`). Where it turns is
/// measured, not explained: a block's `G` is `W · 8 · n²` bytes (262 kB at n = 64 in eight
/// lanes), and writing the results (`2n²` numbers a chain) weighs on both ways.
const LANES_UP_TO: usize = 48;

/// A task's room for one chain at a time: the state's `θ`, `θ̇`, the inputs and the
/// Jacobians of a chain.
type ChainRoom = (DVector<f64>, DVector<f64>, Inputs<Dyn, U2>, Jacobians<PlanarTension<Dyn>>);

/// The states of a call, `B` rows each of numbers `T`: angles `q` (rad), rates `qd`
/// (rad/s), joint torques (N·m; `None`: none) and pivot accelerations (m/s², rows of 2;
/// `None`: at rest).
#[derive(Debug, Clone, Copy)]
struct States<'a, T = f64> {
    q: &'a [T],
    qd: &'a [T],
    torque: Option<&'a [T]>,
    pivot: Option<&'a [T]>,
}

/// A task's room for a block of chains in lanes `V`: its states in lane order, the kept
/// solve's links, `G` (`n × n`), the columns' weights and a row of each Jacobian
/// (`rods::state_rows`).
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
    /// m/s²; `None`: at rest), as [`accelerations`](Self::accelerations) takes them:
    /// written into `dq` and `dqd` as `B` blocks of `n × n`, row-major
    /// (`dq[k n² + a n + b] = ∂θ̈_a/∂θ_b` of chain `k`), exactly what
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
        let args = self.check_jacobian_args(States { q, qd, torque, pivot }, dq, dqd)?;
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
        /// [`block_jacobians`] of block `b` of `W` chains (constants in `blocks`). Returns
        /// the lanes whose `θ̈` is not finite (their blocks are left to the caller).
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
            let block = one_of(blocks, b);
            block_jacobians(self.links, block, lanes, states, room, (dq, dqd), false).map(|flag| flag != 0)
        }
        dispatch fn jacobian_block_simd, jacobian_block_avx2, avx512 jacobian_block_avx512
    }

    /// [`state_jacobians`](Self::state_jacobians) in single precision: arrays in `f32`,
    /// eight chains per AVX2 register, each chain's constants rounded to `f32`, the sines
    /// from the single-precision kernel, in lanes at every length. Not bit for bit
    /// anything: its error against the `f64` call is measured in `docs/ensembles.md`.
    ///
    /// Returns the chains that failed, in order: a non-finite input as the `f64` call names
    /// it, otherwise (a number past `f32`'s range in `θ̈` or the Jacobians)
    /// [`Error::SinglePrecisionOverflow`]; their blocks are NaN. Errors:
    /// [`Error::LengthMismatch`] when an array does not hold `B` rows or blocks.
    pub fn state_jacobians_f32(
        &self,
        q: &[f32],
        qd: &[f32],
        torque: Option<&[f32]>,
        pivot: Option<&[f32]>,
        dq: &mut [f32],
        dqd: &mut [f32],
    ) -> Result<Vec<Failure>> {
        let states = self.check_jacobian_args(States { q, qd, torque, pivot }, dq, dqd)?;
        let (chains, n) = (self.len(), self.links());
        let room = || self.rooms.take(|| BlockRoom::<F32x8>::new(n));
        let one = |room: &mut Room<'_, BlockRoom<F32x8>>, b: usize, dq: &mut [f32], dqd: &mut [f32]| {
            let lanes = block_chains::<WIDTH_F32>(b, chains);
            let flagged = self.jacobian_block_f32_simd(b, lanes, states, room, dq, dqd);
            let blocks = dq.chunks_exact_mut(n * n).zip(dqd.chunks_exact_mut(n * n));
            let mut failures = Vec::new();
            for (k, (dq, dqd)) in blocks.enumerate().filter(|(k, _)| flagged[*k]) {
                dq.fill(f32::NAN);
                dqd.fill(f32::NAN);
                let chain = lanes[k];
                let error = first_bad_input(chain, [n, 2], [q, qd], torque, pivot);
                failures.push(Failure { chain, error: error.unwrap_or(Error::SinglePrecisionOverflow) });
            }
            failures
        };
        Ok(in_blocks(dq, dqd, WIDTH_F32 * n * n, room, one))
    }

    simd_kernel! {
        /// [`block_jacobians`] of block `b` in single precision, eight chains. Returns the
        /// lanes whose `θ̈` or a Jacobian entry is not finite.
        fn jacobian_block_f32(
            &self,
            b: usize,
            lanes: [usize; WIDTH_F32],
            states: States<'_, f32>,
            room: &mut BlockRoom<F32x8>,
            dq: &mut [f32],
            dqd: &mut [f32],
        ) -> [bool; WIDTH_F32] {
            // `G` decays along a chain into `f32`'s subnormals (`lanes::FlushSubnormals`).
            let _flush = FlushSubnormals::new();
            let block = one_of(&self.blocks_f32, b);
            block_jacobians(self.links, block, lanes, states, room, (dq, dqd), true).map(|flag| flag != 0)
        }
        dispatch fn jacobian_block_f32_simd, jacobian_block_f32_avx2
    }

    /// Checks that `q`, `qd` and `torque` hold `B` rows of `n`, `pivot` `B` rows of 2, and
    /// `dq` and `dqd` `B` blocks of `n²`; returns the states.
    fn check_jacobian_args<'a, T>(
        &self,
        states: States<'a, T>,
        dq: &[T],
        dqd: &[T],
    ) -> Result<States<'a, T>> {
        let (chains, n) = (self.len(), self.links());
        check_len("q", states.q, chains, n)?;
        check_len("qd", states.qd, chains, n)?;
        if let Some(t) = states.torque {
            check_len("torque", t, chains, n)?;
        }
        check_len("dq", dq, chains, n * n)?;
        check_len("dqd", dqd, chains, n * n)?;
        if let Some(p) = states.pivot {
            check_len("pivot", p, chains, 2)?;
        }
        Ok(states)
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

/// One block of `W` chains of `n` links in lanes `V` (`W` its width), constants `block`:
/// gather, `sin θ` and `cos θ` of all its angles at once, the kept solve and its Jacobians
/// in lanes, each Jacobian's rows scattered into the block's `dq` and `dqd` as they come.
/// Returns the lanes whose `θ̈` is not finite, and with `entries` also those with a
/// Jacobian entry that is not finite (checked on each row while it is in the cache).
#[inline(always)]
fn block_jacobians<V: RunLane, const W: usize>(
    n: usize,
    block: &Block<V>,
    lanes: [usize; W],
    States { q, qd, torque, pivot }: States<'_, V::Num>,
    room: &mut BlockRoom<V>,
    (dq, dqd): (&mut [V::Num], &mut [V::Num]),
    entries: bool,
) -> V::Mask {
    let (rods, gravity) = block.constants();
    let zero = V::splat(0.0);
    let t = &mut room.states;
    let pivot = t.gather([q, qd], pivot, lanes, n);
    // The pulls as the chain alone forms them, from zero torques if none are given.
    match torque {
        Some(torque) => gather(torque, lanes, n, V::flatten_mut(&mut t.torque)),
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
    let mut flagged = V::non_finite(&room.rows[..n]);
    room.green.fill(zero);
    let columns = Columns { links: &room.links, rods, gravity, pivot };
    let emit = |i: usize, by_q: &[V], by_qd: &[V]| {
        if entries {
            flagged = V::or(flagged, V::or(V::non_finite(by_q), V::non_finite(by_qd)));
        }
        scatter_matrix_row::<_, W>(V::flatten(by_q), n, i, dq);
        scatter_matrix_row::<_, W>(V::flatten(by_qd), n, i, dqd);
    };
    state_rows(columns, &mut room.green, &mut room.weights, &mut room.rows, emit);
    flagged
}
