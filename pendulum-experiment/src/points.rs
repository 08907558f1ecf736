//! A whirl's point as the sweep and the atlas record it: where it stands ([`Status`]), what
//! the chain did there ([`Outcome`]: the shape report in plain numbers, as sweep.csv,
//! sweep.json, atlas.csv and atlas.json hold it), and the JSON file of a command's points
//! ([`PointsFile`]).

use std::path::Path;

use pendulum_core::ShapeReport;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

use crate::balance::RunBalance;
use crate::error::{Error, Result};
use crate::json::{read_command_file, write_json_atomic};
use crate::spelling::opt;

/// Where a point stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Status {
    /// Not started yet.
    Pending,
    /// Ran to the end; its result is there.
    Completed,
    /// Cut by Ctrl-C; no result.
    Interrupted,
    /// Never started (Ctrl-C, or an earlier ramp-down point did not finish).
    NotRun,
    /// A step or the analysis failed; the error says why.
    Failed,
}

impl Status {
    /// The name in the files.
    pub fn name(self) -> &'static str {
        match self {
            Self::Pending => "pending",
            Self::Completed => "completed",
            Self::Interrupted => "interrupted",
            Self::NotRun => "not-run",
            Self::Failed => "failed",
        }
    }
}

/// The shape analysis at the end of a point's run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Outcome {
    /// The time reached, s.
    pub t: f64,
    /// Steps taken.
    pub steps: u64,
    /// Axis crossings + 1 (the pivot counts as a node).
    pub nodes: usize,
    /// Crossings of the rotation axis below the pivot.
    pub axis_crossings: usize,
    /// The free end's distance from the axis, m.
    pub tip_radius: f64,
    /// The same, + on the pivot's side of the axis, − opposite (signed radial coordinate
    /// of the free end in the shape's plane), m.
    pub tip_signed: f64,
    /// Azimuth of the shape's plane behind (−) or ahead of the pivot, rad.
    pub plane_azimuth: f64,
    /// Largest distance of a mass from that plane, m.
    pub out_of_plane: f64,
    /// Whether the chain settled (drift ≤ threshold over the window).
    pub settled: bool,
    /// Largest displacement of a mass over the last window, m.
    pub drift: f64,
    /// The settled threshold, m.
    pub drift_threshold: f64,
    /// The window, s.
    pub window: f64,
    /// The damped steady shape nearest the final shape, if Newton found one.
    pub nearest: Option<Nearest>,
    /// Why no steady shape was found.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nearest_error: Option<String>,
    /// Wall-clock time of the run and its analysis, s (for points run together as a batch:
    /// an equal share of the batch's; `None` where the file must not depend on the machine,
    /// as in atlas.json).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wall_seconds: Option<f64>,
    /// The run's energy balance: `max |H − H0 − W|` over the samples fed to the analysis
    /// and its scale, J (absent in files of earlier versions).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub balance: Option<RunBalance>,
}

/// The damped steady shape nearest a point's final shape.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Nearest {
    /// Largest distance between corresponding masses, m.
    pub distance: f64,
    /// Its node count.
    pub nodes: usize,
    /// Its tip radius, m.
    pub tip_radius: f64,
    /// Every damped mode decays (growth rate below 1e-6 |ω|).
    pub stable: bool,
    /// Largest real part of its damped spectrum, 1/s.
    pub growth_rate: f64,
    /// Growth rates of smaller magnitude are zero within round-off, 1/s (absent in files
    /// of earlier versions).
    #[serde(default)]
    pub growth_rate_bound: f64,
}

impl Outcome {
    /// The outcome of a whirl's run from its shape report, steps, wall time (s) and balance.
    pub fn of(report: &ShapeReport, steps: u64, wall_seconds: Option<f64>, balance: RunBalance) -> Self {
        let (shape, settling) = (&report.shape, &report.settling);
        let (nearest, nearest_error) = match &report.nearest {
            Ok(n) => (
                Some(Nearest {
                    distance: n.distance,
                    nodes: n.shape.nodes,
                    tip_radius: n.shape.tip_radius,
                    stable: n.stable,
                    growth_rate: n.growth_rate,
                    growth_rate_bound: n.rate_bound,
                }),
                None,
            ),
            Err(e) => (None, Some(e.to_string())),
        };
        Self {
            t: report.t,
            steps,
            nodes: shape.nodes,
            axis_crossings: shape.axis_crossings,
            tip_radius: shape.tip_radius,
            tip_signed: shape.tip_radius.copysign(*shape.radial.last().unwrap_or(&0.0)),
            plane_azimuth: shape.plane_azimuth,
            out_of_plane: shape.out_of_plane,
            settled: settling.settled,
            drift: settling.drift,
            drift_threshold: settling.threshold,
            window: settling.window,
            nearest,
            nearest_error,
            wall_seconds,
            balance: Some(balance),
        }
    }
}

/// The columns of a point's result in sweep.csv and atlas.csv, in order.
pub const RESULT_COLUMNS: [&str; 12] = [
    "nodes",
    "axis_crossings",
    "tip_radius_m",
    "tip_signed_m",
    "settled",
    "drift_m",
    "nearest_distance_m",
    "nearest_nodes",
    "stable",
    "growth_rate_1_s",
    "t_end_s",
    "balance_residual_j",
];

/// The [`RESULT_COLUMNS`] of a point: its result's numbers in the shortest form that reads
/// back to the same bits, empty where there is no result (or no nearest steady shape).
pub fn result_fields(result: Option<&Outcome>) -> Vec<String> {
    use crate::csv::number;
    let Some(r) = result else { return vec![String::new(); RESULT_COLUMNS.len()] };
    let mut row = vec![
        r.nodes.to_string(),
        r.axis_crossings.to_string(),
        number(r.tip_radius),
        number(r.tip_signed),
        r.settled.to_string(),
        number(r.drift),
    ];
    match &r.nearest {
        Some(n) => {
            row.extend([number(n.distance), n.nodes.to_string(), n.stable.to_string(), number(n.growth_rate)])
        }
        None => row.extend(std::iter::repeat_n(String::new(), 4)),
    }
    row.push(number(r.t));
    row.push(r.balance.map_or(String::new(), |b| number(b.residual)));
    row
}

/// The parameters of a command whose points a [`PointsFile`] records (`pendulum sweep`'s,
/// `pendulum atlas`'s): the command's name, the file's conventions, and their checks.
pub trait Recorded {
    /// The command (`"sweep"`): the file is `COMMAND.json`.
    const COMMAND: &'static str;
    /// Units and conventions of the file's numbers.
    const CONVENTIONS: &'static str;
    /// Checks the parameters read back; errors name the bad value.
    fn check(&self) -> Result<()>;
    /// How many points they make, where that is fixed (checked on reading).
    fn points(&self) -> Option<usize> {
        None
    }
}

/// A command's JSON file of points (sweep.json, atlas.json): the program and version that
/// wrote it, its conventions, every parameter (`config`), numbers derived from them (not
/// read back), how the command stands (`"running"`, `"completed"`, `"interrupted"` or
/// `"failed"`) and every point so far.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointsFile<C, D, P> {
    /// Always `"pendulum"`.
    pub program: String,
    /// The command, [`Recorded::COMMAND`].
    pub command: String,
    /// The version that wrote the file.
    pub version: String,
    /// [`Recorded::CONVENTIONS`].
    pub conventions: String,
    pub config: C,
    pub derived: D,
    pub status: String,
    pub points: Vec<P>,
}

impl<
    C: Recorded + Serialize + DeserializeOwned,
    D: Serialize + DeserializeOwned,
    P: Serialize + DeserializeOwned,
> PointsFile<C, D, P>
{
    /// The file of this program's version, `"running"`.
    pub fn new(config: C, derived: D, points: Vec<P>) -> Self {
        Self {
            program: "pendulum".into(),
            command: C::COMMAND.into(),
            version: crate::VERSION.into(),
            conventions: C::CONVENTIONS.into(),
            config,
            derived,
            status: "running".into(),
            points,
        }
    }

    /// Reads and checks the file given to `--from`; errors name the file and the problem.
    pub fn read(path: &Path) -> Result<Self> {
        let file: Self = read_command_file(path, C::COMMAND)?;
        file.config.check().map_err(|e| e.context(format_args!("{} {}", opt("from"), path.display())))?;
        if let Some(expected) = file.config.points()
            && expected != file.points.len()
        {
            return Err(Error::invalid(format!(
                "{}: {}: {} points recorded, its configuration has {expected}",
                opt("from"),
                path.display(),
                file.points.len()
            )));
        }
        Ok(file)
    }

    /// Writes the file atomically ([`write_json_atomic`]).
    pub fn write_atomic(&self, path: &Path) -> Result<()> {
        write_json_atomic(path, self)
    }
}
