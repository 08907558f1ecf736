//! `pendulum steady`: the chain turning steadily about the vertical. The branches of
//! steady shapes up to exactly `--omega-max` (`branches`), every shape at the speeds of
//! `--omega` with its node count and stability (`pendulum_experiment::steady::shapes_at`), printed (`table`), written as
//! branches.csv and shapes.csv (`csv`) and drawn as branches.png and shapes.png (`plots`).
//!
//! Node count: `1 + ` the sign changes of `x_1 … x_n` ([`pendulum_core::SteadyShape::nodes`]:
//! the axis crossings plus the pivot, the seed's convention); the vertical itself (on the
//! axis, no crossing to count) is given none. Stability: [`pendulum_core::Verdict`] of the
//! undamped 3D linearisation in the turning frame ([`pendulum_core::stability`]); damped,
//! see [`pendulum_experiment::steady::damped_verdict`]. The branches and verdicts themselves are the run library's
//! ([`pendulum_experiment::steady`]), shared with the Python package.

pub(crate) mod branches;
mod continuum;
mod csv;
pub(crate) mod plots;
mod table;

use pendulum_core::SteadyRotation;

use crate::args::SteadyArgs;
use crate::chain_args::{self, chain_of};
use crate::error::{CliError, CliResult};
use crate::spec::{expand, per_link};

/// Runs `pendulum steady`.
pub fn steady(args: &SteadyArgs) -> CliResult<()> {
    let chain = chain_of(&args.chain)?;
    if args.continuum {
        return continuum::run(args, &chain);
    }
    let n = chain.links();
    let problem = SteadyRotation::new(&chain, args.radius)?;
    let listed = args.omega.as_deref().map(parse_speeds).transpose()?;
    let damping = match &args.damping {
        Some(spec) => {
            let d = expand("--damping", per_link("--damping", spec)?, n)?;
            pendulum_experiment::options::damped(&chain, &d)?;
            d.iter().any(|&v| v > 0.0).then_some(d)
        }
        None => None,
    };
    let free = SteadyRotation::new(&chain, 0.0)?;
    let omega_max =
        requested_omega_max(&free, args.radius, listed.as_deref(), args.omega_max, args.branches)?;
    let (family, cut) = branches::follow(&problem, &free, omega_max, args.branches)?;
    if let Some((judged, total)) = cut {
        create_out(args)?;
        csv::branches(&args.out.join("branches.csv"), &family, n)?;
        return Err(CliError::interrupted(format!(
            "interrupted while judging the steady shapes: {judged} of {total} judged; {} holds \
             each branch up to its last judged point",
            args.out.join("branches.csv").display()
        )));
    }
    let speeds = listed.unwrap_or_else(|| vec![omega_max]);
    let found =
        pendulum_experiment::steady::shapes_at(&problem, &chain, &family, &speeds, damping.as_deref())?;

    create_out(args)?;
    let pivot = if args.radius == 0.0 {
        "pivot fixed".to_string()
    } else {
        format!("pivot on a circle of radius {} m", args.radius)
    };
    println!("steady rotation of {}; {pivot}", chain_args::header(&chain, damping.as_deref()));
    csv::branches(&args.out.join("branches.csv"), &family, n)?;
    csv::shapes(&args.out.join("shapes.csv"), &found, n, damping.is_some())?;
    table::branches(&family, &problem, omega_max);
    table::shapes(&found, args.radius, damping.is_some());
    plots::branches(&args.out.join("branches.png"), &family, &found, omega_max, args.radius)?;
    plots::shapes(&args.out.join("shapes.png"), &chain, args.radius, &found, &speeds)?;
    let count = family.branches.len();
    eprintln!(
        "pendulum: {count} branch{} up to ω = {omega_max} rad/s, {} shape{} at {} speed{}; files in {} \
         (branches.csv, shapes.csv, branches.png, shapes.png)",
        if count == 1 { "" } else { "es" },
        found.len(),
        if found.len() == 1 { "" } else { "s" },
        speeds.len(),
        if speeds.len() == 1 { "" } else { "s" },
        args.out.display()
    );
    Ok(())
}

/// Creates `--out`.
fn create_out(args: &SteadyArgs) -> CliResult<()> {
    crate::args::create_out(&args.out)
}

/// Parses `--omega`: a comma list of finite, non-negative speeds (rad/s), at least one,
/// no empty entry. Errors name the list and the entry.
pub(crate) fn parse_speeds(list: &str) -> CliResult<Vec<f64>> {
    let tokens: Vec<&str> = list.split(',').map(str::trim).collect();
    if tokens.iter().all(|t| t.is_empty()) {
        return Err(CliError::invalid(format!(
            "--omega: '{list}' lists no speed (give one or more in rad/s, e.g. --omega 5,10)"
        )));
    }
    tokens
        .iter()
        .map(|&token| {
            let bad = |why: &str| CliError::invalid(format!("--omega: '{list}' has {why}"));
            if token.is_empty() {
                return Err(bad("an empty entry"));
            }
            match token.parse::<f64>() {
                Ok(v) if !v.is_finite() => Err(bad(&format!("a non-finite entry {token}"))),
                Ok(v) if v < 0.0 => Err(bad(&format!("a negative entry {token} (speeds are ≥ 0 rad/s)"))),
                Ok(v) => Ok(v),
                Err(_) => Err(bad(&format!("a bad entry '{token}' (not a number)"))),
            }
        })
        .collect()
}

/// A rate (1/s) to three significant digits, in exponent form below 1e-3 and from 1e4 on.
fn rate(g: f64) -> String {
    let magnitude = g.abs();
    if (1e-3..1e4).contains(&magnitude) {
        let decimals = (2 - magnitude.log10().floor() as i32).max(0) as usize;
        format!("{g:.decimals$}")
    } else {
        format!("{g:.2e}")
    }
}

pub use pendulum_experiment::steady::{
    DEFAULT_MARGIN, Judged, check_omega_max, nodes_name, requested_omega_max, round_up,
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_numbers() {
        assert_eq!(round_up(15.22677880957823), 15.3);
        assert_eq!(round_up(15.3), 15.3);
        assert_eq!(round_up(0.012341), 0.0124);
        assert_eq!(round_up(1234.5), 1240.0);
        assert_eq!(rate(3.714), "3.71");
        assert_eq!(rate(-0.0196), "-0.0196");
        assert_eq!(rate(2.5e-9), "2.50e-9");
    }

    #[test]
    fn speed_lists() {
        assert_eq!(parse_speeds("5, 10,15").unwrap(), vec![5.0, 10.0, 15.0]);
        assert_eq!(parse_speeds("0").unwrap(), vec![0.0]);
        let message = |s: &str| parse_speeds(s).unwrap_err().to_string();
        assert_eq!(message(""), "--omega: '' lists no speed (give one or more in rad/s, e.g. --omega 5,10)");
        assert_eq!(
            message(","),
            "--omega: ',' lists no speed (give one or more in rad/s, e.g. --omega 5,10)"
        );
        assert_eq!(message("5,,6"), "--omega: '5,,6' has an empty entry");
        assert_eq!(message("5,inf"), "--omega: '5,inf' has a non-finite entry inf");
        assert_eq!(message("NaN"), "--omega: 'NaN' has a non-finite entry NaN");
        assert_eq!(message("-2"), "--omega: '-2' has a negative entry -2 (speeds are ≥ 0 rad/s)");
        assert_eq!(message("3,x"), "--omega: '3,x' has a bad entry 'x' (not a number)");
    }
}
