//! A run as data: [`RunConfig`], every parameter of an experiment (chain, drive, damping
//! and torques, initial state, end, integrator, step and sampling, how to draw it), the
//! schema of `run.json` (inside [`RunFile`](crate::file::RunFile)), and its checks.
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::spelling::{opt, opt_is};

/// Space dimension of the chain.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Dimension {
    /// Planar chain, angles θ_i.
    #[serde(rename = "2")]
    #[cfg_attr(feature = "clap", value(name = "2"))]
    Two,
    /// Spatial chain, integrated in unit link directions (initial states in spherical
    /// angles: θ from −z, φ azimuth from +x).
    #[serde(rename = "3")]
    #[cfg_attr(feature = "clap", value(name = "3"))]
    Three,
}

impl Dimension {
    /// Components of a position: 2 or 3.
    pub fn space(self) -> usize {
        match self {
            Self::Two => 2,
            Self::Three => 3,
        }
    }

    /// `2D` or `3D`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Two => "2D",
            Self::Three => "3D",
        }
    }
}

/// The time integrator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum IntegratorKind {
    /// Gauss–Legendre, 1 stage (implicit midpoint), order 2.
    Gl1,
    /// Gauss–Legendre, 2 stages, order 4.
    Gl2,
    /// Gauss–Legendre, 3 stages, order 6.
    Gl3,
    /// Classical explicit Runge–Kutta, order 4.
    Rk4,
    /// 3D only: the implicit midpoint rule on the rod constraints, O(n) per Newton
    /// iteration, stable at any step; energy and ledger exact; order 2.
    Midpoint,
    /// Dormand–Prince 5(4), explicit, its own step chosen inside each --step to meet
    /// --tolerance (3D: projected onto the rods after every internal step).
    Dp54,
}

/// How an implicit Gauss–Legendre step solves its stage equations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum StageSolver {
    /// Fixed-point iteration: a few right-hand sides per sweep, no Jacobian; needs the
    /// step to be shorter than the chain's fastest period.
    FixedPoint,
    /// Newton's method with a finite-difference Jacobian (cost grows as dim³).
    Newton,
}

/// The plane a 3D chain is drawn in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum View {
    /// Side view: x to the right, z up.
    Xz,
    /// Side view: y to the right, z up.
    Yz,
    /// Top view: x to the right, y up.
    Xy,
    /// The side view in the frame turning with a pivot that circles the vertical axis (3D
    /// runs driven on a circle): a steady shape stands still, and nothing can alias. The
    /// default for such runs.
    #[serde(rename = "co-rotating")]
    CoRotating,
}

impl View {
    /// The view a run is drawn in unless one is asked for: [`View::CoRotating`] for a 3D
    /// chain whose pivot circles, the side view `xz` otherwise.
    pub fn default_for(dim: Dimension, drive: &DriveConfig) -> Self {
        if Self::turns_with(dim, drive) { Self::CoRotating } else { Self::Xz }
    }

    /// Whether the pivot circles the vertical axis of a 3D chain (the turning frame exists).
    fn turns_with(dim: Dimension, drive: &DriveConfig) -> bool {
        dim == Dimension::Three && drive.circles()
    }
}

/// The pivot's motion, with every parameter.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum DriveConfig {
    /// Pivot at rest at the origin.
    Fixed,
    /// `p(t) = A sin(ωt + φ) d̂` (m), `d̂` the normalized direction.
    Harmonic {
        /// Direction of oscillation (2 or 3 components, any non-zero length).
        direction: Vec<f64>,
        /// Amplitude `A`, m.
        amplitude: f64,
        /// Angular frequency `ω`, rad/s.
        omega: f64,
        /// Phase `φ`, rad.
        phase: f64,
    },
    /// `p(t) = R (cos ωt, sin ωt, 0)` (m), 3D only.
    Circle {
        /// Radius `R`, m.
        radius: f64,
        /// Angular frequency `ω`, rad/s.
        omega: f64,
    },
    /// A circle whose speed ramps linearly from `ω0` to `ω` over `duration`, then holds
    /// `ω` (3D only): `p = R (cos φ, sin φ, 0)`, `φ̇` ramping (`pendulum_core::RampedCircle`).
    RampedCircle {
        /// Radius `R`, m.
        radius: f64,
        /// Speed at t = 0, rad/s.
        initial_omega: f64,
        /// Speed from `duration` on, rad/s.
        omega: f64,
        /// Duration of the ramp, s.
        duration: f64,
    },
    /// The cubic spline through sampled positions (`pendulum_core::Sampled`): natural
    /// (`p̈ = 0` at the first and last sample) or at rest there; outside the samples a
    /// straight line at the end velocity.
    Sampled {
        /// The file the samples were read from, as given (for the reader; the numbers
        /// below are the path).
        file: String,
        /// Sample times `t_k`, s, increasing.
        times: Vec<f64>,
        /// Positions `p_k`, m: 2 (2D) or 3 (3D) components each.
        positions: Vec<Vec<f64>>,
        /// Whether the velocity at the first and last sample is zero (else the natural
        /// spline).
        at_rest: bool,
    },
}

impl DriveConfig {
    /// Whether the pivot moves on a horizontal circle about the vertical axis (at a steady
    /// or a ramped speed).
    pub fn circles(&self) -> bool {
        matches!(self, Self::Circle { .. } | Self::RampedCircle { .. })
    }

    /// A sampled path in words ("pivot on 1000 samples of hand.csv, 0 to 9.99 s"), for the
    /// pictures' captions; `None` for the other drives.
    pub fn sampled_words(&self) -> Option<String> {
        let Self::Sampled { file, times, at_rest, .. } = self else { return None };
        let (first, last) = (times.first().copied().unwrap_or(0.0), times.last().copied().unwrap_or(0.0));
        let rest = if *at_rest { ", at rest at both ends" } else { "" };
        Some(format!("pivot on {} samples of {file}, {first} to {last} s{rest}", times.len()))
    }
}

/// The initial state: what was asked for and the resolved numbers.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InitialConfig {
    /// The spec as given (`hanging`, `tilted:0.5`, a file name), for the reader.
    pub spec: String,
    /// Coordinates `q` at t = 0, rad (2D θ_1..θ_n; 3D θ_1..θ_n, φ_1..φ_n).
    pub coordinates: Vec<f64>,
    /// Rates `q̇` at t = 0, rad/s, in the order of `coordinates`.
    pub rates: Vec<f64>,
    /// 3D only, instead of angles (then `coordinates` and `rates` are empty): the exact
    /// state in unit link directions `(u_1..u_n, w_1..w_n)` (1, 1/s), a previous run's
    /// final state (`final.json`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub directions: Option<Vec<f64>>,
}

/// Every parameter of a simulation; with the program version, enough to repeat it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunConfig {
    /// Space dimension.
    pub dim: Dimension,
    /// Masses `m_i`, kg, one per link.
    pub masses: Vec<f64>,
    /// Rod lengths `l_i`, m.
    pub lengths: Vec<f64>,
    /// Gravity `g`, m/s².
    pub gravity: f64,
    /// Damping `λ_i`, N·m·s.
    pub damping: Vec<f64>,
    /// Constant torques `σ_i` on the angles, N·m (2D; empty in 3D).
    pub torque: Vec<f64>,
    /// The pivot's motion.
    pub drive: DriveConfig,
    /// Time integrator.
    pub integrator: IntegratorKind,
    /// Stage solve of the Gauss–Legendre integrators (unused by rk4).
    pub solver: StageSolver,
    /// Step size, s.
    pub step: f64,
    /// The dp54 integrator's tolerance (absent for the others).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tolerance: Option<f64>,
    /// End time, s (start at 0).
    pub end: f64,
    /// Sample every `every` steps.
    pub every: usize,
    /// Initial state.
    pub initial: InitialConfig,
    /// Animation plane (3D).
    pub view: View,
    /// Most frames in the animation.
    pub frames: usize,
    /// What the run chose itself of integrator, step and sampling, and why (absent when
    /// the options named all three).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub chosen: Option<String>,
}

impl RunConfig {
    /// Number of links.
    pub fn links(&self) -> usize {
        self.masses.len()
    }

    /// Checks the parts of a configuration (from the command line or a run.json) that
    /// building the chain, drive and run does not: list lengths, run times, sampling.
    pub fn check(&self) -> Result<()> {
        let n = self.links();
        if n == 0 {
            return Err(Error::invalid("masses: a chain needs at least 1 link, got 0"));
        }
        let dof = match self.dim {
            Dimension::Two => n,
            Dimension::Three => 2 * n,
        };
        let directions = self.initial.directions.as_ref();
        if directions.is_some() && self.dim == Dimension::Two {
            return Err(Error::invalid(format!(
                "initial state: a state in unit directions is for 3D runs ({})",
                opt_is("dim", 3)
            )));
        }
        let angles = if directions.is_some() { 0 } else { dof };
        let counts = [
            ("lengths", self.lengths.len(), n),
            ("damping", self.damping.len(), n),
            ("initial coordinates", self.initial.coordinates.len(), angles),
            ("initial rates", self.initial.rates.len(), angles),
            (
                "initial directions and rates",
                directions.map_or(0, Vec::len),
                if directions.is_some() { 6 * n } else { 0 },
            ),
            ("torque", self.torque.len(), if self.dim == Dimension::Two { n } else { 0 }),
        ];
        for (what, got, expected) in counts {
            if got != expected {
                return Err(Error::invalid(format!("{what}: got {got} values, expected {expected}")));
            }
        }
        let initial = self
            .initial
            .coordinates
            .iter()
            .chain(&self.initial.rates)
            .chain(directions.into_iter().flatten());
        if let Some(v) = initial.copied().find(|v| !v.is_finite()) {
            return Err(Error::invalid(format!("initial state: {v} is not finite")));
        }
        if let Some(v) = self.torque.iter().find(|v| !v.is_finite()) {
            return Err(Error::invalid(format!("{}: {v} is not finite", opt("torque"))));
        }
        check_step(self.step)?;
        if let Some(t) = self.tolerance
            && !(1e-14..=1e-1).contains(&t)
        {
            return Err(Error::invalid(format!("{} must be within 1e-14 … 0.1, got {t}", opt("tolerance"))));
        }
        check_end(self.end)?;
        let steps = (self.end / self.step).ceil();
        if steps > 1e8 {
            let origin = if self.chosen.as_deref().is_some_and(|c| c.contains("step ")) {
                format!(" (chosen for the chain's fastest mode; name one with {})", opt("step"))
            } else {
                String::new()
            };
            return Err(Error::invalid(format!(
                "{} with {}{origin} needs {steps:e} steps; more than 1e8 is refused",
                opt_is("end", self.end),
                opt_is("step", format_args!("{:e}", self.step))
            )));
        }
        if self.every == 0 {
            return Err(Error::invalid(format!("{} must be at least 1 step, got 0", opt("every"))));
        }
        if self.view == View::CoRotating && !View::turns_with(self.dim, &self.drive) {
            return Err(Error::invalid(format!(
                "{} needs a 3D chain whose pivot circles ({} {})",
                opt_is("view", "co-rotating"),
                opt_is("dim", 3),
                opt_is("drive", "circle")
            )));
        }
        if self.frames < 2 {
            return Err(Error::invalid(format!("{} must be at least 2, got {}", opt("frames"), self.frames)));
        }
        if let DriveConfig::Harmonic { direction, .. } = &self.drive {
            let space = if self.dim == Dimension::Two { 2 } else { 3 };
            if direction.len() != space {
                return Err(Error::invalid(format!(
                    "{}: got {} components, the {space}D pivot moves in {space}",
                    opt("direction"),
                    direction.len()
                )));
            }
        }
        if let DriveConfig::Sampled { positions, .. } = &self.drive {
            check_components(positions, self.dim.space())?;
        }
        if self.integrator == IntegratorKind::Midpoint && self.dim == Dimension::Two {
            return Err(midpoint_in_2d());
        }
        if matches!(self.drive, DriveConfig::Circle { .. }) && self.dim == Dimension::Two {
            return Err(circle_in_2d());
        }
        Ok(())
    }
}

/// Errors unless every sampled position has `space` components (2 in 2D, 3 in 3D).
pub(crate) fn check_components(positions: &[Vec<f64>], space: usize) -> Result<()> {
    match positions.iter().enumerate().find(|(_, p)| p.len() != space) {
        Some((k, p)) => Err(Error::invalid(format!(
            "drive positions[{k}]: got {} components, the {space}D pivot moves in {space}",
            p.len()
        ))),
        None => Ok(()),
    }
}

/// The dp54 integrator's tolerance when none is given.
pub const DEFAULT_TOLERANCE: f64 = 1e-8;

/// The rod midpoint asked of a planar run.
pub(crate) fn midpoint_in_2d() -> Error {
    Error::invalid(format!(
        "{} steps chains in unit directions: 3D only ({})",
        opt_is("integrator", "midpoint"),
        opt_is("dim", 3)
    ))
}

/// The circle drive asked of a planar run.
pub(crate) fn circle_in_2d() -> Error {
    Error::invalid(format!(
        "{} moves the pivot on a horizontal circle: 3D only ({})",
        opt_is("drive", "circle"),
        opt_is("dim", 3)
    ))
}

/// Errors unless the run's end time (s) is finite and positive.
pub(crate) fn check_end(end: f64) -> Result<()> {
    if end.is_finite() && end > 0.0 {
        Ok(())
    } else {
        Err(Error::invalid(format!("{} must be finite and positive, got {end}", opt("end"))))
    }
}

/// Errors unless the step is finite and positive.
pub(crate) fn check_step(h: f64) -> Result<()> {
    if h.is_finite() && h > 0.0 {
        Ok(())
    } else {
        Err(Error::invalid(format!("{} must be finite and positive, got {h}", opt("step"))))
    }
}
