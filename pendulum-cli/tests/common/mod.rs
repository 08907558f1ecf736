//! Helpers shared by the integration tests: run the `pendulum` binary, fresh scratch
//! directories, CSV reading.

#![allow(dead_code)] // Each test file uses its own subset.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The binary under test.
pub fn pendulum() -> Command {
    Command::new(env!("CARGO_BIN_EXE_pendulum"))
}

/// Runs `pendulum args...` in `dir`.
pub fn run_in(dir: &Path, args: &[&str]) -> Output {
    pendulum().args(args).current_dir(dir).output().expect("the pendulum binary runs")
}

/// A fresh, empty scratch directory named for the test.
pub fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("pendulum-cli").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Standard error as text.
pub fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// A CSV file: its header and numeric rows; panics (failing the test) on a malformed
/// row, so every test that reads a CSV also checks it is complete.
pub struct Csv {
    pub header: Vec<String>,
    pub rows: Vec<Vec<f64>>,
}

impl Csv {
    pub fn read(path: &Path) -> Self {
        let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert!(text.ends_with('\n'), "{} does not end with a newline", path.display());
        let mut lines = text.lines();
        let header: Vec<String> = lines.next().expect("a header").split(',').map(String::from).collect();
        let rows: Vec<Vec<f64>> = lines
            .enumerate()
            .map(|(i, line)| {
                let row: Vec<f64> = line
                    .split(',')
                    .map(|v| {
                        v.parse().unwrap_or_else(|_| panic!("{} row {i}: bad value {v}", path.display()))
                    })
                    .collect();
                assert_eq!(row.len(), header.len(), "{} row {i} has {} fields", path.display(), row.len());
                row
            })
            .collect();
        Self { header, rows }
    }

    /// The column named `name`.
    pub fn column(&self, name: &str) -> Vec<f64> {
        let j = self.header.iter().position(|h| h == name).unwrap_or_else(|| panic!("no column {name}"));
        self.rows.iter().map(|r| r[j]).collect()
    }
}

/// The parsed run.json of a run directory.
pub fn run_json(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("run.json")).unwrap()).unwrap()
}

/// A CSV file with text columns (sweep.csv, branches.csv, shapes.csv): header and fields;
/// panics (failing the test) on a ragged row or a missing final newline.
pub struct Table {
    pub header: Vec<String>,
    pub rows: Vec<Vec<String>>,
}

impl Table {
    pub fn read(path: &Path) -> Self {
        let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert!(text.ends_with('\n'), "{} does not end with a newline", path.display());
        let mut lines = text.lines();
        let header: Vec<String> = lines.next().expect("a header").split(',').map(String::from).collect();
        let rows: Vec<Vec<String>> = lines.map(|l| l.split(',').map(String::from).collect()).collect();
        for (i, row) in rows.iter().enumerate() {
            assert_eq!(row.len(), header.len(), "{} row {i}", path.display());
        }
        Self { header, rows }
    }

    /// The index of column `name`.
    pub fn index(&self, name: &str) -> usize {
        self.header.iter().position(|h| h == name).unwrap_or_else(|| panic!("no column {name}"))
    }

    /// Column `name` as text.
    pub fn text(&self, name: &str) -> Vec<String> {
        let j = self.index(name);
        self.rows.iter().map(|r| r[j].clone()).collect()
    }

    /// Column `name` as numbers.
    pub fn column(&self, name: &str) -> Vec<f64> {
        self.text(name)
            .iter()
            .map(|v| v.parse().unwrap_or_else(|_| panic!("{name}: bad number '{v}'")))
            .collect()
    }
}
