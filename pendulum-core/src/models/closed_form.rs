//! The hand-written closed-form double pendulum: the document's eq 50 with the θ̈₂ typo
//! corrected (`reference/ERRATA.md`), the floor the generated `Planar2` is benchmarked
//! against.
//!
//! With `l = l₂/l₁`, `m = m₂/(m₁+m₂)`, `g → g/l₁` (time unscaled; the scaling under which
//! eq 49 is the physical equation divided by `(m₁+m₂) l₁²`, ERRATA "49 g"):
//!
//! ```text
//! θ̈₁ = [m l θ̇₂² sin(θ₂−θ₁) − g sin θ₁ − m cos(θ₂−θ₁)(θ̇₁² sin(θ₁−θ₂) − g sin θ₂)] / (1 − m cos²(θ₂−θ₁))
//! θ̈₂ = [θ̇₁² sin(θ₁−θ₂) − g sin θ₂ − cos(θ₁−θ₂)(m l θ̇₂² sin(θ₂−θ₁) − g sin θ₁)] / (l − m l cos²(θ₂−θ₁))
//! ```
//!
//! The document prints `g sin θ₁` for the second `g sin θ₂`. No damping, torque or pivot
//! motion: the free double pendulum of section 2.4.
//!
//! `cargo xtask bench` times it beside the generated and generic models
//! (`pendulum-core/benches/models.rs`); the tests below check it against [`Planar`].

use nalgebra::Dyn;

use crate::chain::Chain;
use crate::error::Result;

/// The free double pendulum in the document's dimensionless parameters (eq 49).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DoublePendulum {
    /// `m = m₂/(m₁+m₂)`, dimensionless, in (0, 1).
    m: f64,
    /// `l = l₂/l₁`, dimensionless.
    l: f64,
    /// `g/l₁`, s⁻².
    g: f64,
}

impl DoublePendulum {
    /// The double pendulum of masses `m1`, `m2` (kg), lengths `l1`, `l2` (m) and gravity
    /// `g` (m/s²). Errors: those of [`Chain::new`], naming the bad value (masses and
    /// lengths positive and finite, `g` finite and non-negative).
    pub fn new(m1: f64, m2: f64, l1: f64, l2: f64, g: f64) -> Result<Self> {
        Chain::<Dyn>::new(&[m1, m2], &[l1, l2], g)?;
        Ok(Self { m: m2 / (m1 + m2), l: l2 / l1, g: g / l1 })
    }

    /// `(θ̈₁, θ̈₂)` (rad/s²) at angles `(θ₁, θ₂)` (rad) and rates `(θ̇₁, θ̇₂)` (rad/s):
    /// eq 50, corrected. Three trigonometric evaluations: `sin_cos(θ₁ − θ₂)`, `sin θ₁`,
    /// `sin θ₂`.
    #[inline]
    pub fn accelerations(&self, q: [f64; 2], qd: [f64; 2]) -> [f64; 2] {
        let Self { m, l, g } = *self;
        // s = sin(θ₁−θ₂) = −sin(θ₂−θ₁), c = cos(θ₁−θ₂) = cos(θ₂−θ₁).
        let (s, c) = (q[0] - q[1]).sin_cos();
        let (g1, g2) = (g * q[0].sin(), g * q[1].sin());
        let (w1s, w2s) = (qd[0] * qd[0] * s, m * l * qd[1] * qd[1] * s);
        let den = 1.0 - m * c * c;
        let a1 = (-w2s - g1 - m * c * (w1s - g2)) / den;
        let a2 = (w1s - g2 - c * (-w2s - g1)) / (l * den);
        [a1, a2]
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::DVector;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::*;
    use crate::model::Model;
    use crate::models::planar::Planar;

    /// Eq 50 (corrected) agrees with the generic `Planar<Dyn>` to round-off at random
    /// states; each component's error is measured against its round-off scale, the sum
    /// of the magnitudes of the numerator's terms over the denominator.
    #[test]
    fn matches_the_generic_model_to_round_off() {
        let mut rng = ChaCha8Rng::seed_from_u64(50);
        for _ in 0..500 {
            let [m1, m2, l1, l2]: [f64; 4] = std::array::from_fn(|_| 10f64.powf(rng.random_range(-1.0..1.0)));
            let g = rng.random_range(0.0..20.0);
            let q = [rng.random_range(-3.2..3.2), rng.random_range(-3.2..3.2)];
            let qd = [rng.random_range(-10.0..10.0), rng.random_range(-10.0..10.0)];
            let closed = DoublePendulum::new(m1, m2, l1, l2, g).unwrap().accelerations(q, qd);

            let generic = Planar::new(Chain::<Dyn>::new(&[m1, m2], &[l1, l2], g).unwrap());
            let mut a = DVector::zeros(2);
            generic
                .accelerations(
                    &DVector::from_row_slice(&q),
                    &DVector::from_row_slice(&qd),
                    &generic.zero_inputs(),
                    &mut a,
                )
                .unwrap();

            let (m, l, g) = (m2 / (m1 + m2), l2 / l1, g / l1);
            let c = (q[0] - q[1]).cos();
            let den = 1.0 - m * c * c;
            let terms = m * l * qd[1] * qd[1] + g + m * (qd[0] * qd[0] + g);
            let scale = [terms / den, terms / (l * den)];
            for i in 0..2 {
                let error = (closed[i] - a[i]).abs() / scale[i];
                assert!(
                    error < 1e-12,
                    "θ̈{}: closed {} vs generic {} (relative to scale {error:e})",
                    i + 1,
                    closed[i],
                    a[i]
                );
            }
        }
    }

    #[test]
    fn bad_parameters_are_errors_naming_the_value() {
        let err = DoublePendulum::new(1.0, -2.0, 1.0, 1.0, 9.81).unwrap_err();
        assert!(err.to_string().contains("mass of link 2 must be finite and positive, got -2"), "{err}");
        let err = DoublePendulum::new(1.0, 2.0, 1.0, 1.0, f64::NAN).unwrap_err();
        assert!(err.to_string().contains("NaN"), "{err}");
    }
}
