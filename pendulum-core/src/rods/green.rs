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

/// One column's load change: `load` on rod `rod` (the pivot's acceleration unchanged).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Column<const S: usize> {
    pub rod: usize,
    pub load: LoadTangent<S>,
}

/// The sparse parts of one column (module docs): `r` in rows `x − 1, x, x + 1` and the
/// local `δü` on rods `x − 1, x, x + 1` (entries outside the chain are zero).
struct Window<const S: usize> {
    rhs: [f64; 3],
    local: [[f64; S]; 3],
}

impl<const S: usize> Linearised<S> {
    /// The window of one column.
    fn window(&self, rods: &Rods, c: &Column<S>) -> Window<S> {
        let n = self.len();
        let x = c.rod;
        let im = |i: usize| rods.inverse_mass[i];
        let im_above = if x > 0 { im(x - 1) } else { 0.0 };
        let (du, dpair) = (c.load.direction, c.load.pair);
        // δa° at masses x − 1 (none above rod 0: the pivot's is unchanged) and x.
        let mut dfree_above = [0.0; S];
        let mut dfree = [0.0; S];
        for k in 0..S {
            dfree[k] = dpair[k] * im(x);
            dfree_above[k] = if x > 0 { -dpair[k] * im_above } else { 0.0 };
        }
        let u = |i: usize| self.direction(i);
        let t = |i: usize| self.tension(i);
        let free = |i: isize| if i < 0 { self.pivot() } else { self.free(i as usize) };
        let mut rhs = [0.0; 3];
        // Row x.
        let (ux, fx, fa) = (u(x), free(x as isize), free(x as isize - 1));
        let mut r = rods.length[x] * c.load.rate_squared;
        for k in 0..S {
            r += du[k] * (fx[k] - fa[k]) + ux[k] * (dfree[k] - dfree_above[k]);
        }
        r -= 2.0 * (im(x) + im_above) * dot(&ux, &du) * t(x);
        if x > 0 {
            let doff = -dot(&u(x - 1), &du) * im_above;
            r -= doff * t(x - 1);
            // Row x − 1: u_{x−1}·(δa°_{x−1} − 0) − δc_x T_x.
            let mut r_above = -doff * t(x);
            for k in 0..S {
                r_above += u(x - 1)[k] * dfree_above[k];
            }
            rhs[0] = r_above;
        }
        if x + 1 < n {
            let doff = -dot(&du, &u(x + 1)) * im(x);
            r -= doff * t(x + 1);
            // Row x + 1: u_{x+1}·(0 − δa°_x) − δc_{x+1} T_x.
            let mut r_below = -doff * t(x);
            for k in 0..S {
                r_below -= u(x + 1)[k] * dfree[k];
            }
            rhs[2] = r_below;
        }
        rhs[1] = r;
        // local_a at masses x − 1 and x, zero elsewhere (the pivot's too);
        // local ü_i = (local_a_i − local_a_{i−1}) / l_i on rods x − 1, x, x + 1.
        let mut a_x = dfree;
        let mut a_above = dfree_above;
        for k in 0..S {
            a_x[k] -= t(x) * du[k] * im(x);
            if x > 0 {
                a_above[k] += t(x) * du[k] * im_above;
            }
        }
        let mut local = [[0.0; S]; 3];
        for k in 0..S {
            if x > 0 {
                // Rod x − 1: local_a_{x−1} − local_a_{x−2}, the latter zero.
                local[0][k] = a_above[k] * rods.inverse_length[x - 1];
                local[1][k] = (a_x[k] - a_above[k]) * rods.inverse_length[x];
            } else {
                local[1][k] = a_x[k] * rods.inverse_length[0];
            }
            if x + 1 < n {
                local[2][k] = -a_x[k] * rods.inverse_length[x + 1];
            }
        }
        Window { rhs, local }
    }

    /// `(w·V_i)_j` for `j = i − 1, i, i + 1` (module docs).
    fn v_row(&self, rods: &Rods, i: usize, w: &[f64; S]) -> [f64; 3] {
        let n = self.len();
        let il = rods.inverse_length[i];
        let im = rods.inverse_mass[i];
        let im_above = if i > 0 { rods.inverse_mass[i - 1] } else { 0.0 };
        let mut v = [0.0; 3];
        if i > 0 {
            v[0] = dot(w, &self.direction(i - 1)) * im_above * il;
        }
        v[1] = -dot(w, &self.direction(i)) * (im + im_above) * il;
        if i + 1 < n {
            v[2] = dot(w, &self.direction(i + 1)) * im * il;
        }
        v
    }

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
