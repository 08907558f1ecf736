//! The Newton iteration of one [`RodMidpoint`](super::RodMidpoint) step, lane by lane:
//! written once for one chain (`V = f64`) and for a batch's chains in SIMD lanes, so that
//! each lane does exactly what its chain alone does. A lane that has converged keeps its
//! numbers while the others iterate on; a lane that fails is flagged and left.
//!
//! The unknowns are the masses' places at `t + h`, held one of two ways (`DISPLACED`):
//! - as positions `x⁺_i` (`false`): the single chain's and the `f64` lanes' way, whose
//!   numbers the run files recorded by earlier releases repeat bit for bit;
//! - as displacements `δ_i = x⁺_i − x_i` over the step (`true`), with the rod vectors
//!   `r_i = l_i u_i` at `t`: the same equations with no two positions of the size of the
//!   chain subtracted, so the round-off is that of the motion over a step, not of the
//!   chain's reach. The `f32` lanes need it: in positions, their new velocities
//!   `2(x⁺_i − x_i)/h − v_i` take a displacement of about `h |v|` from two positions of
//!   about the reach, and keep only `h |v| / reach` of `f32`'s precision
//!   (`tests::in_f32_displacements_keep_the_digits_that_positions_lose` in `rod_midpoint`:
//!   500 steps of 1 ms of a whirled 20-link chain, 5.9e-2 from `f64` in positions, 3.8e-3
//!   in displacements).

use super::newton::{self, LinkRow, Pivot, dot};
use crate::lanes::{Aligned, Masked};

/// One step's chains in lanes `V`, per link: masses (kg), lengths (m) and rod damping
/// `λ_i` (N·m·s), and gravity `−g` along the last axis (m/s²).
pub(crate) struct Chains<'a, V> {
    pub masses: &'a [V],
    pub lengths: &'a [V],
    pub damping: &'a [V],
    pub down: V,
}

/// The pivot's position at `t` and `t + h` (m) and its velocity at `t` and `t + h` (m/s).
pub(crate) type Ends<const C: usize, V> = [[V; C]; 4];

/// The stopping rule: `|δx| ≤ tolerance · reach` per position, at most `max_iterations`.
pub(crate) struct Limits {
    pub tolerance: f64,
    pub max_iterations: usize,
}

/// Buffers kept from step to step, in lanes `V` and `C` dimensions: the positions at `t`
/// and their iterate at `t + h` (displaced: the rod vectors `r_i` at `t` and the
/// displacements `δ_i`), the velocities at `t` (per mass), the multipliers, each rod's
/// damping pair and mass's inertia term, and the Newton matrix's rows and pivots.
#[derive(Debug, Clone)]
pub(crate) struct Work<const C: usize, V: Copy> {
    x0: Aligned<[V; C]>,
    v0: Aligned<[V; C]>,
    x1: Aligned<[V; C]>,
    mu: Aligned<V>,
    pairs: Aligned<V>,
    inertias: Aligned<V>,
    rows: Aligned<LinkRow<C, V>>,
    pivots: Aligned<Pivot<C, V>>,
}

impl<const C: usize, V: Copy> Default for Work<C, V> {
    fn default() -> Self {
        let (x0, v0, x1, mu) = (Aligned::new(), Aligned::new(), Aligned::new(), Aligned::new());
        let (pairs, inertias, rows, pivots) =
            (Aligned::new(), Aligned::new(), Aligned::new(), Aligned::new());
        Self { x0, v0, x1, mu, pairs, inertias, rows, pivots }
    }
}

impl<const C: usize, V: Masked> Work<C, V> {
    /// Buffers for `n` links.
    fn size(&mut self, n: usize) {
        let zero = V::splat(0.0);
        for v in [&mut self.x0, &mut self.v0, &mut self.x1] {
            v.resize(n, [zero; C]);
        }
        for v in [&mut self.mu, &mut self.pairs, &mut self.inertias] {
            v.resize(n, zero);
        }
        let row = LinkRow {
            stiffness: zero,
            coupling: zero,
            midpoint: [zero; C],
            end: [zero; C],
            force: [zero; C],
            constraint: zero,
        };
        self.rows.resize(n, row);
        self.pivots.resize(n, Pivot::zero());
    }
}

/// What an iteration gave, per lane.
pub(crate) struct Iterated<V: Masked> {
    /// The lanes whose step failed (a singular pivot, a non-finite number, no convergence
    /// in the iterations allowed): their results are meaningless.
    pub failed: V::Mask,
    /// The iterations done (each one factorisation): for one chain, its own.
    pub iterations: usize,
    /// The pivot's work (J).
    pub drive: V,
    /// The damping loss (J).
    pub damped: V,
}

/// `a − b`.
#[inline(always)]
fn sub<const C: usize, V: Masked>(a: [V; C], b: [V; C]) -> [V; C] {
    let mut out = a;
    for k in 0..C {
        out[k] = a[k] - b[k];
    }
    out
}

/// The `i`-th `C`-vector of a flat slice.
#[inline(always)]
fn at<const C: usize, V: Masked>(v: &[V], i: usize) -> [V; C] {
    let mut out = [V::splat(0.0); C];
    out.copy_from_slice(&v[i * C..(i + 1) * C]);
    out
}

/// Rod `i`'s vectors at the step's end: its endpoint `e_i` (the rod at `t + h`), midpoint
/// `d_i` and change `s_i` of the rod vector. From the positions at `t` (`x0`) and `t + h`
/// (`x1`), the pivot at `p0` and `p1`: `e_i = x⁺_i − x⁺_{i−1}`,
/// `d_i = (x_i + x⁺_i − x_{i−1} − x⁺_{i−1})/2`, `s_i = (x⁺_i − x_i) − (x⁺_{i−1} − x_{i−1})`.
/// `DISPLACED`, from the rod vectors `r_i` (`x0`) and the displacements `δ_i` (`x1`):
/// `s_i = δ_i − δ_{i−1}` (`δ_0 = p1 − p0`), `e_i = r_i + s_i`, `d_i = r_i + s_i/2`.
#[inline(always)]
fn rod<const C: usize, V: Masked, const DISPLACED: bool>(
    (x0, x1): (&[[V; C]], &[[V; C]]),
    (p0, p1): ([V; C], [V; C]),
    i: usize,
) -> [[V; C]; 3] {
    let half = V::splat(0.5);
    if DISPLACED {
        let (r, before) = (x0[i], if i == 0 { sub(p1, p0) } else { x1[i - 1] });
        let (mut e, mut d, mut s) = (r, r, r);
        for k in 0..C {
            s[k] = x1[i][k] - before[k];
            e[k] = r[k] + s[k];
            d[k] = r[k] + half * s[k];
        }
        return [e, d, s];
    }
    let (a0, a1) = if i == 0 { (p0, p1) } else { (x0[i - 1], x1[i - 1]) };
    let (b0, b1) = (x0[i], x1[i]);
    let (mut d, mut s) = (b0, b0);
    for k in 0..C {
        d[k] = half * (b0[k] + b1[k] - a0[k] - a1[k]);
        s[k] = (b1[k] - b0[k]) - (a1[k] - a0[k]);
    }
    [sub(b1, a1), d, s]
}

/// The Newton iteration of one step of size `h` (s) in `C` dimensions for the chains in
/// the lanes `lanes`, from their states `motion = (u, w)` (`2·C·n` entries, the layout of a
/// `Directions` state) and their rod tensions `tensions` (N) at `t`, into `out`: the
/// midpoint rule on the masses with the rods as constraints (`RodMidpoint`'s equations),
/// one block-tridiagonal solve per iteration (`newton`). The other lanes are computed but
/// never flagged, converged or failed. The unknowns in positions or, `DISPLACED`, in
/// displacements (module docs).
#[inline(always)]
#[allow(clippy::too_many_arguments)] // One step's data, all of it needed.
pub(crate) fn iterate<const C: usize, V: Masked, const DISPLACED: bool>(
    work: &mut Work<C, V>,
    chains: &Chains<'_, V>,
    tensions: &[V],
    ends: Ends<C, V>,
    (motion, h, out): (&[V], f64, &mut [V]),
    lanes: V::Mask,
    limits: &Limits,
) -> Iterated<V> {
    let [p0, p1, pv0, pv1] = ends;
    let n = chains.lengths.len();
    let (m, l, lambda) = (chains.masses, chains.lengths, chains.damping);
    let zero = V::splat(0.0);
    let mut gravity = [zero; C];
    gravity[C - 1] = chains.down;
    let (hv, two) = (V::splat(h), V::splat(2.0));
    // The chain's reach: its length and the pivot's farthest coordinate, m.
    let mut reach = l[0];
    for &li in &l[1..] {
        reach += li;
    }
    let mut far = zero;
    for p in p0.iter().chain(&p1) {
        far = far.max(p.abs());
    }
    let allowed = V::splat(limits.tolerance) * (reach + far);
    let (u, w) = motion.split_at(C * n);

    // Positions (displaced: rod vectors) and velocities at t; the start of the iteration:
    // each rod turned by h w_i (with h²/2 ü_i too it took more iterations), the
    // multipliers μ_i = T_i / l_i at t.
    work.size(n);
    let Work { x0, v0, x1, mu, pairs, inertias, rows, pivots } = work;
    let (mut r0, mut rv, mut r1) = (p0, pv0, p1);
    let mut moved = sub(p1, p0);
    for i in 0..n {
        let (ui, wi) = (at::<C, V>(u, i), at::<C, V>(w, i));
        let mut turned = ui;
        for k in 0..C {
            turned[k] = ui[k] + hv * wi[k];
        }
        let norm = dot(turned, turned).sqrt();
        for k in 0..C {
            rv[k] += l[i] * wi[k];
            if DISPLACED {
                r0[k] = l[i] * ui[k];
                moved[k] += l[i] * (turned[k] / norm - ui[k]);
            } else {
                r0[k] += l[i] * ui[k];
                r1[k] += l[i] * turned[k] / norm;
            }
        }
        (x0[i], v0[i], x1[i]) = (r0, rv, if DISPLACED { moved } else { r1 });
        mu[i] = tensions[i] / l[i];
        // Rod i's damping pair per unit change of the rod vector, λ_i/(l_i² h), and mass
        // i's inertia term 2 m_i/h².
        pairs[i] = lambda[i] / (l[i] * l[i] * hv);
        inertias[i] = two * m[i] / (hv * hv);
    }
    let pivot = (p0, p1);

    // Newton's method, the matrix refactored at every iteration (a frozen matrix, tried,
    // took several times the iterations once the free end whips).
    let (mut active, mut failed) = (lanes, V::none());
    let mut iterations = 0;
    let mut previous = V::splat(f64::INFINITY);
    while V::any(active) {
        if iterations == limits.max_iterations {
            failed = V::or(failed, active);
            break;
        }
        iterations += 1;
        // Residuals and the Newton matrix, link by link (`newton` module docs).
        let mut next = rod::<C, V, DISPLACED>((x0, x1), pivot, 0);
        for i in 0..n {
            let [e, d, s] = next;
            let has_next = i + 1 < n;
            if has_next {
                next = rod::<C, V, DISPLACED>((x0, x1), pivot, i + 1);
            }
            let [_, d_next, s_next] = next;
            let (mu_i, mu_next) = (mu[i], if has_next { mu[i + 1] } else { zero });
            let (c_i, c_next) = (pairs[i], if has_next { pairs[i + 1] } else { zero });
            let (xi, x0i, v0i) = (x1[i], x0[i], v0[i]);
            let mut force = xi;
            for k in 0..C {
                let travelled = if DISPLACED { xi[k] } else { xi[k] - x0i[k] };
                let mut r =
                    inertias[i] * (travelled - hv * v0i[k]) - m[i] * gravity[k] + c_i * s[k] + mu_i * d[k];
                if has_next {
                    r -= c_next * s_next[k] + mu_next * d_next[k];
                }
                force[k] = -r;
            }
            // |e_i|² − l_i², displaced as (|r_i|² − l_i²) + 2 r_i·s_i + |s_i|² (the first
            // term zero but for the rounding of u_i).
            let stretch = if DISPLACED {
                (dot(x0i, x0i) - l[i] * l[i]) + two * dot(x0i, s) + dot(s, s)
            } else {
                dot(e, e) - l[i] * l[i]
            };
            rows[i] = LinkRow {
                stiffness: inertias[i] + c_i + c_next + V::splat(0.5) * (mu_i + mu_next),
                coupling: c_i + V::splat(0.5) * mu_i,
                midpoint: d,
                end: e,
                force,
                constraint: V::splat(-0.5) * stretch,
            };
        }
        let singular = newton::solve(rows, pivots);
        failed = V::or(failed, V::and(active, singular));
        active = V::and_not(active, singular);
        // The converged lanes keep their numbers.
        let mut largest = zero;
        for ((x, mu), row) in x1.iter_mut().zip(mu.iter_mut()).zip(rows.iter()) {
            for (x, &step) in x.iter_mut().zip(&row.force) {
                *x = V::select(active, *x + step, *x);
                largest = largest.max(step.abs());
            }
            *mu = V::select(active, *mu + row.constraint, *mu);
        }
        let blown = largest.not_finite();
        failed = V::or(failed, V::and(active, blown));
        active = V::and_not(active, blown);
        // Newton converges quadratically: the error left after this correction is about
        // δ_k²/δ_{k−1} (or less), so stop once that is below the tolerance.
        let fast = V::and_not((largest * largest / previous).at_most(allowed), previous.not_finite());
        active = V::and_not(active, V::or(largest.at_most(allowed), fast));
        previous = largest;
    }

    // The new state and the step's work: u⁺_i = e_i/l_i, and w⁺_i = (v⁺_i − v⁺_{i−1})/l_i from
    // the masses' new velocities v⁺_i = 2(x⁺_i − x_i)/h − v_i (v⁺_0 = ṗ(t + h)); displaced,
    // the same as 2 s_i/(h l_i) − w_i, plus (2(p1 − p0)/h − ṗ(t) − ṗ(t + h))/l_1 for the
    // first rod.
    let (u_out, w_out) = out.split_at_mut(C * n);
    let mut previous_velocity = pv1;
    let [_, d_first, s_first] = rod::<C, V, DISPLACED>((x0, x1), pivot, 0);
    let mut drive = zero;
    for k in 0..C {
        let term = (-pairs[0] * s_first[k] - mu[0] * d_first[k]) * (p1[k] - p0[k]);
        drive = if k == 0 { term } else { drive + term };
    }
    let mut damped = zero;
    for i in 0..n {
        let [e, _, s] = rod::<C, V, DISPLACED>((x0, x1), pivot, i);
        damped += pairs[i] * dot(s, s);
        for k in 0..C {
            u_out[i * C + k] = e[k] / l[i];
            w_out[i * C + k] = if DISPLACED {
                let change = two * s[k] / hv - l[i] * w[i * C + k];
                let lag = || two * (p1[k] - p0[k]) / hv - pv0[k] - pv1[k];
                (if i == 0 { change + lag() } else { change }) / l[i]
            } else {
                let velocity = two * (x1[i][k] - x0[i][k]) / hv - v0[i][k];
                let change = velocity - previous_velocity[k];
                previous_velocity[k] = velocity;
                change / l[i]
            };
        }
    }
    for v in out.iter() {
        failed = V::or(failed, V::and(lanes, v.not_finite()));
    }
    Iterated { failed, iterations, drive, damped }
}
