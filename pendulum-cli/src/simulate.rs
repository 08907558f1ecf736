//! `pendulum simulate`: the run loop, streaming the trajectory and energy CSVs, then the
//! plots, run.json and the summary line.

use std::fs::File;
use std::io::{BufWriter, IsTerminal, Write};
use std::ops::ControlFlow;
use std::path::PathBuf;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use pendulum_core::integrate::State;
use pendulum_core::trajectory;

use crate::args::{Dimension, SimulateArgs, StageSolver, View};
use crate::choice::{choose, drive_frequency, fastest_mode, suggested_step};
use crate::config::{Outcome, RunConfig, RunFile};
use crate::error::{CliError, CliResult, io_failed};
use crate::final_state::FinalState;
use crate::interrupt::INTERRUPTED;
use crate::json_file::warn_other_version;
use crate::models::{AnySimulation, Method, Motion, Sample, Simulation, build};
use crate::plot;
use crate::render;
use crate::whirl::Whirl;

/// Runs `pendulum simulate`.
pub fn simulate(args: &SimulateArgs, demo: bool) -> CliResult<()> {
    let mut config = match &args.from {
        Some(path) => {
            let file = RunFile::read(path)?;
            if !args.quiet {
                warn_other_version(path, &file.version);
            }
            file.config
        }
        None => RunConfig::from_args(&args.physics, View::Xz, 150, choose)?,
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
    let mut progress = Progress::new(total_steps, config.end, options.quiet);
    let system = simulation.system();
    let mut solver = simulation.integrator(Method::of(config))?;
    let mut state = State::new(0.0, simulation.initial_state());
    let mut kept = Kept::default();
    let whirl = Whirl::of(config)?;
    let mut tracker = whirl.as_ref().map(Whirl::tracker).transpose()?;
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
            if let Some(tracker) = &mut tracker
                && let Err(e) = tracker.push(t, &sample.state)
            {
                write_error = Some(e);
                return ControlFlow::Break(());
            }
            sample_count += 1;
            progress.at(t, (t / config.end * total_steps as f64).round() as u64);
            if INTERRUPTED.load(Ordering::SeqCst) {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        });
    progress.finish();
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
    let motion = &state.x().as_slice()[..system.motion_len()];
    let phase = whirl.as_ref().map(|w| w.phase(state.t()));
    FinalState::new(config.dim, n, state.t(), motion, phase).write(out)?;
    // A whirled chain: its shape in the turning frame, in the user's terms (stdout).
    if let Some(tracker) = &tracker {
        tracker.finish(out, options.plots)?;
    }
    run_file.outcome = Some(Outcome {
        status: status.into(),
        t: state.t(),
        steps,
        samples: sample_count,
        error: error.clone(),
        work: Some(solver.stats().into()),
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
                if tracker.is_some() {
                    " (trajectory.csv, energy.csv, run.json, final.json, shape.json, energy.png, chain.gif, shape.png)"
                } else {
                    " (trajectory.csv, energy.csv, run.json, final.json, energy.png, chain.gif)"
                }
            },
        );
    }
    match result {
        Ok(s) if s.stopped_early => Err(CliError::interrupted(format!(
            "interrupted: the run was cut at t = {} s of {} s; files in {} hold what was computed \
             (run.json says \"interrupted\")",
            state.t(),
            config.end,
            out.display()
        ))),
        Ok(_) => Ok(()),
        Err(e) => Err(CliError::failed(format!(
            "the run stopped at t = {} s: {e}{}; files hold what was computed",
            state.t(),
            stage_solve_hint(&e, config)
        ))),
    }
}

/// Advice for a failed step: a stage solve that did not converge (or a step that blew
/// up) usually means the step is too long for the chain's fastest mode or the drive;
/// names both and suggests a step. Empty for other errors.
fn stage_solve_hint(e: &pendulum_core::Error, config: &RunConfig) -> String {
    let pendulum_core::Error::StepFailed { source, .. } = e else { return String::new() };
    let stage_failure = matches!(**source, pendulum_core::Error::StageSolveFailed { .. });
    let blew_up = matches!(**source, pendulum_core::Error::NonFinite { .. });
    if !stage_failure && !blew_up {
        return String::new();
    }
    let (fastest, drive) = (fastest_mode(config), drive_frequency(config));
    let suggested = suggested_step(fastest, drive);
    let cause = match drive {
        Some(w) => format!(
            "the step --step {} is likely too long for the chain's fastest mode (about {fastest:.3e} rad/s) \
             or the drive ({w} rad/s)",
            config.step
        ),
        None => format!(
            "the step --step {} is likely too long for the chain's fastest mode (about {fastest:.3e} rad/s)",
            config.step
        ),
    };
    let other = match (stage_failure, config.solver) {
        (true, StageSolver::FixedPoint) => ", --solver newton or --integrator rk4",
        (true, StageSolver::Newton) | (false, _) => " or --integrator rk4",
    };
    format!(" ({cause}: try --step {suggested:.1e}{other})")
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

/// How often a run without a terminal reports how far it is.
const PLAIN_PROGRESS_EVERY: Duration = Duration::from_secs(5);

/// Progress of a run of 2000 steps or more: a bar on a terminal; without one (a pipe, a
/// log file, CI), a plain line every [`PLAIN_PROGRESS_EVERY`] instead.
struct Progress {
    bar: ProgressBar,
    /// Plain lines: `(run end t1, when the last line was printed)`.
    plain: Option<(f64, Instant)>,
    started: Instant,
}

impl Progress {
    fn new(steps: u64, end: f64, quiet: bool) -> Self {
        let started = Instant::now();
        if quiet || steps < 2000 {
            return Self { bar: ProgressBar::hidden(), plain: None, started };
        }
        if !std::io::stderr().is_terminal() {
            return Self { bar: ProgressBar::hidden(), plain: Some((end, started)), started };
        }
        let bar = ProgressBar::with_draw_target(Some(steps), ProgressDrawTarget::stderr());
        if let Ok(style) =
            ProgressStyle::with_template("{bar:40} {pos}/{len} steps, {elapsed} elapsed, ETA {eta}")
        {
            bar.set_style(style);
        }
        Self { bar, plain: None, started }
    }

    /// The run reached time `t` (s), step `step`.
    fn at(&mut self, t: f64, step: u64) {
        self.bar.set_position(step);
        if let Some((end, last)) = &mut self.plain
            && last.elapsed() >= PLAIN_PROGRESS_EVERY
        {
            *last = Instant::now();
            let fraction = (t / *end).clamp(0.0, 1.0);
            let elapsed = self.started.elapsed().as_secs_f64();
            let eta = if fraction > 0.0 { elapsed * (1.0 - fraction) / fraction } else { f64::NAN };
            eprintln!(
                "pendulum: t = {t:.3} s of {end} s ({:.0} %), {elapsed:.0} s elapsed, about {eta:.0} s to go",
                100.0 * fraction
            );
        }
    }

    fn finish(&self) {
        self.bar.finish_and_clear();
    }
}
