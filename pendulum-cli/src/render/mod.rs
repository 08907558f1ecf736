//! `pendulum render RUN_DIR`: a run's animation drawn again from its run.json and
//! trajectory.csv, without simulating; `pendulum simulate` draws its chain.gif the same
//! way ([`chain_gif`]).
//!
//! The trajectory is read once, row by row, up to the window's last frame. Only the
//! frames are kept (their points and tip trails): the viewport, the box around
//! everything they show, is known at the end.

mod draw;
mod encode;
mod timing;
mod view;

use std::collections::VecDeque;
use std::f64::consts::TAU;
use std::path::{Path, PathBuf};

use clap::{Args, ValueEnum};

use crate::error::{CliError, CliResult};
use draw::{Layout, Scene, Shot};
use pendulum_experiment::View;
use pendulum_experiment::run_dir::{Run, Trajectory};
use pendulum_experiment::{Dimension, DriveConfig, RunConfig};
use timing::{Request, Timing, speed_words};
use view::{AxisMark, Bounds, Circling, Projection};

/// Options of `pendulum render`.
#[derive(Debug, Args)]
pub struct RenderArgs {
    /// The run directory: what `pendulum simulate --out DIR` wrote (run.json and
    /// trajectory.csv are read).
    #[arg(value_name = "RUN_DIR")]
    pub run: PathBuf,
    /// The GIF to write [default: RUN_DIR/chain.gif, replacing the run's animation].
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// What the animation shows; 2D runs are drawn in their plane whatever the view
    /// [default: the run's --view].
    #[arg(long, value_enum)]
    pub view: Option<RenderView>,
    /// Start of the time window, s [default: the first sample].
    #[arg(long, value_name = "T0", allow_negative_numbers = true)]
    pub from: Option<f64>,
    /// End of the time window, s [default: the last sample].
    #[arg(long, value_name = "T1", allow_negative_numbers = true)]
    pub to: Option<f64>,
    /// Playback speed: simulated seconds per second of animation (1 real time, < 1 slow
    /// motion); frames are thinned to --frames [default: real time if frames 20–120 ms
    /// apart allow it, else the nearer bound, with at least 8 frames per period of a
    /// periodic drive: a window too long for that shows its last --frames frames, or its
    /// first from --from].
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub speed: Option<f64>,
    /// Width and height of the GIF, px (240 to 2400).
    #[arg(long, value_name = "PX", default_value_t = 600, allow_negative_numbers = true)]
    pub size: i64,
    /// Most frames (2 to 5000) [default: the run's --frames].
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub frames: Option<i64>,
    /// No summary line.
    #[arg(long)]
    pub quiet: bool,
}

/// What the animation shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum RenderView {
    /// Side view: x to the right, z up (also: xz).
    #[value(alias = "xz")]
    Side,
    /// Side view from +x: y to the right, z up.
    Yz,
    /// Top view: x to the right, y up (also: xy).
    #[value(alias = "xy")]
    Top,
    /// The side view in the frame turning with a pivot that circles the vertical axis:
    /// every sample turned by −φ(t), φ(t) = atan2(pivot_y, pivot_x) (3D runs whose pivot
    /// circles, at any speed profile).
    CoRotating,
}

impl From<View> for RenderView {
    fn from(view: View) -> Self {
        match view {
            View::Xz => Self::Side,
            View::Yz => Self::Yz,
            View::Xy => Self::Top,
            View::CoRotating => Self::CoRotating,
        }
    }
}

/// The smallest and largest `--size`, px.
const SIZES: (i64, i64) = (240, 2400);
/// The most frames of an animation.
const MOST_FRAMES: usize = 5000;
/// The trail spans this many frame intervals ...
const TRAIL_FRAMES: f64 = 20.0;
/// ... in at most about this many points.
const TRAIL_POINTS: f64 = 240.0;

/// Runs `pendulum render`.
pub fn render(args: &RenderArgs) -> CliResult<()> {
    for (name, value) in [("--from", args.from), ("--to", args.to)] {
        if let Some(v) = value
            && !v.is_finite()
        {
            return Err(CliError::invalid(format!("{name} must be a finite time in s, got {v}")));
        }
    }
    if let (Some(from), Some(to)) = (args.from, args.to)
        && from >= to
    {
        return Err(CliError::invalid(format!("--from {from} s must be before --to {to} s")));
    }
    if let Some(s) = args.speed
        && !(s.is_finite() && s > 0.0)
    {
        return Err(CliError::invalid(format!("--speed must be finite and positive, got {s}")));
    }
    if !(SIZES.0..=SIZES.1).contains(&args.size) {
        let (lo, hi) = SIZES;
        return Err(CliError::invalid(format!("--size must be {lo} to {hi} px, got {}", args.size)));
    }
    if let Some(n) = args.frames
        && !(2..=MOST_FRAMES as i64).contains(&n)
    {
        return Err(CliError::invalid(format!("--frames must be 2 to {MOST_FRAMES}, got {n}")));
    }
    let run = Run::open(&args.run)?;
    let config = &run.file.config;
    let out = args.out.clone().unwrap_or_else(|| args.run.join("chain.gif"));
    let job = Job {
        config,
        trajectory: &run.trajectory,
        reached: run.reached(),
        out: &out,
        view: args.view.unwrap_or(config.view.into()),
        from: args.from,
        to: args.to,
        speed: args.speed,
        size: args.size as u32,
        frames: args.frames.map_or(config.frames.min(MOST_FRAMES), |n| n as usize),
    };
    let done = animate(&job)?;
    if !args.quiet {
        done.report(&job);
    }
    Ok(())
}

/// The animation of `pendulum simulate`: `out/chain.gif` drawn from the run's files just
/// written, in the run's view, at most its --frames frames of 600 px, the speed chosen as
/// for `pendulum render` without --speed; `reached` is the time the run reached (s).
/// Prints the summary line (frames, window, speed) unless `quiet`; returns the path.
pub fn chain_gif(out: &Path, config: &RunConfig, reached: f64, quiet: bool) -> CliResult<PathBuf> {
    let gif = out.join("chain.gif");
    let trajectory = out.join("trajectory.csv");
    let job = Job {
        config,
        trajectory: &trajectory,
        reached,
        out: &gif,
        view: config.view.into(),
        from: None,
        to: None,
        speed: None,
        size: 600,
        frames: config.frames.min(MOST_FRAMES),
    };
    let done = animate(&job)?;
    if !quiet {
        done.report(&job);
    }
    Ok(gif)
}

/// One animation to draw.
struct Job<'a> {
    config: &'a RunConfig,
    trajectory: &'a Path,
    /// The time the run reached, s.
    reached: f64,
    out: &'a Path,
    view: RenderView,
    /// The time window, s.
    from: Option<f64>,
    to: Option<f64>,
    speed: Option<f64>,
    /// Side of the GIF, px.
    size: u32,
    frames: usize,
}

/// What was drawn.
struct Done {
    frames: usize,
    /// Time of the first and last frame, s.
    first: f64,
    last: f64,
    timing: Timing,
    projection: Projection,
    period: Option<f64>,
    /// Time between samples, s.
    sample: f64,
}

/// Draws the animation of `job`.
fn animate(job: &Job) -> CliResult<Done> {
    let config = job.config;
    let projection = Projection::new(job.view, config.dim)?;
    let co_rotating = projection == Projection::CoRotating;
    let mut trajectory = Trajectory::open(job.trajectory, config)?;
    let mut row = trajectory.row();
    let (_, step) = pendulum_core::trajectory::plan(0.0, config.end, config.step)?;
    let sample = step * config.every as f64;
    // In the co-rotating view the drive stands still: nothing to alias.
    let period = if co_rotating { None } else { drive_period(&config.drive) };
    let reach: f64 = config.lengths.iter().sum();
    let slack = 1e-9 * config.end.max(1.0);
    let not_circling = |why: String| {
        CliError::invalid(format!(
            "--view co-rotating: the pivot of {} does not circle the vertical axis: {why}",
            job.trajectory.display()
        ))
    };
    // A pivot driven on a circle circles however sparse the samples; any other is
    // checked sample by sample (and refused).
    let check_circling = co_rotating && !config.drive.circles();
    let mut circling = Circling::new(reach);
    // Planned at the first row: the timing, and the window's first time (s), less a tolerance.
    let mut planned: Option<(Timing, f64)> = None;
    let mut shots: Vec<Shot> = Vec::new();
    let mut trail: VecDeque<(f64, (f64, f64))> = VecDeque::new();
    let mut start = None;
    // The grid index of the next frame, and the samples in the window so far.
    let (mut next, mut seen) = (0u64, 0u64);
    while trajectory.next(&mut row)? {
        if job.to.is_some_and(|to| row.t > to + slack) {
            break;
        }
        let (tm, begin) = match planned {
            Some(p) => p,
            None => {
                let t0 = job.from.map_or(row.t, |from| from.max(row.t));
                let end = job.to.unwrap_or(f64::INFINITY).min(job.reached);
                let request = Request {
                    span: (end - t0).max(0.0),
                    sample,
                    frames: job.frames,
                    speed: job.speed,
                    period,
                };
                let tm = timing::plan(&request).map_err(CliError::invalid)?;
                // Too long a window for the frames: its end, unless --from says where to start.
                let begin = match job.from {
                    Some(from) => from - slack,
                    None if !tm.covers => end - (job.frames - 1) as f64 * tm.interval - 0.25 * sample,
                    None => f64::NEG_INFINITY,
                };
                *planned.insert((tm, begin))
            }
        };
        if row.t < begin {
            continue;
        }
        let t0 = *start.get_or_insert(row.t);
        circling.push(row.t, &row.pivot);
        if check_circling && let Some(why) = circling.broken() {
            return Err(not_circling(why.to_string()));
        }
        let turn = pendulum_core::TurningFrame::of_pivot(&row.pivot);
        let tip = projection.point(row.masses.last().expect("a chain has a mass"), turn);
        let span = TRAIL_FRAMES * tm.interval;
        let trail_stride = ((span / sample / TRAIL_POINTS).ceil() as u64).max(1);
        if seen.is_multiple_of(trail_stride) {
            trail.push_back((row.t, tip));
        }
        while trail.front().is_some_and(|&(t, _)| t < row.t - span - slack) {
            trail.pop_front();
        }
        seen += 1;
        if row.t < t0 + next as f64 * tm.interval - 0.25 * sample {
            continue;
        }
        let points =
            std::iter::once(&row.pivot).chain(&row.masses).map(|r| projection.point(r, turn)).collect();
        let mut path: Vec<(f64, f64)> = trail.iter().map(|&(_, p)| p).collect();
        if trail.back().is_none_or(|&(t, _)| t != row.t) {
            path.push(tip);
        }
        shots.push(Shot { t: row.t, points, trail: path });
        next = ((row.t - t0) / tm.interval + 0.5).floor() as u64 + 1;
        if shots.len() == job.frames {
            break;
        }
    }
    let (Some(first), Some(last), Some((timing, _))) = (shots.first(), shots.last(), planned) else {
        return Err(empty_window(job, &trajectory));
    };
    let (first, last) = (first.t, last.t);
    let circles =
        if config.dim == Dimension::Three && config.drive.circles() { Ok(()) } else { circling.verdict() };
    if co_rotating && let Err(why) = circles.clone() {
        return Err(not_circling(why));
    }
    let axis = circles.is_ok().then(|| projection.axis_mark()).flatten();
    let mut bounds = Bounds::default();
    for shot in &shots {
        shot.points.iter().chain(&shot.trail).for_each(|&p| bounds.add(p));
    }
    match axis {
        Some(AxisMark::Line) => bounds.add_x(0.0),
        Some(AxisMark::Centre) => bounds.add((0.0, 0.0)),
        None => {}
    }
    let layout = Layout::new(job.size);
    let scene = Scene {
        layout,
        viewport: bounds.fit(layout.plot(), 0.02 * reach),
        projection,
        axis,
        caption: format!("{}   {}", projection.title(), speed_words(timing.speed)),
        decimals: decimals(timing.interval),
        links: config.links(),
    };
    let mut gif = encode::GifFile::create(job.out, job.size, &draw::colours())?;
    let side = job.size as usize;
    let mut buffer = vec![0u8; 3 * side * side];
    for shot in &shots {
        draw::frame(&mut buffer, &scene, shot)
            .map_err(|e| CliError::failed(format!("cannot draw {}: {e}", job.out.display())))?;
        gif.frame(&buffer, timing.delay)?;
    }
    gif.finish()?;
    Ok(Done { frames: shots.len(), first, last, timing, projection, period, sample })
}

/// The error for a window that holds no sample.
fn empty_window(job: &Job, trajectory: &Trajectory) -> CliError {
    let shown = job.trajectory.display();
    let (Some(first), Some(last)) = (trajectory.first, trajectory.last) else {
        return CliError::invalid(format!("{shown} holds no samples"));
    };
    let message = match (job.from, job.to) {
        (Some(from), _) if from > last => {
            format!("--from {from} s is after the last sample of {shown} (t = {last} s)")
        }
        (_, Some(to)) if to < first => {
            format!("--to {to} s is before the first sample of {shown} (t = {first} s)")
        }
        (from, to) => format!(
            "no sample of {shown} lies between --from {} and --to {} s",
            from.unwrap_or(first),
            to.unwrap_or(last)
        ),
    };
    CliError::invalid(message)
}

impl Done {
    /// Prints the summary line and any warning about aliasing to stderr.
    fn report(&self, job: &Job) {
        let d = decimals(self.timing.interval);
        let t = &self.timing;
        let (out, size, view) = (job.out.display(), job.size, self.projection.name());
        if self.frames == 1 {
            eprintln!("pendulum: {out}: 1 frame of {size}×{size} px, t = {:.d$} s, {view}", self.first);
            return;
        }
        eprintln!(
            "pendulum: {out}: {} frames of {size}×{size} px, t = {:.d$}–{:.d$} s every {} s, {} ({} ms a frame), {view}",
            self.frames,
            self.first,
            self.last,
            round6(t.interval),
            speed_words(t.speed),
            10 * u32::from(t.delay),
        );
        let Some(period) = self.period else { return };
        let per_period = period / t.interval;
        if !t.covers && job.speed.is_none() {
            eprintln!(
                "pendulum: note: {per_period:.1} frames per drive period ({} s) cover only t = {:.d$}–{:.d$} s; \
                 `pendulum render` draws other windows and speeds",
                round6(period),
                self.first,
                self.last,
            );
        }
        if per_period < timing::FRAMES_PER_PERIOD * (1.0 - 1e-9) {
            let fix = if self.sample > period / timing::FRAMES_PER_PERIOD {
                "the samples are too far apart: simulate with a smaller --every or --step"
            } else {
                "use a lower --speed or more --frames"
            };
            eprintln!(
                "pendulum: warning: {per_period:.1} frames per drive period ({} s): the drive may look aliased; {fix}",
                round6(period)
            );
        }
    }
}

/// The period of a periodic drive, s (`2π/|ω|`), if it moves the pivot; for a speed ramp
/// the shortest one (at its fastest speed).
fn drive_period(drive: &DriveConfig) -> Option<f64> {
    let (omega, size) = match drive {
        DriveConfig::Fixed => return None,
        DriveConfig::Harmonic { omega, amplitude, .. } => (*omega, *amplitude),
        DriveConfig::Circle { radius, omega } => (*omega, *radius),
        DriveConfig::RampedCircle { radius, initial_omega, omega, .. } => {
            (initial_omega.abs().max(omega.abs()), *radius)
        }
        DriveConfig::Sampled { .. } => return None,
    };
    (omega.is_finite() && omega != 0.0 && size != 0.0).then(|| TAU / omega.abs())
}

/// Decimals that show times `interval` s apart exactly (at least 1, at most 6).
fn decimals(interval: f64) -> usize {
    (1..=6)
        .find(|&d| {
            let scaled = interval * 10f64.powi(d as i32);
            (scaled - scaled.round()).abs() < 1e-6 * scaled.max(1.0)
        })
        .unwrap_or(6)
}

/// `x` rounded to 6 significant digits, for messages.
fn round6(x: f64) -> f64 {
    format!("{x:.5e}").parse().unwrap_or(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn times_get_the_decimals_their_spacing_needs() {
        assert_eq!([0.1, 0.05, 0.12, 0.003, 0.1305, 2.0, 0.0].map(decimals), [1, 2, 2, 3, 4, 1, 1]);
    }
}
