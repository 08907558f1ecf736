//! A pivot that follows sampled positions: the cubic spline through them, so that a motion
//! of one's own (measured, planned, or computed elsewhere) drives a chain with a position,
//! velocity and acceleration that agree at every time.

use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

use nalgebra::{DefaultAllocator, DimName, OVector, allocator::Allocator};

use super::Drive;
use crate::error::{Error, Result};

/// The pivot on the cubic spline through positions `p_k` (m) sampled at times `t_0 < t_1 <
/// … < t_m` (s), any spacing. With `h_k = t_{k+1} − t_k`, `d_k = (p_{k+1} − p_k)/h_k` and
/// the spline's accelerations `M_k = p̈(t_k)`, on `[t_k, t_{k+1}]`, `a = (t_{k+1} − t)/h_k`,
/// `b = (t − t_k)/h_k`:
/// ```text
/// p(t) = a p_k + b p_{k+1} + h_k²/6 ((a³ − a) M_k + (b³ − b) M_{k+1})
/// ṗ(t) = d_k + h_k/6 ((1 − 3a²) M_k + (3b² − 1) M_{k+1})
/// p̈(t) = a M_k + b M_{k+1}
/// ```
/// where the `M_k` make `ṗ` continuous at every inner sample:
/// ```text
/// h_{k−1}/6 M_{k−1} + (h_{k−1} + h_k)/3 M_k + h_k/6 M_{k+1} = d_k − d_{k−1}
/// ```
/// closed by the ends: `M_0 = M_m = 0` ([`new`](Self::new), the natural spline), or the
/// velocities `v_0`, `v_m` given there ([`with_end_velocities`](Self::with_end_velocities):
/// `h_0/3 M_0 + h_0/6 M_1 = d_0 − v_0` and `h_{m−1}/6 M_{m−1} + h_{m−1}/3 M_m = v_m − d_{m−1}`).
/// `p`, `ṗ`, `p̈` are continuous, and `p̈` linear between samples. Before `t_0` and after
/// `t_m` the pivot moves on in a straight line at its end velocity (`p̈ = 0`): at rest,
/// if the end velocities given are zero.
///
/// The spline passes through every sample, and reproduces a cubic motion exactly when the
/// end velocities are its own: its error for a smooth motion sampled every `h`, given its
/// end velocities, falls as `h⁴` in `p` (`h²` in `p̈`). The natural spline's `p̈ = 0` at the
/// ends differs from a motion that accelerates there, over the first and last few samples.
/// A drive in any space: `(x, y)` planar, `(x, y, z)` spatial.
///
/// A clone shares the samples (one path for many chains costs its samples once).
///
/// ```
/// use nalgebra::Vector2;
/// use pendulum_core::{Drive, Sampled};
///
/// // A pivot lifted 5 cm and set down again over 1 s, at rest before and after.
/// let times = vec![0.0, 0.5, 1.0];
/// let up = vec![Vector2::zeros(), Vector2::new(0.0, 0.05), Vector2::zeros()];
/// let lift = Sampled::with_end_velocities(times, up, Vector2::zeros(), Vector2::zeros())?;
/// assert_eq!(lift.position(0.5), Vector2::new(0.0, 0.05));
/// assert_eq!(lift.velocity(2.0), Vector2::zeros());
/// # Ok::<(), pendulum_core::Error>(())
/// ```
#[derive(Debug)]
pub struct Sampled<S: DimName>
where
    DefaultAllocator: Allocator<S>,
{
    /// The piece the last time read fell in (a hint for the next: no result depends on it).
    last_piece: AtomicUsize,
    times: Arc<[f64]>,
    positions: Arc<[OVector<f64, S>]>,
    /// `M_k = p̈(t_k)`, m/s².
    accelerations: Arc<[OVector<f64, S>]>,
    /// `ṗ(t_0)` and `ṗ(t_m)`, m/s, as given or (natural) as the spline has them: the
    /// straight lines outside.
    end_velocities: [OVector<f64, S>; 2],
}

impl<S: DimName> Sampled<S>
where
    DefaultAllocator: Allocator<S>,
{
    /// The natural spline (`p̈ = 0` at the first and last sample) through `positions` (m)
    /// at `times` (s).
    ///
    /// Errors: [`Error::TooFewSamples`] for fewer than two samples,
    /// [`Error::LengthMismatch`] for a number of positions other than of times,
    /// [`Error::NonFinite`] naming a time or position that is not finite,
    /// [`Error::UnorderedTimes`] for a time not after the one before it, and
    /// [`Error::InvalidDrive`] when the spline's accelerations overflow.
    pub fn new(times: Vec<f64>, positions: Vec<OVector<f64, S>>) -> Result<Self> {
        Self::build(times, positions, None)
    }

    /// The spline through `positions` (m) at `times` (s) whose velocities at the first and
    /// last sample are `start` and `end` (m/s): zero for a pivot that starts and ends at
    /// rest.
    ///
    /// Errors: as [`new`](Self::new), and [`Error::NonFinite`] for an end velocity that
    /// is not finite.
    pub fn with_end_velocities(
        times: Vec<f64>,
        positions: Vec<OVector<f64, S>>,
        start: OVector<f64, S>,
        end: OVector<f64, S>,
    ) -> Result<Self> {
        Self::build(times, positions, Some([start, end]))
    }

    fn build(
        times: Vec<f64>,
        positions: Vec<OVector<f64, S>>,
        ends: Option<[OVector<f64, S>; 2]>,
    ) -> Result<Self> {
        check_samples(&times, &positions, ends.as_ref())?;
        let accelerations = spline_accelerations(&times, &positions, ends.as_ref());
        if let Some(value) = accelerations.iter().flat_map(|a| a.iter()).find(|v| !v.is_finite()) {
            let requirement = "finite (samples far apart in space for their spacing in time)";
            return Err(Error::InvalidDrive { what: "spline acceleration", requirement, value: *value });
        }
        let given = ends.is_some();
        let zero = || OVector::zeros();
        let mut sampled = Self {
            last_piece: AtomicUsize::new(0),
            times: times.into(),
            positions: positions.into(),
            accelerations: accelerations.into(),
            end_velocities: ends.unwrap_or_else(|| [zero(), zero()]),
        };
        if !given {
            // The natural spline's own, which the straight lines outside continue.
            let last = sampled.times.len() - 1;
            let start = sampled.velocity_at(sampled.locate(sampled.times[0]));
            let end = sampled.velocity_at(sampled.locate(sampled.times[last]));
            sampled.end_velocities = [start, end];
        }
        Ok(sampled)
    }

    /// The sample times `t_k`, s.
    pub fn times(&self) -> &[f64] {
        &self.times
    }

    /// The sampled positions `p_k`, m.
    pub fn positions(&self) -> &[OVector<f64, S>] {
        &self.positions
    }

    /// Where `t` lies: before the samples, on piece `k` with its `(h_k, a, b)`, or after.
    fn locate(&self, t: f64) -> Where {
        let last = self.times.len() - 1;
        if t < self.times[0] {
            return Where::Before;
        }
        if t > self.times[last] {
            return Where::After;
        }
        let k = self.piece(t);
        let h = self.times[k + 1] - self.times[k];
        Where::On(k, h, (self.times[k + 1] - t) / h, (t - self.times[k]) / h)
    }

    /// `p(t)` (the type's equation; the straight lines outside).
    fn position_at(&self, t: f64, at: Where) -> OVector<f64, S> {
        let last = self.times.len() - 1;
        match at {
            Where::Before => &self.positions[0] + &self.end_velocities[0] * (t - self.times[0]),
            Where::After => &self.positions[last] + &self.end_velocities[1] * (t - self.times[last]),
            Where::On(k, h, a, b) => {
                let (p0, p1) = (&self.positions[k], &self.positions[k + 1]);
                let (m0, m1) = (&self.accelerations[k], &self.accelerations[k + 1]);
                p0 * a + p1 * b + (m0 * (a * a * a - a) + m1 * (b * b * b - b)) * (h * h / 6.0)
            }
        }
    }

    /// `ṗ(t)`.
    fn velocity_at(&self, at: Where) -> OVector<f64, S> {
        match at {
            Where::Before => self.end_velocities[0].clone(),
            Where::After => self.end_velocities[1].clone(),
            Where::On(k, h, a, b) => {
                let (p0, p1) = (&self.positions[k], &self.positions[k + 1]);
                let (m0, m1) = (&self.accelerations[k], &self.accelerations[k + 1]);
                (p1 - p0) / h + (m0 * (1.0 - 3.0 * a * a) + m1 * (3.0 * b * b - 1.0)) * (h / 6.0)
            }
        }
    }

    /// `p̈(t)`.
    fn acceleration_at(&self, at: Where) -> OVector<f64, S> {
        match at {
            Where::Before | Where::After => OVector::zeros(),
            Where::On(k, _, a, b) => &self.accelerations[k] * a + &self.accelerations[k + 1] * b,
        }
    }

    /// The piece `k` of `t` in `[t_0, t_m]`: the last sample time at or before `t` (the last
    /// piece for `t_m` itself; NaN lands on the first and stays NaN). The last piece read,
    /// or the one after it, when `t` is there (a run reads its times in order), else by
    /// bisection: the same piece either way. Kept only when it changes (chains sharing one
    /// path do not write to one place at every read).
    fn piece(&self, t: f64) -> usize {
        let last = self.times.len() - 1;
        let holds = |k: usize| k < last && self.times[k] <= t && (t < self.times[k + 1] || k + 1 == last);
        let hint = self.last_piece.load(Ordering::Relaxed);
        if holds(hint) {
            return hint;
        }
        let k = if holds(hint + 1) {
            hint + 1
        } else {
            self.times.partition_point(|&s| s <= t).saturating_sub(1).min(last - 1)
        };
        self.last_piece.store(k, Ordering::Relaxed);
        k
    }
}

impl<S: DimName> Clone for Sampled<S>
where
    DefaultAllocator: Allocator<S>,
{
    /// The same path, its samples shared.
    fn clone(&self) -> Self {
        Self {
            last_piece: AtomicUsize::new(self.last_piece.load(Ordering::Relaxed)),
            times: Arc::clone(&self.times),
            positions: Arc::clone(&self.positions),
            accelerations: Arc::clone(&self.accelerations),
            end_velocities: self.end_velocities.clone(),
        }
    }
}

impl<S: DimName> PartialEq for Sampled<S>
where
    DefaultAllocator: Allocator<S>,
{
    /// The same samples and ends (the hint of the last piece read aside).
    fn eq(&self, other: &Self) -> bool {
        self.times == other.times
            && self.positions == other.positions
            && self.accelerations == other.accelerations
            && self.end_velocities == other.end_velocities
    }
}

/// The checks of [`Sampled::new`] and [`Sampled::with_end_velocities`].
fn check_samples<S: DimName>(
    times: &[f64],
    positions: &[OVector<f64, S>],
    ends: Option<&[OVector<f64, S>; 2]>,
) -> Result<()>
where
    DefaultAllocator: Allocator<S>,
{
    if times.len() < 2 {
        return Err(Error::TooFewSamples { got: times.len() });
    }
    if positions.len() != times.len() {
        return Err(Error::LengthMismatch { what: "positions", expected: times.len(), got: positions.len() });
    }
    let non_finite = |what, index, value: f64| Error::NonFinite { what, index, value };
    for (index, &value) in times.iter().enumerate() {
        if !value.is_finite() {
            return Err(non_finite("times", index, value));
        }
        if index > 0 && value <= times[index - 1] {
            return Err(Error::UnorderedTimes { index, value, previous: times[index - 1] });
        }
    }
    for (index, p) in positions.iter().enumerate() {
        if let Some(&value) = p.iter().find(|v| !v.is_finite()) {
            return Err(non_finite("positions", index, value));
        }
    }
    for (index, v) in ends.into_iter().flatten().enumerate() {
        if let Some(&value) = v.iter().find(|v| !v.is_finite()) {
            return Err(non_finite("end velocities", index, value));
        }
    }
    Ok(())
}

/// The spline's `M_k` (the type's tridiagonal system, diagonally dominant) by the Thomas
/// algorithm, all components at once.
fn spline_accelerations<S: DimName>(
    times: &[f64],
    positions: &[OVector<f64, S>],
    ends: Option<&[OVector<f64, S>; 2]>,
) -> Vec<OVector<f64, S>>
where
    DefaultAllocator: Allocator<S>,
{
    let m = times.len() - 1;
    let h: Vec<f64> = times.windows(2).map(|w| w[1] - w[0]).collect();
    let d: Vec<OVector<f64, S>> = (0..m).map(|k| (&positions[k + 1] - &positions[k]) / h[k]).collect();
    // Row k: below[k] M_{k−1} + diagonal[k] M_k + above[k] M_{k+1} = rhs[k].
    let mut below = vec![0.0; m + 1];
    let mut diagonal = vec![1.0; m + 1];
    let mut above = vec![0.0; m + 1];
    let mut rhs = vec![OVector::<f64, S>::zeros(); m + 1];
    for k in 1..m {
        below[k] = h[k - 1] / 6.0;
        diagonal[k] = (h[k - 1] + h[k]) / 3.0;
        above[k] = h[k] / 6.0;
        rhs[k] = &d[k] - &d[k - 1];
    }
    if let Some([start, end]) = ends {
        (diagonal[0], above[0], rhs[0]) = (h[0] / 3.0, h[0] / 6.0, &d[0] - start);
        (below[m], diagonal[m], rhs[m]) = (h[m - 1] / 6.0, h[m - 1] / 3.0, end - &d[m - 1]);
    }
    // Forward elimination, then back substitution.
    for k in 1..=m {
        let factor = below[k] / diagonal[k - 1];
        diagonal[k] -= factor * above[k - 1];
        let previous = rhs[k - 1].clone();
        rhs[k] -= previous * factor;
    }
    let mut accelerations = vec![OVector::<f64, S>::zeros(); m + 1];
    accelerations[m] = &rhs[m] / diagonal[m];
    for k in (0..m).rev() {
        accelerations[k] = (&rhs[k] - &accelerations[k + 1] * above[k]) / diagonal[k];
    }
    accelerations
}

impl<S: DimName> Drive<S> for Sampled<S>
where
    DefaultAllocator: Allocator<S>,
{
    fn position(&self, t: f64) -> OVector<f64, S> {
        self.position_at(t, self.locate(t))
    }
    fn velocity(&self, t: f64) -> OVector<f64, S> {
        self.velocity_at(self.locate(t))
    }
    fn acceleration(&self, t: f64) -> OVector<f64, S> {
        self.acceleration_at(self.locate(t))
    }
    fn velocity_and_acceleration(&self, t: f64) -> (OVector<f64, S>, OVector<f64, S>) {
        let at = self.locate(t);
        (self.velocity_at(at), self.acceleration_at(at))
    }
    fn position_and_velocity(&self, t: f64) -> (OVector<f64, S>, OVector<f64, S>) {
        let at = self.locate(t);
        (self.position_at(t, at), self.velocity_at(at))
    }
}

/// Where a time lies on a [`Sampled`] path: before its samples, on piece `k` (with
/// `h_k`, `a`, `b` of the type's equations), or after them.
#[derive(Debug, Clone, Copy)]
enum Where {
    Before,
    On(usize, f64, f64, f64),
    After,
}

#[cfg(test)]
mod tests {
    use nalgebra::{U2, U3, Vector2, Vector3};

    use super::*;
    use crate::drive::Harmonic;
    use crate::drive::tests::assert_consistent;

    /// A cubic motion, with its velocity and acceleration.
    fn cubic(t: f64) -> [Vector3<f64>; 3] {
        let c = [Vector3::new(0.1, -0.2, 0.3), Vector3::new(1.0, 0.5, -2.0), Vector3::new(-0.7, 0.2, 0.4)];
        let p = Vector3::new(0.5, 0.0, -1.0) + c[0] * t + c[1] * t * t + c[2] * t * t * t;
        let v = c[0] + c[1] * (2.0 * t) + c[2] * (3.0 * t * t);
        let a = c[1] * 2.0 + c[2] * (6.0 * t);
        [p, v, a]
    }

    /// Uneven times from 0 to about 2 s.
    fn uneven() -> Vec<f64> {
        vec![0.0, 0.1, 0.35, 0.4, 0.9, 1.3, 1.31, 2.0]
    }

    #[test]
    fn passes_through_every_sample() {
        let times = uneven();
        let positions: Vec<Vector2<f64>> =
            times.iter().map(|&t| Vector2::new((3.0 * t).sin(), t * t - 0.2)).collect();
        let path = Sampled::<U2>::new(times.clone(), positions.clone()).unwrap();
        for (t, p) in times.iter().zip(&positions) {
            assert!((path.position(*t) - p).norm() < 1e-15, "t = {t}");
        }
    }

    #[test]
    fn a_cubic_with_its_end_velocities_is_reproduced() {
        let times = uneven();
        let positions = times.iter().map(|&t| cubic(t)[0]).collect();
        let (start, end) = (cubic(0.0)[1], cubic(2.0)[1]);
        let path = Sampled::<U3>::with_end_velocities(times, positions, start, end).unwrap();
        for t in [0.0, 0.05, 0.37, 1.0, 1.305, 1.9, 2.0] {
            let [p, v, a] = cubic(t);
            assert!((path.position(t) - p).norm() < 1e-13, "p at {t}");
            assert!((path.velocity(t) - v).norm() < 1e-12, "ṗ at {t}");
            assert!((path.acceleration(t) - a).norm() < 1e-11, "p̈ at {t}: {} vs {a}", path.acceleration(t));
        }
    }

    #[test]
    fn the_natural_spline_is_straight_at_its_ends_and_beyond() {
        let times = uneven();
        let positions: Vec<Vector3<f64>> = times.iter().map(|&t| cubic(t)[0]).collect();
        let path = Sampled::<U3>::new(times, positions.clone()).unwrap();
        assert!(path.acceleration(0.0).norm() < 1e-13 && path.acceleration(2.0).norm() < 1e-13);
        // Outside, a straight line at the end velocity, continuous with the spline.
        let (v0, v1) = (path.velocity(0.0), path.velocity(2.0));
        assert_eq!(path.velocity(-1.0), v0);
        assert_eq!(path.acceleration(3.0), Vector3::zeros());
        assert!((path.position(-1.0) - (positions[0] - v0)).norm() < 1e-15);
        assert!((path.position(3.0) - (positions[7] + v1)).norm() < 1e-14);
        // A straight line sampled is a straight line.
        let line = Sampled::<U2>::new(
            vec![0.0, 0.3, 1.0],
            vec![Vector2::new(0.0, 1.0), Vector2::new(0.6, 0.7), Vector2::new(2.0, 0.0)],
        )
        .unwrap();
        assert!((line.velocity(0.5) - Vector2::new(2.0, -1.0)).norm() < 1e-14);
        assert!(line.acceleration(0.5).norm() < 1e-14);
    }

    #[test]
    fn position_velocity_and_acceleration_agree_and_are_continuous() {
        // Samples from −0.5 s every 0.07 s: the checks' times (0, 0.3, 1.7 s) inside and
        // away from the samples, where `p̈` has its kinks.
        let times: Vec<f64> = (0..=40).map(|k| -0.5 + k as f64 * 0.07).collect();
        let positions = times.iter().map(|&t| Vector2::new((4.0 * t).sin(), (2.0 * t).cos())).collect();
        let path = Sampled::<U2>::new(times.clone(), positions).unwrap();
        assert_consistent(&path);
        // (The checks' times inside: `p̈` jumps to zero at clamped ends.)
        let at_rest = Sampled::<U2>::with_end_velocities(
            vec![-1.0, 0.5, 2.5],
            vec![Vector2::zeros(), Vector2::new(0.1, 0.2), Vector2::zeros()],
            Vector2::zeros(),
            Vector2::zeros(),
        )
        .unwrap();
        assert_consistent(&at_rest);
        assert_eq!(at_rest.position(5.0), Vector2::zeros());
        // Across every inner sample, from either side.
        let eps = 1e-9;
        for &t in &times[1..times.len() - 1] {
            let at = |t: f64| (path.position(t), path.velocity(t), path.acceleration(t));
            let (left, right) = (at(t - eps), at(t + eps));
            assert!((left.0 - right.0).norm() < 1e-8, "p at {t}");
            assert!((left.1 - right.1).norm() < 1e-7, "ṗ at {t}");
            assert!((left.2 - right.2).norm() < 1e-6, "p̈ at {t}");
        }
    }

    #[test]
    fn its_error_for_a_smooth_motion_falls_as_the_fourth_power_of_the_spacing() {
        let motion = Harmonic::<U3>::new(Vector3::new(1.0, 0.0, 1.0), 0.05, 7.0, 0.3).unwrap();
        let error = |samples: usize| {
            let times: Vec<f64> = (0..=samples).map(|k| 2.0 * k as f64 / samples as f64).collect();
            let positions = times.iter().map(|&t| motion.position(t)).collect();
            let (start, end) = (motion.velocity(0.0), motion.velocity(2.0));
            let path = Sampled::with_end_velocities(times, positions, start, end).unwrap();
            (0..1000)
                .map(|j| 2.0 * j as f64 / 999.0)
                .map(|t| (path.position(t) - motion.position(t)).norm())
                .fold(0.0, f64::max)
        };
        let (coarse, fine) = (error(40), error(80));
        let order = (coarse / fine).log2();
        assert!((3.7..4.3).contains(&order), "order {order}: {coarse:e} then {fine:e}");
    }

    #[test]
    fn the_piece_read_last_gives_the_piece_bisection_gives() {
        let times = uneven();
        let positions: Vec<Vector2<f64>> = times.iter().map(|&t| Vector2::new(t.sin(), t * t)).collect();
        let path = Sampled::<U2>::new(times.clone(), positions).unwrap();
        let bisected = |t: f64| times.partition_point(|&s| s <= t).saturating_sub(1).min(times.len() - 2);
        // In order, backwards, jumping, on samples and between them.
        let mut reads: Vec<f64> = (0..=400).map(|k| k as f64 * 0.005).collect();
        reads.extend(reads.clone().iter().rev());
        reads.extend([1.31, 0.0, 2.0, 0.35, 0.4, 0.399, 1.3, 1.309_999, 2.0, 1.31]);
        for t in reads {
            assert_eq!(path.piece(t), bisected(t), "t = {t}");
            let _ = path.position(t);
        }
    }

    #[test]
    fn bad_samples_are_named() {
        let p = |x: f64| Vector2::new(x, 0.0);
        let message = |r: Result<Sampled<U2>>| r.unwrap_err().to_string();
        assert_eq!(
            message(Sampled::new(vec![0.0], vec![p(0.0)])),
            "a sampled drive needs at least 2 samples, got 1"
        );
        assert_eq!(
            message(Sampled::new(vec![0.0, 1.0], vec![p(0.0)])),
            "positions has 1 entries, expected 2"
        );
        assert_eq!(
            message(Sampled::new(vec![0.0, 1.0, 1.0], vec![p(0.0); 3])),
            "times[2] must be after times[1] = 1, got 1"
        );
        assert_eq!(
            message(Sampled::new(vec![0.0, f64::NAN], vec![p(0.0); 2])),
            "times[1] must be finite, got NaN"
        );
        assert_eq!(
            message(Sampled::new(vec![0.0, 1.0], vec![p(0.0), p(f64::INFINITY)])),
            "positions[1] must be finite, got inf"
        );
        assert_eq!(
            message(Sampled::with_end_velocities(vec![0.0, 1.0], vec![p(0.0); 2], p(0.0), p(f64::NAN))),
            "end velocities[1] must be finite, got NaN"
        );
        assert!(
            message(Sampled::new(vec![0.0, 1e-300, 1.0], vec![p(0.0), p(1e300), p(0.0)]))
                .starts_with("drive spline acceleration must be finite")
        );
    }
}
