//! The ensembles' benchmarks of one run, read back from criterion's directory: for each
//! benchmark (by its full id, `accelerations/planar/single/8`) the median and the fastest
//! sample, per element of its throughput.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{Context, Result, bail};

use crate::bench::results::{fastest_ns, median_ns};

/// A benchmark's times per element of its throughput (ns per chain or chain-step).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Timing {
    /// Criterion's median.
    pub median: f64,
    /// The fastest sample.
    pub fastest: f64,
}

/// Every benchmark of one run, by full id.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Measured {
    times: BTreeMap<String, Timing>,
}

impl Measured {
    /// Reads every `…/new/benchmark.json` under `dir` with its `estimates.json` and
    /// `sample.json`. Errors if there is none, or if one cannot be read, has no
    /// throughput in elements, or no usable time.
    pub fn load(dir: &Path) -> Result<Self> {
        let mut measured = Self::default();
        let mut pending = vec![dir.to_path_buf()];
        while let Some(d) = pending.pop() {
            for entry in std::fs::read_dir(&d).with_context(|| format!("listing {}", d.display()))? {
                let path = entry.with_context(|| format!("listing {}", d.display()))?.path();
                if path.is_dir() {
                    pending.push(path);
                } else if path.file_name().is_some_and(|f| f == "benchmark.json")
                    && path.parent().and_then(Path::file_name).is_some_and(|f| f == "new")
                {
                    let (id, elements) = identity(&path)?;
                    let new = path.parent().expect("a file's directory");
                    let per = |ns: f64| ns / elements;
                    let timing = Timing {
                        median: per(median_ns(&new.join("estimates.json"))?),
                        fastest: per(fastest_ns(&new.join("sample.json"))?),
                    };
                    measured.times.insert(id, timing);
                }
            }
        }
        if measured.times.is_empty() {
            bail!("no criterion benchmarks under {}", dir.display());
        }
        Ok(measured)
    }

    /// Records a benchmark's times per element (ns).
    pub fn insert(&mut self, id: &str, timing: Timing) {
        self.times.insert(id.to_string(), timing);
    }

    /// The times of benchmark `id`, if it ran.
    pub fn get(&self, id: &str) -> Option<Timing> {
        self.times.get(id).copied()
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

/// The full id and the throughput in elements (chains or chain-steps) of one criterion
/// `benchmark.json`.
fn identity(path: &Path) -> Result<(String, f64)> {
    let text = std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let json: serde_json::Value =
        serde_json::from_str(&text).with_context(|| format!("parsing {}", path.display()))?;
    let id = json["full_id"].as_str().with_context(|| format!("{}: no full_id", path.display()))?;
    let elements = json["throughput"]["Elements"]
        .as_f64()
        .with_context(|| format!("{}: {id} declares no throughput in elements", path.display()))?;
    if elements < 1.0 {
        bail!("{}: {id} declares {elements} elements", path.display());
    }
    Ok((id.to_string(), elements))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(dir: &Path, directory: &str, id: &str, throughput: &str, median: f64, sample: &str) {
        let new = dir.join(directory).join("new");
        std::fs::create_dir_all(&new).unwrap();
        std::fs::write(
            new.join("benchmark.json"),
            format!(r#"{{"full_id":"{id}","throughput":{throughput}}}"#),
        )
        .unwrap();
        std::fs::write(new.join("estimates.json"), format!(r#"{{"median":{{"point_estimate":{median}}}}}"#))
            .unwrap();
        std::fs::write(new.join("sample.json"), sample).unwrap();
    }

    #[test]
    fn times_are_per_element_by_full_id() {
        let dir = std::env::temp_dir().join(format!("xtask-ensembles-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let sample = r#"{"iters":[2.0,4.0],"times":[1300.0,2400.0]}"#;
        write(&dir, "rk4/whirl_100_single", "rk4/whirl_100/single", r#"{"Elements":64}"#, 6400.0, sample);
        write(
            &dir,
            "generated/planar_single/4",
            "generated/planar/single/4",
            r#"{"Elements":4}"#,
            400.0,
            sample,
        );
        // Criterion's older run of the same benchmark: not read.
        std::fs::create_dir_all(dir.join("rk4/whirl_100_single/base")).unwrap();
        let measured = Measured::load(&dir).unwrap();
        assert_eq!(measured.len(), 2);
        // 2400 ns over 4 iterations beats 1300 over 2: 600 ns, over 64 chains.
        assert_eq!(
            measured.get("rk4/whirl_100/single"),
            Some(Timing { median: 100.0, fastest: 600.0 / 64.0 })
        );
        assert_eq!(measured.get("generated/planar/single/4").map(|t| t.median), Some(100.0));
        // A benchmark without a throughput cannot be counted per chain: an error naming it.
        write(&dir, "jacobians/planar_single/8", "jacobians/planar/single/8", "null", 1.0, sample);
        let err = Measured::load(&dir).unwrap_err();
        std::fs::remove_dir_all(&dir).unwrap();
        assert!(format!("{err:#}").contains("jacobians/planar/single/8 declares no throughput"), "{err:#}");
    }

    #[test]
    fn an_empty_directory_is_an_error() {
        let dir = std::env::temp_dir().join(format!("xtask-ensembles-empty-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let err = Measured::load(&dir).unwrap_err();
        std::fs::remove_dir_all(&dir).unwrap();
        assert!(err.to_string().contains("no criterion benchmarks"), "{err}");
    }
}
