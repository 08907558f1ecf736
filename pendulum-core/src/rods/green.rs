//! Every column of a tension solve's Jacobian at once, in O(n²) with a small constant.
//!
//! A column whose load change sits on one rod `x` (a coordinate, rate or torque of link
//! `x`) changes the right-hand side of `A δT = r` in rows
//! `x − 1 … x + 1` only, and the part of `δü` that does not go through `δT` only on rods
//! `x − 1 … x + 1` (tangent module: `r = δb − δA T`, and the local part from `δa°`, `δu`).
//! With `δü_i = Σ_j V_ij δT_j + local_i`, `V` block tridiagonal:
//! ```text
//! V_{i,i+1} = u_{i+1}/(m_i l_i),   V_{i,i} = −u_i (1/m_i + 1/m_{i−1})/l_i,   V_{i,i−1} = u_{i−1}/(m_{i−1} l_i)
//! ```
//! an output row `y = w·δü_i` is `Σ_j (G_w)_j r_j + w·local_i` with `G_w = w·V A⁻¹`: one
//! O(n) solve `A g = (w·V_i)ᵀ` per output row (three non-zeros on the right, so the down
//! pass starts at `i − 1`), then three multiply-adds per entry of the Jacobian.

// The per-component loops read and write several `[f64; S]` at one index, like the solve's.
#![allow(clippy::needless_range_loop)]

use super::tangent::{Linearised, LoadTangent};
use super::{Rods, dot};
use crate::lanes::{Aligned, Lane, one_row_at_a_time};

/// One column's load change: `load` on rod `rod` (the pivot's acceleration unchanged).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Column<const S: usize, V: Lane = f64> {
    pub rod: usize,
    pub load: LoadTangent<S, V>,
}

/// The sparse parts of one column (module docs): `r` in rows `x − 1, x, x + 1` and the
/// local `δü` on rods `x − 1, x, x + 1` (entries outside the chain are zero).
struct Window<const S: usize, V: Lane> {
    rhs: [V; 3],
    local: [[V; S]; 3],
}

/// `e_k`, the unit vector along axis `k`.
#[inline(always)]
pub(crate) fn unit<const S: usize, V: Lane>(k: usize) -> [V; S] {
    let mut e = [V::splat(0.0); S];
    e[k] = V::splat(1.0);
    e
}

impl<const S: usize, V: Lane> Linearised<S, V> {
    /// The window of one column.
    #[inline(always)]
    fn window(&self, rods: &Rods<V>, c: &Column<S, V>) -> Window<S, V> {
        let n = self.len();
        let x = c.rod;
        let zero = V::splat(0.0);
        let im = &rods.inverse_mass;
        let im_above = if x > 0 { im[x - 1] } else { zero };
        let (du, dpair) = (c.load.direction, c.load.pair);
        // δa° at masses x − 1 (none above rod 0: the pivot's is unchanged) and x.
        let mut dfree_above = [zero; S];
        let mut dfree = [zero; S];
        for k in 0..S {
            dfree[k] = dpair[k] * im[x];
            dfree_above[k] = if x > 0 { -dpair[k] * im_above } else { zero };
        }
        let mut rhs = [zero; 3];
        // Row x.
        let (ux, fx, tx) = (self.direction(x), self.free(x), self.tension(x));
        let fa = if x > 0 { self.free(x - 1) } else { self.pivot() };
        let mut r = rods.length[x] * c.load.rate_squared;
        for k in 0..S {
            r += du[k] * (fx[k] - fa[k]) + ux[k] * (dfree[k] - dfree_above[k]);
        }
        r -= V::splat(2.0) * (im[x] + im_above) * dot(&ux, &du) * tx;
        if x > 0 {
            let u_above = self.direction(x - 1);
            let doff = -dot(&u_above, &du) * im_above;
            r -= doff * self.tension(x - 1);
            // Row x − 1: u_{x−1}·(δa°_{x−1} − 0) − δc_x T_x.
            let mut r_above = -doff * tx;
            for k in 0..S {
                r_above += u_above[k] * dfree_above[k];
            }
            rhs[0] = r_above;
        }
        if x + 1 < n {
            let u_below = self.direction(x + 1);
            let doff = -dot(&du, &u_below) * im[x];
            r -= doff * self.tension(x + 1);
            // Row x + 1: u_{x+1}·(0 − δa°_x) − δc_{x+1} T_x.
            let mut r_below = -doff * tx;
            for k in 0..S {
                r_below -= u_below[k] * dfree[k];
            }
            rhs[2] = r_below;
        }
        rhs[1] = r;
        // local_a at masses x − 1 and x, zero elsewhere (the pivot's too);
        // local ü_i = (local_a_i − local_a_{i−1}) / l_i on rods x − 1, x, x + 1.
        let mut a_x = dfree;
        let mut a_above = dfree_above;
        for k in 0..S {
            a_x[k] -= tx * du[k] * im[x];
            if x > 0 {
                a_above[k] += tx * du[k] * im_above;
            }
        }
        let il = &rods.inverse_length;
        let mut local = [[zero; S]; 3];
        for k in 0..S {
            if x > 0 {
                // Rod x − 1: local_a_{x−1} − local_a_{x−2}, the latter zero.
                local[0][k] = a_above[k] * il[x - 1];
                local[1][k] = (a_x[k] - a_above[k]) * il[x];
            } else {
                local[1][k] = a_x[k] * il[0];
            }
            if x + 1 < n {
                local[2][k] = -a_x[k] * il[x + 1];
            }
        }
        Window { rhs, local }
    }

    /// `(w·V_i)_j` for `j = i − 1, i, i + 1` (module docs).
    #[inline(always)]
    fn v_row(&self, rods: &Rods<V>, i: usize, w: &[V; S]) -> [V; 3] {
        let n = self.len();
        let zero = V::splat(0.0);
        let il = rods.inverse_length[i];
        let im = rods.inverse_mass[i];
        let im_above = if i > 0 { rods.inverse_mass[i - 1] } else { zero };
        let mut v = [zero; 3];
        if i > 0 {
            v[0] = dot(w, &self.direction(i - 1)) * im_above * il;
        }
        v[1] = -dot(w, &self.direction(i)) * (im + im_above) * il;
        if i + 1 < n {
            v[2] = dot(w, &self.direction(i + 1)) * im * il;
        }
        v
    }
}

/// A room for [`Linearised::state_rows`]: the columns' windows, the `G` of one rod's `S`
/// outputs and their rows.
pub(crate) struct RowsRoom<const S: usize, V: Lane> {
    /// Per column, `r` in rows `x − 1, x, x + 1` and the local `δü` on rods `x − 1 … x + 1`.
    rhs: Aligned<[V; 3]>,
    local: Aligned<[[V; S]; 3]>,
    /// `(f_j, 1/D_j)` per rod, read by every output's solve.
    pivots: Aligned<[V; 2]>,
    /// `G` of the `S` outputs of one rod, `n + 2` entries with a zero at each end (the
    /// rods `−1` and `n` outside the chain).
    green: Aligned<[V; S]>,
    /// Their rows, `S` of `columns` entries.
    rows: Aligned<V>,
}

impl<const S: usize, V: Lane> RowsRoom<S, V> {
    /// Room for chains of `n` rods and Jacobians of `columns` columns.
    pub fn new(n: usize, columns: usize) -> Self {
        let zero = V::splat(0.0);
        Self {
            rhs: Aligned::filled([zero; 3], columns),
            local: Aligned::filled([[zero; S]; 3], columns),
            pivots: Aligned::filled([zero; 2], n),
            green: Aligned::filled([zero; S], n + 2),
            rows: Aligned::filled(zero, S * columns),
        }
    }
}

impl<const S: usize, V: Lane> Linearised<S, V> {
    /// Keeps column `b`'s window (module docs) for [`state_rows`](Self::state_rows).
    #[inline(always)]
    pub fn keep_column(&self, rods: &Rods<V>, b: usize, column: &Column<S, V>, room: &mut RowsRoom<S, V>) {
        let Window { rhs, local } = self.window(rods, column);
        (room.rhs[b], room.local[b]) = (rhs, local);
    }

    /// The Jacobian of `ü` row by row, each output `e_k·δü_i` in turn (`i` rod by rod, `k`
    /// axis by axis): `emit(S·i + k, row)` with its entries over the columns kept in
    /// `room` ([`keep_column`](Self::keep_column)), where column `b` moves rod
    /// `(b / S) mod n` (the state's layout: `S` numbers a rod, in blocks of `n` rods). The
    /// numbers of [`green`](Linearised::green) and [`columns`](Linearised::columns)
    /// with the unit outputs `(i, e_k)` in that order, bit for bit: `G` of the `S` outputs of
    /// a rod at once (one O(n) solve each, their serial chains side by side), then three
    /// multiply-adds an entry, then the local part on rods `i − 1 … i + 1`.
    #[inline(always)]
    pub fn state_rows(&self, rods: &Rods<V>, room: &mut RowsRoom<S, V>, mut emit: impl FnMut(usize, &[V])) {
        let n = self.len();
        let zero = V::splat(0.0);
        let RowsRoom { rhs, local, pivots, green, rows } = room;
        let m = rhs.len();
        for (j, p) in pivots.iter_mut().enumerate() {
            *p = [self.factor(j), self.inverse_pivot(j)];
        }
        for i in 0..n {
            // G's right-hand sides: (w·V_i)_j at j = i − 1, i, i + 1, zeros elsewhere.
            green.fill([zero; S]);
            for k in 0..S {
                let v = self.v_row(rods, i, &unit(k));
                for (slot, &vs) in v.iter().enumerate() {
                    if let Some(j) = (i + slot).checked_sub(1).filter(|&j| j < n) {
                        green[j + 1][k] = vs;
                    }
                }
            }
            // Down from rod i − 1 (above it every e_j is zero, as in `green`'s groups),
            // then up: e_j = v_j − f_j e_{j−1}, g_j = e_j/D_j − f_{j+1} g_{j+1}.
            let mut e = [zero; S];
            for j in i.saturating_sub(1)..n {
                let f = pivots[j][0];
                for k in 0..S {
                    e[k] = green[j + 1][k] - f * e[k];
                }
                green[j + 1] = e;
            }
            let mut g = [zero; S];
            for j in (0..n).rev() {
                let below = if j + 1 < n { pivots[j + 1][0] } else { zero };
                let inverse_pivot = pivots[j][1];
                for k in 0..S {
                    g[k] = green[j + 1][k] * inverse_pivot - below * g[k];
                }
                green[j + 1] = g;
            }
            // Σ_slot G[:, x − 1 + slot] r_slot, G padded with zeros outside the chain; by
            // iterators over each row's blocks of `n` rods (no division to find a column's
            // rod), each rod's body closed by a fence: without it LLVM vectorised a rod's
            // columns with gathers, 1.6× slower (`docs/ensembles.md`).
            for (k, row) in rows.chunks_exact_mut(m).enumerate() {
                for (row, rhs) in row.chunks_exact_mut(S * n).zip(rhs.chunks_exact(S * n)) {
                    let rods = row.chunks_exact_mut(S).zip(rhs.chunks_exact(S));
                    for ((out, rhs), g) in rods.zip(green.windows(3)) {
                        let (g0, g1, g2) = (g[0][k], g[1][k], g[2][k]);
                        for (out, r) in out.iter_mut().zip(rhs) {
                            *out = g0 * r[0] + g1 * r[1] + g2 * r[2];
                        }
                        one_row_at_a_time();
                    }
                }
            }
            // The local part: the columns of rods i − 1, i, i + 1 (slot i − x + 1).
            for x in i.saturating_sub(1)..(i + 2).min(n) {
                let slot = i + 1 - x;
                for b in (S * x..m).step_by(S * n).flat_map(|first| first..first + S) {
                    for k in 0..S {
                        rows[k * m + b] += dot(&unit(k), &local[b][slot]);
                    }
                }
            }
            for k in 0..S {
                emit(S * i + k, &rows[k * m..(k + 1) * m]);
            }
        }
    }
}

impl<const S: usize> Linearised<S> {
    /// `G_w` for the outputs `rows` (`(i, w)`: the output `w·δü_i`, sorted by `i`),
    /// column-major (`rows.len()` × n): one O(n) solve per output, eight outputs at a time
    /// so that their serial chains overlap.
    pub fn green(&self, rods: &Rods, rows: &[(usize, [f64; S])]) -> Vec<f64> {
        const LANES: usize = 8;
        let n = self.len();
        let m = rows.len();
        let factor: Vec<f64> = (0..n).map(|j| self.factor(j)).collect();
        let inverse_pivot: Vec<f64> = (0..n).map(|j| self.inverse_pivot(j)).collect();
        let mut green = vec![0.0; m * n];
        let mut y = vec![[0.0; LANES]; n];
        for (group, chunk) in rows.chunks(LANES).enumerate() {
            let v: Vec<(usize, [f64; 3])> =
                chunk.iter().map(|&(i, w)| (i, self.v_row(rods, i, &w))).collect();
            let start = chunk[0].0.saturating_sub(1);
            // Down: e_j = v_j − f_j e_{j−1} from the first row's `i − 1` (zeros above).
            y.fill([0.0; LANES]);
            for (lane, &(i, vi)) in v.iter().enumerate() {
                for (slot, &vs) in vi.iter().enumerate() {
                    if let Some(j) = (i + slot).checked_sub(1).filter(|&j| j < n) {
                        y[j][lane] = vs;
                    }
                }
            }
            let mut e = [0.0; LANES];
            for j in start..n {
                let f = factor[j];
                for lane in 0..LANES {
                    e[lane] = y[j][lane] - f * e[lane];
                }
                y[j] = e;
            }
            // Up: g_j = e_j/D_j − f_{j+1} g_{j+1}.
            let mut g = [0.0; LANES];
            for j in (0..n).rev() {
                let below = if j + 1 < n { factor[j + 1] } else { 0.0 };
                for lane in 0..LANES {
                    g[lane] = y[j][lane] * inverse_pivot[j] - below * g[lane];
                }
                y[j] = g;
            }
            let first = group * LANES;
            for (j, g) in y.iter().enumerate() {
                for (lane, &value) in g.iter().enumerate().take(chunk.len()) {
                    green[j * m + first + lane] = value;
                }
            }
        }
        green
    }

    /// The Jacobian columns `columns` of the outputs `rows` (sorted by rod) from their
    /// `green` ([`Linearised::green`]), written into `out` (column-major, `rows.len()` ×
    /// `columns.len()`).
    pub fn columns(
        &self,
        rods: &Rods,
        rows: &[(usize, [f64; S])],
        green: &[f64],
        columns: &[Column<S>],
        out: &mut [f64],
    ) {
        let n = self.len();
        let m = rows.len();
        // The outputs of rod i are rows first[i]..first[i + 1].
        let mut first = vec![0; n + 1];
        for &(i, _) in rows {
            first[i + 1] += 1;
        }
        for i in 0..n {
            first[i + 1] += first[i];
        }
        let zeros = vec![0.0; m];
        for (col, c) in columns.iter().enumerate() {
            let window = self.window(rods, c);
            let out = &mut out[col * m..(col + 1) * m];
            // Σ_slot G[:, x − 1 + slot] r_slot in one pass (a slot outside the chain reads zeros).
            let g = |slot: usize| {
                let j = c.rod as isize + slot as isize - 1;
                if j < 0 || j as usize >= n {
                    &zeros[..]
                } else {
                    &green[j as usize * m..(j as usize + 1) * m]
                }
            };
            let (g0, g1, g2) = (&g(0)[..m], &g(1)[..m], &g(2)[..m]);
            let [r0, r1, r2] = window.rhs;
            let out = &mut out[..m];
            for r in 0..m {
                out[r] = g0[r] * r0 + g1[r] * r1 + g2[r] * r2;
            }
            for slot in 0..3 {
                let rod = c.rod as isize + slot as isize - 1;
                if rod < 0 || rod as usize >= n {
                    continue;
                }
                let rod = rod as usize;
                for r in first[rod]..first[rod + 1] {
                    out[r] += dot(&rows[r].1, &window.local[slot]);
                }
            }
        }
    }
}
