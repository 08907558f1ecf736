//! A run's options as the run library's [`Request`]: the per-link values parsed, the
//! drive's flags handed to the library's [`DriveOptions`] (which refuses the
//! combinations the description cannot express, by flag name).

use pendulum_experiment::{DriveOptions, PathSamples, Request, RunConfig, View};

use crate::args::Physics;
use crate::chain_args::per_link_values;
use crate::error::CliResult;
use crate::spec::{expand, parse_list, per_link};

/// The configuration a run's options describe: [`request`], resolved (the integrator,
/// step and sampling chosen where not given).
pub fn resolve(p: &Physics, frames: usize) -> CliResult<RunConfig> {
    request(p, frames)?.resolve()
}

/// The request a run's options make, in the view [`View::default_for`] the run; errors
/// name the flag.
pub fn request(p: &Physics, frames: usize) -> CliResult<Request> {
    let dim = p.dim;
    let (masses, lengths) = per_link_values(&p.chain)?;
    let n = masses.len();
    let damping = expand("--damping", per_link("--damping", &p.damping)?, n)?;
    // A torque in 3D is refused by the library's `resolve`, by the same message.
    let torque = p.torque.as_deref().map(|s| expand("--torque", per_link("--torque", s)?, n)).transpose()?;
    let direction = p.direction.as_deref().map(|s| parse_list("--direction", s)).transpose()?;
    let drive = DriveOptions {
        kind: p.drive,
        amplitude: p.amplitude,
        omega: p.omega,
        phase: p.phase,
        direction,
        radius: p.radius,
        ramp_time: p.ramp_time,
        ramp_from: p.ramp_from,
        path: p.path.clone().map(PathSamples::File),
        path_at_rest: p.path_at_rest,
    }
    .config(dim)?;
    let view = View::default_for(dim, &drive);
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
