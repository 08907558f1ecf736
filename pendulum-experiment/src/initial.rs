//! How a run starts: [`InitialSpec`] (hanging, horizontal, tilted, a file of numbers, a
//! previous run's final state) and its resolution into the numbers of an
//! [`InitialConfig`].

use std::path::Path;

use crate::description::{Dimension, InitialConfig};
use crate::error::{Error, Result};
use crate::final_state::FinalState;
use crate::spelling::opt;

/// How the chain starts.
#[derive(Debug, Clone, PartialEq)]
pub enum InitialSpec {
    /// Every link straight down, at rest.
    Hanging,
    /// Every link along +x, at rest.
    Horizontal,
    /// Every link at the angle (rad) from the downward vertical, toward +x, at rest.
    Tilted(f64),
    /// Coordinates then rates from a file (2D: θ_1..θ_n, θ̇_1..θ̇_n; 3D: θ_1..θ_n,
    /// φ_1..φ_n, θ̇_1..θ̇_n, φ̇_1..φ̇_n).
    File(std::path::PathBuf),
}

impl std::str::FromStr for InitialSpec {
    type Err = String;

    /// `hanging`, `horizontal`, `tilted:ANGLE` (rad) or a file path.
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "hanging" => Ok(Self::Hanging),
            "horizontal" => Ok(Self::Horizontal),
            _ => {
                if let Some(angle) = s.strip_prefix("tilted:") {
                    return match angle.trim().parse::<f64>() {
                        Ok(a) if a.is_finite() => Ok(Self::Tilted(a)),
                        _ => Err(format!("tilted angle '{angle}' is not a finite number (rad)")),
                    };
                }
                if s == "tilted" {
                    return Err("give the angle in rad: tilted:ANGLE, e.g. tilted:0.5".into());
                }
                let path = std::path::PathBuf::from(s);
                // A file of numbers, or a previous run's final state: `final.json` or the
                // run directory holding it (read, and reported if missing, later).
                if path.is_file() || path.is_dir() || s.ends_with(".json") {
                    Ok(Self::File(path))
                } else {
                    Err(format!("'{s}' is not hanging, horizontal, tilted:ANGLE or an existing file"))
                }
            }
        }
    }
}

impl std::fmt::Display for InitialSpec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Hanging => f.write_str("hanging"),
            Self::Horizontal => f.write_str("horizontal"),
            Self::Tilted(a) => write!(f, "tilted:{a}"),
            Self::File(p) => write!(f, "{}", p.display()),
        }
    }
}

/// The coordinates and rates of an initial spec (see [`InitialSpec`]); `spin` is the
/// 3D azimuthal rate φ̇ of every link (rad/s), ignored for a state from a file.
pub fn initial_state(spec: &InitialSpec, dim: Dimension, n: usize, spin: f64) -> Result<InitialConfig> {
    let dof = if dim == Dimension::Two { n } else { 2 * n };
    let straight = |theta: f64| {
        let mut q = vec![0.0; dof];
        q[..n].fill(theta);
        let mut qd = vec![0.0; dof];
        if dim == Dimension::Three {
            qd[n..].fill(spin);
        }
        (q, qd)
    };
    let (coordinates, rates) = match spec {
        InitialSpec::Hanging => straight(0.0),
        InitialSpec::Horizontal => straight(std::f64::consts::FRAC_PI_2),
        InitialSpec::Tilted(a) => straight(*a),
        InitialSpec::File(path) if FinalState::names(path) => {
            let state = FinalState::read_for(path, dim, n)?;
            return Ok(match dim {
                Dimension::Two => InitialConfig {
                    spec: spec.to_string(),
                    coordinates: state.coordinates,
                    rates: state.rates,
                    directions: None,
                },
                Dimension::Three => {
                    let directions = state.start();
                    InitialConfig {
                        spec: spec.to_string(),
                        coordinates: vec![],
                        rates: vec![],
                        directions: Some(directions),
                    }
                }
            });
        }
        InitialSpec::File(path) => {
            let values = read_numbers(&opt("initial"), path)?;
            if values.len() != 2 * dof {
                let layout = if dim == Dimension::Two {
                    "θ_1..θ_n then θ̇_1..θ̇_n"
                } else {
                    "θ_1..θ_n, φ_1..φ_n, θ̇_1..θ̇_n, φ̇_1..φ̇_n"
                };
                return Err(Error::invalid(format!(
                    "{}: {} holds {} numbers, expected {} ({layout}) for n = {n}",
                    opt("initial"),
                    path.display(),
                    values.len(),
                    2 * dof
                )));
            }
            (values[..dof].to_vec(), values[dof..].to_vec())
        }
    };
    Ok(InitialConfig { spec: spec.to_string(), coordinates, rates, directions: None })
}

/// Reads every number in a text file: separated by whitespace or commas, `#` starts a
/// comment that runs to the end of the line.
pub fn read_numbers(what: &str, path: &Path) -> Result<Vec<f64>> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| Error::invalid(format!("{what}: cannot read {}: {e}", path.display())))?;
    let mut out = Vec::new();
    for (line_no, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("");
        for token in line.split(|c: char| c.is_whitespace() || c == ',').filter(|t| !t.is_empty()) {
            match token.parse::<f64>() {
                Ok(v) if v.is_finite() => out.push(v),
                _ => {
                    return Err(Error::invalid(format!(
                        "{what}: {} line {}: '{token}' is not a finite number",
                        path.display(),
                        line_no + 1
                    )));
                }
            }
        }
    }
    if out.is_empty() {
        return Err(Error::invalid(format!("{what}: {} holds no numbers", path.display())));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn initial_specs() {
        assert_eq!("hanging".parse::<InitialSpec>(), Ok(InitialSpec::Hanging));
        assert_eq!("tilted:0.5".parse::<InitialSpec>(), Ok(InitialSpec::Tilted(0.5)));
        assert!("tilted:abc".parse::<InitialSpec>().unwrap_err().contains("abc"));
        assert!("sideways".parse::<InitialSpec>().unwrap_err().contains("sideways"));
    }

    #[test]
    fn a_spinning_3d_start_has_every_azimuthal_rate() {
        let s = initial_state(&InitialSpec::Tilted(0.5), Dimension::Three, 2, 3.0).unwrap();
        assert_eq!((s.coordinates, s.rates), (vec![0.5, 0.5, 0.0, 0.0], vec![0.0, 0.0, 3.0, 3.0]));
    }
}
