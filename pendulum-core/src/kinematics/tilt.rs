//! Tilt angles of a link in the frame turning with a circling pivot: `θ` in the plane of
//! the pivot's radius and the axis, `ψ` out of it (the relative equilibria's unknowns).

use nalgebra::Vector3;

/// `u = (cos ψ sin θ, sin ψ, −cos ψ cos θ)`: at `ψ = 0` the planar chart's direction in
/// the (x, z) plane.
pub(crate) fn direction(theta: f64, psi: f64) -> Vector3<f64> {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = psi.sin_cos();
    Vector3::new(cp * st, sp, -cp * ct)
}

/// The unit tangents `∂u/∂θ / cos ψ` and `∂u/∂ψ`, orthonormal and normal to `u`.
pub(crate) fn tangents(theta: f64, psi: f64) -> (Vector3<f64>, Vector3<f64>) {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = psi.sin_cos();
    (Vector3::new(ct, 0.0, st), Vector3::new(-sp * st, cp, sp * ct))
}
