//! A batch of chains in unit link directions ([`Directions`]), planar or spatial, each with
//! its own drive: accelerations, and whole steps of projected RK4, for many chains per call.

use nalgebra::{DefaultAllocator, DimName, Dyn, OVector, allocator::Allocator};

use super::lane_states::{finite_unless_flagged, non_finite_lanes_f32};
use super::transpose::Transpose;
use super::{
    Blocks, F32x8, Failure, Rooms, WIDTH, WIDTH_AVX512, WIDTH_F32, block_chains, check_len, check_links,
    failed_rows, for_blocks_of, gather, non_finite, one_of, scatter, simd_kernel,
};
use crate::chain::Chain;
use crate::drive::{Drive, Fixed};
use crate::energy::ledger::{LEDGER_LEN, direction_powers};
use crate::error::{Error, Result};
use crate::lanes::{Aligned, Lane, Lanes, Lanes32, one_row_at_a_time};
use crate::models::Directions;
use crate::models::directions::rate_load;
use crate::rods::{Load, Loads, Rods, Rows};

/// `B` chains in unit link directions with the same number of links `n`, each with its own
/// masses, lengths, damping, gravity and drive (`S = U2` planar, `U3` spatial).
///
/// [`accelerations`](Self::accelerations) equals [`Directions::accelerations`] chain by
/// chain, and [`step_rk4`](Self::step_rk4) one step of
/// `Projected::new(Rk4::new(..))` ([`Projected`](crate::integrate::Projected),
/// [`Rk4`](crate::integrate::Rk4)) on each chain, bit for bit (module docs of
/// [`batch`](super)). Four chains per AVX2 register, eight per AVX-512 register where the
/// CPU has it ([`with_avx512`](Self::with_avx512)): the same bits either way. A batch keeps
/// its calls' scratch for the next calls (at most one of a kind per thread; about 3.3 kB
/// per link for a 3D RK4 step in eight lanes), so build it once and call it often.
#[derive(Debug, Clone)]
pub struct DirectionsBatch<S: DimName, Dr = Fixed> {
    /// One model per chain, or one for all ([`repeated`](Self::repeated)).
    models: Vec<Directions<S, Dr>>,
    count: usize,
    pub(super) blocks: Blocks<Block, Block<WIDTH_AVX512>>,
    /// Per block of [`WIDTH_F32`] chains, their rods and `−g` in single precision.
    pub(super) blocks_f32: Vec<(Rods<F32x8>, F32x8)>,
    links: usize,
    /// Whether the states carry the energy ledger of [`Accounted`].
    accounted: bool,
    /// The calls' scratch, kept for the next calls.
    pub(super) rooms: Rooms,
}

/// What the solve needs of one block's `W` chains.
#[derive(Debug, Clone)]
pub(super) struct Block<const W: usize = WIDTH> {
    rods: Rods<Lanes<W>>,
    /// `−g` (m/s²) per lane.
    down: Lanes<W>,
    /// Per link, the mass hanging from it (kg), its length (m) and damping `λ` (N·m·s): the
    /// ledger's powers.
    tails: Aligned<Lanes<W>>,
    lengths: Aligned<Lanes<W>>,
    damping: Aligned<Lanes<W>>,
}

impl<const W: usize> Block<W> {
    /// The chains' rods in lanes.
    pub(super) fn rods(&self) -> &Rods<Lanes<W>> {
        &self.rods
    }

    /// `−g` (m/s²) per lane.
    pub(super) fn down(&self) -> Lanes<W> {
        self.down
    }

    /// Per link, the rods' lengths (m) and damping `λ` (N·m·s) in lanes.
    pub(super) fn lengths_and_damping(&self) -> (&[Lanes<W>], &[Lanes<W>]) {
        (&self.lengths, &self.damping)
    }
}

/// Per task: the rows of the solve and, for the steps, the stage vectors in lane order.
pub(super) struct Scratch<const C: usize, const W: usize> {
    pub solve: Solve<C, Lanes<W>>,
    /// Time and its compensation (s) per lane.
    pub t: [Lanes<W>; 2],
    /// The compensation of the state per lane.
    pub carry: Aligned<Lanes<W>>,
    /// Whether every entry of `carry` is `+0.0` (then clearing it writes nothing): kept so
    /// by whatever writes `carry`.
    pub carry_zero: bool,
    pub x: Aligned<Lanes<W>>,
    pub y: Aligned<Lanes<W>>,
    pub k: [Aligned<Lanes<W>>; 4],
}

/// The rows of one solve in lanes (the loads are built where the solve reads them:
/// [`RateLoads`]).
pub(super) struct Solve<const C: usize, V: Lane> {
    rows: Rows<C, V>,
    links: usize,
}

/// The loads of rods at directions `u` and rates `w` (`C` numbers a rod each, rod after rod)
/// with drags `λ_i/l_i` (N·s): [`rate_load`], built where the solve reads it by a method
/// inlined into the kernel (as a closure called from two places it was compiled apart,
/// without the kernel's target features, and a pass of its own into an array was needed).
pub(super) struct RateLoads<'a, const C: usize, V> {
    directions: &'a [V],
    rates: &'a [V],
    drag: &'a [V],
}

impl<'a, const C: usize, V> RateLoads<'a, C, V> {
    /// The loads at directions `u` and rates `w` (`C·n` numbers each) with drags `λ_i/l_i`.
    pub(super) fn new(directions: &'a [V], rates: &'a [V], drag: &'a [V]) -> Self {
        Self { directions, rates, drag }
    }
}

impl<const C: usize, V: Lane> Loads<C, V> for RateLoads<'_, C, V> {
    #[inline(always)]
    fn load(&mut self, i: usize) -> Load<C, V> {
        let u = self.directions[C * i..C * (i + 1)].try_into().expect("C numbers");
        let w = self.rates[C * i..C * (i + 1)].try_into().expect("C numbers");
        rate_load(u, w, self.drag[i])
    }
}

/// A batch's states for one evaluation: `B` rows of `(u, w)` (`2·S·n` each), or the
/// directions `u` and the rates `w` as two arrays of `B` rows of `S·n`.
#[derive(Clone, Copy)]
pub(super) enum States<'a, T> {
    Joined(&'a [T]),
    Split(&'a [T], &'a [T]),
}

impl<T: Transpose + Into<f64>> States<'_, T> {
    /// The states of `chains` into lanes: `out` (flattened) as [`gather`] of the joined
    /// rows, `u` and then `w` (`half = S·n` numbers each).
    #[inline(always)]
    pub(super) fn gather<const W: usize>(self, chains: [usize; W], half: usize, out: &mut [T]) {
        match self {
            States::Joined(x) => gather(x, chains, 2 * half, out),
            States::Split(u, w) => {
                let (out_u, out_w) = out.split_at_mut(W * half);
                gather(u, chains, half, out_u);
                gather(w, chains, half, out_w);
            }
        }
    }

    /// Chain `c`'s first non-finite number, named by its array and index there.
    pub(super) fn non_finite(self, c: usize, half: usize) -> Option<Error> {
        match self {
            States::Joined(x) => non_finite("x", &x[2 * half * c..2 * half * (c + 1)]),
            States::Split(u, w) => {
                let rows = half * c..half * (c + 1);
                non_finite("u", &u[rows.clone()]).or_else(|| non_finite("w", &w[rows]))
            }
        }
    }
}

/// A task's room for one evaluation in lanes: the solve, the block's states, its results.
type Lanes3<const C: usize, V> = (Solve<C, V>, Aligned<V>, Aligned<V>);

impl<const C: usize, V: Lane> Solve<C, V> {
    pub(super) fn new(links: usize) -> Self {
        Self { rows: Rows::with_len(links), links }
    }

    /// The direction accelerations `ü` (1/s²) into `out` (its first `C·n`) of chains with rods `rods`
    /// at directions and rates `x = (u, w)` (`2·C·n`), under gravity `g⃗` and pivot
    /// accelerations `p̈` (m/s²): [`Directions`]' tension solve, in lanes of any precision.
    /// Returns the lanes' sums of the `ü` written ([`finite_unless_flagged`]).
    #[inline(always)]
    pub(super) fn accelerations(
        &mut self,
        rods: &Rods<V>,
        gravity: [V; C],
        pivot: [V; C],
        x: &[V],
        out: &mut [V],
    ) -> V {
        self.solve_loaded(rods, gravity, pivot, self.loads(rods, x), out)
    }

    /// The loads of the states `x = (u, w)` (`2·C·n`) on rods `rods`.
    #[inline(always)]
    fn loads<'a>(&self, rods: &'a Rods<V>, x: &'a [V]) -> RateLoads<'a, C, V> {
        let half = C * self.links;
        RateLoads::new(&x[..half], &x[half..2 * half], rods.drag())
    }

    /// [`accelerations`](Self::accelerations) at a Runge–Kutta stage `y = x + a·k`, formed
    /// in the loads' pass: `y` written whole (`x`, `k` and `y` alike hold a state), its
    /// rates `w` into `out[..C·n]` (the velocities) and its `ü` into `out[C·n..2·C·n]`.
    /// One pass over the stage's numbers instead of three (the sum, the velocities, the
    /// loads): the lanes' states do not fit in the first-level cache.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub(super) fn stage(
        &mut self,
        rods: &Rods<V>,
        gravity: [V; C],
        pivot: [V; C],
        x: &[V],
        a: V,
        k: &[V],
        y: &mut [V],
        out: &mut [V],
    ) {
        let half = C * self.links;
        let (y_motion, y_rest) = y.split_at_mut(2 * half);
        let (yu, yw) = y_motion.split_at_mut(half);
        let (velocities, accelerations) = out[..2 * half].split_at_mut(half);
        let links = (yu.chunks_exact_mut(C).zip(yw.chunks_exact_mut(C)))
            .zip(x[..half].chunks_exact(C).zip(x[half..2 * half].chunks_exact(C)))
            .zip(k[..half].chunks_exact(C).zip(k[half..2 * half].chunks_exact(C)))
            .zip(velocities.chunks_exact_mut(C));
        for ((((yu, yw), (xu, xw)), (ku, kw)), velocity) in links {
            for c in 0..C {
                yu[c] = a * ku[c] + xu[c];
                yw[c] = a * kw[c] + xw[c];
            }
            velocity.copy_from_slice(yw);
            one_row_at_a_time();
        }
        for ((y, x), k) in y_rest.iter_mut().zip(&x[2 * half..]).zip(&k[2 * half..]) {
            *y = a * *k + *x;
            one_row_at_a_time();
        }
        let (directions, rates) = (&y[..half], &y[half..2 * half]);
        self.solve_loaded(
            rods,
            gravity,
            pivot,
            RateLoads { directions, rates, drag: rods.drag() },
            accelerations,
        );
    }

    /// The rod tensions `T_i` (N) into `out` (`n`) of the solve
    /// [`accelerations`](Self::accelerations) does.
    #[inline(always)]
    pub(super) fn tensions(
        &mut self,
        rods: &Rods<V>,
        gravity: [V; C],
        pivot: [V; C],
        x: &[V],
        out: &mut [V],
    ) {
        let loads = self.loads(rods, x);
        rods.solve(gravity, pivot, &mut self.rows, loads, |i, _, _, t| out[i] = t);
    }

    /// The tension solve of `loads`: `ü` into `out` (`C·n`). Returns the lanes' sums of
    /// the `ü` written, one sum per component (its own serial chain) added at the end (no
    /// work where the caller drops it).
    #[inline(always)]
    fn solve_loaded(
        &mut self,
        rods: &Rods<V>,
        gravity: [V; C],
        pivot: [V; C],
        loads: RateLoads<'_, C, V>,
        out: &mut [V],
    ) -> V {
        let mut sums = [V::splat(0.0); C];
        rods.solve(gravity, pivot, &mut self.rows, loads, |i, a, _, _| {
            out[i * C..(i + 1) * C].copy_from_slice(&a);
            for (sum, a) in sums.iter_mut().zip(a) {
                *sum += a;
            }
        });
        sums.into_iter().fold(V::splat(0.0), |total, sum| total + sum)
    }
}

impl<const C: usize, const W: usize> Scratch<C, W> {
    pub fn new(links: usize, state_len: usize) -> Self {
        let lanes = || Aligned::filled(Lanes([0.0; W]), state_len);
        Self {
            solve: Solve::new(links),
            t: [Lanes([0.0; W]); 2],
            carry: lanes(),
            carry_zero: true,
            x: lanes(),
            y: lanes(),
            k: [lanes(), lanes(), lanes(), lanes()],
        }
    }
}

impl<S: DimName, Dr: Drive<S> + Sync> DirectionsBatch<S, Dr>
where
    DefaultAllocator: Allocator<S>,
{
    /// The batch of `models`, all with the same number of links.
    ///
    /// Errors: [`Error::EmptyBatch`], [`Error::BatchMismatch`] naming the first model whose
    /// length differs from model 0's, [`Error::LengthMismatch`] for a space other than 2 or
    /// 3 dimensions.
    pub fn new(models: Vec<Directions<S, Dr>>) -> Result<Self> {
        if !(2..=3).contains(&S::DIM) {
            return Err(Error::LengthMismatch { what: "space", expected: 3, got: S::DIM });
        }
        let links = check_links(models.iter().map(Directions::links))?;
        let blocks_f32 = (0..models.len().div_ceil(WIDTH_F32))
            .map(|b| {
                let lanes = block_chains::<WIDTH_F32>(b, models.len());
                let down = Lanes32::rounded(lanes.map(|c| -models[c].chain().gravity()));
                (Rods::interleave_f32(lanes.map(|c| models[c].rods())), down)
            })
            .collect();
        let blocks = Blocks::new(true, || f64_blocks(&models, links), || f64_blocks(&models, links));
        let count = models.len();
        Ok(Self { models, count, blocks, blocks_f32, links, accounted: false, rooms: Rooms::default() })
    }

    /// `count` copies of `model`, its drive included: one chain at `count` states per call.
    /// The lanes' constants are built once, for one block, whatever `count`.
    ///
    /// Errors: [`Error::EmptyBatch`] for no copies; those of [`new`](Self::new).
    pub fn repeated(model: Directions<S, Dr>, count: usize) -> Result<Self> {
        if count == 0 {
            return Err(Error::EmptyBatch);
        }
        Ok(Self { count, ..Self::new(vec![model])? })
    }

    /// Whether the `f64` calls may run eight chains per AVX-512 register where the CPU has
    /// AVX-512 (the default), or keep four per AVX2 register (`false`). The results are the
    /// same bits either way; the choice is speed (`docs/ensembles.md`: eight lanes are as
    /// fast or faster in every case measured; four are there to compare, and for tests).
    pub fn with_avx512(mut self, allowed: bool) -> Self {
        if allowed != self.uses_avx512() {
            let (models, links) = (&self.models, self.links);
            self.blocks = Blocks::new(allowed, || f64_blocks(models, links), || f64_blocks(models, links));
            // The kept scratch is in the other width's lanes: no call would take it again.
            self.rooms = Rooms::default();
        }
        self
    }

    /// Whether the `f64` calls run eight lanes (AVX-512).
    pub fn uses_avx512(&self) -> bool {
        self.blocks.eight()
    }

    /// The batch of `models` with their energy ledgers: states as
    /// [`Accounted::state`](crate::energy::Accounted) gives them (`(u, w)` then the ledger's
    /// drive work, torque work and damping loss, J), and
    /// [`step_rk4`](Self::step_rk4) / [`integrate_rk4`](Self::integrate_rk4) equal bit for bit to
    /// `Projected<Rk4>` on [`Accounted`](crate::energy::Accounted)`<Directions>`.
    /// [`accelerations`](Self::accelerations) is unchanged (the motion alone).
    ///
    /// Errors: those of [`new`](Self::new).
    pub fn accounted(models: Vec<Directions<S, Dr>>) -> Result<Self> {
        Ok(Self { accounted: true, ..Self::new(models)? })
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
    pub fn model(&self, k: usize) -> &Directions<S, Dr> {
        assert!(k < self.count, "chain {k} of a batch of {}", self.count);
        one_of(&self.models, k)
    }

    /// Whether the states carry the energy ledger ([`accounted`](Self::accounted)).
    pub fn is_accounted(&self) -> bool {
        self.accounted
    }

    /// Entries of one chain's state: `2·S·n`, and the ledger's 3 when
    /// [`accounted`](Self::accounted).
    pub fn state_len(&self) -> usize {
        2 * S::DIM * self.links + if self.accounted { LEDGER_LEN } else { 0 }
    }

    /// The direction accelerations `ü` (1/s²) of every chain at time `t` (s), written into
    /// `out` as `B` rows of `S·n`, at the states `x = (u, w)` given as `B` rows of `2·S·n`.
    ///
    /// Returns the chains that failed (a non-finite state or result), in order; their rows
    /// of `out` are NaN. Errors: [`Error::LengthMismatch`] when an array does not hold `B`
    /// rows.
    pub fn accelerations(&self, t: f64, x: &[f64], out: &mut [f64]) -> Result<Vec<Failure>> {
        self.check_rows(x, out)?;
        Ok(self.accelerations_of(t, States::Joined(x), out))
    }

    /// [`accelerations`](Self::accelerations) of the states given as two arrays, the
    /// directions `u` and the rates `w`, `B` rows of `S·n` each (as numpy holds `q` and
    /// `qd`): the same numbers, without joining them first.
    ///
    /// Errors: [`Error::LengthMismatch`] when an array does not hold `B` rows.
    pub fn accelerations_split(&self, t: f64, u: &[f64], w: &[f64], out: &mut [f64]) -> Result<Vec<Failure>> {
        self.check_split(u, w, out)?;
        Ok(self.accelerations_of(t, States::Split(u, w), out))
    }

    /// Checks that `u`, `w` and `out` hold `B` rows of `S·n`.
    fn check_split<T>(&self, u: &[T], w: &[T], out: &[T]) -> Result<()> {
        let (chains, half) = (self.len(), S::DIM * self.links);
        check_len("u", u, chains, half)?;
        check_len("w", w, chains, half)?;
        check_len("out", out, chains, half)
    }

    fn accelerations_of(&self, t: f64, x: States<'_, f64>, out: &mut [f64]) -> Vec<Failure> {
        match S::DIM {
            2 => self.accelerations_in::<2>(t, x, out),
            _ => self.accelerations_in::<3>(t, x, out),
        }
    }

    /// Checks that `x` holds `B` states of `(u, w)` (`2·S·n` each) and `out` `B` rows of `S·n`.
    fn check_rows<T>(&self, x: &[T], out: &[T]) -> Result<()> {
        let (chains, half) = (self.len(), S::DIM * self.links);
        check_len("x", x, chains, 2 * half)?;
        check_len("out", out, chains, half)
    }

    fn accelerations_in<const C: usize>(&self, t: f64, x: States<'_, f64>, out: &mut [f64]) -> Vec<Failure> {
        let otherwise = (f64::NAN, Error::NonFiniteAccelerations);
        match &self.blocks {
            Blocks::Four(blocks) => {
                self.in_blocks::<C, WIDTH, _, _>(x, out, otherwise, |b, chains, s, out| {
                    self.evaluate_simd::<C, WIDTH>(one_of(blocks, b), chains, t, x, s, out)
                })
            }
            #[cfg(target_arch = "x86_64")]
            Blocks::Eight(blocks) => {
                self.in_blocks::<C, WIDTH_AVX512, _, _>(x, out, otherwise, |b, chains, s, out| {
                    // SAFETY: eight-lane blocks exist only where the CPU has AVX-512.
                    unsafe {
                        self.evaluate_avx512::<C, WIDTH_AVX512>(one_of(blocks, b), chains, t, x, s, out)
                    }
                })
            }
            #[cfg(not(target_arch = "x86_64"))]
            Blocks::Never(_) => unreachable!("eight lanes only with AVX-512"),
        }
    }

    /// Runs `kernel(b, chains, lanes, rows)` for every block of `W` chains (`lanes`: the
    /// solve's rows and the block's states and results in lanes `V`, one set per task; no
    /// room for RK4's stages, a call that allocated them faulted in fresh pages every time)
    /// and reports the chains whose rows of `out` are not finite, their rows set to `nan`: a
    /// non-finite state by its entry, otherwise with `otherwise`.
    fn in_blocks<const C: usize, const W: usize, T, V>(
        &self,
        x: States<'_, T>,
        out: &mut [T],
        (nan, otherwise): (T, Error),
        kernel: impl Fn(usize, [usize; W], &mut Lanes3<C, V>, &mut [T]) -> [bool; W] + Sync + Send,
    ) -> Vec<Failure>
    where
        T: Transpose + Into<f64> + Send + Sync,
        V: Lane + Send,
    {
        let (chains, n) = (self.len(), self.links);
        let (half, m) = (C * n, 2 * C * n);
        let lanes = |len: usize| Aligned::filled(V::splat(0.0), len);
        for_blocks_of::<W, _, _, _>(
            out,
            half,
            n,
            || self.rooms.take(|| (Solve::<C, V>::new(n), lanes(m), lanes(half))),
            |s, b, out| {
                let ids = block_chains::<W>(b, chains);
                let suspect = kernel(b, ids, s, out);
                failed_rows(out, half, (ids, suspect), nan, |chain| {
                    x.non_finite(chain, half).unwrap_or_else(|| otherwise.clone())
                })
            },
        )
    }

    /// [`accelerations`](Self::accelerations) in single precision: states and results in
    /// `f32`, the solve on eight chains per AVX2 register, each chain's constants rounded to
    /// `f32` and its pivot acceleration computed in `f64` and then rounded. Not bit for bit
    /// anything: its error against the `f64` call is measured in `docs/ensembles.md`.
    ///
    /// Returns the chains that failed, in order: a non-finite state as the `f64` call names
    /// it, otherwise [`Error::SinglePrecisionOverflow`]; their rows of `out` are NaN. Errors:
    /// [`Error::LengthMismatch`] when an array does not hold `B` rows.
    pub fn accelerations_f32(&self, t: f64, x: &[f32], out: &mut [f32]) -> Result<Vec<Failure>> {
        self.check_rows(x, out)?;
        Ok(self.accelerations_f32_of(t, States::Joined(x), out))
    }

    /// [`accelerations_f32`](Self::accelerations_f32) of the states given as two arrays,
    /// as [`accelerations_split`](Self::accelerations_split) takes them.
    ///
    /// Errors: [`Error::LengthMismatch`] when an array does not hold `B` rows.
    pub fn accelerations_split_f32(
        &self,
        t: f64,
        u: &[f32],
        w: &[f32],
        out: &mut [f32],
    ) -> Result<Vec<Failure>> {
        self.check_split(u, w, out)?;
        Ok(self.accelerations_f32_of(t, States::Split(u, w), out))
    }

    fn accelerations_f32_of(&self, t: f64, x: States<'_, f32>, out: &mut [f32]) -> Vec<Failure> {
        match S::DIM {
            2 => self.accelerations_f32_in::<2>(t, x, out),
            _ => self.accelerations_f32_in::<3>(t, x, out),
        }
    }

    fn accelerations_f32_in<const C: usize>(
        &self,
        t: f64,
        x: States<'_, f32>,
        out: &mut [f32],
    ) -> Vec<Failure> {
        self.in_blocks::<C, WIDTH_F32, _, F32x8>(
            x,
            out,
            (f32::NAN, Error::SinglePrecisionOverflow),
            |b, chains, s, out| self.flow_f32_simd::<C>(b, chains, t, x, s, out),
        )
    }

    /// `of(drive, t_k)` (the pivot's acceleration or velocity) of each lane's chain, as
    /// numbers of a lane type made by `lanes`.
    #[inline(always)]
    pub(super) fn pivot_lanes<const C: usize, const W: usize, V>(
        &self,
        chains: [usize; W],
        t: [f64; W],
        of: impl Fn(&Dr, f64) -> OVector<f64, S>,
        lanes: impl Fn([f64; W]) -> V,
    ) -> [V; C] {
        let each: [_; W] = std::array::from_fn(|k| of(one_of(&self.models, chains[k]).drive(), t[k]));
        std::array::from_fn(|c| lanes(std::array::from_fn(|k| each[k][c])))
    }

    simd_kernel! {
        /// `ü(t, x)` for the single-precision block `b` (chains `chains`) into its rows of
        /// `out`: gathered into the lanes `x_lanes`, the solve, into `a_lanes`, scattered.
        /// Returns the lanes with a result not finite.
        fn flow_f32<const C: usize>(
            &self,
            b: usize,
            chains: [usize; WIDTH_F32],
            t: f64,
            x: States<'_, f32>,
            s: &mut Lanes3<C, F32x8>,
            out: &mut [f32],
        ) -> [bool; WIDTH_F32] {
            let (solve, x_lanes, a_lanes) = s;
            let (rods, down) = one_of(&self.blocks_f32, b);
            let half = C * self.links;
            x.gather(chains, half, Lanes32::flatten_mut(x_lanes));
            let pivot = self.pivot_lanes::<C, WIDTH_F32, _>(chains, [t; WIDTH_F32], Dr::acceleration, Lanes32::rounded);
            solve.accelerations(rods, gravity(*down), pivot, x_lanes, a_lanes);
            scatter::<_, WIDTH_F32>(Lanes32::flatten(a_lanes), half, out);
            non_finite_lanes_f32(a_lanes).map(|flag| flag != 0)
        }
        dispatch fn flow_f32_simd, flow_f32_avx2
    }

    simd_kernel! {
        /// `ü(t, x)` for a block (chains `chains`, constants `block`) into its rows of
        /// `out`: gathered into `x_lanes`, the solve, into `a_lanes`, scattered. Returns the
        /// lanes with a result not finite.
        fn evaluate<const C: usize, const W: usize>(
            &self,
            block: &Block<W>,
            chains: [usize; W],
            t: f64,
            x: States<'_, f64>,
            s: &mut Lanes3<C, Lanes<W>>,
            out: &mut [f64],
        ) -> [bool; W] {
            let (solve, x_lanes, a_lanes) = s;
            let half = C * self.links;
            x.gather(chains, half, Lanes::flatten_mut(x_lanes));
            let pivot = self.pivot_lanes::<C, W, _>(chains, [t; W], Dr::acceleration, Lanes);
            let sum = solve.accelerations(&block.rods, gravity(block.down), pivot, x_lanes, a_lanes);
            scatter::<_, W>(Lanes::flatten(a_lanes), half, out);
            finite_unless_flagged(sum, a_lanes).map(|flag| flag != 0)
        }
        dispatch fn evaluate_simd, evaluate_avx2, avx512 evaluate_avx512
    }

    /// Each lane's pivot acceleration `p̈` (m/s²) at its time `t[k]`, and with `velocity`
    /// its velocity `ṗ` (m/s) too, from one evaluation of the drive
    /// ([`Drive::velocity_and_acceleration`]).
    #[inline(always)]
    pub(super) fn pivot_motion<const C: usize, const W: usize>(
        &self,
        chains: [usize; W],
        t: [f64; W],
        velocity: bool,
    ) -> ([Lanes<W>; C], Option<[Lanes<W>; C]>) {
        if !velocity {
            return (self.pivot_lanes::<C, W, _>(chains, t, Dr::acceleration, Lanes), None);
        }
        let motion: [_; W] =
            std::array::from_fn(|k| one_of(&self.models, chains[k]).drive().velocity_and_acceleration(t[k]));
        let velocity = std::array::from_fn(|c| Lanes(std::array::from_fn(|k| motion[k].0[c])));
        let acceleration = std::array::from_fn(|c| Lanes(std::array::from_fn(|k| motion[k].1[c])));
        (acceleration, Some(velocity))
    }

    /// `out = (w, ü(t, x))` for the block's chains in lanes: [`Directions`]' right-hand side,
    /// one tension solve, with each chain's pivot acceleration `pivot` (m/s², at its own
    /// time).
    #[inline(always)]
    pub(super) fn flow<const C: usize, const W: usize>(
        &self,
        block: &Block<W>,
        pivot: [Lanes<W>; C],
        x: &[Lanes<W>],
        solve: &mut Solve<C, Lanes<W>>,
        out: &mut [Lanes<W>],
    ) {
        let half = C * self.links;
        let (velocity, acceleration) = out.split_at_mut(half);
        velocity.copy_from_slice(&x[half..2 * half]);
        solve.accelerations(&block.rods, gravity(block.down), pivot, x, acceleration);
    }

    /// [`flow`](Self::flow) at the Runge–Kutta stage `y = x + a·k`, written into `y` as it
    /// goes ([`Solve::stage`]).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub(super) fn stage<const C: usize, const W: usize>(
        &self,
        block: &Block<W>,
        pivot: [Lanes<W>; C],
        (x, a, k): (&[Lanes<W>], Lanes<W>, &[Lanes<W>]),
        y: &mut [Lanes<W>],
        solve: &mut Solve<C, Lanes<W>>,
        out: &mut [Lanes<W>],
    ) {
        solve.stage(&block.rods, gravity(block.down), pivot, x, a, k, y, out);
    }

    /// The ledger's rates `(P_drive, 0, P_damping)` (W) into `out[2·S·n..]` after [`flow`](Self::flow)
    /// filled `out` at the same `(t, x)` with the pivot accelerations `pivot` (m/s²), the
    /// pivots moving at `velocity` (m/s): as `Accounted`'s right-hand side gives them.
    #[inline(always)]
    pub(super) fn ledger_rates<const C: usize, const W: usize>(
        &self,
        block: &Block<W>,
        x: &[Lanes<W>],
        (velocity, pivot): ([Lanes<W>; C], [Lanes<W>; C]),
        out: &mut [Lanes<W>],
    ) {
        let half = C * self.links;
        let chain = (&block.tails[..], &block.lengths[..], &block.damping[..], -block.down);
        let (rates, accelerations) = (&x[half..2 * half], &out[half..2 * half]);
        let (drive, damping) = direction_powers(chain, velocity, pivot, rates, accelerations);
        out[2 * half..2 * half + LEDGER_LEN].copy_from_slice(&[drive, Lanes([0.0; W]), damping]);
    }
}

/// The constants of `models` (`links` each) in blocks of `W`, side by side.
fn f64_blocks<S: DimName, Dr, const W: usize>(models: &[Directions<S, Dr>], links: usize) -> Vec<Block<W>>
where
    DefaultAllocator: Allocator<S>,
{
    (0..models.len().div_ceil(W))
        .map(|b| {
            let lanes = block_chains::<W>(b, models.len());
            let per_link = |of: fn(&Chain<Dyn>) -> &[f64]| -> Aligned<Lanes<W>> {
                (0..links).map(|i| Lanes::from_fn(|k| of(models[lanes[k]].chain())[i])).collect()
            };
            Block {
                rods: Rods::interleave(lanes.map(|c| models[c].rods())),
                down: Lanes(lanes.map(|c| -models[c].chain().gravity())),
                tails: per_link(|c| c.tail_masses().as_slice()),
                lengths: per_link(|c| c.lengths().as_slice()),
                damping: per_link(|c| c.damping().as_slice()),
            }
        })
        .collect()
}

/// Gravity `g⃗ = −g e_up` (m/s²) per lane, from `−g`: along the last axis.
#[inline(always)]
pub(super) fn gravity<const C: usize, V: Lane>(down: V) -> [V; C] {
    let mut g = [V::splat(0.0); C];
    g[C - 1] = down;
    g
}
