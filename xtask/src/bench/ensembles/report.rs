//! `docs/ensembles-speed.md`: the runs, the targets checked in each, and the times
//! per chain of every row, batch against single, section by section.

use std::fmt::Write;

use super::measured::Measured;
use super::rows::{Check, Row, SECTIONS, checks, rows};
use crate::bench::report::{RunInfo, time};

/// A ratio as the models' report writes it, with its `×`.
fn ratio(r: f64) -> String {
    format!("{}×", crate::bench::report::ratio(r))
}

/// The middle of `values` (the mean of the two middle ones for an even count), if any.
pub(super) fn middle(values: &[f64]) -> Option<f64> {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    match v.len() {
        0 => None,
        n if n % 2 == 1 => Some(v[n / 2]),
        n => Some(0.5 * (v[n / 2 - 1] + v[n / 2])),
    }
}

/// The smallest and the largest of `values`, if any.
pub(super) fn range(values: &[f64]) -> Option<(f64, f64)> {
    let low = values.iter().copied().reduce(f64::min)?;
    Some((low, values.iter().copied().fold(low, f64::max)))
}

/// `values` as one figure, or as their range `a–b` over the runs (`–` for none).
fn spread(values: &[f64], show: fn(f64) -> String) -> String {
    match range(values) {
        None => "–".into(),
        Some((low, high)) if show(low) == show(high) => show(low),
        Some((low, high)) => format!("{}–{}", show(low).trim_end_matches('×'), show(high)),
    }
}

/// Each run's ratio `a ÷ b` of the medians, where both ran (ids `None`: none).
pub(super) fn ratios(runs: &[&Measured], a: &str, b: Option<&str>) -> Vec<f64> {
    runs.iter().filter_map(|m| Some(m.get(a)?.median / m.get(b?)?.median)).collect()
}

/// The middle over the runs of benchmark `id`'s median, as a time.
fn typical(runs: &[&Measured], id: Option<&str>) -> String {
    let times: Vec<f64> = runs.iter().filter_map(|m| Some(m.get(id?)?.median)).collect();
    middle(&times).map_or("–".into(), time)
}

/// The checks of every run (`checks[r]` run `r`'s, in the same order) as a table.
fn targets(checks: &[Vec<Check>]) -> String {
    let mut out = String::from(
        "| target | row | ratio in each run (medians) | fastest samples | met? |\n|---|---|---|---|---|\n",
    );
    for (k, first) in checks[0].iter().enumerate() {
        let each: Vec<&Check> = checks.iter().map(|run| &run[k]).collect();
        let medians: Vec<f64> = each.iter().filter_map(|c| c.median).collect();
        let fastest: Vec<f64> = each.iter().filter_map(|c| c.fastest).collect();
        let met = each.iter().filter(|c| c.met() == Some(true)).count();
        let verdict = match (medians.len(), met) {
            (0, _) => "not run".to_string(),
            (1, 1) => "**yes**".to_string(),
            (1, 0) => "no".to_string(),
            (n, m) if m == n => format!("**yes**, in all {n} runs"),
            (n, 0) => format!("no, in none of {n} runs"),
            (n, m) => format!("in {m} of {n} runs"),
        };
        let each = medians.iter().map(|&r| ratio(r)).collect::<Vec<_>>().join(", ");
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {verdict} |",
            first.target,
            first.what,
            if each.is_empty() { "–".into() } else { each },
            spread(&fastest, ratio),
        );
    }
    out
}

/// One section's rows as a table of times per chain and ratios.
fn times(runs: &[&Measured], rows: &[&Row]) -> String {
    let mut out = String::from(
        "| | single call | batch, 1 thread | batch, 2 threads | batch ÷ single | 2 threads ÷ 1 | \
         `f32` batch, 1 thread | `f32` ÷ single |\n|---|---|---|---|---|---|---|---|\n",
    );
    for row in rows {
        let (single, batch) = (row.single.as_str(), row.batch.as_str());
        let (two, f32) = (row.two_threads.as_deref(), row.f32.as_deref());
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {} | {} | {} | {} |",
            row.label,
            typical(runs, Some(single)),
            typical(runs, Some(batch)),
            typical(runs, two),
            spread(&ratios(runs, single, Some(batch)), ratio),
            spread(&ratios(runs, batch, two), ratio),
            typical(runs, f32),
            spread(&ratios(runs, single, f32), ratio),
        );
    }
    out
}

/// The whole report of `runs` (each run's facts and benchmarks; at least one).
pub fn markdown(runs: &[(RunInfo, Measured)]) -> String {
    let measured: Vec<&Measured> = runs.iter().map(|(_, m)| m).collect();
    let first = &runs[0].0;
    let commit = if first.commit.is_empty() { "unknown" } else { &first.commit };
    let mut out = String::from("# Ensembles: speed, batch against single chain\n\n");
    let _ = writeln!(
        out,
        "Written by `{}` (do not edit: run it again) at commit {commit}. Machine: {}. \
         Criterion {}. What each row does, and why the ratios are what they are: \
         [`ensembles.md`](ensembles.md).\n",
        first.command, first.machine, first.settings
    );
    if runs.len() > 1 {
        let _ = writeln!(
            out,
            "{} runs of the whole benchmark, one after another; a ratio is always taken within \
             one run, and the tables give each run's (or their range), and each benchmark's \
             time the middle over the runs:\n",
            runs.len()
        );
    }
    for (k, (info, _)) in runs.iter().enumerate() {
        let _ = writeln!(
            out,
            "- run {}: {}, {:.0} s of benchmarking, load average (1/5/15 min) before {}, after {};",
            k + 1,
            info.date,
            info.seconds,
            info.load.0,
            info.load.1
        );
    }
    let _ = writeln!(
        out,
        "\nTimes are per chain (per chain-step for the RK4 and rod midpoint rows): each \
         benchmark's median over the chains (or chain-steps) it declares. A batch ÷ single of \
         3× means the batch does a chain's work in a third of the single call's time; two \
         threads ÷ one compares the batch's two columns. On a shared machine other jobs only \
         ever add time, and they come and go within a run: the same binary's ratios move by \
         10–20% from run to run here.\n"
    );
    let _ = writeln!(out, "![batch ÷ single-chain call, per chain, one thread](ensembles-speed.svg)\n");
    let _ = writeln!(out, "## The issue's targets\n");
    let checks: Vec<Vec<Check>> = measured.iter().map(|m| checks(m)).collect();
    out += &targets(&checks);
    let always =
        (0..checks[0].len()).filter(|&k| checks.iter().all(|run| run[k].met() == Some(true))).count();
    let never =
        (0..checks[0].len()).filter(|&k| checks.iter().all(|run| run[k].met() == Some(false))).count();
    let _ = writeln!(
        out,
        "\nOf {} checks, {always} met in every run, {never} in none, {} in some. MuJoCo's \
         figure is the issue's, not measured here.\n",
        checks[0].len(),
        checks[0].len() - always - never,
    );
    let rows = rows();
    for (s, title) in SECTIONS.iter().enumerate() {
        let section: Vec<&Row> = rows.iter().filter(|r| r.section == s).collect();
        let _ = writeln!(out, "## {title}\n");
        out += &times(&measured, &section);
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::measured::Timing;
    use super::*;

    fn run(single: f64, batch: f64) -> (RunInfo, Measured) {
        let mut m = Measured::default();
        m.insert("generated/planar/single/8", Timing { median: single, fastest: single });
        m.insert("generated/planar/batch_1_threads/8", Timing { median: batch, fastest: batch / 1.2 });
        let info = RunInfo {
            command: "cargo xtask bench --ensembles".into(),
            commit: "abc1234".into(),
            ..RunInfo::default()
        };
        (info, m)
    }

    #[test]
    fn one_run_reports_what_ran_and_dashes_for_the_rest() {
        let text = markdown(&[run(82.0, 31.0)]);
        assert!(text.contains("at commit abc1234"), "{text}");
        let line = text.lines().find(|l| l.starts_with("| planar accelerations, n = 8 |")).unwrap();
        assert_eq!(line, "| planar accelerations, n = 8 | 82.0 ns | 31.0 ns | – | 2.65× | – | – | – |");
        let check = text.lines().find(|l| l.contains("| accelerations, N = 8 |")).unwrap();
        assert!(check.ends_with("| 2.65× | 3.17× | no |"), "{check}");
        assert!(text.contains("0 met in every run, 1 in none,"), "{text}");
    }

    #[test]
    fn runs_give_each_ratio_their_range_and_the_middle_time() {
        let text = markdown(&[run(82.0, 31.0), run(90.0, 28.0), run(80.0, 25.0)]);
        let line = text.lines().find(|l| l.starts_with("| planar accelerations, n = 8 |")).unwrap();
        // Times: the middle of 82, 90, 80 and of 31, 28, 25; ratios 2.65, 3.21, 3.20.
        assert_eq!(line, "| planar accelerations, n = 8 | 82.0 ns | 28.0 ns | – | 2.65–3.21× | – | – | – |");
        let check = text.lines().find(|l| l.contains("| accelerations, N = 8 |")).unwrap();
        assert!(check.ends_with("| 2.65×, 3.21×, 3.20× | 3.17–3.86× | in 2 of 3 runs |"), "{check}");
        assert!(text.contains("3 runs of the whole benchmark"), "{text}");
        assert_eq!(middle(&[3.0, 1.0, 2.0, 10.0]), Some(2.5));
    }
}
