//! The one CSV writer of every file the front ends write (trajectory.csv, energy.csv,
//! modes.csv, branches.csv, shapes.csv, sweep.csv): comma-separated, a header line, no
//! quoting (no field holds a comma), numbers in Rust's shortest round-trip form (`{:?}`),
//! so that every value reads back to the same bits.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::error::{Result, io_failed};

/// A CSV file written through a buffer; errors name the file.
pub struct Csv {
    path: PathBuf,
    writer: BufWriter<File>,
}

impl Csv {
    /// Creates (or truncates) `path` and writes the header line.
    pub fn create(path: &Path, header: &[impl AsRef<str>]) -> Result<Self> {
        let file = File::create(path).map_err(|e| io_failed("create", path, e))?;
        let mut csv = Self { path: path.to_path_buf(), writer: BufWriter::new(file) };
        csv.fields(header.iter().map(AsRef::as_ref))?;
        Ok(csv)
    }

    /// One row of numbers, each in its shortest round-trip form.
    pub fn row(&mut self, values: impl IntoIterator<Item = f64>) -> Result<()> {
        let mut first = true;
        for v in values {
            let sep = if first { "" } else { "," };
            first = false;
            write!(self.writer, "{sep}{}", number(v)).map_err(|e| io_failed("write", &self.path, e))?;
        }
        writeln!(self.writer).map_err(|e| io_failed("write", &self.path, e))
    }

    /// One row of fields as written (numbers formatted by [`number`], words, empty fields).
    pub fn fields<S: AsRef<str>>(&mut self, fields: impl IntoIterator<Item = S>) -> Result<()> {
        let mut first = true;
        for field in fields {
            let sep = if first { "" } else { "," };
            first = false;
            write!(self.writer, "{sep}{}", field.as_ref()).map_err(|e| io_failed("write", &self.path, e))?;
        }
        writeln!(self.writer).map_err(|e| io_failed("write", &self.path, e))
    }

    /// Flushes the buffer and syncs the file to disk.
    pub fn finish(mut self) -> Result<()> {
        self.writer.flush().map_err(|e| io_failed("flush", &self.path, e))?;
        self.writer.get_ref().sync_all().map_err(|e| io_failed("sync", &self.path, e))
    }
}

/// `v` in its shortest form that reads back to the same bits (`1.0`, `0.1`, `NaN`).
pub fn number(v: f64) -> String {
    format!("{v:?}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_read_back_to_the_same_bits() {
        let dir = std::env::temp_dir().join(format!("pendulum-experiment-csv-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("a.csv");
        let mut csv = Csv::create(&path, &["t", "x"]).unwrap();
        csv.row([0.1, 1.0 / 3.0]).unwrap();
        csv.fields(["stable", "", &number(2.0)]).unwrap();
        csv.finish().unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(text, format!("t,x\n0.1,{:?}\nstable,,2.0\n", 1.0 / 3.0));
        let x: f64 = text.lines().nth(1).unwrap().split(',').nth(1).unwrap().parse().unwrap();
        assert_eq!(x.to_bits(), (1.0_f64 / 3.0).to_bits());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
