//! The options of the commands (clap derive) that more than one command, or the run files, use.

use std::path::{Path, PathBuf};

use clap::{Arg, Args, ValueEnum};
use pendulum_experiment::{Dimension, DriveKind, InitialSpec, IntegratorKind, StageSolver, View};

use serde::Serialize;

use crate::error::{CliError, CliResult};

/// The chain's options, shared by `pendulum simulate`, `modes` and `steady` (`simulate`
/// words the help of --masses and --gravity its own way, see [`Physics::run_help`]).
#[derive(Debug, Args)]
pub struct ChainOptions {
    /// Number of links (default: the length of a --masses or --lengths list, else 3).
    #[arg(long, allow_negative_numbers = true)]
    pub n: Option<usize>,
    /// Masses, kg: one value, a comma list or a file.
    #[arg(long, allow_hyphen_values = true, value_name = "VALUE|LIST|FILE", default_value = "1")]
    pub masses: String,
    /// Rod lengths, m: one value, a comma list or a file.
    #[arg(long, allow_hyphen_values = true, value_name = "VALUE|LIST|FILE", default_value = "0.5")]
    pub lengths: String,
    /// Gravitational acceleration g, m/s².
    #[arg(long, default_value_t = 9.81, allow_negative_numbers = true)]
    pub gravity: f64,
}

/// Options of `pendulum modes`.
#[derive(Debug, Args)]
pub struct ModesArgs {
    /// The chain.
    #[command(flatten)]
    pub chain: ChainOptions,
    /// How many modes, lowest first (default: all, at most 6).
    #[arg(long, allow_negative_numbers = true)]
    pub count: Option<usize>,
    /// Output directory (created if missing).
    #[arg(long, value_name = "DIR", default_value = "pendulum-modes")]
    pub out: PathBuf,
}

/// Options of `pendulum steady`.
#[derive(Debug, Args)]
pub struct SteadyArgs {
    /// The chain.
    #[command(flatten)]
    pub chain: ChainOptions,
    /// Radius R of the pivot's horizontal circle, m (0: pivot fixed on the axis).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub radius: f64,
    /// List every steady shape at these angular speeds, rad/s, ≥ 0, comma list: branch,
    /// nodes (axis crossings + 1, the pivot counted), tip radius, stability (default: at
    /// --omega-max).
    #[arg(long, value_name = "W[,W…]", allow_hyphen_values = true)]
    pub omega: Option<String>,
    /// The exact end of the branches, rad/s (default, for either pivot: 1.25 × the third
    /// critical speed of the chain on a fixed pivot, the highest if n < 3, rounded up to
    /// three digits; at least the largest --omega).
    #[arg(long, allow_negative_numbers = true)]
    pub omega_max: Option<f64>,
    /// Fixed pivot: how many branches, lowest critical speed first (default: every one
    /// leaving the vertical below --omega-max).
    #[arg(long, allow_negative_numbers = true)]
    pub branches: Option<usize>,
    /// Damping λ_i, N·m·s (one value, a comma list or a file; all zero: none): adds the
    /// damped stability of each listed shape. R = 0: damping of the link rates in the turning frame (the
    /// shape is unchanged); R > 0: the chain's own damping of the inertial rates, the
    /// damped steady shape being the 3D relative equilibrium on the circling pivot.
    #[arg(long, allow_hyphen_values = true, value_name = "VALUE|LIST|FILE")]
    pub damping: Option<String>,
    /// Instead of the chain, the continuum it approaches: Kolodner's heavy string of the
    /// chain's length L under its gravity (its critical speeds (j_0k/2)·√(g/L), its steady
    /// shapes at the --omega speeds and its branches up to --omega-max): continuum.csv,
    /// continuum.png.
    #[arg(long)]
    pub continuum: bool,
    /// Output directory (created if missing).
    #[arg(long, value_name = "DIR", default_value = "pendulum-steady")]
    pub out: PathBuf,
}

/// Options of `pendulum simulate`.
#[derive(Debug, Args)]
// `--from` conflicts with the group of every option of `Physics`. clap's derive leaves that
// group empty because `Physics` flattens `ChainOptions`, so its members are given here.
#[command(mut_group("Physics", |group| group.args(Physics::ids())))]
pub struct SimulateArgs {
    /// Repeat the run recorded in this run.json exactly (only --out, --no-plots, --quiet,
    /// --view and --frames may be given with it).
    #[arg(long, value_name = "RUN_JSON", conflicts_with = "Physics")]
    pub from: Option<PathBuf>,
    /// Output directory (created if missing).
    #[arg(long, value_name = "DIR", default_value = "pendulum-run")]
    pub out: PathBuf,
    /// Write only the CSV files and run.json, no energy.png or chain.gif.
    #[arg(long)]
    pub no_plots: bool,
    /// No progress bar and no summary line.
    #[arg(long)]
    pub quiet: bool,
    /// 3D: the plane the animation shows [default: co-rotating for a pivot on a circle, else xz].
    #[arg(long, value_enum)]
    pub view: Option<View>,
    /// Most frames in the animation (samples are thinned to fit) [default: 150].
    #[arg(long)]
    pub frames: Option<usize>,
    /// The chain, its drive and the run.
    #[command(flatten)]
    pub physics: Physics,
}

/// Everything that defines a run (recorded in run.json).
#[derive(Debug, Args)]
#[command(mut_args(Physics::run_help))]
pub struct Physics {
    /// Space dimension.
    #[arg(long, value_enum, default_value = "2")]
    pub dim: Dimension,
    /// The chain: --n, --masses, --lengths, --gravity.
    #[command(flatten)]
    pub chain: ChainOptions,
    /// Damping λ_i, N·m·s: one value, a comma list or a file.
    #[arg(long, allow_hyphen_values = true, value_name = "VALUE|LIST|FILE", default_value = "0")]
    pub damping: String,
    /// Constant torques σ_i on the angles θ_i, N·m (2D only): one value, a list or a file.
    #[arg(long, allow_hyphen_values = true, value_name = "VALUE|LIST|FILE")]
    pub torque: Option<String>,
    /// Pivot motion.
    #[arg(long, value_enum, default_value = "fixed")]
    pub drive: DriveKind,
    /// Harmonic drive: amplitude A, m.
    #[arg(long, default_value_t = 0.05, allow_negative_numbers = true)]
    pub amplitude: f64,
    /// Harmonic or circle drive: angular frequency ω, rad/s.
    #[arg(long, default_value_t = 10.0, allow_negative_numbers = true)]
    pub omega: f64,
    /// Harmonic drive: phase φ, rad.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub phase: f64,
    /// Harmonic drive: direction of oscillation, 2 (2D) or 3 (3D) comma-separated
    /// components (default: vertical).
    #[arg(long, value_name = "X,Y[,Z]", allow_hyphen_values = true)]
    pub direction: Option<String>,
    /// Circle drive: radius R, m.
    #[arg(long, default_value_t = 0.1, allow_negative_numbers = true)]
    pub radius: f64,
    /// Circle drive: ramp the speed linearly from --ramp-from to --omega over this many
    /// seconds, then hold --omega (a speed ramp up or down), s.
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true)]
    pub ramp_time: Option<f64>,
    /// Circle drive with --ramp-time: the speed at t = 0, rad/s [default: 0].
    #[arg(long, value_name = "OMEGA0", allow_negative_numbers = true)]
    pub ramp_from: Option<f64>,
    /// Sampled drive: the pivot's positions, a text file of rows `t, x, y` (2D) or
    /// `t, x, y, z` (3D), s and m, times increasing (commas or spaces; `#` starts a
    /// comment). The pivot moves on the cubic spline through them, and on a straight line
    /// at its end velocity outside them.
    #[arg(long, value_name = "FILE")]
    pub path: Option<std::path::PathBuf>,
    /// Sampled drive: the pivot at rest at the first and last sample (so it rests before
    /// and after them) [default: the natural spline, p̈ = 0 there].
    #[arg(long)]
    pub path_at_rest: bool,
    /// Time integrator. 3D chains are integrated in unit link directions with a
    /// projection onto the rod constraints after every step (midpoint: exact on them).
    /// [default: chosen from the chain and drive, see run.json's "chosen": midpoint for
    /// driven or damped 3D runs, gl2 otherwise]
    #[arg(long, value_enum)]
    pub integrator: Option<IntegratorKind>,
    /// Stage solve of the Gauss–Legendre integrators.
    #[arg(long, value_enum, default_value = "fixed-point")]
    pub solver: StageSolver,
    /// dp54: relative error tolerance per internal step (per state entry, with the same
    /// absolute floor) [default: 1e-8].
    #[arg(long, allow_negative_numbers = true)]
    pub tolerance: Option<f64>,
    /// Step size h, s (the run takes ⌈end / h⌉ equal steps; dp54: the interval it
    /// adapts its own steps within). [default: chosen for the
    /// integrator from the chain's fastest mode and the drive, see run.json's "chosen"]
    #[arg(long, allow_negative_numbers = true)]
    pub step: Option<f64>,
    /// End time, s (the run starts at t = 0).
    #[arg(long, default_value_t = 10.0, allow_negative_numbers = true)]
    pub end: f64,
    /// Initial state: hanging, horizontal, tilted:ANGLE (rad, every link, toward +x), a
    /// previous run's final state (its directory or its final.json: continue exactly
    /// where it ended, 3D in unit directions; with a circling pivot, whose phase restarts
    /// at 0, turned about the vertical to keep its place relative to the pivot), or a
    /// file of numbers: 2D θ_1..θ_n then
    /// θ̇_1..θ̇_n; 3D θ_1..θ_n, φ_1..φ_n, θ̇_1..θ̇_n, φ̇_1..φ̇_n.
    #[arg(long, value_name = "SPEC", default_value = "tilted:1.0")]
    pub initial: InitialSpec,
    /// 3D only: initial azimuthal rate φ̇ of every link, rad/s (a conical swing).
    #[arg(long, allow_negative_numbers = true)]
    pub spin: Option<f64>,
    /// Write a sample every k steps. [default: about 500 samples over the run]
    #[arg(long, value_name = "K", allow_negative_numbers = true)]
    pub every: Option<usize>,
}

impl Physics {
    /// The help of a chain option where a run says more than `modes` and `steady`.
    fn run_help(arg: Arg) -> Arg {
        match arg.get_id().as_str() {
            "masses" => arg.help(
                "Masses, kg: one value for every link, a comma list (one per link) or a file of numbers",
            ),
            "gravity" => arg.help("Gravitational acceleration g, m/s² (along −y in 2D, −z in 3D)"),
            _ => arg,
        }
    }

    /// The ids of the options of a run, in their order.
    fn ids() -> Vec<clap::Id> {
        Self::augment_args(clap::Command::new("physics"))
            .get_arguments()
            .map(|arg| arg.get_id().clone())
            .collect()
    }
}

/// Model kind of `pendulum eval`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ModelKind {
    /// Planar chain, q = (θ_1..θ_n).
    Planar,
    /// Spatial chain in spherical angles, q = (θ_1..θ_n, φ_1..φ_n).
    Spatial,
}

/// The input `pendulum linearize --lqr` designs a gain for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum LqrInput {
    /// Every generalized torque.
    Torque,
    /// The pivot's x acceleration (a cart).
    PivotX,
    /// The pivot's y acceleration.
    PivotY,
    /// The pivot's z acceleration (3D).
    PivotZ,
}

impl LqrInput {
    /// As on the command line.
    pub fn name(self) -> &'static str {
        match self {
            LqrInput::Torque => "torque",
            LqrInput::PivotX => "pivot-x",
            LqrInput::PivotY => "pivot-y",
            LqrInput::PivotZ => "pivot-z",
        }
    }
}

/// Options of `pendulum linearize`.
#[derive(Debug, Args)]
pub struct LinearizeArgs {
    /// The chain and the state, as for `pendulum eval`.
    #[command(flatten)]
    pub state: EvalArgs,
    /// Linearise even where the state is not steady (|q̈| above --tolerance): A is then
    /// the Jacobian along the trajectory through the state.
    #[arg(long)]
    pub force: bool,
    /// Largest |q̈_i| (rad/s²) of a steady state.
    #[arg(long, default_value_t = pendulum_core::STEADY_TOLERANCE, allow_negative_numbers = true)]
    pub tolerance: f64,
    /// Also design the LQR gain K (u = −K (x − x₀)) for this input, with Q = q I, R = r I.
    #[arg(long, value_enum)]
    pub lqr: Option<LqrInput>,
    /// The LQR state weight q.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    pub lqr_q: f64,
    /// The LQR input weight r.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    pub lqr_r: f64,
}

/// Options of `pendulum eval`.
#[derive(Debug, Args)]
pub struct EvalArgs {
    /// The model.
    #[arg(long, value_enum, default_value = "planar")]
    pub model: ModelKind,
    /// Number of links (default: from the lengths of --q, --masses or --lengths).
    #[arg(long, allow_negative_numbers = true)]
    pub n: Option<usize>,
    /// Masses, kg: one value, a comma list or a file.
    #[arg(long, allow_hyphen_values = true, value_name = "VALUE|LIST|FILE", default_value = "1")]
    pub masses: String,
    /// Rod lengths, m: one value, a comma list or a file.
    #[arg(long, allow_hyphen_values = true, value_name = "VALUE|LIST|FILE", default_value = "1")]
    pub lengths: String,
    /// Gravitational acceleration g, m/s².
    #[arg(long, default_value_t = 9.81, allow_negative_numbers = true)]
    pub gravity: f64,
    /// Damping λ_i, N·m·s: one value, a comma list or a file.
    #[arg(long, allow_hyphen_values = true, value_name = "VALUE|LIST|FILE", default_value = "0")]
    pub damping: String,
    /// Coordinates q, rad (planar θ_1..θ_n; spatial θ_1..θ_n, φ_1..φ_n), comma list.
    #[arg(long, value_name = "LIST", allow_hyphen_values = true)]
    pub q: String,
    /// Rates q̇, rad/s, comma list (default: zeros).
    #[arg(long, value_name = "LIST", allow_hyphen_values = true)]
    pub qd: Option<String>,
    /// Generalized torques σ, one per coordinate, N·m (default: zeros).
    #[arg(long, value_name = "LIST", allow_hyphen_values = true)]
    pub torque: Option<String>,
    /// Pivot acceleration p̈, m/s²: 2 (planar) or 3 (spatial) components (default: 0).
    #[arg(long, value_name = "LIST", allow_hyphen_values = true)]
    pub pivot_acceleration: Option<String>,
}

/// Creates `--out`, the output directory, if missing; the error names it.
pub fn create_out(out: &Path) -> CliResult<()> {
    std::fs::create_dir_all(out)
        .map_err(|e| CliError::invalid(format!("--out: cannot create the directory {}: {e}", out.display())))
}

/// `--jobs`: at least 1; by default the number of cores.
pub fn threads(jobs: Option<usize>) -> CliResult<usize> {
    match jobs {
        Some(0) => Err(CliError::invalid("--jobs must be at least 1, got 0")),
        Some(j) => Ok(j),
        None => Ok(pendulum_experiment::options::all_cores()),
    }
}
