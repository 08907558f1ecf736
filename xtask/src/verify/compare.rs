//! One model against the reference at one state: the worst entry of every quantity
//! (`check_model`), and whether a spatial model reports the singularity at `θ_1 = 0`, `π`.

use anyhow::{Result, bail};
use nalgebra::{
    DMatrix, DVector, DefaultAllocator, Dim, DimName, OMatrix, OVector, U1, allocator::Allocator,
};
use pendulum_core::{Derivatives, Error, Inputs, Jacobians, Model, ModelAlloc};

use super::bounds::{acceleration_error, entry_errors, jacobian_error};
use super::models::ModelVisitor;
use super::reference::Reference;
use crate::case::{Case, Point};

/// The quantities compared, in table order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    /// `M(q)`, entry-wise.
    MassMatrix,
    /// `c(q, q̇)`.
    VelocityTerms,
    /// `k(q)`.
    GravityTerms,
    /// `d(q, p̈)`.
    PivotTerms,
    /// `Q(q, q̇, σ)`.
    GeneralizedForces,
    /// `T`.
    KineticEnergy,
    /// `U`.
    PotentialEnergy,
    /// `q̈`, by the backward error ([`acceleration_error`]).
    Accelerations,
    /// `∂q̈/∂q`, column by column by the backward error of the differentiated equation
    /// `M ∂q̈/∂q_x = ∂F/∂q_x − (∂M/∂q_x) q̈` ([`jacobian_error`]).
    JacobianQ,
    /// `∂q̈/∂q̇`: `M ∂q̈/∂q̇_x = ∂F/∂q̇_x`.
    JacobianQd,
    /// `∂q̈/∂σ`: `M ∂q̈/∂σ_x = ∂F/∂σ_x`.
    JacobianTorque,
    /// `∂q̈/∂p̈`: `M ∂q̈/∂p̈_k = ∂F/∂p̈_k`.
    JacobianPivot,
}

impl Quantity {
    /// Every quantity, in table order.
    pub const ALL: [Quantity; 12] = [
        Quantity::MassMatrix,
        Quantity::VelocityTerms,
        Quantity::GravityTerms,
        Quantity::PivotTerms,
        Quantity::GeneralizedForces,
        Quantity::KineticEnergy,
        Quantity::PotentialEnergy,
        Quantity::Accelerations,
        Quantity::JacobianQ,
        Quantity::JacobianQd,
        Quantity::JacobianTorque,
        Quantity::JacobianPivot,
    ];

    /// The name used in the case files and the table.
    pub fn name(self) -> &'static str {
        match self {
            Quantity::MassMatrix => "mass_matrix",
            Quantity::VelocityTerms => "velocity_terms",
            Quantity::GravityTerms => "gravity_terms",
            Quantity::PivotTerms => "pivot_terms",
            Quantity::GeneralizedForces => "generalized_forces",
            Quantity::KineticEnergy => "kinetic_energy",
            Quantity::PotentialEnergy => "potential_energy",
            Quantity::Accelerations => "accelerations",
            Quantity::JacobianQ => "d(qdd)/dq",
            Quantity::JacobianQd => "d(qdd)/dqd",
            Quantity::JacobianTorque => "d(qdd)/dsigma",
            Quantity::JacobianPivot => "d(qdd)/dpivot",
        }
    }
}

/// One error measurement: the worst entry of one quantity at one state.
#[derive(Debug, Clone, PartialEq)]
pub struct Measured {
    /// The error: the entry's absolute difference relative to its (floored) scale, or
    /// for accelerations the backward error, as compared with [`BOUND`](super::bounds::BOUND); infinite for a
    /// non-finite value or a model error.
    pub error: f64,
    /// Which entry: `[i][j]`, `[i]`, or empty for a scalar.
    pub entry: String,
    /// The implementation's value and the reference's (residual and its scale for
    /// accelerations), or the model's error message.
    pub detail: String,
}

impl Measured {
    fn zero() -> Self {
        Self { error: 0.0, entry: String::new(), detail: String::new() }
    }
}

/// `Ok` if a model reported the singularity, `Err` saying what it did instead.
pub type Reported = Result<(), String>;

/// A [`Point`] as the vectors of one model.
pub(super) struct ModelPoint<M: Model>
where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>,
{
    pub(super) q: OVector<f64, M::Dof>,
    pub(super) qd: OVector<f64, M::Dof>,
    pub(super) inputs: Inputs<M::Dof, M::Space>,
}

impl<M: Model> ModelPoint<M>
where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>,
{
    /// `point`'s coordinates, rates and inputs for `model`.
    pub(super) fn new(model: &M, point: &Point) -> Self {
        let vector =
            |v: &[f64]| OVector::<f64, M::Dof>::from_iterator_generic(model.dof(), U1, v.iter().copied());
        let pivot_acceleration = OVector::<f64, M::Space>::from_iterator_generic(
            M::Space::name(),
            U1,
            point.pivot_acceleration.iter().copied(),
        );
        ModelPoint {
            q: vector(&point.q),
            qd: vector(&point.qd),
            inputs: Inputs { torque: vector(&point.torque), pivot_acceleration },
        }
    }
}

/// Compares one model with the reference at one state: the worst entry of every
/// quantity, in [`Quantity::ALL`] order.
///
/// Outputs are filled with NaN before each call, so an entry a model fails to write
/// shows up as an infinite error. Errors if the model's dimensions do not fit the case.
fn check_model<M: Derivatives>(
    case: &Case,
    model: &M,
    point: &Point,
    reference: &Reference,
) -> Result<Vec<Measured>>
where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space> + Allocator<M::Dof, M::Space>,
{
    let dof = model.dof();
    let n = case.dof();
    if dof.value() != n || M::Space::dim() != case.kind.space() {
        bail!(
            "{}: the model has {} coordinates in {} dimensions, the case {n} in {}",
            case.name,
            dof.value(),
            M::Space::dim(),
            case.kind.space()
        );
    }
    let nan_vector = || OVector::<f64, M::Dof>::from_element_generic(dof, U1, f64::NAN);
    let ModelPoint { q, qd, inputs } = ModelPoint::new(model, point);
    let (values, scales) = (&reference.values, &reference.scales);

    let measure =
        |quantity: Quantity, got: &[f64], want: &[f64], scale: &[f64], entry: &dyn Fn(usize) -> String| {
            let floor = reference.floors[quantity as usize];
            let (i, error) = entry_errors(got, want, scale, floor);
            if error == 0.0 {
                return Measured::zero();
            }
            Measured {
                error,
                entry: entry(i),
                detail: format!(
                    "implementation {:?}, reference {:?}, scale {:.3e}, floor {floor:.3e}",
                    got[i], want[i], scale[i]
                ),
            }
        };
    let index = |i: usize| format!("[{i}]");
    let mut out = Vec::with_capacity(Quantity::ALL.len());

    let mut mass = OMatrix::<f64, M::Dof, M::Dof>::from_element_generic(dof, dof, f64::NAN);
    model.mass_matrix(&q, &mut mass);
    // Both are column-major.
    out.push(measure(
        Quantity::MassMatrix,
        mass.as_slice(),
        values.mass_matrix.as_slice(),
        scales.mass_matrix.as_slice(),
        &|k| format!("[{}][{}]", k % n, k / n),
    ));

    let mut v = nan_vector();
    model.velocity_terms(&q, &qd, &mut v);
    out.push(measure(
        Quantity::VelocityTerms,
        v.as_slice(),
        values.velocity_terms.as_slice(),
        scales.velocity_terms.as_slice(),
        &index,
    ));

    let mut v = nan_vector();
    model.gravity_terms(&q, &mut v);
    out.push(measure(
        Quantity::GravityTerms,
        v.as_slice(),
        values.gravity_terms.as_slice(),
        scales.gravity_terms.as_slice(),
        &index,
    ));

    let mut v = nan_vector();
    model.pivot_terms(&q, &inputs.pivot_acceleration, &mut v);
    out.push(measure(
        Quantity::PivotTerms,
        v.as_slice(),
        values.pivot_terms.as_slice(),
        scales.pivot_terms.as_slice(),
        &index,
    ));

    let mut v = nan_vector();
    model.generalized_forces(&q, &qd, &inputs.torque, &mut v);
    out.push(measure(
        Quantity::GeneralizedForces,
        v.as_slice(),
        values.generalized_forces.as_slice(),
        scales.generalized_forces.as_slice(),
        &index,
    ));

    let scalar = |_| String::new();
    let t = model.kinetic_energy(&q, &qd);
    out.push(measure(
        Quantity::KineticEnergy,
        &[t],
        &[values.kinetic_energy],
        &[scales.kinetic_energy],
        &scalar,
    ));
    let u = model.potential_energy(&q);
    out.push(measure(
        Quantity::PotentialEnergy,
        &[u],
        &[values.potential_energy],
        &[scales.potential_energy],
        &scalar,
    ));

    let mut a = nan_vector();
    out.push(match model.accelerations(&q, &qd, &inputs, &mut a) {
        Err(e) => {
            Measured { error: f64::INFINITY, entry: String::new(), detail: format!("the model failed: {e}") }
        }
        Ok(()) => {
            let a = DVector::from_column_slice(a.as_slice());
            let (row, error, residual) = acceleration_error(
                &scales.mass_matrix,
                &reference.rhs_scale,
                &values.mass_matrix,
                &reference.rhs,
                &a,
            );
            if error == 0.0 {
                Measured::zero()
            } else {
                Measured {
                    error,
                    entry: format!(" (residual row {row})"),
                    detail: format!(
                        "residual {residual:.3e} of M_ref a - rhs_ref; implementation a {:?}, reference a {}",
                        a.as_slice(),
                        values
                            .mass_matrix
                            .clone()
                            .lu()
                            .solve(&reference.rhs)
                            .map_or_else(|| "(singular)".to_owned(), |r| format!("{:?}", r.as_slice()))
                    ),
                }
            }
        }
    });
    out.extend(check_jacobians(model, &q, &qd, &inputs, reference));
    Ok(out)
}

/// The four Jacobian rows of [`check_model`], in [`Quantity::ALL`] order: each column of
/// the model's Jacobian against the reference's differentiated equation, at the model's
/// own `q̈` (whose error the accelerations row measures).
fn check_jacobians<M: Derivatives>(
    model: &M,
    q: &OVector<f64, M::Dof>,
    qd: &OVector<f64, M::Dof>,
    inputs: &Inputs<M::Dof, M::Space>,
    reference: &Reference,
) -> Vec<Measured>
where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space> + Allocator<M::Dof, M::Space>,
{
    let mut jac = Jacobians::zeros(model);
    for m in [&mut jac.q, &mut jac.qd, &mut jac.torque] {
        m.fill(f64::NAN);
    }
    jac.pivot.fill(f64::NAN);
    if let Err(e) = model.acceleration_jacobians(q, qd, inputs, &mut jac) {
        let failed =
            Measured { error: f64::INFINITY, entry: String::new(), detail: format!("the model failed: {e}") };
        return vec![failed; 4];
    }
    let qdd = DVector::from_column_slice(jac.accelerations.as_slice());
    let dense = |m: &[f64], cols: usize| DMatrix::from_column_slice(m.len() / cols, cols, m);
    let dof = qdd.len();
    let jacobians = [
        dense(jac.q.as_slice(), dof),
        dense(jac.qd.as_slice(), dof),
        dense(jac.torque.as_slice(), dof),
        dense(jac.pivot.as_slice(), M::Space::dim()),
    ];
    jacobians.iter().enumerate().map(|(k, j)| jacobian_row(k, j, &qdd, reference)).collect()
}

/// One Jacobian row: `got` is `∂q̈/∂q` (`which` 0), `∂q̈/∂q̇` (1), `∂q̈/∂σ` (2) or `∂q̈/∂p̈`
/// (3) of an implementation whose accelerations are `qdd`, measured column by column by
/// the backward error of the reference's differentiated equation ([`jacobian_error`]).
pub(super) fn jacobian_row(
    which: usize,
    got: &DMatrix<f64>,
    qdd: &DVector<f64>,
    reference: &Reference,
) -> Measured {
    let (values, scales) = (&reference.partials, &reference.partial_scales);
    // ∂F/∂q_x − (∂M/∂q_x) q̈, and its scale S(∂F/∂q_x) + S(∂M/∂q_x) |q̈|.
    let by_q = || {
        let (mut rhs, mut scale) = (values.q.clone(), scales.q.clone());
        for x in 0..qdd.len() {
            rhs.set_column(x, &(values.q.column(x) - &values.mass_matrix[x] * qdd));
            scale.set_column(x, &(scales.q.column(x) + &scales.mass_matrix[x] * qdd.abs()));
        }
        (rhs, scale)
    };
    let (rhs, rhs_scale) = match which {
        0 => by_q(),
        1 => (values.qd.clone(), scales.qd.clone()),
        2 => (values.torque.clone(), scales.torque.clone()),
        _ => (values.pivot.clone(), scales.pivot.clone()),
    };
    let (column, row, error, residual) =
        jacobian_error(&reference.scales.mass_matrix, &rhs_scale, &reference.values.mass_matrix, &rhs, got);
    if error == 0.0 {
        return Measured::zero();
    }
    Measured {
        error,
        entry: format!("[{row}][{column}]"),
        detail: format!(
            "residual {residual:.3e} of M_ref J - rhs_ref in column {column}; implementation column {:?}",
            got.column(column).as_slice()
        ),
    }
}

/// [`check_model`] as a [`ModelVisitor`].
pub(super) struct Check<'a> {
    pub(super) case: &'a Case,
    pub(super) point: &'a Point,
    pub(super) reference: &'a Reference,
}

impl ModelVisitor for Check<'_> {
    type Output = Result<Vec<Measured>>;

    fn visit<M: Derivatives>(self, model: &M) -> Self::Output
    where
        DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space> + Allocator<M::Dof, M::Space>,
    {
        check_model(self.case, model, self.point, self.reference)
    }
}

/// Whether accelerations at `point` fail with [`Error::SingularAngle`] for link 1.
pub(super) struct CheckSingular<'a> {
    pub(super) point: &'a Point,
}

impl ModelVisitor for CheckSingular<'_> {
    type Output = Reported;

    fn visit<M: Derivatives>(self, model: &M) -> Self::Output
    where
        DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space> + Allocator<M::Dof, M::Space>,
    {
        let ModelPoint { q, qd, inputs } = ModelPoint::new(model, self.point);
        let mut a = q.clone();
        match model.accelerations(&q, &qd, &inputs, &mut a) {
            Err(Error::SingularAngle { link: 1, .. }) => Ok(()),
            Err(e) => {
                Err(format!("at theta_1 = {}: expected SingularAngle for link 1, got: {e}", self.point.q[0]))
            }
            Ok(()) => Err(format!(
                "at theta_1 = {}: expected SingularAngle for link 1, got accelerations {:?}",
                self.point.q[0],
                a.as_slice()
            )),
        }
    }
}

#[cfg(test)]
mod tests;
