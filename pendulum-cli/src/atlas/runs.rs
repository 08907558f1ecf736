//! The rounds of an atlas: the pending points in order, cut into rounds of batches of
//! chains (two blocks of four chains per thread), each round one call of
//! [`Atlas::run`] on a rayon pool of `--jobs` threads; after each round a progress line
//! on stderr and atlas.json rewritten. Ctrl-C ends the round at its next sample: its
//! points stay pending, so a resumed atlas runs them from the start.

use std::path::PathBuf;
use std::sync::atomic::Ordering;
use std::time::Instant;

use pendulum_core::batch::WIDTH;
use pendulum_experiment::atlas::{Atlas, AtlasConfig, AtlasFile, AtlasPoint, Derived};
use pendulum_experiment::points::Status;
use pendulum_experiment::write_json_atomic;

use crate::error::{CliError, CliResult};
use crate::interrupt::INTERRUPTED;

/// An atlas set up to run.
pub struct AtlasRun {
    atlas: Atlas,
    derived: Derived,
    out: PathBuf,
    jobs: usize,
    quiet: bool,
    /// Every point, completed ones of a resumed atlas included.
    points: Vec<AtlasPoint>,
    started: Instant,
}

impl AtlasRun {
    /// The atlas of `config` with `points` (a resumed atlas's; `None`: all pending).
    pub fn new(
        config: AtlasConfig,
        points: Option<Vec<AtlasPoint>>,
        out: PathBuf,
        jobs: usize,
        quiet: bool,
    ) -> CliResult<Self> {
        let derived = config.derived()?;
        let atlas = Atlas::new(config)?;
        let points = points.unwrap_or_else(|| atlas.points());
        Ok(Self { atlas, derived, out, jobs, quiet, points, started: Instant::now() })
    }

    /// The configuration.
    pub fn config(&self) -> &AtlasConfig {
        self.atlas.config()
    }

    /// The numbers derived from it.
    pub fn derived(&self) -> &Derived {
        &self.derived
    }

    fn write(&self, points: &[AtlasPoint], status: &str) -> CliResult<()> {
        let mut file = AtlasFile::new(self.config().clone(), self.derived.clone(), points.to_vec());
        file.status = status.into();
        write_json_atomic(&self.out.join("atlas.json"), &file)
    }

    /// Runs the pending points; returns every point.
    pub fn run(&self) -> CliResult<Vec<AtlasPoint>> {
        let mut points = self.points.clone();
        self.write(&points, "running")?;
        let pending: Vec<usize> =
            (0..points.len()).filter(|&i| points[i].status == Status::Pending).collect();
        let c = self.config();
        if !self.quiet {
            let kept = points.len() - pending.len();
            eprintln!(
                "pendulum: atlas of {} × {} ({} × {}) × {} kind{} = {} runs of {} s each (RK4 + projection, \
                 h = {} s, {} steps){} on {} thread{}; {}",
                c.x.values.len(),
                c.y.values.len(),
                c.x.parameter.name(),
                c.y.parameter.name(),
                c.kinds.len(),
                if c.kinds.len() == 1 { "" } else { "s" },
                c.len(),
                c.duration,
                pendulum_experiment::words::short(c.step),
                self.derived.steps_per_point,
                if kept > 0 {
                    format!("; {kept} kept from --from, {} to run", pending.len())
                } else {
                    String::new()
                },
                self.jobs,
                if self.jobs == 1 { "" } else { "s" },
                pendulum_experiment::words::chain_words(
                    &c.masses,
                    &c.lengths,
                    c.gravity,
                    c.damping.as_deref().unwrap_or(&vec![0.0; c.links()])
                ),
            );
        }
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(self.jobs)
            .build()
            .map_err(|e| CliError::failed(format!("cannot start {} threads: {e}", self.jobs)))?;
        let (mut done, total) = (0, pending.len());
        for round in pending.chunks(2 * WIDTH * self.jobs) {
            if INTERRUPTED.load(Ordering::SeqCst) {
                break;
            }
            let ends = pool.install(|| self.atlas.run(round, &|| INTERRUPTED.load(Ordering::Relaxed)));
            for (&i, end) in round.iter().zip(ends) {
                points[i].record(end);
                // A point cut by Ctrl-C runs again from the start on --from.
                if points[i].status == Status::Interrupted {
                    points[i].status = Status::Pending;
                }
            }
            done += round.len();
            self.write(&points, "running")?;
            if !self.quiet && !INTERRUPTED.load(Ordering::SeqCst) {
                let elapsed = self.started.elapsed().as_secs_f64();
                eprintln!(
                    "pendulum: [{done}/{total}] points run ({elapsed:.0} s elapsed, about {:.0} s to go)",
                    elapsed * (total - done) as f64 / done as f64
                );
            }
        }
        Ok(points)
    }

    /// After the files are written: the final atlas.json, the closing line, and the
    /// error for an interrupted (exit 130) or failed (exit 1) atlas.
    pub fn conclude(&self, points: &[AtlasPoint]) -> CliResult<()> {
        let count = |s: Status| points.iter().filter(|p| p.status == s).count();
        let (done, failed, pending) =
            (count(Status::Completed), count(Status::Failed), count(Status::Pending));
        let total = points.len();
        let status = if pending > 0 {
            "interrupted"
        } else if failed > 0 {
            "failed"
        } else {
            "completed"
        };
        self.write(points, status)?;
        let dir = self.out.display();
        if !self.quiet {
            eprintln!(
                "pendulum: {done} of {total} points done in {:.1} s on {} thread{}; files in {dir} \
                 (atlas.csv, atlas.json, atlas.png)",
                self.started.elapsed().as_secs_f64(),
                self.jobs,
                if self.jobs == 1 { "" } else { "s" }
            );
        }
        if pending > 0 {
            return Err(CliError::interrupted(format!(
                "interrupted: {done} of {total} points finished; {dir} holds them (resume with \
                 pendulum atlas --from {}/atlas.json --out {dir})",
                dir
            )));
        }
        if let Some(p) = points.iter().find(|p| p.status == Status::Failed) {
            let c = self.config();
            return Err(CliError::failed(format!(
                "{failed} of {total} points failed (first: {} at {} = {}, {} = {}: {}); files in {dir} hold the others",
                p.kind.name(),
                c.x.parameter.name(),
                p.x,
                c.y.parameter.name(),
                p.y,
                p.error.as_deref().unwrap_or("unknown error")
            )));
        }
        Ok(())
    }
}
