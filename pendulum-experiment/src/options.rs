//! A run's options as a front end collects them (the flags of `pendulum simulate`, the
//! keyword arguments of `pendulum.Run`), made into the description's values with the
//! checks and one-line messages every front end shares: per-link lists, the drive, and
//! the names of the integrators and stage solves.

use std::path::PathBuf;

use nalgebra::{Dyn, U2, U3};
use pendulum_core::Chain;
use serde::de::DeserializeOwned;

use crate::assemble::sampled_path;
use crate::description::{Dimension, DriveConfig};
use crate::error::{Error, Result};
use crate::initial::read_numbers;
use crate::spelling::{opt, opt_is};

/// The links of a chain from its per-link lists: `n` if given, else the length of a list of
/// more than one value, else 3 links; a single value is repeated for every link.
/// Returns `(n, masses, lengths)`; errors name the options `n`, `masses` and `lengths`.
pub fn links(n: Option<usize>, masses: Vec<f64>, lengths: Vec<f64>) -> Result<(usize, Vec<f64>, Vec<f64>)> {
    let n = match n {
        Some(0) => return Err(Error::invalid(format!("{}: a chain needs at least 1 link, got 0", opt("n")))),
        Some(n) => n,
        None => [masses.len(), lengths.len()].into_iter().find(|&len| len > 1).unwrap_or(3),
    };
    Ok((n, expand(&opt("masses"), masses, n)?, expand(&opt("lengths"), lengths, n)?))
}

/// `chain` with `damping` (N·m·s per link), checked by the chain (finite, non-negative,
/// named by link); errors name the option `damping`.
pub fn damped(chain: &Chain<Dyn>, damping: &[f64]) -> Result<Chain<Dyn>> {
    chain.clone().with_damping(damping).map_err(|e| Error::from(e).context(opt("damping")))
}

/// A per-link list of `n` entries: one value is repeated, otherwise the list must have
/// exactly `n` entries.
pub fn expand(what: &str, values: Vec<f64>, n: usize) -> Result<Vec<f64>> {
    match values.len() {
        1 => Ok(vec![values[0]; n]),
        len if len == n => Ok(values),
        len => Err(Error::invalid(format!("{what}: got {len} values for {n} links (give 1 or {n})"))),
    }
}

/// The pivot's motion, as options name it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum DriveKind {
    /// Pivot at rest at the origin.
    Fixed,
    /// p(t) = A sin(ωt + φ) d̂ along --direction (default vertical).
    Harmonic,
    /// p(t) = R (cos ωt, sin ωt, 0), a horizontal circle (3D only).
    Circle,
    /// The cubic spline through the positions of --path FILE (rows of t, x, y[, z]).
    Sampled,
}

/// Where a sampled drive's rows come from.
#[derive(Debug, Clone, PartialEq)]
pub enum PathSamples {
    /// A text file of numbers (commas or spaces, `#` comments), the command line's
    /// `--path FILE`.
    File(PathBuf),
    /// The numbers themselves, row after row, named `label` in run.json and the messages
    /// (Python's arrays).
    Rows {
        /// What names them (`"<array>"`).
        label: String,
        /// Every row's `t` and position, one after the other.
        numbers: Vec<f64>,
    },
}

/// The drive's options: its kind and every parameter any kind takes.
#[derive(Debug, Clone, PartialEq)]
pub struct DriveOptions {
    /// Which motion.
    pub kind: DriveKind,
    /// Harmonic: amplitude `A`, m.
    pub amplitude: f64,
    /// Harmonic or circle: angular frequency `ω`, rad/s.
    pub omega: f64,
    /// Harmonic: phase `φ`, rad.
    pub phase: f64,
    /// Harmonic: direction (2 or 3 components; `None`: vertical).
    pub direction: Option<Vec<f64>>,
    /// Circle: radius `R`, m.
    pub radius: f64,
    /// Circle: ramp the speed from `ramp_from` to `omega` over this many seconds.
    pub ramp_time: Option<f64>,
    /// Circle with a ramp: the speed at t = 0, rad/s (`None`: 0).
    pub ramp_from: Option<f64>,
    /// Sampled: the samples, rows of `t, x, y` (2D) or `t, x, y, z` (3D).
    pub path: Option<PathSamples>,
    /// Sampled: the pivot at rest at the first and last sample (else the natural spline).
    pub path_at_rest: bool,
}

impl DriveOptions {
    /// The drive these options describe for a chain in `dim`; the parameters a kind does
    /// not take are refused by name when given.
    pub fn config(&self, dim: Dimension) -> Result<DriveConfig> {
        let drive = match self.kind {
            DriveKind::Fixed => DriveConfig::Fixed,
            DriveKind::Harmonic => {
                let direction = self.direction.clone().unwrap_or_else(|| {
                    let mut up = vec![0.0; dim.space()];
                    up[dim.space() - 1] = 1.0;
                    up
                });
                DriveConfig::Harmonic {
                    direction,
                    amplitude: self.amplitude,
                    omega: self.omega,
                    phase: self.phase,
                }
            }
            DriveKind::Sampled => self.sampled(dim)?,
            DriveKind::Circle => match self.ramp_time {
                None => DriveConfig::Circle { radius: self.radius, omega: self.omega },
                Some(duration) => DriveConfig::RampedCircle {
                    radius: self.radius,
                    initial_omega: self.ramp_from.unwrap_or(0.0),
                    omega: self.omega,
                    duration,
                },
            },
        };
        if (self.ramp_time.is_some() || self.ramp_from.is_some()) && self.kind != DriveKind::Circle {
            return Err(Error::invalid(format!(
                "{} and {} apply to {} only",
                opt("ramp-time"),
                opt("ramp-from"),
                opt_is("drive", "circle")
            )));
        }
        if self.ramp_from.is_some() && self.ramp_time.is_none() {
            return Err(Error::invalid(format!(
                "{} needs {} (the ramp's duration, s)",
                opt("ramp-from"),
                opt("ramp-time")
            )));
        }
        if self.direction.is_some() && self.kind != DriveKind::Harmonic {
            return Err(Error::invalid(format!(
                "{} applies to {} only",
                opt("direction"),
                opt_is("drive", "harmonic")
            )));
        }
        if (self.path.is_some() || self.path_at_rest) && self.kind != DriveKind::Sampled {
            return Err(Error::invalid(format!(
                "{} and {} apply to {} only",
                opt("path"),
                opt("path-at-rest"),
                opt_is("drive", "sampled")
            )));
        }
        Ok(drive)
    }

    /// The sampled drive of `--path` for a chain in `dim`: its rows read (`t` and the
    /// position's `dim` components each) and its spline checked.
    fn sampled(&self, dim: Dimension) -> Result<DriveConfig> {
        let (label, numbers) = match &self.path {
            None => {
                return Err(Error::invalid(format!(
                    "{} needs {} (rows of t, x, y[, z])",
                    opt_is("drive", "sampled"),
                    opt("path")
                )));
            }
            Some(PathSamples::File(path)) => (path.display().to_string(), read_numbers(&opt("path"), path)?),
            Some(PathSamples::Rows { label, numbers }) => (label.clone(), numbers.clone()),
        };
        let width = 1 + dim.space();
        if numbers.len() % width != 0 || numbers.is_empty() {
            return Err(Error::invalid(format!(
                "{}: {label} holds {} numbers, not rows of {width} (t and {} components of the position)",
                opt("path"),
                numbers.len(),
                dim.space()
            )));
        }
        let times: Vec<f64> = numbers.iter().step_by(width).copied().collect();
        let positions: Vec<Vec<f64>> = numbers.chunks_exact(width).map(|row| row[1..].to_vec()).collect();
        // The spline built once here, so that a bad sample is named with the file.
        let at_rest = self.path_at_rest;
        let checked = match dim {
            Dimension::Two => sampled_path::<U2>(&times, &positions, at_rest).map(|_| ()),
            Dimension::Three => sampled_path::<U3>(&times, &positions, at_rest).map(|_| ()),
        };
        checked.map_err(|e| Error::invalid(format!("{} {label}: {e}", opt("path"))))?;
        Ok(DriveConfig::Sampled { file: label, times, positions, at_rest })
    }
}

/// A value of the description by its name in run.json (`"rk4"`, `"fixed-point"`,
/// `"circle"`); errors name `what` and list the `choices`.
pub fn by_name<T: DeserializeOwned>(what: &str, name: &str, choices: &str) -> Result<T> {
    serde_json::from_value(serde_json::Value::String(name.into()))
        .map_err(|_| Error::invalid(format!("{what}: '{name}' is not one of {choices}")))
}

/// Parses the values of `option` (e.g. `--omega`): a comma list `V1,V2,…` or a range
/// `A:B:N` (N evenly spaced values from A to B, B exactly; N = 1 is A), every value finite
/// and ≥ 0. `noun` names one value and many ("speed", "speeds") and `unit` their unit, in
/// the messages, which name the bad value.
pub fn parse_values(option: &str, spec: &str, noun: (&str, &str), unit: &str) -> Result<Vec<f64>> {
    let (noun, nouns) = noun;
    let bad = |why: String| Error::invalid(format!("{option}: '{spec}' {why}"));
    let number = |token: &str, what: &str| -> Result<f64> {
        let token = token.trim();
        match token.parse::<f64>() {
            Ok(v) if !v.is_finite() => Err(bad(format!("has a non-finite {what} {token}"))),
            Ok(v) if v < 0.0 => Err(bad(format!("has a negative {what} {token} ({nouns} are ≥ 0 {unit})"))),
            Ok(v) => Ok(v),
            Err(_) if token.is_empty() => Err(bad(format!("has an empty {what}"))),
            Err(_) => Err(bad(format!("has a bad {what} '{token}' (not a number)"))),
        }
    };
    if spec.trim().is_empty() || spec.split(',').all(|t| t.trim().is_empty()) {
        return Err(bad(format!(
            "lists no {noun} (give V1,V2,… or A:B:N in {unit}, e.g. {option} 2,4 or {option} 1:5:9)"
        )));
    }
    if spec.contains(':') {
        let parts: Vec<&str> = spec.split(':').collect();
        if parts.len() != 3 || spec.contains(',') {
            return Err(bad("is not a range A:B:N (start, end, number of points)".into()));
        }
        let (a, b) = (number(parts[0], "start")?, number(parts[1], "end")?);
        let count = parts[2].trim();
        let n: usize = match count.parse::<i64>() {
            Ok(n) if n < 1 => return Err(bad(format!("asks for {n} points (N must be at least 1)"))),
            Ok(n) => n as usize,
            Err(_) => {
                return Err(bad(format!("has a bad number of points '{count}' (N: a whole number ≥ 1)")));
            }
        };
        if n == 1 {
            return Ok(vec![a]);
        }
        return Ok((0..n)
            .map(|k| if k == n - 1 { b } else { a + (b - a) * k as f64 / (n - 1) as f64 })
            .collect());
    }
    spec.split(',').map(|token| number(token, "entry")).collect()
}

/// The number of cores (1 if unknown): the default number of threads of a front end.
pub fn all_cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// Checks that `value` of `option` is finite and positive; the error names it and its
/// `unit` (none when empty).
pub fn check_positive(option: &str, value: f64, unit: &str) -> Result<()> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else if unit.is_empty() {
        Err(Error::invalid(format!("{option} must be finite and positive, got {value}")))
    } else {
        Err(Error::invalid(format!("{option} must be finite and positive, got {value} ({unit})")))
    }
}

/// Checks the radius of a pivot's circle, m: finite and positive.
pub fn check_radius(radius: f64) -> Result<()> {
    if radius.is_finite() && radius > 0.0 {
        Ok(())
    } else {
        Err(Error::invalid(format!(
            "{} must be finite and positive (the pivot's circle drives the chain), got {radius}",
            opt("radius")
        )))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::description::IntegratorKind;
    use crate::spelling::Front;

    #[test]
    fn lists_expand_to_the_links_and_errors_name_the_option() {
        assert_eq!(links(None, vec![1.0], vec![0.5]).unwrap(), (3, vec![1.0; 3], vec![0.5; 3]));
        assert_eq!(links(None, vec![1.0, 2.0], vec![0.5]).unwrap().2, vec![0.5; 2]);
        let e = links(Some(3), vec![1.0, 2.0], vec![0.5]).unwrap_err();
        assert_eq!(e.to_string(), "--masses: got 2 values for 3 links (give 1 or 3)");
        assert_eq!(e.message(Front::Python), "masses: got 2 values for 3 links (give 1 or 3)");
        let e = links(Some(0), vec![1.0], vec![1.0]).unwrap_err();
        assert_eq!(e.message(Front::Python), "n: a chain needs at least 1 link, got 0");
    }

    #[test]
    fn a_drive_takes_only_its_own_parameters() {
        let circle = DriveOptions {
            kind: DriveKind::Circle,
            amplitude: 0.05,
            omega: 5.0,
            phase: 0.0,
            direction: None,
            radius: 0.02,
            ramp_time: Some(100.0),
            ramp_from: None,
            path: None,
            path_at_rest: false,
        };
        assert_eq!(
            circle.config(Dimension::Three).unwrap(),
            DriveConfig::RampedCircle { radius: 0.02, initial_omega: 0.0, omega: 5.0, duration: 100.0 }
        );
        let shaken = DriveOptions { kind: DriveKind::Harmonic, ..circle.clone() };
        assert!(shaken.config(Dimension::Two).unwrap_err().to_string().contains("--drive circle only"));
        let up = DriveOptions { ramp_time: None, ..shaken };
        assert_eq!(
            up.config(Dimension::Two).unwrap(),
            DriveConfig::Harmonic { direction: vec![0.0, 1.0], amplitude: 0.05, omega: 5.0, phase: 0.0 }
        );
    }

    #[test]
    fn a_sampled_drive_reads_its_rows_and_names_a_bad_file() {
        let dir = std::env::temp_dir().join(format!("pendulum-options-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = |name: &str, text: &str| {
            let path = dir.join(name);
            std::fs::write(&path, text).unwrap();
            path
        };
        let base = DriveOptions {
            kind: DriveKind::Sampled,
            amplitude: 0.05,
            omega: 5.0,
            phase: 0.0,
            direction: None,
            radius: 0.02,
            ramp_time: None,
            ramp_from: None,
            path: Some(PathSamples::File(file(
                "hand.csv",
                "# t, x, y, z\n0, 0, 0, 0\n0.5, 0.01, 0, 0.02\n1.0 0 0.01 0\n",
            ))),
            path_at_rest: true,
        };
        let DriveConfig::Sampled { times, positions, at_rest, file: name } =
            base.config(Dimension::Three).unwrap()
        else {
            panic!("not sampled")
        };
        assert_eq!((times, at_rest), (vec![0.0, 0.5, 1.0], true));
        assert_eq!(positions[1], vec![0.01, 0.0, 0.02]);
        assert!(name.ends_with("hand.csv"), "{name}");
        let message = |options: DriveOptions, dim| options.config(dim).unwrap_err().to_string();
        let short = file("short.csv", "0 0 0 0\n1 0 0\n");
        let e =
            message(DriveOptions { path: Some(PathSamples::File(short)), ..base.clone() }, Dimension::Three);
        assert!(
            e.ends_with("short.csv holds 7 numbers, not rows of 4 (t and 3 components of the position)"),
            "{e}"
        );
        let unordered = file("back.csv", "0 0 0\n1 0 0\n1 0 1\n");
        let e = message(
            DriveOptions { path: Some(PathSamples::File(unordered)), ..base.clone() },
            Dimension::Two,
        );
        assert!(
            e.starts_with("--path ") && e.ends_with("back.csv: times[2] must be after times[1] = 1, got 1"),
            "{e}"
        );
        let e = message(DriveOptions { path: None, ..base.clone() }, Dimension::Two);
        assert_eq!(e, "--drive sampled needs --path (rows of t, x, y[, z])");
        let e = message(DriveOptions { kind: DriveKind::Harmonic, ..base }, Dimension::Two);
        assert_eq!(e, "--path and --path-at-rest apply to --drive sampled only");
        // A run.json's path whose positions do not fit the chain's space.
        let e = sampled_path::<U2>(&[0.0, 1.0], &[vec![0.0, 0.0], vec![0.0, 0.0, 1.0]], false).unwrap_err();
        assert_eq!(e.to_string(), "drive positions[1]: got 3 components, the 2D pivot moves in 2");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn names_are_run_json_names() {
        assert_eq!(by_name::<IntegratorKind>("integrator", "dp54", "…").unwrap(), IntegratorKind::Dp54);
        assert_eq!(by_name::<DriveKind>("drive", "circle", "…").unwrap(), DriveKind::Circle);
        let e = by_name::<IntegratorKind>("integrator", "euler", "gl1, rk4").unwrap_err();
        assert_eq!(e.to_string(), "integrator: 'euler' is not one of gl1, rk4");
    }
}
