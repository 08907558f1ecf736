//! A batch of chains in unit link directions ([`Directions`]), planar or spatial, each with
//! its own drive: accelerations, and whole steps of projected RK4, for many chains per call.

use nalgebra::{DefaultAllocator, DimName, Dyn, allocator::Allocator};

use super::{
    F64x4, Failure, WIDTH, block_chains, check_len, check_links, for_blocks, gather, non_finite, simd_kernel,
};
use crate::chain::Chain;
use crate::drive::{Drive, Fixed};
use crate::energy::ledger::{LEDGER_LEN, direction_powers};
use crate::error::{Error, Result};
use crate::lanes::Lanes;
use crate::models::Directions;
use crate::models::directions::rate_load;
use crate::rods::{Load, Rods, Rows};

/// `B` chains in unit link directions with the same number of links `n`, each with its own
/// masses, lengths, damping, gravity and drive (`S = U2` planar, `U3` spatial).
///
/// [`accelerations`](Self::accelerations) equals [`Directions::accelerations`] chain by
/// chain, and [`step_rk4`](Self::step_rk4) one step of
/// `Projected::new(Rk4::new(..))` ([`Projected`](crate::integrate::Projected),
/// [`Rk4`](crate::integrate::Rk4)) on each chain, bit for bit (module docs of
/// [`batch`](super)).
#[derive(Debug, Clone)]
pub struct DirectionsBatch<S: DimName, Dr = Fixed> {
    models: Vec<Directions<S, Dr>>,
    blocks: Vec<Block>,
    links: usize,
    /// Whether the states carry the energy ledger of [`Accounted`].
    accounted: bool,
}

/// What the solve needs of one block's chains.
#[derive(Debug, Clone)]
struct Block {
    rods: Rods<F64x4>,
    /// `−g` (m/s²) per lane.
    down: F64x4,
    /// Per link, the mass hanging from it (kg), its length (m) and damping `λ` (N·m·s): the
    /// ledger's powers.
    tails: Vec<F64x4>,
    lengths: Vec<F64x4>,
    damping: Vec<F64x4>,
}

/// Per task: the rows of the solve and, for the steps, the stage vectors in lane order.
pub(super) struct Scratch<const C: usize> {
    pub solve: Solve<C>,
    /// Time and its compensation (s) per lane.
    pub t: [F64x4; 2],
    /// The compensation of the state per lane.
    pub carry: Vec<F64x4>,
    pub x: Vec<F64x4>,
    pub y: Vec<F64x4>,
    pub k: [Vec<F64x4>; 4],
}

/// The loads and rows of one solve in lanes.
pub(super) struct Solve<const C: usize> {
    rows: Rows<C, F64x4>,
    loads: Vec<Load<C, F64x4>>,
}

impl<const C: usize> Scratch<C> {
    pub fn new(links: usize, state_len: usize) -> Self {
        let lanes = || vec![Lanes([0.0; WIDTH]); state_len];
        Self {
            solve: Solve { rows: Rows::with_len(links), loads: vec![Load::zero(); links] },
            t: [Lanes([0.0; WIDTH]); 2],
            carry: lanes(),
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
        let blocks = (0..models.len().div_ceil(WIDTH))
            .map(|b| {
                let lanes = block_chains(b, models.len());
                let per_link = |of: fn(&Chain<Dyn>) -> &[f64]| -> Vec<F64x4> {
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
            .collect();
        Ok(Self { models, blocks, links, accounted: false })
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
        self.models.len()
    }

    /// Never: a batch has at least one chain.
    pub fn is_empty(&self) -> bool {
        self.models.is_empty()
    }

    /// Links per chain `n`.
    pub fn links(&self) -> usize {
        self.links
    }

    /// Chain `k`'s single-chain model.
    pub fn model(&self, k: usize) -> &Directions<S, Dr> {
        &self.models[k]
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
        let (chains, half) = (self.len(), S::DIM * self.links);
        check_len("x", x, chains, 2 * half)?;
        check_len("out", out, chains, half)?;
        Ok(match S::DIM {
            2 => self.accelerations_in::<2>(t, x, out),
            _ => self.accelerations_in::<3>(t, x, out),
        })
    }

    fn accelerations_in<const C: usize>(&self, t: f64, x: &[f64], out: &mut [f64]) -> Vec<Failure> {
        let (chains, n) = (self.len(), self.links);
        let (half, m) = (C * n, 2 * C * n);
        for_blocks(
            out,
            half,
            n,
            || Scratch::<C>::new(n, self.state_len()),
            |s, b, out| {
                let lanes = block_chains(b, chains);
                gather(x, lanes, m, &mut s.x);
                let [k1, ..] = &mut s.k;
                self.flow_simd::<C>(b, lanes, [t; WIDTH], &s.x, &mut s.solve, k1);
                let mut failures = Vec::new();
                for (k, row) in out.chunks_exact_mut(half).enumerate() {
                    for (i, v) in row.iter_mut().enumerate() {
                        *v = s.k[0][half + i].0[k];
                    }
                    if !row.iter().all(|v| v.is_finite()) {
                        let chain = lanes[k];
                        let error = non_finite("x", &x[chain * m..(chain + 1) * m])
                            .unwrap_or(Error::NotPositiveDefinite);
                        row.fill(f64::NAN);
                        failures.push(Failure { chain, error });
                    }
                }
                failures
            },
        )
    }

    simd_kernel! {
        /// `out = (w, ü(t, x))` for the block's chains in lanes: [`Directions`]' right-hand side,
        /// one tension solve, with each chain's pivot acceleration at its own time.
        pub(super) fn flow<const C: usize>(
            &self,
            b: usize,
            chains: [usize; WIDTH],
            t: [f64; WIDTH],
            x: &[F64x4],
            solve: &mut Solve<C>,
            out: &mut [F64x4],
        ) -> [F64x4; C] {
            let half = C * self.links;
            let block = &self.blocks[b];
            let zero = Lanes([0.0; WIDTH]);
            let pivots: [_; WIDTH] = std::array::from_fn(|k| self.models[chains[k]].drive().acceleration(t[k]));
            let pivot: [F64x4; C] = std::array::from_fn(|c| Lanes::from_fn(|k| pivots[k][c]));
            let mut gravity = [zero; C];
            gravity[C - 1] = block.down;
            let (directions, rates) = (&x[..half], &x[half..2 * half]);
            let (velocity, acceleration) = out.split_at_mut(half);
            velocity.copy_from_slice(rates);
            // The loads in a pass of their own: built inside the solve, the builder is not
            // inlined.
            let drag = block.rods.drag();
            for (i, load) in solve.loads.iter_mut().enumerate() {
                let at = |v: &[F64x4]| -> [F64x4; C] { std::array::from_fn(|c| v[i * C + c]) };
                *load = rate_load(at(directions), at(rates), drag[i]);
            }
            let loads = &solve.loads;
            let load = |i: usize| loads[i];
            block.rods.solve(gravity, pivot, &mut solve.rows, load, |i, a, _, _| {
                acceleration[i * C..(i + 1) * C].copy_from_slice(&a);
            });
            pivot
        }
        dispatch pub(super) fn flow_simd, flow_avx2
    }

    /// The ledger's rates `(P_drive, 0, P_damping)` (W) into `out[2·S·n..]` after [`flow`](Self::flow)
    /// filled `out` at the same `(t, x)` with the pivot accelerations `pivot` (m/s²) it
    /// returned: as `Accounted`'s right-hand side gives them.
    #[inline(always)]
    pub(super) fn ledger_rates<const C: usize>(
        &self,
        b: usize,
        chains: [usize; WIDTH],
        t: [f64; WIDTH],
        x: &[F64x4],
        pivot: [F64x4; C],
        out: &mut [F64x4],
    ) {
        let half = C * self.links;
        let block = &self.blocks[b];
        let velocities: [_; WIDTH] = std::array::from_fn(|k| self.models[chains[k]].drive().velocity(t[k]));
        let velocity: [F64x4; C] = std::array::from_fn(|c| Lanes::from_fn(|k| velocities[k][c]));
        let chain = (&block.tails[..], &block.lengths[..], &block.damping[..], -block.down);
        let (rates, accelerations) = (&x[half..2 * half], &out[half..2 * half]);
        let (drive, damping) = direction_powers(chain, velocity, pivot, rates, accelerations);
        out[2 * half..2 * half + LEDGER_LEN].copy_from_slice(&[drive, Lanes([0.0; WIDTH]), damping]);
    }
}
