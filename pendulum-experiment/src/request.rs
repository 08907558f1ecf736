//! A run as asked for ([`Request`]): the chain, drive and start given, the integrator,
//! step and sampling optional ("choose for me"); [`Request::resolve`] checks it, makes
//! the choices ([`choose`](crate::choice::choose)) and returns the complete
//! [`RunConfig`].

use crate::choice::choose;
use crate::description::{
    DEFAULT_TOLERANCE, Dimension, DriveConfig, IntegratorKind, RunConfig, StageSolver, View, check_step,
};
use crate::error::{Error, Result};
use crate::initial::{InitialSpec, initial_state};

/// Everything a run needs except what the library may choose: give `integrator`, `step`
/// and `every` to fix them, leave them `None` to have them chosen from the chain and the
/// drive (the choice and its reason are recorded in [`RunConfig::chosen`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Request {
    /// Space dimension.
    pub dim: Dimension,
    /// Masses `m_i`, kg, one per link.
    pub masses: Vec<f64>,
    /// Rod lengths `l_i`, m, one per link.
    pub lengths: Vec<f64>,
    /// Gravity `g`, m/s² (along −y in 2D, −z in 3D).
    pub gravity: f64,
    /// Damping `λ_i`, N·m·s, one per link.
    pub damping: Vec<f64>,
    /// Constant torques `σ_i` on the angles, N·m, one per link (2D only; `None`: zero).
    pub torque: Option<Vec<f64>>,
    /// The pivot's motion.
    pub drive: DriveConfig,
    /// How the chain starts.
    pub initial: InitialSpec,
    /// 3D only: the initial azimuthal rate `φ̇` of every link, rad/s (a conical swing).
    pub spin: Option<f64>,
    /// The integrator (`None`: chosen).
    pub integrator: Option<IntegratorKind>,
    /// The Gauss–Legendre stage solve.
    pub solver: StageSolver,
    /// dp54's relative tolerance (`None`: [`DEFAULT_TOLERANCE`]; others: must be `None`).
    pub tolerance: Option<f64>,
    /// The step, s (`None`: chosen).
    pub step: Option<f64>,
    /// End time, s (the run starts at 0).
    pub end: f64,
    /// A sample every this many steps (`None`: about 500 samples).
    pub every: Option<usize>,
    /// The animation's plane (3D).
    pub view: View,
    /// Most frames of the animation.
    pub frames: usize,
}

impl Request {
    /// The complete configuration: the initial state resolved (a spec, a file, a previous
    /// run's final state), the integrator, step and sampling chosen where not given, every
    /// value checked. Errors name the bad value.
    pub fn resolve(self) -> Result<RunConfig> {
        let n = self.masses.len();
        if self.spin.is_some() && self.dim == Dimension::Two {
            return Err(Error::invalid("--spin (initial azimuthal rate) applies to --dim 3 only"));
        }
        let torque = match (self.torque.clone(), self.dim) {
            (None, Dimension::Two) => vec![0.0; n],
            (None, Dimension::Three) => Vec::new(),
            (Some(t), Dimension::Two) => t,
            (Some(_), Dimension::Three) => {
                return Err(Error::invalid("--torque: constant torques are available in 2D only (--dim 2)"));
            }
        };
        let initial = initial_state(&self.initial, self.dim, n, self.spin.unwrap_or(0.0))?;
        if let Some(h) = self.step {
            check_step(h)?;
        }
        if !(self.end.is_finite() && self.end > 0.0) {
            return Err(Error::invalid(format!("--end must be finite and positive, got {}", self.end)));
        }
        let choice = choose(&self);
        let config = RunConfig {
            dim: self.dim,
            masses: self.masses,
            lengths: self.lengths,
            gravity: self.gravity,
            damping: self.damping,
            torque,
            drive: self.drive,
            integrator: choice.integrator,
            solver: self.solver,
            step: choice.step,
            tolerance: match (choice.integrator, self.tolerance) {
                (IntegratorKind::Dp54, t) => Some(t.unwrap_or(DEFAULT_TOLERANCE)),
                (_, None) => None,
                (_, Some(_)) => return Err(Error::invalid("--tolerance applies to --integrator dp54 only")),
            },
            end: self.end,
            every: choice.every,
            initial,
            view: self.view,
            frames: self.frames,
            chosen: choice.reason,
        };
        config.check()?;
        Ok(config)
    }
}
