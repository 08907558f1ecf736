//! The energy ledger for the chain in unit link directions ([`Directions`]): the same
//! bookkeeping [`Accounted`](pendulum_core::Accounted) does for angle models, written
//! here because the core's ledger serves [`Model`](pendulum_core::Model)s only.

use nalgebra::{DVector, DefaultAllocator, DimName, Dyn, allocator::Allocator};
use pendulum_core::integrate::{Constrained, System};
use pendulum_core::{Directions, Drive, Result};

/// A [`Directions`] chain whose state carries its energy ledger:
/// ```text
/// x = (u_1..u_n, w_1..w_n, W_drive, E_damped),
/// x' = (w, ü, P_drive, P_damping)
/// ```
/// with the power the moving pivot injects `P_drive = ṗ·F_pivot` (W), the force the
/// pivot exerts on the chain `F_pivot = Σ_k m_k r̈_k + M g ê_up
/// = M p̈ + Σ_j M_j l_j ü_j + M g ê_up` (N; `M_j` the tail masses, `M = M_1`), and the
/// damping loss `P_damping = 2D = Σ_i λ_i |w_i|²` (W). The inertial-frame energy then
/// changes as `dH/dt = P_drive − P_damping`; the integrator computes the work integrals
/// with the motion, so the balance measures the integration error.
pub struct LedgeredDirections<S: DimName>
where
    DefaultAllocator: Allocator<S>,
{
    chain: Directions<S, Box<dyn Drive<S>>>,
}

impl<S: DimName> LedgeredDirections<S>
where
    DefaultAllocator: Allocator<S>,
{
    /// The chain with its ledger.
    pub fn new(chain: Directions<S, Box<dyn Drive<S>>>) -> Self {
        Self { chain }
    }

    /// The chain.
    pub fn chain(&self) -> &Directions<S, Box<dyn Drive<S>>> {
        &self.chain
    }

    /// Length of the chain's own state `(u, w)`: `2·S·n`.
    pub fn motion_len(&self) -> usize {
        self.chain.state_len()
    }

    /// The initial state: the chain's state and an empty ledger.
    pub fn state(&self, motion: &DVector<f64>) -> DVector<f64> {
        DVector::from_iterator(self.motion_len() + 2, motion.iter().copied().chain([0.0, 0.0]))
    }

    /// The chain's part `(u, w)` of a state.
    pub fn motion(&self, x: &DVector<f64>) -> DVector<f64> {
        x.rows(0, self.motion_len()).into_owned()
    }

    /// `(W_drive, E_damped)` of a state, J.
    pub fn ledger(&self, x: &DVector<f64>) -> (f64, f64) {
        let m = self.motion_len();
        (x[m], x[m + 1])
    }
}

impl<S: DimName> System for LedgeredDirections<S>
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

    fn rhs(&self, t: f64, x: &DVector<f64>, out: &mut DVector<f64>) -> Result<()> {
        let len = self.motion_len();
        let motion = self.motion(x);
        let mut flow = DVector::zeros(len);
        self.chain.rhs(t, &motion, &mut flow)?;
        out.rows_mut(0, len).copy_from(&flow);
        let c = self.chain.chain();
        let (n, d) = (c.links(), S::DIM);
        let (tails, lengths, damping) = (c.tail_masses(), c.lengths(), c.damping());
        let drive = self.chain.drive();
        let (pivot_velocity, pivot_acceleration) = (drive.velocity(t), drive.acceleration(t));
        let total = tails[0];
        let mut force = &pivot_acceleration * total;
        force[d - 1] += total * c.gravity();
        let mut damped = 0.0;
        for j in 0..n {
            let weight = tails[j] * lengths[j];
            let mut w2 = 0.0;
            for k in 0..d {
                force[k] += weight * flow[len / 2 + j * d + k];
                w2 += motion[len / 2 + j * d + k].powi(2);
            }
            damped += damping[j] * w2;
        }
        out[len] = pivot_velocity.dot(&force);
        out[len + 1] = damped;
        Ok(())
    }
}

impl<S: DimName> Constrained for LedgeredDirections<S>
where
    DefaultAllocator: Allocator<S>,
{
    /// The chain's projection on the `(u, w)` part; the ledger is left as it is.
    fn project(&self, x: &mut DVector<f64>) {
        let len = self.motion_len();
        if x.len() != len + 2 {
            return;
        }
        let mut motion = self.motion(x);
        self.chain.project(&mut motion);
        x.rows_mut(0, len).copy_from(&motion);
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::U3;
    use pendulum_core::{Chain, Circle};

    use super::*;

    /// `dH/dt` by central differences along the flow equals `P_drive − P_damping`.
    #[test]
    fn the_energy_changes_at_the_ledger_powers() {
        let chain = Chain::new(&[1.0, 0.6, 1.4], &[0.5, 0.3, 0.7], 9.81).unwrap();
        let chain = chain.with_damping(&[0.2, 0.05, 0.3]).unwrap();
        let drive: Box<dyn Drive<U3>> = Box::new(Circle::new(0.1, 5.0).unwrap());
        let system = LedgeredDirections::new(Directions::new(chain).with_drive(drive));
        let motion = system
            .chain()
            .from_spherical(&[0.4, 1.2, 2.0, 0.3, -1.0, 2.2], &[1.0, -0.5, 0.3, 2.0, 0.4, -1.1]);
        let x = system.state(&motion.unwrap());
        let mut f = DVector::zeros(x.len());
        for t in [0.0, 0.7] {
            system.rhs(t, &x, &mut f).unwrap();
            let eps = 1e-5;
            let h = |s: f64| {
                let y = &x + &f * s;
                system.chain().inertial_energy(t + s, &system.motion(&y))
            };
            let rate = (h(eps) - h(-eps)) / (2.0 * eps);
            let len = system.motion_len();
            let net = f[len] - f[len + 1];
            assert!((rate - net).abs() < 1e-6 * (1.0 + f[len].abs() + f[len + 1]), "t={t}: {rate} vs {net}");
            assert!(f[len + 1] > 0.0 && f[len].abs() > 1e-3);
        }
    }
}
