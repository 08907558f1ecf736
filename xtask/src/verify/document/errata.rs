//! `reference/ERRATA.md`: where it is, its summary table, and how the measured findings
//! differ from it.

use std::path::PathBuf;

use anyhow::bail;

use super::finding::{Finding, Verdict};

/// Where the errata (and the machine-readable summary table) live.
pub fn errata_path() -> PathBuf {
    crate::workspace_root().join("reference").join("ERRATA.md")
}

/// The rows of the summary table of ERRATA.md: the first table whose header is
/// `| equation | verdict |`.
pub fn parse_summary(text: &str) -> anyhow::Result<Vec<(String, String)>> {
    let cells = |line: &str| -> Option<Vec<String>> {
        let line = line.trim();
        let inner = line.strip_prefix('|')?.strip_suffix('|')?;
        Some(inner.split('|').map(|c| c.trim().to_string()).collect())
    };
    let mut lines = text.lines();
    loop {
        let Some(line) = lines.next() else { bail!("no summary table with header `| equation | verdict |`") };
        if cells(line).is_some_and(|c| c == ["equation", "verdict"]) {
            break;
        }
    }
    match lines.next().and_then(cells) {
        Some(sep)
            if sep.len() == 2
                && sep.iter().all(|c| !c.is_empty() && c.chars().all(|ch| "-: ".contains(ch))) => {}
        _ => bail!("the summary table header is not followed by a `|---|---|` separator"),
    }
    let mut rows = Vec::new();
    for line in lines {
        let Some(row) = cells(line) else { break };
        let [equation, verdict] = <[String; 2]>::try_from(row)
            .map_err(|row| anyhow::anyhow!("summary row {line:?} has {} cells, expected 2", row.len()))?;
        rows.push((equation, verdict));
    }
    Ok(rows)
}

/// How the measured findings differ from the summary rows (empty: they match), and
/// corrected forms that do not agree. An untested equation (none of its cases given,
/// e.g. under `verify --case`) is no difference, but must still have its row.
pub fn differences(findings: &[Finding], summary: &[(String, String)]) -> Vec<String> {
    let mut out = Vec::new();
    for (k, (equation, _)) in summary.iter().enumerate() {
        if summary[..k].iter().any(|(e, _)| e == equation) {
            out.push(format!("eq {equation}: listed more than once in the ERRATA summary"));
        }
        if !findings.iter().any(|f| &f.equation == equation) {
            out.push(format!("eq {equation}: in the ERRATA summary but not a checked equation"));
        }
    }
    for f in findings {
        match summary.iter().find(|(e, _)| *e == f.equation) {
            None => out.push(format!(
                "eq {}: measured {} but missing from the ERRATA summary",
                f.equation,
                f.verdict.as_str()
            )),
            Some((_, recorded)) if f.verdict != Verdict::Untested && recorded != f.verdict.as_str() => out
                .push(format!(
                    "eq {}: ERRATA says {recorded}, measured {} (worst relative error {:.1e}{})",
                    f.equation,
                    f.verdict.as_str(),
                    f.worst,
                    f.first_disagreement.as_deref().map(|d| format!("; first: {d}")).unwrap_or_default()
                )),
            Some(_) => {}
        }
        if let Some((verdict, worst)) = f.corrected
            && verdict != Verdict::Agrees
        {
            out.push(format!(
                "eq {}: the corrected form in ERRATA {} (worst relative error {worst:.1e})",
                f.equation,
                verdict.as_str()
            ));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn summary_parsing_and_differences() {
        let text = "# x\n\n| equation | verdict |\n|---|---|\n| 22 | agrees |\n| 23 | agrees |\n| 99 | agrees |\n\nmore\n";
        let rows = parse_summary(text).unwrap();
        assert_eq!(rows.len(), 3);
        let finding = |equation: &str, verdict| Finding {
            equation: equation.into(),
            claim: String::new(),
            verdict,
            worst: 0.0,
            first_disagreement: None,
            corrected: None,
            diagnosis: String::new(),
        };
        let found = [
            finding("22", Verdict::Agrees),
            finding("23", Verdict::Disagrees),
            finding("24 C", Verdict::Agrees),
        ];
        let diffs = differences(&found, &rows);
        assert_eq!(diffs.len(), 3, "{diffs:#?}");
        assert!(diffs.iter().any(|d| d.starts_with("eq 23: ERRATA says agrees")));
        assert!(diffs.iter().any(|d| d.starts_with("eq 99:")));
        assert!(diffs.iter().any(|d| d.starts_with("eq 24 C:")));
        assert!(parse_summary("| equation | verdict |\n| 22 | agrees |\n").is_err());
        assert!(parse_summary("nothing here").is_err());
    }
}
