//! Spherical angles: `θ_i` from the −z axis, `φ_i` the azimuth from +x (eqs 27–29),
//! `u_i = (sin θ_i cos φ_i, sin θ_i sin φ_i, −cos θ_i)`; singular where `sin θ_i = 0`.

use nalgebra::{DefaultAllocator, Dim, U3, Vector3, allocator::Allocator};

use super::Chart;
use crate::chain::Chain;
use crate::error::{Error, Result};

/// Below this `|sin θ_i|` a spatial (θ, φ) model refuses to compute accelerations.
///
/// The φ rows of the mass matrix scale with `sin θ_i`, so its condition number grows like
/// `1 / sin² θ_i`: at `1e-6` about twelve of sixteen digits are already gone.
pub const SINGULARITY_TOLERANCE: f64 = 1e-6;

/// [`Error::SingularAngle`] if `|sin θ|` of link `link` (1-based) is below
/// [`SINGULARITY_TOLERANCE`].
pub fn check_polar_angle(link: usize, theta: f64) -> Result<()> {
    check_polar_sin(link, theta, theta.sin())
}

/// [`check_polar_angle`] for a caller that already has `sin_theta = theta.sin()`, so the
/// sine is computed once (the code `pendulum-macros` generates).
pub fn check_polar_sin(link: usize, theta: f64, sin_theta: f64) -> Result<()> {
    let sin_theta = sin_theta.abs();
    if sin_theta < SINGULARITY_TOLERANCE {
        Err(Error::SingularAngle { link, theta, sin_theta, tolerance: SINGULARITY_TOLERANCE })
    } else {
        Ok(())
    }
}

/// The spatial chart: `q = (θ_1…θ_n, φ_1…φ_n)` (eq 30's order).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SphericalAngles;

/// One link's direction `u = (sin θ cos φ, sin θ sin φ, −cos θ)` at angles `(θ, φ)` and its
/// partial derivatives: everything the spatial models, the canonical form, the energy
/// ledger and the conversions to unit directions take from the chart.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SphericalLink {
    /// `u`.
    pub u: Vector3<f64>,
    /// `∂u/∂θ = e_θ = (cos θ cos φ, cos θ sin φ, sin θ)`, a unit vector.
    pub d_theta: Vector3<f64>,
    /// `∂u/∂φ = sin θ e_φ`.
    pub d_phi: Vector3<f64>,
    /// `e_φ = (−sin φ, cos φ, 0)`, the unit azimuthal vector.
    pub e_phi: Vector3<f64>,
    /// `sin θ`.
    pub sin_theta: f64,
    /// `cos θ`.
    pub cos_theta: f64,
}

impl SphericalLink {
    /// The link at angles `(θ, φ)` (rad).
    pub fn new(theta: f64, phi: f64) -> Self {
        let (st, ct) = theta.sin_cos();
        let (sp, cp) = phi.sin_cos();
        Self {
            u: Vector3::new(st * cp, st * sp, -ct),
            d_theta: Vector3::new(ct * cp, ct * sp, st),
            d_phi: Vector3::new(-st * sp, st * cp, 0.0),
            e_phi: Vector3::new(-sp, cp, 0.0),
            sin_theta: st,
            cos_theta: ct,
        }
    }

    /// `∂²u/∂θ² = −u` (computed when asked: the O(n²) loops of the models use only the
    /// first derivatives).
    pub fn d_theta2(&self) -> Vector3<f64> {
        let (st, ct, sp, cp) = self.scalars();
        Vector3::new(-st * cp, -st * sp, ct)
    }

    /// `∂²u/∂φ² = −sin θ (cos φ, sin φ, 0)`.
    pub fn d_phi2(&self) -> Vector3<f64> {
        let (st, _, sp, cp) = self.scalars();
        Vector3::new(-st * cp, -st * sp, 0.0)
    }

    /// `∂²u/∂θ∂φ = cos θ e_φ`.
    pub fn d_theta_phi(&self) -> Vector3<f64> {
        let (_, ct, sp, cp) = self.scalars();
        Vector3::new(-ct * sp, ct * cp, 0.0)
    }

    /// `(sin θ, cos θ, sin φ, cos φ)`, from the stored vectors (`e_φ = (−sin φ, cos φ, 0)`).
    fn scalars(&self) -> (f64, f64, f64, f64) {
        (self.sin_theta, self.cos_theta, -self.e_phi.x, self.e_phi.y)
    }

    /// Link `i` of the chain's `q = (θ_1…θ_n, φ_1…φ_n)`.
    pub fn of(q: &[f64], i: usize) -> Self {
        Self::new(q[i], q[q.len() / 2 + i])
    }

    /// `u̇ = ∂u/∂θ θ̇ + ∂u/∂φ φ̇` (1/s).
    pub fn velocity(&self, theta_dot: f64, phi_dot: f64) -> Vector3<f64> {
        self.d_theta * theta_dot + self.d_phi * phi_dot
    }

    /// `ü` at `q̈ = 0`: the part of the acceleration quadratic in the rates (1/s²).
    pub fn centripetal(&self, theta_dot: f64, phi_dot: f64) -> Vector3<f64> {
        self.d_theta2() * (theta_dot * theta_dot)
            + self.d_phi2() * (phi_dot * phi_dot)
            + self.d_theta_phi() * (2.0 * theta_dot * phi_dot)
    }

    /// `ü = ∂u/∂θ θ̈ + ∂u/∂φ φ̈ +` [`centripetal`](Self::centripetal) (1/s²).
    pub fn acceleration(&self, theta_dot: f64, phi_dot: f64, theta_ddot: f64, phi_ddot: f64) -> Vector3<f64> {
        self.d_theta * theta_ddot + self.d_phi * phi_ddot + self.centripetal(theta_dot, phi_dot)
    }

    /// `∂u̇/∂θ = ∂²u/∂θ² θ̇ + ∂²u/∂θ∂φ φ̇` and `∂u̇/∂φ = ∂²u/∂θ∂φ θ̇ + ∂²u/∂φ² φ̇`: how the
    /// link's velocity changes with its angles at fixed rates.
    pub fn velocity_gradient(&self, theta_dot: f64, phi_dot: f64) -> (Vector3<f64>, Vector3<f64>) {
        let (d_theta_phi, d_phi2) = (self.d_theta_phi(), self.d_phi2());
        (self.d_theta2() * theta_dot + d_theta_phi * phi_dot, d_theta_phi * theta_dot + d_phi2 * phi_dot)
    }

    /// The angle rates `(θ̇, φ̇) = (e_θ·w, e_φ·w / sin θ)` (rad/s) of a link rate `w = u̇`
    /// (the inverse of [`velocity`](Self::velocity); singular where `sin θ = 0`).
    pub fn rates(&self, w: &Vector3<f64>) -> (f64, f64) {
        (self.d_theta.dot(w), self.e_phi.dot(w) / self.sin_theta)
    }

    /// The angle accelerations of a link acceleration `ü` (rad/s²), inverting
    /// [`acceleration`](Self::acceleration):
    /// `θ̈ = e_θ·ü + φ̇² sin θ cos θ`, `φ̈ = (e_φ·ü − 2 θ̇ φ̇ cos θ) / sin θ`.
    pub fn angle_accelerations(&self, udd: &Vector3<f64>, theta_dot: f64, phi_dot: f64) -> (f64, f64) {
        (
            self.d_theta.dot(udd) + phi_dot * phi_dot * self.sin_theta * self.cos_theta,
            (self.e_phi.dot(udd) - 2.0 * theta_dot * phi_dot * self.cos_theta) / self.sin_theta,
        )
    }
}

impl SphericalAngles {
    /// The angles `θ = atan2(|u_xy|, −u_z) ∈ [0, π]`, `φ = atan2(u_y, u_x) ∈ (−π, π]` of a
    /// unit direction `u`.
    pub fn angles_of(u: &Vector3<f64>) -> (f64, f64) {
        (u.xy().norm().atan2(-u.z), u.y.atan2(u.x))
    }
}

impl Chart for SphericalAngles {
    type Space = U3;
    const COORDINATES: &'static [&'static str] = &["theta", "phi"];

    fn direction(q: &[f64], i: usize) -> Vector3<f64> {
        SphericalLink::of(q, i).u
    }

    fn link_velocity(q: &[f64], qd: &[f64], i: usize) -> Vector3<f64> {
        let n = q.len() / 2;
        SphericalLink::of(q, i).velocity(qd[i], qd[n + i])
    }

    fn link_acceleration(q: &[f64], qd: &[f64], qdd: &[f64], i: usize) -> Vector3<f64> {
        let n = q.len() / 2;
        SphericalLink::of(q, i).acceleration(qd[i], qd[n + i], qdd[i], qdd[n + i])
    }

    /// `∂T/∂θ_k = ∂u̇_k/∂θ_k · V_k`, `∂T/∂φ_k = ∂u̇_k/∂φ_k · V_k` with `V_k = Σ_j W_kj u̇_j`.
    fn kinetic_gradient<L: Dim>(chain: &Chain<L>, q: &[f64], qd: &[f64], out: &mut [f64])
    where
        DefaultAllocator: Allocator<L>,
    {
        let n = chain.links();
        assert_eq!(q.len(), 2 * n, "a spatial chain of {n} links has {} coordinates", 2 * n);
        let links: Vec<SphericalLink> = (0..n).map(|k| SphericalLink::of(q, k)).collect();
        let velocities: Vec<Vector3<f64>> = (0..n).map(|k| links[k].velocity(qd[k], qd[n + k])).collect();
        for (k, link) in links.iter().enumerate() {
            let v = (0..n).fold(Vector3::new(0.0, 0.0, 0.0), |v, j| v + velocities[j] * chain.weight(k, j));
            let (d_theta, d_phi) = link.velocity_gradient(qd[k], qd[n + k]);
            out[k] = d_theta.dot(&v);
            out[n + k] = d_phi.dot(&v);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    #[test]
    fn positions_follow_the_conventions() {
        let r = SphericalAngles::positions(&[1.0], &[FRAC_PI_2, FRAC_PI_2], &Vector3::zeros());
        assert!(r[0].x.abs() < 1e-15 && (r[0].y - 1.0).abs() < 1e-15 && r[0].z.abs() < 1e-15);
    }

    #[test]
    fn rates_and_accelerations_invert_the_link_motion() {
        let link = SphericalLink::new(0.8, -2.1);
        let (td, pd, tdd, pdd) = (0.4, -1.3, 2.0, 0.7);
        let (a, b) = link.rates(&link.velocity(td, pd));
        assert!((a - td).abs() < 1e-14 && (b - pd).abs() < 1e-14);
        let (a, b) = link.angle_accelerations(&link.acceleration(td, pd, tdd, pdd), td, pd);
        assert!((a - tdd).abs() < 1e-14 && (b - pdd).abs() < 1e-14);
        let (theta, phi) = SphericalAngles::angles_of(&link.u);
        assert!((theta - 0.8).abs() < 1e-15 && (phi + 2.1).abs() < 1e-15);
    }
}
