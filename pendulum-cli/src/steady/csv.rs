//! branches.csv (every continuation point) and shapes.csv (every shape at the listed
//! speeds) of `pendulum steady`. Numbers in Rust's round-trip format; `nodes` is 0 for
//! the vertical (on the axis: no crossing to count), `stability` one of `stable`,
//! `gyroscopic`, `unstable`.

use std::path::Path;

use pendulum_core::SteadyShape;
use pendulum_experiment::Csv;
use pendulum_experiment::csv::number as num;

use super::branches::Family;
use crate::error::CliResult;
use pendulum_experiment::steady::AtSpeed;

/// branches.csv: `branch` (its number in the table), `omega` (rad/s), `amplitude`
/// (`max |x_i|`, m), `nodes`, `stability`, `index`, `growth_rate` (largest real part, 1/s),
/// `theta1..n` (rad), `x1..n` (m).
pub fn branches(path: &Path, family: &Family, n: usize) -> CliResult<()> {
    let mut rows = Vec::new();
    for (b, labelled) in family.branches.iter().enumerate() {
        for (i, p) in labelled.branch.points.iter().enumerate() {
            let j = &labelled.judged[i];
            let mut row = vec![(b + 1).to_string(), num(p.omega), num(p.amplitude())];
            row.push(labelled.nodes[i].unwrap_or(0).to_string());
            row.extend([j.verdict.label().to_string(), j.index.to_string(), num(j.growth_rate)]);
            row.extend(angles_and_positions(p));
            rows.push(row);
        }
    }
    let mut header = ["branch", "omega", "amplitude", "nodes", "stability", "index", "growth_rate"]
        .map(String::from)
        .to_vec();
    header.extend(shape_columns(n));
    write(path, &header, &rows)
}

/// shapes.csv: `omega` (rad/s), `branch` (0: the vertical), `nodes`, `tip_radius`
/// (`|x_n|`, m), `stability`, `index`, `growth_rate` (1/s); with damping
/// `damped_stability` (`not found` when no damped shape was found, its numbers NaN),
/// `damped_growth_rate` (1/s), `damped_shift` (m); then `theta1..n` (rad), `x1..n` (m).
pub fn shapes(path: &Path, found: &[AtSpeed], n: usize, damped: bool) -> CliResult<()> {
    let mut header = ["omega", "branch", "nodes", "tip_radius", "stability", "index", "growth_rate"]
        .map(String::from)
        .to_vec();
    if damped {
        header.extend(["damped_stability", "damped_growth_rate", "damped_shift"].map(String::from));
    }
    header.extend(shape_columns(n));
    let rows: Vec<Vec<String>> = found
        .iter()
        .map(|f| {
            let mut row = vec![num(f.shape.omega), f.branch.to_string(), f.nodes.unwrap_or(0).to_string()];
            row.extend([num(f.tip_radius()), f.judged.verdict.label().into(), f.judged.index.to_string()]);
            row.push(num(f.judged.growth_rate));
            if damped {
                match &f.damped {
                    Some(d) => row.extend([d.verdict.label().into(), num(d.growth_rate), num(d.shift)]),
                    None => row.extend(["not found".into(), num(f64::NAN), num(f64::NAN)]),
                }
            }
            row.extend(angles_and_positions(&f.shape));
            row
        })
        .collect();
    write(path, &header, &rows)
}

fn shape_columns(n: usize) -> Vec<String> {
    (1..=n).map(|i| format!("theta{i}")).chain((1..=n).map(|i| format!("x{i}"))).collect()
}

fn angles_and_positions(p: &SteadyShape) -> impl Iterator<Item = String> + '_ {
    p.theta.iter().chain(&p.displacements).map(|&v| num(v))
}

fn write(path: &Path, header: &[String], rows: &[Vec<String>]) -> CliResult<()> {
    let mut csv = Csv::create(path, header)?;
    for row in rows {
        csv.fields(row)?;
    }
    csv.finish()
}
