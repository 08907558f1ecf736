//! The energy ledger of a run: [`Accounted`] integrates the powers of drive, torques and
//! damping along the motion, so that `H_in(t) − H_in(t0) − (W_drive + W_torque − E_damped)`
//! measures the integration error. One ledger for every representation; what differs is
//! only who supplies the powers ([`Powered`]: chains in angles and in unit directions).

use nalgebra::{DVector, DefaultAllocator, Dim, DimName, Dyn, OVector, U1, allocator::Allocator};

use crate::drive::{Drive, Driven, TorqueAt};
use crate::energy::power::{Powers, inertial_energy, powers};
use crate::error::{Error, Result};
use crate::integrate::{Constrained, System};
use crate::lanes::Lane;
use crate::model::{InputsAt, Model, ModelAlloc};
use crate::models::directions::Directions;
use crate::systems::first_order::FirstOrder;

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

/// How well the energy balance closes between two states of an [`Accounted`] run.
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

/// A motion whose energy exchange can be accounted: its first-order flow (the state without
/// the ledger, as a slice), the powers at each instant and its inertial-frame energy.
///
/// Implemented for a model in angles with its drive and torques
/// (`FirstOrder<M, Driven<Dr, T>>`, state `(q, q̇)`) and for a chain in unit directions
/// ([`Directions`], state `(u, w)`).
pub trait Powered {
    /// Length of the motion's state.
    fn motion_len(&self) -> usize;

    /// [`System::second_order`] of the motion: where the rates start in its state.
    fn second_order(&self) -> Option<usize>;

    /// Writes the motion's `x'` at `(t, x)` into `out` (both [`motion_len`](Self::motion_len)
    /// long, checked by the caller) and returns the [`Powers`] there.
    fn flow_and_powers(&self, t: f64, x: &[f64], out: &mut [f64]) -> Result<Powers>;

    /// The inertial-frame energy `H_in = T + U` (J) of the motion's state `x` at time `t`.
    fn inertial_energy(&self, t: f64, x: &[f64]) -> f64;
}

/// A motion ([`Powered`]) as a first-order system whose state carries its energy ledger:
/// ```text
/// x = (motion, W_drive, W_torque, E_damped),
/// x' = (motion', P_drive, P_torque, P_damping)
/// ```
/// of dimension `motion_len + 3` (`Dyn`): for a model in angles `x = (q, q̇, ledger)`
/// ([`new`](Accounted::new)), for a chain in unit directions `x = (u, w, ledger)`
/// ([`of`](Accounted::of); no torques there, `W_torque` stays 0). The integrator computes
/// the work integrals with the same method and step as the motion, so
/// `H_in(t) − H_in(t0) − (W_drive + W_torque − E_damped)` ([`balance`](Accounted::balance))
/// measures the integration error of the run (round-off for a converged Gauss–Legendre
/// run), not a quadrature error.
///
/// The motion's part of the solution is exactly what the integrator gives for the motion
/// alone (for angles `FirstOrder::with_inputs(model, Driven::new(drive, torque))`): the
/// ledger does not feed back. A constrained motion's projection
/// ([`Constrained::project`]) leaves the ledger as it is.
///
/// In code generic over the model, add `DefaultAllocator: SystemAlloc<Dyn>` next to the
/// `ModelAlloc` bound: without it the compiler tries to satisfy the integrators'
/// allocator bounds from the model's where-clause (dimension `M::Dof`) and reports a type
/// mismatch with `Dyn`.
#[derive(Debug, Clone)]
pub struct Accounted<P> {
    motion: P,
}

/// The ledger of a chain in unit link directions: the name of earlier releases, kept for
/// one release (construct it with [`Accounted::of`]).
pub type AccountedDirections<S, Dr> = Accounted<Directions<S, Dr>>;

/// Length of the ledger at the end of an [`Accounted`] state.
pub(crate) const LEDGER_LEN: usize = 3;

impl<P: Powered> Accounted<P> {
    /// The motion with its ledger.
    pub fn of(motion: P) -> Self {
        Self { motion }
    }

    /// The motion.
    pub fn motion_system(&self) -> &P {
        &self.motion
    }

    /// Length of the motion's own state (without the ledger).
    pub fn motion_len(&self) -> usize {
        self.motion.motion_len()
    }

    /// The initial state: the motion's state and an empty ledger.
    ///
    /// Errors: [`Error::LengthMismatch`] when `motion` is not
    /// [`motion_len`](Self::motion_len) long.
    pub fn start(&self, motion: &[f64]) -> Result<DVector<f64>> {
        let expected = self.motion_len();
        if motion.len() != expected {
            return Err(Error::LengthMismatch { what: "motion", expected, got: motion.len() });
        }
        Ok(DVector::from_iterator(expected + LEDGER_LEN, motion.iter().copied().chain([0.0; LEDGER_LEN])))
    }

    /// The ledger of a state (J).
    pub fn ledger(&self, x: &DVector<f64>) -> Ledger {
        let m = self.motion_len();
        Ledger { drive: x[m], torque: x[m + 1], damped: x[m + 2] }
    }

    /// The inertial-frame energy `H_in = T + U` of the state `x` at time `t` (J).
    pub fn energy(&self, t: f64, x: &DVector<f64>) -> f64 {
        self.motion.inertial_energy(t, &x.as_slice()[..self.motion_len()])
    }

    /// The [`Powers`] at `(t, x)`. Errors of the motion's flow pass through.
    pub fn powers(&self, t: f64, x: &DVector<f64>) -> Result<Powers> {
        self.check_len("state", x.len())?;
        let mut flow = vec![0.0; self.motion_len()];
        self.motion.flow_and_powers(t, &x.as_slice()[..flow.len()], &mut flow)
    }

    /// The energy balance from `(t0, x0)` to `(t, x)` (see [`Balance`]).
    pub fn balance(&self, t0: f64, x0: &DVector<f64>, t: f64, x: &DVector<f64>) -> Balance {
        Balance::between(self.energy(t0, x0), self.energy(t, x), &self.ledger(x0), &self.ledger(x))
    }

    fn check_len(&self, what: &'static str, got: usize) -> Result<()> {
        let expected = self.motion_len() + LEDGER_LEN;
        if got == expected { Ok(()) } else { Err(Error::LengthMismatch { what, expected, got }) }
    }
}

impl<P: Powered> System for Accounted<P> {
    type Dim = Dyn;

    fn dim(&self) -> Dyn {
        Dyn(self.motion_len() + LEDGER_LEN)
    }

    /// `x = (motion, ledger)`: the motion's own.
    fn second_order(&self) -> Option<usize> {
        self.motion.second_order()
    }

    /// `(motion', P_drive, P_torque, P_damping)`. Errors: those of the motion's flow, and
    /// [`Error::LengthMismatch`] for a state or output of the wrong length.
    fn rhs(&self, t: f64, x: &DVector<f64>, out: &mut DVector<f64>) -> Result<()> {
        self.check_len("state", x.len())?;
        self.check_len("out", out.len())?;
        let len = self.motion_len();
        // The motion's part in place: no copy of the state, nothing allocated per call.
        let p = self.motion.flow_and_powers(t, &x.as_slice()[..len], &mut out.as_mut_slice()[..len])?;
        out[len] = p.drive;
        out[len + 1] = p.torque;
        out[len + 2] = p.damping;
        Ok(())
    }
}

/// A model in angles with its pivot drive and torques: state `(q, q̇)`.
impl<M: Model, Dr: Drive<M::Space>, T: TorqueAt<M::Dof>> Powered for FirstOrder<M, Driven<Dr, T>>
where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>,
{
    fn motion_len(&self) -> usize {
        2 * self.model().dof().value()
    }

    fn second_order(&self) -> Option<usize> {
        Some(self.model().dof().value())
    }

    /// `(q̇, q̈)` and the powers of [`powers`].
    fn flow_and_powers(&self, t: f64, x: &[f64], out: &mut [f64]) -> Result<Powers> {
        let model = self.model();
        let (q, qd) = split_angles(model, x);
        let inputs = self.inputs().inputs_at(t);
        let mut qdd = OVector::zeros_generic(model.dof(), U1);
        model.accelerations(&q, &qd, &inputs, &mut qdd)?;
        let powers = powers(model, &q, &qd, &qdd, &inputs, &self.inputs().drive().velocity(t));
        let n = qd.len();
        for i in 0..n {
            out[i] = qd[i];
            out[n + i] = qdd[i];
        }
        Ok(powers)
    }

    /// [`inertial_energy`] with the drive's position and velocity at `t`.
    fn inertial_energy(&self, t: f64, x: &[f64]) -> f64 {
        let (q, qd) = split_angles(self.model(), x);
        let drive = self.inputs().drive();
        inertial_energy(self.model(), &q, &qd, &drive.position(t), &drive.velocity(t))
    }
}

/// `(q, q̇)` of a state that starts with them.
#[allow(clippy::type_complexity)] // The pair is the plainest reading.
fn split_angles<M: Model>(model: &M, x: &[f64]) -> (OVector<f64, M::Dof>, OVector<f64, M::Dof>)
where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>,
{
    let dof = model.dof();
    let n = dof.value();
    let q = OVector::from_iterator_generic(dof, U1, x.iter().take(n).copied());
    let qd = OVector::from_iterator_generic(dof, U1, x.iter().skip(n).take(n).copied());
    (q, qd)
}

impl<M: Model, Dr: Drive<M::Space>, T: TorqueAt<M::Dof>> Accounted<FirstOrder<M, Driven<Dr, T>>>
where
    DefaultAllocator: ModelAlloc<M::Links, M::Dof, M::Space>,
{
    /// `model` with its pivot moving as `drive` and the torques `torque` acting.
    pub fn new(model: M, drive: Dr, torque: T) -> Self {
        Self::of(FirstOrder::with_inputs(model, Driven::new(drive, torque)))
    }

    /// The model.
    pub fn model(&self) -> &M {
        self.motion.model()
    }

    /// The drive and torques.
    pub fn inputs(&self) -> &Driven<Dr, T> {
        self.motion.inputs()
    }

    /// The initial state `(q, q̇, 0, 0, 0)`: an empty ledger.
    pub fn state(&self, q: &OVector<f64, M::Dof>, qd: &OVector<f64, M::Dof>) -> DVector<f64> {
        DVector::from_iterator(
            2 * q.len() + LEDGER_LEN,
            q.iter().chain(qd.iter()).copied().chain([0.0; LEDGER_LEN]),
        )
    }

    /// Splits a state into `(q, q̇, ledger)`.
    #[allow(clippy::type_complexity)] // The tuple is the plainest reading.
    pub fn split(&self, x: &DVector<f64>) -> (OVector<f64, M::Dof>, OVector<f64, M::Dof>, Ledger) {
        let (q, qd) = split_angles(self.model(), x.as_slice());
        (q, qd, self.ledger(x))
    }
}

/// A chain in unit link directions: state `(u, w)`, no torques.
impl<S: DimName, Dr: Drive<S>> Powered for Directions<S, Dr>
where
    DefaultAllocator: Allocator<S>,
{
    fn motion_len(&self) -> usize {
        self.state_len()
    }

    fn second_order(&self) -> Option<usize> {
        Some(S::DIM * self.links())
    }

    /// `(w, ü)` by the tension solve, with the power the moving pivot injects
    /// `P_drive = ṗ·F_pivot` (W), the force the pivot exerts on the chain
    /// `F_pivot = Σ_k m_k r̈_k + M g ê_up = M p̈ + Σ_j M_j l_j ü_j + M g ê_up` (N; `M_j` the
    /// mass hanging from link `j`, `M = M_1`), and the damping loss
    /// `P_damping = 2D = Σ_i λ_i |w_i|²` (W).
    fn flow_and_powers(&self, t: f64, x: &[f64], out: &mut [f64]) -> Result<Powers> {
        // The pivot's motion from one evaluation of the drive (one `sincos` for a circle).
        let (pivot_velocity, pivot_acceleration) = self.drive().velocity_and_acceleration(t);
        self.flow_at_pivot(&pivot_acceleration, x, out)?;
        let c = self.chain();
        let half = x.len() / 2;
        let (w, wd) = (&x[half..], &out[half..]);
        let (tails, lengths, damping) =
            (c.tail_masses().as_slice(), c.lengths().as_slice(), c.damping().as_slice());
        let (drive, damping) = match S::DIM {
            2 => direction_powers::<2, f64>(
                (tails, lengths, damping, c.gravity()),
                [pivot_velocity[0], pivot_velocity[1]],
                [pivot_acceleration[0], pivot_acceleration[1]],
                w,
                wd,
            ),
            _ => direction_powers::<3, f64>(
                (tails, lengths, damping, c.gravity()),
                [pivot_velocity[0], pivot_velocity[1], pivot_velocity[2]],
                [pivot_acceleration[0], pivot_acceleration[1], pivot_acceleration[2]],
                w,
                wd,
            ),
        };
        Ok(Powers { drive, torque: 0.0, damping })
    }

    fn inertial_energy(&self, t: f64, x: &[f64]) -> f64 {
        self.inertial_energy_of(t, x)
    }
}

/// The powers of a chain in `C`-dimensional directions at rates `w` and accelerations
/// `wd = ẇ` (1/s, 1/s²; `C` per link), lane by lane for [`Lanes`](crate::lanes::Lanes):
/// `(P_drive, P_damping)` (W) with `P_drive = ṗ·F_pivot`, the pivot's force on the chain
/// `F_pivot = M p̈ + Σ_j M_j l_j ẅ_j + M g ê_up` (`M_j` the mass hanging from link `j`,
/// `M = M_1`), and `P_damping = Σ_i λ_i |w_i|²`. `chain` = (tail masses `M_j` (kg), lengths
/// (m), damping `λ_j` (N·m·s), `g` (m/s²)); pivot velocity (m/s) and acceleration (m/s²).
#[inline(always)]
pub(crate) fn direction_powers<const C: usize, V: Lane>(
    (tails, lengths, damping, gravity): (&[V], &[V], &[V], V),
    pivot_velocity: [V; C],
    pivot_acceleration: [V; C],
    w: &[V],
    wd: &[V],
) -> (V, V) {
    let total = tails[0];
    let mut force: [V; C] = std::array::from_fn(|k| pivot_acceleration[k] * total);
    force[C - 1] += total * gravity;
    let zero = V::splat(0.0);
    let mut damped = zero;
    for j in 0..tails.len() {
        let weight = tails[j] * lengths[j];
        let mut w2 = zero;
        for k in 0..C {
            force[k] += weight * wd[j * C + k];
            w2 += w[j * C + k] * w[j * C + k];
        }
        damped += damping[j] * w2;
    }
    // In nalgebra's order for a dot product of two or three components.
    let mut drive = pivot_velocity[0] * force[0];
    for k in 1..C {
        drive += pivot_velocity[k] * force[k];
    }
    (drive, damped)
}

impl<S: DimName, Dr: Drive<S>> Accounted<Directions<S, Dr>>
where
    DefaultAllocator: Allocator<S>,
{
    /// The chain.
    pub fn chain(&self) -> &Directions<S, Dr> {
        &self.motion
    }

    /// The initial state: the chain's state `(u, w)` and an empty ledger (errors of
    /// [`start`](Self::start)).
    pub fn state(&self, motion: &DVector<f64>) -> Result<DVector<f64>> {
        self.start(motion.as_slice())
    }

    /// The chain's part `(u, w)` of a state.
    pub fn motion(&self, x: &DVector<f64>) -> DVector<f64> {
        x.rows(0, self.motion_len()).into_owned()
    }
}

impl<S: DimName, Dr: Drive<S>> Constrained for Accounted<Directions<S, Dr>>
where
    DefaultAllocator: Allocator<S>,
{
    /// The chain's projection on the `(u, w)` part; the ledger is left as it is. A state
    /// of the wrong length is left alone (the next `rhs` reports it).
    fn project(&self, x: &mut DVector<f64>) {
        let len = self.motion_len();
        if x.len() != len + LEDGER_LEN {
            return;
        }
        self.motion.project_slice(&mut x.as_mut_slice()[..len]);
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::{U2, U3, Vector2};

    use super::*;
    use std::ops::ControlFlow;

    use crate::chain::Chain;
    use crate::drive::{Circle, ConstantTorque, Harmonic};
    use crate::integrate::Integrator;
    use crate::models::planar::Planar;
    use crate::models::spatial::Spatial;
    use crate::rod_midpoint::RodMidpoint;

    use crate::integrate::{Projected, Rk4, State};
    use crate::trajectory;

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
        let drive = crate::drive::Circle::new(0.1, 6.0).unwrap();
        check_power_balance(
            model,
            drive,
            &[0.4, 1.9, 0.3, -2.0],
            &[1.0, -0.5, 2.5, 0.7],
            &[0.3, -0.2, 0.5, 0.1],
        );
    }

    fn chain() -> Chain {
        Chain::new(&[1.0, 0.6, 1.4], &[0.5, 0.3, 0.7], 9.81).unwrap().with_damping(&[0.2, 0.05, 0.3]).unwrap()
    }

    /// `dH/dt` by central differences along the flow equals `P_drive − P_damping`.
    #[test]
    fn the_energy_changes_at_the_ledger_powers() {
        let system = Accounted::of(Directions::<U3>::new(chain()).with_drive(Circle::new(0.1, 5.0).unwrap()));
        let motion = system
            .chain()
            .from_spherical(&[0.4, 1.2, 2.0, 0.3, -1.0, 2.2], &[1.0, -0.5, 0.3, 2.0, 0.4, -1.1])
            .unwrap();
        let x = system.state(&motion).unwrap();
        let mut f = DVector::zeros(x.len());
        for t in [0.0, 0.7] {
            system.rhs(t, &x, &mut f).unwrap();
            let eps = 1e-5;
            let h = |s: f64| system.energy(t + s, &(&x + &f * s));
            let rate = (h(eps) - h(-eps)) / (2.0 * eps);
            let len = system.motion_len();
            // The ledger's layout: drive, torque (none here), damping.
            let (drive, torque, damping) = (f[len], f[len + 1], f[len + 2]);
            let net = drive - damping;
            assert!((rate - net).abs() < 1e-6 * (1.0 + drive.abs() + damping), "t={t}: {rate} vs {net}");
            assert!(damping > 0.0 && drive.abs() > 1e-3 && torque == 0.0);
        }
    }

    /// A driven, damped planar run: the balance closes to the integration error
    /// (RK4, h = 1 ms, 2 s) while drive work and damping losses are large.
    #[test]
    fn the_balance_closes_along_a_driven_damped_run() {
        let drive = Harmonic::new(nalgebra::Vector2::new(1.0, 0.0), 0.05, 6.0, 0.0).unwrap();
        let system = Accounted::of(Directions::<U2>::new(chain()).with_drive(drive));
        let motion = system.chain().from_angles(&[0.5, -0.3, 1.0], &[0.0, 1.0, -1.0]).unwrap();
        let x0 = system.state(&motion).unwrap();
        let mut integrator = Projected::new(Rk4::new(&system));
        let mut state = State::new(0.0, x0.clone());
        trajectory::run(&mut integrator, &system, &mut state, 2.0, 1e-3, 2000, |_, _| {
            ControlFlow::Continue(())
        })
        .unwrap();
        let balance = system.balance(0.0, &x0, state.t(), state.x());
        assert!(balance.ledger.damped > 0.1 && balance.ledger.drive.abs() > 1e-3, "{balance:?}");
        assert!(balance.relative < 1e-8, "{balance:?}");
        assert_eq!(balance.ledger.torque, 0.0);
    }

    #[test]
    fn states_of_the_wrong_length_are_named() {
        let system = Accounted::of(Directions::<U3>::new(chain()));
        let err = system.state(&DVector::zeros(5)).unwrap_err();
        assert_eq!(err, Error::LengthMismatch { what: "motion", expected: 18, got: 5 });
        let mut out = DVector::zeros(21);
        let err = system.rhs(0.0, &DVector::zeros(20), &mut out).unwrap_err();
        assert_eq!(err, Error::LengthMismatch { what: "state", expected: 21, got: 20 });
    }

    /// Driven and damped, the implicit midpoint step closes the ledger to round-off at a
    /// long step.
    #[test]
    fn the_midpoint_step_closes_the_ledger_of_a_driven_damped_chain() {
        let n = 30;
        let chain = Chain::uniform(n, 0.03, 0.03, 9.81).unwrap().with_damping(&[3e-4; 30]).unwrap();
        let model = Accounted::of(Directions::<U3>::new(chain).with_drive(Circle::new(0.02, 6.0).unwrap()));
        let x0 = model.state(&model.chain().hanging()).unwrap();
        let mut state = State::new(0.0, x0.clone());
        let mut solver = RodMidpoint::new();
        solver.integrate(&model, &mut state, 5.0, 500).unwrap();
        let balance = model.balance(0.0, &x0, state.t(), state.x());
        let ledger = model.ledger(state.x());
        assert!(ledger.drive > 1e-3 && ledger.damped > 1e-4, "{ledger:?}");
        assert!(balance.residual.abs() < 1e-12 * ledger.drive, "{balance:?}");
    }
}
