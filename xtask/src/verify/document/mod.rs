//! "The document as printed": a numerical check of the seed document's hand derivation.
//!
//! The seed document ("鎖を振り回したい", 中山大樹, 2018) prints the
//! equations of motion of planar and spatial N-link pendulums. Its equations are
//! *claims*; the truth is the sympy reference in `reference/cases` (positions → T, U →
//! Euler–Lagrange). This module encodes the printed equations **exactly as printed**
//! (typos included) and compares each one, in isolation, with the reference at many
//! random states: every ingredient other than the equation under test is taken from
//! the reference, so each verdict is attributable to that one equation.
//!
//! Reference conventions: `M q̈ + c + k + d = Q`, `c` the velocity terms (exactly
//! quadratic in the rates), `k = ∂U/∂q`. In the document's planar notation (eq 18)
//! `C = M`, `S θ̇² = −c`, `h = k`; in the spatial block form (eq 30)
//! `B [θ̇²; φ̇²] − C [θ̇φ̇] − [g; 0] = −c − k`. The reference's coefficient matrices
//! `S`, `B`, `C` are extracted numerically from `c` (unit rates and polarization).
//!
//! Every compared number carries an absolute round-off scale (the sum of the absolute
//! values of the terms it was computed from): one rule, [`Scaled`], tracked through the
//! printed formula here and through the reference's expressions by
//! [`Case::evaluate_with_scales`]. The relative error of an entry is
//! `|printed − reference| / (scale_printed + scale_reference)`; an equation agrees if
//! its worst relative error over all entries, cases and states is below
//! [`AGREEMENT`](tally::AGREEMENT).
//!
//! The verdicts are recorded in `reference/ERRATA.md` (with the corrected forms, which
//! are checked here too); [`run`] fails if the measured findings no longer match it.
//!
//! The checked equations are listed in [`claims`] and encoded as printed in `planar` and
//! `spatial`, which read the reference through `state`; [`tally`] turns their errors into
//! verdicts, [`errata`] compares those with `reference/ERRATA.md`.

pub mod claims;
pub mod errata;
mod planar;
mod spatial;
pub(crate) mod state;
pub mod tally;

use std::fmt::Write as _;

use anyhow::{Context, bail};
use rand::Rng;

use crate::case::{Case, Kind};
use crate::expr::Scaled;
use claims::{Finding, Verdict};
use errata::{differences, errata_path, parse_summary};
use state::State;
use tally::Recorder;

/// Check every printed equation against the reference `cases` at `states` random
/// states per case (the states of [`crate::sample::state`] for `seed`). Pure: reads nothing but `cases`.
pub fn findings(cases: &[Case], states: usize, seed: u64) -> Vec<Finding> {
    let mut rec = Recorder::new();
    for case in cases {
        let n = case.links;
        for index in 0..states {
            // State `index` is the one `verify` draws ([`crate::sample::state`]); the
            // accelerations for eqs 15–17 are drawn after it from the same generator.
            let (params, point, mut rng) = crate::sample::state_with_rng(seed, case.kind, n, index);
            let qdd: Vec<Scaled> =
                (0..case.dof()).map(|_| Scaled::exact(rng.random_range(-2.0..2.0))).collect();
            let (ev, sc) = case.evaluate_with_scales(&params, &point);
            let st = State { case, index, params, point, ev, sc };
            match case.kind {
                Kind::Planar => planar::check(&mut rec, &st, &qdd),
                Kind::Spatial => spatial::check(&mut rec, &st),
            }
        }
    }
    rec.findings()
}

/// The findings as a table.
pub fn render(findings: &[Finding]) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "| equation | what it claims | verdict | worst rel. error | corrected form | first disagreeing entry and state |"
    );
    let _ = writeln!(out, "|---|---|---|---|---|---|");
    for f in findings {
        let corrected = match f.corrected {
            Some((verdict, worst)) => format!("{} ({worst:.1e})", verdict.as_str()),
            None => "–".into(),
        };
        let _ = writeln!(
            out,
            "| {} | {} | {} | {:.1e} | {} | {} |",
            f.equation,
            f.claim,
            f.verdict.as_str(),
            f.worst,
            corrected,
            f.first_disagreement.as_deref().unwrap_or("–")
        );
    }
    out
}

/// Check the document's printed equations at `states` random states per case, print
/// the findings, and fail iff they no longer match `reference/ERRATA.md`.
/// Disagreements with the reference are findings, not failures.
pub fn run(cases: &[Case], states: usize, seed: u64) -> anyhow::Result<()> {
    let findings = findings(cases, states, seed);
    println!("The document as printed ({states} random states per case, seed {seed}):");
    print!("{}", render(&findings));
    let path = errata_path();
    let text = std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
    let summary = parse_summary(&text).with_context(|| format!("parsing {}", path.display()))?;
    let differences = differences(&findings, &summary);
    if !differences.is_empty() {
        bail!("the document check no longer matches {}:\n  {}", path.display(), differences.join("\n  "));
    }
    let untested: Vec<&str> =
        findings.iter().filter(|f| f.verdict == Verdict::Untested).map(|f| f.equation).collect();
    if !untested.is_empty() {
        println!("Untested (none of their cases given): eqs {}.", untested.join(", "));
    }
    println!("The findings match {}.", path.display());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The committed reference and ERRATA.md agree with a short run.
    #[test]
    fn findings_match_errata() {
        let cases = crate::case::load_all(&crate::cases_dir()).expect("the committed reference cases load");
        let findings = findings(&cases, 6, 20181223);
        let untested: Vec<_> =
            findings.iter().filter(|f| f.verdict == Verdict::Untested).map(|f| f.equation).collect();
        assert!(untested.is_empty(), "the committed cases leave eqs {untested:?} untested");
        let text = std::fs::read_to_string(errata_path()).expect("reference/ERRATA.md exists");
        let summary = parse_summary(&text).expect("the ERRATA summary parses");
        let differences = differences(&findings, &summary);
        assert!(differences.is_empty(), "{}\n{}", render(&findings), differences.join("\n"));
    }
}
