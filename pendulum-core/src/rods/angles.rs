//! [`PlanarTangents`]: the tension system of the [module docs](super) solved in the links'
//! own angles at one state and kept for its derivatives: `θ̈`, Jacobian-vector products in
//! O(n) here, full Jacobians in O(n²) in `angle_jacobians`. Generic over the chain's
//! dimension, so the generated models (`Const<N>`, stack arrays) and
//! [`PlanarTension`](crate::PlanarTension) (`Dyn`) share it; the solve ([`solve`]) and
//! the columns' view are generic over [`Lane`] too, so a batch runs them in lanes.
//!
//! The system `A T = b` written in the links' frames (the planar substitution of
//! [`PlanarTension`](crate::PlanarTension): `u_i = (sin θ_i, −cos θ_i)`, so
//! `u_{j−1}·u_j = C_j`), with `C_j = cos(θ_j − θ_{j−1})`, `S_j = sin(θ_j − θ_{j−1})`, the pulls
//! `f_i = σ_i/l_i − (λ_i/l_i) θ̇_i`, `A` the tension system with `A_ii = 1/m_i + 1/m_{i−1}`
//! and `A_{j,j−1} = −C_j/m_{j−1}`, 0-based, `1/m_{−1} = 0`) the solve is `A T = b` and
//! `θ̈ = h(θ, θ̇, σ, p̈, T)`:
//! ```text
//! b_i = l_i θ̇_i² + f_{i+1} S_{i+1}/m_i − f_{i−1} S_i/m_{i−1}  [+ u_0·(g⃗ − p̈) for i = 0]
//! θ̈_i = (f_i A_ii − f_{i+1} C_{i+1}/m_i − f_{i−1} C_i/m_{i−1}
//!         + T_{i+1} S_{i+1}/m_i − T_{i−1} S_i/m_{i−1}) / l_i   [− n_0·(p̈ − g⃗)/l_0 for i = 0]
//! ```
//! with `u_0 = (sin θ_0, −cos θ_0)`, `n_0 = (cos θ_0, sin θ_0)`, `g⃗ = (0, −g)`; `A` is
//! factored by Gaussian elimination (`D_i = A_ii − F_i A_{i,i−1}`,
//! `F_i = A_{i,i−1}/D_{i−1}`), the pivots `1/D_i` as ratios of continuants
//! (`rods::Continuants`), or the classical way should one leave its range.
//!
//! With the residual `r = b − A T` at fixed `T` and `H = ∂h/∂T` (tridiagonal, zero
//! diagonal: `H_{i,i+1} = S_{i+1}/(m_i l_i)`, `H_{i,i−1} = −S_i/(m_{i−1} l_i)`), a change
//! `δx` of the state or the inputs gives `δθ̈ = δh + H A⁻¹ δr`. An angle, rate or torque
//! of link `x` moves `r` and `h` in rows `x − 1 … x + 1` only, through the joints `x` and
//! `x + 1` (`φ_j = θ_j − θ_{j−1}`, [`Joint`]) and the pull `f_x`; so a JVP is one pass that
//! gathers `δr`, `δh` per row, and one tridiagonal solve with the kept factors.

use nalgebra::{DefaultAllocator, Dim, Dyn, OVector, U1, U2, allocator::Allocator};

use crate::lanes::Lane;
use crate::model::Inputs;

use super::{Continuants, RodConstants, pull};
use crate::kinematics::trig::sin_cos_into;

/// The joint above link `j` (between links `j − 1` and `j`, module docs): `C_j`, `S_j` and
/// the derivatives of `r_{j−1}`, `r_j`, `h_{j−1}`, `h_j` by `φ_j = θ_j − θ_{j−1}`; zero for
/// the joints outside the chain (above link 0, below the last). In lanes `V`, those of
/// `W` chains side by side.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Joint<V = f64> {
    pub cos: V,
    pub sin: V,
    pub r_above: V,
    pub r_below: V,
    pub h_above: V,
    pub h_below: V,
}

impl<V: Lane> Joint<V> {
    /// A joint outside the chain.
    #[inline(always)]
    pub fn zero() -> Self {
        let zero = V::splat(0.0);
        Self { cos: zero, sin: zero, r_above: zero, r_below: zero, h_above: zero, h_below: zero }
    }
}

/// One link of the kept solve (in lanes `V`, of `W` chains).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Link<V = f64> {
    pub sin: V,
    pub cos: V,
    /// `θ̇_i` (rad/s).
    pub rate: V,
    /// `f_i` (N).
    pub pull: V,
    /// The joint above this link.
    pub joint: Joint<V>,
    /// `F_i = A_{i,i−1}/D_{i−1}` (0 for link 0) and `1/D_i` (kg).
    pub factor: V,
    pub inverse_pivot: V,
    /// `T_i` (N).
    pub tension: V,
    /// `θ̈_i` (rad/s²).
    pub acceleration: V,
}

impl<V: Lane> Link<V> {
    /// The link at `sin θ_i`, `cos θ_i`, `θ̇_i` (rad/s) with the pull `f_i` (N), the rest
    /// for [`solve`] to fill.
    #[inline(always)]
    pub fn at(sin: V, cos: V, rate: V, pull: V) -> Self {
        let zero = V::splat(0.0);
        let joint = Joint::zero();
        Self {
            sin,
            cos,
            rate,
            pull,
            joint,
            factor: zero,
            inverse_pivot: zero,
            tension: zero,
            acceleration: zero,
        }
    }
}

/// `PlanarTension`'s solve at one state, kept for its tangents:
/// the directional derivatives (Jacobian-vector products) of `θ̈` in O(n) each
/// ([`jvp`](Self::jvp)), and its full Jacobians in O(n²)
/// ([`jacobians`](Self::jacobians)), in the links' own angles (module docs).
#[derive(Debug, Clone)]
pub struct PlanarTangents<'a, L: Dim = Dyn>
where
    DefaultAllocator: Allocator<L>,
{
    pub(super) rods: RodConstants<'a>,
    /// `g` (m/s²).
    pub(super) gravity: f64,
    /// `p̈` (m/s²).
    pub(super) pivot: [f64; 2],
    pub(super) links: OVector<Link, L>,
    /// The JVP's right-hand side `δr`, then `A⁻¹ δr`.
    work: OVector<f64, L>,
}

impl<'a, L: Dim> PlanarTangents<'a, L>
where
    DefaultAllocator: Allocator<L>,
{
    /// The solve of the chain `rods` under gravity `g` (m/s²) at `θ = q`, `θ̇ = qd` with
    /// the torques (N·m) and pivot acceleration (m/s²) of `inputs`: as many links as `q`
    /// has entries, every vector that long (the caller checks). Non-finite inputs give
    /// non-finite results. Inlined so that a fixed `n` unrolls it and the result is built
    /// in place.
    #[inline(always)]
    pub(crate) fn new(
        rods: RodConstants<'a>,
        gravity: f64,
        q: &OVector<f64, L>,
        qd: &OVector<f64, L>,
        inputs: &Inputs<L, U2>,
    ) -> Self
    where
        DefaultAllocator: Allocator<U2>,
    {
        let dim = q.shape_generic().0;
        let (q, qd, torque) = (q.as_slice(), qd.as_slice(), inputs.torque.as_slice());
        let pivot = [inputs.pivot_acceleration[0], inputs.pivot_acceleration[1]];
        let RodConstants { inverse_length: il, drag, .. } = rods;
        let mut trig = OVector::<[f64; 2], L>::from_element_generic(dim, U1, [0.0; 2]);
        sin_cos_into(q, trig.as_mut_slice());
        let mut links = OVector::<Link, L>::from_fn_generic(dim, U1, |i, _| {
            let [sin, cos] = trig[i];
            Link::at(sin, cos, qd[i], pull(torque[i], il[i], drag[i], qd[i]))
        });
        solve(links.as_mut_slice(), rods, gravity, pivot);
        let work = OVector::from_element_generic(dim, U1, 0.0);
        Self { rods, gravity, pivot, links, work }
    }

    /// `θ̈` at the state (rad/s²), per link.
    pub fn accelerations(&self) -> impl ExactSizeIterator<Item = f64> + '_ {
        self.links.iter().map(|l| l.acceleration)
    }

    /// `δθ̈` (rad/s²) along `(δθ, δθ̇, δσ, δp̈)`, written into `out`; every slice has `n`
    /// entries: one pass gathering `δr` and `δh` row by row and eliminating `δr` as it
    /// goes, one back substitution applying `H` (module docs). O(n), allocation-free.
    ///
    /// The rows hold `Columns`' derivatives transposed (each row sums what the columns
    /// `i − 1 … i + 1` put in it), written out per row: gathering through `Columns`
    /// measured twice as slow. The unit tests hold the JVP to the full Jacobians.
    pub fn jvp(&mut self, dq: &[f64], dqd: &[f64], dtorque: &[f64], dpivot: [f64; 2], out: &mut [f64]) {
        let n = self.links.len();
        let RodConstants { inverse_mass: im, length, inverse_length: il, drag } = self.rods;
        let (links, work) = (self.links.as_slice(), self.work.as_mut_slice());
        let columns = Columns { links, rods: self.rods, gravity: self.gravity, pivot: self.pivot };
        let (dq, dqd, dtorque, out) = (&dq[..n], &dqd[..n], &dtorque[..n], &mut out[..n]);
        let dpull = |i: usize| pull(dtorque[i], il[i], drag[i], dqd[i]);
        let mut e_above = 0.0;
        for i in 0..n {
            let here = &links[i];
            let df = dpull(i);
            let im_above = if i >= 1 { im[i - 1] } else { 0.0 };
            let mut dr = 2.0 * length[i] * here.rate * dqd[i];
            let mut dh = il[i] * (im[i] + im_above) * df;
            if i >= 1 {
                let (j, dphi, df_above) = (here.joint, dq[i] - dq[i - 1], dpull(i - 1));
                dr += j.r_below * dphi - im_above * j.sin * df_above;
                dh += j.h_below * dphi - il[i] * im_above * j.cos * df_above;
            } else {
                let [px, py] = self.pivot;
                let (s, c, g) = (here.sin, here.cos, self.gravity);
                dr -= (s * (g + py) + c * px) * dq[0] + s * dpivot[0] - c * dpivot[1];
                dh += il[0] * ((s * px - c * (g + py)) * dq[0] - c * dpivot[0] - s * dpivot[1]);
            }
            if i + 1 < n {
                let (j, dphi, df_below) = (links[i + 1].joint, dq[i + 1] - dq[i], dpull(i + 1));
                dr += j.r_above * dphi + im[i] * j.sin * df_below;
                dh += j.h_above * dphi - il[i] * im[i] * j.cos * df_below;
            }
            e_above = dr - here.factor * e_above;
            work[i] = e_above;
            out[i] = dh;
        }
        // Up: y_i = e_i/D_i − F_{i+1} y_{i+1}; row i + 1 of H A⁻¹ δr once y_i is known.
        let mut y_below = 0.0;
        for i in (0..n).rev() {
            let factor_below = if i + 1 < n { links[i + 1].factor } else { 0.0 };
            let y = work[i] * links[i].inverse_pivot - factor_below * y_below;
            work[i] = y;
            if i + 1 < n {
                // H_{i+1,i} y_i + H_{i+1,i+2} y_{i+2}.
                let [h_above, h_below] = columns.coupling(i + 1);
                let y_below2 = if i + 2 < n { work[i + 2] } else { 0.0 };
                out[i + 1] += h_above * y + h_below * y_below2;
            }
            y_below = y;
        }
        if n > 1 {
            out[0] += columns.coupling(0)[1] * work[1];
        }
    }

    /// The columns' view of the kept solve.
    pub(super) fn columns(&self) -> Columns<'_> {
        Columns { links: self.links.as_slice(), rods: self.rods, gravity: self.gravity, pivot: self.pivot }
    }
}

/// The solve of [`PlanarTangents::new`] on `ls`, whose `sin`, `cos`, `rate` and `pull` are
/// set ([`Link::at`]), for a chain of `rods` under gravity `g` (m/s²) with the pivot
/// acceleration `p̈` (m/s²): the joints, the elimination (`F_i`, `1/D_i`), the tensions,
/// `θ̈` and the joints' derivative terms. In lanes `V`, `W` chains at once, each lane doing
/// the operations of the chain alone in the same order (so the same bits); a lane whose
/// continuants leave their range redoes its pivots the classical way, the others keep
/// theirs.
#[inline(always)]
pub(crate) fn solve<V: Lane>(ls: &mut [Link<V>], rods: RodConstants<'_, V>, gravity: V, pivot: [V; 2]) {
    let n = ls.len();
    let RodConstants { inverse_mass: im, inverse_length: il, .. } = rods;
    let zero = V::splat(0.0);
    for j in 1..n {
        let (above, here) = (ls[j - 1], ls[j]);
        ls[j].joint.cos = above.cos * here.cos + above.sin * here.sin;
        ls[j].joint.sin = here.sin * above.cos - here.cos * above.sin;
    }
    // Down: b_i, eliminated as it comes, the pivots by continuants (the classical way in the
    // lanes where a continuant left its range).
    let mut continuants = Continuants::new();
    eliminate(ls, rods, gravity, pivot, None, |i, diagonal, off| continuants.inverse_pivot(i, diagonal, off));
    let outside = continuants.outside();
    if V::any(outside) {
        let mut inverse_pivot_above = zero;
        eliminate(ls, rods, gravity, pivot, Some(outside), |_, diagonal, off| {
            inverse_pivot_above = V::splat(1.0) / (diagonal - off * off * inverse_pivot_above);
            inverse_pivot_above
        });
    }
    // Up: T_i = e_i/D_i − F_{i+1} T_{i+1}.
    let (mut factor_below, mut tension_below) = (zero, zero);
    for link in ls.iter_mut().rev() {
        link.tension = link.tension * link.inverse_pivot - factor_below * tension_below;
        (factor_below, tension_below) = (link.factor, link.tension);
    }
    // θ̈ and the joints' derivative terms.
    for i in 0..n {
        let here = ls[i];
        let im_above = if i >= 1 { im[i - 1] } else { zero };
        let mut a = here.pull * (im[i] + im_above);
        if i + 1 < n {
            let b = ls[i + 1];
            a += (b.tension * b.joint.sin - b.pull * b.joint.cos) * im[i];
        }
        if i >= 1 {
            let (above, j) = (ls[i - 1], here.joint);
            a -= (above.pull * j.cos + above.tension * j.sin) * im_above;
            let w = im_above;
            ls[i].joint = Joint {
                r_above: w * (here.pull * j.cos - j.sin * here.tension),
                r_below: w * (-above.pull * j.cos - j.sin * above.tension),
                h_above: il[i - 1] * w * (here.pull * j.sin + here.tension * j.cos),
                h_below: il[i] * w * (above.pull * j.sin - above.tension * j.cos),
                ..j
            };
        } else {
            let [px, py] = pivot;
            a -= here.cos * px + here.sin * (py + gravity);
        }
        ls[i].acceleration = a * il[i];
    }
}

/// How each input of `θ̈` moves `r` and `h` (module docs): a column changes rows
/// `x − 1 … x + 1` only, given as `(∂r, ∂h)` in those rows, entries outside the chain zero.
/// The one place these derivatives are written: the JVP gathers them, the full Jacobians
/// (`jacobians`) mix `G`'s columns with them.
/// In lanes `V`, the columns of `W` chains side by side.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Columns<'a, V = f64> {
    pub links: &'a [Link<V>],
    pub rods: RodConstants<'a, V>,
    /// `g` (m/s²) and `p̈` (m/s²).
    pub gravity: V,
    pub pivot: [V; 2],
}

impl<V: Lane> Columns<'_, V> {
    /// The joint above link `j` (zero outside the chain).
    #[inline(always)]
    fn joint(&self, j: usize) -> Joint<V> {
        if j < self.links.len() { self.links[j].joint } else { Joint::zero() }
    }

    /// By `θ_x`: through `φ_x` (+1) and `φ_{x+1}` (−1); link 0 also through
    /// `u_0·(g⃗ − p̈)` in `b_0` and `−n_0·(p̈ − g⃗)/l_0` in `h_0`.
    #[inline(always)]
    pub fn angle(&self, x: usize) -> ([V; 3], [V; 3]) {
        let (a, b) = (self.joint(x), self.joint(x + 1));
        let mut r = [a.r_above, a.r_below - b.r_above, -b.r_below];
        let mut h = [a.h_above, a.h_below - b.h_above, -b.h_below];
        if x == 0 {
            let ([px, py], g, il) = (self.pivot, self.gravity, self.rods.inverse_length[0]);
            let (s0, c0) = (self.links[0].sin, self.links[0].cos);
            r[1] -= s0 * (g + py) + c0 * px;
            h[1] += il * (s0 * px - c0 * (g + py));
        }
        (r, h)
    }

    /// By the pull `f_x` (N): `θ̇_x` enters as `−(λ_x/l_x) f_x` (and `2 l_x θ̇_x` in `b_x`),
    /// `σ_x` as `f_x/l_x`.
    #[inline(always)]
    pub fn pull(&self, x: usize) -> ([V; 3], [V; 3]) {
        let (im, il) = (self.rods.inverse_mass, self.rods.inverse_length);
        let (above, below) = (self.joint(x), self.joint(x + 1));
        let zero = V::splat(0.0);
        let (im_above, il_above) = if x >= 1 { (im[x - 1], il[x - 1]) } else { (zero, zero) };
        let il_below = il.get(x + 1).copied().unwrap_or(zero);
        let r = [im_above * above.sin, zero, -im[x] * below.sin];
        let h = [-il_above * im_above * above.cos, il[x] * (im[x] + im_above), -il_below * im[x] * below.cos];
        (r, h)
    }

    /// By `p̈_x` and `p̈_y`: through `u_0·(g⃗ − p̈)` in `b_0` and `−n_0·(p̈ − g⃗)/l_0` in `h_0`
    /// (columns of link 0).
    #[inline(always)]
    pub fn pivot(&self) -> [([V; 3], [V; 3]); 2] {
        let (s0, c0, il) = (self.links[0].sin, self.links[0].cos, self.rods.inverse_length[0]);
        let zero = V::splat(0.0);
        [([zero, -s0, zero], [zero, -il * c0, zero]), ([zero, c0, zero], [zero, -il * s0, zero])]
    }

    /// Row `i` of `H = ∂h/∂T` (module docs): `[H_{i,i−1}, H_{i,i+1}] =
    /// [−S_i/(m_{i−1} l_i), S_{i+1}/(m_i l_i)]` (1/(kg·m)), zero outside the chain.
    #[inline(always)]
    pub fn coupling(&self, i: usize) -> [V; 2] {
        let (links, im, il) = (self.links, self.rods.inverse_mass, self.rods.inverse_length);
        let zero = V::splat(0.0);
        let above = if i >= 1 { -il[i] * im[i - 1] * links[i].joint.sin } else { zero };
        let below = if i + 1 < links.len() { il[i] * im[i] * links[i + 1].joint.sin } else { zero };
        [above, below]
    }
}

/// The down pass of [`solve`]: `b_i` (module docs) and its elimination,
/// `F_i = A_{i,i−1}/D_{i−1}` and `e_i = b_i − F_i e_{i−1}` (kept in `tension`), with the
/// pivots `1/D_i` from `inverse_pivot(i, A_ii, A_{i,i−1})`; stored in every lane, or only
/// in the lanes of `only`.
#[inline(always)]
fn eliminate<V: Lane>(
    ls: &mut [Link<V>],
    rods: RodConstants<'_, V>,
    gravity: V,
    [px, py]: [V; 2],
    only: Option<V::Mask>,
    mut inverse_pivot: impl FnMut(usize, V, V) -> V,
) {
    let n = ls.len();
    let RodConstants { inverse_mass: im, length, .. } = rods;
    let zero = V::splat(0.0);
    let (mut inverse_pivot_above, mut e_above) = (zero, zero);
    for i in 0..n {
        let here = ls[i];
        let im_above = if i >= 1 { im[i - 1] } else { zero };
        let mut b = length[i] * here.rate * here.rate;
        if i == 0 {
            b += here.cos * (gravity + py) - here.sin * px;
        } else {
            b -= ls[i - 1].pull * here.joint.sin * im_above;
        }
        if i + 1 < n {
            b += ls[i + 1].pull * ls[i + 1].joint.sin * im[i];
        }
        let off = -here.joint.cos * im_above;
        let ip = inverse_pivot(i, im[i] + im_above, off);
        let factor = off * inverse_pivot_above;
        let e = b - factor * e_above;
        let link = &mut ls[i];
        match only {
            None => (link.factor, link.inverse_pivot, link.tension) = (factor, ip, e),
            Some(lanes) => {
                link.factor = V::select(lanes, factor, link.factor);
                link.inverse_pivot = V::select(lanes, ip, link.inverse_pivot);
                link.tension = V::select(lanes, e, link.tension);
            }
        }
        (inverse_pivot_above, e_above) = (ip, e);
    }
}
