//! The O(n) forward dynamics of a chain of point masses on rigid rods, by the rod
//! tensions: one symmetric tridiagonal solve, planar and spatial alike.
//!
//! Mass `i` (1-based, `r_0 = p` the pivot) sits at `r_i = r_{i−1} + l_i u_i` with `u_i` the
//! unit direction of rod `i`. Rod `i` pulls mass `i−1` towards mass `i` and mass `i`
//! towards mass `i−1` with the tension `T_i` (N). With `F_i` the force applied by
//! whatever acts on rod `i` itself (a torque or damping on the link, as a force pair:
//! `+F_i` on mass `i`, `−F_i` on mass `i−1`) and `g⃗` gravity, Newton's law for mass `i` is
//! ```text
//! m_i a_i = m_i g⃗ + F_i − F_{i+1} + T_{i+1} u_{i+1} − T_i u_i        (T_{n+1} = F_{n+1} = 0)
//! ```
//! and the rods stay rigid when `u_i · ü_i = −|u̇_i|²`, i.e. `u_i · (a_i − a_{i−1}) = −l_i |u̇_i|²`
//! with `a_0 = p̈`. Writing `a_i = a°_i + (T_{i+1} u_{i+1} − T_i u_i)/m_i` with the free
//! accelerations `a°_i = g⃗ + (F_i − F_{i+1})/m_i` (`a°_0 = p̈`) gives, per rod,
//! ```text
//! (1/m_i + 1/m_{i−1}) T_i − (u_{i−1}·u_i / m_{i−1}) T_{i−1} − (u_i·u_{i+1} / m_i) T_{i+1}
//!     = l_i |u̇_i|² + u_i · (a°_i − a°_{i−1})                                  (1/m_0 = 0)
//! ```
//! a symmetric positive definite tridiagonal system `A T = b` (`A = G M⁻¹ Gᵀ` with `G` the
//! rods' constraint Jacobian, full rank). One elimination pass down the chain and one
//! back-substitution pass up it give the tensions, the mass accelerations and
//! `ü_i = (a_i − a_{i−1}) / l_i`: O(n) work, one division per rod, no trigonometry.
//!
//! With `d_i = A_ii` and `c_i = A_{i,i−1}` (`c_1 = 0`), Gaussian elimination has the
//! pivots `D_i = d_i − c_i² / D_{i−1}`, a division on the serial chain of every rod. The
//! down pass computes them instead as ratios of continuants (the leading principal minors
//! of `A`, all positive):
//! ```text
//! P_i = d_i P_{i−1} − c_i² P_{i−2}      (P_0 = 1),      1/D_i = P_{i−1} / P_i
//! f_i = c_i / D_{i−1},   e_i = b_i − f_i e_{i−1},   h_i = e_i / D_i
//! ```
//! so each serial chain (`P`, `e`) is one multiply and one subtraction per rod and the
//! divisions are independent of each other. `P` grows or shrinks geometrically; every 16
//! rods both `P_{i−1}` and `P_{i−2}` are multiplied by the power of two that brings
//! `P_{i−1}` into `[1, 2)` (exact, and the ratios are unchanged). Should a continuant
//! still leave `[2⁻⁸⁰⁰, 2⁸⁰⁰]` (pivots beyond `2^±48` for 16 rods in a row: masses far
//! outside `1e-6 … 1e6` kg), the pivots are redone the classical way
//! from the stored `b_i`. The up pass is `T_n = h_n`, `T_i = h_i − f_{i+1} T_{i+1}`: one
//! multiply and one subtraction per rod on its chain.
//!
//! This is the same physics as the Lagrangian models (`reference/`): the tests in
//! `tests/tests/large_chains.rs` compare it with the dense route to round-off.
use std::cell::RefCell;

use crate::lanes::{Aligned, Lane};

mod angle_jacobians;
mod angles;
mod green;
mod solve;
mod tangent;

pub(crate) use angle_jacobians::state_rows;
pub use angles::PlanarTangents;
pub(crate) use angles::{Columns, Link, solve as solve_in_angles};
pub(crate) use green::{Column, RowsRoom, unit};
pub(crate) use tangent::{Linearised, LoadTangent, TangentRow};

/// Per-chain constants of the solve: reciprocal masses and lengths, and the drag
/// coefficients `λ_i / l_i` the models use to build the force pairs; for `V` = [`Lanes`](crate::lanes::Lanes)
/// those of `W` chains side by side.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Rods<V: Lane = f64> {
    inverse_mass: Aligned<V>,
    inverse_length: Aligned<V>,
    length: Aligned<V>,
    drag: Aligned<V>,
}

/// A chain's per-link constants as the tension solve reads them, `n` entries each:
/// `1/m_i` (1/kg), `l_i` (m), `1/l_i` (1/m) and the drag `λ_i/l_i` (N·s); with `V` =
/// [`Lanes`](crate::lanes::Lanes), those of `W` chains side by side.
#[derive(Debug)]
pub struct RodConstants<'a, V = f64> {
    pub inverse_mass: &'a [V],
    pub length: &'a [V],
    pub inverse_length: &'a [V],
    pub drag: &'a [V],
}

// By hand: a derive would ask `V: Copy`, which the slices do not need.
impl<V> Clone for RodConstants<'_, V> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<V> Copy for RodConstants<'_, V> {}

/// The pull on planar rod `i` (N), `f_i = Q_i/l_i − (λ_i/l_i) θ̇_i`, from the joint torque
/// `Q_i` (N·m), `1/l_i`, the drag `λ_i/l_i` (N·s) and the rate `θ̇_i` (rad/s); linear, so
/// also its change along `(δQ, δθ̇)`.
#[inline(always)]
pub(crate) fn pull<V: Lane>(torque: V, inverse_length: V, drag: V, rate: V) -> V {
    torque * inverse_length - drag * rate
}

/// [`pull`] of a chain without torques, as the model forms it then: `−(λ_i/l_i) θ̇_i`
/// (the same number but for the sign of a zero).
#[inline(always)]
pub(crate) fn damping_pull<V: Lane>(drag: V, rate: V) -> V {
    -drag * rate
}

/// What the solve needs to know of rod `i`: its direction `u_i`, `|u̇_i|²` (1/s²) and the
/// force pair `F_i` (N) acting on it (on mass `i`; the opposite on mass `i−1`).
/// Where the solve reads rod `i`'s [`Load`]: a closure, or a type whose `#[inline(always)]`
/// method builds the load where it is read (a closure called from two places was compiled
/// apart from the lanes' kernel, without its target features).
pub(crate) trait Loads<const S: usize, V: Lane> {
    /// Rod `i`'s load.
    fn load(&mut self, i: usize) -> Load<S, V>;
}

impl<const S: usize, V: Lane, F: FnMut(usize) -> Load<S, V>> Loads<S, V> for F {
    #[inline(always)]
    fn load(&mut self, i: usize) -> Load<S, V> {
        self(i)
    }
}

#[derive(Debug, Clone, Copy)]
pub(crate) struct Load<const S: usize, V: Lane = f64> {
    pub direction: [V; S],
    pub rate_squared: V,
    pub pair: [V; S],
}

/// What the down pass leaves for the up pass, per rod: the direction `u_i`, the free
/// acceleration `a°_i` of the mass (m/s²), the elimination factor `f_i = c_i / D_{i−1}`, the
/// scaled eliminated right-hand side `h_i = e_i / D_i` (N) and the right-hand side `b_i`
/// itself (kept for [`Rods::eliminate_by_pivots`]).
#[derive(Debug, Clone, Copy)]
struct Row<const S: usize, V: Lane = f64> {
    direction: [V; S],
    free: [V; S],
    factor: V,
    scaled: V,
    rhs: V,
}

/// The rows the down pass leaves for the up pass (see [`Rods::solve`]).
#[derive(Debug)]
pub(crate) struct Rows<const S: usize, V: Lane = f64>(Aligned<Row<S, V>>);

impl<const S: usize, V: Lane> Default for Rows<S, V> {
    fn default() -> Self {
        Self(Aligned::new())
    }
}

impl<const S: usize, V: Lane> Rows<S, V> {
    /// Room for `n` rods.
    pub fn with_len(n: usize) -> Self {
        let zero = V::splat(0.0);
        Self(Aligned::filled(
            Row { direction: [zero; S], free: [zero; S], factor: zero, scaled: zero, rhs: zero },
            n,
        ))
    }
}

/// The per-rod buffers of one solve (allocated once per thread, see [`with_scratch`]):
/// the solve's rows, and room for a model to prepare `(sin θ_i, cos θ_i)` and the rods'
/// [`Load`]s in passes of their own before the solve ([`Scratch::staging`]).
#[derive(Debug, Default)]
pub(crate) struct Scratch<const S: usize> {
    pub rows: Rows<S>,
    sin_cos: Vec<[f64; 2]>,
    loads: Vec<Load<S>>,
}

impl<const S: usize> Scratch<S> {
    /// Room for `n` rods' `(sin θ_i, cos θ_i)` and [`Load`]s (grown on first use, so models
    /// that build their loads inside the solve pay nothing for it), and the solve's rows.
    pub fn staging(&mut self, n: usize) -> (&mut [[f64; 2]], &mut [Load<S>], &mut Rows<S>) {
        if self.loads.len() < n {
            self.sin_cos.resize(n, [0.0; 2]);
            self.loads.resize(n, Load { direction: [0.0; S], rate_squared: 0.0, pair: [0.0; S] });
        }
        (&mut self.sin_cos[..n], &mut self.loads[..n], &mut self.rows)
    }
}

thread_local! {
    static PLANAR: RefCell<Scratch<2>> = RefCell::new(Scratch::default());
    static SPATIAL: RefCell<Scratch<3>> = RefCell::new(Scratch::default());
}

/// Runs `f` with this thread's scratch for `S`-dimensional chains, sized for `n` rods.
///
/// The buffer lives as long as the thread and only grows, so evaluations after the first
/// allocate nothing. Not re-entrant: `f` must not call back into a solve.
pub(crate) fn with_scratch<const S: usize, R>(n: usize, f: impl FnOnce(&mut Scratch<S>) -> R) -> R {
    fn run<const S: usize, R>(
        cell: &RefCell<Scratch<S>>,
        n: usize,
        f: impl FnOnce(&mut Scratch<S>) -> R,
    ) -> R {
        let mut scratch = cell.borrow_mut();
        if scratch.rows.0.len() < n {
            let row = Row { direction: [0.0; S], free: [0.0; S], factor: 0.0, scaled: 0.0, rhs: 0.0 };
            scratch.rows.0.resize(n, row);
        }
        f(&mut scratch)
    }
    match S {
        // S == 2 here, so Scratch<S> and Scratch<2> are one type and the downcast holds.
        2 => PLANAR.with(|cell| {
            let cell: &RefCell<Scratch<S>> = (cell as &dyn std::any::Any).downcast_ref().expect("S = 2");
            run(cell, n, f)
        }),
        3 => SPATIAL.with(|cell| {
            let cell: &RefCell<Scratch<S>> = (cell as &dyn std::any::Any).downcast_ref().expect("S = 3");
            run(cell, n, f)
        }),
        _ => run(&RefCell::new(Scratch::default()), n, f),
    }
}

#[inline(always)]
fn dot<const S: usize, V: Lane>(a: &[V; S], b: &[V; S]) -> V {
    let mut s = V::splat(0.0);
    for k in 0..S {
        s += a[k] * b[k];
    }
    s
}

/// Row `i` of the tridiagonal system `A T = b` (module docs): the diagonal entry
/// `A_ii = (1/m_i + 1/m_{i−1}) |u_i|²` and the entry `c_i = A_{i,i−1} = −(u_{i−1}·u_i)/m_{i−1}`
/// (1/kg), from `1/m_i`, `1/m_{i−1}` (0 for the first rod) and the directions.
///
/// `|u_i|²` is 1 on the constraint manifold; keeping it makes `u_i·ü_i = −|u̇_i|²` hold
/// exactly also at the slightly non-unit directions inside an integrator step.
#[inline(always)]
fn entries<const S: usize, V: Lane>(
    inverse_mass: V,
    inverse_mass_above: V,
    u_above: &[V; S],
    u: &[V; S],
) -> (V, V) {
    ((inverse_mass + inverse_mass_above) * dot(u, u), -dot(u_above, u) * inverse_mass_above)
}

pub use crate::lanes::CONTINUANT_RANGE;

/// The pivots `1/D_i` of a tridiagonal elimination as ratios of continuants (module docs),
/// row by row: one multiply and one subtraction per row on the serial chain, the division
/// off it; both continuants multiplied every [`Lane::RESCALE_ROWS`] rows by the power of two that brings
/// `P_{i−1}` into `[1, 2)`. The pivots are valid in the lanes not flagged by
/// [`outside`](Self::outside).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Continuants<V: Lane = f64> {
    /// `P_{i−1}`, `P_{i−2}` (`P_{−1} = 1`; `P_{−2}` only meets `c_0 = 0`).
    above: V,
    above2: V,
    /// The smallest and the largest `P_i` so far ([`Lane::widen`]). A NaN `P_i` makes every
    /// later one NaN (the recurrence multiplies it), so the range ends NaN; the range
    /// checked once at the end flags the lanes that one check per row would (flags kept
    /// row by row were five instructions a row, the range two).
    range: [V; 2],
}

impl<V: Lane> Continuants<V> {
    pub fn new() -> Self {
        let range = [V::splat(f64::INFINITY), V::splat(f64::NEG_INFINITY)];
        Self { above: V::splat(1.0), above2: V::splat(0.0), range }
    }

    /// `1/D_i` of row `i` (rows in order from 0) with `A_ii = diagonal`, `A_{i,i−1} = off`.
    #[inline(always)]
    pub fn inverse_pivot(&mut self, i: usize, diagonal: V, off: V) -> V {
        if i.is_multiple_of(V::RESCALE_ROWS) {
            let scale = self.above.normalizer();
            self.above = self.above * scale;
            self.above2 = self.above2 * scale;
        }
        let p = diagonal * self.above - (off * off) * self.above2;
        self.range = p.widen(self.range);
        let inverse_pivot = self.above / p;
        (self.above2, self.above) = (self.above, p);
        inverse_pivot
    }

    /// The lanes whose continuants left their precision's range ([`Lane::continuant_outside`])
    /// at some row so far.
    pub fn outside(&self) -> V::Mask {
        V::range_outside(self.range)
    }
}
