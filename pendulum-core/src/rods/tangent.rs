//! The tangent of the tension solve: how the direction accelerations `ü_i` change along a
//! change of the rods' loads (`δu_i`, `δ|u̇_i|²`, `δF_i`) and of the pivot acceleration
//! `δp̈`, in O(n) per direction.
//!
//! Differentiating the solve of the parent module (`A T = b`, then
//! `a_i = a°_i + (T_{i+1} u_{i+1} − T_i u_i)/m_i`, `ü_i = (a_i − a_{i−1})/l_i`):
//! ```text
//! δa°_i = (δF_i − δF_{i+1})/m_i                      (δa°_0 = δp̈)
//! δb_i  = l_i δ|u̇_i|² + δu_i·(a°_i − a°_{i−1}) + u_i·(δa°_i − δa°_{i−1})
//! δA_ii = 2 (1/m_i + 1/m_{i−1}) u_i·δu_i,   δA_{i,i−1} = −(δu_{i−1}·u_i + u_{i−1}·δu_i)/m_{i−1}
//! A δT  = δb − δA T                                   (the same A: its factors are kept)
//! δa_i  = δa°_i + (δT_{i+1} u_{i+1} + T_{i+1} δu_{i+1} − δT_i u_i − T_i δu_i)/m_i
//! δü_i  = (δa_i − δa_{i−1})/l_i
//! ```
//! The primal pass ([`Linearised::solve`], also in lanes of chains) is Gaussian elimination
//! (`D_i = A_ii − f_i A_{i,i−1}`, `f_i = A_{i,i−1}/D_{i−1}`, the pivots as ratios of
//! continuants like the solve's, the classical way should one leave its range), keeping
//! per rod what the tangents need; each [`Linearised::tangent`] is then one down and one up
//! pass over the load changes in its rows, allocation-free.

// The per-component loops read and write several `[V; S]` at one index, like the solve's.
#![allow(clippy::needless_range_loop)]

use super::{Continuants, Load, Loads, Rods, dot, entries};
use crate::lanes::{Aligned, Lane};

/// The change of one rod's [`Load`] along a direction (in lanes `V`, of `W` chains).
#[derive(Debug, Clone, Copy)]
pub(crate) struct LoadTangent<const S: usize, V: Lane = f64> {
    /// `δu_i`.
    pub direction: [V; S],
    /// `δ|u̇_i|²` (1/s²).
    pub rate_squared: V,
    /// `δF_i` (N).
    pub pair: [V; S],
}

/// One rod of a solve kept for its tangents.
#[derive(Debug, Clone, Copy)]
struct Kept<const S: usize, V: Lane> {
    load: Load<S, V>,
    /// `a°_i`.
    free: [V; S],
    /// `b_i`, kept for [`Linearised::eliminate_by_pivots`].
    rhs: V,
    /// `f_i = A_{i,i−1}/D_{i−1}` and `1/D_i`.
    factor: V,
    inverse_pivot: V,
    /// `T_i` (N); `e_i = b_i − f_i e_{i−1}` until [`Linearised::substitute`].
    tension: V,
}

/// A tension solve at one state, kept for its tangents (module docs); in lanes `V`, the
/// solves of `W` chains side by side, each lane doing its chain's operations in the same
/// order (so the same bits).
#[derive(Debug, Clone)]
pub(crate) struct Linearised<const S: usize, V: Lane = f64> {
    rods: Aligned<Kept<S, V>>,
    pivot: [V; S],
}

impl<const S: usize, V: Lane> Linearised<S, V> {
    /// Room for the solves of chains of `n` rods ([`solve`](Self::solve)).
    pub fn with_len(n: usize) -> Self {
        let zero = V::splat(0.0);
        let load = Load { direction: [zero; S], rate_squared: zero, pair: [zero; S] };
        let kept =
            Kept { load, free: [zero; S], rhs: zero, factor: zero, inverse_pivot: zero, tension: zero };
        Self { rods: Aligned::filled(kept, n), pivot: [zero; S] }
    }

    /// The solve of `rods` (as many as this room's) with the loads `load`, gravity `g⃗` and
    /// pivot acceleration `p̈`: the pivots by continuants ([`Continuants`]), the classical
    /// way in the lanes where one leaves its range.
    #[inline(always)]
    pub fn solve(&mut self, rods: &Rods<V>, gravity: [V; S], pivot: [V; S], mut load: impl Loads<S, V>) {
        let n = self.rods.len();
        debug_assert_eq!(n, rods.length.len(), "a room for {n} rods");
        let zero = V::splat(0.0);
        let mut continuants = Continuants::new();
        let (mut free_above, mut im_above, mut u_above) = (pivot, zero, [zero; S]);
        let (mut inverse_pivot_above, mut eliminated_above) = (zero, zero);
        let none = Load { direction: [zero; S], rate_squared: zero, pair: [zero; S] };
        // No `Option` of a lane load: it fell apart into scalars.
        let mut below = if n > 0 { load.load(0) } else { none };
        for i in 0..n {
            let here = below;
            below = if i + 1 < n { load.load(i + 1) } else { none };
            let im = rods.inverse_mass[i];
            let mut a = gravity;
            let mut rhs = rods.length[i] * here.rate_squared;
            for k in 0..S {
                a[k] += (here.pair[k] - below.pair[k]) * im;
                rhs += here.direction[k] * (a[k] - free_above[k]);
            }
            let (diagonal, off) = entries(im, im_above, &u_above, &here.direction);
            let inverse_pivot = continuants.inverse_pivot(i, diagonal, off);
            let factor = off * inverse_pivot_above;
            let eliminated = rhs - factor * eliminated_above;
            self.rods[i] = Kept { load: here, free: a, rhs, factor, inverse_pivot, tension: eliminated };
            (free_above, im_above, u_above) = (a, im, here.direction);
            (inverse_pivot_above, eliminated_above) = (inverse_pivot, eliminated);
        }
        self.pivot = pivot;
        let outside = continuants.outside();
        if V::any(outside) {
            self.eliminate_by_pivots(rods, outside);
        }
        self.substitute();
    }

    /// The elimination again with the pivots `D_i = A_ii − f_i A_{i,i−1}` (a division on
    /// the serial chain) in the lanes `only`, whose continuants left their range.
    #[cold]
    #[inline(never)]
    fn eliminate_by_pivots(&mut self, rods: &Rods<V>, only: V::Mask) {
        let zero = V::splat(0.0);
        let (mut im_above, mut u_above) = (zero, [zero; S]);
        let (mut inverse_pivot_above, mut eliminated_above) = (zero, zero);
        for (i, kept) in self.rods.iter_mut().enumerate() {
            let (im, u) = (rods.inverse_mass[i], kept.load.direction);
            let (diagonal, off) = entries(im, im_above, &u_above, &u);
            let factor = off * inverse_pivot_above;
            let inverse_pivot = V::splat(1.0) / (diagonal - factor * off);
            let tension = kept.rhs - factor * eliminated_above;
            kept.factor = V::select(only, factor, kept.factor);
            kept.inverse_pivot = V::select(only, inverse_pivot, kept.inverse_pivot);
            kept.tension = V::select(only, tension, kept.tension);
            (im_above, u_above) = (im, u);
            (inverse_pivot_above, eliminated_above) = (inverse_pivot, tension);
        }
    }

    /// Number of rods.
    pub(super) fn len(&self) -> usize {
        self.rods.len()
    }

    /// `u_i`.
    pub(super) fn direction(&self, i: usize) -> [V; S] {
        self.rods[i].load.direction
    }

    /// `T_i` (N).
    pub(crate) fn tension(&self, i: usize) -> V {
        self.rods[i].tension
    }

    /// `a°_i` (m/s²).
    pub(super) fn free(&self, i: usize) -> [V; S] {
        self.rods[i].free
    }

    /// `p̈` (m/s²).
    pub(crate) fn pivot(&self) -> [V; S] {
        self.pivot
    }

    /// `f_i = A_{i,i−1}/D_{i−1}`.
    pub(crate) fn factor(&self, i: usize) -> V {
        self.rods[i].factor
    }

    /// `1/D_i`.
    pub(crate) fn inverse_pivot(&self, i: usize) -> V {
        self.rods[i].inverse_pivot
    }

    /// The primal back substitution of the tensions: `T_i = e_i/D_i − f_{i+1} T_{i+1}`.
    #[inline(always)]
    fn substitute(&mut self) {
        let n = self.rods.len();
        let mut tension_below = V::splat(0.0);
        for i in (0..n).rev() {
            let below_factor = if i + 1 < n { self.rods[i + 1].factor } else { V::splat(0.0) };
            let t = self.rods[i].tension * self.rods[i].inverse_pivot - below_factor * tension_below;
            self.rods[i].tension = t;
            tension_below = t;
        }
    }
}

impl<const S: usize> Linearised<S> {
    /// The solve of `rods` with these loads, gravity `g⃗` and pivot acceleration `p̈`
    /// ([`solve`](Self::solve)).
    pub fn new(rods: &Rods, gravity: [f64; S], pivot: [f64; S], load: impl Loads<S, f64>) -> Self {
        let mut out = Self::with_len(rods.len());
        out.solve(rods, gravity, pivot, load);
        out
    }

    /// `δü_i` (1/s²) along the load tangents in `work` (one [`TangentRow`] per rod) and
    /// the pivot tangent `dpivot`, written into `out` (`n` entries).
    pub fn tangent(&self, rods: &Rods, dpivot: [f64; S], work: &mut [TangentRow<S>], out: &mut [[f64; S]]) {
        let n = self.rods.len();
        let work = &mut work[..n];
        // Down: δF, δa°, r = δb − δA T, eliminated with the kept factors one row behind
        // (row i − 1's r is complete once row i has added its −δA_{i−1,i} T_i).
        let (mut dfree_above, mut free_above) = (dpivot, self.pivot);
        let (mut du_above, mut rhs_above, mut e_above) = ([0.0; S], 0.0, 0.0);
        for i in 0..n {
            let dload_here = work[i].load;
            let kept = &self.rods[i];
            let im = rods.inverse_mass[i];
            let im_above = if i > 0 { rods.inverse_mass[i - 1] } else { 0.0 };
            let u = kept.load.direction;
            let du = dload_here.direction;
            let dpair_below = if i + 1 < n { work[i + 1].load.pair } else { [0.0; S] };
            let mut dfree = [0.0; S];
            let mut rhs = rods.length[i] * dload_here.rate_squared;
            for k in 0..S {
                dfree[k] = (dload_here.pair[k] - dpair_below[k]) * im;
                rhs += du[k] * (kept.free[k] - free_above[k]) + u[k] * (dfree[k] - dfree_above[k]);
            }
            // −δA T: the diagonal, and the two off-diagonal entries of row i.
            rhs -= 2.0 * (im + im_above) * dot(&u, &du) * kept.tension;
            if i > 0 {
                let above = &self.rods[i - 1];
                let doff = -(dot(&du_above, &u) + dot(&above.load.direction, &du)) * im_above;
                rhs -= doff * above.tension;
                rhs_above -= doff * kept.tension;
                e_above = rhs_above - above.factor * e_above;
                work[i - 1].rhs = e_above;
            }
            work[i].free = dfree;
            (dfree_above, free_above, du_above, rhs_above) = (dfree, kept.free, du, rhs);
        }
        if n > 0 {
            work[n - 1].rhs = rhs_above - self.rods[n - 1].factor * e_above;
        }
        // Up: δT_i = e_i/D_i − f_{i+1} δT_{i+1}, δa_i with it, and δü_{i+1} once δa_i is known.
        let (mut dt_below, mut da_below) = (0.0, [0.0; S]);
        for i in (0..n).rev() {
            let im = rods.inverse_mass[i];
            let kept = &self.rods[i];
            let below_factor = if i + 1 < n { self.rods[i + 1].factor } else { 0.0 };
            let dt = work[i].rhs * kept.inverse_pivot - below_factor * dt_below;
            let row = &work[i];
            let mut da = row.free;
            for k in 0..S {
                da[k] -= (dt * kept.load.direction[k] + kept.tension * row.load.direction[k]) * im;
            }
            if i + 1 < n {
                let (kb, rb) = (&self.rods[i + 1], &work[i + 1]);
                for k in 0..S {
                    da[k] += (dt_below * kb.load.direction[k] + kb.tension * rb.load.direction[k]) * im;
                }
                let il = rods.inverse_length[i + 1];
                for k in 0..S {
                    out[i + 1][k] = (da_below[k] - da[k]) * il;
                }
            }
            (dt_below, da_below) = (dt, da);
        }
        if n > 0 {
            let il = rods.inverse_length[0];
            for k in 0..S {
                out[0][k] = (da_below[k] - dpivot[k]) * il;
            }
        }
    }
}

/// One rod of a [`Linearised::tangent`]: its load's tangent, and the pass's scratch
/// (`δa°_i` and the eliminated right-hand side).
#[derive(Debug, Clone, Copy)]
pub(crate) struct TangentRow<const S: usize> {
    load: LoadTangent<S>,
    free: [f64; S],
    rhs: f64,
}

impl<const S: usize> TangentRow<S> {
    /// The row of a rod whose load moves by `load`.
    pub fn new(load: LoadTangent<S>) -> Self {
        Self { load, free: [0.0; S], rhs: 0.0 }
    }
}
