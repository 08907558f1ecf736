//! sweep.csv: one row per point and kind, numbers in the shortest form that reads back to
//! the same bits, empty fields where a point has no result.

use std::path::Path;

use super::point::Point;
use crate::csv::{Csv, number};
use crate::error::Result;
use crate::points::{RESULT_COLUMNS, result_fields};

/// The columns of sweep.csv: the point, then [`RESULT_COLUMNS`] with the wall-clock time
/// before the last (the energy balance's residual).
pub fn header() -> Vec<&'static str> {
    let (last, results) = RESULT_COLUMNS.split_last().expect("result columns");
    let mut header = vec!["kind", "omega_rad_s", "omega_over_sqrt_g_over_L", "status"];
    header.extend(results);
    header.extend(["wall_s", last]);
    header
}

/// Writes sweep.csv: its [`header`], then one row per point, in the order of the points.
pub fn write(path: &Path, points: &[Point]) -> Result<()> {
    let mut csv = Csv::create(path, &header())?;
    for p in points {
        let mut row: Vec<String> =
            vec![p.kind.name().into(), number(p.omega), number(p.omega_scaled), p.status.name().into()];
        let mut result = result_fields(p.result.as_ref());
        // wall_s before the last column, balance_residual_j.
        let balance = result.pop().unwrap_or_default();
        row.extend(result);
        row.push(p.result.as_ref().and_then(|r| r.wall_seconds).map_or(String::new(), |w| format!("{w:.3}")));
        row.push(balance);
        csv.fields(&row)?;
    }
    csv.finish()
}
