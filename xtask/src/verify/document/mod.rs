//! "The document as printed": a numerical check of the seed document's hand derivation.
//!
//! The seed document ("鎖を振り回したい", 中山大樹, 2018) prints the equations of motion
//! of planar and spatial N-link pendulums. Its equations are *claims*; the truth is the
//! sympy reference in `reference/cases`. They are written down **exactly as printed**
//! (typos included) in `reference/claims/seed.claims`, one claim per checked equation
//! titled `Eq N: …`, with the corrected form `reference/ERRATA.md` gives after
//! `corrected`. This module checks that file as any claims file is checked
//! ([`crate::claims`]: every entry at the random states of `verify`, each claim in
//! isolation, the common slips diagnosed) and turns the outcomes into one row per
//! printed equation.
//!
//! The verdicts are recorded in `reference/ERRATA.md`; [`run`] fails if the measured
//! findings no longer match it, or if a corrected form does not agree.

pub mod errata;
pub mod finding;

use std::fmt::Write as _;
use std::path::PathBuf;

use anyhow::{Context, bail};

use crate::case::Case;
use crate::claims::{Outcome, check_all, corrections, load};
use errata::{differences, errata_path, parse_summary};
use finding::{Finding, Verdict};

/// The seed document's equations as a claims file.
pub fn seed_claims_path() -> PathBuf {
    crate::workspace_root().join("reference").join("claims").join("seed.claims")
}

/// `"Eq 24 S: the n = 3 matrix S"` → `("24 S", "the n = 3 matrix S")`.
fn equation_of(title: &str) -> anyhow::Result<(String, String)> {
    let rest = title.strip_prefix("Eq ").with_context(|| format!("claim {title:?}: a title `Eq N: …`"))?;
    let (equation, claim) =
        rest.split_once(':').with_context(|| format!("claim {title:?}: a title `Eq N: what it claims`"))?;
    Ok((equation.trim().to_string(), claim.trim().to_string()))
}

/// One finding per printed equation (claims of the same equation, e.g. eq 12 planar and
/// spatial, merged), in the file's order, and the claims' outcomes.
pub fn findings(cases: &[Case], states: usize, seed: u64) -> anyhow::Result<(Vec<Finding>, Vec<Outcome>)> {
    let path = seed_claims_path();
    let outcomes = check_all(&path, load(&path)?, cases, states, seed)?;
    let mut found: Vec<Finding> = Vec::new();
    for o in &outcomes {
        let (equation, claim) = equation_of(&o.claim.title)?;
        let next = Finding {
            equation,
            claim,
            verdict: o.verdict(),
            worst: o.worst(),
            first_disagreement: o.first_disagreement().map(String::from),
            corrected: o.corrected(),
            diagnosis: o.diagnosis(),
        };
        let Some(f) = found.iter_mut().find(|f| f.equation == next.equation) else {
            found.push(next);
            continue;
        };
        f.verdict = match (f.verdict, next.verdict) {
            (Verdict::Disagrees, _) | (_, Verdict::Disagrees) => Verdict::Disagrees,
            (Verdict::Untested, Verdict::Untested) => Verdict::Untested,
            _ => Verdict::Agrees,
        };
        f.claim = format!("{}; {}", f.claim, next.claim);
        f.worst = f.worst.max(next.worst);
        f.first_disagreement = f.first_disagreement.take().or(next.first_disagreement);
        if next.diagnosis != "–" {
            f.diagnosis = if f.diagnosis == "–" {
                next.diagnosis
            } else {
                format!("{}; {}", f.diagnosis, next.diagnosis)
            };
        }
        f.corrected = f.corrected.or(next.corrected);
    }
    Ok((found, outcomes))
}

/// The findings as a table.
pub fn render(findings: &[Finding]) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "| equation | what it claims | verdict | worst rel. error | corrected form | first disagreeing entry and state | diagnosis |"
    );
    let _ = writeln!(out, "|---|---|---|---|---|---|---|");
    for f in findings {
        let corrected = match f.corrected {
            Some((verdict, worst)) => format!("{} ({worst:.1e})", verdict.as_str()),
            None => "–".into(),
        };
        let _ = writeln!(
            out,
            "| {} | {} | {} | {:.1e} | {} | {} | {} |",
            f.equation,
            f.claim,
            f.verdict.as_str(),
            f.worst,
            corrected,
            f.first_disagreement.as_deref().unwrap_or("–"),
            f.diagnosis
        );
    }
    out
}

/// Check the document's printed equations at `states` random states per case, print
/// the findings and the corrections the diagnoses give, and fail iff they no longer
/// match `reference/ERRATA.md`. Disagreements with the reference are findings, not
/// failures.
pub fn run(cases: &[Case], states: usize, seed: u64) -> anyhow::Result<()> {
    let (findings, outcomes) = findings(cases, states, seed)?;
    println!(
        "The document as printed ({}, {states} random states per case, seed {seed}):",
        seed_claims_path().strip_prefix(crate::workspace_root()).unwrap_or(&seed_claims_path()).display()
    );
    print!("{}", render(&findings));
    print!("{}", corrections(&outcomes));
    let path = errata_path();
    let text = std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
    let summary = parse_summary(&text).with_context(|| format!("parsing {}", path.display()))?;
    let differences = differences(&findings, &summary);
    if !differences.is_empty() {
        bail!("the document check no longer matches {}:\n  {}", path.display(), differences.join("\n  "));
    }
    let untested: Vec<&str> =
        findings.iter().filter(|f| f.verdict == Verdict::Untested).map(|f| f.equation.as_str()).collect();
    if !untested.is_empty() {
        println!("Untested (none of their cases given): eqs {}.", untested.join(", "));
    }
    println!("The findings match {}.", path.display());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The committed reference, seed.claims and ERRATA.md agree with a short run: the
    /// same 32 equations, verdicts and corrected forms.
    #[test]
    fn findings_match_errata() {
        let cases = crate::case::load_all(&crate::cases_dir()).expect("the committed reference cases load");
        let (findings, _) = findings(&cases, 6, 20181223).expect("seed.claims checks");
        assert_eq!(findings.len(), 32, "{}", render(&findings));
        let untested: Vec<_> =
            findings.iter().filter(|f| f.verdict == Verdict::Untested).map(|f| f.equation.clone()).collect();
        assert!(untested.is_empty(), "the committed cases leave eqs {untested:?} untested");
        let text = std::fs::read_to_string(errata_path()).expect("reference/ERRATA.md exists");
        let summary = parse_summary(&text).expect("the ERRATA summary parses");
        let differences = differences(&findings, &summary);
        assert!(differences.is_empty(), "{}\n{}", render(&findings), differences.join("\n"));
        for f in findings.iter().filter(|f| f.verdict == Verdict::Disagrees) {
            assert!(f.corrected.is_some(), "eq {}: no corrected form in seed.claims", f.equation);
        }
    }

    #[test]
    fn titles_name_their_equation() {
        assert_eq!(equation_of("Eq 24 S: S written out").unwrap(), ("24 S".into(), "S written out".into()));
        assert!(equation_of("Eq 24 S S").is_err() && equation_of("24: x").is_err());
    }
}
