//! `cargo xtask bench`: runs the criterion benchmarks of unrolled vs generic models and
//! prints, from that one run, each model's time and the ratio to the generated model.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, Result, bail};

/// The benchmark groups and the implementations each compares.
const GROUPS: [&str; 2] = ["planar_accelerations", "spatial_accelerations"];
const IMPLEMENTATIONS: [&str; 3] = ["generated", "generic_fixed", "generic_dyn"];

/// Runs `cargo bench -p xtask --bench models` (extra `args` go to criterion, e.g. a
/// filter), then prints the summary table.
pub fn run(args: &[String]) -> Result<()> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let status = Command::new(cargo)
        .current_dir(crate::workspace_root())
        .args(["bench", "-p", "xtask", "--bench", "models", "--"])
        .args(args)
        .status()
        .context("running cargo bench")?;
    if !status.success() {
        bail!("cargo bench failed ({status})");
    }
    let table = summary(&criterion_dir())?;
    println!("\n{table}");
    Ok(())
}

/// Where criterion writes its estimates.
fn criterion_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| crate::workspace_root().join("target"))
        .join("criterion")
}

/// Mean time (ns) of one benchmark from criterion's `new/estimates.json`, if it ran.
fn mean_ns(dir: &Path, group: &str, implementation: &str, n: &str) -> Result<Option<f64>> {
    let path = dir.join(group).join(implementation).join(n).join("new").join("estimates.json");
    if !path.exists() {
        return Ok(None);
    }
    let text = std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
    let json: serde_json::Value =
        serde_json::from_str(&text).with_context(|| format!("parsing {}", path.display()))?;
    let mean = json["mean"]["point_estimate"]
        .as_f64()
        .with_context(|| format!("{}: no mean.point_estimate", path.display()))?;
    Ok(Some(mean))
}

/// A markdown table: group, n, mean time of each implementation and its ratio to the
/// generated model.
pub fn summary(dir: &Path) -> Result<String> {
    let mut out = String::from(
        "| model | n | generated | generic fixed | generic Dyn | fixed / generated | Dyn / generated |\n|---|---|---|---|---|---|---|\n",
    );
    let mut rows = 0;
    for group in GROUPS {
        let generated_dir = dir.join(group).join("generated");
        let Ok(entries) = std::fs::read_dir(&generated_dir) else { continue };
        let mut sizes: Vec<usize> =
            entries.filter_map(|e| e.ok()?.file_name().to_str()?.parse().ok()).collect();
        sizes.sort_unstable();
        for n in sizes {
            let n = n.to_string();
            let mut times = [None; 3];
            for (slot, implementation) in times.iter_mut().zip(IMPLEMENTATIONS) {
                *slot = mean_ns(dir, group, implementation, &n)?;
            }
            let show = |t: Option<f64>| t.map_or("–".to_string(), |t| format!("{t:.0} ns"));
            let ratio = |t: Option<f64>| match (t, times[0]) {
                (Some(t), Some(g)) => format!("{:.2}", t / g),
                _ => "–".to_string(),
            };
            let model = group.trim_end_matches("_accelerations");
            out += &format!(
                "| {model} | {n} | {} | {} | {} | {} | {} |\n",
                show(times[0]),
                show(times[1]),
                show(times[2]),
                ratio(times[1]),
                ratio(times[2])
            );
            rows += 1;
        }
    }
    if rows == 0 {
        bail!("no benchmark results under {}", dir.display());
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn summary_reads_criterion_estimates_and_forms_ratios() {
        let dir = std::env::temp_dir().join(format!("xtask-bench-{}", std::process::id()));
        for (implementation, mean) in [("generated", 50.0), ("generic_fixed", 100.0), ("generic_dyn", 200.0)]
        {
            let d = dir.join("planar_accelerations").join(implementation).join("3").join("new");
            std::fs::create_dir_all(&d).unwrap();
            std::fs::write(d.join("estimates.json"), format!(r#"{{"mean":{{"point_estimate":{mean}}}}}"#))
                .unwrap();
        }
        let table = summary(&dir).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
        assert!(table.contains("| planar | 3 | 50 ns | 100 ns | 200 ns | 2.00 | 4.00 |"), "{table}");
    }

    #[test]
    fn no_results_is_an_error() {
        let dir = std::env::temp_dir().join(format!("xtask-bench-empty-{}", std::process::id()));
        assert!(summary(&dir).is_err());
    }
}
