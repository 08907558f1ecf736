//! Kolodner's heavy rotating string: the continuum a uniform chain of many links
//! approaches, turning rigidly at ω about the vertical through its top (or with its top
//! driven round a horizontal circle of radius `R` at ω).
//!
//! # The equations
//!
//! Measure the arclength `s` up from the free end (`0 ≤ s ≤ L`), let `x(s)` be the signed
//! distance from the axis in the turning plane and `H(s)` the horizontal component of the
//! tension divided by the line density. The vertical component carries the weight below,
//! `g s`; the horizontal one the centripetal force on the part below:
//!
//! ```text
//! dH/ds = −ω² x,   dx/ds = r / √(1 + r²),   dz/ds = 1 / √(1 + r²),   r = H / (g s),
//! ```
//!
//! with `H(0) = 0` at the free end (where `r → −ω² x(0) / g`) and `x(L) = R` at the top.
//! Linearised, `g (s x′)′ + ω² x = 0`: `x = x(0) J₀(2ω √(s/g))`, so branches leave the
//! vertical (`R = 0`) at `ω_k = (j_{0,k}/2) √(g/L)` — Bernoulli's frequencies of the
//! hanging chain, Kolodner's critical speeds — the k-th with `k − 1` axis crossings.
//!
//! # The solution
//!
//! A shooting method: for a tip `x(0) = a`, RK4 in `s` (smooth: the solution is analytic
//! in `s`) gives `x(L; a, ω)`; the steady shapes at ω are the roots of
//! `x(L; a, ω) = R` in `a`, found by a scan of `R − L ≤ a ≤ R + L` and bisection. This is
//! the nonlinear eigenproblem of Kolodner (1955); its branches bound what a chain of many
//! links does, with an error of order `1/n` (`docs/rotating-chain.md`).

use crate::analysis::bessel::bessel_j0_zero;
use crate::analysis::modes::sign_changes;
use crate::error::{Error, Result};

/// A heavy uniform string of length `L` under gravity, turning about the vertical.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RotatingString {
    length: f64,
    gravity: f64,
    radius: f64,
}

/// One steady shape of the string.
#[derive(Debug, Clone, PartialEq)]
pub struct StringShape {
    /// Angular speed, rad/s.
    pub omega: f64,
    /// Signed distance of the free end from the axis, m (+ on the pivot's side for a
    /// circling top; for a fixed top the shape and its mirror image both turn, and the
    /// positive one is given).
    pub tip: f64,
    /// The pivot and the axis crossings below it (a fixed top, on the axis, counts once).
    pub nodes: usize,
    /// Signed distance from the axis at `STEPS + 1` points equally spaced along the
    /// string, from the top down, m.
    pub x: Vec<f64>,
    /// Depth below the top at the same points, m.
    pub depth: Vec<f64>,
}

impl StringShape {
    /// The free end's distance from the axis, m.
    pub fn tip_radius(&self) -> f64 {
        self.tip.abs()
    }
}

/// RK4 steps along the string for the shapes given (their error is about 1e-13 L).
const STEPS: usize = 2000;
/// RK4 steps of the scan for roots and of [`RotatingString::sketch_at`] (error about
/// 1e-9 L).
const COARSE: usize = 200;
/// Points of the scan for the tip.
const SCAN: usize = 400;

impl RotatingString {
    /// A string of length `length` (m) under `gravity` (m/s²), its top at distance
    /// `radius` (m) from the axis (0: fixed on the axis).
    ///
    /// Errors: [`Error::InvalidSteady`] for a length or gravity that is not finite and
    /// positive, or a radius that is not finite and non-negative.
    pub fn new(length: f64, gravity: f64, radius: f64) -> Result<Self> {
        let check = |what: &'static str, value: f64, ok: bool, requirement: &'static str| {
            if ok { Ok(()) } else { Err(Error::InvalidSteady { what, requirement, value }) }
        };
        check("string length", length, length.is_finite() && length > 0.0, "finite and positive")?;
        check("gravity", gravity, gravity.is_finite() && gravity > 0.0, "finite and positive")?;
        check("pivot radius", radius, radius.is_finite() && radius >= 0.0, "finite and non-negative")?;
        Ok(Self { length, gravity, radius })
    }

    /// The first `count` critical speeds `ω_k = (j_{0,k}/2) √(g/L)`, rad/s, where the
    /// k-node branches of a fixed top leave the vertical.
    pub fn critical_speeds(&self, count: usize) -> Vec<f64> {
        let scale = (self.gravity / self.length).sqrt();
        (1..=count).map(|k| 0.5 * bessel_j0_zero(k) * scale).collect()
    }

    /// Integrates from the free end at `x(0) = tip` (m) to the top at speed `omega`:
    /// `x(L)`, and with `keep` the shape (x, height above the free end) at every step.
    fn shoot(&self, omega: f64, tip: f64, steps: usize, keep: bool) -> (f64, Vec<(f64, f64)>) {
        let (g, w2) = (self.gravity, omega * omega);
        let h = self.length / steps as f64;
        // y = (x, H, z); r = H / (g s) with its limit at the free end.
        let rate = |s: f64, y: [f64; 3]| {
            let r = if s == 0.0 { -w2 * y[0] / g } else { y[1] / (g * s) };
            let c = 1.0 / (1.0 + r * r).sqrt();
            [r * c, -w2 * y[0], c]
        };
        let add = |y: [f64; 3], k: [f64; 3], f: f64| [y[0] + f * k[0], y[1] + f * k[1], y[2] + f * k[2]];
        let mut y = [tip, 0.0, 0.0];
        let mut path = Vec::with_capacity(if keep { steps + 1 } else { 0 });
        for i in 0..steps {
            if keep {
                path.push((y[0], y[2]));
            }
            let s = i as f64 * h;
            let k1 = rate(s, y);
            let k2 = rate(s + 0.5 * h, add(y, k1, 0.5 * h));
            let k3 = rate(s + 0.5 * h, add(y, k2, 0.5 * h));
            let k4 = rate(s + h, add(y, k3, h));
            for j in 0..3 {
                y[j] += h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]);
            }
        }
        if keep {
            path.push((y[0], y[2]));
        }
        (y[0], path)
    }

    /// Every steady shape at speed `omega` (rad/s), by tip: for a fixed top the shapes
    /// off the vertical (tip > 0; their mirror images turn too), for a circling top all
    /// of them. Ordered by tip; the tips to about 1e-14 L.
    ///
    /// Errors: [`Error::InvalidSteady`] for a negative or non-finite speed.
    pub fn shapes_at(&self, omega: f64) -> Result<Vec<StringShape>> {
        let brackets = self.brackets(omega)?;
        let fine = |a: f64| self.shoot(omega, a, STEPS, false).0 - self.radius;
        Ok(brackets
            .into_iter()
            .map(|(a, b)| self.shape(omega, refine(&fine, a, b, self.length), STEPS))
            .collect())
    }

    /// [`shapes_at`](Self::shapes_at) to about 1e-8 L, at a tenth of the cost: for
    /// pictures of the branches.
    ///
    /// Errors: as [`shapes_at`](Self::shapes_at).
    pub fn sketch_at(&self, omega: f64) -> Result<Vec<StringShape>> {
        Ok(self.brackets(omega)?.into_iter().map(|(a, b)| self.shape(omega, 0.5 * (a + b), COARSE)).collect())
    }

    /// Intervals of the tip, each holding one root of `x(L) = R` and about 1e-8 L wide:
    /// a scan and bisection on the coarse integration.
    fn brackets(&self, omega: f64) -> Result<Vec<(f64, f64)>> {
        if !(omega.is_finite() && omega >= 0.0) {
            return Err(Error::InvalidSteady {
                what: "speed",
                requirement: "finite and non-negative",
                value: omega,
            });
        }
        let miss = |a: f64| self.shoot(omega, a, COARSE, false).0 - self.radius;
        let (low, high) = if self.radius == 0.0 {
            // The vertical (a = 0) solves it at every speed: scan above it.
            (1e-9 * self.length, self.length)
        } else {
            (self.radius - self.length, self.radius + self.length)
        };
        let grid: Vec<f64> = (0..=SCAN).map(|i| low + (high - low) * i as f64 / SCAN as f64).collect();
        let values: Vec<f64> = grid.iter().map(|&a| miss(a)).collect();
        let mut out = Vec::new();
        for i in 0..SCAN {
            let (mut a, mut b, mut fa) = (grid[i], grid[i + 1], values[i]);
            if fa == 0.0 || fa.signum() == values[i + 1].signum() {
                continue;
            }
            while b - a > 1e-8 * self.length {
                let mid = 0.5 * (a + b);
                let fm = miss(mid);
                if fm.signum() == fa.signum() {
                    (a, fa) = (mid, fm);
                } else {
                    b = mid;
                }
            }
            out.push((a, b));
        }
        Ok(out)
    }

    /// The shape from tip `tip` at `omega`, integrated in `steps` steps.
    fn shape(&self, omega: f64, tip: f64, steps: usize) -> StringShape {
        let (_, path) = self.shoot(omega, tip, steps, true);
        let top = path.last().map_or(0.0, |p| p.1);
        // From the top down.
        let x: Vec<f64> = path.iter().rev().map(|p| p.0).collect();
        let depth: Vec<f64> = path.iter().rev().map(|p| top - p.1).collect();
        // Axis crossings below the top; a fixed top (x = 0 there) is the pivot node itself.
        let below = if self.radius == 0.0 { &x[1..] } else { &x[..] };
        let crossings = sign_changes(below);
        StringShape { omega, tip, nodes: 1 + crossings, x, depth }
    }
}

/// The root of `f` near the bracket `[a, b]` (a few 1e-8 `scale` wide, found on a coarser
/// `f`): the bracket widened until `f` changes sign on it, then the Illinois variant of
/// regula falsi to 1e-15 `scale`.
fn refine(f: &dyn Fn(f64) -> f64, a: f64, b: f64, scale: f64) -> f64 {
    let (mut a, mut b) = (a, b);
    let (mut fa, mut fb) = (f(a), f(b));
    let mut widen = b - a;
    while fa.signum() == fb.signum() && widen < 1e-4 * scale {
        widen *= 4.0;
        (a, b) = (a - widen, b + widen);
        (fa, fb) = (f(a), f(b));
    }
    if fa.signum() == fb.signum() {
        return 0.5 * (a + b);
    }
    let mut side = 0;
    for _ in 0..100 {
        let c = (a * fb - b * fa) / (fb - fa);
        let fc = f(c);
        if fc == 0.0 || (b - a).abs() <= 1e-15 * scale {
            return c;
        }
        if fc.signum() == fb.signum() {
            (b, fb) = (c, fc);
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        } else {
            (a, fa) = (c, fc);
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        }
        if (b - a).abs() <= 1e-15 * scale {
            return 0.5 * (a + b);
        }
    }
    0.5 * (a + b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn near_a_critical_speed_the_string_leaves_the_vertical_in_the_bessel_shape() {
        let string = RotatingString::new(1.0, 9.81, 0.0).unwrap();
        let critical = string.critical_speeds(3);
        for (k, &w) in critical.iter().enumerate() {
            // Just below ω_k there are k − 1 shapes off the vertical; just above, k.
            assert_eq!(string.shapes_at(w * (1.0 - 1e-4)).unwrap().len(), k, "below ω_{}", k + 1);
            let above = string.shapes_at(w * (1.0 + 1e-4)).unwrap();
            assert_eq!(above.len(), k + 1, "above ω_{}", k + 1);
            // The new one is small, with k + 1 − 1 = k nodes counted with the pivot.
            let new = above.iter().min_by(|a, b| a.tip.total_cmp(&b.tip)).unwrap();
            assert!(new.tip < 0.05, "ω_{}: tip {}", k + 1, new.tip);
            assert_eq!(new.nodes, k + 1);
            // Its shape is J0(2ω√(s/g)) scaled to its tip (s up from the free end).
            for (i, &x) in new.x.iter().enumerate().step_by(100) {
                let s = 1.0 - i as f64 / STEPS as f64;
                let bessel = bessel_j0(2.0 * w * (s / 9.81).sqrt());
                assert!(
                    (x / new.tip - bessel).abs() < 2e-2,
                    "ω_{}: s = {s}: {} against {bessel}",
                    k + 1,
                    x / new.tip
                );
            }
        }
    }

    #[test]
    fn a_fast_string_is_nearly_straight_and_a_circling_top_has_its_forced_shape() {
        // Far above the first critical speed the one-node shape swings out: tip near L.
        let string = RotatingString::new(1.0, 9.81, 0.0).unwrap();
        let shapes = string.shapes_at(60.0).unwrap();
        let one = shapes.iter().find(|s| s.nodes == 1).unwrap();
        assert!(one.tip > 0.99, "{}", one.tip);
        // Every shape has the string's length: the chords between the points, L/STEPS of
        // arc apart, add up to L less the chords' shortfall on the curved arc.
        for s in &shapes {
            let length: f64 =
                s.x.windows(2).zip(s.depth.windows(2)).map(|(x, d)| (x[1] - x[0]).hypot(d[1] - d[0])).sum();
            assert!(length < 1.0 && 1.0 - length < 1e-5, "{length}");
        }
        // A circling top below the first critical speed: one shape, on the pivot's side.
        let forced = RotatingString::new(1.0, 9.81, 0.02).unwrap();
        let slow = forced.shapes_at(2.0).unwrap();
        assert_eq!(slow.len(), 1);
        assert!(slow[0].tip > 0.02 && slow[0].nodes == 1, "{:?}", slow[0].tip);
        assert!((slow[0].x[0] - 0.02).abs() < 1e-12);
    }

    #[test]
    fn bad_strings_are_refused() {
        assert!(RotatingString::new(0.0, 9.81, 0.0).is_err());
        assert!(RotatingString::new(1.0, f64::NAN, 0.0).is_err());
        assert!(RotatingString::new(1.0, 9.81, -1.0).is_err());
        assert!(RotatingString::new(1.0, 9.81, 0.0).unwrap().shapes_at(-1.0).is_err());
    }

    /// J0 by its power series (enough for the test's arguments, below 10).
    fn bessel_j0(x: f64) -> f64 {
        let (mut term, mut sum) = (1.0, 1.0);
        for k in 1..60 {
            term *= -(x * x / 4.0) / (k * k) as f64;
            sum += term;
        }
        sum
    }
}
