//! An atlas as a front end asks for it ([`AtlasRequest`]: one value holds a parameter
//! fixed, two or more make it an axis) and its resolution into an [`AtlasConfig`], with the
//! defaults of duration, ramp and step and one-line errors naming the bad value.

use nalgebra::Dyn;
use pendulum_core::Chain;

use super::{AtlasConfig, AtlasKind, Axis, Parameter};
use crate::error::{Error, Result};
use crate::options::{check_positive, damped};
use crate::spelling::opt;
use crate::steady::round_up;
use crate::whirls::{
    FEED_EVERY, SETTLE_PERIODS, SETTLE_TOLERANCE, default_duration, default_step, reference_speed,
};

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

impl AtlasRequest {
    /// Resolves the request into a complete configuration; errors name the bad value.
    pub fn resolve(&self) -> Result<AtlasConfig> {
        let n = self.masses.len();
        let chain = Chain::<Dyn>::new(&self.masses, &self.lengths, self.gravity)?;
        if !(self.gravity.is_finite() && self.gravity > 0.0) {
            return Err(Error::invalid(format!(
                "{} must be finite and positive for an atlas (the chain starts hanging at rest), got {}",
                opt("gravity"),
                self.gravity
            )));
        }
        let unit = if self.scaled { reference_speed(self.gravity, &self.lengths) } else { 1.0 };
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
            let named: Vec<String> = axes.iter().map(|a| a.parameter.option()).collect();
            let all: Vec<String> = Parameter::ALL.iter().map(|p| p.option()).collect();
            return Err(Error::invalid(format!(
                "an atlas needs exactly two axes (two of {} with more than one value), got {}{}",
                all.join(", "),
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
            return Err(Error::invalid(format!(
                "{} as an axis applies to the kind ramp-up only (a sudden start has no ramp)",
                opt("ramp-time")
            )));
        }
        if !ramps && !self.ramp_time.is_empty() {
            return Err(Error::invalid(format!(
                "{} applies to the kind ramp-up only (a sudden start has no ramp)",
                opt("ramp-time")
            )));
        }
        if let Some(d) = self.duration {
            check_positive(&opt("duration"), d, "s")?;
        }
        // The least damped chain decays slowest; the most damped has the fastest decay.
        let extreme = |pick: fn(f64, f64) -> f64| -> Result<Chain<Dyn>> {
            let per_link = match &damping_fixed {
                Some(d) => d.clone(),
                None => vec![damping_axis.iter().copied().reduce(pick).unwrap_or(0.0); n],
            };
            damped(&chain, &per_link)
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
