//! What `verify` found for the dense models: the worst error per case, quantity and
//! implementation, the failures with the states to reproduce them, and the table.

use std::fmt;

use super::bounds::{BOUND, worse};
use super::compare::{Measured, Quantity, Reported};
use crate::case::{Kind, Params, Point};
use crate::sample;

/// The worst [`Measured`] of one model on one quantity of one case, over the states.
#[derive(Debug, Clone, PartialEq)]
pub struct Worst {
    /// The measurement.
    pub measured: Measured,
    /// The state index (see [`sample::state`]).
    pub state: usize,
}

impl Worst {
    pub(super) fn update(slot: &mut Option<Worst>, measured: Measured, state: usize) {
        if slot.as_ref().is_none_or(|w| worse(measured.error, w.measured.error)) {
            *slot = Some(Worst { measured, state });
        }
    }

    /// Whether the error is within [`BOUND`] (NaN is not).
    pub fn ok(&self) -> bool {
        self.measured.error <= BOUND
    }
}

/// Which implementation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Implementation {
    /// The fixed-N model of `pendulum_macros::model!`.
    Generated,
    /// `Planar<Dyn>` or `Spatial<Dyn>`.
    Generic,
}

impl fmt::Display for Implementation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Implementation::Generated => "generated",
            Implementation::Generic => "generic",
        })
    }
}

/// One result per implementation of a case's size.
#[derive(Debug, Clone, PartialEq)]
pub struct PerModel<T> {
    /// The generated model's (`None` if there is none of that size).
    pub generated: Option<T>,
    /// The generic model's.
    pub generic: T,
}

impl<T> PerModel<T> {
    /// Every present result with its implementation, generated first.
    pub fn iter(&self) -> impl Iterator<Item = (Implementation, &T)> {
        let generated = self.generated.iter().map(|t| (Implementation::Generated, t));
        generated.chain([(Implementation::Generic, &self.generic)])
    }
}

/// One table row: a case's quantity, worst error per implementation.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// Case name.
    pub case: String,
    /// What is compared.
    pub quantity: Quantity,
    /// The worst error of each implementation.
    pub worst: PerModel<Worst>,
}

impl Row {
    /// Whether every present implementation is within [`BOUND`].
    pub fn ok(&self) -> bool {
        self.worst.iter().all(|(_, w)| w.ok())
    }
}

/// The spatial singularity check of one case: at `θ_1 = 0` (and `π`), accelerations
/// must fail with [`Error::SingularAngle`](pendulum_core::Error::SingularAngle) for link 1.
#[derive(Debug, Clone, PartialEq)]
pub struct Singularity {
    /// Case name.
    pub case: String,
    /// Per implementation: `Ok` if it reported the singularity, `Err` saying what it
    /// did instead.
    pub reported: PerModel<Reported>,
}

impl Singularity {
    /// Whether every present implementation reported the singularity.
    pub fn ok(&self) -> bool {
        self.reported.iter().all(|(_, r)| r.is_ok())
    }
}

/// Everything [`verify_cases`](super::dense::verify_cases) found.
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    /// The seed of the random states.
    pub seed: u64,
    /// One row per case and quantity.
    pub rows: Vec<Row>,
    /// One per spatial case.
    pub singularities: Vec<Singularity>,
    /// Kind and links per case name, to regenerate a state for a failure message.
    pub(super) cases: Vec<(String, Kind, usize)>,
}

/// A failing measurement, with what is needed to reproduce it.
#[derive(Debug, Clone, PartialEq)]
pub struct Failure {
    /// Case name.
    pub case: String,
    /// Which implementation failed.
    pub implementation: Implementation,
    /// Which quantity.
    pub quantity: Quantity,
    /// The worst measurement and its state.
    pub worst: Worst,
    /// That state's parameters.
    pub params: Params,
    /// That state's point.
    pub point: Point,
}

impl fmt::Display for Failure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let m = &self.worst.measured;
        writeln!(
            f,
            "{} {}: {}{}: error {:.3e} > {BOUND:e} at state {}",
            self.case,
            self.implementation,
            self.quantity.name(),
            m.entry,
            m.error,
            self.worst.state
        )?;
        writeln!(f, "    {}", m.detail)?;
        let p = &self.params;
        writeln!(
            f,
            "    masses {:?}, lengths {:?}, g {:?}, damping {:?}",
            p.masses, p.lengths, p.gravity, p.damping
        )?;
        let x = &self.point;
        write!(
            f,
            "    q {:?}, qd {:?}, torque {:?}, pivot_acceleration {:?}",
            x.q, x.qd, x.torque, x.pivot_acceleration
        )
    }
}

impl Report {
    /// Whether every row and singularity check passed.
    pub fn ok(&self) -> bool {
        self.rows.iter().all(Row::ok) && self.singularities.iter().all(Singularity::ok)
    }

    /// Every failing (case, implementation, quantity), worst error first, with its
    /// state's values.
    pub fn failures(&self) -> Vec<Failure> {
        let mut failures = Vec::new();
        for row in &self.rows {
            for (implementation, worst) in row.worst.iter().filter(|(_, w)| !w.ok()) {
                let (_, kind, links) = self
                    .cases
                    .iter()
                    .find(|(name, ..)| *name == row.case)
                    .expect("every row's case is listed");
                let (params, point) = sample::state(self.seed, *kind, *links, worst.state);
                failures.push(Failure {
                    case: row.case.clone(),
                    implementation,
                    quantity: row.quantity,
                    worst: worst.clone(),
                    params,
                    point,
                });
            }
        }
        failures.sort_by(|a, b| b.worst.measured.error.total_cmp(&a.worst.measured.error));
        failures
    }

    /// The table: case | quantity | worst generated | worst generic | verdict.
    pub fn table(&self) -> String {
        let error = |w: &Worst| match w.measured.error {
            0.0 => "0".to_owned(),
            e => format!("{e:.1e}"),
        };
        let singular = |r: &Reported| match r {
            Ok(()) => "SingularAngle".to_owned(),
            Err(_) => "WRONG".to_owned(),
        };
        let verdict = |ok: bool| if ok { "ok" } else { "FAIL" }.to_owned();
        let mut lines = vec![[
            "case".to_owned(),
            "quantity".to_owned(),
            "generated".to_owned(),
            "generic".to_owned(),
            "verdict".to_owned(),
        ]];
        for row in &self.rows {
            lines.push([
                row.case.clone(),
                row.quantity.name().to_owned(),
                row.worst.generated.as_ref().map_or("n/a".to_owned(), error),
                error(&row.worst.generic),
                verdict(row.ok()),
            ]);
            if row.quantity == Quantity::Accelerations
                && let Some(s) = self.singularities.iter().find(|s| s.case == row.case)
            {
                lines.push([
                    s.case.clone(),
                    "singular θ1 = 0, π".to_owned(),
                    s.reported.generated.as_ref().map_or("n/a".to_owned(), singular),
                    singular(&s.reported.generic),
                    verdict(s.ok()),
                ]);
            }
        }
        let mut widths = [0; 5];
        for line in &lines {
            for (w, cell) in widths.iter_mut().zip(line) {
                *w = (*w).max(cell.chars().count());
            }
        }
        let mut out = String::new();
        for (k, line) in lines.iter().enumerate() {
            let cells: Vec<String> = line
                .iter()
                .zip(widths)
                .enumerate()
                .map(|(c, (cell, w))| {
                    let pad = w - cell.chars().count();
                    // Numbers right-aligned, names left-aligned.
                    if (2..4).contains(&c) {
                        format!("{}{cell}", " ".repeat(pad))
                    } else {
                        format!("{cell}{}", " ".repeat(pad))
                    }
                })
                .collect();
            out += cells.join(" | ").trim_end();
            out.push('\n');
            if k == 0 {
                out += &widths.iter().map(|&w| "-".repeat(w)).collect::<Vec<_>>().join("-|-");
                out.push('\n');
            }
        }
        out
    }
}
