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

use nalgebra::{DVector, DefaultAllocator, Dim, DimName, Dyn, OVector, U1, Vector3};

use crate::integrate::System;
use crate::spatial::Frame;
use crate::{Drive, Driven, Inputs, InputsAt, Model, ModelAlloc, Result, TorqueAt};

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
/// accelerations `q̈`.
///
/// Uses the documented coordinates: planar `q = (θ_1…θ_n)`, `u_i = (sin θ_i, −cos θ_i)`,
/// `ü_i = (cos θ_i, sin θ_i) θ̈_i + (−sin θ_i, cos θ_i) θ̇_i²`; spatial
/// `q = (θ_1…θ_n, φ_1…φ_n)`, `u_i = (sin θ cos φ, sin θ sin φ, −cos θ)`,
/// `ü = u_θ θ̈ + u_φ φ̈ + u_θθ θ̇² + u_φφ φ̇² + 2 u_θφ θ̇ φ̇`.
///
/// # Panics
/// If the model's space is neither 2- nor 3-dimensional.
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
    let n = c.links();
    let weight = |i: usize| c.tail_masses()[i] * c.lengths()[i];
    let mut rate = OVector::<f64, M::Space>::zeros();
    match M::Space::dim() {
        2 => {
            for i in 0..n {
                let (s, co) = q[i].sin_cos();
                let w = weight(i);
                let rate2 = qd[i] * qd[i];
                rate[0] += w * (co * qdd[i] - s * rate2);
                rate[1] += w * (s * qdd[i] + co * rate2);
            }
        }
        3 => {
            let mut sum = Vector3::zeros();
            for i in 0..n {
                let frame = Frame::new(q[i], q[n + i]);
                sum += frame.acceleration(qd[i], qd[n + i], qdd[i], qdd[n + i]) * weight(i);
            }
            for j in 0..3 {
                rate[j] = sum[j];
            }
        }
        d => panic!("pivot_momentum_rate: models live in 2 or 3 dimensions, got {d}"),
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

/// Energy exchanged since the start of a run (J): the integrals of the [`Powers`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Ledger {
    /// `W_drive = ∫ P_drive dt`, work done by the pivot on the chain.
    pub drive: f64,
    /// `W_torque = ∫ q̇ᵀσ dt`, work done by the torques.
    pub torque: f64,
    /// `E_damped = ∫ 2D dt ≥ 0`, energy dissipated by damping.
    pub damped: f64,
}

impl Ledger {
    /// `W_drive + W_torque − E_damped`, J: what `H_in(t) − H_in(t0)` should be.
    pub fn net(&self) -> f64 {
        self.drive + self.torque - self.damped
    }

    /// The energy exchanged from the ledger `start` to this one, J.
    pub fn since(&self, start: &Ledger) -> Ledger {
        Ledger {
            drive: self.drive - start.drive,
            torque: self.torque - start.torque,
            damped: self.damped - start.damped,
        }
    }
}

/// How well the energy balance closes between two states of an [`Accounted`] (or
/// [`AccountedDirections`](crate::AccountedDirections)) run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Balance {
    /// `H_in(t0)`, J.
    pub initial_energy: f64,
    /// `H_in(t)`, J.
    pub energy: f64,
    /// The energy exchanged from `t0` to `t` (the ledger at `t` minus that at `t0`).
    pub ledger: Ledger,
    /// `H_in(t) − H_in(t0) − (W_drive + W_torque − E_damped)`, J; zero for the exact flow.
    pub residual: f64,
    /// `|residual| / (|H_in(t0)| + |H_in(t)| + |W_drive| + |W_torque| + E_damped)`.
    pub relative: f64,
}

impl Balance {
    /// The balance between the inertial-frame energies `initial_energy = H_in(t0)` and
    /// `energy = H_in(t)` (J) and the ledgers `start` (at `t0`) and `end` (at `t`).
    pub fn between(initial_energy: f64, energy: f64, start: &Ledger, end: &Ledger) -> Self {
        let ledger = end.since(start);
        let residual = energy - initial_energy - ledger.net();
        let scale = initial_energy.abs()
            + energy.abs()
            + ledger.drive.abs()
            + ledger.torque.abs()
            + ledger.damped.abs();
        Self {
            initial_energy,
            energy,
            ledger,
            residual,
            relative: residual.abs() / scale.max(f64::MIN_POSITIVE),
        }
    }
}

/// A driven chain as a first-order system whose state carries its energy ledger:
/// ```text
/// x = (q, q̇, W_drive, W_torque, E_damped),
/// x' = (q̇, q̈, P_drive, P_torque, P_damping)
/// ```
/// of dimension `2·dof + 3` (`Dyn`). The integrator computes the work integrals with the
/// same method and step as the motion, so `H_in(t) − H_in(t0) − (W_drive + W_torque −
/// E_damped)` ([`balance`](Accounted::balance)) measures the integration error of the
/// run (round-off for a converged Gauss–Legendre run), not a quadrature error.
///
/// The `(q, q̇)` part of the solution is exactly what the integrator gives for
/// `FirstOrder::with_inputs(model, Driven::new(drive, torque))`: the ledger does not
/// feed back.
///
/// In code generic over the model, add `DefaultAllocator: SystemAlloc<Dyn>` next to the
/// `ModelAlloc` bound: without it the compiler tries to satisfy the integrators'
/// allocator bounds from the model's where-clause (dimension `M::Dof`) and reports a type
/// mismatch with `Dyn`.
#[derive(Debug, Clone)]
pub struct Accounted<M, Dr, T> {
    model: M,
    inputs: Driven<Dr, T>,
}

impl<M: Model, Dr: Drive<M::Space>, T: TorqueAt<M::Dof>> Accounted<M, Dr, T>
where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>,
{
    /// `model` with its pivot moving as `drive` and the torques `torque` acting.
    pub fn new(model: M, drive: Dr, torque: T) -> Self {
        Self { model, inputs: Driven::new(drive, torque) }
    }

    /// The model.
    pub fn model(&self) -> &M {
        &self.model
    }

    /// The drive and torques.
    pub fn inputs(&self) -> &Driven<Dr, T> {
        &self.inputs
    }

    /// The initial state `(q, q̇, 0, 0, 0)`: an empty ledger.
    pub fn state(&self, q: &OVector<f64, M::Dof>, qd: &OVector<f64, M::Dof>) -> DVector<f64> {
        DVector::from_iterator(2 * q.len() + 3, q.iter().chain(qd.iter()).copied().chain([0.0; 3]))
    }

    /// Splits a state into `(q, q̇, ledger)`.
    #[allow(clippy::type_complexity)] // The tuple is the plainest reading.
    pub fn split(&self, x: &DVector<f64>) -> (OVector<f64, M::Dof>, OVector<f64, M::Dof>, Ledger) {
        let dof = self.model.dof();
        let n = dof.value();
        let q = OVector::from_iterator_generic(dof, U1, x.iter().take(n).copied());
        let qd = OVector::from_iterator_generic(dof, U1, x.iter().skip(n).take(n).copied());
        let ledger = Ledger { drive: x[2 * n], torque: x[2 * n + 1], damped: x[2 * n + 2] };
        (q, qd, ledger)
    }

    /// The inertial-frame energy [`inertial_energy`] of the state `x` at time `t` (J).
    pub fn energy(&self, t: f64, x: &DVector<f64>) -> f64 {
        let (q, qd, _) = self.split(x);
        let drive = self.inputs.drive();
        inertial_energy(&self.model, &q, &qd, &drive.position(t), &drive.velocity(t))
    }

    /// The [`Powers`] at `(t, x)`. Errors of [`Model::accelerations`] pass through.
    pub fn powers(&self, t: f64, x: &DVector<f64>) -> Result<Powers> {
        self.evaluate(t, x).map(|(.., powers)| powers)
    }

    /// `(q̇, q̈, powers)` at `(t, x)`: what [`System::rhs`] and [`powers`](Self::powers)
    /// both need.
    #[allow(clippy::type_complexity)] // The tuple is the plainest reading.
    fn evaluate(
        &self,
        t: f64,
        x: &DVector<f64>,
    ) -> Result<(OVector<f64, M::Dof>, OVector<f64, M::Dof>, Powers)> {
        let (q, qd, _) = self.split(x);
        let inputs = self.inputs.inputs_at(t);
        let mut qdd = OVector::zeros_generic(self.model.dof(), U1);
        self.model.accelerations(&q, &qd, &inputs, &mut qdd)?;
        let powers = powers(&self.model, &q, &qd, &qdd, &inputs, &self.inputs.drive().velocity(t));
        Ok((qd, qdd, powers))
    }

    /// The energy balance from `(t0, x0)` to `(t, x)` (see [`Balance`]).
    pub fn balance(&self, t0: f64, x0: &DVector<f64>, t: f64, x: &DVector<f64>) -> Balance {
        let (.., start) = self.split(x0);
        let (.., end) = self.split(x);
        Balance::between(self.energy(t0, x0), self.energy(t, x), &start, &end)
    }
}

impl<M: Model, Dr: Drive<M::Space>, T: TorqueAt<M::Dof>> System for Accounted<M, Dr, T>
where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>,
{
    type Dim = Dyn;

    fn dim(&self) -> Dyn {
        Dyn(2 * self.model.dof().value() + 3)
    }

    /// `x = (q, q̇, ledger)`, `q' = q̇`.
    fn second_order(&self) -> Option<usize> {
        Some(self.model.dof().value())
    }

    /// `(q̇, q̈, P_drive, P_torque, P_damping)`; errors of [`Model::accelerations`] pass
    /// through.
    fn rhs(&self, t: f64, x: &DVector<f64>, out: &mut DVector<f64>) -> Result<()> {
        let (qd, qdd, p) = self.evaluate(t, x)?;
        let n = qd.len();
        for i in 0..n {
            out[i] = qd[i];
            out[n + i] = qdd[i];
        }
        out[2 * n] = p.drive;
        out[2 * n + 1] = p.torque;
        out[2 * n + 2] = p.damping;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::{DVector, Dyn, Vector2};

    use super::*;
    use crate::{Chain, ConstantTorque, Harmonic, Planar, Spatial};

    /// `dH_in/dt` by central differences along the flow equals the power sum.
    fn check_power_balance<M: Model, Dr: Drive<M::Space>>(
        model: M,
        drive: Dr,
        q: &[f64],
        qd: &[f64],
        sigma: &[f64],
    ) where
        DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>,
    {
        let dof = model.dof();
        let vector = |v: &[f64]| OVector::<f64, M::Dof>::from_row_slice_generic(dof, U1, v);
        let system = Accounted::new(model, drive, ConstantTorque(vector(sigma)));
        let x = system.state(&vector(q), &vector(qd));
        let mut f = x.clone();
        for t in [0.0, 0.37, 1.1] {
            system.rhs(t, &x, &mut f).unwrap();
            let eps = 1e-5;
            let h = |s: f64| system.energy(t + s, &(&x + &f * s));
            let rate = (h(eps) - h(-eps)) / (2.0 * eps);
            let p = system.powers(t, &x).unwrap();
            let scale = p.drive.abs() + p.torque.abs() + p.damping.abs() + 1.0;
            assert!((rate - p.net()).abs() < 1e-7 * scale, "t={t}: dH/dt = {rate}, powers {p:?}");
            assert!(p.damping >= 0.0);
        }
    }

    #[test]
    fn planar_inertial_energy_changes_at_the_power_of_drive_torque_and_damping() {
        let chain = Chain::<Dyn>::new(&[1.0, 0.7, 1.3], &[0.5, 0.8, 0.4], 9.81).unwrap();
        let model = Planar::new(chain.with_damping(&[0.2, 0.1, 0.3]).unwrap());
        let drive = Harmonic::new(Vector2::new(0.3, 1.0), 0.05, 11.0, 0.4).unwrap();
        check_power_balance(model, drive, &[0.4, -1.0, 2.0], &[1.0, -0.5, 2.5], &[0.3, -0.2, 0.5]);
    }

    #[test]
    fn spatial_inertial_energy_changes_at_the_power_of_drive_torque_and_damping() {
        let chain = Chain::<Dyn>::new(&[1.0, 0.7], &[0.5, 0.8], 9.81).unwrap();
        let model = Spatial::new(chain.with_damping(&[0.2, 0.3]).unwrap());
        let drive = crate::Circle::new(0.1, 6.0).unwrap();
        check_power_balance(
            model,
            drive,
            &[0.4, 1.9, 0.3, -2.0],
            &[1.0, -0.5, 2.5, 0.7],
            &[0.3, -0.2, 0.5, 0.1],
        );
    }

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
