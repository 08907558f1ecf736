//! The atlas: which shape a whirled 3D chain ends in from hanging at rest, over a grid of
//! two of the drive's speed ω, its circle's radius R, the damping λ and the ramp time.
//!
//! Every point is a whirl ([`WhirlRuns`]): the chain from hanging at rest, its pivot on a
//! horizontal circle switched on at ω (`sudden`) or ramped up from rest (`ramp-up`), RK4 +
//! projection and the shape analysis, the same computation as `pendulum simulate` with
//! those parameters. [`Atlas::run`] runs any set of points as batches of chains
//! ([`WhirlRuns::run_batch_of`]), so a front end may cut the grid into chunks (rounds on
//! one machine, tasks on a cluster) without changing a bit of any point.
//!
//! [`AtlasConfig`] holds every parameter (atlas.json's `config`); [`AtlasFile`] is
//! atlas.json itself, with every point's status and result so far.

use std::path::Path;

use nalgebra::Dyn;
use pendulum_core::{Chain, SteadyRotation};
use serde::{Deserialize, Serialize};

use crate::description::DriveConfig;
use crate::error::{Error, Result};
use crate::json::read_command_file;
use crate::points::{Outcome, Status};
use crate::steady::{follow, round_up};
use crate::whirls::{
    FEED_EVERY, SETTLE_PERIODS, SETTLE_TOLERANCE, WhirlResult, WhirlRuns, WhirlStop, default_duration,
    default_step, first_mode_decay,
};

/// Most steps of one point.
const MAX_STEPS: f64 = 1e8;

/// Most points of an atlas (kinds × grid).
pub const MAX_POINTS: usize = 1 << 20;

/// A parameter an axis of the atlas runs over.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Parameter {
    /// The drive's speed ω, rad/s.
    Omega,
    /// The radius R of the pivot's circle, m.
    Radius,
    /// The damping λ of every link, N·m·s.
    Damping,
    /// The length of the ramp from rest to ω, s (ramp-up only).
    RampTime,
}

impl Parameter {
    /// The four, in the order that makes the axes: the first that varies is x.
    pub const ALL: [Self; 4] = [Self::Omega, Self::Radius, Self::Damping, Self::RampTime];

    /// The name in the files and in Python.
    pub fn name(self) -> &'static str {
        match self {
            Self::Omega => "omega",
            Self::Radius => "radius",
            Self::Damping => "damping",
            Self::RampTime => "ramp-time",
        }
    }

    /// Its symbol: ω, R, λ, T.
    pub fn symbol(self) -> &'static str {
        match self {
            Self::Omega => "ω",
            Self::Radius => "R",
            Self::Damping => "λ",
            Self::RampTime => "the ramp time",
        }
    }

    /// The option that sets it on the command line.
    pub fn option(self) -> &'static str {
        match self {
            Self::Omega => "--omega",
            Self::Radius => "--radius",
            Self::Damping => "--damping",
            Self::RampTime => "--ramp-time",
        }
    }

    /// Its symbol and unit, for axes' labels.
    pub fn label(self) -> &'static str {
        match self {
            Self::Omega => "ω (rad/s)",
            Self::Radius => "R (m)",
            Self::Damping => "λ per link (N·m·s)",
            Self::RampTime => "ramp time (s)",
        }
    }
}

/// How a point of the atlas is started, from hanging at rest.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum AtlasKind {
    /// The pivot circling at ω from t = 0.
    Sudden,
    /// The speed ramped linearly from 0 to ω over the ramp time, then held.
    RampUp,
}

impl AtlasKind {
    /// The name on the command line and in the files.
    pub fn name(self) -> &'static str {
        match self {
            Self::Sudden => "sudden",
            Self::RampUp => "ramp-up",
        }
    }
}

/// An axis: a parameter and its values, increasing or as given (SI units; ω in rad/s).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Axis {
    pub parameter: Parameter,
    pub values: Vec<f64>,
}

/// The values of the four parameters as a front end gives them: one value holds a
/// parameter fixed, two or more make it an axis (exactly two must). `damping` is either
/// per link (held fixed) or, as an axis, one λ for every link.
#[derive(Debug, Clone, PartialEq)]
pub struct AtlasRequest {
    pub masses: Vec<f64>,
    pub lengths: Vec<f64>,
    pub gravity: f64,
    /// ω, rad/s (or in units of √(g/L) when `scaled`).
    pub omega: Vec<f64>,
    /// Whether `omega` is in units of `√(g/L)`, L the chain's length.
    pub scaled: bool,
    /// R, m.
    pub radius: Vec<f64>,
    pub damping: Damping,
    /// The ramp's length, s (empty: a third of the duration where a ramp needs it).
    pub ramp_time: Vec<f64>,
    pub kinds: Vec<AtlasKind>,
    /// Simulated time of every point, s (`None`: as `pendulum sweep` chooses it).
    pub duration: Option<f64>,
    /// RK4 step, s (`None`: as `pendulum sweep` chooses it, for the fastest, widest and most
    /// damped point).
    pub step: Option<f64>,
}

/// The damping of an atlas request.
#[derive(Debug, Clone, PartialEq)]
pub enum Damping {
    /// λ_i per link, N·m·s, the same at every point.
    PerLink(Vec<f64>),
    /// One λ for every link, N·m·s: an axis if more than one.
    Uniform(Vec<f64>),
}

/// Every parameter of an atlas; with the program version, enough to repeat it exactly.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AtlasConfig {
    /// Masses `m_i`, kg, one per link.
    pub masses: Vec<f64>,
    /// Rod lengths `l_i`, m.
    pub lengths: Vec<f64>,
    /// Gravity `g`, m/s² (along −z).
    pub gravity: f64,
    /// The horizontal axis (its values vary along a row).
    pub x: Axis,
    /// The vertical axis.
    pub y: Axis,
    /// ω where it is not an axis, rad/s.
    pub omega: Option<f64>,
    /// Whether ω was given in units of `√(g/L)`.
    pub scaled: bool,
    /// R where it is not an axis, m.
    pub radius: Option<f64>,
    /// λ_i per link where damping is not an axis, N·m·s.
    pub damping: Option<Vec<f64>>,
    /// The ramp's length where it is not an axis and a kind ramps, s.
    pub ramp_time: Option<f64>,
    /// The kinds of start, in the order given, each once.
    pub kinds: Vec<AtlasKind>,
    /// Simulated time of every point, s, ramp included.
    pub duration: f64,
    /// RK4 step, s.
    pub step: f64,
    /// The shape analysis is fed every this many steps.
    pub feed_every: usize,
    /// Settle window, drive periods.
    pub settle_periods: f64,
    /// Settled when the drift is at most this times the chain's length.
    pub settle_tolerance: f64,
}

/// The parameters of one point of the grid.
#[derive(Debug, Clone, PartialEq)]
pub struct Setting {
    /// ω, rad/s.
    pub omega: f64,
    /// R, m.
    pub radius: f64,
    /// λ_i, N·m·s.
    pub damping: Vec<f64>,
    /// The ramp's length, s (`None` without a ramp kind).
    pub ramp_time: Option<f64>,
}

impl AtlasRequest {
    /// Resolves the request into a complete configuration; errors name the bad value.
    pub fn resolve(&self) -> Result<AtlasConfig> {
        let n = self.masses.len();
        let chain = Chain::<Dyn>::new(&self.masses, &self.lengths, self.gravity)?;
        if !(self.gravity.is_finite() && self.gravity > 0.0) {
            return Err(Error::invalid(format!(
                "--gravity must be finite and positive for an atlas (the chain starts hanging at rest), got {}",
                self.gravity
            )));
        }
        let length: f64 = self.lengths.iter().sum();
        let unit = if self.scaled { (self.gravity / length).sqrt() } else { 1.0 };
        let omega: Vec<f64> = self.omega.iter().map(|w| w * unit).collect();
        let (damping_fixed, damping_axis) = match &self.damping {
            Damping::PerLink(d) => (Some(d.clone()), vec![]),
            Damping::Uniform(v) if v.len() == 1 => (Some(vec![v[0]; n]), vec![]),
            Damping::Uniform(v) => (None, v.clone()),
        };
        let listed = [
            (Parameter::Omega, &omega),
            (Parameter::Radius, &self.radius),
            (Parameter::Damping, &damping_axis),
            (Parameter::RampTime, &self.ramp_time),
        ];
        for (p, values) in listed {
            if let Some(v) = values.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
                return Err(Error::invalid(format!("{}: {v} is not a finite value ≥ 0", p.option())));
            }
        }
        let axes: Vec<Axis> = listed
            .iter()
            .filter(|(_, values)| values.len() > 1)
            .map(|(parameter, values)| Axis { parameter: *parameter, values: values.to_vec() })
            .collect();
        if axes.len() != 2 {
            let named: Vec<&str> = axes.iter().map(|a| a.parameter.option()).collect();
            return Err(Error::invalid(format!(
                "an atlas needs exactly two axes (two of --omega, --radius, --damping, --ramp-time with \
                 more than one value, e.g. --omega 1:5:32), got {}{}",
                axes.len(),
                if named.is_empty() { String::new() } else { format!(" ({})", named.join(", ")) }
            )));
        }
        let fixed = |values: &[f64]| (values.len() == 1).then(|| values[0]);
        let mut kinds = Vec::new();
        for &k in &self.kinds {
            if !kinds.contains(&k) {
                kinds.push(k);
            }
        }
        let ramps = kinds.contains(&AtlasKind::RampUp);
        let ramp_axis = axes.iter().any(|a| a.parameter == Parameter::RampTime);
        if ramp_axis && kinds.contains(&AtlasKind::Sudden) {
            return Err(Error::invalid(
                "--ramp-time as an axis applies to the kind ramp-up only (--kind sudden has no ramp)",
            ));
        }
        if !ramps && !self.ramp_time.is_empty() {
            return Err(Error::invalid(
                "--ramp-time applies to the kind ramp-up only (--kind sudden has no ramp)",
            ));
        }
        if let Some(d) = self.duration {
            check_positive("--duration", d, "s")?;
        }
        // The least damped chain decays slowest; the most damped has the fastest decay.
        let extreme = |pick: fn(f64, f64) -> f64| -> Result<Chain<Dyn>> {
            let per_link = match &damping_fixed {
                Some(d) => d.clone(),
                None => vec![damping_axis.iter().copied().reduce(pick).unwrap_or(0.0); n],
            };
            chain.clone().with_damping(&per_link).map_err(|e| Error::from(e).context("--damping"))
        };
        let duration = match self.duration {
            Some(d) => d,
            None => default_duration(&extreme(f64::min)?),
        };
        let ramp_time = match (fixed(&self.ramp_time), ramps && !ramp_axis) {
            (Some(t), true) => Some(t),
            (None, true) => Some(round_up(duration / 3.0)),
            _ => None,
        };
        let largest = |values: &[f64]| values.iter().copied().fold(0.0, f64::max);
        let step = match self.step {
            Some(h) => h,
            None => default_step(&extreme(f64::max)?, largest(&self.radius), largest(&omega)),
        };
        let config = AtlasConfig {
            masses: self.masses.clone(),
            lengths: self.lengths.clone(),
            gravity: self.gravity,
            x: axes[0].clone(),
            y: axes[1].clone(),
            omega: fixed(&omega),
            scaled: self.scaled,
            radius: fixed(&self.radius),
            damping: damping_fixed,
            ramp_time,
            kinds,
            duration,
            step,
            feed_every: FEED_EVERY,
            settle_periods: SETTLE_PERIODS,
            settle_tolerance: SETTLE_TOLERANCE,
        };
        config.check()?;
        Ok(config)
    }
}

fn check_positive(option: &str, value: f64, unit: &str) -> Result<()> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(Error::invalid(format!("{option} must be finite and positive, got {value} ({unit})")))
    }
}

impl AtlasConfig {
    /// Number of links.
    pub fn links(&self) -> usize {
        self.masses.len()
    }

    /// The chain's length `L = Σ l_i`, m.
    pub fn length(&self) -> f64 {
        self.lengths.iter().sum()
    }

    /// `√(g/L)`, rad/s: the unit of scaled speeds.
    pub fn reference_speed(&self) -> f64 {
        (self.gravity / self.length()).sqrt()
    }

    /// Points per kind: the grid's size.
    pub fn grid_len(&self) -> usize {
        self.x.values.len() * self.y.values.len()
    }

    /// Every point of the atlas: kinds × grid.
    pub fn len(&self) -> usize {
        self.kinds.len() * self.grid_len()
    }

    /// Whether the atlas has no point (never, once checked).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The kind and the grid's column and row of point `index` (points run kind by kind,
    /// then row by row of y, then along x).
    pub fn locate(&self, index: usize) -> (AtlasKind, usize, usize) {
        let nx = self.x.values.len();
        let grid = index % self.grid_len();
        (self.kinds[index / self.grid_len()], grid % nx, grid / nx)
    }

    /// The parameters at column `ix`, row `iy`.
    pub fn setting(&self, ix: usize, iy: usize) -> Setting {
        let mut s = Setting {
            omega: self.omega.unwrap_or(0.0),
            radius: self.radius.unwrap_or(0.0),
            damping: self.damping.clone().unwrap_or_default(),
            ramp_time: self.ramp_time,
        };
        for (axis, i) in [(&self.x, ix), (&self.y, iy)] {
            let v = axis.values[i];
            match axis.parameter {
                Parameter::Omega => s.omega = v,
                Parameter::Radius => s.radius = v,
                Parameter::Damping => s.damping = vec![v; self.links()],
                Parameter::RampTime => s.ramp_time = Some(v),
            }
        }
        s
    }

    /// The drive of point `index`: a circle switched on at ω, or ramped from rest.
    pub fn drive(&self, index: usize) -> DriveConfig {
        let (kind, ix, iy) = self.locate(index);
        let s = self.setting(ix, iy);
        match kind {
            AtlasKind::Sudden => DriveConfig::Circle { radius: s.radius, omega: s.omega },
            AtlasKind::RampUp => DriveConfig::RampedCircle {
                radius: s.radius,
                initial_omega: 0.0,
                omega: s.omega,
                duration: s.ramp_time.unwrap_or(self.duration / 3.0),
            },
        }
    }

    /// The undamped chain (the steady shapes, the critical speeds).
    pub fn chain(&self) -> Result<Chain<Dyn>> {
        Ok(Chain::<Dyn>::new(&self.masses, &self.lengths, self.gravity)?)
    }

    /// Checks what building the chain and the drives does not: axes, counts, signs, times.
    pub fn check(&self) -> Result<()> {
        let n = self.links();
        if n == 0 {
            return Err(Error::invalid("masses: a chain needs at least 1 link, got 0"));
        }
        if self.lengths.len() != n {
            return Err(Error::invalid(format!("lengths: got {} values, expected {n}", self.lengths.len())));
        }
        if !(self.gravity.is_finite() && self.gravity > 0.0) {
            return Err(Error::invalid(format!(
                "gravity must be finite and positive for an atlas, got {}",
                self.gravity
            )));
        }
        let chain = self.chain()?;
        if self.x.parameter == self.y.parameter {
            return Err(Error::invalid(format!("both axes run over {}", self.x.parameter.name())));
        }
        for axis in [&self.x, &self.y] {
            let p = axis.parameter;
            if axis.values.len() < 2 {
                return Err(Error::invalid(format!("the {} axis has fewer than 2 values", p.name())));
            }
            if let Some(v) = axis.values.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
                return Err(Error::invalid(format!("{}: {v} is not a finite value ≥ 0", p.option())));
            }
        }
        let is_axis = |p: Parameter| self.x.parameter == p || self.y.parameter == p;
        let fixed_given = [
            (Parameter::Omega, self.omega.is_some()),
            (Parameter::Radius, self.radius.is_some()),
            (Parameter::Damping, self.damping.is_some()),
        ];
        for (p, given) in fixed_given {
            if given == is_axis(p) {
                return Err(Error::invalid(if given {
                    format!("{} is an axis and also given one value", p.option())
                } else {
                    format!("{}: no value given (it is not an axis)", p.option())
                }));
            }
        }
        if let Some(w) = self.omega.filter(|w| !(w.is_finite() && *w >= 0.0)) {
            return Err(Error::invalid(format!("--omega: {w} rad/s is not a finite speed ≥ 0")));
        }
        if let Some(d) = &self.damping {
            if d.len() != n {
                return Err(Error::invalid(format!("damping: got {} values, expected {n}", d.len())));
            }
            chain.clone().with_damping(d).map_err(|e| Error::from(e).context("--damping"))?;
        }
        let radii = match self.radius {
            Some(r) => vec![r],
            None => self.axis(Parameter::Radius).map_or(vec![], |a| a.values.clone()),
        };
        if let Some(r) = radii.iter().find(|r| !(r.is_finite() && **r > 0.0)) {
            return Err(Error::invalid(format!(
                "--radius must be finite and positive (the pivot's circle drives the chain), got {r}"
            )));
        }
        if self.kinds.is_empty() {
            return Err(Error::invalid("--kind: no kind of start given"));
        }
        let ramps = self.kinds.contains(&AtlasKind::RampUp);
        let ramp_axis = is_axis(Parameter::RampTime);
        if ramp_axis && self.kinds.contains(&AtlasKind::Sudden) {
            return Err(Error::invalid("--ramp-time as an axis applies to the kind ramp-up only"));
        }
        check_positive("--duration", self.duration, "s")?;
        let ramp_times = match (self.ramp_time, ramp_axis) {
            (Some(_), true) => return Err(Error::invalid("--ramp-time is an axis and also given one value")),
            (Some(t), false) if ramps => vec![t],
            (Some(_), false) => return Err(Error::invalid("--ramp-time applies to the kind ramp-up only")),
            (None, true) => self.axis(Parameter::RampTime).map_or(vec![], |a| a.values.clone()),
            (None, false) if ramps => return Err(Error::invalid("--ramp-time: no value given for ramp-up")),
            (None, false) => vec![],
        };
        if let Some(t) = ramp_times.iter().find(|t| !(t.is_finite() && **t > 0.0 && **t < self.duration)) {
            return Err(Error::invalid(format!(
                "--ramp-time must be positive and shorter than --duration {} s, got {t} s",
                self.duration
            )));
        }
        if !(self.step.is_finite() && self.step > 0.0) {
            return Err(Error::invalid(format!("--step must be finite and positive, got {} (s)", self.step)));
        }
        if self.duration / self.step > MAX_STEPS {
            return Err(Error::invalid(format!(
                "--step {} s: {} s would take more than {MAX_STEPS:e} steps per point",
                self.step, self.duration
            )));
        }
        if self.feed_every == 0 {
            return Err(Error::invalid("feed_every must be at least 1"));
        }
        for (what, v) in
            [("settle_periods", self.settle_periods), ("settle_tolerance", self.settle_tolerance)]
        {
            check_positive(what, v, "")?;
        }
        if self.len() > MAX_POINTS {
            return Err(Error::invalid(format!(
                "the atlas has {} points ({} kinds × {} × {}), more than {MAX_POINTS}",
                self.len(),
                self.kinds.len(),
                self.x.values.len(),
                self.y.values.len()
            )));
        }
        Ok(())
    }

    /// The axis over `p`, if there is one.
    pub fn axis(&self, p: Parameter) -> Option<&Axis> {
        [&self.x, &self.y].into_iter().find(|a| a.parameter == p)
    }

    /// The numbers a reader of atlas.json wants beside the parameters.
    pub fn derived(&self) -> Result<Derived> {
        let free = SteadyRotation::new(&self.chain()?, 0.0)?;
        let critical = free.bifurcation_speeds(self.links().min(4))?;
        let (steps, _) = pendulum_core::trajectory::plan(0.0, self.duration, self.step)?;
        Ok(Derived {
            length: self.length(),
            reference_speed: self.reference_speed(),
            critical_speeds: critical,
            first_mode_decay_rate: self
                .damping
                .as_ref()
                .map(|d| self.chain().and_then(|c| Ok(c.with_damping(d)?)).map(|c| first_mode_decay(&c)))
                .transpose()?,
            steps_per_point: steps,
            points: self.len(),
        })
    }
}

/// A fold of a steady branch of the chain on a circle of radius R: the lowest speed its
/// shapes exist at (a branch that turns back there, the forced shapes of a circling
/// pivot born in pairs), with the node count there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fold {
    /// The branch's number in `pendulum steady --radius R`'s table.
    pub branch: usize,
    /// The lowest speed on the branch, rad/s.
    pub omega: f64,
    /// Node count of the shape there.
    pub nodes: Option<usize>,
}

/// The folds of the steady branches of `chain` (undamped) on a circle of `radius` (m),
/// followed up to `omega_max` (rad/s) as `pendulum steady` follows them: every branch
/// whose lowest speed lies strictly inside it.
pub fn folds(chain: &Chain<Dyn>, radius: f64, omega_max: f64) -> Result<Vec<Fold>> {
    let problem = SteadyRotation::new(chain, radius)?;
    let free = SteadyRotation::new(chain, 0.0)?;
    let family = follow(&problem, &free, omega_max, None, &|_| true)?;
    Ok(family
        .branches
        .iter()
        .enumerate()
        .filter_map(|(b, labelled)| {
            let points = &labelled.branch.points;
            let lowest = (0..points.len()).min_by(|&i, &j| points[i].omega.total_cmp(&points[j].omega))?;
            (lowest > 0 && lowest + 1 < points.len()).then(|| Fold {
                branch: b + 1,
                omega: points[lowest].omega,
                nodes: labelled.nodes[labelled.shown(lowest)],
            })
        })
        .collect())
}

/// Numbers a reader of atlas.json wants beside the parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Derived {
    /// The chain's length `L`, m.
    pub length: f64,
    /// `√(g/L)`, rad/s.
    pub reference_speed: f64,
    /// The lowest critical speeds of the chain on a fixed pivot, rad/s.
    pub critical_speeds: Vec<f64>,
    /// Decay rate of the first mode at rest where the damping is fixed, 1/s.
    pub first_mode_decay_rate: Option<f64>,
    /// Steps of every run.
    pub steps_per_point: u64,
    /// Points of the atlas, kinds × grid.
    pub points: usize,
}

/// An atlas ready to run: its configuration and the chains of its rows or columns.
#[derive(Debug, Clone)]
pub struct Atlas {
    config: AtlasConfig,
    whirls: WhirlRuns,
    /// The damped chain of every damping value (one if the damping is not an axis).
    chains: Vec<Chain<Dyn>>,
}

impl Atlas {
    /// Checks `config` and builds its chains.
    pub fn new(config: AtlasConfig) -> Result<Self> {
        config.check()?;
        let chain = config.chain()?;
        let damped =
            |d: &[f64]| chain.clone().with_damping(d).map_err(|e| Error::from(e).context("--damping"));
        let chains = match (&config.damping, config.axis(Parameter::Damping)) {
            (Some(d), _) => vec![damped(d)?],
            (None, Some(axis)) => {
                axis.values.iter().map(|&v| damped(&vec![v; config.links()])).collect::<Result<_>>()?
            }
            (None, None) => return Err(Error::invalid("--damping: no value given")),
        };
        let whirls = WhirlRuns::new(
            chains[0].clone(),
            config.duration,
            config.step,
            config.feed_every,
            (config.settle_periods, config.settle_tolerance),
        );
        Ok(Self { config, whirls, chains })
    }

    /// The configuration.
    pub fn config(&self) -> &AtlasConfig {
        &self.config
    }

    /// The damped chain of point `index`.
    pub fn chain(&self, index: usize) -> &Chain<Dyn> {
        let (_, ix, iy) = self.config.locate(index);
        match (self.config.x.parameter, self.config.y.parameter) {
            (Parameter::Damping, _) => &self.chains[ix],
            (_, Parameter::Damping) => &self.chains[iy],
            _ => &self.chains[0],
        }
    }

    /// Runs the points `indices` (each < [`AtlasConfig::len`]) as one batch of chains on
    /// the current rayon pool, bit for bit each point alone; `stop()` is asked at every
    /// sample. Results in the order of `indices`.
    pub fn run(&self, indices: &[usize], stop: &(dyn Fn() -> bool + Sync)) -> Vec<WhirlResult> {
        if let Some(&bad) = indices.iter().find(|&&i| i >= self.config.len()) {
            let why =
                WhirlStop::Failed(format!("point {bad} is not in the atlas of {} points", self.config.len()));
            return indices.iter().map(|_| Err(why.clone())).collect();
        }
        let drives: Vec<DriveConfig> = indices.iter().map(|&i| self.config.drive(i)).collect();
        let whirls: Vec<(&Chain<Dyn>, &DriveConfig)> =
            indices.iter().zip(&drives).map(|(&i, d)| (self.chain(i), d)).collect();
        self.whirls.run_batch_of(&whirls, stop)
    }

    /// The points of the atlas, all pending.
    pub fn points(&self) -> Vec<AtlasPoint> {
        (0..self.config.len())
            .map(|i| {
                let (kind, ix, iy) = self.config.locate(i);
                AtlasPoint {
                    kind,
                    x: self.config.x.values[ix],
                    y: self.config.y.values[iy],
                    status: Status::Pending,
                    error: None,
                    result: None,
                }
            })
            .collect()
    }
}

/// One point of the atlas: its kind and place, where it stands, and its result once run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AtlasPoint {
    /// How it is started.
    pub kind: AtlasKind,
    /// Its value of the x axis' parameter.
    pub x: f64,
    /// Its value of the y axis' parameter.
    pub y: f64,
    /// Where it stands.
    pub status: Status,
    /// Why it failed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// What the shape analysis said at the end (no wall time: the file does not depend on
    /// the machine or on how the atlas was cut).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub result: Option<Outcome>,
}

impl AtlasPoint {
    /// Records how the point's run ended.
    pub fn record(&mut self, ended: WhirlResult) {
        match ended {
            Ok(end) => {
                self.status = Status::Completed;
                self.error = None;
                self.result = Some(Outcome::of(&end.report, end.steps, None, end.balance));
            }
            Err(WhirlStop::Interrupted) => self.status = Status::Interrupted,
            Err(WhirlStop::Failed(e)) => {
                self.status = Status::Failed;
                self.error = Some(e);
            }
        }
    }
}

/// What atlas.json holds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AtlasFile {
    /// Always `"pendulum"`.
    pub program: String,
    /// Always `"atlas"`.
    pub command: String,
    /// The version that wrote the file.
    pub version: String,
    /// Units and conventions of the numbers.
    pub conventions: String,
    /// Every parameter of the atlas.
    pub config: AtlasConfig,
    /// Numbers derived from them (not read back).
    pub derived: Derived,
    /// `"running"`, `"completed"`, `"interrupted"` or `"failed"`.
    pub status: String,
    /// Every point (kind by kind, row by row of y, along x): its status and result.
    pub points: Vec<AtlasPoint>,
}

const CONVENTIONS: &str = "SI units: ω in rad/s, R in m, λ in N·m·s, times in s, growth rates in 1/s. Points run \
kind by kind, then row by row of the y axis, then along the x axis. Each point: a 3D chain from hanging at rest in \
unit link directions, RK4 + projection, its pivot on the horizontal circle of radius R about the z axis (sudden: at \
ω from t = 0; ramp-up: ω ramped linearly from 0 over the ramp time); the shape in the frame turning with the pivot: \
nodes = axis crossings + 1 (the pivot counts as a node), tip radius = the free end's distance from the axis \
(tip_signed: + on the pivot's side), settled = drift ≤ settle_tolerance · L over the last settle_periods drive \
periods; nearest = the damped steady shape nearest the final shape, its distance, nodes and growth rate (stable: \
below 1e-6 |ω|).";

impl AtlasFile {
    /// An atlas.json of this program's version.
    pub fn new(config: AtlasConfig, derived: Derived, points: Vec<AtlasPoint>) -> Self {
        Self {
            program: "pendulum".into(),
            command: "atlas".into(),
            version: crate::VERSION.into(),
            conventions: CONVENTIONS.into(),
            config,
            derived,
            status: "running".into(),
            points,
        }
    }

    /// Reads and checks an atlas.json; errors name the file and the problem.
    pub fn read(path: &Path) -> Result<Self> {
        let file: Self = read_command_file(path, "atlas")?;
        file.config.check().map_err(|e| e.context(format_args!("--from {}", path.display())))?;
        if file.points.len() != file.config.len() {
            return Err(Error::invalid(format!(
                "--from: {}: {} points recorded, its configuration has {}",
                path.display(),
                file.points.len(),
                file.config.len()
            )));
        }
        Ok(file)
    }

    /// The points to resume from: the completed ones kept, every other pending again.
    pub fn resumed_points(&self) -> Vec<AtlasPoint> {
        self.points
            .iter()
            .map(|p| match p.status {
                Status::Completed => p.clone(),
                _ => AtlasPoint { status: Status::Pending, error: None, result: None, ..p.clone() },
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn request() -> AtlasRequest {
        AtlasRequest {
            masses: vec![0.05; 3],
            lengths: vec![0.1; 3],
            gravity: 9.81,
            omega: vec![1.0, 2.0, 3.0],
            scaled: true,
            radius: vec![0.01, 0.02],
            damping: Damping::Uniform(vec![1e-3]),
            ramp_time: vec![],
            kinds: vec![AtlasKind::Sudden, AtlasKind::RampUp, AtlasKind::Sudden],
            duration: Some(30.0),
            step: None,
        }
    }

    #[test]
    fn points_run_kind_by_kind_then_row_by_row() {
        let config = request().resolve().unwrap();
        assert_eq!((config.x.parameter, config.y.parameter), (Parameter::Omega, Parameter::Radius));
        assert_eq!(config.kinds, [AtlasKind::Sudden, AtlasKind::RampUp]);
        assert_eq!((config.len(), config.ramp_time), (12, Some(10.0)));
        let unit = config.reference_speed();
        assert_eq!(config.x.values, [unit, 2.0 * unit, 3.0 * unit]);
        assert_eq!(config.locate(7), (AtlasKind::RampUp, 1, 0));
        let s = config.setting(2, 1);
        assert_eq!((s.omega, s.radius, s.damping), (3.0 * unit, 0.02, vec![1e-3; 3]));
        assert_eq!(
            config.drive(10),
            DriveConfig::RampedCircle { radius: 0.02, initial_omega: 0.0, omega: 2.0 * unit, duration: 10.0 }
        );
    }

    #[test]
    fn bad_requests_say_what_is_wrong() {
        let message = |r: AtlasRequest| r.resolve().unwrap_err().to_string();
        let one_axis = AtlasRequest { radius: vec![0.02], ..request() };
        assert_eq!(
            message(one_axis),
            "an atlas needs exactly two axes (two of --omega, --radius, --damping, --ramp-time with more than \
             one value, e.g. --omega 1:5:32), got 1 (--omega)"
        );
        let ramp_axis = AtlasRequest { radius: vec![0.02], ramp_time: vec![1.0, 2.0], ..request() };
        assert!(message(ramp_axis).contains("applies to the kind ramp-up only"));
        let negative = AtlasRequest { radius: vec![0.01, -0.02], ..request() };
        assert_eq!(message(negative), "--radius: -0.02 is not a finite value ≥ 0");
        let zero = message(AtlasRequest { radius: vec![0.0, 0.02], ..request() });
        assert!(zero.starts_with("--radius must be finite and positive"), "{zero}");
        let long_ramp = AtlasRequest { ramp_time: vec![40.0], ..request() };
        assert!(message(long_ramp).contains("shorter than --duration 30 s"));
    }

    #[test]
    fn a_damping_axis_gives_each_column_its_chain() {
        let r = AtlasRequest { radius: vec![0.02], damping: Damping::Uniform(vec![1e-3, 2e-3]), ..request() };
        let atlas = Atlas::new(r.resolve().unwrap()).unwrap();
        assert_eq!(atlas.config().y.parameter, Parameter::Damping);
        assert_eq!(atlas.chain(4).damping().as_slice(), [2e-3; 3]);
        assert_eq!(atlas.chain(1).damping().as_slice(), [1e-3; 3]);
    }
}
