//! Every steady shape at the speeds of `--omega`: where each branch crosses the speed
//! (and, for a fixed pivot, the vertical), with node count, tip radius and verdict, and
//! with `--damping` the damped verdict.
//!
//! Damped, for a fixed pivot (`R = 0`): [`stability`] with the damping `λ_i` on the link
//! rates in the turning frame; the steady shape is unchanged, and by Kelvin–Tait–Chetaev
//! only index-0 shapes stay stable. A fixed pivot cannot drive the rotation against a drag
//! of the inertial rates, so that damping has no steady shape to ask about. For a circling
//! pivot (`R > 0`): the chain's own damping of the inertial rates (`½ Σ λ_i |u̇_i|²`, as in
//! `pendulum simulate`); the damped steady shape is the relative equilibrium of the 3D
//! chain in unit directions on the circling pivot ([`relative_equilibrium`], Newton from
//! the undamped planar shape), and its verdict is that of the eigenvalues that can grow
//! ([`relative_spectrum_near_origin`]), growth counted above `1e-6` times the spectrum's
//! size ([`SteadyRotation::spectrum_scale`]).

use nalgebra::{Dyn, U3, Vector3};
use pendulum_core::{
    Chain, Circle, Directions, SteadyRotation, SteadyShape, Verdict, relative_equilibrium,
    relative_spectrum_near_origin, stability,
};

use super::branches::Family;
use super::{Judged, judge, nodes};
use crate::error::{CliError, CliResult};

/// One steady shape at one listed speed.
#[derive(Debug, Clone)]
pub struct Found {
    /// The branch's number in the tables and CSV files, 0 for the vertical.
    pub branch: usize,
    /// Its name (`"vertical"` for the vertical).
    pub name: String,
    /// The shape, at exactly the listed speed.
    pub shape: SteadyShape,
    /// Node count (`None`: the vertical).
    pub nodes: Option<usize>,
    /// Undamped verdict.
    pub judged: Judged,
    /// With damping: the damped verdict, `None` if no damped steady shape was found.
    pub damped: Option<Damped>,
}

impl Found {
    /// Tip radius `|x_n|`, m: the free end's distance from the axis.
    pub fn tip_radius(&self) -> f64 {
        self.shape.displacements.last().map_or(0.0, |x| x.abs())
    }
}

/// The damped verdict of one shape.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Damped {
    /// Stable (every eigenvalue decays) or unstable.
    pub verdict: Verdict,
    /// Largest real part of the damped eigenvalues, 1/s.
    pub growth_rate: f64,
    /// Largest distance between corresponding masses of the damped and the undamped
    /// shape, m (the damped shape lags out of the plane; 0 for a fixed pivot).
    pub shift: f64,
}

/// Every steady shape at each of `speeds` (rad/s) on the branches of `family` (and the
/// vertical for a fixed pivot), speeds in the order given, branches in their order. For a
/// fixed pivot the mirror image `θ → −θ` of a shape is the same shape turned by π about
/// the axis and is not listed again.
pub fn at(
    problem: &SteadyRotation,
    chain: &Chain<Dyn>,
    family: &Family,
    speeds: &[f64],
    damping: Option<&[f64]>,
) -> CliResult<Vec<Found>> {
    let n = problem.links();
    let mut found = Vec::new();
    for &omega in speeds {
        let mut here: Vec<(usize, String, SteadyShape)> = Vec::new();
        if problem.radius() == 0.0 {
            here.push((0, "vertical".into(), problem.shape(omega, nalgebra::DVector::zeros(n))));
        }
        for (b, labelled) in family.branches.iter().enumerate() {
            for shape in problem.solutions_at(std::slice::from_ref(&labelled.branch), omega) {
                if here.iter().all(|(_, _, s)| (&s.theta - &shape.theta).amax() > 1e-8) {
                    here.push((b + 1, labelled.name.clone(), shape));
                }
            }
        }
        for (branch, name, shape) in here {
            let judged = judge(problem, &shape)?;
            let damped = match damping {
                Some(d) => damped(problem, chain, &shape, d)?,
                None => None,
            };
            found.push(Found { branch, name, nodes: nodes(&shape), shape, judged, damped });
        }
    }
    Ok(found)
}

/// The damped verdict of `shape` (module docs); `None` when Newton finds no damped
/// relative equilibrium near it.
fn damped(
    problem: &SteadyRotation,
    chain: &Chain<Dyn>,
    shape: &SteadyShape,
    d: &[f64],
) -> CliResult<Option<Damped>> {
    let omega = shape.omega;
    if problem.radius() == 0.0 {
        let st = stability(problem, shape, Some(d))
            .map_err(|e| CliError::failed(format!("damped stability at ω = {omega} rad/s: {e}")))?;
        return Ok(Some(Damped { verdict: st.verdict(), growth_rate: st.growth_rate, shift: 0.0 }));
    }
    let radius = problem.radius();
    let Ok(circle) = Circle::new(radius, omega) else { return Ok(None) };
    let model = Directions::<U3>::new(chain.clone().with_damping(d)?).with_drive(circle);
    let guess: Vec<(f64, f64)> = shape.theta.iter().map(|&t| (t, 0.0)).collect();
    let Ok(eq) = relative_equilibrium(&model, &guess) else { return Ok(None) };
    let spectrum = relative_spectrum_near_origin(&model, &eq)
        .map_err(|e| CliError::failed(format!("damped spectrum at ω = {omega} rad/s: {e}")))?;
    let tolerance = 1e-6 * problem.spectrum_scale(shape);
    let verdict = Verdict::of_spectrum(&spectrum, None, tolerance);
    let growth_rate = spectrum.iter().map(|z| z.re).fold(f64::NEG_INFINITY, f64::max);
    // Masses of the damped shape, r_i = (R, 0, 0) + Σ_{j≤i} l_j u_j, against (x_i, 0, z_i).
    let (mut r, mut z, mut shift) = (Vector3::new(radius, 0.0, 0.0), 0.0, 0.0_f64);
    for (i, (&l, &theta)) in chain.lengths().iter().zip(shape.theta.iter()).enumerate() {
        r += l * eq.state.fixed_rows::<3>(3 * i).into_owned();
        z -= l * theta.cos();
        shift = shift.max((r - Vector3::new(shape.displacements[i], 0.0, z)).norm());
    }
    Ok(Some(Damped { verdict, growth_rate, shift }))
}
