//! The runs of a sweep: one point (a chain from hanging at rest, or from the previous
//! point's end, its pivot circling at a speed switched on or ramped; RK4 + projection; the
//! shape analysis fed every few steps and its report at the end), and their scheduling on
//! a rayon pool — sudden and ramp-up points independent, run as batches of chains in
//! rounds (bit for bit the runs one at a time), the ramp-down points one chain in
//! decreasing ω — with the front end told of every finished point and `stop()` asked
//! between samples.

use std::sync::Mutex;
use std::time::Instant;

use nalgebra::DVector;
use pendulum_core::batch::WIDTH;

use super::SweepKind;
use super::config::{Derived, SweepConfig, SweepFile};
use super::point::{Outcome, Point, Status};
use crate::description::DriveConfig;
use crate::error::{Error, Result};
use crate::whirls::{WhirlRuns, WhirlStop};

/// What a front end is told after each point: every point so far, the index of the one
/// that just finished, and how many have; an error (a file that could not be written)
/// ends the sweep after the points running.
pub type OnPoint<'a> = &'a (dyn Fn(&[Point], usize, usize) -> Result<()> + Sync);

/// A sweep set up to run: its configuration and points.
pub struct Sweep {
    config: SweepConfig,
    derived: Derived,
    /// The chain, the runs' length, step and analysis.
    whirls: WhirlRuns,
    /// Every point and kind, in the order of the files.
    points: Vec<Point>,
    /// The independent points (sudden, ramp-up), indices into `points`.
    singles: Vec<usize>,
    /// The ramp-down points in the order they run (decreasing ω).
    down: Vec<usize>,
}

impl Sweep {
    /// The points of `config`: per kind (in the order given) sudden and ramp-up at the
    /// speeds in the order given, ramp-down in decreasing ω.
    pub fn new(config: SweepConfig) -> Result<Self> {
        config.check()?;
        let derived = config.derived()?;
        let whirls = WhirlRuns::new(
            config.damped_chain()?,
            config.duration,
            config.step,
            config.feed_every,
            (config.settle_periods, config.settle_tolerance),
        );
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
        Ok(Self { config, derived, whirls, points, singles, down })
    }

    /// The configuration.
    pub fn config(&self) -> &SweepConfig {
        &self.config
    }

    /// The numbers derived from it.
    pub fn derived(&self) -> &Derived {
        &self.derived
    }

    /// The points before any has run.
    pub fn points(&self) -> &[Point] {
        &self.points
    }

    /// Whether some points run one after the other (ramp-down).
    pub fn has_ramp_down(&self) -> bool {
        !self.down.is_empty()
    }

    /// sweep.json with `points`.
    pub fn file(&self, points: &[Point]) -> SweepFile {
        SweepFile::new(self.config.clone(), self.derived.clone(), points.to_vec())
    }

    /// Runs every point on `jobs` threads; `stop()` is asked between samples and
    /// `on_point` told of every finished point. Returns the points, each completed,
    /// interrupted, not run (still [`Status::Pending`] becomes [`Status::NotRun`]) or
    /// failed; the first error of `on_point`, if any.
    pub fn run(
        &self,
        jobs: usize,
        stop: &(dyn Fn() -> bool + Sync),
        on_point: OnPoint<'_>,
    ) -> Result<Vec<Point>> {
        let shared = Mutex::new(Shared { points: self.points.clone(), finished: 0, error: None });
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(jobs)
            .build()
            .map_err(|e| Error::failed(format!("cannot start {jobs} threads: {e}")))?;
        let runs = Runs { sweep: self, shared: &shared, stop, on_point };
        pool.scope_fifo(|s| {
            // The sequential chain first: it is the longest task.
            if !self.down.is_empty() {
                s.spawn_fifo(|_| runs.down());
            }
            // The independent points as batches of chains, four per SIMD register (eight with AVX-512), on the
            // pool's threads, in rounds of two blocks per thread (a stop keeps finished rounds).
            if !self.singles.is_empty() {
                s.spawn_fifo(|_| {
                    for round in self.singles.chunks(2 * WIDTH * jobs) {
                        runs.singles(round);
                    }
                });
            }
        });
        let mut shared = shared.into_inner().map_err(|_| Error::failed("a run panicked"))?;
        for p in &mut shared.points {
            if p.status == Status::Pending {
                p.status = Status::NotRun;
            }
        }
        match shared.error {
            Some(e) => Err(e),
            None => Ok(shared.points),
        }
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

    /// The drive of an independent point: switched on at ω, or ramped from rest.
    fn single_drive(&self, p: &Point) -> DriveConfig {
        match p.ramp_from {
            None => DriveConfig::Circle { radius: self.config.radius, omega: p.omega },
            Some(from) => self.ramp(from, p.omega),
        }
    }
}

/// A sweep running: where its points are recorded, when to stop, whom to tell.
struct Runs<'a> {
    sweep: &'a Sweep,
    shared: &'a Mutex<Shared>,
    stop: &'a (dyn Fn() -> bool + Sync),
    on_point: OnPoint<'a>,
}

impl Runs<'_> {
    /// The ramp-down points, each from the previous one's final state.
    fn down(&self) {
        let sweep = self.sweep;
        let mut previous: Option<(f64, DVector<f64>)> = None;
        for &i in &sweep.down {
            if (self.stop)() {
                return;
            }
            let omega = sweep.points[i].omega;
            let (from, start) = match &previous {
                None => (0.0, None),
                Some((w, x)) => (*w, Some(x.clone())),
            };
            let clock = Instant::now();
            match sweep.whirls.run_one(&sweep.ramp(from, omega), start, self.stop) {
                Ok((end, last)) => {
                    let wall = Some(clock.elapsed().as_secs_f64());
                    self.record(i, Ok(Outcome::of(&end.report, end.steps, wall, end.balance)));
                    previous = Some((omega, last));
                }
                Err(stop) => {
                    let failed = matches!(stop, WhirlStop::Failed(_));
                    self.record(i, Err(stop));
                    if failed {
                        let mut s = self.shared.lock().unwrap_or_else(|e| e.into_inner());
                        for &j in &sweep.down {
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

    /// Independent points (sudden, ramp-up; indices into `points`), all from hanging at
    /// rest: one batch of chains ([`WhirlRuns::run_batch`], the same steps as
    /// [`WhirlRuns::run_one`] bit for bit).
    fn singles(&self, singles: &[usize]) {
        if (self.stop)() {
            return;
        }
        let sweep = self.sweep;
        let clock = Instant::now();
        let drives: Vec<DriveConfig> =
            singles.iter().map(|&i| sweep.single_drive(&sweep.points[i])).collect();
        let ends = sweep.whirls.run_batch(&drives, self.stop);
        // Each point's wall time: its share of the batch's.
        let share = Some(clock.elapsed().as_secs_f64() / singles.len() as f64);
        for (&i, end) in singles.iter().zip(ends) {
            self.record(i, end.map(|e| Outcome::of(&e.report, e.steps, share, e.balance)));
        }
    }

    /// Records the end of point `i` (status and result) and tells the front end.
    fn record(&self, i: usize, ended: std::result::Result<Outcome, WhirlStop>) {
        let mut s = self.shared.lock().unwrap_or_else(|e| e.into_inner());
        let point = &mut s.points[i];
        match ended {
            Ok(outcome) => {
                point.status = Status::Completed;
                point.result = Some(outcome);
            }
            Err(WhirlStop::Interrupted) => point.status = Status::Interrupted,
            Err(WhirlStop::Failed(e)) => {
                point.status = Status::Failed;
                point.error = Some(e);
            }
        }
        s.finished += 1;
        if s.error.is_none()
            && let Err(e) = (self.on_point)(&s.points, i, s.finished)
        {
            s.error = Some(e);
        }
    }
}

/// What the threads share.
struct Shared {
    points: Vec<Point>,
    finished: usize,
    /// The first error of the front end's `on_point`.
    error: Option<Error>,
}
