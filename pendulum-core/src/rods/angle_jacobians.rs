//! [`PlanarTangents`]' full Jacobians in the links' own angles, O(n²) with a small constant.
//!
//! With the residual `r = b − A T` at fixed `T` and `H = ∂h/∂T` (`angles` module docs),
//! `∂θ̈/∂x = ∂h/∂x + G ∂r/∂x` with `G = H A⁻¹`. Every column `x` (an angle, rate or torque
//! of link `x`, or the pivot) changes `r` and `h` in rows `x − 1 … x + 1` only, so after
//! `G` (n solves with the kept factors of `A`, all outputs at once) each entry costs three
//! multiply-adds. Generic over [`Lane`]: the chain alone runs it with `f64`, a batch with
//! `W` chains a lane group (`batch::planar_jacobians`), the same operations lane by lane.

use nalgebra::{DefaultAllocator, Dim, OMatrix, allocator::Allocator};

use super::RodConstants;
use super::angles::{Columns, PlanarTangents};
use crate::lanes::Lane;

impl<L: Dim> PlanarTangents<'_, L>
where
    DefaultAllocator: Allocator<L> + Allocator<L, L>,
{
    /// `∂θ̈/∂θ`, `∂θ̈/∂θ̇`, `∂θ̈/∂σ` (column-major n × n each) and `∂θ̈/∂p̈` (n × 2), all
    /// at once: each column changes the solve in three rows, so after `G = H A⁻¹` (n solves
    /// with the kept factors, all at once) each entry is three multiply-adds, O(n²) in all
    /// (module docs).
    #[inline(always)]
    pub fn jacobians(&self, dq: &mut [f64], dqd: &mut [f64], dtorque: &mut [f64], dpivot: &mut [f64]) {
        self.blocks(dq, dqd, Some((dtorque, dpivot)));
    }

    /// [`jacobians`](Self::jacobians) by `θ` and `θ̇` only: the state Jacobians a
    /// linearisation or an implicit integrator needs.
    #[inline(always)]
    pub fn state_jacobians(&self, dq: &mut [f64], dqd: &mut [f64]) {
        self.blocks(dq, dqd, None);
    }

    /// `∂θ̈/∂θ`, `∂θ̈/∂θ̇` and, if asked, `∂θ̈/∂σ` and `∂θ̈/∂p̈`, column-major (module docs).
    #[inline(always)]
    fn blocks(&self, dq: &mut [f64], dqd: &mut [f64], inputs: Option<(&mut [f64], &mut [f64])>) {
        let dim = self.links.shape_generic().0;
        let mut green = OMatrix::<f64, L, L>::zeros_generic(dim, dim);
        blocks(self.columns(), green.as_mut_slice(), dq, dqd, inputs);
    }
}

/// `∂θ̈/∂θ`, `∂θ̈/∂θ̇` and, if asked, `∂θ̈/∂σ` and `∂θ̈/∂p̈` of the kept solve `columns`,
/// column by column (module docs), with `green` (`n²` zeros) as room for `G`: the chain
/// alone's order (a batch's lanes take [`state_rows`]).
#[inline(always)]
fn blocks<V: Lane>(
    columns: Columns<'_, V>,
    green: &mut [V],
    dq: &mut [V],
    dqd: &mut [V],
    inputs: Option<(&mut [V], &mut [V])>,
) {
    let links = columns.links;
    let n = links.len();
    if n == 0 {
        return;
    }
    let RodConstants { length, inverse_length: il, drag, .. } = columns.rods;
    let green = green_of(columns, green);
    let mix = |out: &mut [V], x: usize, r: [V; 3], h: [V; 3]| mix(green, n, out, x, r, h);
    for x in 0..n {
        let (r, h) = columns.angle(x);
        mix(&mut dq[x * n..(x + 1) * n], x, r, h);
    }
    // By θ̇_x (the pull's column scaled by −λ_x/l_x, and 2 l_x θ̇_x in b_x) and, if asked,
    // by σ_x: the pull's column P_x into dqd's column x first, then ∂θ̈/∂σ_x = P_x/l_x
    // and ∂θ̈/∂θ̇_x = −(λ_x/l_x) P_x + 2 l_x θ̇_x G[:, x].
    let (mut dtorque, dpivot) = inputs.unzip();
    for x in 0..n {
        let column = &mut dqd[x * n..(x + 1) * n];
        let Some(dtorque) = dtorque.as_deref_mut() else {
            let (r, h) = rate_weights(columns, x);
            mix(column, x, r, h);
            continue;
        };
        let (r, h) = columns.pull(x);
        let (k, rate) = (-drag[x], V::splat(2.0) * length[x] * links[x].rate);
        mix(column, x, r, h);
        for (t, &p) in dtorque[x * n..(x + 1) * n].iter_mut().zip(&*column) {
            *t = il[x] * p;
        }
        for (p, &g) in column.iter_mut().zip(&green[x * n..(x + 1) * n]) {
            *p = k * *p + rate * g;
        }
    }
    if let Some(dpivot) = dpivot {
        for (k, (r, h)) in columns.pivot().into_iter().enumerate() {
            mix(&mut dpivot[k * n..(k + 1) * n], 0, r, h);
        }
    }
}

/// `∂θ̈/∂θ` and `∂θ̈/∂θ̇` of the kept solve `columns` row by row, for lanes, where a row
/// costs what a column does and needs no room of `n²` for the result: `G` into `green`
/// (`n²` zeros), the weights of every column into `weights` (`2n`), then
/// `emit(i, row i of ∂θ̈/∂θ, row i of ∂θ̈/∂θ̇)` for `i = 0 … n − 1`, each row built in
/// `rows` (`2n`). Every entry is the sum [`blocks`] forms (the same operations in the same
/// order), so the same bits.
#[inline(always)]
pub(crate) fn state_rows<V: Lane>(
    columns: Columns<'_, V>,
    green: &mut [V],
    weights: &mut [([V; 3], [V; 3])],
    rows: &mut [V],
    mut emit: impl FnMut(usize, &[V], &[V]),
) {
    let n = columns.links.len();
    if n == 0 {
        return;
    }
    let green = green_of(columns, green);
    let (by_angle, by_rate) = weights[..2 * n].split_at_mut(n);
    for x in 0..n {
        by_angle[x] = columns.angle(x);
        by_rate[x] = rate_weights(columns, x);
    }
    let (dq, dqd) = rows[..2 * n].split_at_mut(n);
    for i in 0..n {
        for (weights, row) in [(&*by_angle, &mut *dq), (&*by_rate, &mut *dqd)] {
            for (x, (o, &(r, _))) in row.iter_mut().zip(weights).enumerate() {
                let at = |j: usize| green[j * n + i];
                *o = r[0] * at(x.saturating_sub(1)) + r[1] * at(x) + r[2] * at((x + 1).min(n - 1));
            }
            // Row i is changed directly by columns i + 1, i and i − 1 (`mix`'s `h`).
            if i >= 1 {
                row[i - 1] += weights[i - 1].1[2];
            }
            row[i] += weights[i].1[1];
            if i + 1 < n {
                row[i + 1] += weights[i + 1].1[0];
            }
        }
        emit(i, dq, dqd);
    }
}

/// The weights of column `x` of `∂θ̈/∂θ̇` ([`mix`]): the pull's column scaled by
/// `−λ_x/l_x`, and `2 l_x θ̇_x` in `b_x`.
#[inline(always)]
fn rate_weights<V: Lane>(columns: Columns<'_, V>, x: usize) -> ([V; 3], [V; 3]) {
    let RodConstants { length, drag, .. } = columns.rods;
    let (r, h) = columns.pull(x);
    let (k, rate) = (-drag[x], V::splat(2.0) * length[x] * columns.links[x].rate);
    // Written out: `array::map`'s closure was compiled apart from the lanes' kernels,
    // without their target features.
    ([k * r[0], k * r[1] + rate, k * r[2]], [k * h[0], k * h[1], k * h[2]])
}

/// `G = H A⁻¹` of the kept solve `columns` (module docs) into `green` (`n²` zeros),
/// column-major: column j is row j of A⁻¹ Hᵀ, the solve of every output at once, each a
/// row operation of the kept elimination.
#[inline(always)]
fn green_of<'g, V: Lane>(columns: Columns<'_, V>, green: &'g mut [V]) -> &'g [V] {
    let links = columns.links;
    let n = links.len();
    let green = &mut green[..n * n];
    for j in 0..n {
        if j >= 1 {
            green[j * n + j - 1] = columns.coupling(j - 1)[1];
        }
        if j + 1 < n {
            green[j * n + j + 1] = columns.coupling(j + 1)[0];
        }
    }
    for j in 1..n {
        let factor = links[j].factor;
        let (above, here) = green.split_at_mut(j * n);
        // Rows i > j + 1 of column j − 1 are still zero.
        let end = (j + 1).min(n);
        for (g, &a) in here[..end].iter_mut().zip(&above[(j - 1) * n..(j - 1) * n + end]) {
            *g -= factor * a;
        }
    }
    let last = links[n - 1].inverse_pivot;
    green[(n - 1) * n..].iter_mut().for_each(|g| *g = *g * last);
    for j in (0..n - 1).rev() {
        let (inverse_pivot, factor) = (links[j].inverse_pivot, links[j + 1].factor);
        let (here, below) = green.split_at_mut((j + 1) * n);
        for (g, &b) in here[j * n..].iter_mut().zip(&below[..n]) {
            *g = *g * inverse_pivot - factor * b;
        }
    }
    green
}

/// Column `x` of a Jacobian from `G`'s columns `x − 1`, `x`, `x + 1` (weights `r`, the
/// change of the residual in rows `x − 1 … x + 1`) and the direct change `h` of those
/// rows; a weight outside the chain is zero (the joints there are), so its column may be
/// any. Inlined so that a fixed `n` unrolls it.
#[inline(always)]
fn mix<V: Lane>(green: &[V], n: usize, out: &mut [V], x: usize, r: [V; 3], h: [V; 3]) {
    let column = |j: usize| &green[j * n..(j + 1) * n];
    let (above, here, below) = (column(x.saturating_sub(1)), column(x), column((x + 1).min(n - 1)));
    for (o, ((&a, &g), &b)) in out[..n].iter_mut().zip(above.iter().zip(here).zip(below)) {
        *o = r[0] * a + r[1] * g + r[2] * b;
    }
    // Rows x − 1 … x + 1 again from G, not read back from `out` (a load of a value just
    // stored by the vector loop stalls).
    if x >= 1 {
        out[x - 1] = entry(r, [above, here, below], x - 1) + h[0];
    }
    out[x] = entry(r, [above, here, below], x) + h[1];
    if x + 1 < n {
        out[x + 1] = entry(r, [above, here, below], x + 1) + h[2];
    }
}

/// Row `i` of `G`'s columns `x − 1`, `x`, `x + 1` weighted by `r` ([`mix`]); a function, not
/// a closure, so that it is inlined into the lanes' kernels with their target features.
#[inline(always)]
fn entry<V: Lane>(r: [V; 3], [above, here, below]: [&[V]; 3], i: usize) -> V {
    r[0] * above[i] + r[1] * here[i] + r[2] * below[i]
}
