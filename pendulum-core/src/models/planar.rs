//! The generic planar chain (any number of links): eqs 18–26 of the document, as derived.

use nalgebra::{DefaultAllocator, Dim, Dyn, OMatrix, OVector, U2, allocator::Allocator};

use crate::chain::Chain;
use crate::jacobians::Derivatives;
use crate::kinematics::PlanarAngles;
use crate::model::{Inputs, Model};

/// A planar chain in absolute link angles `θ_i` from the downward vertical (eqs 1–2),
/// for any number of links `L` (`Dyn` by default; `Const<N>` gives a fixed-size generic).
///
/// Coordinates `q = (θ_1, …, θ_n)` (rad), rates `q̇ = (θ̇_1, …, θ̇_n)` (rad/s). With
/// `W_ij = M_max(i,j) l_i l_j` (eq 10 tail masses):
/// - mass matrix `C_ij = W_ij cos(θ_i − θ_j)` (eq 22, confirmed by the reference);
/// - velocity terms `c_i = Σ_j W_ij sin(θ_i − θ_j) θ̇_j²`, i.e. `S_ij = W_ij sin(θ_j − θ_i)`
///   for all i, j (eq 23 as printed has the sign of the lower triangle wrong;
///   `reference/ERRATA.md`);
/// - gravity `h_i = M_i g l_i sin θ_i` (eq 21);
/// - pivot `d_i = M_i l_i (p̈_x cos θ_i + p̈_y sin θ_i)`;
/// - forces `f_i = σ_i − λ_i θ̇_i` (eq 26).
#[derive(Debug, Clone, PartialEq)]
pub struct Planar<L: Dim = Dyn>
where
    DefaultAllocator: Allocator<L>,
{
    chain: Chain<L>,
}

impl<L: Dim> Planar<L>
where
    DefaultAllocator: Allocator<L>,
{
    /// The planar model of `chain`.
    pub fn new(chain: Chain<L>) -> Self {
        Self { chain }
    }
}

impl<L: Dim> From<Chain<L>> for Planar<L>
where
    DefaultAllocator: Allocator<L>,
{
    fn from(chain: Chain<L>) -> Self {
        Self::new(chain)
    }
}

impl<L: Dim> Model for Planar<L>
where
    DefaultAllocator: Allocator<L> + Allocator<L, L> + Allocator<U2>,
{
    type Links = L;
    type Dof = L;
    type Space = U2;
    type Chart = PlanarAngles;

    fn chain(&self) -> &Chain<L> {
        &self.chain
    }

    fn dof(&self) -> L {
        self.chain.link_dim()
    }

    fn mass_matrix(&self, q: &OVector<f64, L>, out: &mut OMatrix<f64, L, L>) {
        let n = self.chain.links();
        for i in 0..n {
            out[(i, i)] = self.chain.weight(i, i);
            for j in 0..i {
                let v = self.chain.weight(i, j) * (q[i] - q[j]).cos();
                out[(i, j)] = v;
                out[(j, i)] = v;
            }
        }
    }

    fn velocity_terms(&self, q: &OVector<f64, L>, qd: &OVector<f64, L>, out: &mut OVector<f64, L>) {
        let n = self.chain.links();
        for i in 0..n {
            out[i] = (0..n).map(|j| self.chain.weight(i, j) * (q[i] - q[j]).sin() * qd[j] * qd[j]).sum();
        }
    }

    fn gravity_terms(&self, q: &OVector<f64, L>, out: &mut OVector<f64, L>) {
        let c = &self.chain;
        for i in 0..c.links() {
            out[i] = c.tail_masses()[i] * c.gravity() * c.lengths()[i] * q[i].sin();
        }
    }

    fn pivot_terms(&self, q: &OVector<f64, L>, a: &OVector<f64, U2>, out: &mut OVector<f64, L>) {
        let c = &self.chain;
        for i in 0..c.links() {
            let (s, co) = q[i].sin_cos();
            out[i] = c.tail_masses()[i] * c.lengths()[i] * (a[0] * co + a[1] * s);
        }
    }

    fn generalized_forces(
        &self,
        _q: &OVector<f64, L>,
        qd: &OVector<f64, L>,
        torque: &OVector<f64, L>,
        out: &mut OVector<f64, L>,
    ) {
        let c = &self.chain;
        for i in 0..c.links() {
            out[i] = torque[i] - c.damping()[i] * qd[i];
        }
    }

    /// `T = ½ Σ_ij W_ij cos(θ_i − θ_j) θ̇_i θ̇_j` (eq 11).
    fn kinetic_energy(&self, q: &OVector<f64, L>, qd: &OVector<f64, L>) -> f64 {
        let n = self.chain.links();
        let mut t = 0.0;
        for i in 0..n {
            t += 0.5 * self.chain.weight(i, i) * qd[i] * qd[i];
            for j in 0..i {
                t += self.chain.weight(i, j) * (q[i] - q[j]).cos() * qd[i] * qd[j];
            }
        }
        t
    }

    /// `U = −Σ_i M_i g l_i cos θ_i` (eq 12).
    fn potential_energy(&self, q: &OVector<f64, L>) -> f64 {
        let c = &self.chain;
        -(0..c.links()).map(|i| c.tail_masses()[i] * c.gravity() * c.lengths()[i] * q[i].cos()).sum::<f64>()
    }
}

/// With `Δ_ab = θ_a − θ_b`: `∂M_ab/∂θ_x = −W_ab sin Δ_ab (δ_ax − δ_bx)`, and of
/// `F_a = σ_a − λ_a θ̇_a − Σ_j W_aj sin Δ_aj θ̇_j² − M_a l_a (g sin θ_a + p̈_x cos θ_a + p̈_y sin θ_a)`:
/// `∂F_a/∂θ_x = W_ax cos Δ_ax θ̇_x²` (x ≠ a),
/// `∂F_a/∂θ_a = −Σ_j W_aj cos Δ_aj θ̇_j² − M_a l_a ((g + p̈_y) cos θ_a − p̈_x sin θ_a)`,
/// `∂F_a/∂θ̇_x = −λ_a δ_ax − 2 W_ax sin Δ_ax θ̇_x`, `∂F_a/∂p̈ = −M_a l_a (cos θ_a, sin θ_a)`.
impl<L: Dim> Derivatives for Planar<L>
where
    DefaultAllocator: Allocator<L> + Allocator<L, L> + Allocator<U2> + Allocator<L, U2>,
{
    fn mass_matrix_partials(&self, q: &OVector<f64, L>, v: &OVector<f64, L>, out: &mut OMatrix<f64, L, L>) {
        let n = self.chain.links();
        for a in 0..n {
            let mut diagonal = 0.0;
            for x in 0..n {
                if x != a {
                    let w = self.chain.weight(a, x) * (q[a] - q[x]).sin();
                    out[(a, x)] = w * v[x];
                    diagonal -= w * v[x];
                }
            }
            out[(a, a)] = diagonal;
        }
    }

    fn force_jacobians(
        &self,
        q: &OVector<f64, L>,
        qd: &OVector<f64, L>,
        inputs: &Inputs<L, U2>,
        dq: &mut OMatrix<f64, L, L>,
        dqd: &mut OMatrix<f64, L, L>,
        dp: &mut OMatrix<f64, L, U2>,
    ) {
        let c = &self.chain;
        let n = c.links();
        let p = &inputs.pivot_acceleration;
        for a in 0..n {
            let (s, co) = q[a].sin_cos();
            let moment = c.tail_masses()[a] * c.lengths()[a];
            let mut diagonal = -moment * ((c.gravity() + p[1]) * co - p[0] * s);
            for x in 0..n {
                if x == a {
                    continue;
                }
                let w = c.weight(a, x);
                let (sd, cd) = (q[a] - q[x]).sin_cos();
                let rate = qd[x];
                dq[(a, x)] = w * cd * rate * rate;
                diagonal -= w * cd * rate * rate;
                dqd[(a, x)] = -2.0 * w * sd * rate;
            }
            dq[(a, a)] = diagonal;
            dqd[(a, a)] = -c.damping()[a];
            dp[(a, 0)] = -moment * co;
            dp[(a, 1)] = -moment * s;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::Error;
    use approx::assert_relative_eq;
    use nalgebra::{DVector, Vector2};

    #[test]
    fn single_pendulum_accelerates_like_minus_g_over_l_sin_theta() {
        let model = Planar::new(Chain::<Dyn>::new(&[2.0], &[0.5], 9.81).unwrap());
        let q = DVector::from_vec(vec![0.3]);
        let qd = DVector::from_vec(vec![1.7]);
        let mut a = DVector::zeros(1);
        model.accelerations(&q, &qd, &model.zero_inputs(), &mut a).unwrap();
        assert_relative_eq!(a[0], -9.81 / 0.5 * 0.3f64.sin(), max_relative = 1e-14);
    }

    #[test]
    fn vertical_pivot_acceleration_adds_to_gravity() {
        // p̈ = (0, a) acts like gravity g + a in the pivot's frame.
        let chain = Chain::<Dyn>::new(&[1.0, 2.0], &[1.0, 0.5], 9.81).unwrap();
        let lifted = Planar::new(Chain::new(&[1.0, 2.0], &[1.0, 0.5], 9.81 + 3.0).unwrap());
        let model = Planar::new(chain);
        let q = DVector::from_vec(vec![0.4, -1.1]);
        let qd = DVector::from_vec(vec![0.2, 2.0]);
        let inputs = Inputs { torque: DVector::zeros(2), pivot_acceleration: Vector2::new(0.0, 3.0) };
        let (mut a, mut b) = (DVector::zeros(2), DVector::zeros(2));
        model.accelerations(&q, &qd, &inputs, &mut a).unwrap();
        lifted.accelerations(&q, &qd, &lifted.zero_inputs(), &mut b).unwrap();
        assert_relative_eq!(a, b, max_relative = 1e-13);
    }

    #[test]
    fn bad_state_is_an_error_naming_the_entry() {
        let model = Planar::new(Chain::<Dyn>::uniform(2, 1.0, 1.0, 9.81).unwrap());
        let mut a = DVector::zeros(2);
        let q = DVector::from_vec(vec![0.0, f64::NAN]);
        let err = model.accelerations(&q, &DVector::zeros(2), &model.zero_inputs(), &mut a).unwrap_err();
        assert!(matches!(err, Error::NonFinite { what: "q", index: 1, .. }), "{err}");
        let short = DVector::zeros(1);
        let err = model.accelerations(&short, &DVector::zeros(2), &model.zero_inputs(), &mut a).unwrap_err();
        assert_eq!(err, Error::LengthMismatch { what: "q", expected: 2, got: 1 });
    }
}
