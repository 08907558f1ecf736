//! `pendulum sweep`: which shape a whirled 3D chain chooses. For every drive speed ω of a
//! list or range and every way of starting it (`--kind`), the chain is run from hanging at
//! rest (or, ramping down, from the previous point's end) with its pivot on a horizontal
//! circle, RK4 + projection, and the shape analysis of `pendulum simulate` reports what it
//! settled into. Points run in parallel (rayon; the independent ones as batches of chains in
//! SIMD lanes, `pendulum_core::batch`); the results go to sweep.csv, sweep.json
//! (enough to repeat the sweep with `--from`) and sweep.png (the chain's choices over the
//! steady branch diagram of `pendulum steady --radius R`), and a table on stdout.
//!
//! The parts: the options and the command ([`SweepArgs`], [`sweep`]), the lines on stderr
//! and sweep.json after each point ([`report`]), the table ([`table`]), the picture
//! ([`plot`]). The sweep itself (its parameters, sweep.json and sweep.csv, the runs) is
//! the run library's ([`pendulum_experiment::sweep`]), shared with Python.

mod plot;
mod report;
mod table;

use std::path::PathBuf;
use std::sync::atomic::Ordering;
use std::time::Instant;

use clap::Args;
use pendulum_experiment::sweep::{Sweep, SweepFile, SweepRequest};

use crate::args::ChainOptions;
use crate::chain_args::per_link_values;
use crate::error::{CliError, CliResult};
use crate::interrupt::INTERRUPTED;
use crate::spec::{expand, per_link};

pub use pendulum_experiment::sweep::SweepKind;

/// Options of `pendulum sweep`.
#[derive(Debug, Args)]
// `--from` conflicts with every option of `SweepPhysics`; clap's derive leaves that group
// empty because it flattens `ChainOptions`, so its members are given here.
#[command(mut_group("SweepPhysics", |group| group.args(SweepPhysics::ids())))]
pub struct SweepArgs {
    /// Repeat the sweep recorded in this sweep.json exactly (only --out, --jobs and --quiet
    /// may be given with it).
    #[arg(long, value_name = "SWEEP_JSON", conflicts_with = "SweepPhysics")]
    pub from: Option<PathBuf>,
    /// Output directory (created if missing): sweep.csv, sweep.json, sweep.png.
    #[arg(long, value_name = "DIR", default_value = "pendulum-sweep")]
    pub out: PathBuf,
    /// Points run at once, at least 1 [default: the number of cores]. The results do not
    /// depend on it.
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub jobs: Option<usize>,
    /// No line per finished point on stderr (the table on stdout is still printed).
    #[arg(long)]
    pub quiet: bool,
    /// The chain, its drive and the runs.
    #[command(flatten)]
    pub physics: SweepPhysics,
}

/// Everything that defines a sweep (recorded in sweep.json).
#[derive(Debug, Args)]
pub struct SweepPhysics {
    /// The drive speeds ω, rad/s, ≥ 0: a comma list W1,W2,… or A:B:N, N evenly spaced
    /// points from A to B (N ≥ 1; N = 1 is A).
    #[arg(long, value_name = "W[,W…]|A:B:N", allow_hyphen_values = true, required_unless_present = "from")]
    pub omega: Option<String>,
    /// The --omega values are in units of √(g/L), L the chain's length (the sum of the
    /// rod lengths); the outputs give ω in rad/s and in these units.
    #[arg(long)]
    pub scaled: bool,
    /// How each point is started, one or more, comma-separated (sudden and ramp-up points
    /// are independent; the ramp-down points run one after the other).
    #[arg(
        long,
        value_enum,
        value_delimiter = ',',
        value_name = "KIND[,KIND…]",
        default_values = ["sudden", "ramp-up", "ramp-down"]
    )]
    pub kind: Vec<SweepKind>,
    /// The chain: --n, --masses, --lengths, --gravity.
    #[command(flatten)]
    pub chain: ChainOptions,
    /// Damping λ_i, N·m·s: one value, a comma list or a file (the chain's Rayleigh function
    /// ½ Σ λ_i |u̇_i|², inertial rates, as `pendulum simulate`).
    #[arg(long, allow_hyphen_values = true, value_name = "VALUE|LIST|FILE", default_value = "0")]
    pub damping: String,
    /// Radius R of the pivot's horizontal circle, m (> 0).
    #[arg(long, default_value_t = 0.02, allow_negative_numbers = true)]
    pub radius: f64,
    /// Simulated time of every point, s, ramp included [default: 12 decay times 1/σ of the
    /// chain's first mode at rest, σ = ½ Σ λ_i v_i² (v mass-normalised), rounded up to
    /// three digits; undamped: 200 periods of that mode].
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true)]
    pub duration: Option<f64>,
    /// The ramps' length, s, shorter than --duration [default: a third of --duration, rounded
    /// up to three digits].
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true)]
    pub ramp_time: Option<f64>,
    /// RK4 step h, s [default: 0.5 / (the chain's fastest mode at the largest ω), at most a
    /// fortieth of the fastest drive period, as `pendulum simulate` suggests, and at most
    /// 1 / (the fastest damping rate); rounded down to two digits].
    #[arg(long, value_name = "H", allow_negative_numbers = true)]
    pub step: Option<f64>,
    /// Not an option of `pendulum sweep` (sweeps are 3D): refused with a message.
    #[arg(long, hide = true, allow_hyphen_values = true)]
    pub dim: Option<String>,
}

impl SweepPhysics {
    /// The request these options make.
    fn request(&self) -> CliResult<SweepRequest> {
        if let Some(dim) = &self.dim {
            return Err(CliError::invalid(format!(
                "--dim {dim}: not an option of pendulum sweep: sweeps are 3D (the pivot circles the vertical axis)"
            )));
        }
        let (masses, lengths) = per_link_values(&self.chain)?;
        let damping = expand("--damping", per_link("--damping", &self.damping)?, masses.len())?;
        Ok(SweepRequest {
            masses,
            lengths,
            gravity: self.chain.gravity,
            damping,
            radius: self.radius,
            omega_spec: self.omega.clone().unwrap_or_default(),
            scaled: self.scaled,
            kinds: self.kind.clone(),
            duration: self.duration,
            ramp_time: self.ramp_time,
            step: self.step,
        })
    }

    /// The ids of the options that define a sweep.
    fn ids() -> Vec<clap::Id> {
        Self::augment_args(clap::Command::new("sweep"))
            .get_arguments()
            .map(|arg| arg.get_id().clone())
            .collect()
    }
}

/// Runs `pendulum sweep`.
pub fn sweep(args: &SweepArgs) -> CliResult<()> {
    let config = match &args.from {
        Some(path) => {
            let file = SweepFile::read(path)?;
            if !args.quiet
                && let Some(warning) = pendulum_experiment::other_version(path, &file.version)
            {
                eprintln!("pendulum: warning: {warning}");
            }
            file.config
        }
        None => args.physics.request()?.resolve()?,
    };
    let jobs = crate::args::threads(args.jobs)?;
    crate::args::create_out(&args.out)?;
    let sweep = Sweep::new(config)?;
    let started = Instant::now();
    if !args.quiet {
        report::header(&sweep, jobs);
    }
    let out = &args.out;
    sweep.file(sweep.points()).write_atomic(&out.join("sweep.json"))?;
    let points = {
        let _stops = crate::interrupt::StopsItself::enter();
        let stop = || INTERRUPTED.load(Ordering::Relaxed);
        let on_point = |points: &[_], i, finished| {
            report::point_done(&sweep, out, args.quiet, started, (points, i, finished))
        };
        sweep.run(jobs, &stop, &on_point)?
    };
    sweep.file(&points).write_atomic(&out.join("sweep.json"))?;
    let config = sweep.config();
    pendulum_experiment::sweep::csv::write(&out.join("sweep.csv"), &points)?;
    table::table(config, &points);
    plot::draw(&out.join("sweep.png"), config, &points)?;
    report::conclude(&sweep, &points, out, (jobs, args.quiet), started)
}
