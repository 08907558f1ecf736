//! A pivot steered by hand: it follows a target point that may change at any time, while
//! circling it at a speed and radius that may also change, every channel through a
//! critically damped filter, so `p`, `ṗ` stay continuous and `p̈` finite whatever the
//! targets do. The drive of `pendulum view --live`.

use nalgebra::{U3, Vector3};

use super::{Drive, check_parameter};
use crate::error::{Error, Result};

/// A quantity that follows its target `x*` as a critically damped oscillator of rate `k`
/// (1/s): `ẍ = k²(x* − x) − 2k ẋ`. From `x(0) = x₀`, `ẋ(0) = v₀` with the target held:
/// ```text
/// x(s) = x* + (a + b s) e^{−ks},    a = x₀ − x*,   b = v₀ + k a
/// ẋ(s) = (b − k(a + b s)) e^{−ks},   ẍ(s) = (k²(a + b s) − 2k b) e^{−ks}
/// ∫₀ˢ x = x* s + a (1 − e^{−ks})/k + b (1 − (1 + ks) e^{−ks})/k²
/// ```
/// A step of the target moves `ẍ` by `k²` times the step and leaves `x`, `ẋ` continuous;
/// the follower settles in a few `1/k` without overshoot.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Follower {
    value: f64,
    rate: f64,
    target: f64,
    k: f64,
}

impl Follower {
    /// At rest at `value`, aiming at it, with rate `k` (finite and positive, 1/s).
    fn new(value: f64, k: f64) -> Self {
        Self { value, rate: 0.0, target: value, k }
    }

    /// `(a, b, e^{−ks})` of the closed form at `s`.
    fn terms(&self, s: f64) -> (f64, f64, f64) {
        let a = self.value - self.target;
        (a, self.rate + self.k * a, (-self.k * s).exp())
    }

    /// `(x, ẋ, ẍ)` at `s` seconds after the anchor.
    fn at(&self, s: f64) -> [f64; 3] {
        let (a, b, e) = self.terms(s);
        let k = self.k;
        let line = a + b * s;
        [self.target + line * e, (b - k * line) * e, (k * k * line - 2.0 * k * b) * e]
    }

    /// `∫₀ˢ x`.
    fn integral(&self, s: f64) -> f64 {
        let (a, b, e) = self.terms(s);
        let k = self.k;
        self.target * s + a * (1.0 - e) / k + b * (1.0 - (1.0 + k * s) * e) / (k * k)
    }

    /// Moves the anchor `s` seconds on (the motion unchanged).
    fn advance(&mut self, s: f64) {
        let [x, v, _] = self.at(s);
        self.value = x;
        self.rate = v;
    }
}

/// A spatial pivot drive steered while it runs: the pivot circles a centre `c(t)` (the
/// hand) at radius `r(t)` and angular speed `ω(t)` in the horizontal plane,
/// ```text
/// p = c + r e_r,   e_r = (cos φ, sin φ, 0),   e_φ = (−sin φ, cos φ, 0),   φ̇ = ω
/// ṗ = ċ + ṙ e_r + r ω e_φ
/// p̈ = c̈ + (r̈ − r ω²) e_r + (2 ṙ ω + r ω̇) e_φ
/// ```
/// where `c` (each component), `r` and `ω` are `Follower`s of their targets: `c` at the
/// hand's rate, `r` and `ω` at the circle's. Targets change through
/// [`steer`](Self::steer), [`set_radius`](Self::set_radius) and
/// [`set_speed`](Self::set_speed) at a time `t`; the motion before `t` is unchanged and
/// `p`, `ṗ` are continuous across it. Times before the last change continue the present
/// motion backwards (they are not the history).
#[derive(Debug, Clone, PartialEq)]
pub struct Steered {
    anchor: f64,
    centre: [Follower; 3],
    radius: Follower,
    speed: Follower,
    phase: f64,
}

impl Steered {
    /// At rest at the origin from `t = 0` (centre 0, radius 0, speed 0): `hand` (1/s) is
    /// the rate at which the centre follows its target, `circle` (1/s) the rate of radius
    /// and speed.
    ///
    /// Errors: [`Error::InvalidDrive`] unless both rates are finite and positive.
    pub fn new(hand: f64, circle: f64) -> Result<Self> {
        for (what, k) in [("hand rate", hand), ("circle rate", circle)] {
            if !(k.is_finite() && k > 0.0) {
                return Err(Error::InvalidDrive { what, requirement: "finite and positive", value: k });
            }
        }
        Ok(Self {
            anchor: 0.0,
            centre: [Follower::new(0.0, hand); 3],
            radius: Follower::new(0.0, circle),
            speed: Follower::new(0.0, circle),
            phase: 0.0,
        })
    }

    /// Moves the anchor to `t` (nothing changes in the motion).
    fn rebase(&mut self, t: f64) {
        let s = t - self.anchor;
        self.phase += self.speed.integral(s);
        for f in self.centre.iter_mut().chain([&mut self.radius, &mut self.speed]) {
            f.advance(s);
        }
        self.anchor = t;
    }

    /// From `t` on, the centre heads for `target` (m).
    ///
    /// Errors: [`Error::InvalidDrive`] (`"target"`) when a component is not finite.
    pub fn steer(&mut self, t: f64, target: Vector3<f64>) -> Result<()> {
        for v in target.iter() {
            check_parameter("target", *v, false)?;
        }
        self.rebase(t);
        for (f, v) in self.centre.iter_mut().zip(target.iter()) {
            f.target = *v;
        }
        Ok(())
    }

    /// From `t` on, the radius heads for `radius` (m, finite and `≥ 0`).
    pub fn set_radius(&mut self, t: f64, radius: f64) -> Result<()> {
        let radius = check_parameter("radius", radius, true)?;
        self.rebase(t);
        self.radius.target = radius;
        Ok(())
    }

    /// From `t` on, the speed heads for `speed` (rad/s, finite).
    pub fn set_speed(&mut self, t: f64, speed: f64) -> Result<()> {
        let speed = check_parameter("angular frequency", speed, false)?;
        self.rebase(t);
        self.speed.target = speed;
        Ok(())
    }

    /// The centre's target, m.
    pub fn target(&self) -> Vector3<f64> {
        Vector3::from_fn(|k, _| self.centre[k].target)
    }

    /// The radius and speed aimed at: `(r*, ω*)`, m and rad/s.
    pub fn circle_target(&self) -> (f64, f64) {
        (self.radius.target, self.speed.target)
    }

    /// The centre `c(t)`, m.
    pub fn centre(&self, t: f64) -> Vector3<f64> {
        Vector3::from_fn(|k, _| self.centre[k].at(t - self.anchor)[0])
    }

    /// The azimuth `φ(t)` of the pivot about the centre, rad (unwrapped).
    pub fn phase(&self, t: f64) -> f64 {
        self.phase + self.speed.integral(t - self.anchor)
    }

    /// The radius `r(t)`, m, and speed `ω(t)`, rad/s.
    pub fn circle(&self, t: f64) -> (f64, f64) {
        let s = t - self.anchor;
        (self.radius.at(s)[0], self.speed.at(s)[0])
    }

    /// The channels at `t`.
    fn parts(&self, t: f64) -> Parts {
        let s = t - self.anchor;
        let c = self.centre.map(|f| f.at(s));
        let (sin, cos) = self.phase(t).sin_cos();
        Parts {
            centre: [0, 1, 2].map(|d| Vector3::new(c[0][d], c[1][d], c[2][d])),
            radius: self.radius.at(s),
            speed: self.speed.at(s),
            e_r: Vector3::new(cos, sin, 0.0),
            e_phi: Vector3::new(-sin, cos, 0.0),
        }
    }
}

/// `(c, ċ, c̈)`, `(r, ṙ, r̈)`, `(ω, ω̇, ω̈)` and the axes `e_r`, `e_φ` at one time.
struct Parts {
    centre: [Vector3<f64>; 3],
    radius: [f64; 3],
    speed: [f64; 3],
    e_r: Vector3<f64>,
    e_phi: Vector3<f64>,
}

impl Drive<U3> for Steered {
    fn position(&self, t: f64) -> Vector3<f64> {
        let Parts { centre: [c, ..], radius: [r, ..], e_r, .. } = self.parts(t);
        c + e_r * r
    }
    fn velocity(&self, t: f64) -> Vector3<f64> {
        let Parts { centre: [_, c, _], radius: [r, r_dot, _], speed: [w, ..], e_r, e_phi } = self.parts(t);
        c + e_r * r_dot + e_phi * (r * w)
    }
    fn acceleration(&self, t: f64) -> Vector3<f64> {
        let Parts { centre: [.., c], radius: [r, r_dot, r_ddot], speed: [w, w_dot, _], e_r, e_phi } =
            self.parts(t);
        c + e_r * (r_ddot - r * w * w) + e_phi * (2.0 * r_dot * w + r * w_dot)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_follower_is_its_own_equation() {
        let f = Follower { value: 0.3, rate: -2.0, target: 1.1, k: 7.0 };
        for s in [0.0, 0.05, 0.4, 2.0] {
            let [x, v, a] = f.at(s);
            assert!((a - (49.0 * (1.1 - x) - 14.0 * v)).abs() < 1e-12, "ẍ at {s}");
            let eps = 1e-6;
            let dx = (f.at(s + eps)[0] - f.at(s - eps)[0]) / (2.0 * eps);
            assert!((dx - v).abs() < 1e-8, "ẋ at {s}");
            let di = (f.integral(s + eps) - f.integral(s - eps)) / (2.0 * eps);
            assert!((di - x).abs() < 1e-8, "∫x at {s}");
        }
        let [x0, v0, _] = f.at(0.0);
        assert!((x0 - 0.3).abs() < 1e-15 && v0 == -2.0, "the start");
        assert_eq!(f.integral(0.0), 0.0);
        assert!((f.at(5.0)[0] - 1.1).abs() < 1e-12, "settled");
    }

    #[test]
    fn steering_keeps_position_and_velocity_continuous() {
        let mut d = Steered::new(25.0, 2.0).unwrap();
        d.set_radius(0.0, 0.02).unwrap();
        d.set_speed(0.0, 6.0).unwrap();
        d.steer(0.3, Vector3::new(0.1, -0.05, 0.02)).unwrap();
        let t = 0.7;
        let before = d.clone();
        d.steer(t, Vector3::new(-0.2, 0.1, 0.0)).unwrap();
        d.set_speed(t, -3.0).unwrap();
        assert!((d.position(t) - before.position(t)).norm() < 1e-15);
        assert!((d.velocity(t) - before.velocity(t)).norm() < 1e-14);
        assert!((d.acceleration(t) - before.acceleration(t)).norm() > 1.0, "the steer acts at once");
        super::super::tests::assert_consistent(&d);
        // Long after, the pivot circles the target at the target radius and speed.
        let late = 20.0;
        assert!((d.centre(late) - Vector3::new(-0.2, 0.1, 0.0)).norm() < 1e-12);
        let (r, w) = d.circle(late);
        assert!((r - 0.02).abs() < 1e-12 && (w + 3.0).abs() < 1e-12);
        assert!(((d.position(late) - d.centre(late)).norm() - 0.02).abs() < 1e-12);
    }

    #[test]
    fn bad_values_name_themselves() {
        assert!(Steered::new(0.0, 1.0).unwrap_err().to_string().contains("hand rate"));
        let mut d = Steered::new(1.0, 1.0).unwrap();
        assert!(d.set_radius(0.0, -1.0).unwrap_err().to_string().contains("radius"));
        assert!(d.set_speed(0.0, f64::NAN).is_err());
        assert!(d.steer(0.0, Vector3::new(0.0, f64::INFINITY, 0.0)).is_err());
        assert_eq!(d, Steered::new(1.0, 1.0).unwrap(), "a refused change changes nothing");
    }
}
