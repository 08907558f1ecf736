//! Parsing of the values a user types: numbers, comma lists, number files, initial-state
//! specs.

use std::path::Path;

use crate::error::{CliError, CliResult};

/// Parses `s` as a comma-separated list of finite numbers (`"1"`, `"1,2.5,3"`).
///
/// Errors name the bad entry: `"masses: '1,x' has a bad entry 'x' (not a number)"`.
pub fn parse_list(what: &str, s: &str) -> CliResult<Vec<f64>> {
    let mut out = Vec::new();
    for token in s.split(',') {
        out.push(parse_number(what, s, token)?);
    }
    Ok(out)
}

fn parse_number(what: &str, whole: &str, token: &str) -> CliResult<f64> {
    let token = token.trim();
    match token.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(v) => Err(CliError::usage(format!("{what}: '{whole}' has a non-finite entry {v}"))),
        Err(_) => Err(CliError::usage(format!("{what}: '{whole}' has a bad entry '{token}' (not a number)"))),
    }
}

/// Reads every number in a text file: separated by whitespace or commas, `#` starts a
/// comment that runs to the end of the line.
pub fn read_numbers(what: &str, path: &Path) -> CliResult<Vec<f64>> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| CliError::usage(format!("{what}: cannot read {}: {e}", path.display())))?;
    let mut out = Vec::new();
    for (line_no, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("");
        for token in line.split(|c: char| c.is_whitespace() || c == ',').filter(|t| !t.is_empty()) {
            match token.parse::<f64>() {
                Ok(v) if v.is_finite() => out.push(v),
                _ => {
                    return Err(CliError::usage(format!(
                        "{what}: {} line {}: '{token}' is not a finite number",
                        path.display(),
                        line_no + 1
                    )));
                }
            }
        }
    }
    if out.is_empty() {
        return Err(CliError::usage(format!("{what}: {} holds no numbers", path.display())));
    }
    Ok(out)
}

/// A per-link value as given: one number for every link, a comma list, or a file.
///
/// `"0.5"` (uniform), `"1,2,3"` (one per link), or the path of a text file of numbers
/// ([`read_numbers`]); a spec that is not a number list is taken as a path.
pub fn per_link(what: &str, spec: &str) -> CliResult<Vec<f64>> {
    let looks_numeric = spec.split(',').all(|t| t.trim().parse::<f64>().is_ok());
    if looks_numeric {
        return parse_list(what, spec);
    }
    let path = Path::new(spec);
    if path.exists() {
        return read_numbers(what, path);
    }
    if spec.contains(',') || spec.chars().next().is_some_and(|c| c.is_ascii_digit() || c == '-' || c == '.') {
        // Looks like an attempt at a list: report the bad entry, not a missing file.
        return parse_list(what, spec);
    }
    Err(CliError::usage(format!("{what}: '{spec}' is neither a number, a comma list nor an existing file")))
}

/// Expands a per-link list to `n` entries: a single value is repeated, otherwise the
/// list must have exactly `n` entries.
pub fn expand(what: &str, values: Vec<f64>, n: usize) -> CliResult<Vec<f64>> {
    match values.len() {
        1 => Ok(vec![values[0]; n]),
        len if len == n => Ok(values),
        len => Err(CliError::usage(format!("{what}: got {len} values for {n} links (give 1 or {n})"))),
    }
}

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
    fn from_str(s: &str) -> Result<Self, String> {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lists_and_uniform_values() {
        assert_eq!(per_link("masses", "2").unwrap(), vec![2.0]);
        assert_eq!(per_link("masses", "1, 2,3").unwrap(), vec![1.0, 2.0, 3.0]);
        assert_eq!(expand("masses", vec![2.0], 3).unwrap(), vec![2.0; 3]);
        let err = expand("masses", vec![1.0, 2.0], 3).unwrap_err();
        assert_eq!(err.to_string(), "masses: got 2 values for 3 links (give 1 or 3)");
        let err = per_link("lengths", "1,x").unwrap_err();
        assert_eq!(err.to_string(), "lengths: '1,x' has a bad entry 'x' (not a number)");
        let err = per_link("lengths", "nofile").unwrap_err();
        assert!(err.to_string().contains("neither a number"), "{err}");
        assert!(per_link("lengths", "1,inf").is_err());
    }

    #[test]
    fn initial_specs() {
        assert_eq!("hanging".parse::<InitialSpec>(), Ok(InitialSpec::Hanging));
        assert_eq!("tilted:0.5".parse::<InitialSpec>(), Ok(InitialSpec::Tilted(0.5)));
        assert!("tilted:abc".parse::<InitialSpec>().unwrap_err().contains("abc"));
        assert!("sideways".parse::<InitialSpec>().unwrap_err().contains("sideways"));
    }
}
