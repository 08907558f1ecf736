//! `pendulum simulate`: the run loop, streaming the trajectory and energy CSVs, then the
//! plots, run.json and the summary line.

use std::io::IsTerminal;
use std::ops::ControlFlow;
use std::path::PathBuf;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use pendulum_experiment::{
    IntegratorKind, RunConfig, RunFile, Sample, SampleFiles, Sink, StageSolver, Status,
    balance::potential_scale, build, chain, drive_frequency, fastest_mode, other_version, suggested_step,
};

use crate::args::SimulateArgs;
use crate::error::{CliError, CliResult};
use crate::interrupt::{INTERRUPTED, StopsItself};
use crate::plot;
use crate::render;
use crate::request;
use crate::whirl;

/// Runs `pendulum simulate`.
pub fn simulate(args: &SimulateArgs, demo: bool) -> CliResult<()> {
    let mut config = match &args.from {
        Some(path) => {
            let file = RunFile::read(path)?;
            if !args.quiet
                && let Some(warning) = other_version(path, &file.version)
            {
                eprintln!("pendulum: warning: {warning}");
            }
            file.config
        }
        None => request::resolve(&args.physics, 150)?,
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
    crate::args::create_out(&args.out)?;
    let options = Options { out: args.out.clone(), plots: !args.no_plots, quiet: args.quiet };
    if !args.quiet {
        let chain = pendulum_experiment::words::chain_words(
            &config.masses,
            &config.lengths,
            config.gravity,
            &config.damping,
        );
        eprintln!("pendulum: {}D, {chain}", config.dim.space());
    }
    if demo && !args.quiet {
        eprintln!(
            "pendulum: no options given, running the demo (a triple pendulum released from 1 rad, 10 s); \
             see `pendulum simulate --help`"
        );
    }
    execute(&simulation, &config, &options)
}

/// Where and what to write.
struct Options {
    out: PathBuf,
    plots: bool,
    quiet: bool,
}

/// What the plots need from the samples, kept in memory while the CSVs stream out.
#[derive(Default)]
struct Kept {
    times: Vec<f64>,
    energy: Vec<f64>,
    /// `H_in(0) + W_drive + W_torque − E_damped`: the energy the ledger predicts.
    predicted: Vec<f64>,
}

impl Sink for Kept {
    fn sample(&mut self, s: &Sample, h0: f64) -> CliResult<()> {
        self.times.push(s.t);
        self.energy.push(s.energy);
        self.predicted.push(h0 + s.ledger.net());
        Ok(())
    }
}

/// Integrates, writes every output, prints the summary.
fn execute(
    simulation: &pendulum_experiment::AnySimulation,
    config: &RunConfig,
    options: &Options,
) -> CliResult<()> {
    let out = &options.out;
    let n = config.links();
    let mut run_file = RunFile::new(config.clone());
    let run_json = out.join("run.json");
    run_file.write_atomic(&run_json)?;

    let (total_steps, _) = pendulum_core::trajectory::plan(0.0, config.end, config.step)?;
    let mut files = SampleFiles::create(out, &simulation.layout(config))?;
    let mut kept = Kept::default();
    let mut progress = Progress::new(total_steps, config.end, options.quiet);
    let stops = StopsItself::enter();
    let report = simulation.run(config, &mut [&mut files, &mut kept], &mut |t| {
        progress.at(t, (t / config.end * total_steps as f64).round() as u64);
        if INTERRUPTED.load(Ordering::SeqCst) { ControlFlow::Break(()) } else { ControlFlow::Continue(()) }
    });
    drop(stops);
    progress.finish();
    files.finish()?;
    let report = report?;

    // The data first, so that a Ctrl-C while drawing (which ends the program at once)
    // leaves them complete.
    report.final_state.write(out)?;
    run_file.outcome = Some(report.outcome());
    run_file.write_atomic(&run_json)?;
    // A whirled chain: its shape in the turning frame, in the user's terms (stdout).
    let shape = report.shape.as_ref().map(|shape| shape.as_ref().map_err(Clone::clone)).transpose()?;
    if let Some(shape) = shape {
        whirl::write(shape, out)?;
    }
    let mut images = Vec::new();
    if options.plots && !kept.times.is_empty() {
        let energy_png = out.join("energy.png");
        plot::energy(&energy_png, &kept.times, &kept.energy, &kept.predicted, potential_scale(config))?;
        let gif = render::chain_gif(out, config, report.t, options.quiet)?;
        images.extend([energy_png, gif]);
    }
    if let Some(shape) = shape {
        whirl::present(shape, out, options.plots)?;
    }

    // Said even with --quiet: the run's answer is not to be trusted as it stands.
    for warning in report.warnings() {
        eprintln!("pendulum: warning: {warning}");
    }
    let status = report.status.name();
    if !options.quiet {
        let balance = &report.balance;
        let off = if balance.is_off() {
            format!(" ({:.1} % of the energy scale: off)", 100.0 * balance.fraction())
        } else {
            String::new()
        };
        eprintln!(
            "pendulum: {status}: {n} links, {dim}D, t = {t:.4} s in {steps} steps ({integrator:?}, h = {h} s); \
             max |H − H0 − W| = {drift:.3e} J{off}; {samples} samples; files in {dir}{images}",
            drift = balance.residual,
            dim = config.dim.space(),
            t = report.t,
            steps = report.steps,
            integrator = config.integrator,
            h = config.step,
            samples = report.samples,
            dir = out.display(),
            images = if images.is_empty() {
                ""
            } else {
                if report.shape.is_some() {
                    " (trajectory.csv, energy.csv, run.json, final.json, shape.json, energy.png, chain.gif, shape.png)"
                } else {
                    " (trajectory.csv, energy.csv, run.json, final.json, energy.png, chain.gif)"
                }
            },
        );
    }
    match (report.status, report.error) {
        (Status::Interrupted, _) => Err(CliError::interrupted(format!(
            "interrupted: the run was cut at t = {} s of {} s; files in {} hold what was computed \
             (run.json says \"interrupted\")",
            report.t,
            config.end,
            out.display()
        ))),
        (Status::Failed, Some(e)) => {
            let hint = stage_solve_hint(&e, config);
            Err(CliError::failed(match e {
                // Names its time itself.
                pendulum_core::Error::BlewUp { .. } => format!("{e}{hint}; files hold what was computed"),
                _ => {
                    format!("the run stopped at t = {} s: {e}{hint}; files hold what was computed", report.t)
                }
            }))
        }
        _ => Ok(()),
    }
}

/// Advice for a run that failed: a stage solve that did not converge or a run that blew
/// up usually means the step is too long for the chain's fastest mode or the drive; names
/// both and suggests what the user has not already chosen (a shorter step, Newton's stage
/// solve, RK4). Empty for other errors.
fn stage_solve_hint(e: &pendulum_core::Error, config: &RunConfig) -> String {
    use pendulum_core::Error;
    let source = match e {
        Error::StepFailed { source, .. } => &**source,
        other => other,
    };
    let stage_failure = matches!(source, Error::StageSolveFailed { .. });
    let blew_up =
        matches!(source, Error::NonFinite { .. } | Error::NonFiniteState { .. } | Error::BlewUp { .. });
    if !stage_failure && !blew_up {
        return String::new();
    }
    let fastest = chain(config).map_or(0.0, |c| fastest_mode(&c, &config.drive));
    let drive = drive_frequency(&config.drive);
    let suggested = suggested_step(fastest, drive);
    let mut tries = Vec::new();
    // A suggestion must be a real change: shorter than the step already taken.
    if suggested < 0.9 * config.step.abs() {
        tries.push(format!("--step {suggested:.1e}"));
    }
    if stage_failure && config.solver == StageSolver::FixedPoint {
        tries.push("--solver newton".into());
    }
    if config.integrator != IntegratorKind::Rk4 && config.integrator != IntegratorKind::Dp54 {
        tries.push("--integrator rk4".into());
    }
    let modes = match drive {
        Some(w) => format!("the chain's fastest mode (about {fastest:.3e} rad/s) or the drive ({w} rad/s)"),
        None => format!("the chain's fastest mode (about {fastest:.3e} rad/s)"),
    };
    let cause = if tries.iter().any(|t| t.starts_with("--step")) {
        format!("the step --step {} is likely too long for {modes}", config.step)
    } else {
        format!("the step --step {} is already short for {modes}", config.step)
    };
    match tries.len() {
        0 => format!(" ({cause})"),
        1 => format!(" ({cause}: try {})", tries[0]),
        _ => {
            let (last, rest) = tries.split_last().expect("two or more");
            format!(" ({cause}: try {} or {last})", rest.join(", "))
        }
    }
}

/// How often a run without a terminal reports how far it is.
const PLAIN_PROGRESS_EVERY: Duration = Duration::from_secs(5);

/// Progress of a run that lasts: nothing for its first [`QUIET_START`]; then a bar on a
/// terminal, or without one (a pipe, a log file, CI) a plain line every
/// [`PLAIN_PROGRESS_EVERY`].
struct Progress {
    bar: ProgressBar,
    /// Plain lines: `(run end t1, when the last line was printed)`.
    plain: Option<(f64, Instant)>,
    /// The bar is drawn (after [`QUIET_START`]).
    shown: bool,
    quiet: bool,
    started: Instant,
}

/// How long a run goes before it reports progress.
const QUIET_START: Duration = Duration::from_secs(2);

impl Progress {
    fn new(steps: u64, end: f64, quiet: bool) -> Self {
        let started = Instant::now();
        // The first plain line QUIET_START after the start.
        let plain = (!std::io::stderr().is_terminal())
            .then(|| (end, started.checked_sub(PLAIN_PROGRESS_EVERY - QUIET_START).unwrap_or(started)));
        let bar = ProgressBar::with_draw_target(Some(steps), ProgressDrawTarget::hidden());
        if let Ok(style) =
            ProgressStyle::with_template("{bar:40} {pos}/{len} steps, {elapsed} elapsed, ETA {eta}")
        {
            bar.set_style(style);
        }
        Self { bar, plain, shown: false, quiet, started }
    }

    /// The run reached time `t` (s), step `step`.
    fn at(&mut self, t: f64, step: u64) {
        if self.quiet || self.started.elapsed() < QUIET_START {
            return;
        }
        self.bar.set_position(step);
        if self.plain.is_none() && !self.shown {
            self.shown = true;
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
        }
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
