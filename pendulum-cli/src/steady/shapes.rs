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
use crate::error::{CliError, CliResult};
use pendulum_experiment::steady::AtSpeed;

/// One steady shape at one listed speed ([`AtSpeed`]: branch, name, shape, nodes,
/// undamped verdict) and, with damping, its damped verdict.
#[derive(Debug, Clone)]
pub struct Found {
    /// The shape and its undamped verdict.
    pub at: AtSpeed,
    /// With damping: the damped verdict, `None` if no damped steady shape was found.
    pub damped: Option<Damped>,
}

impl std::ops::Deref for Found {
    type Target = AtSpeed;

    fn deref(&self) -> &AtSpeed {
        &self.at
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
    pendulum_experiment::steady::shapes_at(problem, family, speeds)?
        .into_iter()
        .map(|s| {
            let damped = match damping {
                Some(d) => damped(problem, chain, &s.shape, d)?,
                None => None,
            };
            Ok(Found { at: s, damped })
        })
        .collect()
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
