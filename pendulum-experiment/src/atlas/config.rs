//! Every parameter of an atlas ([`AtlasConfig`], atlas.json's `config`): its grid (points
//! kind by kind, row by row of y, along x), each point's parameters and drive, the checks
//! of a configuration read back, and the numbers derived from it.

use nalgebra::Dyn;
use pendulum_core::{Chain, SteadyRotation};
use serde::{Deserialize, Serialize};

use super::{AtlasKind, Axis, Parameter};
use crate::description::DriveConfig;
use crate::error::{Error, Result};
use crate::options::{check_positive, check_radius, damped};
use crate::spelling::{opt, opt_is};
use crate::whirls::{first_mode_decay, reference_speed};

/// Most steps of one point.
const MAX_STEPS: f64 = 1e8;

/// Most points of an atlas (kinds × grid).
pub const MAX_POINTS: usize = 1 << 20;

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
        reference_speed(self.gravity, &self.lengths)
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
            return Err(Error::invalid(format!("{}: {w} rad/s is not a finite speed ≥ 0", opt("omega"))));
        }
        if let Some(d) = &self.damping {
            if d.len() != n {
                return Err(Error::invalid(format!("damping: got {} values, expected {n}", d.len())));
            }
            damped(&chain, d)?;
        }
        let radii = match self.radius {
            Some(r) => vec![r],
            None => self.axis(Parameter::Radius).map_or(vec![], |a| a.values.clone()),
        };
        for &r in &radii {
            check_radius(r)?;
        }
        if self.kinds.is_empty() {
            return Err(Error::invalid(format!("{}: no kind of start given", opt("kind"))));
        }
        let ramps = self.kinds.contains(&AtlasKind::RampUp);
        let ramp_axis = is_axis(Parameter::RampTime);
        if ramp_axis && self.kinds.contains(&AtlasKind::Sudden) {
            return Err(Error::invalid(format!(
                "{} as an axis applies to the kind ramp-up only",
                opt("ramp-time")
            )));
        }
        check_positive(&opt("duration"), self.duration, "s")?;
        let ramp_times = match (self.ramp_time, ramp_axis) {
            (Some(_), true) => {
                return Err(Error::invalid(format!(
                    "{} is an axis and also given one value",
                    opt("ramp-time")
                )));
            }
            (Some(t), false) if ramps => vec![t],
            (Some(_), false) => {
                return Err(Error::invalid(format!("{} applies to the kind ramp-up only", opt("ramp-time"))));
            }
            (None, true) => self.axis(Parameter::RampTime).map_or(vec![], |a| a.values.clone()),
            (None, false) if ramps => {
                return Err(Error::invalid(format!("{}: no value given for ramp-up", opt("ramp-time"))));
            }
            (None, false) => vec![],
        };
        if let Some(t) = ramp_times.iter().find(|t| !(t.is_finite() && **t > 0.0 && **t < self.duration)) {
            return Err(Error::invalid(format!(
                "{} must be positive and shorter than {} s, got {t} s",
                opt("ramp-time"),
                opt_is("duration", self.duration)
            )));
        }
        if !(self.step.is_finite() && self.step > 0.0) {
            return Err(Error::invalid(format!(
                "{} must be finite and positive, got {} (s)",
                opt("step"),
                self.step
            )));
        }
        if self.duration / self.step > MAX_STEPS {
            return Err(Error::invalid(format!(
                "{} s: {} s would take more than {MAX_STEPS:e} steps per point",
                opt_is("step", self.step),
                self.duration
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
