//! The O(n) routes against the sympy reference: `PlanarTension` (planar angles, rod
//! tensions), `Directions` (unit link directions, planar and spatial) and the generated
//! models with each algorithm (`algorithm: dense`, `algorithm: tension`) at the same
//! seeded random states as the dense models.
//!
//! They compute accelerations only (mass matrix and force terms are the dense models'),
//! so they are judged like the dense accelerations: by the backward error of the
//! reference's own system `M a = Q − c − k − d` ([`acceleration_error`]), bound [`BOUND`].
//! `Directions` takes no torques: its states have `σ = 0` (the reference is evaluated so).

use anyhow::{Context, Result, bail};
use nalgebra::{DMatrix, DVector, DefaultAllocator, U2, U3, Vector2, Vector3, allocator::Allocator};
use pendulum_core::{Derivatives, Directions, FnDrive, Inputs, Jacobians, Model, ModelAlloc, PlanarTension};

use super::bounds::{BOUND, acceleration_error};
use super::compare::{ModelPoint, jacobian_row};
use super::models;
use super::reference::Reference;
use super::route_jacobians;
use crate::case::{Case, Kind, Point};
use crate::sample;

/// The worst backward error of one route on one case, and the state it came from.
#[derive(Debug, Clone, PartialEq)]
pub struct RouteRow {
    /// Reference case name.
    pub case: String,
    /// `"PlanarTension"`, `"Directions"`, `"generated dense"` or `"generated tension"`.
    pub route: &'static str,
    /// Worst backward error over the states.
    pub error: f64,
    /// The state index where it occurred.
    pub state: usize,
}

/// The backward error of accelerations `a` at `point` against the reference.
fn backward_error(case: &Case, params: &crate::case::Params, point: &Point, a: &DVector<f64>) -> f64 {
    let reference = Reference::new(case, params, point);
    let (_, error, _) = acceleration_error(
        &reference.scales.mass_matrix,
        &reference.rhs_scale,
        &reference.values.mass_matrix,
        &reference.rhs,
        a,
    );
    error
}

/// The accelerations of a model at a point, as a [`models::ModelVisitor`].
struct Accelerations<'a>(&'a Point);

impl models::ModelVisitor for Accelerations<'_> {
    type Output = pendulum_core::Result<DVector<f64>>;

    fn visit<M: Derivatives>(self, model: &M) -> Self::Output
    where
        DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space> + Allocator<M::Dof, M::Space>,
    {
        let ModelPoint { q, qd, inputs } = ModelPoint::new(model, self.0);
        let mut a = q.clone();
        model.accelerations(&q, &qd, &inputs, &mut a)?;
        Ok(DVector::from_column_slice(a.as_slice()))
    }
}

/// `point` with its torques set to zero.
fn without_torque(point: &Point) -> Point {
    Point { torque: vec![0.0; point.torque.len()], ..point.clone() }
}

/// The routes' errors for `case` at `states` states from `seed`, one row per route.
pub fn verify_case(case: &Case, states: usize, seed: u64) -> Result<Vec<RouteRow>> {
    let mut rows: Vec<RouteRow> = Vec::new();
    let mut record =
        |route: &'static str, error: f64, state: usize| match rows.iter_mut().find(|r| r.route == route) {
            Some(row) if error > row.error || error.is_nan() => {
                row.error = error;
                row.state = state;
            }
            Some(_) => {}
            None => rows.push(RouteRow { case: case.name.clone(), route, error, state }),
        };
    for state in 0..states {
        let (params, point) = sample::state(seed, case.kind, case.links, state);
        let chain = models::chain::<nalgebra::Dyn>(&params)?;
        let context = || format!("{} state {state}", case.name);
        for (algorithm, route) in models::ALGORITHMS.into_iter().zip(["generated dense", "generated tension"])
        {
            if let Some(a) = models::with_generated_algorithm(
                case.kind,
                case.links,
                algorithm,
                &params,
                Accelerations(&point),
            )? {
                let a = a.with_context(context)?;
                record(route, backward_error(case, &params, &point, &a), state);
            }
        }
        match case.kind {
            Kind::Planar => {
                let model = PlanarTension::new(chain.clone());
                let inputs = Inputs {
                    torque: DVector::from_vec(point.torque.clone()),
                    pivot_acceleration: Vector2::from_column_slice(&point.pivot_acceleration),
                };
                let (q, qd) = (DVector::from_vec(point.q.clone()), DVector::from_vec(point.qd.clone()));
                let mut a = DVector::zeros(case.links);
                model.accelerations(&q, &qd, &inputs, &mut a).with_context(context)?;
                record("PlanarTension", backward_error(case, &params, &point, &a), state);
                let reference = Reference::new(case, &params, &point);
                let mut jac = Jacobians::zeros(&model);
                model.acceleration_jacobians(&q, &qd, &inputs, &mut jac).with_context(context)?;
                for (k, (route, j)) in
                    TENSION_JACOBIANS.iter().zip([&jac.q, &jac.qd, &jac.torque]).enumerate()
                {
                    record(route, jacobian_row(k, j, &jac.accelerations, &reference).error, state);
                }
                let pivot = DMatrix::from_column_slice(case.links, 2, jac.pivot.as_slice());
                record(
                    TENSION_JACOBIANS[3],
                    jacobian_row(3, &pivot, &jac.accelerations, &reference).error,
                    state,
                );

                let p = Vector2::from_column_slice(&point.pivot_acceleration);
                let drive = FnDrive::new(move |t: f64| p * (0.5 * t * t), move |t: f64| p * t, move |_| p);
                let directions = Directions::<U2>::new(chain).with_drive(drive);
                let x = directions.from_angles(&point.q, &point.qd).with_context(context)?;
                let a = directions.angle_accelerations(0.0, &x).with_context(context)?;
                record("Directions", backward_error(case, &params, &without_torque(&point), &a), state);
                let (qdd, jq, jqd) =
                    route_jacobians::planar(&directions, &point.q, &point.qd).with_context(context)?;
                directions_rows(&mut record, case, &params, &point, &qdd, &jq, &jqd, state);
            }
            Kind::Spatial => {
                let p = Vector3::from_column_slice(&point.pivot_acceleration);
                let drive = FnDrive::new(move |t: f64| p * (0.5 * t * t), move |t: f64| p * t, move |_| p);
                let directions = Directions::<U3>::new(chain).with_drive(drive);
                let a = directions.spherical_accelerations(0.0, &point.q, &point.qd).with_context(context)?;
                record("Directions", backward_error(case, &params, &without_torque(&point), &a), state);
                let (qdd, jq, jqd) =
                    route_jacobians::spatial(&directions, &point.q, &point.qd).with_context(context)?;
                directions_rows(&mut record, case, &params, &point, &qdd, &jq, &jqd, state);
            }
        }
    }
    Ok(rows)
}

/// `PlanarTension`'s Jacobian rows, in the order of [`jacobian_row`]'s `which`.
const TENSION_JACOBIANS: [&str; 4] =
    ["PlanarTension d/dq", "PlanarTension d/dqd", "PlanarTension d/dsig", "PlanarTension d/dp"];

/// `Directions`' Jacobian rows (no torques; its pivot follows a drive).
const DIRECTIONS_JACOBIANS: [&str; 2] = ["Directions d/dq", "Directions d/dqd"];

/// Records `Directions`' `∂q̈/∂q` and `∂q̈/∂q̇` (in angles) against the reference at the
/// torque-free `point`.
#[allow(clippy::too_many_arguments)]
fn directions_rows(
    record: &mut impl FnMut(&'static str, f64, usize),
    case: &Case,
    params: &crate::case::Params,
    point: &Point,
    qdd: &DVector<f64>,
    jq: &DMatrix<f64>,
    jqd: &DMatrix<f64>,
    state: usize,
) {
    let reference = Reference::new(case, params, &without_torque(point));
    for (k, j) in [jq, jqd].into_iter().enumerate() {
        record(DIRECTIONS_JACOBIANS[k], jacobian_row(k, j, qdd, &reference).error, state);
    }
}

/// Every case's rows.
pub fn verify_cases(cases: &[Case], states: usize, seed: u64) -> Result<Vec<RouteRow>> {
    let mut rows = Vec::new();
    for case in cases {
        rows.extend(verify_case(case, states, seed)?);
    }
    Ok(rows)
}

/// Prints the table of `rows` and errors if any is above [`BOUND`] (or NaN).
pub fn report(rows: &[RouteRow]) -> Result<()> {
    println!(
        "O(n) routes and each generated algorithm, accelerations (componentwise backward error \
         against the reference, bound {BOUND:e}):"
    );
    println!("{:<12} {:<20} {:>10}  verdict", "case", "route", "worst");
    for row in rows {
        let ok = row.error <= BOUND;
        println!(
            "{:<12} {:<20} {:>10.1e}  {}",
            row.case,
            row.route,
            row.error,
            if ok { "ok" } else { "FAIL" }
        );
    }
    if let Some(bad) = rows.iter().find(|r| r.error.is_nan() || r.error > BOUND) {
        bail!(
            "verify failed: O(n) route {} on {} has backward error {:e} at state {} (bound {BOUND:e})",
            bad.route,
            bad.case,
            bad.error,
            bad.state
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::case::load_all;

    #[test]
    fn routes_agree_with_the_reference() {
        let cases = load_all(&crate::cases_dir()).unwrap();
        let rows = verify_cases(&cases, 20, 0x5eed).unwrap();
        assert_eq!(
            rows.len(),
            cases.iter().map(|c| if c.kind == Kind::Planar { 10 } else { 5 }).sum::<usize>()
        );
        report(&rows).unwrap();
    }
}
