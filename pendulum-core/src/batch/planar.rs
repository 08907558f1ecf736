//! A batch of planar chains in link angles: [`PlanarTension`]'s accelerations for many
//! chains per call.

use nalgebra::Dyn;

use super::lane_states::{non_finite_lanes, non_finite_lanes_f32};
use super::run_lanes::RunLane;
use super::transpose::Transpose;
use super::{
    Blocks, F32x8, F64x4, F64x8, Failure, Rooms, WIDTH, WIDTH_F32, block_chains, check_len, check_links,
    failed_rows, first_bad_input, for_blocks_of, gather, one_of, scatter, simd_kernel,
};
use crate::chain::Chain;
use crate::error::{Error, Result};
use crate::lanes::{Aligned, Lane, Lanes, Lanes32};
use crate::model::Model;
use crate::models::PlanarTension;
use crate::models::tension::{angle_acceleration, planar_load};
use crate::rods::{Load, Loads, RodConstants, Rods, Rows, damping_pull, pull};

/// `B` planar chains with the same number of links `n`, in absolute link angles (rad) as
/// [`PlanarTension`]: each chain's own masses, lengths, damping and gravity, and per call
/// each chain's state, joint torques and pivot acceleration.
///
/// [`accelerations`](Self::accelerations) gives every chain's `θ̈` equal bit for bit to
/// [`PlanarTension::accelerations`](crate::model::Model::accelerations) of that chain alone
/// (module docs of [`batch`](super)), and [`integrate_rk4`](Self::integrate_rk4) its RK4
/// steps. Four chains per AVX2 register, eight per AVX-512 register where the CPU has it
/// ([`with_avx512`](Self::with_avx512)): the same bits either way. A batch keeps its calls'
/// scratch for the next calls (at most one of a kind per thread; about 0.8 kB per link for
/// the accelerations in eight lanes), so build it once and call it often.
#[derive(Debug, Clone)]
pub struct PlanarBatch {
    /// One model per chain, or one for all ([`repeated`](Self::repeated)).
    chains: Vec<PlanarTension<Dyn>>,
    /// Per block of [`WIDTH`] chains, their constants side by side (one block for all when
    /// the chains are one chain repeated).
    pub(super) blocks: Blocks<Block, Block<F64x8>>,
    /// The same in single precision, per block of [`WIDTH_F32`] chains.
    pub(super) blocks_f32: Vec<Block<F32x8>>,
    count: usize,
    pub(super) links: usize,
    /// The calls' scratch, kept for the next calls.
    pub(super) rooms: Rooms,
}

/// What the solve needs of one block's chains, in lanes `V`.
#[derive(Debug, Clone)]
pub(super) struct Block<V: Lane = F64x4> {
    rods: Rods<V>,
    /// `−g` (m/s²) per lane.
    down: V,
}

/// A block's states in lane order: the angles, `sin θ` and `cos θ`, the rates and the
/// joint torques.
pub(super) struct BlockStates<V: Lane> {
    pub angles: Aligned<V>,
    pub sin: Aligned<V>,
    pub cos: Aligned<V>,
    pub rates: Aligned<V>,
    pub torque: Aligned<V>,
}

impl<V: Lane> BlockStates<V> {
    pub(super) fn new(links: usize) -> Self {
        let lanes = || Aligned::filled(V::splat(0.0), links);
        Self { angles: lanes(), sin: lanes(), cos: lanes(), rates: lanes(), torque: lanes() }
    }
}

impl<V: RunLane> BlockStates<V> {
    /// `θ` and `θ̇` of the chains `lanes` (rows of `n` of `q` and `qd`; `W` is `V`'s
    /// width) in lane order, and `sin θ`, `cos θ` of all of them at once by `V`'s sine
    /// kernel; returns their pivot accelerations (rows of 2 of `pivot`; `None`: zero).
    #[inline(always)]
    pub(super) fn gather<const W: usize>(
        &mut self,
        [q, qd]: [&[V::Num]; 2],
        pivot: Option<&[V::Num]>,
        lanes: [usize; W],
        n: usize,
    ) -> [V; 2] {
        gather(q, lanes, n, V::flatten_mut(&mut self.angles));
        V::sin_cos(&self.angles, &mut self.sin, &mut self.cos);
        gather(qd, lanes, n, V::flatten_mut(&mut self.rates));
        match pivot {
            Some(p) => [V::from_nums(|k| p[2 * lanes[k]]), V::from_nums(|k| p[2 * lanes[k] + 1])],
            None => [V::splat(0.0); 2],
        }
    }
}

/// Per task: the block's states in lane order, the solve's room and the accelerations.
struct Scratch<V: Lane = F64x4> {
    states: BlockStates<V>,
    work: Work<V>,
    accelerations: Aligned<V>,
}

impl<V: Lane> Scratch<V> {
    fn new(links: usize) -> Self {
        let accelerations = Aligned::filled(V::splat(0.0), links);
        Self { states: BlockStates::new(links), work: Work::new(links), accelerations }
    }
}

/// The solve's room: the rows its down pass leaves for its up pass.
pub(super) struct Work<V: Lane> {
    rows: Rows<2, V>,
}

impl<V: Lane> Work<V> {
    pub(super) fn new(links: usize) -> Self {
        Self { rows: Rows::with_len(links) }
    }
}

/// A block's joint torques `Q_i` (N·m, lane order) and the lanes that have any: the others'
/// torques are not read.
pub(super) type Torques<'a, V> = (&'a [V], <V as Lane>::Mask);

impl<V: Lane> Block<V> {
    /// The block's chains' constants, and gravity `g` (m/s²) per lane.
    #[inline(always)]
    pub(super) fn constants(&self) -> (RodConstants<'_, V>, V) {
        (self.rods.constants(), -self.down)
    }

    /// `θ̈` (rad/s²) of the block's chains into `out`, from `[sin θ, cos θ, θ̇ (rad/s)]`, the
    /// joint torques and the pivot accelerations `pivot` (m/s²): [`PlanarTension`]'s
    /// tension solve, in lanes of any precision. The pull on rod `i` is
    /// `Q_i/l_i − λ_i θ̇_i/l_i` in a lane with torques and `−λ_i θ̇_i/l_i` in the others, as
    /// the model forms it for a chain with torques and one without.
    #[inline(always)]
    pub(super) fn accelerations(
        &self,
        [sin, cos, rates]: [&[V]; 3],
        (torque, torqued): Torques<'_, V>,
        pivot: [V; 2],
        work: &mut Work<V>,
        out: &mut [V],
    ) {
        // The loads are built where the solve reads them, by types whose methods are
        // inlined into the kernel: as closures (called from two places) they were compiled
        // apart, without the kernel's target features, and a pass of their own into an
        // array was the way out; this is 1.1–1.2× faster than that pass.
        let untorqued = Untorqued { sin, cos, rates, drag: self.rods.drag() };
        let gravity = [V::splat(0.0), self.down];
        let emit = |i: usize, a, u: &[V; 2], _| out[i] = angle_acceleration(a, u);
        if V::any(torqued) {
            let inverse_length = self.rods.inverse_length();
            let loads = Torqued { untorqued, torque, inverse_length, torqued };
            self.rods.solve(gravity, pivot, &mut work.rows, loads, emit);
        } else {
            self.rods.solve(gravity, pivot, &mut work.rows, untorqued, emit);
        }
    }
}

/// The loads of chains without joint torques: the pull on rod `i` is `−λ_i θ̇_i/l_i`.
struct Untorqued<'a, V> {
    sin: &'a [V],
    cos: &'a [V],
    rates: &'a [V],
    /// `λ_i/l_i` (N·s).
    drag: &'a [V],
}

impl<V: Lane> Loads<2, V> for Untorqued<'_, V> {
    #[inline(always)]
    fn load(&mut self, i: usize) -> Load<2, V> {
        planar_load(self.sin[i], self.cos[i], self.rates[i], damping_pull(self.drag[i], self.rates[i]))
    }
}

/// The loads of a block with joint torques `Q_i` (N·m) in the lanes `torqued`: the pull on
/// rod `i` is `Q_i/l_i − λ_i θ̇_i/l_i` there and `−λ_i θ̇_i/l_i` in the others, as the model
/// forms it for a chain with torques and one without.
struct Torqued<'a, V: Lane> {
    untorqued: Untorqued<'a, V>,
    torque: &'a [V],
    /// `1/l_i` (1/m).
    inverse_length: &'a [V],
    torqued: V::Mask,
}

impl<V: Lane> Loads<2, V> for Torqued<'_, V> {
    #[inline(always)]
    fn load(&mut self, i: usize) -> Load<2, V> {
        let Untorqued { sin, cos, rates, drag } = self.untorqued;
        let torqued_pull = pull(self.torque[i], self.inverse_length[i], drag[i], rates[i]);
        let pull = V::select(self.torqued, torqued_pull, damping_pull(drag[i], rates[i]));
        planar_load(sin[i], cos[i], rates[i], pull)
    }
}

impl PlanarBatch {
    /// The batch of `chains`, all with the same number of links.
    ///
    /// Errors: [`Error::EmptyBatch`], [`Error::BatchMismatch`] naming the first chain whose
    /// length differs from chain 0's.
    pub fn new(chains: Vec<Chain<Dyn>>) -> Result<Self> {
        let links = check_links(chains.iter().map(Chain::links))?;
        let chains: Vec<_> = chains.into_iter().map(PlanarTension::new).collect();
        let blocks = Blocks::new(true, || f64_blocks(&chains), || f64_blocks(&chains));
        let blocks_f32 = (0..chains.len().div_ceil(WIDTH_F32))
            .map(|b| {
                let lanes = block_chains::<WIDTH_F32>(b, chains.len());
                Block {
                    rods: Rods::interleave_f32(lanes.map(|c| chains[c].rods())),
                    down: Lanes32::rounded(lanes.map(|c| -Model::chain(chains[c].dense()).gravity())),
                }
            })
            .collect();
        Ok(Self { count: chains.len(), chains, blocks, blocks_f32, links, rooms: Rooms::default() })
    }

    /// Whether the `f64` calls may run eight chains per AVX-512 register where the CPU has
    /// AVX-512 (the default), or keep four per AVX2 register (`false`). The results are the
    /// same bits either way; the choice is speed (`docs/ensembles.md`: eight lanes are as
    /// fast or faster in every case measured; four are there to compare, and for tests).
    pub fn with_avx512(mut self, allowed: bool) -> Self {
        if allowed != self.uses_avx512() {
            self.blocks = Blocks::new(allowed, || f64_blocks(&self.chains), || f64_blocks(&self.chains));
            // The kept scratch is in the other width's lanes: no call would take it again.
            self.rooms = Rooms::default();
        }
        self
    }

    /// Whether the `f64` calls run eight lanes (AVX-512).
    pub fn uses_avx512(&self) -> bool {
        self.blocks.eight()
    }

    /// `count` copies of `chain`: one model at `count` states per call. The lanes' constants
    /// are built once, for one block, whatever `count`.
    ///
    /// Errors: [`Error::EmptyBatch`] for no copies.
    pub fn repeated(chain: Chain<Dyn>, count: usize) -> Result<Self> {
        if count == 0 {
            return Err(Error::EmptyBatch);
        }
        let mut one = Self::new(vec![chain])?;
        one.count = count;
        Ok(one)
    }

    /// Number of chains `B`.
    pub fn len(&self) -> usize {
        self.count
    }

    /// Never: a batch has at least one chain.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// Links per chain `n`.
    pub fn links(&self) -> usize {
        self.links
    }

    /// Chain `k`'s single-chain model. Panics for `k ≥ B`.
    pub fn chain(&self, k: usize) -> &PlanarTension<Dyn> {
        assert!(k < self.count, "chain {k} of a batch of {}", self.count);
        one_of(&self.chains, k)
    }

    /// The angle accelerations `θ̈` (rad/s²) of every chain, written into `out` as `B` rows of
    /// `n`, at angles `q` (rad) and rates `qd` (rad/s) given the same way, with each chain's
    /// joint torques `Q_i` (N·m) from `torque` (`B` rows of `n`; `None`: none) and pivot
    /// acceleration `p̈ = (ẍ, ÿ)` (m/s²) from `pivot` (`B` rows of 2; `None`: pivots at
    /// rest).
    ///
    /// Returns the chains that failed (a non-finite input or result), in order; their rows of
    /// `out` are NaN. Errors: [`Error::LengthMismatch`] when an array does not hold `B` rows.
    pub fn accelerations(
        &self,
        q: &[f64],
        qd: &[f64],
        torque: Option<&[f64]>,
        pivot: Option<&[f64]>,
        out: &mut [f64],
    ) -> Result<Vec<Failure>> {
        self.check_rows(q, qd, pivot, out)?;
        if let Some(torque) = torque {
            check_len("torque", torque, self.len(), self.links)?;
        }
        let otherwise = (f64::NAN, Error::NonFiniteAccelerations);
        Ok(match &self.blocks {
            Blocks::Four(blocks) => {
                self.in_blocks([q, qd], torque, pivot, out, otherwise, |b, lanes, s, out| {
                    self.block_simd::<WIDTH>(blocks, b, lanes, q, qd, torque, pivot, s, out)
                })
            }
            #[cfg(target_arch = "x86_64")]
            Blocks::Eight(blocks) => {
                self.in_blocks([q, qd], torque, pivot, out, otherwise, |b, lanes, s, out| {
                    // SAFETY: eight-lane blocks exist only where the CPU has AVX-512.
                    unsafe { self.block_avx512(blocks, b, lanes, q, qd, torque, pivot, s, out) }
                })
            }
            #[cfg(not(target_arch = "x86_64"))]
            Blocks::Never(_) => unreachable!("eight lanes only with AVX-512"),
        })
    }

    /// [`accelerations`](Self::accelerations) in single precision, joint torques (`None`:
    /// none) and pivot accelerations as it takes them: arrays in `f32`, eight chains per
    /// AVX2 register, each chain's constants rounded to `f32`, the sines from the
    /// single-precision kernel (Cephes' `sinf`). Not bit for bit anything: its error against
    /// the `f64` call is measured in `docs/ensembles.md`.
    ///
    /// Returns the chains that failed, in order: a non-finite input as the `f64` call names
    /// it, otherwise [`Error::SinglePrecisionOverflow`]; their rows of `out` are NaN.
    /// Errors: [`Error::LengthMismatch`] when an array does not hold `B` rows.
    pub fn accelerations_f32(
        &self,
        q: &[f32],
        qd: &[f32],
        torque: Option<&[f32]>,
        pivot: Option<&[f32]>,
        out: &mut [f32],
    ) -> Result<Vec<Failure>> {
        self.check_rows(q, qd, pivot, out)?;
        if let Some(torque) = torque {
            check_len("torque", torque, self.len(), self.links)?;
        }
        Ok(self.in_blocks(
            [q, qd],
            torque,
            pivot,
            out,
            (f32::NAN, Error::SinglePrecisionOverflow),
            |b, lanes, s, out| self.block_f32_simd(b, lanes, q, qd, torque, pivot, s, out),
        ))
    }

    /// Runs `kernel(b, chains, scratch, rows)` for every block of `W` chains (a scratch in
    /// lanes `V` per task) and reports the chains whose rows of `out` are not finite, their
    /// rows set to `nan`: a non-finite input by its entry, otherwise with `otherwise`.
    fn in_blocks<const W: usize, T, V>(
        &self,
        [q, qd]: [&[T]; 2],
        torque: Option<&[T]>,
        pivot: Option<&[T]>,
        out: &mut [T],
        (nan, otherwise): (T, Error),
        kernel: impl Fn(usize, [usize; W], &mut Scratch<V>, &mut [T]) -> [bool; W] + Sync + Send,
    ) -> Vec<Failure>
    where
        T: Copy + Into<f64> + Send + Sync,
        V: Lane + Send,
    {
        let (chains, n) = (self.len(), self.links);
        for_blocks_of::<W, _, _, _>(
            out,
            n,
            n,
            || self.rooms.take(|| Scratch::new(n)),
            |scratch, b, out| {
                let lanes = block_chains::<W>(b, chains);
                let suspect = kernel(b, lanes, scratch, out);
                failed_rows(out, n, (lanes, suspect), nan, |chain| {
                    first_bad_input(chain, [n, 2], [q, qd], torque, pivot)
                        .unwrap_or_else(|| otherwise.clone())
                })
            },
        )
    }

    /// Checks that `q`, `qd` and `out` hold `B` rows of `n` and `pivot` `B` rows of 2.
    fn check_rows<T>(&self, q: &[T], qd: &[T], pivot: Option<&[T]>, out: &[T]) -> Result<()> {
        let (chains, n) = (self.len(), self.links);
        check_len("q", q, chains, n)?;
        check_len("qd", qd, chains, n)?;
        check_len("out", out, chains, n)?;
        pivot.map_or(Ok(()), |p| check_len("pivot", p, chains, 2))
    }

    simd_kernel! {
        /// [`block`](Self::block) in single precision, eight chains.
        fn block_f32(
            &self,
            b: usize,
            lanes: [usize; WIDTH_F32],
            q: &[f32],
            qd: &[f32],
            torque: Option<&[f32]>,
            pivot: Option<&[f32]>,
            s: &mut Scratch<F32x8>,
            out: &mut [f32],
        ) -> [bool; WIDTH_F32] {
            let (n, t) = (self.links, &mut s.states);
            let block = one_of(&self.blocks_f32, b);
            let torqued = match torque {
                Some(torque) => gather_torques(torque, lanes, n, Lanes32::flatten_mut(&mut t.torque)).map(u32::from),
                None => F32x8::none(),
            };
            let pivot = t.gather([q, qd], pivot, lanes, n);
            let trig = [&t.sin[..], &t.cos, &t.rates];
            block.accelerations(trig, (&t.torque, torqued), pivot, &mut s.work, &mut s.accelerations);
            scatter::<_, WIDTH_F32>(Lanes32::flatten(&s.accelerations), n, out);
            non_finite_lanes_f32(&s.accelerations).map(|flag| flag != 0)
        }
        dispatch fn block_f32_simd, block_f32_avx2
    }

    simd_kernel! {
        /// One block of `W` chains (constants in `blocks`): gather, `sin θ` and `cos θ` of all
        /// its angles at once, the solve in lanes, scatter into `out` (the block's rows).
        /// Returns the lanes with a result not finite.
        fn block<const W: usize>(
            &self,
            blocks: &[Block<Lanes<W>>],
            b: usize,
            lanes: [usize; W],
            q: &[f64],
            qd: &[f64],
            torque: Option<&[f64]>,
            pivot: Option<&[f64]>,
            s: &mut Scratch<Lanes<W>>,
            out: &mut [f64],
        ) -> [bool; W] {
            let n = self.links;
            let block = one_of(blocks, b);
            let t = &mut s.states;
            let torqued = torque.map_or(Lanes::<W>::none(), |torque| {
                gather_torques(torque, lanes, n, Lanes::flatten_mut(&mut t.torque)).map(u64::from)
            });
            let pivot = t.gather([q, qd], pivot, lanes, n);
            let trig = [&t.sin[..], &t.cos, &t.rates];
            block.accelerations(trig, (&t.torque, torqued), pivot, &mut s.work, &mut s.accelerations);
            scatter::<_, W>(Lanes::flatten(&s.accelerations), n, out);
            non_finite_lanes(&s.accelerations).map(|flag| flag != 0)
        }
        dispatch fn block_simd, block_avx2, avx512 block_avx512
    }
}

/// The constants of `chains` in blocks of `W`, side by side.
fn f64_blocks<const W: usize>(chains: &[PlanarTension<Dyn>]) -> Vec<Block<Lanes<W>>> {
    (0..chains.len().div_ceil(W))
        .map(|b| {
            let lanes = block_chains::<W>(b, chains.len());
            Block {
                rods: Rods::interleave(lanes.map(|c| chains[c].rods())),
                down: Lanes(lanes.map(|c| -Model::chain(chains[c].dense()).gravity())),
            }
        })
        .collect()
}

/// The joint torques of the chains `lanes` (rows of `n` of `torque`) into lane order in
/// `out` (flattened lanes), and which of them has a non-zero torque.
#[inline(always)]
pub(super) fn gather_torques<T: Transpose + Into<f64>, const W: usize>(
    torque: &[T],
    lanes: [usize; W],
    n: usize,
    out: &mut [T],
) -> [bool; W] {
    gather(torque, lanes, n, out);
    // As the model decides per chain: any non-zero torque (no early exit, so it vectorises).
    lanes.map(|c| !torque[c * n..(c + 1) * n].iter().fold(true, |zero, &x| zero & (x.into() == 0.0)))
}
