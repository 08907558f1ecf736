//! Planar angles: `θ_i` from the downward vertical, `u_i = (sin θ_i, −cos θ_i)` (eqs 1–2).

use nalgebra::{DefaultAllocator, Dim, U2, Vector2, allocator::Allocator};

use super::Chart;
use crate::chain::Chain;

/// The planar chart: `q = (θ_1…θ_n)`, `u_i = (sin θ_i, −cos θ_i)` in the (x, y) plane with
/// y up, so `∂u_i/∂θ_i = n_i = (cos θ_i, sin θ_i)` and `∂²u_i/∂θ_i² = −u_i`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PlanarAngles;

impl PlanarAngles {
    /// The angle and rate `(θ, θ̇)` of a link with unit direction `u` and rate `w = u̇`:
    /// `θ = atan2(u_x, −u_y)` (rad, in (−π, π]) and `θ̇ = n·w` (rad/s).
    pub fn from_direction(u: [f64; 2], w: [f64; 2]) -> (f64, f64) {
        let theta = u[0].atan2(-u[1]);
        let (s, c) = theta.sin_cos();
        (theta, c * w[0] + s * w[1])
    }

    /// The angle acceleration `θ̈ = n·ü` (rad/s²) of a link with unit direction `u` and
    /// acceleration `ü` (since `ü = θ̈ n − θ̇² u` and `n = (−u_y, u_x)`).
    pub fn angle_acceleration(u: [f64; 2], udd: [f64; 2]) -> f64 {
        -u[1] * udd[0] + u[0] * udd[1]
    }
}

impl Chart for PlanarAngles {
    type Space = U2;
    const COORDINATES: &'static [&'static str] = &["theta"];

    fn direction(q: &[f64], i: usize) -> Vector2<f64> {
        let (s, c) = q[i].sin_cos();
        Vector2::new(s, -c)
    }

    /// `u̇_i = θ̇_i (cos θ_i, sin θ_i)`.
    fn link_velocity(q: &[f64], qd: &[f64], i: usize) -> Vector2<f64> {
        let (s, c) = q[i].sin_cos();
        Vector2::new(qd[i] * c, qd[i] * s)
    }

    /// `ü_i = (cos θ_i, sin θ_i) θ̈_i + (−sin θ_i, cos θ_i) θ̇_i²`.
    fn link_acceleration(q: &[f64], qd: &[f64], qdd: &[f64], i: usize) -> Vector2<f64> {
        let (s, c) = q[i].sin_cos();
        let rate2 = qd[i] * qd[i];
        Vector2::new(c * qdd[i] - s * rate2, s * qdd[i] + c * rate2)
    }

    /// `∂T/∂θ_k = −Σ_j W_kj sin(θ_k − θ_j) θ̇_k θ̇_j` (`T = ½ Σ_ij W_ij cos(θ_i − θ_j) θ̇_i θ̇_j`).
    fn kinetic_gradient<L: Dim>(chain: &Chain<L>, q: &[f64], qd: &[f64], out: &mut [f64])
    where
        DefaultAllocator: Allocator<L>,
    {
        let n = chain.links();
        assert_eq!(q.len(), n, "a planar chain of {n} links has {n} coordinates");
        for k in 0..n {
            let sum: f64 = (0..n).map(|j| chain.weight(k, j) * (q[k] - q[j]).sin() * qd[j]).sum();
            out[k] = -qd[k] * sum;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    #[test]
    fn positions_follow_the_conventions() {
        let r = PlanarAngles::positions(&[1.0, 2.0], &[FRAC_PI_2, 0.0], &Vector2::new(0.5, 0.0));
        assert!((r[0].x - 1.5).abs() < 1e-15 && r[0].y.abs() < 1e-15);
        assert!((r[1].x - 1.5).abs() < 1e-15 && (r[1].y + 2.0).abs() < 1e-15);
    }

    #[test]
    fn direction_round_trips_through_the_angle() {
        let (theta, rate) = (2.5, -0.7);
        let (u, w) =
            (PlanarAngles::direction(&[theta], 0), PlanarAngles::link_velocity(&[theta], &[rate], 0));
        let (t, r) = PlanarAngles::from_direction([u.x, u.y], [w.x, w.y]);
        assert!((t - theta).abs() < 1e-15 && (r - rate).abs() < 1e-15);
        let a = PlanarAngles::link_acceleration(&[theta], &[rate], &[3.0], 0);
        assert!((PlanarAngles::angle_acceleration([u.x, u.y], [a.x, a.y]) - 3.0).abs() < 1e-14);
    }
}
