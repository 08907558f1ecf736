//! The resolved parameters of a run: built from the command line, written to `run.json`
//! (atomically) and read back by `pendulum simulate --from run.json`.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::args::{Dimension, DriveKind, IntegratorKind, Physics, StageSolver, View};
use crate::chain_args::per_link_values;
use crate::error::{CliError, CliResult};
use crate::final_state::FinalState;
use crate::json_file::write_json_atomic;
use crate::spec::{InitialSpec, expand, per_link, read_numbers};

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

    /// Resolves the command line into a complete configuration, checking what the core
    /// does not check itself (counts, signs, combinations); `choose` fills in the
    /// integrator, step and sampling the options leave open
    /// ([`choose`](crate::choice::choose)).
    pub fn from_args(
        p: &Physics,
        view: View,
        frames: usize,
        choose: impl FnOnce(&RunConfig, Option<IntegratorKind>, Option<f64>, Option<usize>) -> Choice,
    ) -> CliResult<Self> {
        let (masses, lengths) = per_link_values(&p.chain)?;
        let n = masses.len();
        let damping = expand("--damping", per_link("--damping", &p.damping)?, n)?;
        let torque = match (&p.torque, p.dim) {
            (None, Dimension::Two) => vec![0.0; n],
            (None, Dimension::Three) => Vec::new(),
            (Some(s), Dimension::Two) => expand("--torque", per_link("--torque", s)?, n)?,
            (Some(_), Dimension::Three) => {
                return Err(CliError::usage("--torque: constant torques are available in 2D only (--dim 2)"));
            }
        };
        let space = match p.dim {
            Dimension::Two => 2,
            Dimension::Three => 3,
        };
        let drive = match p.drive {
            DriveKind::Fixed => DriveConfig::Fixed,
            DriveKind::Harmonic => {
                let direction = match &p.direction {
                    Some(s) => crate::spec::parse_list("--direction", s)?,
                    None => {
                        let mut up = vec![0.0; space];
                        up[space - 1] = 1.0;
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
            return Err(CliError::usage("--ramp-time and --ramp-from apply to --drive circle only"));
        }
        if p.ramp_from.is_some() && p.ramp_time.is_none() {
            return Err(CliError::usage("--ramp-from needs --ramp-time (the ramp's duration, s)"));
        }
        if p.direction.is_some() && p.drive != DriveKind::Harmonic {
            return Err(CliError::usage("--direction applies to --drive harmonic only"));
        }
        if p.spin.is_some() && p.dim == Dimension::Two {
            return Err(CliError::usage("--spin (initial azimuthal rate) applies to --dim 3 only"));
        }
        let initial = initial_state(&p.initial, p.dim, n, p.spin.unwrap_or(0.0))?;
        let mut config = Self {
            dim: p.dim,
            masses,
            lengths,
            gravity: p.chain.gravity,
            damping,
            torque,
            drive,
            integrator: p.integrator.unwrap_or(IntegratorKind::Gl2),
            solver: p.solver,
            step: p.step.unwrap_or(1.0),
            tolerance: None,
            end: p.end,
            every: p.every.unwrap_or(1),
            initial,
            view,
            frames,
            chosen: None,
        };
        if let Some(h) = p.step {
            check_step(h)?;
        }
        if !(p.end.is_finite() && p.end > 0.0) {
            return Err(CliError::usage(format!("--end must be finite and positive, got {}", p.end)));
        }
        let choice = choose(&config, p.integrator, p.step, p.every);
        config.integrator = choice.integrator;
        config.step = choice.step;
        config.every = choice.every;
        config.chosen = choice.reason;
        config.tolerance = match (config.integrator, p.tolerance) {
            (IntegratorKind::Dp54, t) => Some(t.unwrap_or(DEFAULT_TOLERANCE)),
            (_, None) => None,
            (_, Some(_)) => return Err(CliError::usage("--tolerance applies to --integrator dp54 only")),
        };
        config.check()?;
        Ok(config)
    }

    /// Checks the parts of a configuration (from the command line or a run.json) that
    /// building the chain, drive and run does not: list lengths, run times, sampling.
    pub fn check(&self) -> CliResult<()> {
        let n = self.links();
        if n == 0 {
            return Err(CliError::usage("masses: a chain needs at least 1 link, got 0"));
        }
        let dof = match self.dim {
            Dimension::Two => n,
            Dimension::Three => 2 * n,
        };
        let directions = self.initial.directions.as_ref();
        if directions.is_some() && self.dim == Dimension::Two {
            return Err(CliError::usage(
                "initial state: a state in unit directions is for 3D runs (--dim 3)",
            ));
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
                return Err(CliError::usage(format!("{what}: got {got} values, expected {expected}")));
            }
        }
        let initial = self
            .initial
            .coordinates
            .iter()
            .chain(&self.initial.rates)
            .chain(directions.into_iter().flatten());
        if let Some(v) = initial.copied().find(|v| !v.is_finite()) {
            return Err(CliError::usage(format!("initial state: {v} is not finite")));
        }
        if let Some(v) = self.torque.iter().find(|v| !v.is_finite()) {
            return Err(CliError::usage(format!("--torque: {v} is not finite")));
        }
        check_step(self.step)?;
        if let Some(t) = self.tolerance
            && !(1e-14..=1e-1).contains(&t)
        {
            return Err(CliError::usage(format!("--tolerance must be within 1e-14 … 0.1, got {t}")));
        }
        if !(self.end.is_finite() && self.end > 0.0) {
            return Err(CliError::usage(format!("--end must be finite and positive, got {}", self.end)));
        }
        let steps = (self.end / self.step).ceil();
        if steps > 1e8 {
            let origin = if self.chosen.as_deref().is_some_and(|c| c.contains("step ")) {
                " (chosen for the chain's fastest mode; name one with --step)"
            } else {
                ""
            };
            return Err(CliError::usage(format!(
                "--end {} with --step {:e}{origin} needs {steps:e} steps; more than 1e8 is refused",
                self.end, self.step
            )));
        }
        if self.every == 0 {
            return Err(CliError::usage("--every must be at least 1 step, got 0"));
        }
        if self.frames < 2 {
            return Err(CliError::usage(format!("--frames must be at least 2, got {}", self.frames)));
        }
        if let DriveConfig::Harmonic { direction, .. } = &self.drive {
            let space = if self.dim == Dimension::Two { 2 } else { 3 };
            if direction.len() != space {
                return Err(CliError::usage(format!(
                    "--direction: got {} components, the {space}D pivot moves in {space}",
                    direction.len()
                )));
            }
        }
        if self.integrator == IntegratorKind::Midpoint && self.dim == Dimension::Two {
            return Err(CliError::usage(
                "--integrator midpoint steps chains in unit directions: 3D only (--dim 3)",
            ));
        }
        if matches!(self.drive, DriveConfig::Circle { .. }) && self.dim == Dimension::Two {
            return Err(CliError::usage(
                "--drive circle moves the pivot on a horizontal circle: 3D only (--dim 3)",
            ));
        }
        Ok(())
    }
}

/// The coordinates and rates of an initial spec (see [`InitialSpec`]); `spin` is the
/// 3D azimuthal rate φ̇ of every link (rad/s), ignored for a state from a file.
pub fn initial_state(spec: &InitialSpec, dim: Dimension, n: usize, spin: f64) -> CliResult<InitialConfig> {
    let dof = if dim == Dimension::Two { n } else { 2 * n };
    let straight = |theta: f64| {
        let mut q = vec![0.0; dof];
        q[..n].fill(theta);
        let mut qd = vec![0.0; dof];
        if dim == Dimension::Three {
            qd[n..].fill(spin);
        }
        (q, qd)
    };
    let (coordinates, rates) = match spec {
        InitialSpec::Hanging => straight(0.0),
        InitialSpec::Horizontal => straight(std::f64::consts::FRAC_PI_2),
        InitialSpec::Tilted(a) => straight(*a),
        InitialSpec::File(path) if FinalState::names(path) => {
            let state = FinalState::read_for(path, dim, n)?;
            return Ok(match dim {
                Dimension::Two => InitialConfig {
                    spec: spec.to_string(),
                    coordinates: state.coordinates,
                    rates: state.rates,
                    directions: None,
                },
                Dimension::Three => {
                    let directions = state.start();
                    InitialConfig {
                        spec: spec.to_string(),
                        coordinates: vec![],
                        rates: vec![],
                        directions: Some(directions),
                    }
                }
            });
        }
        InitialSpec::File(path) => {
            let values = read_numbers("--initial", path)?;
            if values.len() != 2 * dof {
                let layout = if dim == Dimension::Two {
                    "θ_1..θ_n then θ̇_1..θ̇_n"
                } else {
                    "θ_1..θ_n, φ_1..φ_n, θ̇_1..θ̇_n, φ̇_1..φ̇_n"
                };
                return Err(CliError::usage(format!(
                    "--initial: {} holds {} numbers, expected {} ({layout}) for n = {n}",
                    path.display(),
                    values.len(),
                    2 * dof
                )));
            }
            (values[..dof].to_vec(), values[dof..].to_vec())
        }
    };
    Ok(InitialConfig { spec: spec.to_string(), coordinates, rates, directions: None })
}

/// What a run was given or chose: the integrator, step and sampling, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct Choice {
    /// The integrator.
    pub integrator: IntegratorKind,
    /// The step, s.
    pub step: f64,
    /// A sample every `every` steps.
    pub every: usize,
    /// Why, in words, for what was chosen (`None` when everything was given).
    pub reason: Option<String>,
}

/// The dp54 integrator's tolerance when `--tolerance` is not given.
pub const DEFAULT_TOLERANCE: f64 = 1e-8;

/// Errors unless the step is finite and positive.
fn check_step(h: f64) -> CliResult<()> {
    if h.is_finite() && h > 0.0 {
        Ok(())
    } else {
        Err(CliError::usage(format!("--step must be finite and positive, got {h}")))
    }
}

/// What `run.json` holds: the program and version that made it, the configuration and
/// (once known) how the run ended.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunFile {
    /// Always `"pendulum"`.
    pub program: String,
    /// The `pendulum-cli` version that wrote the file.
    pub version: String,
    /// Every parameter of the run.
    pub config: RunConfig,
    /// How the run ended; absent while it runs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub outcome: Option<Outcome>,
}

/// How a run ended.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Outcome {
    /// `"completed"`, `"interrupted"` (Ctrl-C) or `"failed"`.
    pub status: String,
    /// The time reached, s.
    pub t: f64,
    /// Steps taken.
    pub steps: u64,
    /// Samples written.
    pub samples: u64,
    /// The error, when the run failed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// What the integrator did (absent in files of earlier versions).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub work: Option<IntegratorWork>,
}

/// What the integrator did over a run: the counts that say what a step cost.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IntegratorWork {
    /// Right-hand sides evaluated by the integrator itself.
    pub rhs_evaluations: u64,
    /// Steps it took (dp54: internal steps accepted; midpoint: the steps asked for).
    pub steps: u64,
    /// dp54: internal steps rejected and retried smaller.
    pub rejected_steps: u64,
    /// Implicit methods: Newton iterations.
    pub newton_iterations: u64,
    /// midpoint: steps split into halves (a link turning more than 1 rad, or Newton not
    /// converging).
    pub halved_steps: u64,
}

impl From<&pendulum_core::integrate::Stats> for IntegratorWork {
    fn from(s: &pendulum_core::integrate::Stats) -> Self {
        Self {
            rhs_evaluations: s.rhs_evaluations,
            steps: s.steps,
            rejected_steps: s.rejected_steps,
            newton_iterations: s.newton_iterations,
            halved_steps: s.halved_steps,
        }
    }
}

impl RunFile {
    /// A run file of this program's version for `config`.
    pub fn new(config: RunConfig) -> Self {
        Self { program: "pendulum".into(), version: env!("CARGO_PKG_VERSION").into(), config, outcome: None }
    }

    /// Reads and checks a run.json; errors name the file and the problem.
    pub fn read(path: &Path) -> CliResult<Self> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| CliError::usage(format!("--from: cannot read {}: {e}", path.display())))?;
        let file: Self = serde_json::from_str(&text).map_err(|e| {
            CliError::usage(format!("--from: {} is not a valid run.json: {e}", path.display()))
        })?;
        if file.program != "pendulum" {
            return Err(CliError::usage(format!(
                "--from: {} was written by '{}', not pendulum",
                path.display(),
                file.program
            )));
        }
        file.config.check().map_err(|e| CliError::usage(format!("--from: {}: {e}", path.display())))?;
        Ok(file)
    }

    /// Writes the file atomically ([`write_json_atomic`](crate::json_file::write_json_atomic)).
    pub fn write_atomic(&self, path: &Path) -> CliResult<()> {
        write_json_atomic(path, self)
    }
}
