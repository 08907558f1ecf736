//! Criterion's estimates of one run, read back from its output directory.
//!
//! Criterion writes `<dir>/<group>/<function>/<n>/new/{estimates,sample}.json` per
//! benchmark; here group is `<kind>_<operation>`, function the implementation, `n` the
//! number of links (`pendulum-core/benches/models.rs`).

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

use anyhow::{Context, Result, bail};

/// Which statistic of a benchmark's samples [`Results`] holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Statistic {
    /// Criterion's median time per iteration (`estimates.json`).
    Median,
    /// The fastest sample's time per iteration (`sample.json`): on a machine shared with
    /// other jobs, preemption only ever adds time, so this is the least disturbed figure.
    Fastest,
}

/// One statistic (ns per iteration) of every benchmark of one run, by
/// `(group, implementation, n)`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Results {
    times: BTreeMap<(String, String, usize), f64>,
}

impl Results {
    /// Reads `statistic` of every `<group>/<implementation>/<n>/new/` under `dir`.
    /// Errors if there is none, or if one cannot be read or has no such statistic.
    pub fn load(dir: &Path, statistic: Statistic) -> Result<Self> {
        let mut results = Self::default();
        for group in subdirectories(dir)? {
            for implementation in subdirectories(&dir.join(&group))? {
                for size in subdirectories(&dir.join(&group).join(&implementation))? {
                    let Ok(n) = size.parse::<usize>() else { continue };
                    let new = dir.join(&group).join(&implementation).join(&size).join("new");
                    if new.join("estimates.json").exists() {
                        let t = match statistic {
                            Statistic::Median => median_ns(&new.join("estimates.json"))?,
                            Statistic::Fastest => fastest_ns(&new.join("sample.json"))?,
                        };
                        results.insert(&group, &implementation, n, t);
                    }
                }
            }
        }
        if results.times.is_empty() {
            bail!("no criterion estimates under {}", dir.display());
        }
        Ok(results)
    }

    /// Records a time (ns).
    pub fn insert(&mut self, group: &str, implementation: &str, n: usize, ns: f64) {
        self.times.insert((group.to_string(), implementation.to_string(), n), ns);
    }

    /// The time (ns) of `implementation` at `n` in `group`, if it ran.
    pub fn get(&self, group: &str, implementation: &str, n: usize) -> Option<f64> {
        self.times.get(&(group.to_string(), implementation.to_string(), n)).copied()
    }

    /// The implementations that ran in `group`.
    pub fn implementations(&self, group: &str) -> BTreeSet<&str> {
        self.times.keys().filter(|(g, ..)| g == group).map(|(_, i, _)| i.as_str()).collect()
    }

    /// The sizes `n` that ran in `group`, ascending.
    pub fn sizes(&self, group: &str) -> BTreeSet<usize> {
        self.times.keys().filter(|(g, ..)| g == group).map(|&(_, _, n)| n).collect()
    }

    /// `(n, ns)` of `implementation` in `group`, ascending in n.
    pub fn series(&self, group: &str, implementation: &str) -> Vec<(usize, f64)> {
        self.times
            .iter()
            .filter(|((g, i, _), _)| g == group && i == implementation)
            .map(|(&(_, _, n), &t)| (n, t))
            .collect()
    }

    /// Whether any benchmark of `group` ran.
    pub fn has_group(&self, group: &str) -> bool {
        self.times.keys().any(|(g, ..)| g == group)
    }

    /// Number of benchmarks.
    pub fn len(&self) -> usize {
        self.times.len()
    }

    /// Whether no benchmark ran.
    pub fn is_empty(&self) -> bool {
        self.times.is_empty()
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
pub(crate) fn median_ns(path: &Path) -> Result<f64> {
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

/// The fastest sample's time per iteration (ns) in one criterion `sample.json`
/// (`times[i]` ns over `iters[i]` iterations).
pub(crate) fn fastest_ns(path: &Path) -> Result<f64> {
    let text = std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let json: serde_json::Value =
        serde_json::from_str(&text).with_context(|| format!("parsing {}", path.display()))?;
    let column = |key: &str| -> Result<Vec<f64>> {
        json[key]
            .as_array()
            .and_then(|a| a.iter().map(|v| v.as_f64()).collect())
            .with_context(|| format!("{}: no numeric array {key}", path.display()))
    };
    let (iters, times) = (column("iters")?, column("times")?);
    let fastest = iters.iter().zip(&times).map(|(i, t)| t / i).fold(f64::INFINITY, f64::min);
    if iters.len() != times.len() || !(fastest.is_finite() && fastest > 0.0) {
        bail!(
            "{}: no usable samples ({} iteration counts, {} times)",
            path.display(),
            iters.len(),
            times.len()
        );
    }
    Ok(fastest)
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
    fn reads_times_by_group_implementation_and_size() {
        let dir = scratch("load");
        let est = |median: f64| {
            format!(r#"{{"mean":{{"point_estimate":1.0}},"median":{{"point_estimate":{median}}}}}"#)
        };
        write(&dir, "planar_accelerations", "generated", "3", &est(50.0));
        write(&dir, "planar_accelerations", "generic_dyn", "3", &est(200.0));
        write(&dir, "planar_accelerations", "generic_dyn", "10", &est(900.0));
        let sample = |n: &str| dir.join("planar_accelerations/generic_dyn").join(n).join("new/sample.json");
        std::fs::write(sample("3"), r#"{"iters":[10.0,20.0],"times":[3000.0,4400.0]}"#).unwrap();
        // generated/3 and generic_dyn/10 have no sample.json: an error naming the file.
        let err = Results::load(&dir, Statistic::Fastest).unwrap_err();
        assert!(format!("{err:#}").contains("sample.json"), "{err:#}");
        std::fs::write(
            dir.join("planar_accelerations/generated/3/new/sample.json"),
            r#"{"iters":[1.0],"times":[48.0]}"#,
        )
        .unwrap();
        std::fs::write(sample("10"), r#"{"iters":[1.0],"times":[880.0]}"#).unwrap();
        let fastest = Results::load(&dir, Statistic::Fastest).unwrap();
        // Criterion's report directory, not a size: ignored.
        std::fs::create_dir_all(dir.join("planar_accelerations").join("generated").join("report")).unwrap();
        let results = Results::load(&dir, Statistic::Median).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
        // 4400 ns over 20 iterations (220 per iteration) beats 3000 over 10.
        assert_eq!(fastest.get("planar_accelerations", "generic_dyn", 3), Some(220.0));
        assert_eq!(fastest.get("planar_accelerations", "generated", 3), Some(48.0));
        assert_eq!(results.len(), 3);
        assert_eq!(results.get("planar_accelerations", "generated", 3), Some(50.0));
        assert_eq!(results.series("planar_accelerations", "generic_dyn"), vec![(3, 200.0), (10, 900.0)]);
        assert_eq!(results.sizes("planar_accelerations").into_iter().collect::<Vec<_>>(), vec![3, 10]);
    }

    #[test]
    fn no_results_and_bad_times_are_errors() {
        let dir = scratch("empty");
        assert!(
            Results::load(&dir, Statistic::Median)
                .unwrap_err()
                .to_string()
                .contains("no criterion estimates")
        );
        write(&dir, "planar_energy", "generated", "2", r#"{"median":{"point_estimate":-1.0}}"#);
        let err = Results::load(&dir, Statistic::Median).unwrap_err();
        std::fs::remove_dir_all(&dir).unwrap();
        assert!(format!("{err:#}").contains("median -1 ns"), "{err:#}");
    }
}
