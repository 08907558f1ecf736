//! `pendulum atlas`: which shape a whirled 3D chain at rest ends in, over a grid of two of
//! ω, R, λ and the ramp time. Every point is the run of `pendulum sweep` (and `pendulum
//! simulate`) with its parameters; the grid runs in rounds of batches of chains on all
//! cores ([`pendulum_experiment::atlas::Atlas::run`]), atlas.json rewritten after each
//! round (Ctrl-C keeps finished points; `--from atlas.json` resumes), then atlas.csv, the
//! map atlas.png and a character map on stdout.
//!
//! The parts: the options and the command ([`AtlasArgs`], [`atlas`]), the rounds
//! ([`runs`]), the CSV file and the text map ([`csv`]), the picture ([`plot`]).

mod csv;
mod plot;
mod runs;

use std::path::PathBuf;

use clap::Args;
use pendulum_experiment::atlas::{AtlasFile, AtlasKind, AtlasRequest, Damping};
use pendulum_experiment::options::parse_values;

use crate::args::ChainOptions;
use crate::chain_args::per_link_values;
use crate::error::CliResult;
use crate::spec::{expand, per_link};

/// Options of `pendulum atlas`.
#[derive(Debug, Args)]
#[command(mut_group("AtlasPhysics", |group| group.args(AtlasPhysics::ids())))]
pub struct AtlasArgs {
    /// Resume the atlas recorded in this atlas.json: its completed points are kept, the
    /// others run (only --out, --jobs, --again and --quiet may be given with it).
    #[arg(long, value_name = "ATLAS_JSON", conflicts_with = "AtlasPhysics")]
    pub from: Option<PathBuf>,
    /// With --from: run every point again, the completed ones too.
    #[arg(long, requires = "from")]
    pub again: bool,
    /// Output directory (created if missing): atlas.csv, atlas.json, atlas.png.
    #[arg(long, value_name = "DIR", default_value = "pendulum-atlas")]
    pub out: PathBuf,
    /// Threads, at least 1 [default: the number of cores]. The results do not depend on it.
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub jobs: Option<usize>,
    /// No progress lines on stderr (the map on stdout is still printed).
    #[arg(long)]
    pub quiet: bool,
    /// The chain, its drive and the runs.
    #[command(flatten)]
    pub physics: AtlasPhysics,
}

/// Everything that defines an atlas (recorded in atlas.json). Exactly two of --omega,
/// --radius, --damping and --ramp-time have more than one value: they are the axes (the
/// first of them in this order runs along x).
#[derive(Debug, Args)]
pub struct AtlasPhysics {
    /// The drive speeds ω, rad/s, ≥ 0: one value, a comma list W1,W2,… or A:B:N (N evenly
    /// spaced points from A to B).
    #[arg(long, value_name = "W|W,W…|A:B:N", allow_hyphen_values = true, required_unless_present = "from")]
    pub omega: Option<String>,
    /// The --omega values are in units of √(g/L), L the chain's length.
    #[arg(long)]
    pub scaled: bool,
    /// Radius R of the pivot's circle, m (> 0): one value, a list or A:B:N.
    #[arg(long, value_name = "R|R,R…|A:B:N", allow_hyphen_values = true, default_value = "0.02")]
    pub radius: String,
    /// Damping λ_i, N·m·s: one value, a comma list or a file per link; or, as an axis,
    /// A:B:N (one λ for every link at each point).
    #[arg(long, allow_hyphen_values = true, value_name = "VALUE|LIST|FILE|A:B:N", default_value = "0")]
    pub damping: String,
    /// The ramp's length for --kind ramp-up, s: one value or, as an axis, a list or A:B:N
    /// [default: a third of --duration, rounded up to three digits].
    #[arg(long, value_name = "T|T,T…|A:B:N", allow_hyphen_values = true)]
    pub ramp_time: Option<String>,
    /// How each point is started from hanging at rest, one or both, comma-separated:
    /// sudden (ω from t = 0), ramp-up (ω ramped from 0 over --ramp-time).
    #[arg(long, value_enum, value_delimiter = ',', value_name = "KIND[,KIND]", default_values = ["sudden"])]
    pub kind: Vec<AtlasKind>,
    /// The chain: --n, --masses, --lengths, --gravity.
    #[command(flatten)]
    pub chain: ChainOptions,
    /// Simulated time of every point, s [default: as `pendulum sweep`, from the least
    /// damped point].
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true)]
    pub duration: Option<f64>,
    /// RK4 step h, s [default: as `pendulum sweep`, for the fastest, widest, most damped
    /// point].
    #[arg(long, value_name = "H", allow_negative_numbers = true)]
    pub step: Option<f64>,
}

impl AtlasPhysics {
    /// The ids of the options that define an atlas.
    fn ids() -> Vec<clap::Id> {
        Self::augment_args(clap::Command::new("atlas")).get_arguments().map(|a| a.get_id().clone()).collect()
    }

    /// The request these options make.
    fn request(&self) -> CliResult<AtlasRequest> {
        let (masses, lengths) = per_link_values(&self.chain)?;
        let n = masses.len();
        let omega_unit = if self.scaled { "√(g/L)" } else { "rad/s" };
        let omega =
            parse_values("--omega", self.omega.as_deref().unwrap_or(""), ("speed", "speeds"), omega_unit)?;
        let radius = parse_values("--radius", &self.radius, ("radius", "radii"), "m")?;
        let damping = if self.damping.contains(':') {
            Damping::Uniform(parse_values("--damping", &self.damping, ("damping", "dampings"), "N·m·s")?)
        } else {
            Damping::PerLink(expand("--damping", per_link("--damping", &self.damping)?, n)?)
        };
        let ramp_time = match &self.ramp_time {
            Some(spec) => parse_values("--ramp-time", spec, ("ramp time", "ramp times"), "s")?,
            None => vec![],
        };
        Ok(AtlasRequest {
            masses,
            lengths,
            gravity: self.chain.gravity,
            omega,
            scaled: self.scaled,
            radius,
            damping,
            ramp_time,
            kinds: self.kind.clone(),
            duration: self.duration,
            step: self.step,
        })
    }
}

/// Runs `pendulum atlas`.
pub fn atlas(args: &AtlasArgs) -> CliResult<()> {
    let (config, points) = match &args.from {
        Some(path) => {
            let file = AtlasFile::read(path)?;
            if !args.quiet
                && let Some(warning) = pendulum_experiment::other_version(path, &file.version)
            {
                eprintln!("pendulum: warning: {warning}");
            }
            let points = (!args.again).then(|| file.resumed_points());
            (file.config, points)
        }
        None => (args.physics.request()?.resolve()?, None),
    };
    let jobs = crate::args::threads(args.jobs)?;
    crate::args::create_out(&args.out)?;
    let run = runs::AtlasRun::new(config, points, args.out.clone(), jobs, args.quiet)?;
    let points = {
        let _stops = crate::interrupt::StopsItself::enter();
        run.run()?
    };
    let config = run.config();
    csv::write(&args.out.join("atlas.csv"), config, &points)?;
    csv::map(config, &points);
    plot::draw(&args.out.join("atlas.png"), config, run.derived(), &points)?;
    run.conclude(&points)
}
