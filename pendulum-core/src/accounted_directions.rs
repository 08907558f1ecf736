//! The energy ledger of a chain in unit link directions ([`Directions`]): the
//! bookkeeping [`Accounted`](crate::Accounted) does for models in angle coordinates.

use nalgebra::{DVector, DefaultAllocator, DimName, Dyn, allocator::Allocator};

use crate::integrate::{Constrained, System};
use crate::{Balance, Directions, Drive, Error, Ledger, Result};

/// A [`Directions`] chain whose state carries its energy ledger:
/// ```text
/// x  = (u_1..u_n, w_1..w_n, W_drive, E_damped),
/// x' = (w, ü, P_drive, P_damping)
/// ```
/// (dimension `2·S·n + 2`) with the power the moving pivot injects
/// `P_drive = ṗ·F_pivot` (W), the force the pivot exerts on the chain
/// `F_pivot = Σ_k m_k r̈_k + M g ê_up = M p̈ + Σ_j M_j l_j ü_j + M g ê_up` (N; `M_j` the
/// mass hanging from link `j`, `M = M_1`), and the damping loss
/// `P_damping = 2D = Σ_i λ_i |w_i|²` (W). The inertial-frame energy then changes as
/// `dH/dt = P_drive − P_damping`. The integrator computes the work integrals with the
/// same method and step as the motion, so [`balance`](Self::balance) measures the
/// integration error of the run, not a quadrature error. There are no torques in this
/// representation: the ledger's `torque` entry is always 0.
///
/// The `(u, w)` part of the solution is what the integrator gives for the
/// [`Directions`] chain alone: the ledger does not feed back. [`Constrained::project`]
/// projects the `(u, w)` part and leaves the ledger as it is.
#[derive(Debug, Clone)]
pub struct AccountedDirections<S: DimName, Dr> {
    chain: Directions<S, Dr>,
}

impl<S: DimName, Dr: Drive<S>> AccountedDirections<S, Dr>
where
    DefaultAllocator: Allocator<S>,
{
    /// The chain with its ledger.
    pub fn new(chain: Directions<S, Dr>) -> Self {
        Self { chain }
    }

    /// The chain.
    pub fn chain(&self) -> &Directions<S, Dr> {
        &self.chain
    }

    /// Length of the chain's own state `(u, w)`: `2·S·n`.
    pub fn motion_len(&self) -> usize {
        self.chain.state_len()
    }

    /// The initial state: the chain's state `(u, w)` and an empty ledger.
    ///
    /// Errors: [`Error::LengthMismatch`] when `motion` is not `2·S·n` long.
    pub fn state(&self, motion: &DVector<f64>) -> Result<DVector<f64>> {
        let expected = self.motion_len();
        if motion.len() != expected {
            return Err(Error::LengthMismatch { what: "motion", expected, got: motion.len() });
        }
        Ok(DVector::from_iterator(expected + 2, motion.iter().copied().chain([0.0, 0.0])))
    }

    /// The chain's part `(u, w)` of a state.
    pub fn motion(&self, x: &DVector<f64>) -> DVector<f64> {
        x.rows(0, self.motion_len()).into_owned()
    }

    /// The ledger of a state (J): `W_drive`, `E_damped`, and `W_torque = 0`.
    pub fn ledger(&self, x: &DVector<f64>) -> Ledger {
        let m = self.motion_len();
        Ledger { drive: x[m], torque: 0.0, damped: x[m + 1] }
    }

    /// The inertial-frame energy `H = T + U` of the state `x` at time `t` (J).
    pub fn energy(&self, t: f64, x: &DVector<f64>) -> f64 {
        self.chain.inertial_energy(t, &self.motion(x))
    }

    /// The energy balance from `(t0, x0)` to `(t, x)` (see [`Balance`]).
    pub fn balance(&self, t0: f64, x0: &DVector<f64>, t: f64, x: &DVector<f64>) -> Balance {
        Balance::between(self.energy(t0, x0), self.energy(t, x), &self.ledger(x0), &self.ledger(x))
    }
}

impl<S: DimName, Dr: Drive<S>> System for AccountedDirections<S, Dr>
where
    DefaultAllocator: Allocator<S>,
{
    type Dim = Dyn;

    fn dim(&self) -> Dyn {
        Dyn(self.motion_len() + 2)
    }

    /// `x = (u, w, ledger)`, `u' = w`.
    fn second_order(&self) -> Option<usize> {
        self.chain.second_order()
    }

    /// `(w, ü, P_drive, P_damping)`. Errors: those of the chain's [`System::rhs`], and
    /// [`Error::LengthMismatch`] for a state or output of the wrong length.
    fn rhs(&self, t: f64, x: &DVector<f64>, out: &mut DVector<f64>) -> Result<()> {
        let len = self.motion_len();
        for (what, got) in [("state", x.len()), ("out", out.len())] {
            if got != len + 2 {
                return Err(Error::LengthMismatch { what, expected: len + 2, got });
            }
        }
        // The chain's part in place: no copy of the state, nothing allocated per call.
        self.chain.flow(t, &x.as_slice()[..len], &mut out.as_mut_slice()[..len])?;
        let c = self.chain.chain();
        let (n, d) = (c.links(), S::DIM);
        let (tails, lengths, damping) = (c.tail_masses(), c.lengths(), c.damping());
        let drive = self.chain.drive();
        let (pivot_velocity, pivot_acceleration) = (drive.velocity(t), drive.acceleration(t));
        let total = tails[0];
        let mut force = &pivot_acceleration * total;
        force[d - 1] += total * c.gravity();
        let mut damped = 0.0;
        let (w, wd) = (&x.as_slice()[len / 2..len], &out.as_slice()[len / 2..len]);
        for j in 0..n {
            let weight = tails[j] * lengths[j];
            let mut w2 = 0.0;
            for k in 0..d {
                force[k] += weight * wd[j * d + k];
                w2 += w[j * d + k].powi(2);
            }
            damped += damping[j] * w2;
        }
        out[len] = pivot_velocity.dot(&force);
        out[len + 1] = damped;
        Ok(())
    }
}

impl<S: DimName, Dr: Drive<S>> Constrained for AccountedDirections<S, Dr>
where
    DefaultAllocator: Allocator<S>,
{
    /// The chain's projection on the `(u, w)` part; the ledger is left as it is. A state
    /// of the wrong length is left alone (the next `rhs` reports it).
    fn project(&self, x: &mut DVector<f64>) {
        let len = self.motion_len();
        if x.len() != len + 2 {
            return;
        }
        self.chain.project_slice(&mut x.as_mut_slice()[..len]);
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::{U2, U3};

    use super::*;
    use std::ops::ControlFlow;

    use crate::integrate::{Projected, Rk4, State};
    use crate::trajectory;
    use crate::{Chain, Circle, Harmonic};

    fn chain() -> Chain {
        Chain::new(&[1.0, 0.6, 1.4], &[0.5, 0.3, 0.7], 9.81).unwrap().with_damping(&[0.2, 0.05, 0.3]).unwrap()
    }

    /// `dH/dt` by central differences along the flow equals `P_drive − P_damping`.
    #[test]
    fn the_energy_changes_at_the_ledger_powers() {
        let system = AccountedDirections::new(
            Directions::<U3>::new(chain()).with_drive(Circle::new(0.1, 5.0).unwrap()),
        );
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
            let net = f[len] - f[len + 1];
            assert!((rate - net).abs() < 1e-6 * (1.0 + f[len].abs() + f[len + 1]), "t={t}: {rate} vs {net}");
            assert!(f[len + 1] > 0.0 && f[len].abs() > 1e-3);
        }
    }

    /// A driven, damped planar run: the balance closes to the integration error
    /// (RK4, h = 1 ms, 2 s) while drive work and damping losses are large.
    #[test]
    fn the_balance_closes_along_a_driven_damped_run() {
        let drive = Harmonic::new(nalgebra::Vector2::new(1.0, 0.0), 0.05, 6.0, 0.0).unwrap();
        let system = AccountedDirections::new(Directions::<U2>::new(chain()).with_drive(drive));
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
        let system = AccountedDirections::new(Directions::<U3>::new(chain()));
        let err = system.state(&DVector::zeros(5)).unwrap_err();
        assert_eq!(err, Error::LengthMismatch { what: "motion", expected: 18, got: 5 });
        let mut out = DVector::zeros(20);
        let err = system.rhs(0.0, &DVector::zeros(19), &mut out).unwrap_err();
        assert_eq!(err, Error::LengthMismatch { what: "state", expected: 20, got: 19 });
    }
}
