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
//! Written once, here; `pendulum-core/benches/models.rs` compiles this file too (by
//! `#[path]`), so it must use nothing of xtask and holds no test module (a test-mode build
//! of a bench sets `cfg(test)` but drops `#[test]` functions). Its tests are
//! `xtask/tests/closed_form.rs`.

use anyhow::{Result, ensure};

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
    /// `g` (m/s²). Errors name the bad value: masses and lengths must be positive and
    /// finite, `g` finite and non-negative.
    pub fn new(m1: f64, m2: f64, l1: f64, l2: f64, g: f64) -> Result<Self> {
        for (name, value) in [("m1", m1), ("m2", m2), ("l1", l1), ("l2", l2)] {
            ensure!(value.is_finite() && value > 0.0, "{name} = {value} must be positive and finite");
        }
        ensure!(g.is_finite() && g >= 0.0, "g = {g} must be finite and non-negative");
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
