//! A run's options as the run library's [`Request`]: the per-link values parsed, the
//! drive assembled from its flags, and the combinations the description cannot express
//! refused by flag name.

use pendulum_experiment::{Dimension, DriveConfig, Request, RunConfig, View};

use crate::args::{DriveKind, Physics};
use crate::chain_args::per_link_values;
use crate::error::{CliError, CliResult};
use crate::spec::{expand, parse_list, per_link};

/// The configuration a run's options describe: [`request`], resolved (the integrator,
/// step and sampling chosen where not given).
pub fn resolve(p: &Physics, view: View, frames: usize) -> CliResult<RunConfig> {
    request(p, view, frames)?.resolve()
}

/// The request a run's options make; errors name the flag.
pub fn request(p: &Physics, view: View, frames: usize) -> CliResult<Request> {
    let dim = p.dim;
    let (masses, lengths) = per_link_values(&p.chain)?;
    let n = masses.len();
    let damping = expand("--damping", per_link("--damping", &p.damping)?, n)?;
    let torque = match (&p.torque, dim) {
        (None, _) => None,
        (Some(s), Dimension::Two) => Some(expand("--torque", per_link("--torque", s)?, n)?),
        (Some(_), Dimension::Three) => {
            return Err(CliError::invalid("--torque: constant torques are available in 2D only (--dim 2)"));
        }
    };
    let drive = match p.drive {
        DriveKind::Fixed => DriveConfig::Fixed,
        DriveKind::Harmonic => {
            let direction = match &p.direction {
                Some(s) => parse_list("--direction", s)?,
                None => {
                    let mut up = vec![0.0; dim.space()];
                    up[dim.space() - 1] = 1.0;
                    up
                }
            };
            DriveConfig::Harmonic { direction, amplitude: p.amplitude, omega: p.omega, phase: p.phase }
        }
        DriveKind::Circle => match p.ramp_time {
            None => DriveConfig::Circle { radius: p.radius, omega: p.omega },
            Some(duration) => DriveConfig::RampedCircle {
                radius: p.radius,
                initial_omega: p.ramp_from.unwrap_or(0.0),
                omega: p.omega,
                duration,
            },
        },
    };
    if (p.ramp_time.is_some() || p.ramp_from.is_some()) && p.drive != DriveKind::Circle {
        return Err(CliError::invalid("--ramp-time and --ramp-from apply to --drive circle only"));
    }
    if p.ramp_from.is_some() && p.ramp_time.is_none() {
        return Err(CliError::invalid("--ramp-from needs --ramp-time (the ramp's duration, s)"));
    }
    if p.direction.is_some() && p.drive != DriveKind::Harmonic {
        return Err(CliError::invalid("--direction applies to --drive harmonic only"));
    }
    Ok(Request {
        dim,
        masses,
        lengths,
        gravity: p.chain.gravity,
        damping,
        torque,
        drive,
        initial: p.initial.clone(),
        spin: p.spin,
        integrator: p.integrator,
        solver: p.solver,
        tolerance: p.tolerance,
        step: p.step,
        end: p.end,
        every: p.every,
        view,
        frames,
    })
}
