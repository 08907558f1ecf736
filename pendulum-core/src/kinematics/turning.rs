//! The frame turning with a pivot that circles the vertical axis: the one place a position,
//! a link direction or a state is seen co-rotating (the shape analysis, a continuing run's
//! start, the co-rotating pictures and pages).
//!
//! At the pivot's azimuth `φ` a vector `r` of the inertial frame is
//! `r̃ = Rot_z(−φ) r = (x cos φ + y sin φ, −x sin φ + y cos φ, z)` in the turning frame:
//! the pivot lies on the +x̃ axis, and a steady whirl stands still.

/// The frame turned by the azimuth `φ` of a pivot circling the vertical (z) axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TurningFrame {
    cos: f64,
    sin: f64,
}

impl TurningFrame {
    /// At the azimuth `phase` (rad), e.g. a circling drive's
    /// [`Turning::phase`](crate::drive::Turning::phase).
    pub fn at(phase: f64) -> Self {
        let (sin, cos) = phase.sin_cos();
        Self { cos, sin }
    }

    /// At the azimuth `φ = atan2(p_y, p_x)` of the pivot's position `p` (m): the frame
    /// a recorded trajectory is turned into when only the pivot's positions are known. A
    /// pivot on the axis gives `φ = 0`.
    pub fn of_pivot(p: &[f64; 3]) -> Self {
        let r = p[0].hypot(p[1]);
        if r > 0.0 { Self { cos: p[0] / r, sin: p[1] / r } } else { Self { cos: 1.0, sin: 0.0 } }
    }

    /// The azimuth `φ` in (−π, π], rad.
    pub fn phase(self) -> f64 {
        self.sin.atan2(self.cos)
    }

    /// The horizontal components `(x, y)` of a vector, seen in the turning frame:
    /// `(x cos φ + y sin φ, −x sin φ + y cos φ)`.
    pub fn turn(self, x: f64, y: f64) -> (f64, f64) {
        (self.cos * x + self.sin * y, -self.sin * x + self.cos * y)
    }

    /// A point at `(x, y)` from the pivot (m), in the turning frame with the pivot at
    /// `(radius, 0)`: `(R + x cos φ + y sin φ, −x sin φ + y cos φ)` (the co-rotating
    /// positions of the shape analysis, summed in this order).
    pub fn place(self, radius: f64, x: f64, y: f64) -> (f64, f64) {
        (radius + self.cos * x + self.sin * y, -self.sin * x + self.cos * y)
    }

    /// A 3D state of vectors `(v_1, v_2, …)` (three components each: unit link
    /// directions `u_i` and their rates `w_i`), every one seen in the turning frame.
    pub fn turn_vectors(self, x: &[f64]) -> Vec<f64> {
        let mut y = x.to_vec();
        for v in y.chunks_exact_mut(3) {
            (v[0], v[1]) = self.turn(v[0], v[1]);
        }
        y
    }
}

#[cfg(test)]
mod tests {
    use std::f64::consts::FRAC_PI_2;

    use super::*;

    #[test]
    fn the_pivot_lands_on_the_x_axis_and_vectors_keep_their_length_and_height() {
        let p = [0.3, 0.4, -1.0];
        let frame = TurningFrame::of_pivot(&p);
        let (x, y) = frame.turn(p[0], p[1]);
        assert!((x - 0.5).abs() < 1e-15 && y.abs() < 1e-15, "{x} {y}");
        assert!((frame.phase() - 0.4_f64.atan2(0.3)).abs() < 1e-15);
        let at = TurningFrame::at(frame.phase());
        let (a, b) = at.turn(p[0], p[1]);
        assert!((a - x).abs() < 1e-15 && (b - y).abs() < 1e-15);
        assert_eq!(TurningFrame::of_pivot(&[0.0, 0.0, 2.0]), TurningFrame { cos: 1.0, sin: 0.0 });
    }

    #[test]
    fn a_state_turns_every_vector_about_z() {
        // A quarter turn of the pivot: +y becomes +x̃, +x becomes −ỹ.
        let x = [1.0, 0.0, -1.0, 0.0, 2.0, 0.5];
        let y = TurningFrame::at(FRAC_PI_2).turn_vectors(&x);
        let expected = [0.0, -1.0, -1.0, 2.0, 0.0, 0.5];
        for (a, b) in y.iter().zip(expected) {
            assert!((a - b).abs() < 1e-15, "{y:?}");
        }
    }
}
