//! Claims files: equations of motion written by hand in index notation
//! (`reference/CLAIMS.md`), checked against the sympy reference with
//! `cargo xtask verify --claims FILE`.
//!
//! [`syntax`] reads a file (every error with its line and column), [`eval`] gives its
//! names their meaning and evaluates an entry at one state, [`check`] compares an entry
//! with the reference at random states of every case it covers, [`diagnose`](mod@diagnose) tries the
//! common slips on a disagreeing entry and prints the corrected entry. (Having sympy prove
//! the agreeing ones exactly, `cargo xtask reference --claims FILE`, is xtask's.)

pub mod check;
pub mod diagnose;
pub mod eval;
mod lex;
mod print;
pub(crate) mod state;
pub mod syntax;

use std::fmt::Write as _;
use std::path::Path;

use anyhow::{Context, bail};

use crate::case::Case;
use check::{Samples, Tally, check_entry, covered};
use diagnose::{Diagnosis, diagnose};
use syntax::{Claim, Entry, parse};

/// A claim's verdict.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    Agrees,
    Disagrees,
    /// None of the cases it covers was given.
    Untested,
}

impl Verdict {
    pub fn as_str(self) -> &'static str {
        match self {
            Verdict::Agrees => "agrees",
            Verdict::Disagrees => "disagrees",
            Verdict::Untested => "untested",
        }
    }
}

/// What checking one entry of a claim found.
pub struct EntryOutcome {
    pub entry: Entry,
    pub tally: Tally,
    pub diagnosis: Option<Diagnosis>,
}

/// What checking one claim found.
pub struct Outcome {
    pub claim: Claim,
    /// The cases it covered, by name.
    pub cases: Vec<String>,
    pub entries: Vec<EntryOutcome>,
    /// The corrected form's entries (no diagnoses), if the claim has one.
    pub corrected: Vec<EntryOutcome>,
}

impl Outcome {
    pub fn verdict(&self) -> Verdict {
        verdict(&self.cases, &self.entries)
    }

    pub fn worst(&self) -> f64 {
        worst(&self.entries)
    }

    /// The corrected form's verdict and worst error, if the claim has one.
    pub fn corrected(&self) -> Option<(Verdict, f64)> {
        (!self.corrected.is_empty()).then(|| (verdict(&self.cases, &self.corrected), worst(&self.corrected)))
    }
}

fn verdict(cases: &[String], entries: &[EntryOutcome]) -> Verdict {
    if cases.is_empty() {
        Verdict::Untested
    } else if entries.iter().all(|e| e.tally.agrees()) {
        Verdict::Agrees
    } else {
        Verdict::Disagrees
    }
}

fn worst(entries: &[EntryOutcome]) -> f64 {
    entries.iter().map(|e| e.tally.worst).fold(0.0, f64::max)
}

/// `file:line:col: found: expected …`, one line per error.
fn located(file: &str, line: usize, col: usize, found: &str, expected: &str, source: &str) -> String {
    let text = source.lines().nth(line.saturating_sub(1)).unwrap_or("");
    format!("{file}:{line}:{col}: found {found}; expected {expected}\n    | {text}")
}

/// Reads and parses a claims file: every syntax error, or the claims.
pub fn load(path: &Path) -> anyhow::Result<Vec<Claim>> {
    let text = std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    parse_named(&text, &path.display().to_string())
}

/// Parses the text of a claims file named `file` (in the errors): every syntax error, or
/// the claims.
pub fn parse_named(text: &str, file: &str) -> anyhow::Result<Vec<Claim>> {
    parse(text).map_err(|errors| {
        let all: Vec<String> =
            errors.iter().map(|e| located(file, e.pos.line, e.pos.col, &e.found, &e.message, text)).collect();
        anyhow::anyhow!(
            "{} error{} in {file}:\n{}",
            all.len(),
            if all.len() == 1 { "" } else { "s" },
            all.join("\n")
        )
    })
}

/// Checks every claim at `states` random states per covered case; a disagreeing entry
/// is diagnosed. Errors (an unknown symbol, an index out of range, …) of every claim are
/// reported together, each with its place in `path`.
pub fn check_all(
    path: &Path,
    claims: Vec<Claim>,
    cases: &[Case],
    states: usize,
    seed: u64,
) -> anyhow::Result<Vec<Outcome>> {
    let source = std::fs::read_to_string(path).unwrap_or_default();
    check_source(&path.display().to_string(), &source, claims, cases, states, seed)
}

/// [`check_all`] of the claims parsed from `source`, the text of the file named `file`.
pub fn check_source(
    file: &str,
    source: &str,
    claims: Vec<Claim>,
    cases: &[Case],
    states: usize,
    seed: u64,
) -> anyhow::Result<Vec<Outcome>> {
    let mut outcomes = Vec::new();
    let mut errors = Vec::new();
    let samples = Samples::new(seed);
    for claim in claims {
        let covering = covered(&claim, cases);
        let mut check = |entries: &[Entry], diagnosed: bool| {
            let mut out = Vec::new();
            for entry in entries {
                match check_entry(entry, &covering, states, &samples) {
                    Ok(tally) => {
                        let diagnosis = (diagnosed && !tally.agrees())
                            .then(|| diagnose(entry, &tally, &covering, &samples))
                            .flatten();
                        out.push(EntryOutcome { entry: entry.clone(), tally, diagnosis });
                    }
                    Err(found) => errors.extend(found.into_iter().map(|(line, col, what, expected)| {
                        located(file, line, col, &what, &expected, source)
                    })),
                }
            }
            out
        };
        let entries = check(&claim.entries, true);
        let corrected = check(&claim.corrected, false);
        let cases = covering.iter().map(|c| c.name.clone()).collect();
        outcomes.push(Outcome { claim, cases, entries, corrected });
    }
    if !errors.is_empty() {
        errors.dedup();
        bail!(
            "{} error{} in {file}:\n{}",
            errors.len(),
            if errors.len() == 1 { "" } else { "s" },
            errors.join("\n")
        );
    }
    Ok(outcomes)
}

/// `planar n = 1..4 (4 cases)`: the chains claimed and the cases there were.
fn cases_text(claim: &Claim, cases: &[String]) -> String {
    let c = &claim.chains;
    let kind = if c.spatial { "spatial" } else { "planar" };
    let range = match c.high {
        Some(h) if h == c.low => format!("n = {h}"),
        Some(h) => format!("n = {}..{h}", c.low),
        None => format!("n ≥ {}", c.low),
    };
    format!("{kind} {range} ({} case{})", cases.len(), if cases.len() == 1 { "" } else { "s" })
}

/// The outcomes as a table, then every diagnosis with its corrected claim.
pub fn render(outcomes: &[Outcome]) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "| claim | cases | verdict | worst rel. error | corrected form | first disagreeing entry and state | diagnosis |"
    );
    let _ = writeln!(out, "|---|---|---|---|---|---|---|");
    for o in outcomes {
        let _ = writeln!(
            out,
            "| {} | {} | {} | {:.1e} | {} | {} | {} |",
            o.claim.title,
            cases_text(&o.claim, &o.cases),
            o.verdict().as_str(),
            o.worst(),
            o.corrected().map_or("–".into(), |(v, w)| format!("{} ({w:.1e})", v.as_str())),
            o.first_disagreement().unwrap_or("–"),
            o.diagnosis()
        );
    }
    out.push_str(&corrections(outcomes));
    out
}

/// Every diagnosis with its corrected entry, as printed after the table.
pub fn corrections(outcomes: &[Outcome]) -> String {
    let mut out = String::new();
    for o in outcomes {
        for e in &o.entries {
            if let Some(d) = &e.diagnosis {
                let _ = writeln!(
                    out,
                    "\n{} (line {}): {}. Corrected:\n{}",
                    o.claim.title,
                    e.entry.pos.line,
                    d.slip,
                    d.corrected.render()
                );
            }
        }
    }
    out
}

impl Outcome {
    /// The first disagreeing entry, with its case and state.
    pub fn first_disagreement(&self) -> Option<&str> {
        self.entries.iter().find_map(|e| e.tally.first.as_deref())
    }

    /// The slips found, or why there are none.
    pub fn diagnosis(&self) -> String {
        let found: Vec<&str> =
            self.entries.iter().filter_map(|e| e.diagnosis.as_ref().map(|d| d.slip.as_str())).collect();
        let undiagnosed =
            self.entries.iter().any(|e| !e.tally.agrees() && e.diagnosis.is_none() && e.tally.count > 0);
        match (found.is_empty(), undiagnosed) {
            (true, false) => "–".to_string(),
            (true, true) => "none of the common slips explains it".to_string(),
            _ => found.join("; "),
        }
    }
}

/// `cargo xtask verify --claims FILE`: checks the file's claims and prints the table;
/// errors only when the file has errors (a disagreeing claim is a finding).
pub fn run(path: &Path, cases: &[Case], states: usize, seed: u64) -> anyhow::Result<Vec<Outcome>> {
    let claims = load(path)?;
    let outcomes = check_all(path, claims, cases, states, seed)?;
    let (count, plural) = (outcomes.len(), if outcomes.len() == 1 { "" } else { "s" });
    println!("{}: {count} claim{plural} ({states} random states per case, seed {seed:#x}):", path.display());
    print!("{}", render(&outcomes));
    Ok(outcomes)
}
