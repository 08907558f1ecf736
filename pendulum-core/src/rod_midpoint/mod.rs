//! An implicit step for long chains: the midpoint rule on the masses with the rods as
//! exact constraints, one block-tridiagonal Newton solve per iteration, `O(n)`.
//!
//! Explicit methods are held to `h ≲ 3/ω_max` by the chain's fastest modes
//! (`ω_max ≈ 2n √(g/L)` for a uniform chain: 6.3e3 rad/s at n = 1000, L = 1 m), which
//! matter little to the shape the chain takes. This step is stable at any `h`, conserves
//! the energy of a free undamped chain exactly (to the Newton tolerance) and closes the
//! drive and damping ledger exactly, so it can step over those modes; it does not resolve
//! them (their frequencies come out too low), and it is of order 2.

use nalgebra::{DefaultAllocator, DimName, Dyn, allocator::Allocator};

use crate::drive::Drive;
use crate::energy::Accounted;
use crate::energy::ledger::LEDGER_LEN;
use crate::error::{Error, Result};
use crate::integrate::{Integrator, State, Stats};
use crate::lanes::{Lane, Masked};
use crate::models::directions::Directions;
use iteration::{Chains, Iterated, Limits, Work};

pub(crate) mod iteration;
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
    planar: Work<2, f64>,
    spatial: Work<3, f64>,
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
        crate::integrate::check_step_size(h)?;
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
        // A link turning by more than MAX_TURN in the step: halve it without trying.
        if depth < MAX_HALVINGS && turns_too_far(&motion[S::DIM * chain.links()..], S::DIM, h) {
            return self.halves(chain, t, motion, h, out, depth);
        }
        let drive = chain.drive();
        let ((p0, v0), (p1, v1)) = (drive.position_and_velocity(t), drive.position_and_velocity(t + h));
        let ends = [p0, p1, v0, v1];
        let limits = self.limits();
        // The multipliers' start: the tensions at t (the accelerations come with them).
        let n = chain.links();
        let mut start = vec![0.0; (S::DIM + 1) * n];
        let (accelerations, tensions) = start.split_at_mut(S::DIM * n);
        if chain.accelerations_of_valid(t, motion, accelerations, Some(tensions)).is_err() {
            return Err(0);
        }
        let links = chain.chain();
        let chains = Chains {
            masses: links.masses().as_slice(),
            lengths: links.lengths().as_slice(),
            damping: links.damping().as_slice(),
            down: -links.gravity(),
        };
        let data = (motion, h, &mut *out);
        let Iterated { failed, iterations, drive, damped } = match S::DIM {
            2 => {
                let ends = ends.map(|v| [v[0], v[1]]);
                iteration::iterate::<2, f64, false>(
                    &mut self.planar,
                    &chains,
                    tensions,
                    ends,
                    data,
                    true,
                    &limits,
                )
            }
            _ => {
                let ends = ends.map(|v| [v[0], v[1], v[2]]);
                iteration::iterate::<3, f64, false>(
                    &mut self.spatial,
                    &chains,
                    tensions,
                    ends,
                    data,
                    true,
                    &limits,
                )
            }
        };
        let result = if failed { Err(iterations) } else { Ok((StepWork { drive, damped }, iterations)) };
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

    /// The stopping rule of the Newton iteration.
    pub(crate) fn limits(&self) -> Limits {
        Limits { tolerance: self.tolerance, max_iterations: self.max_iterations }
    }
}

/// The lanes in which a link would turn by more than [`MAX_TURN`] in a step of `h` (s):
/// `|h| max_i |w_i| > MAX_TURN`, from the rates `w` of a state (`dims` numbers each, 1/s).
#[inline(always)]
pub(crate) fn turns_too_far<V: Masked>(rates: &[V], dims: usize, h: f64) -> V::Mask {
    let mut fastest = V::splat(0.0);
    for w in rates.chunks_exact(dims) {
        let mut squared = w[0] * w[0];
        for &v in &w[1..] {
            squared += v * v;
        }
        fastest = fastest.max(squared);
    }
    (V::splat(h.abs()) * fastest.sqrt()).above(V::splat(MAX_TURN))
}

/// Entry `j` of a step's increment of a state whose entry is `x`: `next_j − x` for the
/// motion (`j < next.len()`), then the step's `work` for the ledger's `W_drive` and
/// `E_damped` (J) when given, and `x − x` (zero, or NaN as the entry) for its other entry.
#[inline(always)]
#[allow(clippy::eq_op)] // `x − x` on purpose: zero, or NaN as the entry.
pub(crate) fn increment<V: Lane>(j: usize, x: V, next: &[V], work: Option<(V, V)>) -> V {
    let len = next.len();
    match work {
        _ if j < len => next[j] - x,
        Some((drive, _)) if j == len => drive,
        Some((_, damped)) if j == len + 2 => damped,
        _ => x - x,
    }
}

/// Moves `state` by a step of `h` (s) to its new motion `next` (the state's first
/// entries), adding the step's `work` to the ledger after them when given.
fn take_step(state: &mut State<Dyn>, h: f64, next: &[f64], work: Option<&StepWork>) {
    let work = work.map(|w| (w.drive, w.damped));
    state.advance_with(h, 0.., |x, j| increment(j, x, next, work));
}

impl<S: DimName, Dr: Drive<S>> Integrator<Directions<S, Dr>> for RodMidpoint
where
    DefaultAllocator: Allocator<S>,
{
    fn step(&mut self, system: &Directions<S, Dr>, state: &mut State<nalgebra::Dyn>, h: f64) -> Result<()> {
        let mut next = state.x().clone();
        self.advance(system, state.t(), state.x().as_slice(), h, next.as_mut_slice())?;
        take_step(state, h, next.as_slice(), None);
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
        take_step(state, h, &next.as_slice()[..len], Some(&work));
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
    use crate::chain::Chain;
    use crate::integrate::{Projected, Rk4};
    use crate::lanes::Lanes32;

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

    /// Numbers into lanes `V` (every lane the same) and back out of the first lane.
    type Conversions<V> = (fn(f64) -> V, fn(V) -> f64);

    /// The conversions of one chain's own numbers.
    const SCALAR: Conversions<f64> = (|x| x, |x| x);

    /// `count` steps of `h` (s) of `model` from `(t, x)` by the Newton iteration alone in
    /// lanes `V` (every lane the same chain, its numbers made by `lane`, read back from the
    /// first lane by `back`), the unknowns as `DISPLACED` says, the multipliers started
    /// from the `f64` model's tensions: the final state and the last step's pivot work and
    /// damping loss (J).
    fn iterated<V: Masked, const DISPLACED: bool>(
        model: &Directions<U3, crate::Circle>,
        (t0, x): (f64, &DVector<f64>),
        (h, count, tolerance): (f64, usize, f64),
        (lane, back): Conversions<V>,
    ) -> (Vec<f64>, f64, f64) {
        let (n, links) = (model.links(), model.chain());
        let per = |v: &[f64]| v.iter().map(|&x| lane(x)).collect::<Vec<V>>();
        let (masses, lengths) = (per(links.masses().as_slice()), per(links.lengths().as_slice()));
        let damping = per(links.damping().as_slice());
        let chains =
            Chains { masses: &masses, lengths: &lengths, damping: &damping, down: lane(-links.gravity()) };
        let limits = Limits { tolerance, max_iterations: 12 };
        let every_lane = V::splat(0.0).at_most(V::splat(1.0));
        let (mut work, mut lanes, mut out) = (Work::default(), per(x.as_slice()), vec![lane(0.0); 6 * n]);
        let (mut now, mut energy) = (x.as_slice().to_vec(), (0.0, 0.0));
        for j in 0..count {
            let t = t0 + j as f64 * h;
            let drive = model.drive();
            let ((p0, v0), (p1, v1)) = (drive.position_and_velocity(t), drive.position_and_velocity(t + h));
            let ends = [p0, p1, v0, v1].map(|v| [lane(v[0]), lane(v[1]), lane(v[2])]);
            let mut start = vec![0.0; 4 * n];
            let (accelerations, tensions) = start.split_at_mut(3 * n);
            model.accelerations_of_valid(t, &now, accelerations, Some(tensions)).unwrap();
            let tensions = per(tensions);
            let data = (&lanes[..], h, &mut out[..]);
            let it = iteration::iterate::<3, V, DISPLACED>(
                &mut work, &chains, &tensions, ends, data, every_lane, &limits,
            );
            assert!(!V::any(it.failed), "step {j}");
            lanes.copy_from_slice(&out);
            now = lanes.iter().map(|&v| back(v)).collect();
            energy = (back(it.drive), back(it.damped));
        }
        (now, energy.0, energy.1)
    }

    /// `max |a − b| / max |a|`.
    fn relative(a: &[f64], b: &[f64]) -> f64 {
        let apart = a.iter().zip(b).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        apart / a.iter().fold(0.0f64, |m, a| m.max(a.abs()))
    }

    /// The iteration in displacements (the `f32` lanes') is the same step as in positions:
    /// a damped 3D chain of 12 links on a circling pivot, twisted and spinning, one step of
    /// 20 ms both ways in `f64`, the new states and the step's work alike to round-off.
    #[test]
    fn in_displacements_the_step_is_the_same_step() {
        let n = 12;
        let chain = Chain::uniform(n, 0.05, 0.08, 9.81).unwrap().with_damping(&[2e-4; 12]).unwrap();
        let model = Directions::<U3>::new(chain).with_drive(crate::Circle::new(0.03, 6.0).unwrap());
        let q: Vec<f64> =
            (0..2 * n).map(|i| if i < n { 0.2 + 0.1 * i as f64 } else { 0.4 * i as f64 }).collect();
        let qd: Vec<f64> = (0..2 * n).map(|i| (i as f64 * 0.7).sin() * 3.0).collect();
        let x = model.from_spherical(&q, &qd).unwrap();
        let step = (0.02, 1, RodMidpoint::new().tolerance);
        let (positions, drive, damped) = iterated::<f64, false>(&model, (0.3, &x), step, SCALAR);
        let displaced = iterated::<f64, true>(&model, (0.3, &x), step, SCALAR);
        let moved = x.iter().zip(&positions).map(|(x, p)| (p - x).abs()).fold(0.0, f64::max);
        assert!(moved > 0.1, "the step moves the chain: {moved:e}");
        let apart = relative(&positions, &displaced.0);
        assert!(apart < 1e-12, "{apart:e}");
        for (p, d) in [(drive, displaced.1), (damped, displaced.2)] {
            assert!((p - d).abs() < 1e-12 * p.abs() && p != 0.0, "{p:e} {d:e}");
        }
    }

    /// In `f32` lanes displacements keep the digits that positions lose: 20 links (100 g,
    /// 1 m) whirled from hanging on a 2 cm circle at 6 rad/s, 500 steps of 1 ms by the
    /// iteration in eight `f32` lanes both ways (the batch's tolerance, 2⁻²⁶ of the reach),
    /// against `f64` in positions (`--nocapture` prints the errors).
    #[test]
    fn in_f32_displacements_keep_the_digits_that_positions_lose() {
        let n = 20;
        let chain = Chain::uniform(n, 0.005, 0.05, 9.81).unwrap().with_damping(&[1e-4; 20]).unwrap();
        let model = Directions::<U3>::new(chain).with_drive(crate::Circle::new(0.02, 6.0).unwrap());
        let x = model.hanging();
        let (h, steps) = (1e-3, 500);
        let exact = iterated::<f64, false>(&model, (0.0, &x), (h, steps, 1e-13), SCALAR).0;
        let f32s: Conversions<Lanes32<8>> = (Lanes32::splat, |v| f64::from(v.0[0]));
        let tolerance = 1.0 / (1u64 << 26) as f64;
        let positions = iterated::<Lanes32<8>, false>(&model, (0.0, &x), (h, steps, tolerance), f32s).0;
        let displaced = iterated::<Lanes32<8>, true>(&model, (0.0, &x), (h, steps, tolerance), f32s).0;
        let (lost, kept) = (relative(&exact, &positions), relative(&exact, &displaced));
        println!(
            "500 steps of 1 ms in f32 lanes: in positions {lost:.1e}, in displacements {kept:.1e} from f64"
        );
        assert!(kept < lost / 4.0, "{kept:e} against {lost:e}");
    }
}
