//! `pendulum simulate`: the run loop, streaming the trajectory and energy CSVs, then the
//! plots, run.json and the summary line.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::ops::ControlFlow;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use pendulum_core::integrate::State;
use pendulum_core::trajectory;

use crate::args::{Dimension, SimulateArgs, StageSolver, View};
use crate::config::{Outcome, RunConfig, RunFile};
use crate::error::{CliError, CliResult, io_failed};
use crate::models::{AnySimulation, Motion, Sample, Simulation, build};
use crate::plot;
use crate::render;

/// Set by the Ctrl-C handler; the run stops at the next sample and writes its files.
pub static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// Runs `pendulum simulate`.
pub fn simulate(args: &SimulateArgs, demo: bool) -> CliResult<()> {
    let mut config = match &args.from {
        Some(path) => {
            let file = RunFile::read(path)?;
            if file.version != env!("CARGO_PKG_VERSION") && !args.quiet {
                eprintln!(
                    "pendulum: warning: {} was written by pendulum {}, this is {}; results may differ",
                    path.display(),
                    file.version,
                    env!("CARGO_PKG_VERSION")
                );
            }
            file.config
        }
        None => RunConfig::from_args(&args.physics, View::Xz, 150)?,
    };
    // Presentation only: may differ from the recorded run.
    config.view = args.view.unwrap_or(config.view);
    config.frames = args.frames.unwrap_or(config.frames);
    config.check()?;
    // A value the chain, drive or state rejects names the file it came from.
    let simulation = build(&config).map_err(|e| match &args.from {
        Some(path) => e.context(format_args!("--from {}", path.display())),
        None => e,
    })?;
    std::fs::create_dir_all(&args.out).map_err(|e| {
        CliError::usage(format!("--out: cannot create the directory {}: {e}", args.out.display()))
    })?;
    let options = Options { out: args.out.clone(), plots: !args.no_plots, quiet: args.quiet };
    if demo && !args.quiet {
        eprintln!(
            "pendulum: no options given, running the demo (a triple pendulum released from 1 rad, 10 s); \
             see `pendulum simulate --help`"
        );
    }
    match &simulation {
        AnySimulation::Planar(s) => execute(s, &config, &options),
        AnySimulation::Spatial(s) => execute(s, &config, &options),
    }
}

/// Where and what to write.
struct Options {
    out: PathBuf,
    plots: bool,
    quiet: bool,
}

/// A CSV file written through a buffer.
struct Csv {
    path: PathBuf,
    writer: BufWriter<File>,
}

impl Csv {
    fn create(path: PathBuf, header: &[String]) -> CliResult<Self> {
        let file = File::create(&path).map_err(|e| io_failed("create", &path, e))?;
        let mut csv = Self { path, writer: BufWriter::new(file) };
        let line = header.join(",");
        csv.line(&line)?;
        Ok(csv)
    }

    fn line(&mut self, line: &str) -> CliResult<()> {
        writeln!(self.writer, "{line}").map_err(|e| io_failed("write", &self.path, e))
    }

    fn row(&mut self, values: impl IntoIterator<Item = f64>) -> CliResult<()> {
        let mut first = true;
        for v in values {
            let sep = if first { "" } else { "," };
            first = false;
            write!(self.writer, "{sep}{v:?}").map_err(|e| io_failed("write", &self.path, e))?;
        }
        writeln!(self.writer).map_err(|e| io_failed("write", &self.path, e))
    }

    fn finish(mut self) -> CliResult<()> {
        self.writer.flush().map_err(|e| io_failed("flush", &self.path, e))?;
        self.writer.get_ref().sync_all().map_err(|e| io_failed("sync", &self.path, e))
    }
}

/// Columns of the trajectory: t, the simulation's state columns, the pivot and every
/// mass (x, y in 2D; x, y, z in 3D).
fn trajectory_header<P: Motion>(simulation: &Simulation<P>, dim: Dimension, n: usize) -> Vec<String> {
    let axes: &[&str] = if dim == Dimension::Two { &["x", "y"] } else { &["x", "y", "z"] };
    let mut header = vec!["t".to_string()];
    header.extend(simulation.state_columns());
    header.extend(axes.iter().map(|a| format!("pivot_{a}")));
    for i in 1..=n {
        header.extend(axes.iter().map(|a| format!("{a}{i}")));
    }
    header
}

const ENERGY_HEADER: [&str; 6] = ["t", "energy", "drive_work", "torque_work", "damped", "balance_residual"];

/// What the plots need from the samples, kept in memory while the CSVs stream out.
#[derive(Default)]
struct Kept {
    times: Vec<f64>,
    energy: Vec<f64>,
    /// `H_in(0) + W_drive + W_torque − E_damped`: the energy the ledger predicts.
    predicted: Vec<f64>,
}

/// Integrates, writes every output, prints the summary.
fn execute<P: Motion>(simulation: &Simulation<P>, config: &RunConfig, options: &Options) -> CliResult<()> {
    let out = &options.out;
    let n = config.links();
    let mut run_file = RunFile::new(config.clone());
    let run_json = out.join("run.json");
    run_file.write_atomic(&run_json)?;

    let (total_steps, _) = trajectory::plan(0.0, config.end, config.step)?;

    let mut trajectory_csv =
        Csv::create(out.join("trajectory.csv"), &trajectory_header(simulation, config.dim, n))?;
    let header: Vec<String> = ENERGY_HEADER.iter().map(|s| s.to_string()).collect();
    let mut energy_csv = Csv::create(out.join("energy.csv"), &header)?;

    let dims = if config.dim == Dimension::Two { 2 } else { 3 };
    let progress = progress_bar(total_steps, options.quiet);
    let system = simulation.system();
    let mut solver = simulation.integrator(config.integrator, config.solver);
    let mut state = State::new(0.0, simulation.initial_state());
    let mut kept = Kept::default();
    let mut write_error = None;
    let mut initial_energy = None;
    let mut sample_count: u64 = 0;
    let result =
        trajectory::run(&mut *solver, system, &mut state, config.end, config.step, config.every, |t, x| {
            let sample = simulation.sample(t, x);
            let h0 = *initial_energy.get_or_insert(sample.energy);
            if let Err(e) = write_sample(&mut trajectory_csv, &mut energy_csv, &sample, h0, dims) {
                write_error = Some(e);
                return ControlFlow::Break(());
            }
            keep(&mut kept, &sample, h0);
            sample_count += 1;
            progress.set_position((t / config.end * total_steps as f64).round() as u64);
            if INTERRUPTED.load(Ordering::SeqCst) {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        });
    progress.finish_and_clear();
    trajectory_csv.finish()?;
    energy_csv.finish()?;
    if let Some(e) = write_error {
        return Err(e);
    }

    let (status, error, steps) = match &result {
        Ok(s) if s.stopped_early => ("interrupted", None, s.steps),
        Ok(s) => ("completed", None, s.steps),
        Err(e) => ("failed", Some(e.to_string()), failed_steps(e)),
    };
    let mut images = Vec::new();
    if options.plots && !kept.times.is_empty() {
        let energy_png = out.join("energy.png");
        plot::energy(&energy_png, &kept.times, &kept.energy, &kept.predicted, energy_scale(config))?;
        let gif = render::chain_gif(out, config, state.t(), options.quiet)?;
        images.extend([energy_png, gif]);
    }
    run_file.outcome = Some(Outcome {
        status: status.into(),
        t: state.t(),
        steps,
        samples: sample_count,
        error: error.clone(),
    });
    run_file.write_atomic(&run_json)?;

    if !options.quiet {
        let drift =
            kept.energy.iter().zip(&kept.predicted).map(|(h, p)| (h - p).abs()).fold(0.0_f64, f64::max);
        eprintln!(
            "pendulum: {status}: {n} links, {dim}D, t = {t:.4} s in {steps} steps ({integrator:?}, h = {h} s); \
             max |H − H0 − W| = {drift:.3e} J; {samples} samples; files in {dir}{images}",
            dim = if config.dim == Dimension::Two { 2 } else { 3 },
            t = state.t(),
            integrator = config.integrator,
            h = config.step,
            samples = sample_count,
            dir = out.display(),
            images = if images.is_empty() {
                ""
            } else {
                " (trajectory.csv, energy.csv, run.json, energy.png, chain.gif)"
            },
        );
    }
    match result {
        Ok(_) => Ok(()),
        Err(e) => Err(CliError::failed(format!(
            "the run stopped at t = {} s: {e}{}; files hold what was computed",
            state.t(),
            stage_solve_hint(&e, config.solver)
        ))),
    }
}

/// Advice for a failed Gauss–Legendre stage solve, empty for other errors.
fn stage_solve_hint(e: &pendulum_core::Error, solver: StageSolver) -> &'static str {
    let stage_failure = matches!(e, pendulum_core::Error::StepFailed { source, .. }
        if matches!(**source, pendulum_core::Error::StageSolveFailed { .. }));
    match (stage_failure, solver) {
        (false, _) => "",
        (true, StageSolver::FixedPoint) => {
            " (the fixed-point stage solve converges only for steps shorter than about the \
             chain's fastest period: use a smaller --step, --solver newton or --integrator rk4)"
        }
        (true, StageSolver::Newton) => " (use a smaller --step, or --integrator rk4)",
    }
}

/// The steps a failed run completed (the failed step's number).
fn failed_steps(e: &pendulum_core::Error) -> u64 {
    match e {
        pendulum_core::Error::StepFailed { step, .. } => *step,
        _ => 0,
    }
}

/// A scale for the energy axis (J): the work gravity could do on the chain,
/// `Σ_k m_k g (l_1 + … + l_k)`, or the total mass times 1 m²/s² without gravity.
fn energy_scale(config: &RunConfig) -> f64 {
    let mut reach = 0.0;
    let mut scale = 0.0;
    for (m, l) in config.masses.iter().zip(&config.lengths) {
        reach += l;
        scale += m * config.gravity.max(1.0) * reach;
    }
    scale
}

/// Writes one sample: a trajectory row (positions with `dims` components) and an
/// energy row with the balance residual `H − H0 − (W_drive + W_torque − E_damped)`.
fn write_sample(trajectory: &mut Csv, energy: &mut Csv, s: &Sample, h0: f64, dims: usize) -> CliResult<()> {
    let positions = std::iter::once(&s.pivot).chain(&s.masses).flat_map(|r| r[..dims].iter().copied());
    trajectory.row(std::iter::once(s.t).chain(s.state.iter().copied()).chain(positions))?;
    let l = &s.ledger;
    let residual = s.energy - h0 - l.net();
    energy.row([s.t, s.energy, l.drive, l.torque, l.damped, residual])
}

fn keep(kept: &mut Kept, s: &Sample, h0: f64) {
    kept.times.push(s.t);
    kept.energy.push(s.energy);
    kept.predicted.push(h0 + s.ledger.net());
}

/// A progress bar for runs of 2000 steps or more, drawn only on a terminal.
fn progress_bar(steps: u64, quiet: bool) -> ProgressBar {
    if quiet || steps < 2000 {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(Some(steps), ProgressDrawTarget::stderr());
    if let Ok(style) =
        ProgressStyle::with_template("{bar:40} {pos}/{len} steps, {elapsed} elapsed, ETA {eta}")
    {
        bar.set_style(style);
    }
    bar
}
