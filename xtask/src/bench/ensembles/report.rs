//! `docs/ensembles-speed.md`: the run, the targets checked, and the times per chain
//! of every row, batch against single, section by section.

use std::fmt::Write;

use super::measured::{Measured, Timing};
use super::rows::{Check, Row, SECTIONS, checks, rows};
use crate::bench::report::{RunInfo, time};

/// A ratio with three significant figures, or `–`.
fn ratio(r: Option<f64>) -> String {
    match r {
        Some(r) if r < 10.0 => format!("{r:.2}×"),
        Some(r) if r < 100.0 => format!("{r:.1}×"),
        Some(r) => format!("{r:.0}×"),
        None => "–".into(),
    }
}

/// `a ÷ b` from the medians, then the fastest samples in brackets.
fn both(a: Option<Timing>, b: Option<Timing>) -> String {
    match (a, b) {
        (Some(a), Some(b)) => {
            format!("{} ({})", ratio(Some(a.median / b.median)), ratio(Some(a.fastest / b.fastest)))
        }
        _ => "–".into(),
    }
}

/// The median's time, or `–`.
fn median(t: Option<Timing>) -> String {
    t.map_or("–".into(), |t| time(t.median))
}

/// The checks as a table: the medians decide.
fn targets(checks: &[Check]) -> String {
    let mut out =
        String::from("| target | row | ratio, medians (fastest samples) | met? |\n|---|---|---|---|\n");
    for c in checks {
        let verdict = match c.met() {
            Some(true) => "**yes**".to_string(),
            Some(false) if c.fastest.is_some_and(|r| r >= c.bound) => {
                "no (yes from the fastest samples)".to_string()
            }
            Some(false) => "no".to_string(),
            None => "not run".to_string(),
        };
        let measured = format!("{} ({})", ratio(c.median), ratio(c.fastest));
        let _ = writeln!(out, "| {} | {} | {measured} | {verdict} |", c.target, c.what);
    }
    out
}

/// One section's rows as a table of times per chain and ratios.
fn times(measured: &Measured, rows: &[&Row]) -> String {
    let mut out = String::from(
        "| | single call | batch, 1 thread | batch, 2 threads | batch ÷ single | 2 threads ÷ 1 | \
         `f32` batch, 1 thread | `f32` ÷ single |\n|---|---|---|---|---|---|---|---|\n",
    );
    let get = |id: &Option<String>| id.as_deref().and_then(|id| measured.get(id));
    for row in rows {
        let (single, batch) = (measured.get(&row.single), measured.get(&row.batch));
        let (two, f32) = (get(&row.two_threads), get(&row.f32));
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {} | {} | {} | {} |",
            row.label,
            median(single),
            median(batch),
            median(two),
            both(single, batch),
            both(batch, two),
            median(f32),
            both(single, f32),
        );
    }
    out
}

/// The whole report of `measured`, run `info`.
pub fn markdown(measured: &Measured, info: &RunInfo) -> String {
    let commit = if info.commit.is_empty() { "unknown" } else { &info.commit };
    let mut out = String::from("# Ensembles: speed from one run\n\n");
    let _ = writeln!(
        out,
        "Written by `{}` (do not edit: run it again) on {} at commit {commit}, in {:.0} s of \
         benchmarking. Machine: {}. Load average (1/5/15 min) before: {}, after: {}. \
         Criterion {}. What each row does, and why the ratios are what they are: \
         [`ensembles.md`](ensembles.md).\n",
        info.command, info.date, info.seconds, info.machine, info.load.0, info.load.1, info.settings
    );
    let _ = writeln!(
        out,
        "Times are per chain (per chain-step for the RK4 and rod midpoint rows): each \
         benchmark's time over the chains (or chain-steps) it declares, criterion's median. \
         Every ratio comes from this one run: the medians', then the fastest samples' in \
         brackets (on a shared machine other jobs only ever add time). A batch ÷ single of \
         3× means the batch does a chain's work in a third of the single call's time. \
         Two threads ÷ one compares the batch's two columns.\n"
    );
    let _ = writeln!(out, "![batch ÷ single-chain call, per chain, one thread](ensembles-speed.svg)\n");
    let _ = writeln!(out, "## The issue's targets in this run\n");
    let checks = checks(measured);
    out += &targets(&checks);
    let missed = checks.iter().filter(|c| c.met() == Some(false)).count();
    let _ = writeln!(
        out,
        "\n{} of {} checks met{}. MuJoCo's figure is the issue's, not measured here.\n",
        checks.iter().filter(|c| c.met() == Some(true)).count(),
        checks.len(),
        if missed == 0 { String::new() } else { format!("; {missed} missed") },
    );
    let rows = rows();
    for (s, title) in SECTIONS.iter().enumerate() {
        let section: Vec<&Row> = rows.iter().filter(|r| r.section == s).collect();
        let _ = writeln!(out, "## {title}\n");
        out += &times(measured, &section);
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_partial_run_reports_what_ran_and_dashes_for_the_rest() {
        let mut m = Measured::default();
        m.insert("generated/planar/single/8", Timing { median: 82.0, fastest: 80.0 });
        m.insert("generated/planar/batch_1_threads/8", Timing { median: 31.0, fastest: 25.0 });
        let info = RunInfo {
            command: "cargo xtask bench --ensembles".into(),
            commit: "abc1234".into(),
            ..RunInfo::default()
        };
        let text = markdown(&m, &info);
        assert!(text.contains("at commit abc1234"), "{text}");
        let line = text.lines().find(|l| l.starts_with("| planar accelerations, n = 8 |")).unwrap();
        assert_eq!(
            line,
            "| planar accelerations, n = 8 | 82.0 ns | 31.0 ns | – | 2.65× (3.20×) | – | – | – |"
        );
        let check = text.lines().find(|l| l.contains("| accelerations, N = 8 |")).unwrap();
        assert!(check.ends_with("| 2.65× (3.20×) | no (yes from the fastest samples) |"), "{check}");
        let summary = format!("0 of {} checks met; 1 missed", checks(&m).len());
        assert!(text.contains(&summary), "{text}");
    }
}
