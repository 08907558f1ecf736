//! The O(n) routes' Jacobians in the reference's angles: `PlanarTension`'s directly (it
//! implements `Derivatives` by the tangents of its solve), `Directions`' from its
//! Jacobian-vector products in unit directions through the chain rule of the angle charts:
//!
//! - in: `δu_i = J_α δα`, `δw_i = (∂w_i/∂α) δα + J_α δα̇` (planar `J = n_i`,
//!   `∂w/∂θ = −θ̇ u`; spatial `SphericalLink::velocity_gradient`);
//! - out, planar: `θ̈_i = n_i·ü_i`, so `δθ̈_i = n_i·δü_i − (u_i·ü_i) δθ_i`;
//! - out, spatial: `θ̈ = e_θ·ü + φ̇² sin θ cos θ`, `φ̈ = (e_φ·ü − 2 θ̇ φ̇ cos θ) / sin θ`,
//!   differentiated with `∂e_θ/∂θ = −u`, `∂e_θ/∂φ = ∂²u/∂θ∂φ`, `∂e_φ/∂φ = −(cos φ, sin φ, 0)`.
//!
//! (`Directions` takes no torques and its pivot follows a drive: only `∂q̈/∂q` and
//! `∂q̈/∂q̇` are compared.)

use anyhow::Result;
use nalgebra::{DMatrix, DVector, U2, U3, Vector3};
use pendulum_core::{Directions, Drive, kinematics::SphericalLink};

/// `q̈`, `∂q̈/∂q` and `∂q̈/∂q̇` of a planar `Directions` chain at angles `q`, rates `qd`.
pub(super) fn planar<Dr: Drive<U2>>(
    directions: &Directions<U2, Dr>,
    q: &[f64],
    qd: &[f64],
) -> Result<(DVector<f64>, DMatrix<f64>, DMatrix<f64>)> {
    let n = q.len();
    let x = directions.from_angles(q, qd)?;
    let mut udd = vec![0.0; 2 * n];
    directions.accelerations(0.0, &x, &mut udd, None)?;
    let u = |i: usize| [q[i].sin(), -q[i].cos()];
    let nv = |i: usize| [q[i].cos(), q[i].sin()];
    let dot = |a: [f64; 2], b: &[f64]| a[0] * b[0] + a[1] * b[1];
    let qdd = DVector::from_fn(n, |i, _| dot(nv(i), &udd[2 * i..2 * i + 2]));
    let (mut jq, mut jqd) = (DMatrix::zeros(n, n), DMatrix::zeros(n, n));
    let mut dudd = vec![0.0; 2 * n];
    for (by_rate, out) in [(false, &mut jq), (true, &mut jqd)] {
        for c in 0..n {
            let mut dx = DVector::zeros(4 * n);
            let (uc, nc) = (u(c), nv(c));
            for k in 0..2 {
                if by_rate {
                    dx[2 * n + 2 * c + k] = nc[k];
                } else {
                    dx[2 * c + k] = nc[k];
                    dx[2 * n + 2 * c + k] = -qd[c] * uc[k];
                }
            }
            directions.jvp(0.0, &x, &dx, &mut dudd)?;
            for i in 0..n {
                let mut v = dot(nv(i), &dudd[2 * i..2 * i + 2]);
                if !by_rate && i == c {
                    v -= dot(u(i), &udd[2 * i..2 * i + 2]);
                }
                out[(i, c)] = v;
            }
        }
    }
    Ok((qdd, jq, jqd))
}

/// `q̈`, `∂q̈/∂q` and `∂q̈/∂q̇` of a spatial `Directions` chain at spherical angles
/// `q = (θ, φ)`, rates `qd`.
pub(super) fn spatial<Dr: Drive<U3>>(
    directions: &Directions<U3, Dr>,
    q: &[f64],
    qd: &[f64],
) -> Result<(DVector<f64>, DMatrix<f64>, DMatrix<f64>)> {
    let dof = q.len();
    let n = dof / 2;
    let x = directions.from_spherical(q, qd)?;
    let mut udd = vec![0.0; 3 * n];
    directions.accelerations(0.0, &x, &mut udd, None)?;
    let links: Vec<SphericalLink> = (0..n).map(|i| SphericalLink::of(q, i)).collect();
    let at = |v: &[f64], i: usize| Vector3::new(v[3 * i], v[3 * i + 1], v[3 * i + 2]);
    let angles: Vec<(f64, f64)> =
        (0..n).map(|i| links[i].angle_accelerations(&at(&udd, i), qd[i], qd[n + i])).collect();
    let qdd = DVector::from_fn(dof, |r, _| if r < n { angles[r].0 } else { angles[r - n].1 });
    let (mut jq, mut jqd) = (DMatrix::zeros(dof, dof), DMatrix::zeros(dof, dof));
    let mut dudd = vec![0.0; 3 * n];
    for (by_rate, out) in [(false, &mut jq), (true, &mut jqd)] {
        for c in 0..dof {
            let (k, beta) = (c % n, c / n);
            let f = &links[k];
            let jacobian = if beta == 0 { f.d_theta } else { f.d_phi };
            let (dw_angle, dw_rate) = {
                let (t, p) = f.velocity_gradient(qd[k], qd[n + k]);
                (if beta == 0 { t } else { p }, jacobian)
            };
            let mut dx = DVector::zeros(6 * n);
            for m in 0..3 {
                if by_rate {
                    dx[3 * n + 3 * k + m] = dw_rate[m];
                } else {
                    dx[3 * k + m] = jacobian[m];
                    dx[3 * n + 3 * k + m] = dw_angle[m];
                }
            }
            directions.jvp(0.0, &x, &dx, &mut dudd)?;
            for (i, link) in links.iter().enumerate() {
                let (a, da) = (at(&udd, i), at(&dudd, i));
                // This column's change of link i's own angles and rates.
                let on = i == k;
                let d =
                    |is_rate: bool, b: usize| if on && by_rate == is_rate && beta == b { 1.0 } else { 0.0 };
                let (dth, dph, dthd, dphd) = (d(false, 0), d(false, 1), d(true, 0), d(true, 1));
                let (s, co) = (link.sin_theta, link.cos_theta);
                let (thd, phd) = (qd[i], qd[n + i]);
                let de_theta = -link.u * dth + link.d_theta_phi() * dph;
                let de_phi = Vector3::new(-link.e_phi.y, link.e_phi.x, 0.0) * dph;
                let dtheta = de_theta.dot(&a)
                    + link.d_theta.dot(&da)
                    + 2.0 * phd * dphd * s * co
                    + phd * phd * (co * co - s * s) * dth;
                let dphi = (de_phi.dot(&a) + link.e_phi.dot(&da) - 2.0 * co * (dthd * phd + thd * dphd)
                    + 2.0 * thd * phd * s * dth
                    - angles[i].1 * co * dth)
                    / s;
                out[(i, c)] = dtheta;
                out[(n + i, c)] = dphi;
            }
        }
    }
    Ok((qdd, jq, jqd))
}
