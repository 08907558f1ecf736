//! The reference at one state of one case, as every implementation is compared with
//! it: values, entry scales, scale floors and the right-hand side `Q − c − k − d`.

use nalgebra::{DVector, DVectorView};

use super::bounds::{SCALE_FLOOR, row_sum_norm};
use crate::case::{Case, Evaluated, Params, PartialsAt, Point};

/// The reference at one state: values, entry scales, floors, and the right-hand side.
pub(crate) struct Reference {
    pub(crate) values: Evaluated,
    pub(crate) scales: Evaluated,
    /// The scale floor of each entry-wise quantity, in [`Quantity::ALL`] order.
    pub(super) floors: [f64; 7],
    /// `Q − c − k − d`.
    pub(crate) rhs: DVector<f64>,
    /// Its scale `S(Q) + S(c) + S(k) + S(d)`.
    pub(crate) rhs_scale: DVector<f64>,
    /// The stored derivatives (`∂M/∂q`, the Jacobians of `Q − c − k − d`).
    pub(crate) partials: PartialsAt,
    /// Their scales.
    pub(crate) partial_scales: PartialsAt,
}

impl Reference {
    pub(crate) fn new(case: &Case, params: &Params, point: &Point) -> Self {
        let (values, scales) = case.evaluate_with_scales(params, point);
        let rate = DVectorView::from_slice(&point.qd, point.qd.len()).amax();
        // Terms of the form W u̇·u̇ are bounded by ‖S(M)‖_∞ ‖q̇‖²_∞ (SCALE_FLOOR).
        let quadratic = row_sum_norm(&scales.mass_matrix) * rate * rate;
        let floors = [
            scales.mass_matrix.amax(),
            scales.velocity_terms.amax().max(quadratic),
            scales.gravity_terms.amax(),
            scales.pivot_terms.amax(),
            scales.generalized_forces.amax(),
            scales.kinetic_energy.max(quadratic),
            scales.potential_energy,
        ]
        .map(|n| SCALE_FLOOR * n);
        let rhs_scale =
            &scales.generalized_forces + &scales.velocity_terms + &scales.gravity_terms + &scales.pivot_terms;
        let (partials, partial_scales) = case.partials_with_scales(params, point);
        Reference { rhs: values.rhs(), values, scales, floors, rhs_scale, partials, partial_scales }
    }
}
