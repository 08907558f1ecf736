//! Parsing of the values a user types: numbers, comma lists, per-link values (a number
//! file is read by the run library's [`read_numbers`]; initial-state specs are its
//! [`InitialSpec`](pendulum_experiment::InitialSpec)).

use std::path::Path;

pub use pendulum_experiment::options::expand;
use pendulum_experiment::read_numbers;

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
        Ok(v) => Err(CliError::invalid(format!("{what}: '{whole}' has a non-finite entry {v}"))),
        Err(_) => {
            Err(CliError::invalid(format!("{what}: '{whole}' has a bad entry '{token}' (not a number)")))
        }
    }
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
    Err(CliError::invalid(format!("{what}: '{spec}' is neither a number, a comma list nor an existing file")))
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
}
