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

/// What the solve needs about the state and the applied forces, per rod.
pub(crate) struct Loads<'a, const S: usize> {
    /// Unit rod directions `u_i`.
    pub directions: &'a [[f64; S]],
    /// `|u̇_i|²` (1/s²).
    pub rate_squared: &'a [f64],
    /// Force pairs `F_i` (N) acting on rod `i` (on mass `i`; the opposite on mass `i−1`).
    pub pairs: &'a [[f64; S]],
    /// Gravity vector `g⃗` (m/s²).
    pub gravity: [f64; S],
    /// Pivot acceleration `p̈` (m/s²).
    pub pivot_acceleration: [f64; S],
}

/// Scratch of one solve: the elimination's pivots and right-hand sides, the free
/// accelerations and the tensions.
#[derive(Debug, Default)]
pub(crate) struct Scratch<const S: usize> {
    free: Vec<[f64; S]>,
    coupling: Vec<f64>,
    inverse_pivot: Vec<f64>,
    eliminated: Vec<f64>,
    tension: Vec<f64>,
    /// Per-rod buffers for the callers: directions, rates squared, force pairs and the
    /// direction accelerations.
    pub directions: Vec<[f64; S]>,
    pub rate_squared: Vec<f64>,
    pub pairs: Vec<[f64; S]>,
    pub direction_accelerations: Vec<[f64; S]>,
}

impl<const S: usize> Scratch<S> {
    /// Sizes every buffer for `n` rods (allocates only when `n` grows).
    pub fn resize(&mut self, n: usize) {
        self.free.resize(n, [0.0; S]);
        self.coupling.resize(n, 0.0);
        self.inverse_pivot.resize(n, 0.0);
        self.eliminated.resize(n, 0.0);
        self.tension.resize(n, 0.0);
        self.directions.resize(n, [0.0; S]);
        self.rate_squared.resize(n, 0.0);
        self.pairs.resize(n, [0.0; S]);
        self.direction_accelerations.resize(n, [0.0; S]);
    }

    /// The rod tensions `T_i` (N) of the last solve.
    pub fn tensions(&self) -> &[f64] {
        &self.tension
    }
}

thread_local! {
    static PLANAR: RefCell<Scratch<2>> = RefCell::new(Scratch::default());
    static SPATIAL: RefCell<Scratch<3>> = RefCell::new(Scratch::default());
}

/// Runs `f` with this thread's scratch for `S`-dimensional chains, sized for `n` rods.
///
/// The buffers live as long as the thread and only grow, so evaluations after the first
/// allocate nothing. Not re-entrant: `f` must not call back into a solve.
pub(crate) fn with_scratch<const S: usize, R>(n: usize, f: impl FnOnce(&mut Scratch<S>) -> R) -> R {
    fn run<const S: usize, R>(
        cell: &RefCell<Scratch<S>>,
        n: usize,
        f: impl FnOnce(&mut Scratch<S>) -> R,
    ) -> R {
        let mut scratch = cell.borrow_mut();
        scratch.resize(n);
        f(&mut scratch)
    }
    // Dispatch on S by the size of the scratch type: S is 2 or 3 in this crate.
    match S {
        2 => PLANAR.with(|cell| {
            // S == 2 here, so Scratch<S> and Scratch<2> are one type and the downcast holds.
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

    /// Solves for the tensions and writes the direction accelerations `ü_i` (1/s²) into
    /// `scratch.direction_accelerations`, reading the loads from `scratch.directions`,
    /// `scratch.rate_squared` and `scratch.pairs` (each `n` long).
    pub fn solve_in_place<const S: usize>(
        &self,
        gravity: [f64; S],
        pivot_acceleration: [f64; S],
        scratch: &mut Scratch<S>,
    ) {
        let Scratch {
            free,
            coupling,
            inverse_pivot,
            eliminated,
            tension,
            directions,
            rate_squared,
            pairs,
            direction_accelerations,
        } = scratch;
        let loads = Loads { directions, rate_squared, pairs, gravity, pivot_acceleration };
        self.solve(&loads, free, coupling, inverse_pivot, eliminated, tension, direction_accelerations);
    }

    /// The two passes of the tension solve (module docs).
    #[allow(clippy::too_many_arguments)]
    fn solve<const S: usize>(
        &self,
        loads: &Loads<'_, S>,
        free: &mut [[f64; S]],
        coupling: &mut [f64],
        inverse_pivot: &mut [f64],
        eliminated: &mut [f64],
        tension: &mut [f64],
        out: &mut [[f64; S]],
    ) {
        let n = self.len();
        let u = loads.directions;
        // Down the chain: free accelerations, right-hand sides, elimination.
        let mut free_above = loads.pivot_acceleration;
        let mut inverse_mass_above = 0.0;
        let mut pivot_above = 0.0; // 1 / (pivot of the row above)
        let mut eliminated_above = 0.0;
        for i in 0..n {
            let im = self.inverse_mass[i];
            let mut a = loads.gravity;
            let below = if i + 1 < n { loads.pairs[i + 1] } else { [0.0; S] };
            for k in 0..S {
                a[k] += (loads.pairs[i][k] - below[k]) * im;
            }
            let mut rhs = self.length[i] * loads.rate_squared[i];
            for k in 0..S {
                rhs += u[i][k] * (a[k] - free_above[k]);
            }
            // |u_i|² is 1 on the constraint manifold; keeping it makes u_i·ü_i = −|u̇_i|²
            // hold exactly also at the slightly non-unit directions inside an integrator step.
            let diagonal = (im + inverse_mass_above) * dot(&u[i], &u[i]);
            // Off-diagonal entry between rods i−1 and i: −(u_{i−1}·u_i)/m_{i−1}.
            let off = if i == 0 { 0.0 } else { -dot(&u[i - 1], &u[i]) * inverse_mass_above };
            let factor = off * pivot_above;
            let pivot = diagonal - factor * off;
            let e = rhs - factor * eliminated_above;
            let inv = 1.0 / pivot;
            free[i] = a;
            coupling[i] = off;
            inverse_pivot[i] = inv;
            eliminated[i] = e;
            free_above = a;
            inverse_mass_above = im;
            pivot_above = inv;
            eliminated_above = e;
        }
        // Up the chain: tensions, mass accelerations, direction accelerations.
        let mut tension_below = 0.0;
        let mut coupling_below = 0.0;
        let mut u_below = [0.0; S];
        let mut a_below = [0.0; S];
        for i in (0..n).rev() {
            let t = (eliminated[i] - coupling_below * tension_below) * inverse_pivot[i];
            tension[i] = t;
            let im = self.inverse_mass[i];
            let mut a = free[i];
            for k in 0..S {
                a[k] += (tension_below * u_below[k] - t * u[i][k]) * im;
            }
            if i + 1 < n {
                let il = self.inverse_length[i + 1];
                for k in 0..S {
                    out[i + 1][k] = (a_below[k] - a[k]) * il;
                }
            }
            tension_below = t;
            coupling_below = coupling[i];
            u_below = u[i];
            a_below = a;
        }
        let il = self.inverse_length[0];
        for k in 0..S {
            out[0][k] = (a_below[k] - loads.pivot_acceleration[k]) * il;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hanging_chain_carries_the_weight_below_each_rod() {
        let masses = [1.0, 2.0, 0.5];
        let rods = Rods::new(&masses, &[1.0, 0.5, 2.0]);
        let g = 9.81;
        with_scratch::<2, _>(3, |s| {
            s.directions.fill([0.0, -1.0]);
            s.rate_squared.fill(0.0);
            s.pairs.fill([0.0; 2]);
            rods.solve_in_place([0.0, -g], [0.0; 2], s);
            let expected = [3.5 * g, 2.5 * g, 0.5 * g];
            for (t, e) in s.tensions().iter().zip(expected) {
                assert!((t - e).abs() < 1e-12 * e, "{t} vs {e}");
            }
            assert!(s.direction_accelerations.iter().flatten().all(|a| a.abs() < 1e-12));
        });
    }

    #[test]
    fn spinning_single_rod_pulls_with_the_centripetal_force() {
        // One mass m on a rod l turning at ω without gravity: T = m l ω², ü = −ω² u.
        let (m, l, w) = (2.0, 0.5, 3.0);
        let rods = Rods::new(&[m], &[l]);
        with_scratch::<3, _>(1, |s| {
            s.directions[0] = [1.0, 0.0, 0.0];
            s.rate_squared[0] = w * w;
            s.pairs[0] = [0.0; 3];
            rods.solve_in_place([0.0; 3], [0.0; 3], s);
            assert!((s.tensions()[0] - m * l * w * w).abs() < 1e-12);
            assert!((s.direction_accelerations[0][0] + w * w).abs() < 1e-12);
        });
    }
}
