//! An implicit step for long chains: the midpoint rule on the masses with the rods as
//! exact constraints, one block-tridiagonal Newton solve per iteration, `O(n)`.
//!
//! Explicit methods are held to `h ≲ 3/ω_max` by the chain's fastest modes
//! (`ω_max ≈ 2n √(g/L)` for a uniform chain: 6.3e3 rad/s at n = 1000, L = 1 m), which
//! matter little to the shape the chain takes. This step is stable at any `h`, conserves
//! the energy of a free undamped chain exactly (to the Newton tolerance) and closes the
//! drive and damping ledger exactly, so it can step over those modes; it does not resolve
//! them (their frequencies come out too low), and it is of order 2.

use nalgebra::{DefaultAllocator, DimName, allocator::Allocator};

use crate::chain::Chain;
use crate::drive::Drive;
use crate::energy::Accounted;
use crate::energy::ledger::LEDGER_LEN;
use crate::error::{Error, Result};
use crate::integrate::{Integrator, State, Stats};
use crate::models::directions::Directions;
use newton::{LinkRow, Pivot};

mod newton;

/// The energy-conserving midpoint step of a chain of point masses on rigid rods
/// (Gonzalez, *Mechanical systems subject to holonomic constraints*, 1999), on the mass
/// positions `x_i` and velocities `v_i` with the rod multipliers `μ_i` as unknowns:
/// ```text
/// x⁺_i − x_i = h v̄_i,    v̄_i = (v_i + v⁺_i)/2
/// m_i (v⁺_i − v_i)/h = m_i g⃗ + F_i − F_{i+1} + μ_{i+1} d_{i+1} − μ_i d_i
/// |x⁺_i − x⁺_{i−1}| = l_i                         (x_0 = p(t), x⁺_0 = p(t + h))
/// ```
/// with `d_i = x̄_i − x̄_{i−1}` the rod at the step's midpoint (`x̄ = (x + x⁺)/2`) and
/// `F_i = −(λ_i/l_i²)(v̄_i − v̄_{i−1})` rod `i`'s damping pair (`v̄_0 = (p(t+h) − p(t))/h`).
/// Because the rod constraints are quadratic, `d_i·(x⁺_i − x⁺_{i−1} − x_i + x_{i−1})`
/// is exactly the change of `½|x_i − x_{i−1}|²`, zero; so the step changes the inertial
/// energy `H = Σ ½ m_i |v_i|² + m_i g z_i` by exactly
/// ```text
/// ΔH = (F_1 − μ_1 d_1)·(p(t+h) − p(t))  −  h Σ λ_i |v̄_i − v̄_{i−1}|² / l_i²
///      (work of the pivot)                (damping loss)
/// ```
/// which is what it adds to an [`Accounted`] ledger (that impl is in
/// `energy/ledger.rs`): the balance closes to the Newton
/// tolerance and round-off at any step size.
///
/// Each Newton iteration assembles the Newton matrix link by link (link `i`'s position and
/// multiplier) and eliminates it in `O(n)` (`newton`). Start: the rods turned by `h w_i` and the
/// multipliers `T_i/l_i` of the tensions at `t`. A step in which a link would turn by more
/// than 1 rad, or whose Newton iteration does not converge in 12 iterations, is taken as
/// two halves (up to 10 times nested). The state is the [`Directions`] state `(u, w)`
/// (`u_i = (x_i − x_{i−1})/l_i`, `w_i = (v_i − v_{i−1})/l_i` with `v_0 = ṗ`), which this
/// step keeps on `|u_i| = 1` by construction; the rates are not projected (`u_i·w_i` is
/// of the size of the step's error), since that would change the energy outside the
/// ledger. So use it bare, not inside [`Projected`](crate::integrate::Projected).
#[derive(Debug, Clone)]
pub struct RodMidpoint {
    stats: Stats,
    tolerance: f64,
    max_iterations: usize,
    planar: Work<2>,
    spatial: Work<3>,
}

/// The Newton matrix's rows and its elimination's pivots, in `C` dimensions: buffers kept
/// from step to step.
#[derive(Debug, Clone, Default)]
struct Work<const C: usize> {
    rows: Vec<LinkRow<C>>,
    pivots: Vec<Pivot<C>>,
}

impl Default for RodMidpoint {
    fn default() -> Self {
        Self::new()
    }
}

/// The most a link may turn in one step, rad (`h |w_i|`); a longer step is halved before
/// it is tried. The midpoint rod `d_i` is the chord of the turn and vanishes at a half
/// turn, where the Newton matrix becomes singular; a whipping free end gets there.
const MAX_TURN: f64 = 1.0;

/// How deep a step may be halved (a half of a half …) before its failure is an error.
const MAX_HALVINGS: u32 = 10;

/// What one converged step produced, besides the new state.
#[derive(Debug, Default)]
pub(crate) struct StepWork {
    /// The pivot's work, J.
    pub(crate) drive: f64,
    /// The damping loss, J.
    pub(crate) damped: f64,
}

impl RodMidpoint {
    /// The step with its Newton iteration converged to `1e-13` of the chain's reach
    /// (`Σ l_i`) per position, at most 12 iterations; a step in which a link would turn by
    /// more than `MAX_TURN`, or whose iteration does not converge, is taken as two halves
    /// (up to `MAX_HALVINGS` times nested).
    pub fn new() -> Self {
        Self {
            stats: Stats::default(),
            tolerance: 1e-13,
            max_iterations: 12,
            planar: Work::default(),
            spatial: Work::default(),
        }
    }

    /// What the step has done so far: steps, Newton iterations and factorisations.
    pub fn stats(&self) -> &Stats {
        &self.stats
    }

    /// Advances the motion part `(u, w)` of a state by `h`, writing it into `out`, and
    /// returns the pivot's work and the damping loss of the step.
    pub(crate) fn advance<S: DimName, Dr: Drive<S>>(
        &mut self,
        chain: &Directions<S, Dr>,
        t: f64,
        motion: &[f64],
        h: f64,
        out: &mut [f64],
    ) -> Result<StepWork>
    where
        DefaultAllocator: Allocator<S>,
    {
        chain.check_state_slice(motion)?;
        if !(h.is_finite() && h != 0.0) {
            return Err(Error::InvalidStepSize { h });
        }
        if S::DIM != 2 && S::DIM != 3 {
            return Err(Error::LengthMismatch { what: "space", expected: 3, got: S::DIM });
        }
        match self.attempt(chain, t, motion, h, out, 0) {
            Ok(work) => {
                self.stats.steps += 1;
                Ok(work)
            }
            Err(iterations) => {
                self.stats.failed_steps += 1;
                Err(Error::StageSolveFailed { t, h, iterations })
            }
        }
    }

    /// One step, split into two halves (recursively, at most [`MAX_HALVINGS`] deep) when
    /// its Newton iteration does not converge. Errors: the iterations spent.
    fn attempt<S: DimName, Dr: Drive<S>>(
        &mut self,
        chain: &Directions<S, Dr>,
        t: f64,
        motion: &[f64],
        h: f64,
        out: &mut [f64],
        depth: u32,
    ) -> std::result::Result<StepWork, usize>
    where
        DefaultAllocator: Allocator<S>,
    {
        let n = chain.links();
        // A link turning by more than MAX_TURN in the step: halve it without trying.
        let fastest = motion[S::DIM * n..]
            .chunks_exact(S::DIM)
            .map(|w| w.iter().map(|v| v * v).sum::<f64>())
            .fold(0.0, f64::max)
            .sqrt();
        if depth < MAX_HALVINGS && h.abs() * fastest > MAX_TURN {
            return self.halves(chain, t, motion, h, out, depth);
        }
        let drive = chain.drive();
        let ends = [drive.position(t), drive.position(t + h), drive.velocity(t), drive.velocity(t + h)];
        let limits = self.limits();
        // The multipliers' start: the tensions at t (the accelerations come with them).
        let mut start = vec![0.0; (S::DIM + 1) * n];
        let (accelerations, tensions) = start.split_at_mut(S::DIM * n);
        if chain.accelerations_of_valid(t, motion, accelerations, Some(tensions)).is_err() {
            return Err(0);
        }
        let start = Start { tensions };
        let result = match S::DIM {
            2 => {
                let ends = ends.map(|v| [v[0], v[1]]);
                newton::<2>(&mut self.planar, &start, chain.chain(), ends, motion, h, out, &limits)
            }
            _ => {
                let ends = ends.map(|v| [v[0], v[1], v[2]]);
                newton::<3>(&mut self.spatial, &start, chain.chain(), ends, motion, h, out, &limits)
            }
        };
        // One tension solve for the start; one factorisation per Newton iteration.
        let iterations = match &result {
            Ok((_, i)) | Err(i) => *i,
        };
        self.stats.rhs_evaluations += 1;
        self.stats.newton_iterations += iterations as u64;
        self.stats.factorizations += iterations as u64;
        match result {
            Ok((work, _)) => Ok(work),
            Err(iterations) if depth == MAX_HALVINGS => Err(iterations),
            Err(_) => self.halves(chain, t, motion, h, out, depth),
        }
    }

    /// The step as two halves, each an [`attempt`](Self::attempt) one level deeper.
    fn halves<S: DimName, Dr: Drive<S>>(
        &mut self,
        chain: &Directions<S, Dr>,
        t: f64,
        motion: &[f64],
        h: f64,
        out: &mut [f64],
        depth: u32,
    ) -> std::result::Result<StepWork, usize>
    where
        DefaultAllocator: Allocator<S>,
    {
        self.stats.halved_steps += 1;
        let mut middle = motion.to_vec();
        let first = self.attempt(chain, t, motion, 0.5 * h, &mut middle, depth + 1)?;
        let second = self.attempt(chain, t + 0.5 * h, &middle, 0.5 * h, out, depth + 1)?;
        Ok(StepWork { drive: first.drive + second.drive, damped: first.damped + second.damped })
    }

    fn limits(&self) -> Limits {
        Limits { tolerance: self.tolerance, max_iterations: self.max_iterations }
    }
}

/// The rod tensions `T_i` at the start of a step.
struct Start<'a> {
    tensions: &'a [f64],
}

struct Limits {
    tolerance: f64,
    max_iterations: usize,
}

/// `a − b`, `a·b` and the `i`-th `C`-vector of a flat slice.
fn sub<const C: usize>(a: [f64; C], b: [f64; C]) -> [f64; C] {
    std::array::from_fn(|k| a[k] - b[k])
}
fn dot<const C: usize>(a: [f64; C], b: [f64; C]) -> f64 {
    (0..C).map(|k| a[k] * b[k]).sum()
}
fn at<const C: usize>(v: &[f64], i: usize) -> [f64; C] {
    std::array::from_fn(|k| v[i * C + k])
}

/// The Newton iteration of one step in `C` dimensions. `ends`:
/// pivot position at `t` and `t + h`, velocity at `t` and `t + h`. Returns the step's
/// work and its Newton iterations (each one factorisation), or the iterations spent when
/// it did not converge.
#[allow(clippy::too_many_arguments)] // One step's data, all of it needed.
fn newton<const C: usize>(
    work: &mut Work<C>,
    start: &Start,
    chain: &Chain<nalgebra::Dyn>,
    ends: [[f64; C]; 4],
    motion: &[f64],
    h: f64,
    out: &mut [f64],
    limits: &Limits,
) -> std::result::Result<(StepWork, usize), usize> {
    let [p0, p1, pv0, pv1] = ends;
    let n = chain.links();
    let (m, l, lambda) = (chain.masses(), chain.lengths(), chain.damping());
    let mut gravity = [0.0; C];
    gravity[C - 1] = -chain.gravity();
    let reach: f64 = l.iter().sum::<f64>() + p0.iter().chain(&p1).fold(0.0_f64, |a, b| a.max(b.abs()));
    let (u, w) = motion.split_at(C * n);

    // Positions and velocities at t; the start of the iteration: each rod turned by h w_i
    // (with h²/2 ü_i too it took more iterations), the multipliers μ_i = T_i / l_i at t.
    let mut x0 = vec![0.0; C * n];
    let mut v0 = vec![0.0; C * n];
    let mut x1 = vec![0.0; C * n];
    let (mut r0, mut rv, mut r1) = (p0, pv0, p1);
    for i in 0..n {
        let (ui, wi) = (at::<C>(u, i), at::<C>(w, i));
        let turned: [f64; C] = std::array::from_fn(|k| ui[k] + h * wi[k]);
        let norm = dot(turned, turned).sqrt();
        for k in 0..C {
            r0[k] += l[i] * ui[k];
            rv[k] += l[i] * wi[k];
            r1[k] += l[i] * turned[k] / norm;
            x0[i * C + k] = r0[k];
            v0[i * C + k] = rv[k];
            x1[i * C + k] = r1[k];
        }
    }
    let mut mu: Vec<f64> = (0..n).map(|i| start.tensions[i] / l[i]).collect();
    // Rod i's damping pair per unit change of the rod vector, λ_i/(l_i² h), and mass i's
    // inertia term 2 m_i/h².
    let damping = |i: usize| lambda[i] / (l[i] * l[i] * h);
    let inertia = |i: usize| 2.0 * m[i] / (h * h);
    let pivot_step = sub(p1, p0);

    // Rod i's vectors: endpoint e_i, midpoint d_i, change of the rod vector s_i.
    let rod = |x1: &[f64], i: usize| -> ([f64; C], [f64; C], [f64; C]) {
        let (a0, a1) = if i == 0 { (p0, p1) } else { (at::<C>(&x0, i - 1), at::<C>(x1, i - 1)) };
        let (b0, b1) = (at::<C>(&x0, i), at::<C>(x1, i));
        let e = sub(b1, a1);
        let d = std::array::from_fn(|k| 0.5 * (b0[k] + b1[k] - a0[k] - a1[k]));
        let s = std::array::from_fn(|k| (b1[k] - b0[k]) - (a1[k] - a0[k]));
        (e, d, s)
    };

    // Newton's method, the matrix refactored at every iteration (a frozen matrix, tried,
    // took several times the iterations once the free end whips).
    let mut iterations = 0;
    let mut previous = f64::INFINITY;
    loop {
        if iterations == limits.max_iterations {
            return Err(iterations);
        }
        iterations += 1;
        // Residuals and the Newton matrix, link by link (`newton` module docs).
        let Work { rows, pivots } = &mut *work;
        rows.clear();
        let mut next = rod(&x1, 0);
        for i in 0..n {
            let (e, d, s) = next;
            let has_next = i + 1 < n;
            if has_next {
                next = rod(&x1, i + 1);
            }
            let (_, d_next, s_next) = next;
            let (mu_i, mu_next) = (mu[i], if has_next { mu[i + 1] } else { 0.0 });
            let (c_i, c_next) = (damping(i), if has_next { damping(i + 1) } else { 0.0 });
            let xi = at::<C>(&x1, i);
            let x0i = at::<C>(&x0, i);
            let v0i = at::<C>(&v0, i);
            let force: [f64; C] = std::array::from_fn(|k| {
                let mut r =
                    inertia(i) * (xi[k] - x0i[k] - h * v0i[k]) - m[i] * gravity[k] + c_i * s[k] + mu_i * d[k];
                if has_next {
                    r -= c_next * s_next[k] + mu_next * d_next[k];
                }
                -r
            });
            rows.push(LinkRow {
                stiffness: inertia(i) + c_i + c_next + 0.5 * (mu_i + mu_next),
                coupling: c_i + 0.5 * mu_i,
                midpoint: d,
                end: e,
                force,
                constraint: -0.5 * (dot(e, e) - l[i] * l[i]),
            });
        }
        if !newton::solve(rows, pivots) {
            return Err(iterations);
        }
        let mut largest: f64 = 0.0;
        for (i, row) in rows.iter().enumerate() {
            for k in 0..C {
                x1[i * C + k] += row.force[k];
                largest = largest.max(row.force[k].abs());
            }
            mu[i] += row.constraint;
        }
        if !largest.is_finite() {
            return Err(iterations);
        }
        // Newton converges quadratically: the error left after this correction is about
        // δ_k²/δ_{k−1} (or less), so stop once that is below the tolerance.
        if largest <= limits.tolerance * reach
            || (previous.is_finite() && largest * largest / previous <= limits.tolerance * reach)
        {
            break;
        }
        previous = largest;
    }

    // The new state and the step's work.
    let (u_out, w_out) = out.split_at_mut(C * n);
    let mut previous_velocity = pv1;
    let (_, d_first, s_first) = rod(&x1, 0);
    let pair_first: [f64; C] = std::array::from_fn(|k| -damping(0) * s_first[k]);
    let drive: f64 = (0..C).map(|k| (pair_first[k] - mu[0] * d_first[k]) * pivot_step[k]).sum();
    let mut damped = 0.0;
    for i in 0..n {
        let (e, _, s) = rod(&x1, i);
        damped += damping(i) * dot(s, s);
        let velocity: [f64; C] =
            std::array::from_fn(|k| 2.0 * (x1[i * C + k] - x0[i * C + k]) / h - v0[i * C + k]);
        for k in 0..C {
            u_out[i * C + k] = e[k] / l[i];
            w_out[i * C + k] = (velocity[k] - previous_velocity[k]) / l[i];
        }
        previous_velocity = velocity;
    }
    if !out.iter().all(|v| v.is_finite()) {
        return Err(iterations);
    }
    Ok((StepWork { drive, damped }, iterations))
}

impl<S: DimName, Dr: Drive<S>> Integrator<Directions<S, Dr>> for RodMidpoint
where
    DefaultAllocator: Allocator<S>,
{
    fn step(&mut self, system: &Directions<S, Dr>, state: &mut State<nalgebra::Dyn>, h: f64) -> Result<()> {
        let mut next = state.x().clone();
        self.advance(system, state.t(), state.x().as_slice(), h, next.as_mut_slice())?;
        let increment = next - state.x();
        state.advance(h, &increment);
        Ok(())
    }

    fn stats(&self) -> &Stats {
        &self.stats
    }
}

/// [`RodMidpoint`] with the ledger: the pivot's work and the damping loss of each step are added to
/// `W_drive` and `E_damped` exactly as the step changes the energy.
impl<S: DimName, Dr: Drive<S>> Integrator<Accounted<Directions<S, Dr>>> for RodMidpoint
where
    DefaultAllocator: Allocator<S>,
{
    fn step(
        &mut self,
        system: &Accounted<Directions<S, Dr>>,
        state: &mut State<nalgebra::Dyn>,
        h: f64,
    ) -> Result<()> {
        let len = system.motion_len();
        let x = state.x();
        if x.len() != len + LEDGER_LEN {
            return Err(Error::LengthMismatch { what: "x", expected: len + LEDGER_LEN, got: x.len() });
        }
        let mut next = x.clone();
        let work = self.advance(
            system.chain(),
            state.t(),
            &x.as_slice()[..len],
            h,
            &mut next.as_mut_slice()[..len],
        )?;
        let mut increment = next - x;
        increment[len] = work.drive;
        increment[len + 2] = work.damped;
        state.advance(h, &increment);
        Ok(())
    }

    fn stats(&self) -> &Stats {
        RodMidpoint::stats(self)
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::{DVector, U2, U3};

    use super::*;
    use crate::integrate::{Projected, Rk4};

    fn twisted(model: &Directions<U3, impl Drive<U3>>, n: usize, tilt: f64) -> DVector<f64> {
        let q: Vec<f64> = (0..2 * n)
            .map(|i| if i < n { tilt } else { std::f64::consts::PI * (i - n) as f64 / n as f64 })
            .collect();
        model.from_spherical(&q, &vec![0.0; 2 * n]).unwrap()
    }

    /// A free chain keeps its energy to round-off at a step 10× past RK4's limit.
    #[test]
    fn a_free_chain_keeps_its_energy_at_a_long_step() {
        let n = 40;
        let model = Directions::<U3>::new(Chain::uniform(n, 0.025, 0.025, 9.81).unwrap());
        let x0 = twisted(&model, n, 0.3);
        let e0 = model.energy(&x0);
        let mut solver = RodMidpoint::new();
        let mut state = State::new(0.0, x0);
        let mut worst: f64 = 0.0;
        for _ in 0..200 {
            solver.step(&model, &mut state, 0.02).unwrap();
            worst = worst.max((model.energy(state.x()) - e0).abs() / e0.abs());
        }
        assert!(worst < 1e-11, "{worst:e}");
        let rods = (0..n).map(|i| (model.direction(state.x(), i).norm() - 1.0).abs()).fold(0.0, f64::max);
        assert!(rods < 1e-12, "{rods:e}");
    }

    /// At a small step it agrees with RK4 to its order: a planar swing over 1 s.
    #[test]
    fn it_converges_to_the_exact_motion_at_order_two() {
        let model = Directions::<U2>::new(Chain::uniform(3, 1.0, 1.0, 9.81).unwrap());
        let x0 = model.from_angles(&[1.0, 0.5, -0.3], &[0.0, 1.0, 0.0]).unwrap();
        let reference = {
            let mut state = State::new(0.0, x0.clone());
            Projected::new(Rk4::new(&model)).integrate(&model, &mut state, 1.0, 4000).unwrap();
            state.into_x()
        };
        let error = |steps: usize| {
            let mut state = State::new(0.0, x0.clone());
            RodMidpoint::new().integrate(&model, &mut state, 1.0, steps).unwrap();
            (state.x() - &reference).amax()
        };
        let (coarse, fine) = (error(200), error(400));
        let order = (coarse / fine).log2();
        assert!((1.8..2.3).contains(&order), "order {order}, errors {coarse:e} {fine:e}");
    }
}
