//! One random state of one case as the checks read it: the reference's values with their
//! scales, the coefficient matrices its velocity terms imply, and its free accelerations.

use nalgebra::{DMatrix, DVector};

use crate::case::{Case, Evaluated, Params, Point};
use crate::expr::Scaled;

/// One random state of one case, evaluated by the reference.
pub(crate) struct State<'a> {
    pub(crate) case: &'a Case,
    pub(crate) params: Params,
    pub(crate) point: Point,
    pub(crate) ev: Evaluated,
    pub(crate) sc: Evaluated,
}

impl State<'_> {
    pub(crate) fn mass(&self, i: usize, j: usize) -> Scaled {
        Scaled::with_scale(self.ev.mass_matrix[(i, j)], self.sc.mass_matrix[(i, j)])
    }

    pub(crate) fn velocity(&self, i: usize) -> Scaled {
        Scaled::with_scale(self.ev.velocity_terms[i], self.sc.velocity_terms[i])
    }

    pub(crate) fn gravity(&self, i: usize) -> Scaled {
        Scaled::with_scale(self.ev.gravity_terms[i], self.sc.gravity_terms[i])
    }

    pub(crate) fn force(&self, i: usize) -> Scaled {
        Scaled::with_scale(self.ev.generalized_forces[i], self.sc.generalized_forces[i])
    }

    pub(crate) fn kinetic(&self) -> Scaled {
        Scaled::with_scale(self.ev.kinetic_energy, self.sc.kinetic_energy)
    }

    pub(crate) fn potential(&self) -> Scaled {
        Scaled::with_scale(self.ev.potential_energy, self.sc.potential_energy)
    }

    /// The reference's velocity terms `c` at this configuration with rates `qd`.
    pub(crate) fn velocity_terms_at(&self, qd: Vec<f64>) -> Vec<Scaled> {
        let point = Point {
            q: self.point.q.clone(),
            qd,
            torque: vec![0.0; self.point.torque.len()],
            pivot_acceleration: vec![0.0; self.point.pivot_acceleration.len()],
        };
        let (ev, sc) = self.case.evaluate_with_scales(&self.params, &point);
        (0..ev.velocity_terms.len())
            .map(|i| Scaled::with_scale(ev.velocity_terms[i], sc.velocity_terms[i]))
            .collect()
    }

    /// `c` with rate `j` (and optionally also rate `k`) set to one, all others zero.
    pub(crate) fn velocity_terms_unit(&self, j: usize, k: Option<usize>) -> Vec<Scaled> {
        let mut qd = vec![0.0; self.point.qd.len()];
        qd[j] = 1.0;
        if let Some(k) = k {
            qd[k] = 1.0;
        }
        self.velocity_terms_at(qd)
    }

    /// `(M q̈ + c + k)_d` at accelerations `qdd`.
    pub(crate) fn lagrange_lhs(&self, qdd: &[Scaled], d: usize) -> Scaled {
        (0..qdd.len()).map(|j| self.mass(d, j) * qdd[j]).sum::<Scaled>() + self.velocity(d) + self.gravity(d)
    }

    /// The free, undriven, undamped accelerations `M⁻¹(−c − k)`, each with the
    /// componentwise round-off bound `|M⁻¹|(s_M |q̈| + s_c + s_k)` as its scale.
    pub(crate) fn free_accelerations(&self) -> Option<Vec<Scaled>> {
        let mass = &self.ev.mass_matrix;
        let rhs: DVector<f64> = -(&self.ev.velocity_terms + &self.ev.gravity_terms);
        let inverse: DMatrix<f64> = mass.clone().try_inverse()?;
        let acc = &inverse * &rhs;
        let rhs_scale = self.sc.velocity_terms.abs() + self.sc.gravity_terms.abs();
        let mass_scale = self.sc.mass_matrix.abs().zip_map(&mass.abs(), f64::max);
        let scale = inverse.abs() * (mass_scale * acc.abs() + rhs_scale);
        Some((0..acc.len()).map(|i| Scaled::with_scale(acc[i], scale[i])).collect())
    }
}

/// The tail masses `M_i = Σ_{j≥i} m_j` (eq 10), exact, 0-based.
pub(crate) fn tail_masses(masses: &[f64]) -> Vec<Scaled> {
    (0..masses.len()).map(|i| masses[i..].iter().map(|&m| Scaled::exact(m)).sum()).collect()
}
