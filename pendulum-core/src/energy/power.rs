//! Energy accounting of a driven, damped, torqued chain in the inertial frame: the energy
//! `H = T + U`, the powers of the drive, the torques and the damping, and [`Accounted`],
//! a system that integrates those powers along the run so the balance can be checked.
//!
//! With `r_k = p + ρ_k` the inertial position of mass `k` (`ρ_k = Σ_{i≤k} l_i u_i` relative
//! to the pivot) and `P = Σ_k m_k ρ̇_k = Σ_i M_i l_i u̇_i` (tail masses `M_i`, eq 10):
//! ```text
//! T_in = T + ṗ·P + ½ M_tot |ṗ|²,        U_in = U + M_tot g p_up,
//! dH_in/dt = P_drive + P_torque − P_damping,
//! P_drive = ṗ·F_pivot,   F_pivot = Ṗ + M_tot p̈ + M_tot g ê_up = Σ m_k r̈_k + M_tot g ê_up,
//! P_torque = q̇ᵀσ,       P_damping = q̇ᵀ ∂D/∂q̇ = 2D = Σ_i λ_i |u̇_i|²,
//! ```
//! where `T`, `U` are the model's pivot-frame energies and `ê_up` the vertical (y planar,
//! z spatial). Derivation: along the model's equations `dH/dt = q̇ᵀ(Q − d)` and
//! `q̇ᵀd = p̈·P`; differentiating the two extra terms gives the rest. `F_pivot` is the force
//! the pivot exerts on the chain (the rods' internal forces do no net work).

use nalgebra::{DefaultAllocator, DimName, OVector, U1};

use crate::kinematics::Chart;
use crate::model::{Inputs, Model, ModelAlloc};

/// `P = Σ_k m_k ρ̇_k = Σ_i M_i l_i u̇_i` (kg·m/s): the chain's momentum relative to the
/// pivot, in the model's space.
///
/// Computed from the model's own pivot terms, `P_j = q̇ᵀ d(q, e_j)` (because
/// `d(q, a) = Σ_k m_k (∂ρ_k/∂q)ᵀ a`), so it holds for any [`Model`].
pub fn pivot_momentum<M: Model>(
    model: &M,
    q: &OVector<f64, M::Dof>,
    qd: &OVector<f64, M::Dof>,
) -> OVector<f64, M::Space>
where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>,
{
    let mut momentum = OVector::<f64, M::Space>::zeros();
    let mut unit = OVector::<f64, M::Space>::zeros();
    let mut d = OVector::<f64, M::Dof>::zeros_generic(model.dof(), U1);
    for j in 0..M::Space::dim() {
        unit.fill(0.0);
        unit[j] = 1.0;
        model.pivot_terms(q, &unit, &mut d);
        momentum[j] = qd.dot(&d);
    }
    momentum
}

/// `Ṗ = Σ_k m_k ρ̈_k = Σ_i M_i l_i ü_i` (N): the rate of [`pivot_momentum`], given the
/// accelerations `q̈`, with the link accelerations `ü_i` from the model's chart
/// ([`Chart::link_acceleration`]).
pub fn pivot_momentum_rate<M: Model>(
    model: &M,
    q: &OVector<f64, M::Dof>,
    qd: &OVector<f64, M::Dof>,
    qdd: &OVector<f64, M::Dof>,
) -> OVector<f64, M::Space>
where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>,
{
    let c = model.chain();
    let mut rate = OVector::<f64, M::Space>::zeros();
    for i in 0..c.links() {
        let weight = c.tail_masses()[i] * c.lengths()[i];
        rate += M::Chart::link_acceleration(q.as_slice(), qd.as_slice(), qdd.as_slice(), i) * weight;
    }
    rate
}

/// The vertical unit vector `ê_up` of the model's space (its last axis).
fn up<S: DimName>() -> OVector<f64, S>
where
    DefaultAllocator: nalgebra::allocator::Allocator<S>,
{
    let mut e = OVector::<f64, S>::zeros();
    e[S::dim() - 1] = 1.0;
    e
}

/// Total mechanical energy in the inertial frame (J), pivot at `p` (m) moving at `ṗ`
/// (m/s):
/// ```text
/// H_in = T + ṗ·P + ½ M_tot |ṗ|² + U + M_tot g p_up
/// ```
/// with `T`, `U` the model's pivot-frame energies and `P` the [`pivot_momentum`].
pub fn inertial_energy<M: Model>(
    model: &M,
    q: &OVector<f64, M::Dof>,
    qd: &OVector<f64, M::Dof>,
    pivot_position: &OVector<f64, M::Space>,
    pivot_velocity: &OVector<f64, M::Space>,
) -> f64
where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>,
{
    let c = model.chain();
    let total = c.tail_masses()[0];
    let height = pivot_position[M::Space::dim() - 1];
    model.energy(q, qd)
        + pivot_velocity.dot(&pivot_momentum(model, q, qd))
        + 0.5 * total * pivot_velocity.norm_squared()
        + total * c.gravity() * height
}

/// The force the pivot exerts on the chain (N):
/// `F_pivot = Σ_k m_k r̈_k + M_tot g ê_up = Ṗ + M_tot p̈ + M_tot g ê_up`.
pub fn pivot_force<M: Model>(
    model: &M,
    q: &OVector<f64, M::Dof>,
    qd: &OVector<f64, M::Dof>,
    qdd: &OVector<f64, M::Dof>,
    pivot_acceleration: &OVector<f64, M::Space>,
) -> OVector<f64, M::Space>
where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>,
{
    let c = model.chain();
    let total = c.tail_masses()[0];
    pivot_momentum_rate(model, q, qd, qdd)
        + pivot_acceleration * total
        + up::<M::Space>() * (total * c.gravity())
}

/// The powers (W) that change the inertial-frame energy:
/// `dH_in/dt = drive + torque − damping`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Powers {
    /// `P_drive = ṗ·F_pivot`, the power the moving pivot injects.
    pub drive: f64,
    /// `P_torque = q̇ᵀσ`.
    pub torque: f64,
    /// `P_damping = q̇ᵀ ∂D/∂q̇ = 2D ≥ 0`, the power the damping dissipates (planar
    /// `Σ λ_i θ̇_i²`, spatial `Σ λ_i (θ̇_i² + sin²θ_i φ̇_i²)`).
    pub damping: f64,
}

impl Powers {
    /// `dH_in/dt = drive + torque − damping`, W.
    pub fn net(&self) -> f64 {
        self.drive + self.torque - self.damping
    }
}

/// The [`Powers`] at one instant, given the accelerations `q̈` the inputs produce.
///
/// `P_damping = −q̇ᵀ Q(q, q̇, σ = 0)` from the model's generalized forces, so it holds for
/// any [`Model`].
pub fn powers<M: Model>(
    model: &M,
    q: &OVector<f64, M::Dof>,
    qd: &OVector<f64, M::Dof>,
    qdd: &OVector<f64, M::Dof>,
    inputs: &Inputs<M::Dof, M::Space>,
    pivot_velocity: &OVector<f64, M::Space>,
) -> Powers
where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>,
{
    let dof = model.dof();
    let zero = OVector::<f64, M::Dof>::zeros_generic(dof, U1);
    let mut forces = zero.clone();
    model.generalized_forces(q, qd, &zero, &mut forces);
    let force = pivot_force(model, q, qd, qdd, &inputs.pivot_acceleration);
    Powers { drive: pivot_velocity.dot(&force), torque: qd.dot(&inputs.torque), damping: -qd.dot(&forces) }
}

#[cfg(test)]
mod tests {
    use nalgebra::{DVector, Dyn, Vector2};

    use super::*;
    use crate::chain::Chain;
    use crate::models::planar::Planar;

    #[test]
    fn pivot_momentum_rate_is_the_derivative_of_the_momentum() {
        let model = Planar::new(Chain::<Dyn>::new(&[1.0, 2.0], &[0.5, 1.5], 9.81).unwrap());
        let (q, qd, qdd) = (
            DVector::from_vec(vec![0.3, -1.2]),
            DVector::from_vec(vec![2.0, 0.4]),
            DVector::from_vec(vec![-1.0, 3.0]),
        );
        let eps = 1e-5;
        let p = |s: f64| pivot_momentum(&model, &(&q + &qd * s + &qdd * (0.5 * s * s)), &(&qd + &qdd * s));
        let fd: Vector2<f64> = (p(eps) - p(-eps)) / (2.0 * eps);
        let exact = pivot_momentum_rate(&model, &q, &qd, &qdd);
        assert!((fd - exact).norm() < 1e-8 * exact.norm(), "{fd} vs {exact}");
    }
}
