//! The trait every chain model implements, generated fixed-N and generic dynamic-N alike.

use std::borrow::Cow;

use nalgebra::{DefaultAllocator, Dim, DimName, OMatrix, OVector, allocator::Allocator};

use crate::chain::Chain;
use crate::error::{Error, Result};
use crate::kinematics::Chart;

/// The allocator bounds a [`Model`] needs, in one name.
///
/// Write `DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>` once in a generic
/// function instead of four `Allocator` bounds.
pub trait ModelAlloc<L: Dim, D: Dim, S: DimName>:
    Allocator<L> + Allocator<D> + Allocator<D, D> + Allocator<S>
{
}

impl<L: Dim, D: Dim, S: DimName, A> ModelAlloc<L, D, S> for A where
    A: Allocator<L> + Allocator<D> + Allocator<D, D> + Allocator<S>
{
}

/// What acts on the chain from outside at one instant.
///
/// `torque` holds the generalized forces `σ` conjugate to each coordinate (N·m; eq 26),
/// `pivot_acceleration` the pivot's acceleration `p̈` (m/s²) in the model's space
/// (2 components planar, 3 spatial). A driven pivot enters the equations only through
/// `p̈` (`docs/conventions.md`).
#[derive(Debug, Clone, PartialEq)]
pub struct Inputs<D: Dim, S: DimName>
where
    DefaultAllocator: Allocator<D> + Allocator<S>,
{
    /// Generalized torques `σ`, one per coordinate, N·m.
    pub torque: OVector<f64, D>,
    /// Pivot acceleration `p̈`, m/s².
    pub pivot_acceleration: OVector<f64, S>,
}

impl<D: Dim, S: DimName> Inputs<D, S>
where
    DefaultAllocator: Allocator<D> + Allocator<S>,
{
    /// No torque, pivot at rest.
    pub fn zeros(dof: D) -> Self {
        Self {
            torque: OVector::zeros_generic(dof, nalgebra::U1),
            pivot_acceleration: OVector::zeros_generic(S::name(), nalgebra::U1),
        }
    }
}

/// The inputs (torques, pivot acceleration) acting at time `t`: the seam for a
/// time-dependent drive.
///
/// Constant [`Inputs`] implement it (borrowed, no copy), and so does any closure
/// `Fn(f64) -> Inputs` (`t` in s) and [`Driven`](crate::drive::Driven), a pivot
/// [`Drive`](crate::drive::Drive) with torques of time.
pub trait InputsAt<D: Dim, S: DimName>
where
    DefaultAllocator: Allocator<D> + Allocator<S>,
{
    /// The inputs at time `t` (s).
    fn inputs_at(&self, t: f64) -> Cow<'_, Inputs<D, S>>;
}

impl<D: Dim, S: DimName> InputsAt<D, S> for Inputs<D, S>
where
    DefaultAllocator: Allocator<D> + Allocator<S>,
{
    fn inputs_at(&self, _t: f64) -> Cow<'_, Inputs<D, S>> {
        Cow::Borrowed(self)
    }
}

impl<D: Dim, S: DimName, F: Fn(f64) -> Inputs<D, S>> InputsAt<D, S> for F
where
    DefaultAllocator: Allocator<D> + Allocator<S>,
{
    fn inputs_at(&self, t: f64) -> Cow<'_, Inputs<D, S>> {
        Cow::Owned(self(t))
    }
}

/// An n-link chain's equations of motion in generalized coordinates `q`:
///
/// ```text
/// M(q) q̈ + c(q, q̇) + k(q) + d(q, p̈) = Q(q, q̇, σ)
/// ```
///
/// with `M` the mass matrix, `c` the terms quadratic in the rates, `k = ∂U/∂q` the
/// gravity terms, `d` the terms of the pivot acceleration and `Q` the non-conservative
/// generalized forces (torques and damping). This is the sympy reference's form
/// (`reference/README.md`); in the document's planar notation (eq 25)
/// `C = M`, `S θ̇² = −c`, `h = k`, `f = Q`.
///
/// Building blocks write into `&mut` outputs and assume the vectors have
/// [`dof`](Model::dof) entries (fixed-size models enforce it by type; dynamic ones
/// panic like nalgebra on a mismatch). [`accelerations`](Model::accelerations) is the
/// checked entry point: it validates sizes and finiteness and returns errors.
pub trait Model
where
    DefaultAllocator: ModelAlloc<Self::Links, Self::Dof, Self::Space>,
{
    /// Number of links as a dimension (`Const<N>` or `Dyn`).
    type Links: Dim;
    /// Number of generalized coordinates (`n` planar, `2n` spatial).
    type Dof: Dim;
    /// The pivot's space: `U2` planar (x, y), `U3` spatial (x, y, z).
    type Space: DimName;
    /// The angle coordinates `q` is written in ([`PlanarAngles`](crate::kinematics::PlanarAngles)
    /// or [`SphericalAngles`](crate::kinematics::SphericalAngles)): where the link
    /// geometry (directions, positions, `∂T/∂q`) comes from.
    type Chart: Chart<Space = Self::Space>;

    /// The chain's parameters.
    fn chain(&self) -> &Chain<Self::Links>;

    /// Number of generalized coordinates as a dimension.
    fn dof(&self) -> Self::Dof;

    /// Mass matrix `M(q)` (kg·m²), symmetric; positive definite away from singularities.
    fn mass_matrix(&self, q: &OVector<f64, Self::Dof>, out: &mut OMatrix<f64, Self::Dof, Self::Dof>);

    /// Velocity terms `c(q, q̇)` (N·m), homogeneous quadratic in `q̇`: Coriolis and
    /// centrifugal terms as they stand on the left-hand side.
    fn velocity_terms(
        &self,
        q: &OVector<f64, Self::Dof>,
        qd: &OVector<f64, Self::Dof>,
        out: &mut OVector<f64, Self::Dof>,
    );

    /// Gravity terms `k(q) = ∂U/∂q` (N·m).
    fn gravity_terms(&self, q: &OVector<f64, Self::Dof>, out: &mut OVector<f64, Self::Dof>);

    /// Pivot terms `d(q, p̈) = Σ_k m_k (∂r_k/∂q)ᵀ p̈` (N·m), linear in the pivot
    /// acceleration `p̈` (m/s²).
    fn pivot_terms(
        &self,
        q: &OVector<f64, Self::Dof>,
        pivot_acceleration: &OVector<f64, Self::Space>,
        out: &mut OVector<f64, Self::Dof>,
    );

    /// Non-conservative generalized forces `Q = σ − ∂D/∂q̇` (N·m): torques `σ` and the
    /// damping of the Rayleigh function `D = ½ Σ λ_i |u̇_i|²` (`u_i` link i's unit
    /// direction). Planar this is eq 26, `Q_i = σ_i − λ_i θ̇_i`.
    fn generalized_forces(
        &self,
        q: &OVector<f64, Self::Dof>,
        qd: &OVector<f64, Self::Dof>,
        torque: &OVector<f64, Self::Dof>,
        out: &mut OVector<f64, Self::Dof>,
    );

    /// Kinetic energy `T` (J) relative to the pivot (pivot at rest).
    fn kinetic_energy(&self, q: &OVector<f64, Self::Dof>, qd: &OVector<f64, Self::Dof>) -> f64;

    /// Potential energy `U = Σ m_i g (height of mass i above the pivot)` (J).
    fn potential_energy(&self, q: &OVector<f64, Self::Dof>) -> f64;

    /// Errors when the coordinates themselves are unusable at `q` (the spatial model's
    /// `sin θ_i = 0`). Planar models have no such states.
    fn check_configuration(&self, _q: &OVector<f64, Self::Dof>) -> Result<()> {
        Ok(())
    }

    /// Accelerations `q̈ = M⁻¹ (Q − c − k − d)` (rad/s²), by a symmetric
    /// positive-definite (Cholesky) solve.
    ///
    /// Errors: [`Error::LengthMismatch`] or [`Error::NonFinite`] for bad inputs,
    /// [`Error::SingularAngle`] at a coordinate singularity,
    /// [`Error::NotPositiveDefinite`] if the factorisation fails.
    fn accelerations(
        &self,
        q: &OVector<f64, Self::Dof>,
        qd: &OVector<f64, Self::Dof>,
        inputs: &Inputs<Self::Dof, Self::Space>,
        out: &mut OVector<f64, Self::Dof>,
    ) -> Result<()> {
        self.factor_and_solve(q, qd, inputs, out).map(|_| ())
    }

    /// The force side `F = Q − c − k − d` (N·m) of `M q̈ = F` from the building blocks,
    /// written into `out`.
    fn force_side(
        &self,
        q: &OVector<f64, Self::Dof>,
        qd: &OVector<f64, Self::Dof>,
        inputs: &Inputs<Self::Dof, Self::Space>,
        out: &mut OVector<f64, Self::Dof>,
    ) {
        let mut tmp = OVector::<f64, Self::Dof>::zeros_generic(self.dof(), nalgebra::U1);
        self.generalized_forces(q, qd, &inputs.torque, out);
        self.velocity_terms(q, qd, &mut tmp);
        *out -= &tmp;
        self.gravity_terms(q, &mut tmp);
        *out -= &tmp;
        self.pivot_terms(q, &inputs.pivot_acceleration, &mut tmp);
        *out -= &tmp;
    }

    /// The default route of [`accelerations`](Model::accelerations): checks the inputs
    /// and the configuration, factors `M` (Cholesky) and solves `M q̈ = F` into `out`;
    /// returns the factorisation for further solves with the same `M` (the Jacobians').
    fn factor_and_solve(
        &self,
        q: &OVector<f64, Self::Dof>,
        qd: &OVector<f64, Self::Dof>,
        inputs: &Inputs<Self::Dof, Self::Space>,
        out: &mut OVector<f64, Self::Dof>,
    ) -> Result<nalgebra::Cholesky<f64, Self::Dof>> {
        check_inputs(self.dof().value(), q, qd, inputs)?;
        self.check_configuration(q)?;
        let dof = self.dof();
        let mut mass = OMatrix::<f64, Self::Dof, Self::Dof>::zeros_generic(dof, dof);
        self.mass_matrix(q, &mut mass);
        self.force_side(q, qd, inputs, out);
        let cholesky = nalgebra::Cholesky::new(mass).ok_or(Error::NotPositiveDefinite)?;
        cholesky.solve_mut(out);
        if out.iter().all(|a| a.is_finite()) { Ok(cholesky) } else { Err(Error::NotPositiveDefinite) }
    }

    /// The gradient `∂T/∂q` of the kinetic energy at fixed rates `q̇` (N·m), written into
    /// `out`: the chart's [`Chart::kinetic_gradient`]. The canonical form's momentum
    /// equation needs it (`∂T/∂q = Ṁ q̇ − c`, but `∂M/∂q` is not part of the trait).
    fn kinetic_gradient(
        &self,
        q: &OVector<f64, Self::Dof>,
        qd: &OVector<f64, Self::Dof>,
        out: &mut OVector<f64, Self::Dof>,
    ) {
        Self::Chart::kinetic_gradient(self.chain(), q.as_slice(), qd.as_slice(), out.as_mut_slice());
    }

    /// Total mechanical energy `H = T + U` (J) relative to the pivot.
    fn energy(&self, q: &OVector<f64, Self::Dof>, qd: &OVector<f64, Self::Dof>) -> f64 {
        self.kinetic_energy(q, qd) + self.potential_energy(q)
    }

    /// No torque and a pivot at rest, sized for this model.
    fn zero_inputs(&self) -> Inputs<Self::Dof, Self::Space> {
        Inputs::zeros(self.dof())
    }
}

/// Checks that `q`, `q̇` and the inputs have `dof` entries and are finite.
///
/// Called by every model's [`Model::accelerations`], generated ones included.
pub fn check_inputs<D: Dim, S: DimName>(
    dof: usize,
    q: &OVector<f64, D>,
    qd: &OVector<f64, D>,
    inputs: &Inputs<D, S>,
) -> Result<()>
where
    DefaultAllocator: Allocator<D> + Allocator<S>,
{
    let vectors: [(&'static str, &[f64]); 4] = [
        ("q", q.as_slice()),
        ("qd", qd.as_slice()),
        ("torque", inputs.torque.as_slice()),
        ("pivot_acceleration", inputs.pivot_acceleration.as_slice()),
    ];
    for (what, v) in vectors {
        check_vector(what, v, if what == "pivot_acceleration" { S::dim() } else { dof })?;
    }
    Ok(())
}

/// Errors unless `v` has `expected` entries, all finite: [`Error::LengthMismatch`] or
/// [`Error::NonFinite`] naming `what` and the first bad entry. The one input check behind
/// every model's and system's.
pub(crate) fn check_vector(what: &'static str, v: &[f64], expected: usize) -> Result<()> {
    if v.len() != expected {
        return Err(Error::LengthMismatch { what, expected, got: v.len() });
    }
    non_finite(what, v).map_or(Ok(()), Err)
}

/// The first entry of `v` that is not finite, as [`Error::NonFinite`] naming `what`, its
/// index and its value; `None` when all are finite (`f64` or `f32` entries).
pub(crate) fn non_finite<T: Copy + Into<f64>>(what: &'static str, v: &[T]) -> Option<Error> {
    // Vectorised first: a scalar search costs a third of an O(n) evaluation (and was a
    // tenth of a batch's one-step RK4 call).
    if all_finite(v) {
        return None;
    }
    let index = v.iter().position(|&x| !x.into().is_finite())?;
    Some(Error::NonFinite { what, index, value: v[index].into() })
}

/// Whether every entry of `v` (`f64` or `f32`) is finite: `Σ 0·v_i` is zero when they all
/// are and NaN as soon as one is infinite or NaN. Summed in eight lanes without an early
/// exit, so that it vectorises; the cheap test before searching for the first bad entry.
#[inline]
pub(crate) fn all_finite<T: Copy + Into<f64>>(v: &[T]) -> bool {
    let mut lanes = [0.0f64; 8];
    let chunks = v.chunks_exact(8);
    for (lane, &x) in lanes.iter_mut().zip(chunks.remainder()) {
        *lane += x.into() * 0.0;
    }
    for chunk in chunks {
        for (lane, &x) in lanes.iter_mut().zip(chunk) {
            *lane += x.into() * 0.0;
        }
    }
    lanes.iter().all(|lane| *lane == 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn all_finite_and_non_finite_find_every_bad_entry_in_both_precisions() {
        for n in 0..27 {
            let good: Vec<f64> = (0..n).map(|i| [f64::MAX, -f64::MAX, 5e-324, -0.0, 1.5][i % 5]).collect();
            assert!(all_finite(&good), "n = {n}");
            let good32: Vec<f32> = (0..n).map(|i| [f32::MAX, -f32::MAX, 1e-45, -0.0, 1.5][i % 5]).collect();
            assert!(all_finite(&good32), "f32: n = {n}");
            for i in 0..n {
                for bad in [f64::INFINITY, f64::NEG_INFINITY, f64::NAN] {
                    let mut v = good.clone();
                    v[i] = bad;
                    assert!(!all_finite(&v), "n = {n}, {bad} at {i}");
                    let Some(Error::NonFinite { index, .. }) = non_finite("v", &v) else {
                        panic!("n = {n}, {bad} at {i} not found")
                    };
                    assert_eq!(index, i);
                    // The same in single precision.
                    let mut single = good32.clone();
                    single[i] = bad as f32;
                    assert!(!all_finite(&single), "f32: n = {n}, {bad} at {i}");
                }
            }
        }
    }
}
