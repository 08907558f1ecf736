//! Criterion's estimates of one run, read back from its output directory.
//!
//! Criterion writes `<dir>/<group>/<function>/<n>/new/estimates.json` per benchmark;
//! here group is `<kind>_<operation>`, function the implementation, `n` the number of
//! links (`xtask/benches/models.rs`).

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

use anyhow::{Context, Result, bail};

/// Median time per iteration (ns) of every benchmark of one run, by
/// `(group, implementation, n)`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Results {
    medians: BTreeMap<(String, String, usize), f64>,
}

impl Results {
    /// Reads every `<group>/<implementation>/<n>/new/estimates.json` under `dir`.
    /// Errors if there is none, or if one cannot be read or has no median.
    pub fn load(dir: &Path) -> Result<Self> {
        let mut results = Self::default();
        for group in subdirectories(dir)? {
            for implementation in subdirectories(&dir.join(&group))? {
                for size in subdirectories(&dir.join(&group).join(&implementation))? {
                    let Ok(n) = size.parse::<usize>() else { continue };
                    let path =
                        dir.join(&group).join(&implementation).join(&size).join("new").join("estimates.json");
                    if path.exists() {
                        results.insert(&group, &implementation, n, median_ns(&path)?);
                    }
                }
            }
        }
        if results.medians.is_empty() {
            bail!("no criterion estimates under {}", dir.display());
        }
        Ok(results)
    }

    /// Records a median (ns).
    pub fn insert(&mut self, group: &str, implementation: &str, n: usize, median_ns: f64) {
        self.medians.insert((group.to_string(), implementation.to_string(), n), median_ns);
    }

    /// The median (ns) of `implementation` at `n` in `group`, if it ran.
    pub fn get(&self, group: &str, implementation: &str, n: usize) -> Option<f64> {
        self.medians.get(&(group.to_string(), implementation.to_string(), n)).copied()
    }

    /// The implementations that ran in `group`.
    pub fn implementations(&self, group: &str) -> BTreeSet<&str> {
        self.medians.keys().filter(|(g, ..)| g == group).map(|(_, i, _)| i.as_str()).collect()
    }

    /// The sizes `n` that ran in `group`, ascending.
    pub fn sizes(&self, group: &str) -> BTreeSet<usize> {
        self.medians.keys().filter(|(g, ..)| g == group).map(|&(_, _, n)| n).collect()
    }

    /// `(n, median ns)` of `implementation` in `group`, ascending in n.
    pub fn series(&self, group: &str, implementation: &str) -> Vec<(usize, f64)> {
        self.medians
            .iter()
            .filter(|((g, i, _), _)| g == group && i == implementation)
            .map(|(&(_, _, n), &t)| (n, t))
            .collect()
    }

    /// Whether any benchmark of `group` ran.
    pub fn has_group(&self, group: &str) -> bool {
        self.medians.keys().any(|(g, ..)| g == group)
    }

    /// Number of benchmarks.
    pub fn len(&self) -> usize {
        self.medians.len()
    }

    /// Whether no benchmark ran.
    pub fn is_empty(&self) -> bool {
        self.medians.is_empty()
    }
}

/// Names of the subdirectories of `dir` (none if `dir` does not exist), sorted.
fn subdirectories(dir: &Path) -> Result<Vec<String>> {
    if !dir.exists() {
        return Ok(Vec::new());
    }
    let mut names = Vec::new();
    for entry in std::fs::read_dir(dir).with_context(|| format!("listing {}", dir.display()))? {
        let entry = entry.with_context(|| format!("listing {}", dir.display()))?;
        if entry.file_type()?.is_dir()
            && let Some(name) = entry.file_name().to_str()
        {
            names.push(name.to_string());
        }
    }
    names.sort();
    Ok(names)
}

/// The median (ns) in one criterion `estimates.json`.
fn median_ns(path: &Path) -> Result<f64> {
    let text = std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let json: serde_json::Value =
        serde_json::from_str(&text).with_context(|| format!("parsing {}", path.display()))?;
    let median = json["median"]["point_estimate"]
        .as_f64()
        .with_context(|| format!("{}: no median.point_estimate", path.display()))?;
    if !(median.is_finite() && median > 0.0) {
        bail!("{}: median {median} ns is not a positive time", path.display());
    }
    Ok(median)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scratch directory unique to this test and process.
    fn scratch(name: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("xtask-bench-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        dir
    }

    fn write(dir: &Path, group: &str, implementation: &str, n: &str, json: &str) {
        let d = dir.join(group).join(implementation).join(n).join("new");
        std::fs::create_dir_all(&d).unwrap();
        std::fs::write(d.join("estimates.json"), json).unwrap();
    }

    #[test]
    fn reads_medians_by_group_implementation_and_size() {
        let dir = scratch("load");
        let est = |median: f64| {
            format!(r#"{{"mean":{{"point_estimate":1.0}},"median":{{"point_estimate":{median}}}}}"#)
        };
        write(&dir, "planar_accelerations", "generated", "3", &est(50.0));
        write(&dir, "planar_accelerations", "generic_dyn", "3", &est(200.0));
        write(&dir, "planar_accelerations", "generic_dyn", "10", &est(900.0));
        // Criterion's report directory, not a size: ignored.
        std::fs::create_dir_all(dir.join("planar_accelerations").join("generated").join("report")).unwrap();
        let results = Results::load(&dir).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
        assert_eq!(results.len(), 3);
        assert_eq!(results.get("planar_accelerations", "generated", 3), Some(50.0));
        assert_eq!(results.series("planar_accelerations", "generic_dyn"), vec![(3, 200.0), (10, 900.0)]);
        assert_eq!(results.sizes("planar_accelerations").into_iter().collect::<Vec<_>>(), vec![3, 10]);
    }

    #[test]
    fn no_results_and_bad_medians_are_errors() {
        let dir = scratch("empty");
        assert!(Results::load(&dir).unwrap_err().to_string().contains("no criterion estimates"));
        write(&dir, "planar_energy", "generated", "2", r#"{"median":{"point_estimate":-1.0}}"#);
        let err = Results::load(&dir).unwrap_err();
        std::fs::remove_dir_all(&dir).unwrap();
        assert!(format!("{err:#}").contains("median -1 ns"), "{err:#}");
    }
}
