//! Many chains per call: `B` chains with the same number of links, each with its own
//! masses, lengths, damping, gravity, drive and state, evaluated and stepped together.
//!
//! A single chain's tension solve is a serial recurrence down the chain and back up it;
//! across chains the recurrences are independent. The batch therefore runs the one solve
//! of the [`rods`](crate::rods) module on [`Lanes`] of [`WIDTH`] chains: every number of the
//! solve is `WIDTH` numbers, one per chain, and each operation one SIMD instruction (AVX2,
//! detected at run time like the sine kernel's; a portable loop otherwise). Blocks of
//! `WIDTH` chains go to the cores through rayon (the current pool: wrap a call in
//! `ThreadPool::install` to choose the threads).
//! [`UnrolledBatch`] and [`UnrolledSpatialBatch`] do the same for the straight-line
//! kernels `model!` generates for planar and spatial chains of a fixed number of links.
//!
//! **Bit for bit.** A lane does the same IEEE operations in the same order as the
//! single-chain call (no fused multiply-add, the same sine kernel), so every chain of a
//! batch gets exactly the single-chain result, whatever the thread count and however the
//! chains are split into calls. The tests check it.
//!
//! **Failures stay in their chain.** A chain with a non-finite input, or whose result is
//! not finite, is reported by its index ([`Failure`]) and does not stop the others; its
//! rows of the output are NaN (accelerations) or its state is left as it was (steps).
//!
//! Layout: arrays are chain-major, `(B, m)` row after row as numpy stores a `(B, m)` array.
//! Each block is gathered into lane order (`m` rows of `WIDTH`) and scattered back, in
//! transposed tiles (`transpose`). A run ([`DirectionsBatch::integrate_rk4`],
//! [`DirectionsBatch::run_rk4`], [`PlanarBatch::integrate_rk4`]) keeps its states in lanes
//! from the first step to the last and gains most (`docs/ensembles.md`).

use nalgebra::Dyn;
use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::integrate::State;
use crate::lanes::{Lanes, Lanes32};

mod directions;
mod jacobians;
mod lane_states;
mod planar;
mod planar_jacobians;
mod planar_rk4;
mod rk4;
mod rk4_f32;
mod rod_midpoint;
mod rod_midpoint_f32;
mod rooms;
mod run;
mod run_lanes;
pub(crate) mod transpose;
mod unrolled;

pub(crate) use crate::model::{all_finite, non_finite};
pub use directions::DirectionsBatch;
pub use planar::PlanarBatch;
pub(crate) use rooms::Rooms;
pub(crate) use transpose::{gather, scatter};
pub use unrolled::{
    Generated, LinkConstants, PlanarKernel, SpatialKernel, UnrolledBatch, UnrolledSpatialBatch,
};

/// Chains per block: four `f64` lanes, one AVX2 register.
pub const WIDTH: usize = 4;

/// Chains per block in single precision: eight `f32` lanes, one AVX2 register.
pub const WIDTH_F32: usize = 8;

/// Chains per block of the `f64` planar and direction batches on a CPU with AVX-512: eight
/// `f64` lanes, one AVX-512 register.
pub const WIDTH_AVX512: usize = 8;

/// Four chains' numbers, one per lane.
pub(crate) type F64x4 = Lanes<WIDTH>;

/// Eight chains' numbers, one per lane: one AVX-512 register.
pub(crate) type F64x8 = Lanes<WIDTH_AVX512>;

/// Eight chains' numbers in single precision, one per lane: one AVX2 register.
pub(crate) type F32x8 = Lanes32<WIDTH_F32>;

/// A batch's `f64` constants in lanes, block by block: blocks of [`WIDTH`] chains (`Four`,
/// AVX2) or, on a CPU with AVX-512, of [`WIDTH_AVX512`] (`Eight`). One or the other: the
/// lanes a call runs in follow from which.
#[derive(Debug, Clone)]
pub(crate) enum Blocks<Four, Eight> {
    Four(Vec<Four>),
    #[cfg(target_arch = "x86_64")]
    Eight(Vec<Eight>),
    /// Other targets have no eight-lane kernels: this keeps `Eight` a parameter there.
    #[cfg(not(target_arch = "x86_64"))]
    #[allow(dead_code)]
    Never(std::marker::PhantomData<Eight>),
}

impl<Four, Eight> Blocks<Four, Eight> {
    /// Eight lanes where `eight_allowed` and the CPU has AVX-512 (`eight()` builds them),
    /// else four (`four()`).
    pub(crate) fn new(
        eight_allowed: bool,
        four: impl FnOnce() -> Vec<Four>,
        eight: impl FnOnce() -> Vec<Eight>,
    ) -> Self {
        #[cfg(target_arch = "x86_64")]
        if eight_allowed && crate::lanes::has_avx512() {
            return Self::Eight(eight());
        }
        let _ = (eight_allowed, eight);
        Self::Four(four())
    }

    /// Whether the blocks are of eight lanes.
    pub(crate) fn eight(&self) -> bool {
        !matches!(self, Self::Four(_))
    }
}

/// A chain of a batch that failed, and why; the other chains finished.
#[derive(Debug, Clone, PartialEq)]
pub struct Failure {
    /// The chain's 0-based index in the batch.
    pub chain: usize,
    /// What went wrong, as the single-chain call would say it.
    pub error: Error,
}

impl std::fmt::Display for Failure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "chain {}: {}", self.chain, self.error)
    }
}

/// Checks that the batch has chains and that chain `k` has as many links as chain 0:
/// `links` gives each chain's.
pub(crate) fn check_links(links: impl ExactSizeIterator<Item = usize>) -> Result<usize> {
    let mut expected = None;
    for (chain, n) in links.enumerate() {
        match expected {
            None => expected = Some(n),
            Some(e) if e != n => return Err(Error::BatchMismatch { chain, links: n, expected: e }),
            Some(_) => {}
        }
    }
    expected.ok_or(Error::EmptyBatch)
}

/// Checks that there is one state per chain, each of `m` entries.
pub(crate) fn check_states(states: &[State<Dyn>], chains: usize, m: usize) -> Result<()> {
    if states.len() != chains {
        return Err(Error::LengthMismatch { what: "states", expected: chains, got: states.len() });
    }
    match states.iter().find(|s| s.x().len() != m) {
        Some(s) => Err(Error::LengthMismatch { what: "x", expected: m, got: s.x().len() }),
        None => Ok(()),
    }
}

/// Checks that a run's held inputs hold `chains` rows: the torques (`None`: none) of `m`,
/// the pivot accelerations (`None`: at rest) of `space`.
pub(crate) fn check_held<T>(
    (torque, pivot): (Option<&[T]>, Option<&[T]>),
    chains: usize,
    [m, space]: [usize; 2],
) -> Result<()> {
    if let Some(t) = torque {
        check_len("torque", t, chains, m)?;
    }
    pivot.map_or(Ok(()), |p| check_len("pivot", p, chains, space))
}

/// [`Error::NonFinite`] naming `t0` unless a run's start time `t0` (s) is finite.
pub(crate) fn check_t0(t0: f64) -> Result<()> {
    if t0.is_finite() { Ok(()) } else { Err(Error::NonFinite { what: "t0", index: 0, value: t0 }) }
}

/// Checks that `v` holds `chains` rows of `per_chain` numbers.
pub(crate) fn check_len<T>(what: &'static str, v: &[T], chains: usize, per_chain: usize) -> Result<()> {
    if v.len() == chains * per_chain {
        Ok(())
    } else {
        Err(Error::LengthMismatch { what, expected: chains * per_chain, got: v.len() })
    }
}

/// Item `k` of a batch's per-chain or per-block `items`, or the one item of a batch of one
/// chain repeated (`repeated`: one model and one block of constants for all). Out of range
/// otherwise, it panics as indexing does (no silent clamping).
#[inline(always)]
pub(crate) fn one_of<T>(items: &[T], k: usize) -> &T {
    if items.len() == 1 { &items[0] } else { &items[k] }
}

/// The chains of block `b` of a batch of `chains`, in blocks of `W`: lane `k` holds chain
/// `W·b + k`, and the lanes past the last chain repeat it (their results are dropped).
pub(crate) fn block_chains<const W: usize>(b: usize, chains: usize) -> [usize; W] {
    std::array::from_fn(|k| (W * b + k).min(chains - 1))
}

/// The first non-finite input of chain `chain` as the single-chain check names it: its row
/// of `n` in `q`, `qd` and `torque`, then its row of `space` (2 or 3) in `pivot`.
pub(crate) fn first_bad_input<T: Copy + Into<f64>>(
    chain: usize,
    [n, space]: [usize; 2],
    [q, qd]: [&[T]; 2],
    torque: Option<&[T]>,
    pivot: Option<&[T]>,
) -> Option<Error> {
    let row = |what, v: &[T], m: usize| non_finite(what, &v[chain * m..(chain + 1) * m]);
    row("q", q, n)
        .or_else(|| row("qd", qd, n))
        .or_else(|| torque.and_then(|t| row("torque", t, n)))
        .or_else(|| pivot.and_then(|p| row("pivot_acceleration", p, space)))
}

/// The chains of a block whose rows of `out` (`m` each, row `k` for chain `chains[k]`) are
/// not all finite, each with `error(chain)`; their rows set to `nan`. Only the rows of the
/// lanes flagged in `suspect` are read: the kernels find the lanes with a non-finite result
/// in lanes, where it costs a sum per row of lanes (scanning every row of a short block's
/// result here was a seventh of a call).
pub(crate) fn failed_rows<T: Copy + Into<f64>, const W: usize>(
    out: &mut [T],
    m: usize,
    (chains, suspect): ([usize; W], [bool; W]),
    nan: T,
    error: impl Fn(usize) -> Error,
) -> Vec<Failure> {
    let mut failures = Vec::new();
    for (k, row) in out.chunks_exact_mut(m).enumerate().filter(|(k, _)| suspect[*k]) {
        if !all_finite(row) {
            row.fill(nan);
            failures.push(Failure { chain: chains[k], error: error(chains[k]) });
        }
    }
    failures
}

/// Blocks of `width` chains a rayon task takes at least, for blocks of `solves` rods'
/// solves each: about 2000 rods' solves a task, so that short work does not drown in
/// scheduling.
pub(crate) fn blocks_per_task(width: usize, solves: usize) -> usize {
    (2048 / (width * solves).max(1)).max(1)
}

/// Runs `block(scratch, b, rows)` for every block `b` of `out` (`W` rows of `m` numbers
/// each, the last one shorter) across the current rayon pool, with a `scratch` from `init`
/// per task, and collects the failures (or what `block` reports) in block order.
/// `solves`: rods' solves per chain of a block (links × evaluations), for the task size.
pub(crate) fn for_blocks_of<const W: usize, T: Send, S, F: Send>(
    out: &mut [T],
    m: usize,
    solves: usize,
    init: impl Fn() -> S + Sync + Send,
    block: impl Fn(&mut S, usize, &mut [T]) -> Vec<F> + Sync + Send,
) -> Vec<F> {
    let per_task = blocks_per_task(W, solves);
    if out.len() <= per_task * W * m || rayon::current_num_threads() == 1 {
        // One task's work, or one thread: no handing over to the pool (a thread's wake-up
        // costs more than a short batch).
        // A plain loop: a `flat_map` over the blocks cost 6–9% of a short block's time.
        let mut scratch = init();
        let mut failures = Vec::new();
        for (b, rows) in out.chunks_mut(W * m).enumerate() {
            failures.extend(block(&mut scratch, b, rows));
        }
        return failures;
    }
    out.par_chunks_mut(W * m)
        .enumerate()
        .with_min_len(per_task)
        .map_init(init, |scratch, (b, rows)| block(scratch, b, rows))
        .flat_map_iter(|failures| failures)
        .collect()
}

/// A kernel written once, in three methods (with at most one generic parameter, a const
/// or a type, or two consts): `fn kernel(&self, args…)` as given (inlined wherever it is called),
/// `fn avx2(&self, args…)`, the kernel compiled for AVX2 (it must be
/// `#[inline(always)]` all the way down for its lanes to become registers), and
/// `fn dispatch(&self, args…)`, which runs the AVX2 one when the CPU has AVX2 and the
/// kernel as it is otherwise; optionally `fn avx512(&self, args…)`, the kernel compiled for
/// AVX-512, for the caller to run (unsafely) where the CPU has it:
/// ```text
/// simd_kernel! {
///     /// docs
///     fn kernel<const C: usize>(&self, a: A, …) -> R { … }
///     dispatch pub(super) fn dispatch, avx2, avx512 avx512
/// }
/// ```
macro_rules! simd_kernel {
    // One generic parameter at most, a const or a type, or two consts: normalised, then
    // emitted.
    (
        $(#[$meta:meta])*
        $vis:vis fn $kernel:ident <const $c:ident: usize, const $w:ident: usize> $($rest:tt)*
    ) => {
        $crate::batch::simd_kernel!(
            @emit [const $c: usize, const $w: usize] [$c, $w] $(#[$meta])* $vis fn $kernel $($rest)*
        );
    };
    (
        $(#[$meta:meta])*
        $vis:vis fn $kernel:ident <const $c:ident: usize> $($rest:tt)*
    ) => {
        $crate::batch::simd_kernel!(@emit [const $c: usize] [$c] $(#[$meta])* $vis fn $kernel $($rest)*);
    };
    (
        $(#[$meta:meta])*
        $vis:vis fn $kernel:ident <$t:ident: $bound:path> $($rest:tt)*
    ) => {
        $crate::batch::simd_kernel!(@emit [$t: $bound] [$t] $(#[$meta])* $vis fn $kernel $($rest)*);
    };
    (
        $(#[$meta:meta])*
        $vis:vis fn $kernel:ident ($($args:tt)*) $($rest:tt)*
    ) => {
        $crate::batch::simd_kernel!(@emit [] [] $(#[$meta])* $vis fn $kernel ($($args)*) $($rest)*);
    };
    (
        @emit [$($decl:tt)*] [$($name:tt)*]
        $(#[$meta:meta])*
        $vis:vis fn $kernel:ident (&$this:ident, $($arg:ident: $ty:ty),* $(,)?) $(-> $ret:ty)?
        $body:block
        dispatch $dvis:vis fn $dispatch:ident, $avx2:ident, avx512 $avx512:ident
    ) => {
        $crate::batch::simd_kernel!(
            @emit [$($decl)*] [$($name)*] $(#[$meta])*
            $vis fn $kernel (&$this, $($arg: $ty),*) $(-> $ret)? $body
            dispatch $dvis fn $dispatch, $avx2
        );

        /// [`Self::$kernel`] compiled for AVX-512 (foundation): only for a CPU that has it.
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx512f")]
        #[allow(clippy::too_many_arguments)]
        fn $avx512 <$($decl)*> (&$this, $($arg: $ty),*) $(-> $ret)? {
            $this.$kernel::<$($name)*>($($arg),*)
        }
    };
    (
        @emit [$($decl:tt)*] [$($name:tt)*]
        $(#[$meta:meta])*
        $vis:vis fn $kernel:ident (&$this:ident, $($arg:ident: $ty:ty),* $(,)?) $(-> $ret:ty)?
        $body:block
        dispatch $dvis:vis fn $dispatch:ident, $avx2:ident
    ) => {
        $(#[$meta])*
        #[inline(always)]
        #[allow(clippy::too_many_arguments)]
        $vis fn $kernel <$($decl)*> (&$this, $($arg: $ty),*) $(-> $ret)? $body

        /// [`Self::$kernel`] with AVX2 when the CPU has it.
        #[allow(clippy::too_many_arguments)]
        $dvis fn $dispatch <$($decl)*> (&$this, $($arg: $ty),*) $(-> $ret)? {
            #[cfg(target_arch = "x86_64")]
            if $crate::lanes::has_avx2() {
                // SAFETY: the CPU has AVX2, checked just above.
                return unsafe { $this.$avx2::<$($name)*>($($arg),*) };
            }
            $this.$kernel::<$($name)*>($($arg),*)
        }

        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2")]
        #[allow(clippy::too_many_arguments)]
        fn $avx2 <$($decl)*> (&$this, $($arg: $ty),*) $(-> $ret)? {
            $this.$kernel::<$($name)*>($($arg),*)
        }
    };
}
pub(crate) use simd_kernel;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_batch_must_have_chains_of_one_length() {
        assert_eq!(check_links([3, 3, 3].into_iter()), Ok(3));
        assert_eq!(
            check_links([3, 3, 4].into_iter()),
            Err(Error::BatchMismatch { chain: 2, links: 4, expected: 3 })
        );
        assert_eq!(check_links(std::iter::empty::<usize>()), Err(Error::EmptyBatch));
        assert_eq!(
            Error::BatchMismatch { chain: 2, links: 4, expected: 3 }.to_string(),
            "chain 2 of the batch has 4 links, chain 0 has 3"
        );
    }

    #[test]
    fn the_last_block_repeats_the_last_chain() {
        assert_eq!(block_chains::<4>(0, 6), [0, 1, 2, 3]);
        assert_eq!(block_chains(1, 6), [4, 5, 5, 5]);
        assert_eq!(block_chains(0, 1), [0, 0, 0, 0]);
    }
}
