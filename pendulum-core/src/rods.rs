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
//! This is the same physics as the Lagrangian models (`reference/`): the tests in
//! `tests/tests/large_chains.rs` compare it with the dense route to round-off.
use std::cell::RefCell;

/// Per-chain constants of the solve: reciprocal masses and lengths.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Rods {
    inverse_mass: Vec<f64>,
    inverse_length: Vec<f64>,
    length: Vec<f64>,
}

/// What the solve needs to know of rod `i`: its direction `u_i`, `|u̇_i|²` (1/s²) and the
/// force pair `F_i` (N) acting on it (on mass `i`; the opposite on mass `i−1`).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Load<const S: usize> {
    pub direction: [f64; S],
    pub rate_squared: f64,
    pub pair: [f64; S],
}

/// What the down pass leaves for the up pass, per rod: the direction, the free
/// acceleration of the mass, the coupling to the rod above, the reciprocal pivot and the
/// eliminated right-hand side of the tridiagonal system.
#[derive(Debug, Clone, Copy)]
struct Row<const S: usize> {
    direction: [f64; S],
    free: [f64; S],
    coupling: f64,
    inverse_pivot: f64,
    eliminated: f64,
}

/// The per-rod buffer of one solve (allocated once per thread, see [`with_scratch`]).
#[derive(Debug, Default)]
pub(crate) struct Scratch<const S: usize> {
    rows: Vec<Row<S>>,
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
        if scratch.rows.len() < n {
            scratch.rows.resize(
                n,
                Row {
                    direction: [0.0; S],
                    free: [0.0; S],
                    coupling: 0.0,
                    inverse_pivot: 0.0,
                    eliminated: 0.0,
                },
            );
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
fn dot<const S: usize>(a: &[f64; S], b: &[f64; S]) -> f64 {
    let mut s = 0.0;
    for k in 0..S {
        s += a[k] * b[k];
    }
    s
}

impl Rods {
    /// The constants of a chain with these masses (kg) and lengths (m), both positive.
    pub fn new(masses: &[f64], lengths: &[f64]) -> Self {
        Self {
            inverse_mass: masses.iter().map(|m| 1.0 / m).collect(),
            inverse_length: lengths.iter().map(|l| 1.0 / l).collect(),
            length: lengths.to_vec(),
        }
    }

    /// Number of rods.
    pub fn len(&self) -> usize {
        self.length.len()
    }

    /// The tension solve (module docs) in two fused passes.
    ///
    /// `load(i)` gives rod `i`'s [`Load`] (called once per rod, in order `0, 1, …`);
    /// `emit(i, ü_i, u_i, T_i)` receives rod `i`'s direction acceleration (1/s²), its
    /// direction and its tension (N), once per rod in order `n−1, …, 0`. Gravity `g⃗` and
    /// the pivot acceleration `p̈` in m/s². Work O(n), one division per rod, and one
    /// buffer row of `2S + 3` numbers per rod, so long chains stay in cache.
    #[inline(always)]
    pub fn solve<const S: usize>(
        &self,
        gravity: [f64; S],
        pivot_acceleration: [f64; S],
        scratch: &mut Scratch<S>,
        mut load: impl FnMut(usize) -> Load<S>,
        mut emit: impl FnMut(usize, [f64; S], &[f64; S], f64),
    ) {
        let n = self.len();
        let rows = &mut scratch.rows[..n];
        // Down the chain: free accelerations, right-hand sides, elimination.
        let mut free_above = pivot_acceleration;
        let mut inverse_mass_above = 0.0;
        let mut pivot_above = 0.0; // 1 / (pivot of the row above)
        let mut eliminated_above = 0.0;
        let mut u_above = [0.0; S];
        let mut here = load(0);
        for (i, row) in rows.iter_mut().enumerate() {
            let below = if i + 1 < n { Some(load(i + 1)) } else { None };
            let pair_below = below.map_or([0.0; S], |b| b.pair);
            let im = self.inverse_mass[i];
            let u = here.direction;
            let mut a = gravity;
            let mut rhs = self.length[i] * here.rate_squared;
            for k in 0..S {
                a[k] += (here.pair[k] - pair_below[k]) * im;
                rhs += u[k] * (a[k] - free_above[k]);
            }
            // |u_i|² is 1 on the constraint manifold; keeping it makes u_i·ü_i = −|u̇_i|²
            // hold exactly also at the slightly non-unit directions inside an integrator step.
            let diagonal = (im + inverse_mass_above) * dot(&u, &u);
            // Off-diagonal entry between rods i−1 and i: −(u_{i−1}·u_i)/m_{i−1}.
            let off = -dot(&u_above, &u) * inverse_mass_above;
            let factor = off * pivot_above;
            let inverse_pivot = 1.0 / (diagonal - factor * off);
            let eliminated = rhs - factor * eliminated_above;
            *row = Row { direction: u, free: a, coupling: off, inverse_pivot, eliminated };
            free_above = a;
            inverse_mass_above = im;
            pivot_above = inverse_pivot;
            eliminated_above = eliminated;
            u_above = u;
            if let Some(b) = below {
                here = b;
            }
        }
        // Up the chain: tensions, mass accelerations, direction accelerations.
        let mut tension_below = 0.0;
        let mut coupling_below = 0.0;
        let mut u_below = [0.0; S];
        let mut a_below = [0.0; S];
        for i in (0..n).rev() {
            let row = &rows[i];
            let t = (row.eliminated - coupling_below * tension_below) * row.inverse_pivot;
            let im = self.inverse_mass[i];
            let mut a = row.free;
            for k in 0..S {
                a[k] += (tension_below * u_below[k] - t * row.direction[k]) * im;
            }
            if i + 1 < n {
                let il = self.inverse_length[i + 1];
                let mut udd = [0.0; S];
                for k in 0..S {
                    udd[k] = (a_below[k] - a[k]) * il;
                }
                emit(i + 1, udd, &u_below, tension_below);
            }
            tension_below = t;
            coupling_below = row.coupling;
            u_below = row.direction;
            a_below = a;
        }
        let il = self.inverse_length[0];
        let mut udd = [0.0; S];
        for k in 0..S {
            udd[k] = (a_below[k] - pivot_acceleration[k]) * il;
        }
        emit(0, udd, &u_below, tension_below);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Solves for `n` rods with the given directions, rates and pairs; returns (ü, T).
    fn solve<const S: usize>(rods: &Rods, gravity: [f64; S], loads: &[Load<S>]) -> (Vec<[f64; S]>, Vec<f64>) {
        let n = loads.len();
        let (mut udd, mut tension) = (vec![[0.0; S]; n], vec![0.0; n]);
        with_scratch::<S, _>(n, |s| {
            rods.solve(
                gravity,
                [0.0; S],
                s,
                |i| loads[i],
                |i, a, _, t| {
                    udd[i] = a;
                    tension[i] = t;
                },
            )
        });
        (udd, tension)
    }

    #[test]
    fn hanging_chain_carries_the_weight_below_each_rod() {
        let rods = Rods::new(&[1.0, 2.0, 0.5], &[1.0, 0.5, 2.0]);
        let g = 9.81;
        let hanging = Load { direction: [0.0, -1.0], rate_squared: 0.0, pair: [0.0; 2] };
        let (udd, tension) = solve(&rods, [0.0, -g], &[hanging; 3]);
        for (t, e) in tension.iter().zip([3.5 * g, 2.5 * g, 0.5 * g]) {
            assert!((t - e).abs() < 1e-12 * e, "{t} vs {e}");
        }
        assert!(udd.iter().flatten().all(|a| a.abs() < 1e-12));
    }

    #[test]
    fn spinning_single_rod_pulls_with_the_centripetal_force() {
        // One mass m on a rod l turning at ω without gravity: T = m l ω², ü = −ω² u.
        let (m, l, w) = (2.0, 0.5, 3.0);
        let rods = Rods::new(&[m], &[l]);
        let load = Load { direction: [1.0, 0.0, 0.0], rate_squared: w * w, pair: [0.0; 3] };
        let (udd, tension) = solve(&rods, [0.0; 3], &[load]);
        assert!((tension[0] - m * l * w * w).abs() < 1e-12);
        assert!((udd[0][0] + w * w).abs() < 1e-12);
    }
}
