//! The generic spatial chain in spherical angles (θ, φ): the document's eq 30, as derived.

use nalgebra::{
    DefaultAllocator, Dim, DimMul, DimProd, Dyn, OMatrix, OVector, U2, U3, Vector3, allocator::Allocator,
};

use crate::chain::Chain;
use crate::error::Result;
use crate::jacobians::Derivatives;
use crate::kinematics::SphericalLink;
use crate::kinematics::{Chart, SphericalAngles, check_polar_angle};
use crate::model::{Inputs, Model};

/// A spatial chain in spherical angles: `θ_i` from the −z axis, `φ_i` the azimuth from
/// +x (eqs 27–29), for any number of links `L`.
///
/// Coordinates are ordered as the document's block form (eq 30):
/// `q = (θ_1, …, θ_n, φ_1, …, φ_n)`. With link direction `u_i = (sin θ_i cos φ_i,
/// sin θ_i sin φ_i, −cos θ_i)` and `W_ij = M_max(i,j) l_i l_j`, the kinetic energy is
/// `T = ½ Σ_ij W_ij u̇_i·u̇_j`, so with `J_a = ∂u/∂q_a`:
/// - mass matrix `M_ab = W_ij J_a·J_b` — the blocks A11, A12, A21, A22 of eqs 31–34;
/// - velocity terms `c_a = Σ_j W_ij J_a·ü_j|_{q̈=0}`, where `ü_j|_{q̈=0} = −u_j θ̇_j² +
///   ∂²u_j/∂φ_j² φ̇_j² + 2 ∂²u_j/∂θ_j∂φ_j θ̇_j φ̇_j`; eqs 35–39 print some of these
///   wrongly (`reference/ERRATA.md`);
/// - gravity `k_θi = M_i g l_i sin θ_i` (eq 40), `k_φi = 0`;
/// - pivot `d_a = M_i l_i J_a·p̈`;
/// - forces `Q_θi = σ_θi − λ_i θ̇_i`, `Q_φi = σ_φi − λ_i sin²θ_i φ̇_i` (Rayleigh
///   `D = ½ Σ λ_i |u̇_i|²`, the 3D analogue of eq 26).
///
/// These coordinates are singular where `sin θ_i = 0` (a link straight down, where a
/// chain rests): [`Model::accelerations`](crate::Model::accelerations) then returns [`Error::SingularAngle`](crate::Error::SingularAngle).
#[derive(Debug, Clone, PartialEq)]
pub struct Spatial<L: Dim = Dyn>
where
    DefaultAllocator: Allocator<L>,
{
    chain: Chain<L>,
}

impl<L: Dim> Spatial<L>
where
    DefaultAllocator: Allocator<L>,
{
    /// The spatial model of `chain`.
    pub fn new(chain: Chain<L>) -> Self {
        Self { chain }
    }
}

impl<L: Dim> From<Chain<L>> for Spatial<L>
where
    DefaultAllocator: Allocator<L>,
{
    fn from(chain: Chain<L>) -> Self {
        Self::new(chain)
    }
}

impl<L> Spatial<L>
where
    L: Dim + DimMul<U2>,
    DefaultAllocator: Allocator<L> + Allocator<DimProd<L, U2>>,
{
    fn frames(&self, q: &OVector<f64, DimProd<L, U2>>) -> Vec<SphericalLink> {
        (0..self.chain.links()).map(|i| SphericalLink::of(q.as_slice(), i)).collect()
    }
}

impl<L> Model for Spatial<L>
where
    L: Dim + DimMul<U2>,
    DefaultAllocator:
        Allocator<L> + Allocator<DimProd<L, U2>> + Allocator<DimProd<L, U2>, DimProd<L, U2>> + Allocator<U3>,
{
    type Links = L;
    type Dof = DimProd<L, U2>;
    type Space = U3;
    type Chart = SphericalAngles;

    fn chain(&self) -> &Chain<L> {
        &self.chain
    }

    fn dof(&self) -> Self::Dof {
        self.chain.link_dim().mul(U2)
    }

    fn mass_matrix(&self, q: &OVector<f64, Self::Dof>, out: &mut OMatrix<f64, Self::Dof, Self::Dof>) {
        let n = self.chain.links();
        let f = self.frames(q);
        for i in 0..n {
            for j in 0..n {
                let w = self.chain.weight(i, j);
                out[(i, j)] = w * f[i].d_theta.dot(&f[j].d_theta);
                out[(i, n + j)] = w * f[i].d_theta.dot(&f[j].d_phi);
                out[(n + i, j)] = w * f[i].d_phi.dot(&f[j].d_theta);
                out[(n + i, n + j)] = w * f[i].d_phi.dot(&f[j].d_phi);
            }
        }
    }

    fn velocity_terms(
        &self,
        q: &OVector<f64, Self::Dof>,
        qd: &OVector<f64, Self::Dof>,
        out: &mut OVector<f64, Self::Dof>,
    ) {
        let n = self.chain.links();
        let f = self.frames(q);
        let acc: Vec<Vector3<f64>> = (0..n).map(|j| f[j].centripetal(qd[j], qd[n + j])).collect();
        for i in 0..n {
            let (mut ct, mut cp) = (0.0, 0.0);
            for (j, a) in acc.iter().enumerate() {
                let w = self.chain.weight(i, j);
                ct += w * f[i].d_theta.dot(a);
                cp += w * f[i].d_phi.dot(a);
            }
            out[i] = ct;
            out[n + i] = cp;
        }
    }

    fn gravity_terms(&self, q: &OVector<f64, Self::Dof>, out: &mut OVector<f64, Self::Dof>) {
        let c = &self.chain;
        let n = c.links();
        for i in 0..n {
            out[i] = c.tail_masses()[i] * c.gravity() * c.lengths()[i] * q[i].sin();
            out[n + i] = 0.0;
        }
    }

    fn pivot_terms(
        &self,
        q: &OVector<f64, Self::Dof>,
        a: &OVector<f64, U3>,
        out: &mut OVector<f64, Self::Dof>,
    ) {
        let c = &self.chain;
        let n = c.links();
        let a = Vector3::new(a[0], a[1], a[2]);
        for (i, f) in self.frames(q).iter().enumerate() {
            let ml = c.tail_masses()[i] * c.lengths()[i];
            out[i] = ml * f.d_theta.dot(&a);
            out[n + i] = ml * f.d_phi.dot(&a);
        }
    }

    fn generalized_forces(
        &self,
        q: &OVector<f64, Self::Dof>,
        qd: &OVector<f64, Self::Dof>,
        torque: &OVector<f64, Self::Dof>,
        out: &mut OVector<f64, Self::Dof>,
    ) {
        let c = &self.chain;
        let n = c.links();
        for i in 0..n {
            let s = q[i].sin();
            out[i] = torque[i] - c.damping()[i] * qd[i];
            out[n + i] = torque[n + i] - c.damping()[i] * s * s * qd[n + i];
        }
    }

    /// `T = ½ Σ_k m_k |v_k|²` with `v_k = Σ_{j≤k} l_j u̇_j` (eq 48 as derived), from the chart.
    fn kinetic_energy(&self, q: &OVector<f64, Self::Dof>, qd: &OVector<f64, Self::Dof>) -> f64 {
        SphericalAngles::kinetic_energy(&self.chain, q.as_slice(), qd.as_slice())
    }

    /// `U = −Σ_i M_i g l_i cos θ_i` (eq 12, unchanged in 3D).
    fn potential_energy(&self, q: &OVector<f64, Self::Dof>) -> f64 {
        let c = &self.chain;
        -(0..c.links()).map(|i| c.tail_masses()[i] * c.gravity() * c.lengths()[i] * q[i].cos()).sum::<f64>()
    }

    fn check_configuration(&self, q: &OVector<f64, Self::Dof>) -> Result<()> {
        for i in 0..self.chain.links() {
            check_polar_angle(i + 1, q[i])?;
        }
        Ok(())
    }
}

/// Link `i`'s angle `α` (0 = θ, 1 = φ) is coordinate `i + α n`. With `J_α = ∂u/∂α`,
/// `H_αβ = ∂²u/∂α∂β` and, for rates `v`, `w_j = Σ_α J_α(j) v_αj`:
/// `Σ_b ∂M_ab/∂q_x v_b = δ_ik H_αβ(i)·Σ_j W_ij w_j + W_ik J_α(i)·∂w_k/∂β` for `a = (i, α)`,
/// `x = (k, β)`. With `z_j = ü_j|_{q̈=0}`, `c_a = J_α(i)·Σ_j W_ij z_j` and
/// `k_a + d_a = M_i l_i J_α(i)·(p̈ + g ẑ)`, the same product rule gives `∂F/∂q`, `∂F/∂q̇`
/// (`z_k` by its angles and rates, `centripetal_partials`) and `∂F/∂p̈ = −M_i l_i J_α(i)`;
/// `Q_φi = σ_φi − λ_i sin²θ_i φ̇_i` adds `−2 λ_i sin θ_i cos θ_i φ̇_i` by `θ_i`.
impl<L> Derivatives for Spatial<L>
where
    L: Dim + DimMul<U2>,
    DefaultAllocator: Allocator<L>
        + Allocator<DimProd<L, U2>>
        + Allocator<DimProd<L, U2>, DimProd<L, U2>>
        + Allocator<U3>
        + Allocator<DimProd<L, U2>, U3>,
{
    fn mass_matrix_partials(
        &self,
        q: &OVector<f64, Self::Dof>,
        v: &OVector<f64, Self::Dof>,
        out: &mut OMatrix<f64, Self::Dof, Self::Dof>,
    ) {
        let n = self.chain.links();
        let f = self.frames(q);
        let w: Vec<Vector3<f64>> = (0..n).map(|j| f[j].velocity(v[j], v[n + j])).collect();
        let grad: Vec<[Vector3<f64>; 2]> = (0..n)
            .map(|k| {
                let (t, p) = f[k].velocity_gradient(v[k], v[n + k]);
                [t, p]
            })
            .collect();
        for i in 0..n {
            let sum: Vector3<f64> = (0..n).map(|j| w[j] * self.chain.weight(i, j)).sum();
            for alpha in 0..2 {
                let ja = jacobian(&f[i], alpha);
                for k in 0..n {
                    let wik = self.chain.weight(i, k);
                    for beta in 0..2 {
                        let mut value = wik * ja.dot(&grad[k][beta]);
                        if k == i {
                            value += second(&f[i], alpha, beta).dot(&sum);
                        }
                        out[(i + alpha * n, k + beta * n)] = value;
                    }
                }
            }
        }
    }

    fn force_jacobians(
        &self,
        q: &OVector<f64, Self::Dof>,
        qd: &OVector<f64, Self::Dof>,
        inputs: &Inputs<Self::Dof, U3>,
        dq: &mut OMatrix<f64, Self::Dof, Self::Dof>,
        dqd: &mut OMatrix<f64, Self::Dof, Self::Dof>,
        dp: &mut OMatrix<f64, Self::Dof, U3>,
    ) {
        let c = &self.chain;
        let n = c.links();
        let f = self.frames(q);
        let p = &inputs.pivot_acceleration;
        let lift = Vector3::new(p[0], p[1], p[2] + c.gravity());
        let z: Vec<Vector3<f64>> = (0..n).map(|j| f[j].centripetal(qd[j], qd[n + j])).collect();
        let partials: Vec<_> = (0..n).map(|k| centripetal_partials(&f[k], qd[k], qd[n + k])).collect();
        for i in 0..n {
            let moment = c.tail_masses()[i] * c.lengths()[i];
            let load: Vector3<f64> =
                (0..n).map(|j| z[j] * c.weight(i, j)).sum::<Vector3<f64>>() + lift * moment;
            for alpha in 0..2 {
                let a = i + alpha * n;
                let ja = jacobian(&f[i], alpha);
                for (k, (by_angle, by_rate)) in partials.iter().enumerate() {
                    let wik = c.weight(i, k);
                    for beta in 0..2 {
                        let x = k + beta * n;
                        let mut value = -wik * ja.dot(&by_angle[beta]);
                        if k == i {
                            value -= second(&f[i], alpha, beta).dot(&load);
                        }
                        dq[(a, x)] = value;
                        dqd[(a, x)] = -wik * ja.dot(&by_rate[beta]);
                    }
                }
                for axis in 0..3 {
                    dp[(a, axis)] = -moment * ja[axis];
                }
            }
            let (s, co, lambda) = (f[i].sin_theta, f[i].cos_theta, c.damping()[i]);
            dq[(n + i, i)] -= 2.0 * lambda * s * co * qd[n + i];
            dqd[(i, i)] -= lambda;
            dqd[(n + i, n + i)] -= lambda * s * s;
        }
    }
}

/// `J_α = ∂u/∂α` of one link (`α` 0 = θ, 1 = φ).
fn jacobian(f: &SphericalLink, alpha: usize) -> Vector3<f64> {
    if alpha == 0 { f.d_theta } else { f.d_phi }
}

/// `H_αβ = ∂²u/∂α∂β` of one link.
fn second(f: &SphericalLink, alpha: usize, beta: usize) -> Vector3<f64> {
    match alpha + beta {
        0 => f.d_theta2(),
        1 => f.d_theta_phi(),
        _ => f.d_phi2(),
    }
}

/// The partial derivatives of `z = ü|_{q̈=0} = H_θθ θ̇² + H_φφ φ̇² + 2 H_θφ θ̇ φ̇` (1/s²) by
/// the link's angles `(θ, φ)` and by its rates `(θ̇, φ̇)`, from the third derivatives
/// `∂³u/∂θ³ = −J_θ`, `∂³u/∂θ²∂φ = ∂³u/∂φ³ = −J_φ`, `∂³u/∂θ∂φ² = −cos θ (cos φ, sin φ, 0)`.
fn centripetal_partials(f: &SphericalLink, td: f64, pd: f64) -> ([Vector3<f64>; 2], [Vector3<f64>; 2]) {
    let theta_phi2 = Vector3::new(f.e_phi.y, -f.e_phi.x, 0.0) * -f.cos_theta;
    let by_angle = [
        -f.d_theta * (td * td) + theta_phi2 * (pd * pd) - f.d_phi * (2.0 * td * pd),
        -f.d_phi * (td * td + pd * pd) + theta_phi2 * (2.0 * td * pd),
    ];
    let (tt, tp, pp) = (f.d_theta2(), f.d_theta_phi(), f.d_phi2());
    let by_rate = [(tt * td + tp * pd) * 2.0, (pp * pd + tp * td) * 2.0];
    (by_angle, by_rate)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::Error;
    use approx::assert_relative_eq;
    use nalgebra::DVector;

    fn single(theta: f64, phi: f64, theta_dot: f64, phi_dot: f64) -> Result<DVector<f64>> {
        let model = Spatial::new(Chain::<Dyn>::new(&[1.5], &[0.8], 9.81).unwrap());
        let q = DVector::from_vec(vec![theta, phi]);
        let qd = DVector::from_vec(vec![theta_dot, phi_dot]);
        let mut a = DVector::zeros(2);
        model.accelerations(&q, &qd, &model.zero_inputs(), &mut a).map(|()| a)
    }

    #[test]
    fn spherical_pendulum_matches_its_textbook_equations() {
        // θ̈ = sinθ cosθ φ̇² − (g/l) sinθ,  φ̈ = −2 cotθ θ̇ φ̇.
        let (th, ph, thd, phd) = (0.9, 2.0, 0.7, -1.3);
        let a = single(th, ph, thd, phd).unwrap();
        assert_relative_eq!(
            a[0],
            th.sin() * th.cos() * phd * phd - 9.81 / 0.8 * th.sin(),
            max_relative = 1e-13
        );
        assert_relative_eq!(a[1], -2.0 * thd * phd / th.tan(), max_relative = 1e-13);
    }

    #[test]
    fn fixed_size_generic_agrees_with_dynamic() {
        use nalgebra::{Const, SVector};
        let masses = [1.0, 0.3, 2.0];
        let lengths = [0.5, 1.0, 0.7];
        let fixed = Spatial::new(Chain::<Const<3>>::new(&masses, &lengths, 9.81).unwrap());
        let dynamic = Spatial::new(Chain::<Dyn>::new(&masses, &lengths, 9.81).unwrap());
        let q = [0.4, 1.0, 2.5, 0.1, -2.0, 3.0];
        let qd = [1.0, -0.5, 0.3, 2.0, 0.7, -1.1];
        let mut af = SVector::<f64, 6>::zeros();
        let mut ad = DVector::zeros(6);
        fixed.accelerations(&SVector::from(q), &SVector::from(qd), &fixed.zero_inputs(), &mut af).unwrap();
        dynamic
            .accelerations(
                &DVector::from_row_slice(&q),
                &DVector::from_row_slice(&qd),
                &dynamic.zero_inputs(),
                &mut ad,
            )
            .unwrap();
        assert_relative_eq!(af.as_slice(), ad.as_slice(), max_relative = 1e-14);
    }

    #[test]
    fn hanging_straight_down_is_a_singular_angle_error() {
        for theta in [0.0, 1e-9, std::f64::consts::PI] {
            let err = single(theta, 0.3, 0.0, 0.0).unwrap_err();
            assert!(matches!(err, Error::SingularAngle { link: 1, .. }), "{err}");
        }
        assert!(single(1e-3, 0.3, 0.0, 0.0).is_ok());
    }
}
