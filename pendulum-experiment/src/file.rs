//! `run.json`: the program and version that wrote it, the [`RunConfig`] and, once known,
//! how the run ended ([`Outcome`]). Every run.json an earlier release wrote still loads
//! (`tests/run_files.rs`).

use std::path::Path;

use crate::balance::RunBalance;
use serde::{Deserialize, Serialize};

use crate::description::RunConfig;
use crate::error::{Error, Result};
use crate::json::write_json_atomic;
use crate::spelling::opt;

/// The version of the program that writes run.json and final.json (the workspace's crates
/// share it).
pub const VERSION: &str = env!("CARGO_PKG_VERSION");

/// What `run.json` holds: the program and version that made it, the configuration and
/// (once known) how the run ended.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunFile {
    /// Always `"pendulum"`.
    pub program: String,
    /// The version of the program that wrote the file.
    pub version: String,
    /// Every parameter of the run.
    pub config: RunConfig,
    /// How the run ended; absent while it runs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub outcome: Option<Outcome>,
}

/// How a run ended.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Outcome {
    /// `"completed"`, `"interrupted"` (Ctrl-C) or `"failed"`.
    pub status: String,
    /// The time reached, s.
    pub t: f64,
    /// Steps taken.
    pub steps: u64,
    /// Samples written.
    pub samples: u64,
    /// The error, when the run failed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// What the integrator did (absent in files of earlier versions).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub work: Option<IntegratorWork>,
    /// The energy balance: `max |H − H0 − W|` and the scale it is judged against (absent
    /// in files of earlier versions).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub balance: Option<RunBalance>,
    /// What the reader of the run should know: an energy balance that is off (absent when
    /// there is nothing to say).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
}

/// What the integrator did over a run: the counts that say what a step cost.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IntegratorWork {
    /// Right-hand sides evaluated by the integrator itself.
    pub rhs_evaluations: u64,
    /// Steps it took (dp54: internal steps accepted; midpoint: the steps asked for).
    pub steps: u64,
    /// dp54: internal steps rejected and retried smaller.
    pub rejected_steps: u64,
    /// Implicit methods: Newton iterations.
    pub newton_iterations: u64,
    /// midpoint: steps split into halves (a link turning more than 1 rad, or Newton not
    /// converging).
    pub halved_steps: u64,
}

impl From<&pendulum_core::integrate::Stats> for IntegratorWork {
    fn from(s: &pendulum_core::integrate::Stats) -> Self {
        Self {
            rhs_evaluations: s.rhs_evaluations,
            steps: s.steps,
            rejected_steps: s.rejected_steps,
            newton_iterations: s.newton_iterations,
            halved_steps: s.halved_steps,
        }
    }
}

impl RunFile {
    /// A run file of this program's version for `config`.
    pub fn new(config: RunConfig) -> Self {
        Self { program: "pendulum".into(), version: VERSION.into(), config, outcome: None }
    }

    /// Reads and checks a run.json; errors name the file and the problem.
    pub fn read(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| Error::invalid(format!("{}: cannot read {}: {e}", opt("from"), path.display())))?;
        let file: Self = serde_json::from_str(&text).map_err(|e| {
            Error::invalid(format!("{}: {} is not a valid run.json: {e}", opt("from"), path.display()))
        })?;
        if file.program != "pendulum" {
            return Err(Error::invalid(format!(
                "{}: {} was written by '{}', not pendulum",
                opt("from"),
                path.display(),
                file.program
            )));
        }
        file.config.check().map_err(|e| e.context(format_args!("{}: {}", opt("from"), path.display())))?;
        Ok(file)
    }

    /// Writes the file atomically ([`write_json_atomic`]).
    pub fn write_atomic(&self, path: &Path) -> Result<()> {
        write_json_atomic(path, self)
    }
}

/// A warning for a file written by another version of the program (`version`), to repeat
/// a run from: the results may differ. `None` for this version.
pub fn other_version(path: &Path, version: &str) -> Option<String> {
    (version != VERSION).then(|| {
        format!(
            "{} was written by pendulum {version}, this is {}; results may differ",
            path.display(),
            VERSION
        )
    })
}
