//! A run directory as `pendulum simulate` (or `pendulum.Run.run(out=…)`) leaves it, read
//! back: its run.json, and its trajectory.csv one row at a time (only the time, pivot and
//! mass columns are parsed). What `pendulum render` draws and the page shows.

use std::fs::File;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};

use crate::description::{Dimension, RunConfig};
use crate::error::{Error, Result};
use crate::file::RunFile;
use crate::spelling::opt_is;

/// A run directory as `pendulum simulate` leaves it.
pub struct Run {
    /// The run's parameters (and outcome, once it ended).
    pub file: RunFile,
    /// Its trajectory.csv.
    pub trajectory: PathBuf,
}

impl Run {
    /// Opens `dir`: it must hold a valid run.json and a trajectory.csv.
    pub fn open(dir: &Path) -> Result<Self> {
        let shown = dir.display();
        if !dir.is_dir() {
            return Err(Error::invalid(format!(
                "{shown} is not a run directory (what a run given {} writes)",
                opt_is("out", "DIR")
            )));
        }
        let json = dir.join("run.json");
        if !json.is_file() {
            return Err(Error::invalid(format!(
                "{shown} holds no run: no run.json (a run given {} writes one)",
                opt_is("out", "DIR")
            )));
        }
        let text = std::fs::read_to_string(&json)
            .map_err(|e| Error::invalid(format!("cannot read {}: {e}", json.display())))?;
        let file: RunFile = serde_json::from_str(&text)
            .map_err(|e| Error::invalid(format!("{} is not a valid run.json: {e}", json.display())))?;
        if file.program != "pendulum" {
            return Err(Error::invalid(format!(
                "{} was written by '{}', not pendulum",
                json.display(),
                file.program
            )));
        }
        file.config.check().map_err(|e| e.context(json.display()))?;
        let trajectory = dir.join("trajectory.csv");
        if !trajectory.is_file() {
            return Err(Error::invalid(format!(
                "{shown} holds no run: no trajectory.csv beside its run.json"
            )));
        }
        Ok(Self { file, trajectory })
    }

    /// The time the run reached, s: its outcome, or the planned end while it runs.
    pub fn reached(&self) -> f64 {
        self.file.outcome.as_ref().map_or(self.file.config.end, |o| o.t)
    }
}

/// One row of the trajectory: what the animation needs.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// Time, s.
    pub t: f64,
    /// Pivot position, m (z = 0 in 2D).
    pub pivot: [f64; 3],
    /// Mass positions, m, mass 1 first (z = 0 in 2D).
    pub masses: Vec<[f64; 3]>,
}

/// trajectory.csv, read row by row; every error names the file and line.
pub struct Trajectory {
    path: PathBuf,
    reader: BufReader<File>,
    line: String,
    /// The number of the line last read (the header is line 1).
    number: usize,
    header: Vec<String>,
    /// Index of `pivot_x`: the position columns start there.
    pivot: usize,
    /// Components per position: 2 or 3.
    dims: usize,
    /// Rows read.
    pub rows: u64,
    /// The time of the first and of the latest row read, s.
    pub first: Option<f64>,
    pub last: Option<f64>,
}

impl Trajectory {
    /// Opens the file and checks its header against the run: `t`, then `pivot_x`,
    /// `pivot_y`[, `pivot_z`] and `x1`, `y1`[, `z1`] … for every mass, last.
    pub fn open(path: &Path, config: &RunConfig) -> Result<Self> {
        let file =
            File::open(path).map_err(|e| Error::invalid(format!("cannot read {}: {e}", path.display())))?;
        let mut reader = BufReader::new(file);
        let mut line = String::new();
        reader.read_line(&mut line).map_err(|e| read_failed(path, 1, e))?;
        if line.is_empty() {
            return Err(Error::invalid(format!("{} is empty (no header line)", path.display())));
        }
        let header: Vec<String> = line.trim_end().split(',').map(String::from).collect();
        let axes: &[&str] = if config.dim == Dimension::Two { &["x", "y"] } else { &["x", "y", "z"] };
        let mut expected: Vec<String> = axes.iter().map(|a| format!("pivot_{a}")).collect();
        for i in 1..=config.links() {
            expected.extend(axes.iter().map(|a| format!("{a}{i}")));
        }
        let pivot = header.len().saturating_sub(expected.len());
        if header.first().map(String::as_str) != Some("t") || pivot == 0 || header[pivot..] != expected[..] {
            return Err(Error::invalid(format!(
                "{} line 1: the header is not that of a {}D run of {} links (t, …, {}, …, {})",
                path.display(),
                axes.len(),
                config.links(),
                expected[0],
                expected[expected.len() - 1]
            )));
        }
        Ok(Self {
            path: path.to_path_buf(),
            reader,
            line,
            number: 1,
            header,
            pivot,
            dims: axes.len(),
            rows: 0,
            first: None,
            last: None,
        })
    }

    /// A row buffer of the right size for [`Trajectory::next`].
    pub fn row(&self) -> Row {
        let n = (self.header.len() - self.pivot) / self.dims - 1;
        Row { t: 0.0, pivot: [0.0; 3], masses: vec![[0.0; 3]; n] }
    }

    /// Reads the next row into `row`; `false` at the end of the file. Errors: a line cut
    /// short, a wrong number of fields, a value that is not a finite number, a time that
    /// does not increase.
    pub fn next(&mut self, row: &mut Row) -> Result<bool> {
        self.line.clear();
        self.number += 1;
        let read =
            self.reader.read_line(&mut self.line).map_err(|e| read_failed(&self.path, self.number, e))?;
        if read == 0 {
            return Ok(false);
        }
        let at = || format!("{} line {}", self.path.display(), self.number);
        let Some(text) = self.line.strip_suffix('\n') else {
            return Err(Error::invalid(format!("{}: the line is cut short (no line end)", at())));
        };
        let mut fields = 0;
        for (j, value) in text.trim_end_matches('\r').split(',').enumerate() {
            fields += 1;
            if (j != 0 && j < self.pivot) || j >= self.header.len() {
                continue;
            }
            let v: f64 = match value.trim().parse() {
                Ok(v) if f64::is_finite(v) => v,
                _ => {
                    return Err(Error::invalid(format!(
                        "{}, column {}: '{value}' is not a finite number",
                        at(),
                        self.header[j]
                    )));
                }
            };
            if j == 0 {
                row.t = v;
            } else {
                let k = j - self.pivot;
                let (point, axis) = (k / self.dims, k % self.dims);
                match point {
                    0 => row.pivot[axis] = v,
                    p => row.masses[p - 1][axis] = v,
                }
            }
        }
        if fields != self.header.len() {
            return Err(Error::invalid(format!(
                "{}: {fields} fields, expected {} (is the file cut short?)",
                at(),
                self.header.len()
            )));
        }
        if let Some(last) = self.last
            && row.t <= last
        {
            return Err(Error::invalid(format!("{}: t = {} s does not follow t = {last} s", at(), row.t)));
        }
        self.first.get_or_insert(row.t);
        self.last = Some(row.t);
        self.rows += 1;
        Ok(true)
    }
}

fn read_failed(path: &Path, line: usize, e: std::io::Error) -> Error {
    Error::invalid(format!("{} line {line}: cannot read: {e}", path.display()))
}
