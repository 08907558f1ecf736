//! The Jacobians of a batch in directions: each chain's kept O(n) solve and O(n²) Jacobian
//! ([`Directions::analytic_jacobian`](crate::Directions::analytic_jacobian)'s numbers) in
//! SIMD lanes, mixed row by row (`Linearised::state_rows`) and scattered straight into
//! numpy's `(B, h, h)` order, every chain's own results bit for bit; the blocks over the
//! cores. And the loop over blocks the planar Jacobians use too.

use nalgebra::{DefaultAllocator, DimName, allocator::Allocator};
use rayon::prelude::*;

use super::directions::{Block, RateLoads, States, gravity};
use super::rooms::Room as Kept;
use super::run_lanes::RunLane;
use super::transpose::scatter_matrix_row;
use super::{
    Blocks, DirectionsBatch, F32x8, Failure, WIDTH, WIDTH_AVX512, WIDTH_F32, block_chains, check_len, one_of,
    simd_kernel,
};
use crate::drive::Drive;
use crate::error::{Error, Result};
use crate::lanes::{Aligned, FlushSubnormals, Lane, Lanes, Lanes32};
use crate::models::directions::state_column;
use crate::rods::{Linearised, Rods, RowsRoom};

/// A task's room for a block of chains in lanes `V`, `C` dimensions: their states in lanes,
/// the kept solve, and the Jacobians' windows and rows.
struct Room<const C: usize, V: Lane> {
    x: Aligned<V>,
    solve: Linearised<C, V>,
    rows: RowsRoom<C, V>,
}

impl<const C: usize, V: Lane> Room<C, V> {
    fn new(n: usize) -> Self {
        let h = C * n;
        Self {
            x: Aligned::filled(V::splat(0.0), 2 * h),
            solve: Linearised::with_len(n),
            rows: RowsRoom::new(n, 2 * h),
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
    /// (the constraint `|u_i| = 1` not imposed), O(n²) a chain. The kept solve and the
    /// Jacobians run in SIMD lanes (four or eight chains, as
    /// [`accelerations`](Self::accelerations)), the blocks over the current rayon pool.
    ///
    /// Returns the chains that failed, in order, with their errors (a non-finite state as
    /// the chain alone names it; a non-finite result as
    /// [`Error::NonFiniteAccelerations`](crate::Error::NonFiniteAccelerations), as in
    /// [`accelerations`](Self::accelerations)); their blocks are NaN. Errors:
    /// [`Error::LengthMismatch`](crate::Error::LengthMismatch) when an array does not hold
    /// `B` rows or blocks.
    pub fn state_jacobians(&self, t: f64, x: &[f64], du: &mut [f64], dw: &mut [f64]) -> Result<Vec<Failure>> {
        self.jacobians_f64(t, States::Joined(x), du, dw)
    }

    /// [`state_jacobians`](Self::state_jacobians) of the states given as two arrays, the
    /// directions `u` and the rates `w`, `B` rows of `S·n` each (as numpy holds `q` and
    /// `qd`): the same numbers; a non-finite state is named by its array, `u` or `w`.
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
        self.jacobians_f64(t, States::Split(u, w), du, dw)
    }

    /// [`state_jacobians`](Self::state_jacobians) in single precision: arrays in `f32`,
    /// eight chains per AVX2 register, each chain's constants rounded to `f32` and its pivot
    /// acceleration computed in `f64` and then rounded. Not bit for bit anything: its error
    /// against the `f64` call is measured in `docs/ensembles.md`.
    ///
    /// Returns the chains that failed, in order: a non-finite state as the `f64` call names
    /// it, otherwise (a number past `f32`'s range) [`Error::SinglePrecisionOverflow`]; their
    /// blocks are NaN. Errors: [`Error::LengthMismatch`] when an array does not hold `B`
    /// rows or blocks.
    pub fn state_jacobians_f32(
        &self,
        t: f64,
        x: &[f32],
        du: &mut [f32],
        dw: &mut [f32],
    ) -> Result<Vec<Failure>> {
        self.jacobians_f32(t, States::Joined(x), du, dw)
    }

    /// [`state_jacobians_f32`](Self::state_jacobians_f32) of the states given as two
    /// arrays, as [`state_jacobians_split`](Self::state_jacobians_split) takes them.
    ///
    /// Errors: [`Error::LengthMismatch`] when an array does not hold `B` rows or blocks.
    pub fn state_jacobians_split_f32(
        &self,
        t: f64,
        u: &[f32],
        w: &[f32],
        du: &mut [f32],
        dw: &mut [f32],
    ) -> Result<Vec<Failure>> {
        self.jacobians_f32(t, States::Split(u, w), du, dw)
    }

    /// Checks that the states hold `B` rows (`2·S·n` joined, `S·n` each apart) and `du`
    /// and `dw` `B` blocks of `(S·n)²`.
    fn check_jacobian_args<T>(&self, x: States<'_, T>, du: &[T], dw: &[T]) -> Result<()> {
        let (chains, half) = (self.len(), S::DIM * self.links());
        match x {
            States::Joined(x) => check_len("x", x, chains, 2 * half)?,
            States::Split(u, w) => {
                check_len("u", u, chains, half)?;
                check_len("w", w, chains, half)?;
            }
        }
        check_len("du", du, chains, half * half)?;
        check_len("dw", dw, chains, half * half)
    }

    /// The checked call in `f64`, in `S` dimensions.
    fn jacobians_f64(
        &self,
        t: f64,
        x: States<'_, f64>,
        du: &mut [f64],
        dw: &mut [f64],
    ) -> Result<Vec<Failure>> {
        self.check_jacobian_args(x, du, dw)?;
        Ok(match S::DIM {
            2 => self.jacobians_in::<2>(t, x, du, dw),
            _ => self.jacobians_in::<3>(t, x, du, dw),
        })
    }

    /// The checked call in `f32`, in `S` dimensions.
    fn jacobians_f32(
        &self,
        t: f64,
        x: States<'_, f32>,
        du: &mut [f32],
        dw: &mut [f32],
    ) -> Result<Vec<Failure>> {
        self.check_jacobian_args(x, du, dw)?;
        Ok(match S::DIM {
            2 => self.jacobians_f32_in::<2>(t, x, du, dw),
            _ => self.jacobians_f32_in::<3>(t, x, du, dw),
        })
    }

    fn jacobians_in<const C: usize>(
        &self,
        t: f64,
        x: States<'_, f64>,
        du: &mut [f64],
        dw: &mut [f64],
    ) -> Vec<Failure> {
        let otherwise = (f64::NAN, Error::NonFiniteAccelerations);
        match &self.blocks {
            Blocks::Four(blocks) => {
                self.jacobian_blocks::<C, WIDTH, _>(x, du, dw, otherwise, |b, chains, room, du, dw| {
                    self.jacobian_block_simd::<C, WIDTH>(one_of(blocks, b), chains, t, x, room, du, dw)
                })
            }
            #[cfg(target_arch = "x86_64")]
            Blocks::Eight(blocks) => {
                self.jacobian_blocks::<C, WIDTH_AVX512, _>(x, du, dw, otherwise, |b, chains, room, du, dw| {
                    // SAFETY: eight-lane blocks exist only where the CPU has AVX-512.
                    unsafe {
                        self.jacobian_block_avx512::<C, WIDTH_AVX512>(
                            one_of(blocks, b),
                            chains,
                            t,
                            x,
                            room,
                            du,
                            dw,
                        )
                    }
                })
            }
            #[cfg(not(target_arch = "x86_64"))]
            Blocks::Never(_) => unreachable!("eight lanes only with AVX-512"),
        }
    }

    fn jacobians_f32_in<const C: usize>(
        &self,
        t: f64,
        x: States<'_, f32>,
        du: &mut [f32],
        dw: &mut [f32],
    ) -> Vec<Failure> {
        let otherwise = (f32::NAN, Error::SinglePrecisionOverflow);
        self.jacobian_blocks::<C, WIDTH_F32, F32x8>(x, du, dw, otherwise, |b, chains, room, du, dw| {
            self.jacobian_block_f32_simd::<C>(b, chains, t, x, room, du, dw)
        })
    }

    /// Runs `kernel(b, chains, room, du, dw)` for every block of `W` chains with its blocks
    /// of `du` and `dw`, and reports each chain with a non-finite state (named by its entry)
    /// or a lane the kernel flags (a result not finite, reported as `otherwise`), its blocks
    /// set to `nan`.
    fn jacobian_blocks<const C: usize, const W: usize, V: RunLane>(
        &self,
        x: States<'_, V::Num>,
        du: &mut [V::Num],
        dw: &mut [V::Num],
        (nan, otherwise): (V::Num, Error),
        kernel: impl Fn(usize, [usize; W], &mut Room<C, V>, &mut [V::Num], &mut [V::Num]) -> [bool; W]
        + Sync
        + Send,
    ) -> Vec<Failure> {
        let (chains, h) = (self.len(), C * self.links());
        let block = h * h;
        let room = || self.rooms.take(|| Room::<C, V>::new(self.links()));
        let one = |room: &mut Kept<'_, Room<C, V>>, b: usize, du: &mut [V::Num], dw: &mut [V::Num]| {
            let lanes = block_chains::<W>(b, chains);
            let flagged = kernel(b, lanes, room, du, dw);
            let blocks = du.chunks_exact_mut(block).zip(dw.chunks_exact_mut(block));
            let mut failures = Vec::new();
            for (k, (du, dw)) in blocks.enumerate() {
                let chain = lanes[k];
                let error = x.non_finite(chain, h).or_else(|| flagged[k].then(|| otherwise.clone()));
                if let Some(error) = error {
                    du.fill(nan);
                    dw.fill(nan);
                    failures.push(Failure { chain, error });
                }
            }
            failures
        };
        in_blocks(du, dw, W * block, room, one)
    }

    simd_kernel! {
        /// [`block_jacobians`] of block `b` of `W` chains (`chains`, constants `block`).
        /// Returns the lanes with an entry not finite.
        fn jacobian_block<const C: usize, const W: usize>(
            &self,
            block: &Block<W>,
            chains: [usize; W],
            t: f64,
            x: States<'_, f64>,
            room: &mut Room<C, Lanes<W>>,
            du: &mut [f64],
            dw: &mut [f64],
        ) -> [bool; W] {
            let pivot = self.pivot_lanes::<C, W, _>(chains, [t; W], Dr::acceleration, Lanes);
            let constants = (self.links(), block.rods(), block.down());
            block_jacobians(constants, pivot, (x, chains), room, (du, dw)).map(|flag| flag != 0)
        }
        dispatch fn jacobian_block_simd, jacobian_block_avx2, avx512 jacobian_block_avx512
    }

    simd_kernel! {
        /// [`block_jacobians`] of the single-precision block `b` (chains `chains`). Returns
        /// the lanes with an entry not finite.
        fn jacobian_block_f32<const C: usize>(
            &self,
            b: usize,
            chains: [usize; WIDTH_F32],
            t: f64,
            x: States<'_, f32>,
            room: &mut Room<C, F32x8>,
            du: &mut [f32],
            dw: &mut [f32],
        ) -> [bool; WIDTH_F32] {
            // `G` decays along a chain into `f32`'s subnormals (`lanes::FlushSubnormals`).
            let _flush = FlushSubnormals::new();
            let (rods, down) = one_of(&self.blocks_f32, b);
            let pivot = self.pivot_lanes::<C, WIDTH_F32, _>(chains, [t; WIDTH_F32], Dr::acceleration, Lanes32::rounded);
            block_jacobians((self.links(), rods, *down), pivot, (x, chains), room, (du, dw)).map(|flag| flag != 0)
        }
        dispatch fn jacobian_block_f32_simd, jacobian_block_f32_avx2
    }
}

/// The Jacobians of one block of `W` chains of `n` links in lanes `V` (constants `rods`,
/// `−g` per lane `down`, pivot accelerations `pivot`) at the states `x` of `chains` into
/// the block's `du` and `dw`: the states gathered into lanes, the kept solve, every
/// column's window, then row by row, each row scattered as it comes. Returns the lanes
/// with an entry not finite.
#[inline(always)]
fn block_jacobians<const C: usize, V: RunLane, const W: usize>(
    (n, rods, down): (usize, &Rods<V>, V),
    pivot: [V; C],
    (x, chains): (States<'_, V::Num>, [usize; W]),
    room: &mut Room<C, V>,
    (du, dw): (&mut [V::Num], &mut [V::Num]),
) -> V::Mask {
    let h = C * n;
    let Room { x: states, solve, rows } = room;
    x.gather(chains, h, V::flatten_mut(states));
    let (directions, rates) = states.split_at(h);
    solve.solve(rods, gravity(down), pivot, RateLoads::new(directions, rates, rods.drag()));
    for b in 0..2 * h {
        solve.keep_column(rods, b, &state_column::<C, _>(b, n, rates, rods.drag()), rows);
    }
    let mut flags = V::none();
    solve.state_rows(rods, rows, |a, row| {
        flags = V::or(flags, V::non_finite(row));
        scatter_matrix_row::<_, W>(V::flatten(&row[..h]), h, a, du);
        scatter_matrix_row::<_, W>(V::flatten(&row[h..]), h, a, dw);
    });
    flags
}

/// Runs `one(scratch, k, a_k, b_k)` for every block `k` of `a` and `b` (`len` numbers each,
/// the last ones shorter), the blocks over the current rayon pool with a `scratch` from
/// `init` per task, and collects the failures in order.
pub(super) fn in_blocks<N: Send, T, F: IntoIterator<Item = Failure> + Send>(
    a: &mut [N],
    b: &mut [N],
    len: usize,
    init: impl Fn() -> T + Sync + Send,
    one: impl Fn(&mut T, usize, &mut [N], &mut [N]) -> F + Sync + Send,
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
