//! The dense models, generated fixed-N and generic `Dyn`, against the reference at every
//! seeded state of every case: the [`Report`].

use anyhow::{Result, ensure};

use super::compare::{Check, CheckSingular, Quantity, Reported};
use super::models;
use super::reference::Reference;
use super::report::{PerModel, Report, Row, Singularity, Worst};
use crate::case::{Case, Kind};
use crate::sample;

/// Runs one case: every state, both implementations.
fn verify_case(case: &Case, states: usize, seed: u64) -> Result<(Vec<Row>, Option<Singularity>)> {
    let mut generic: Vec<Option<Worst>> = vec![None; Quantity::ALL.len()];
    let mut generated: Vec<Option<Worst>> = vec![None; Quantity::ALL.len()];
    for state in 0..states {
        let (params, point) = sample::state(seed, case.kind, case.links, state);
        let reference = Reference::new(case, &params, &point);
        let check = || Check { case, point: &point, reference: &reference };
        let measured = models::with_generic(case.kind, &params, check())??;
        for (slot, m) in generic.iter_mut().zip(measured) {
            Worst::update(slot, m, state);
        }
        if let Some(measured) = models::with_generated(case.kind, case.links, &params, check())? {
            for (slot, m) in generated.iter_mut().zip(measured?) {
                Worst::update(slot, m, state);
            }
        }
    }
    // Every state updates every generic slot, and every generated slot iff the case has a
    // generated model: with at least one state, the slots are `Some` exactly then.
    let rows = Quantity::ALL
        .iter()
        .zip(generic.into_iter().zip(generated))
        .map(|(&quantity, (generic, generated))| Row {
            case: case.name.clone(),
            quantity,
            worst: PerModel { generic: generic.expect("at least one state"), generated },
        })
        .collect();

    let singularity = match case.kind {
        Kind::Planar => None,
        Kind::Spatial => {
            let (params, mut point) = sample::state(seed, case.kind, case.links, 0);
            let mut run = |theta: f64| -> Result<(Reported, Option<Reported>)> {
                point.q[0] = theta;
                let generic = models::with_generic(case.kind, &params, CheckSingular { point: &point })?;
                let generated =
                    models::with_generated(case.kind, case.links, &params, CheckSingular { point: &point })?;
                Ok((generic, generated))
            };
            let (generic_zero, generated_zero) = run(0.0)?;
            let (generic_pi, generated_pi) = run(std::f64::consts::PI)?;
            Some(Singularity {
                case: case.name.clone(),
                reported: PerModel {
                    generic: generic_zero.and(generic_pi),
                    generated: generated_zero.zip(generated_pi).map(|(z, p)| z.and(p)),
                },
            })
        }
    };
    Ok((rows, singularity))
}

/// Verifies `cases` at `states` random states from `seed`.
///
/// Errors only when `states` is 0 or a model cannot be built or does not fit its case;
/// mismatches are in the [`Report`].
pub fn verify_cases(cases: &[Case], states: usize, seed: u64) -> Result<Report> {
    ensure!(states >= 1, "verify needs at least one state: a verify of no states would prove nothing");
    let mut report = Report {
        seed,
        rows: Vec::new(),
        singularities: Vec::new(),
        cases: cases.iter().map(|c| (c.name.clone(), c.kind, c.links)).collect(),
    };
    for case in cases {
        let (rows, singularity) = verify_case(case, states, seed)?;
        report.rows.extend(rows);
        report.singularities.extend(singularity);
    }
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::verify::bounds::BOUND;
    use crate::verify::fixtures::fixtures;

    #[test]
    fn generic_models_agree_with_the_hand_written_fixtures() {
        let report = verify_cases(&fixtures(), 30, 1).unwrap();
        assert!(report.ok(), "\n{}", report.table());
        assert_eq!(report.rows.len(), 3 * Quantity::ALL.len());
        assert_eq!(report.singularities.len(), 1);
        let worst = report.rows.iter().map(|r| r.worst.generic.measured.error).fold(0.0, f64::max);
        assert!(worst < 1e-2 * BOUND, "round-off only: {worst:e}");
    }

    #[test]
    fn the_table_is_aligned() {
        let table = verify_cases(&fixtures(), 2, 1).unwrap().table();
        let bars: Vec<Vec<usize>> = table
            .lines()
            .map(|l| {
                l.char_indices().filter(|&(_, c)| c == '|').map(|(i, _)| l[..i].chars().count()).collect()
            })
            .collect();
        assert!(bars.iter().all(|b| b.len() == 4 && *b == bars[0]), "{table}");
        assert!(table.contains("spatial_n1 | singular θ1 = 0, π |"), "{table}");
    }
}
