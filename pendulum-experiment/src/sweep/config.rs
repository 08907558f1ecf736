//! The resolved parameters of a sweep ([`SweepConfig`], from a front end's
//! [`SweepRequest`] or a sweep.json), their checks and defaults (duration from the damping, step from the
//! chain's fastest mode), the `--omega` list or range, and sweep.json itself
//! ([`SweepFile`]: the parameters, derived numbers and every point's result so far).

use nalgebra::Dyn;
use pendulum_core::{Chain, SteadyRotation};
use serde::{Deserialize, Serialize};

use super::SweepKind;
use super::point::Point;
use crate::error::{Error, Result};
use crate::options::{check_positive, check_radius, damped, parse_values};
use crate::points::{PointsFile, Recorded};
use crate::spelling::{opt, opt_is};
use crate::steady::round_up;
use crate::whirls::{
    FEED_EVERY, SETTLE_PERIODS, SETTLE_TOLERANCE, default_duration, default_step, first_mode_decay,
    reference_speed,
};

/// Most steps of one point.
const MAX_STEPS: f64 = 1e8;

/// Every parameter of a sweep; with the program version, enough to repeat it exactly.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepConfig {
    /// Masses `m_i`, kg, one per link.
    pub masses: Vec<f64>,
    /// Rod lengths `l_i`, m.
    pub lengths: Vec<f64>,
    /// Gravity `g`, m/s² (along −z).
    pub gravity: f64,
    /// Damping `λ_i`, N·m·s.
    pub damping: Vec<f64>,
    /// Radius `R` of the pivot's circle, m.
    pub radius: f64,
    /// `--omega` as given.
    pub omega_spec: String,
    /// Whether `--omega` was in units of `√(g/L)`.
    pub scaled: bool,
    /// The speeds, rad/s, in the order given.
    pub omegas: Vec<f64>,
    /// The kinds of experiment, in the order given, each once.
    pub kinds: Vec<SweepKind>,
    /// Simulated time of every point, s.
    pub duration: f64,
    /// Length of the ramps, s (`None` without a ramp kind).
    pub ramp_time: Option<f64>,
    /// RK4 step, s (every run takes `⌈duration / step⌉` equal steps).
    pub step: f64,
    /// The shape analysis is fed every this many steps.
    pub feed_every: usize,
    /// Settle window, drive periods.
    pub settle_periods: f64,
    /// Settled when the drift is at most this times the chain's length.
    pub settle_tolerance: f64,
}

impl SweepConfig {
    /// Number of links.
    pub fn links(&self) -> usize {
        self.masses.len()
    }

    /// The chain's length `L = Σ l_i`, m.
    pub fn length(&self) -> f64 {
        self.lengths.iter().sum()
    }

    /// `√(g/L)`, rad/s: the unit of `--scaled` speeds.
    pub fn reference_speed(&self) -> f64 {
        reference_speed(self.gravity, &self.lengths)
    }

    /// The chain without damping (the steady shapes).
    pub fn chain(&self) -> Result<Chain<Dyn>> {
        Ok(Chain::<Dyn>::new(&self.masses, &self.lengths, self.gravity)?)
    }

    /// The damped chain of the runs.
    pub fn damped_chain(&self) -> Result<Chain<Dyn>> {
        damped(&self.chain()?, &self.damping)
    }

    /// Checks what building the chain and the drives does not: counts, signs, times.
    pub fn check(&self) -> Result<()> {
        let n = self.links();
        if n == 0 {
            return Err(Error::invalid("masses: a chain needs at least 1 link, got 0"));
        }
        for (what, got) in [("lengths", self.lengths.len()), ("damping", self.damping.len())] {
            if got != n {
                return Err(Error::invalid(format!("{what}: got {got} values, expected {n}")));
            }
        }
        if !(self.gravity.is_finite() && self.gravity > 0.0) {
            return Err(Error::invalid(format!(
                "gravity must be finite and positive for a sweep, got {}",
                self.gravity
            )));
        }
        self.damped_chain()?;
        check_radius(self.radius)?;
        if self.omegas.is_empty() {
            return Err(Error::invalid(format!("{}: no speed to sweep", opt("omega"))));
        }
        if let Some(w) = self.omegas.iter().find(|w| !(w.is_finite() && **w >= 0.0)) {
            return Err(Error::invalid(format!("{}: {w} rad/s is not a finite speed ≥ 0", opt("omega"))));
        }
        if self.kinds.is_empty() {
            return Err(Error::invalid(format!("{}: no kind of experiment given", opt("kind"))));
        }
        check_positive(&opt("duration"), self.duration, "s")?;
        let ramps = self.kinds.iter().any(|&k| k != SweepKind::Sudden);
        match (self.ramp_time, ramps) {
            (Some(t), true) => {
                if !(t.is_finite() && t > 0.0) {
                    return Err(Error::invalid(format!(
                        "{} must be finite and positive, got {t} (s)",
                        opt("ramp-time")
                    )));
                }
                if t >= self.duration {
                    return Err(Error::invalid(format!(
                        "{} s must be shorter than {} s (the speed is held at ω after the ramp)",
                        opt_is("ramp-time", t),
                        opt_is("duration", self.duration)
                    )));
                }
            }
            (None, true) => return Err(Error::invalid("ramp_time: the ramp kinds need a ramp time")),
            (Some(_), false) => return Err(Error::invalid("ramp_time: given without a ramp kind")),
            (None, false) => {}
        }
        if !(self.step.is_finite() && self.step > 0.0) {
            return Err(Error::invalid(format!(
                "{} must be finite and positive, got {}",
                opt("step"),
                self.step
            )));
        }
        let steps = (self.duration / self.step).ceil();
        if steps > MAX_STEPS {
            return Err(Error::invalid(format!(
                "{} s with {} s needs {steps:e} steps per point; more than {MAX_STEPS:e} is refused",
                opt_is("duration", self.duration),
                opt_is("step", self.step)
            )));
        }
        if self.feed_every == 0 {
            return Err(Error::invalid("feed_every must be at least 1 step, got 0"));
        }
        if !(self.settle_periods.is_finite() && self.settle_periods > 0.0) {
            return Err(Error::invalid(format!(
                "settle_periods must be finite and positive, got {}",
                self.settle_periods
            )));
        }
        if !(self.settle_tolerance.is_finite() && self.settle_tolerance >= 0.0) {
            return Err(Error::invalid(format!(
                "settle_tolerance must be finite and non-negative, got {}",
                self.settle_tolerance
            )));
        }
        Ok(())
    }

    /// Numbers derived from the parameters, for the reader (not read back).
    pub fn derived(&self) -> Result<Derived> {
        let chain = self.damped_chain()?;
        let free = SteadyRotation::new(&chain, 0.0)?;
        let critical = free.bifurcation_speeds(self.links().min(4))?;
        let (steps, _) = pendulum_core::trajectory::plan(0.0, self.duration, self.step)?;
        Ok(Derived {
            length: self.length(),
            reference_speed: self.reference_speed(),
            first_mode_decay_rate: first_mode_decay(&chain),
            critical_speeds: critical,
            steps_per_point: steps,
        })
    }
}

/// A sweep as a front end asks for it: the chain (damping per link), the circle, the
/// speeds as `--omega` writes them, the kinds, and the times (`None`: the defaults).
#[derive(Debug, Clone, PartialEq)]
pub struct SweepRequest {
    /// Masses `m_i`, kg.
    pub masses: Vec<f64>,
    /// Rod lengths `l_i`, m.
    pub lengths: Vec<f64>,
    /// Gravity `g`, m/s².
    pub gravity: f64,
    /// Damping `λ_i`, N·m·s, one per link.
    pub damping: Vec<f64>,
    /// Radius `R` of the pivot's circle, m.
    pub radius: f64,
    /// The speeds: a comma list or `A:B:N` (`--omega`).
    pub omega_spec: String,
    /// Whether the speeds are in units of `√(g/L)`.
    pub scaled: bool,
    /// The kinds of experiment, in order (repeats dropped).
    pub kinds: Vec<SweepKind>,
    /// Simulated time of every point, s (default: [`default_duration`]).
    pub duration: Option<f64>,
    /// Length of the ramps, s (default: a third of the duration).
    pub ramp_time: Option<f64>,
    /// RK4 step, s (default: [`default_step`] at the largest ω).
    pub step: Option<f64>,
}

impl SweepRequest {
    /// Resolves the request into a complete configuration; errors name the bad value.
    pub fn resolve(&self) -> Result<SweepConfig> {
        let p = self;
        let (masses, lengths, damping) = (p.masses.clone(), p.lengths.clone(), p.damping.clone());
        if !(p.gravity.is_finite() && p.gravity > 0.0) {
            return Err(Error::invalid(format!(
                "{} must be finite and positive for a sweep (the chain starts hanging at rest), got {}",
                opt("gravity"),
                p.gravity
            )));
        }
        if damping.len() != masses.len() {
            return Err(Error::invalid(format!(
                "{}: got {} values, expected {}",
                opt("damping"),
                damping.len(),
                masses.len()
            )));
        }
        // The chain's own checks (positive masses and lengths, damping ≥ 0), named by link.
        let chain = Chain::<Dyn>::new(&masses, &lengths, p.gravity)?;
        let damped = damped(&chain, &damping)?;
        check_radius(p.radius)?;
        let spec = p.omega_spec.clone();
        let listed = parse_omegas(&spec, p.scaled)?;
        let scale = reference_speed(p.gravity, &lengths);
        let omegas: Vec<f64> = if p.scaled { listed.iter().map(|w| w * scale).collect() } else { listed };
        let mut kinds = Vec::new();
        for &k in &p.kinds {
            if !kinds.contains(&k) {
                kinds.push(k);
            }
        }
        if let Some(d) = p.duration {
            check_positive(&opt("duration"), d, "s")?;
        }
        let duration = match p.duration {
            Some(d) => d,
            None => default_duration(&damped),
        };
        let ramps = kinds.iter().any(|&k| k != SweepKind::Sudden);
        let ramp_time = match (p.ramp_time, ramps) {
            (Some(t), true) => Some(t),
            (None, true) => Some(round_up(duration / 3.0)),
            (Some(_), false) => {
                return Err(Error::invalid(format!(
                    "{} applies to the kinds ramp-up and ramp-down only (a sudden start has no ramp)",
                    opt("ramp-time")
                )));
            }
            (None, false) => None,
        };
        let fastest_drive = omegas.iter().copied().fold(0.0, f64::max);
        let step = match p.step {
            Some(h) => h,
            None => default_step(&damped, p.radius, fastest_drive),
        };
        let config = SweepConfig {
            masses,
            lengths,
            gravity: p.gravity,
            damping,
            radius: p.radius,
            omega_spec: spec,
            scaled: p.scaled,
            omegas,
            kinds,
            duration,
            ramp_time,
            step,
            feed_every: FEED_EVERY,
            settle_periods: SETTLE_PERIODS,
            settle_tolerance: SETTLE_TOLERANCE,
        };
        config.check()?;
        Ok(config)
    }
}

/// Numbers a reader of sweep.json wants beside the parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Derived {
    /// The chain's length `L`, m.
    pub length: f64,
    /// `√(g/L)`, rad/s.
    pub reference_speed: f64,
    /// Decay rate of the first mode at rest, `σ = ½ Σ λ_i v_i²`, 1/s.
    pub first_mode_decay_rate: f64,
    /// The lowest critical speeds of the chain on a fixed pivot, rad/s.
    pub critical_speeds: Vec<f64>,
    /// Steps of every run.
    pub steps_per_point: u64,
}

/// Parses `--omega`: a comma list of speeds or `A:B:N`, every speed finite and ≥ 0 (in
/// rad/s, or in units of √(g/L) when `scaled`). Errors name the value.
pub fn parse_omegas(spec: &str, scaled: bool) -> Result<Vec<f64>> {
    parse_values(&opt("omega"), spec, ("speed", "speeds"), if scaled { "√(g/L)" } else { "rad/s" })
}

/// What sweep.json holds.
pub type SweepFile = PointsFile<SweepConfig, Derived, Point>;

impl Recorded for SweepConfig {
    const COMMAND: &'static str = "sweep";
    const CONVENTIONS: &'static str = "SI units: ω in rad/s (omega_scaled: ω / √(g/L), L the chain's length), lengths in m, \
    times in s, growth rates in 1/s. Each point: a 3D chain in unit link directions, RK4 + projection, its pivot on the \
    horizontal circle of radius R about the z axis; the shape in the frame turning with the pivot (pivot at (R, 0, 0)): \
    nodes = axis crossings + 1 (the pivot counts as a node), tip radius = the free end's distance from the axis \
    (tip_signed: + on the pivot's side), settled = drift ≤ settle_tolerance · L over the last settle_periods drive \
    periods; nearest = the damped steady shape (relative equilibrium) nearest the final shape, its distance, nodes \
    and growth rate (stable: below 1e-6 |ω|).";

    fn check(&self) -> Result<()> {
        SweepConfig::check(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn speed_lists_and_ranges() {
        assert_eq!(parse_omegas("1, 2,3", false).unwrap(), vec![1.0, 2.0, 3.0]);
        assert_eq!(parse_omegas("1:3:5", false).unwrap(), vec![1.0, 1.5, 2.0, 2.5, 3.0]);
        assert_eq!(parse_omegas("4:2:3", false).unwrap(), vec![4.0, 3.0, 2.0]);
        assert_eq!(parse_omegas("2:9:1", false).unwrap(), vec![2.0]);
        let range = parse_omegas("0.5:5:24", true).unwrap();
        assert_eq!((range.len(), range[0], range[23]), (24, 0.5, 5.0));
        let message = |s: &str| parse_omegas(s, false).unwrap_err().to_string();
        assert!(message("").contains("lists no speed"), "{}", message(""));
        assert_eq!(message("1,,2"), "--omega: '1,,2' has an empty entry");
        assert_eq!(message("1,-2"), "--omega: '1,-2' has a negative entry -2 (speeds are ≥ 0 rad/s)");
        assert_eq!(message("inf"), "--omega: 'inf' has a non-finite entry inf");
        assert_eq!(message("1:2"), "--omega: '1:2' is not a range A:B:N (start, end, number of points)");
        assert_eq!(message("1:2:0"), "--omega: '1:2:0' asks for 0 points (N must be at least 1)");
        assert_eq!(message("1:x:3"), "--omega: '1:x:3' has a bad end 'x' (not a number)");
        assert_eq!(
            message("1:2:2.5"),
            "--omega: '1:2:2.5' has a bad number of points '2.5' (N: a whole number ≥ 1)"
        );
    }
}
