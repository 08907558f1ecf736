//! `cargo xtask verify`: the models against the sympy reference at many random states.
//!
//! For every reference case and every seeded random state ([`crate::sample`]) the
//! reference's equations are evaluated (`reference`) and compared, entry by entry
//! ([`compare`]), with the generic model (`Planar<Dyn>`/`Spatial<Dyn>`) and the generated
//! fixed-N model of that size ([`models`]): mass matrix, velocity, gravity and pivot terms,
//! generalized forces, kinetic and potential energy, and accelerations. The worst error
//! per case, quantity and model ([`dense`]) is printed as a table ([`report`]); any error
//! above [`BOUND`] ([`bounds`]) fails the run, naming the case, state, quantity and entry.
//! The O(n) routes (accelerations only) follow in their own table ([`routes`]), then the
//! seed document's printed equations ([`document`]). (`--claims FILE` is not this run:
//! `main` hands it to [`crate::claims`].)
//!
//! This module is the run itself: the options and the order of the sections. The others
//! import downwards only: `bounds` ← `reference` ← `compare` ← `report` ← `dense`, and
//! `routes` on `bounds`, `reference` and `models`; `document` stands on its own.

pub mod bounds;
pub mod compare;
pub mod dense;
pub mod document;
#[cfg(test)]
mod fixtures;
pub mod models;
mod reference;
pub mod report;
mod route_jacobians;
pub mod routes;

use std::time::Instant;

use anyhow::{Result, bail};

use crate::case::{Case, load_all};
use bounds::BOUND;
use report::Report;

pub use crate::sample::{DEFAULT_SEED, DEFAULT_STATES};

/// Parses `--states`: a positive count.
fn at_least_one(text: &str) -> Result<usize, String> {
    match text.parse::<usize>() {
        Ok(0) => Err("must be at least 1: a verify of no states would prove nothing".into()),
        Ok(n) => Ok(n),
        Err(e) => Err(format!("{e}")),
    }
}

/// Options of `cargo xtask verify`.
#[derive(Debug, Clone, clap::Args)]
pub struct Options {
    /// Random states per case (at least 1: a verify of no states would prove nothing).
    #[arg(long, default_value_t = DEFAULT_STATES, value_parser = at_least_one)]
    pub states: usize,
    /// Seed of the random states; state k of a case depends only on the seed and k.
    #[arg(long, default_value_t = DEFAULT_SEED)]
    pub seed: u64,
    /// Only the cases whose name contains FILTER (e.g. `spatial`, `planar_n3`).
    #[arg(long = "case", value_name = "FILTER")]
    pub case: Option<String>,
    /// Check the claims of this file (`reference/CLAIMS.md`) against the reference
    /// instead: a table of verdicts, the first disagreeing entry, and a diagnosis with the
    /// corrected claim where a common slip explains the difference.
    #[arg(long, value_name = "FILE")]
    pub claims: Option<std::path::PathBuf>,
}

impl Default for Options {
    fn default() -> Self {
        Self { states: DEFAULT_STATES, seed: DEFAULT_SEED, case: None, claims: None }
    }
}

/// Loads the committed reference cases (those whose name contains `filter`, if given)
/// and verifies them: what `cargo xtask verify` and the `fast_verify` test run.
pub fn verify_all(states: usize, seed: u64, filter: Option<&str>) -> Result<(Vec<Case>, Report)> {
    let mut cases = load_all(&crate::cases_dir())?;
    if let Some(filter) = filter {
        cases.retain(|c| c.name.contains(filter));
        if cases.is_empty() {
            bail!("no reference case name contains {filter:?}");
        }
    }
    let report = dense::verify_cases(&cases, states, seed)?;
    Ok((cases, report))
}

/// `cargo xtask verify`: prints the table and the document section; errors on any
/// failure, describing the worst.
pub fn run(options: &Options) -> Result<()> {
    let start = Instant::now();
    let (cases, report) = verify_all(options.states, options.seed, options.case.as_deref())?;
    println!(
        "verify: {} reference cases x {} random states (seed {:#x}); bound {BOUND:e} on the error \
         relative to each entry's absolute scale, componentwise backward error for accelerations",
        cases.len(),
        options.states,
        options.seed
    );
    println!();
    print!("{}", report.table());
    let failures = report.failures();
    for failure in &failures {
        println!("\nFAIL {failure}");
    }
    for s in &report.singularities {
        for (implementation, result) in s.reported.iter() {
            if let Err(message) = result {
                println!("\nFAIL {} {implementation}: spatial singularity: {message}", s.case);
            }
        }
    }
    println!("\nmodels checked in {:.2} s", start.elapsed().as_secs_f64());

    // The O(n) routes (tension solve), accelerations only, at the same states.
    println!();
    let routes =
        routes::verify_cases(&cases, options.states, options.seed).and_then(|rows| routes::report(&rows));

    // The seed document's printed equations against the reference: prints its own
    // table, errors when reference/ERRATA.md no longer matches what it finds.
    println!();
    let document = document::run(&cases, options.states, options.seed);

    if let Some(worst) = failures.first() {
        bail!(
            "verify failed: {} of {} comparisons above {BOUND:e}; the worst:\n{worst}",
            failures.len(),
            report.rows.len() * 2
        );
    }
    if !report.ok() {
        bail!("verify failed: a spatial model did not report the singularity at theta_1 = 0 or pi");
    }
    routes?;
    document
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The project's main check on the committed reference, at fewer states.
    #[test]
    fn fast_verify() {
        let (cases, report) = verify_all(20, DEFAULT_SEED, None).unwrap();
        let names: Vec<&str> = cases.iter().map(|c| c.name.as_str()).collect();
        let expected: Vec<String> =
            (1..=8).map(|n| format!("planar_n{n}")).chain((1..=5).map(|n| format!("spatial_n{n}"))).collect();
        assert_eq!(names, expected, "the committed reference cases");
        // Every case has its generated model: a case without one would pass unnoticed.
        for row in &report.rows {
            assert!(row.worst.generated.is_some(), "{}: no generated model in models.rs", row.case);
        }
        for s in &report.singularities {
            assert!(s.reported.generated.is_some(), "{}: no generated model in models.rs", s.case);
        }
        let failures = report.failures();
        assert!(
            report.ok(),
            "\n{}\n{}",
            report.table(),
            failures.iter().map(|f| f.to_string() + "\n").collect::<String>()
        );
    }
}
