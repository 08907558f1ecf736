//! A batch of planar chains in link angles: [`PlanarTension`]'s accelerations for many
//! chains per call.

use nalgebra::Dyn;

use super::{
    F64x4, Failure, WIDTH, block_chains, check_len, check_links, failed_rows, first_bad_input, for_blocks,
    gather, simd_kernel,
};
use crate::chain::Chain;
use crate::error::{Error, Result};
use crate::kinematics::trig::sin_cos_split;
use crate::lanes::Lanes;
use crate::model::Model;
use crate::models::PlanarTension;
use crate::models::tension::{angle_acceleration, planar_load};
use crate::rods::{Load, Rods, Rows};

/// `B` planar chains with the same number of links `n`, in absolute link angles (rad) as
/// [`PlanarTension`]: each chain's own masses, lengths, damping and gravity, and per call
/// each chain's state and pivot acceleration. No joint torques.
///
/// [`accelerations`](Self::accelerations) gives every chain's `θ̈` equal bit for bit to
/// [`PlanarTension::accelerations`](crate::model::Model::accelerations) of that chain alone
/// (module docs of [`batch`](super)).
#[derive(Debug, Clone)]
pub struct PlanarBatch {
    /// One model per chain, or one for all ([`repeated`](Self::repeated)).
    chains: Vec<PlanarTension<Dyn>>,
    /// Per block of [`WIDTH`] chains, their constants side by side (one block for all when
    /// the chains are one chain repeated).
    blocks: Vec<Block>,
    count: usize,
    links: usize,
}

/// What the solve needs of one block's chains.
#[derive(Debug, Clone)]
struct Block {
    rods: Rods<F64x4>,
    /// `−g` (m/s²) per lane.
    down: F64x4,
}

/// Per task: the block's angles, `sin θ` and `cos θ` in lane order, its rates, and the rows.
struct Scratch {
    angles: Vec<F64x4>,
    sin: Vec<F64x4>,
    cos: Vec<F64x4>,
    rates: Vec<F64x4>,
    loads: Vec<Load<2, F64x4>>,
    rows: Rows<2, F64x4>,
    accelerations: Vec<F64x4>,
}

impl PlanarBatch {
    /// The batch of `chains`, all with the same number of links.
    ///
    /// Errors: [`Error::EmptyBatch`], [`Error::BatchMismatch`] naming the first chain whose
    /// length differs from chain 0's.
    pub fn new(chains: Vec<Chain<Dyn>>) -> Result<Self> {
        let links = check_links(chains.iter().map(Chain::links))?;
        let chains: Vec<_> = chains.into_iter().map(PlanarTension::new).collect();
        let blocks = (0..chains.len().div_ceil(WIDTH))
            .map(|b| {
                let lanes = block_chains(b, chains.len());
                Block {
                    rods: Rods::interleave(lanes.map(|c| chains[c].rods())),
                    down: Lanes(lanes.map(|c| -Model::chain(chains[c].dense()).gravity())),
                }
            })
            .collect();
        Ok(Self { count: chains.len(), chains, blocks, links })
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

    /// Chain `k`'s single-chain model.
    pub fn chain(&self, k: usize) -> &PlanarTension<Dyn> {
        &self.chains[k.min(self.chains.len() - 1)]
    }

    /// The angle accelerations `θ̈` (rad/s²) of every chain, written into `out` as `B` rows of
    /// `n`, at angles `q` (rad) and rates `qd` (rad/s) given the same way, with each chain's
    /// pivot acceleration `p̈ = (ẍ, ÿ)` (m/s²) from `pivot` (`B` rows of 2; `None`: pivots at
    /// rest).
    ///
    /// Returns the chains that failed (a non-finite input or result), in order; their rows of
    /// `out` are NaN. Errors: [`Error::LengthMismatch`] when an array does not hold `B` rows.
    pub fn accelerations(
        &self,
        q: &[f64],
        qd: &[f64],
        pivot: Option<&[f64]>,
        out: &mut [f64],
    ) -> Result<Vec<Failure>> {
        let (chains, n) = (self.len(), self.links);
        check_len("q", q, chains, n)?;
        check_len("qd", qd, chains, n)?;
        check_len("out", out, chains, n)?;
        if let Some(p) = pivot {
            check_len("pivot", p, chains, 2)?;
        }
        let lanes = || vec![Lanes([0.0; WIDTH]); n];
        let scratch = || Scratch {
            angles: lanes(),
            sin: lanes(),
            cos: lanes(),
            rates: lanes(),
            loads: vec![Load::zero(); n],
            rows: Rows::with_len(n),
            accelerations: lanes(),
        };
        let failures = for_blocks(out, n, n, scratch, |scratch, b, out| {
            let lanes = block_chains(b, chains);
            self.block_simd(b, lanes, q, qd, pivot, scratch, out);
            failed_rows(out, n, lanes, f64::NAN, |chain| {
                first_bad_input(chain, n, [q, qd], None, pivot).unwrap_or(Error::NotPositiveDefinite)
            })
        });
        Ok(failures)
    }

    simd_kernel! {
        /// One block: gather, `sin θ` and `cos θ` of all its angles at once, the solve in lanes,
        /// scatter into `out` (the block's rows).
        fn block(
            &self,
            b: usize,
            lanes: [usize; WIDTH],
            q: &[f64],
            qd: &[f64],
            pivot: Option<&[f64]>,
            s: &mut Scratch,
            out: &mut [f64],
        ) {
            let n = self.links;
            let block = &self.blocks[b.min(self.blocks.len() - 1)];
            gather(q, lanes, n, Lanes::flatten_mut(&mut s.angles));
            sin_cos_split(
                Lanes::flatten(&s.angles),
                Lanes::flatten_mut(&mut s.sin),
                Lanes::flatten_mut(&mut s.cos),
            );
            gather(qd, lanes, n, Lanes::flatten_mut(&mut s.rates));
            let zero = Lanes([0.0; WIDTH]);
            let pivot = match pivot {
                Some(p) => [Lanes::from_fn(|k| p[2 * lanes[k]]), Lanes::from_fn(|k| p[2 * lanes[k] + 1])],
                None => [zero; 2],
            };
            // The loads in a pass of their own: built inside the solve, the builder is not
            // inlined (as in the single-chain model).
            let drag = block.rods.drag();
            for (i, load) in s.loads.iter_mut().enumerate() {
                *load = planar_load(s.sin[i], s.cos[i], s.rates[i], -drag[i] * s.rates[i]);
            }
            let loads = &s.loads;
            let load = |i: usize| loads[i];
            let accelerations = &mut s.accelerations;
            block.rods.solve([zero, block.down], pivot, &mut s.rows, load, |i, a, u, _| {
                accelerations[i] = angle_acceleration(a, u);
            });
            for (k, row) in out.chunks_exact_mut(n).enumerate() {
                for (o, a) in row.iter_mut().zip(accelerations.iter()) {
                    *o = a.0[k];
                }
            }
        }
        dispatch fn block_simd, block_avx2
    }
}
