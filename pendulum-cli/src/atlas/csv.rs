//! atlas.csv (one row per point and kind: its parameters, status and result, numbers in
//! the shortest form that reads back to the same bits) and the map on stdout.

use std::fmt::Write as _;
use std::path::Path;

use pendulum_experiment::Csv;
use pendulum_experiment::atlas::{AtlasConfig, AtlasPoint, Parameter};
use pendulum_experiment::csv::number;
use pendulum_experiment::points::{RESULT_COLUMNS, Status, result_fields};

use crate::error::CliResult;
use pendulum_experiment::words::short;

/// The columns before a point's result.
const HEAD: [&str; 9] = [
    "kind",
    "ix",
    "iy",
    "omega_rad_s",
    "omega_over_sqrt_g_over_L",
    "radius_m",
    "damping_n_m_s",
    "ramp_time_s",
    "status",
];

/// Writes atlas.csv: the header, then one row per point in the order of atlas.json.
/// `damping_n_m_s` is λ where every link has the same (empty otherwise), `ramp_time_s`
/// empty for sudden starts.
pub fn write(path: &Path, config: &AtlasConfig, points: &[AtlasPoint]) -> CliResult<()> {
    let header: Vec<&str> = HEAD.iter().chain(RESULT_COLUMNS.iter()).copied().collect();
    let mut csv = Csv::create(path, &header)?;
    let scale = config.reference_speed();
    for (i, p) in points.iter().enumerate() {
        let (kind, ix, iy) = config.locate(i);
        let s = config.setting(ix, iy);
        let uniform = s.damping.iter().all(|&d| d == s.damping[0]);
        let ramp = match kind {
            pendulum_experiment::atlas::AtlasKind::Sudden => None,
            pendulum_experiment::atlas::AtlasKind::RampUp => s.ramp_time,
        };
        let mut row = vec![
            kind.name().to_string(),
            ix.to_string(),
            iy.to_string(),
            number(s.omega),
            number(s.omega / scale),
            number(s.radius),
            if uniform { number(s.damping[0]) } else { String::new() },
            ramp.map_or(String::new(), number),
            p.status.name().into(),
        ];
        row.extend(result_fields(p.result.as_ref()));
        csv.fields(&row)?;
    }
    csv.finish()
}

/// An axis' value as the map shows it, to three digits: ω in units of √(g/L) when given so.
fn shown(config: &AtlasConfig, p: Parameter, v: f64) -> String {
    let v = if p == Parameter::Omega && config.scaled { v / config.reference_speed() } else { v };
    format!("{v:.2e}").parse::<f64>().map_or_else(|_| v.to_string(), |v| v.to_string())
}

/// The name of an axis on the map.
pub fn axis_name(config: &AtlasConfig, p: Parameter) -> String {
    if p == Parameter::Omega && config.scaled { "ω / √(g/L)".into() } else { p.label().into() }
}

/// The character of a point on the map: its node count (9 for 9 or more) if it settled,
/// `*` if it did not, `x` failed, `.` not run.
fn cell(p: &AtlasPoint) -> char {
    match (&p.result, p.status) {
        (Some(r), _) if r.settled => char::from_digit(r.nodes.min(9) as u32, 10).unwrap_or('9'),
        (Some(_), _) => '*',
        (None, Status::Failed) => 'x',
        (None, _) => '.',
    }
}

/// The map on stdout: per kind, the node count at every point, y decreasing downwards.
pub fn map(config: &AtlasConfig, points: &[AtlasPoint]) {
    let (nx, ny) = (config.x.values.len(), config.y.values.len());
    let (xp, yp) = (config.x.parameter, config.y.parameter);
    let mut out = format!(
        "atlas: n = {}, L = {} m, {} s per point, RK4 + projection h = {} s; nodes = axis crossings + 1 \
         (* not settled, x failed, . not run)\n",
        config.links(),
        short(config.length()),
        config.duration,
        short(config.step)
    );
    let width = (0..ny).map(|iy| shown(config, yp, config.y.values[iy]).len()).max().unwrap_or(0);
    for (k, kind) in config.kinds.iter().enumerate() {
        let _ = writeln!(
            out,
            "{}: rows {} from {} (top) to {}, columns {} from {} to {}",
            kind.name(),
            axis_name(config, yp),
            shown(config, yp, config.y.values[ny - 1]),
            shown(config, yp, config.y.values[0]),
            axis_name(config, xp),
            shown(config, xp, config.x.values[0]),
            shown(config, xp, config.x.values[nx - 1]),
        );
        for iy in (0..ny).rev() {
            let row: String = (0..nx).map(|ix| cell(&points[k * nx * ny + iy * nx + ix])).collect();
            let _ = writeln!(out, "  {:>width$}  {row}", shown(config, yp, config.y.values[iy]));
        }
    }
    print!("{out}");
}
