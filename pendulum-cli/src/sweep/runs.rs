//! The runs of a sweep: one point (a chain from hanging at rest, or from the previous
//! point's end, its pivot circling at a speed switched on or ramped; RK4 + projection; the
//! shape analysis fed every few steps and its report at the end), and their scheduling on
//! a rayon pool — sudden and ramp-up points independent, run as batches of chains in
//! rounds (bit for bit the runs one at a time), the ramp-down points one chain in
//! decreasing ω — with a line per finished point on stderr, sweep.json rewritten after
//! each, and Ctrl-C honoured between samples.

use std::path::PathBuf;
use std::sync::Mutex;
use std::sync::atomic::Ordering;
use std::time::Instant;

use nalgebra::DVector;
use pendulum_core::ShapeOptions;
use pendulum_core::batch::WIDTH;
use pendulum_experiment::DriveConfig;
use pendulum_experiment::balance::chain_scale;
use pendulum_experiment::whirls::{WhirlRuns, WhirlStop as Stop};

use super::SweepKind;
use super::config::{Derived, SweepConfig, SweepFile};
use super::point::{Outcome, Point, Status};
use crate::error::{CliError, CliResult};
use crate::interrupt::INTERRUPTED;

/// A sweep set up to run: its configuration and points, where to write, how many threads.
pub struct Sweep {
    config: SweepConfig,
    derived: Derived,
    /// The chain, the runs' length, step and analysis.
    whirls: WhirlRuns,
    out: PathBuf,
    jobs: usize,
    quiet: bool,
    /// Every point and kind, in the order of the files.
    points: Vec<Point>,
    /// The independent points (sudden, ramp-up), indices into `points`.
    singles: Vec<usize>,
    /// The ramp-down points in the order they run (decreasing ω).
    down: Vec<usize>,
    started: Instant,
}

impl Sweep {
    /// The points of `config`: per kind (in the order given) sudden and ramp-up at the
    /// speeds in the order given, ramp-down in decreasing ω.
    pub fn new(config: SweepConfig, out: PathBuf, jobs: usize, quiet: bool) -> CliResult<Self> {
        let derived = config.derived()?;
        let whirls = WhirlRuns {
            chain: config.damped_chain()?,
            duration: config.duration,
            step: config.step,
            feed_every: config.feed_every,
            shape: ShapeOptions {
                periods: config.settle_periods,
                tolerance: config.settle_tolerance,
                ..ShapeOptions::default()
            },
            energy_scale: chain_scale(&config.masses, &config.lengths, config.gravity),
        };
        let scale = config.reference_speed();
        let point = |kind, omega: f64, ramp_from, start: String| Point {
            kind,
            omega,
            omega_scaled: omega / scale,
            ramp_from,
            start,
            status: Status::Pending,
            error: None,
            result: None,
        };
        let hanging = || "hanging at rest".to_string();
        let (mut points, mut singles, mut down) = (Vec::new(), Vec::new(), Vec::new());
        for &kind in &config.kinds {
            match kind {
                SweepKind::Sudden | SweepKind::RampUp => {
                    for &w in &config.omegas {
                        singles.push(points.len());
                        let from = (kind == SweepKind::RampUp).then_some(0.0);
                        points.push(point(kind, w, from, hanging()));
                    }
                }
                SweepKind::RampDown => {
                    let mut order = config.omegas.clone();
                    order.sort_by(|a, b| b.total_cmp(a));
                    let mut previous: Option<f64> = None;
                    for &w in &order {
                        down.push(points.len());
                        let start = match previous {
                            None => hanging(),
                            Some(p) => format!("the final state of the ramp-down point at ω = {p} rad/s"),
                        };
                        points.push(point(kind, w, Some(previous.unwrap_or(0.0)), start));
                        previous = Some(w);
                    }
                }
            }
        }
        Ok(Self { config, derived, whirls, out, jobs, quiet, points, singles, down, started: Instant::now() })
    }

    /// The configuration.
    pub fn config(&self) -> &SweepConfig {
        &self.config
    }

    fn file(&self, points: &[Point]) -> SweepFile {
        SweepFile::new(self.config.clone(), self.derived.clone(), points.to_vec())
    }

    /// Runs every point on `jobs` threads, sweep.json written before and rewritten after
    /// each point; returns the points, each completed, interrupted, not run or failed.
    pub fn run(&self) -> CliResult<Vec<Point>> {
        let json = self.out.join("sweep.json");
        self.file(&self.points).write_atomic(&json)?;
        let c = &self.config;
        if !self.quiet {
            let (speeds, kinds) = (c.omegas.len(), c.kinds.len());
            eprintln!(
                "pendulum: sweep of {speeds} speed{} × {kinds} kind{} = {} runs of {} s each \
                 (RK4 + projection, h = {} s, {} steps) on {} thread{}{}; {}, pivot on a circle of \
                 radius {} m",
                if speeds == 1 { "" } else { "s" },
                if kinds == 1 { "" } else { "s" },
                self.points.len(),
                c.duration,
                c.step,
                self.derived.steps_per_point,
                self.jobs,
                if self.jobs == 1 { "" } else { "s" },
                if self.down.is_empty() { "" } else { "; the ramp-down points run one after the other" },
                pendulum_experiment::words::chain_words(&c.masses, &c.lengths, c.gravity, &c.damping),
                c.radius,
            );
        }
        let shared = Mutex::new(Shared { points: self.points.clone(), finished: 0, error: None });
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(self.jobs)
            .build()
            .map_err(|e| CliError::failed(format!("cannot start {} threads: {e}", self.jobs)))?;
        pool.scope_fifo(|s| {
            // The sequential chain first: it is the longest task.
            if !self.down.is_empty() {
                s.spawn_fifo(|_| self.run_down(&shared));
            }
            // The independent points as batches of chains, four per SIMD lane group, on the
            // pool's threads, in rounds of two blocks per thread (Ctrl-C keeps finished rounds).
            if !self.singles.is_empty() {
                s.spawn_fifo(|_| {
                    for round in self.singles.chunks(2 * WIDTH * self.jobs) {
                        self.run_singles(round, &shared);
                    }
                });
            }
        });
        let mut shared = shared.into_inner().map_err(|_| CliError::failed("a run panicked"))?;
        for p in &mut shared.points {
            if p.status == Status::Pending {
                p.status = Status::NotRun;
            }
        }
        if let Some(e) = shared.error {
            return Err(e);
        }
        self.file(&shared.points).write_atomic(&json)?;
        Ok(shared.points)
    }

    /// The ramp from `from` to `omega` (rad/s) over the ramp time.
    fn ramp(&self, from: f64, omega: f64) -> DriveConfig {
        let c = &self.config;
        DriveConfig::RampedCircle {
            radius: c.radius,
            initial_omega: from,
            omega,
            duration: c.ramp_time.unwrap_or(c.duration / 3.0),
        }
    }

    /// The ramp-down points, each from the previous one's final state.
    fn run_down(&self, shared: &Mutex<Shared>) {
        let mut previous: Option<(f64, DVector<f64>)> = None;
        for &i in &self.down {
            if INTERRUPTED.load(Ordering::SeqCst) {
                return;
            }
            let omega = self.points[i].omega;
            let (from, start) = match &previous {
                None => (0.0, None),
                Some((w, x)) => (*w, Some(x.clone())),
            };
            match self.run_point(&self.ramp(from, omega), start) {
                Ok((outcome, last)) => {
                    self.record(shared, i, Ok(outcome));
                    previous = Some((omega, last));
                }
                Err(stop) => {
                    let failed = matches!(stop, Stop::Failed(_));
                    self.record(shared, i, Err(stop));
                    if failed {
                        let mut s = shared.lock().unwrap_or_else(|e| e.into_inner());
                        for &j in &self.down {
                            if s.points[j].status == Status::Pending {
                                s.points[j].error = Some("an earlier ramp-down point failed".into());
                            }
                        }
                    }
                    return;
                }
            }
        }
    }

    /// The drive of an independent point: switched on at ω, or ramped from rest.
    fn single_drive(&self, p: &Point) -> DriveConfig {
        match p.ramp_from {
            None => DriveConfig::Circle { radius: self.config.radius, omega: p.omega },
            Some(from) => self.ramp(from, p.omega),
        }
    }

    /// Independent points (sudden, ramp-up; indices into `points`), all from hanging at
    /// rest: one batch of chains ([`WhirlRuns::run_batch`], the same steps as
    /// [`run_point`](Self::run_point) bit for bit).
    fn run_singles(&self, singles: &[usize], shared: &Mutex<Shared>) {
        if INTERRUPTED.load(Ordering::SeqCst) {
            return;
        }
        let clock = Instant::now();
        let drives: Vec<DriveConfig> = singles.iter().map(|&i| self.single_drive(&self.points[i])).collect();
        let ends = self.whirls.run_batch(&drives, &interrupted);
        // Each point's wall time: its share of the batch's.
        let share = clock.elapsed().as_secs_f64() / singles.len() as f64;
        for (&i, end) in singles.iter().zip(ends) {
            self.record(shared, i, end.map(|e| Outcome::of(&e.report, e.steps, Some(share), e.balance)));
        }
    }

    /// Runs one point with `drive` from `start` (default: hanging at rest); returns the
    /// outcome and the final state turned about the axis so that the pivot is at phase 0
    /// (the next ramp-down point's start: its drive starts there).
    fn run_point(
        &self,
        drive: &DriveConfig,
        start: Option<DVector<f64>>,
    ) -> Result<(Outcome, DVector<f64>), Stop> {
        let clock = Instant::now();
        let (end, turned) = self.whirls.run_one(drive, start, &interrupted)?;
        Ok((Outcome::of(&end.report, end.steps, Some(clock.elapsed().as_secs_f64()), end.balance), turned))
    }

    /// Records the end of point `i`: status and result, a line on stderr, sweep.json.
    fn record(&self, shared: &Mutex<Shared>, i: usize, ended: Result<Outcome, Stop>) {
        let mut s = shared.lock().unwrap_or_else(|e| e.into_inner());
        let point = &mut s.points[i];
        match ended {
            Ok(outcome) => {
                if let Some(warning) = outcome.balance.and_then(|b| b.warning()) {
                    eprintln!(
                        "pendulum: warning: {} at ω = {} rad/s: {warning}",
                        point.kind.name(),
                        point.omega
                    );
                }
                point.status = Status::Completed;
                point.result = Some(outcome);
            }
            Err(Stop::Interrupted) => point.status = Status::Interrupted,
            Err(Stop::Failed(e)) => {
                point.status = Status::Failed;
                point.error = Some(e);
            }
        }
        s.finished += 1;
        if !self.quiet {
            let elapsed = self.started.elapsed().as_secs_f64();
            eprintln!(
                "pendulum: [{}/{}] {} ({elapsed:.0} s elapsed)",
                s.finished,
                self.points.len(),
                progress_line(&s.points[i])
            );
        }
        if s.error.is_none()
            && let Err(e) = self.file(&s.points).write_atomic(&self.out.join("sweep.json"))
        {
            s.error = Some(e);
        }
    }

    /// After the files are written: the final sweep.json, the closing line, and the
    /// error for an interrupted (exit 130) or failed (exit 1) sweep.
    pub fn conclude(&self, points: &[Point]) -> CliResult<()> {
        let count = |s: Status| points.iter().filter(|p| p.status == s).count();
        let (done, failed) = (count(Status::Completed), count(Status::Failed));
        let cut = count(Status::Interrupted) + count(Status::NotRun);
        let interrupted = cut > 0 && INTERRUPTED.load(Ordering::SeqCst);
        let mut file = self.file(points);
        file.status = if interrupted {
            "interrupted"
        } else if failed > 0 {
            "failed"
        } else {
            "completed"
        }
        .into();
        file.write_atomic(&self.out.join("sweep.json"))?;
        let total = points.len();
        let dir = self.out.display();
        if !self.quiet {
            eprintln!(
                "pendulum: {done} of {total} points done in {:.1} s on {} thread{}; files in {dir} \
                 (sweep.csv, sweep.json, sweep.png)",
                self.started.elapsed().as_secs_f64(),
                self.jobs,
                if self.jobs == 1 { "" } else { "s" }
            );
        }
        if interrupted {
            return Err(CliError::interrupted(format!(
                "interrupted: {done} of {total} points finished; {dir} holds them (sweep.csv, sweep.json, \
                 sweep.png; the {cut} unfinished are marked interrupted or not-run)"
            )));
        }
        if let Some(p) = points.iter().find(|p| p.status == Status::Failed) {
            return Err(CliError::failed(format!(
                "{failed} of {total} points failed (first: {} at ω = {} rad/s: {}); files in {dir} hold the others",
                p.kind.name(),
                p.omega,
                p.error.as_deref().unwrap_or("unknown error")
            )));
        }
        Ok(())
    }
}

/// Whether Ctrl-C was pressed.
fn interrupted() -> bool {
    INTERRUPTED.load(Ordering::Relaxed)
}

/// What the threads share.
struct Shared {
    points: Vec<Point>,
    finished: usize,
    /// The first failure to write sweep.json.
    error: Option<CliError>,
}

/// `1 node`, `3 nodes`.
pub fn nodes_name(k: usize) -> String {
    format!("{k} node{}", if k == 1 { "" } else { "s" })
}

/// One line about a finished point: kind, speed, nodes, tip radius, settled, nearest.
fn progress_line(p: &Point) -> String {
    let head = format!("{} ω = {:.4} rad/s ({:.3} √(g/L))", p.kind.name(), p.omega, p.omega_scaled);
    match (&p.result, p.status) {
        (Some(r), _) => {
            let settled = if r.settled { "settled" } else { "not settled" };
            let nearest = match &r.nearest {
                Some(n) => format!(
                    "nearest steady shape {:.1e} m away, {}, {}",
                    n.distance,
                    nodes_name(n.nodes),
                    if n.stable { "stable" } else { "unstable" }
                ),
                None => "no steady shape found nearby".into(),
            };
            format!(
                "{head}: {}, tip radius {:.4} m, {settled} (drift {:.1e} m); {nearest}{}",
                nodes_name(r.nodes),
                r.tip_radius,
                r.drift,
                r.wall_seconds.map_or(String::new(), |w| format!("; {w:.1} s"))
            )
        }
        (None, status) => match &p.error {
            Some(e) => format!("{head}: {}: {e}", status.name()),
            None => format!("{head}: {}", status.name()),
        },
    }
}
