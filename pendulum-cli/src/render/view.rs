//! What a frame shows: the plane a position is drawn in (turned with the pivot for the
//! co-rotating view), whether the pivot circles the vertical axis, and the region the
//! motion covers (the viewport, m, equal scales on both axes).

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use super::RenderView;
use crate::error::{CliError, CliResult};
use pendulum_core::TurningFrame;
use pendulum_experiment::Dimension;

/// How a position (m) becomes a point of the picture (m).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Projection {
    /// A 2D run in its plane: x right, y up.
    Plane,
    /// x right, z up.
    Side,
    /// y right, z up.
    SideY,
    /// x right, y up, seen from above.
    Top,
    /// The side view in the frame turning with the pivot: every sample turned by −φ(t)
    /// about the vertical axis, φ(t) the pivot's azimuth; x' right (toward the pivot), z up.
    CoRotating,
}

/// The mark of the rotation axis (the vertical through the circle's centre, the origin).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AxisMark {
    /// A vertical line at horizontal coordinate 0 (side views).
    Line,
    /// A cross at the origin (top view).
    Centre,
}

impl Projection {
    /// The projection of `view` for a run of dimension `dim`; 2D runs are drawn in their
    /// plane whatever the view, except that a 2D pivot cannot circle the vertical.
    pub fn new(view: RenderView, dim: Dimension) -> CliResult<Self> {
        Ok(match (dim, view) {
            (Dimension::Two, RenderView::CoRotating) => {
                return Err(CliError::invalid(
                    "--view co-rotating: this is a 2D run; the co-rotating view needs a 3D run whose \
                     pivot circles the vertical axis",
                ));
            }
            (Dimension::Two, _) => Self::Plane,
            (Dimension::Three, RenderView::Side) => Self::Side,
            (Dimension::Three, RenderView::Yz) => Self::SideY,
            (Dimension::Three, RenderView::Top) => Self::Top,
            (Dimension::Three, RenderView::CoRotating) => Self::CoRotating,
        })
    }

    /// The drawn point of the position `r` (m); `turn` is the frame turning with the
    /// pivot at the same instant (only the co-rotating view uses it).
    pub fn point(self, r: &[f64; 3], turn: TurningFrame) -> (f64, f64) {
        match self {
            Self::Plane | Self::Top => (r[0], r[1]),
            Self::Side => (r[0], r[2]),
            Self::SideY => (r[1], r[2]),
            Self::CoRotating => (turn.turn(r[0], r[1]).0, r[2]),
        }
    }

    /// The axis labels (horizontal, vertical).
    pub fn labels(self) -> (&'static str, &'static str) {
        match self {
            Self::Plane | Self::Top => ("x (m)", "y (m)"),
            Self::Side => ("x (m)", "z (m)"),
            Self::SideY => ("y (m)", "z (m)"),
            Self::CoRotating => ("x' (m), toward the pivot, turning with it", "z (m)"),
        }
    }

    /// The view's name, for titles and messages.
    pub fn name(self) -> &'static str {
        match self {
            Self::Plane => "x–y plane",
            Self::Side => "side view x–z",
            Self::SideY => "side view y–z",
            Self::Top => "top view x–y",
            Self::CoRotating => "co-rotating side view x'–z",
        }
    }

    /// The view's name as a frame's title shows it.
    pub fn title(self) -> &'static str {
        match self {
            // Two spaces: plotters' text drops the left bearing of the "p".
            Self::Plane => "x–y  plane",
            _ => self.name(),
        }
    }

    /// How the rotation axis of a circling pivot is marked (none in a 2D plane).
    pub fn axis_mark(self) -> Option<AxisMark> {
        match self {
            Self::Plane => None,
            Self::Top => Some(AxisMark::Centre),
            Self::Side | Self::SideY | Self::CoRotating => Some(AxisMark::Line),
        }
    }
}

/// Follows the pivot's azimuth φ(t) = atan2(p_y, p_x) sample by sample: the pivot circles
/// the vertical axis if it stays off the axis, turns one way only (by less than a quarter
/// turn between samples, so the turning is resolved) and turns at all. Any drive that
/// does so qualifies, whatever its speed profile.
#[derive(Debug)]
pub struct Circling {
    /// Distance from the axis that counts as on it, m.
    tolerance: f64,
    previous: Option<f64>,
    /// +1 counter-clockwise seen from above, −1 clockwise, 0 not yet turned.
    sense: f64,
    /// Azimuth turned so far, rad.
    turned: f64,
    /// Why it does not circle, once known.
    broken: Option<String>,
}

impl Circling {
    /// For a chain of reach `reach` (m).
    pub fn new(reach: f64) -> Self {
        Self { tolerance: 1e-9 * reach, previous: None, sense: 0.0, turned: 0.0, broken: None }
    }

    /// Takes the pivot `p` (m) at time `t` (s).
    pub fn push(&mut self, t: f64, p: &[f64; 3]) {
        if self.broken.is_some() {
            return;
        }
        if p[0].hypot(p[1]) <= self.tolerance {
            self.broken = Some(format!("it is on the axis at t = {t} s"));
            return;
        }
        let phi = TurningFrame::of_pivot(p).phase();
        if let Some(previous) = self.previous {
            let step = (phi - previous + PI).rem_euclid(TAU) - PI;
            if step.abs() > FRAC_PI_2 {
                self.broken = Some(format!("its azimuth jumps by {:.3} rad at t = {t} s", step.abs()));
            } else if step.abs() > 1e-12 {
                if self.sense == 0.0 {
                    self.sense = step.signum();
                } else if step.signum() != self.sense && step.abs() > 1e-9 {
                    self.broken = Some(format!("it turns back at t = {t} s"));
                }
                self.turned += step;
            }
        }
        self.previous = Some(phi);
    }

    /// Why the pivot does not circle, once a sample showed it.
    pub fn broken(&self) -> Option<&str> {
        self.broken.as_deref()
    }

    /// `Ok` if the pivot circled over the samples given, else why not.
    pub fn verdict(&self) -> Result<(), String> {
        match &self.broken {
            Some(why) => Err(why.clone()),
            None if self.turned.abs() < 1e-6 => Err("it does not turn about the axis".into()),
            None => Ok(()),
        }
    }
}

/// The smallest box holding some points, m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bounds {
    /// Horizontal extent (lowest, highest).
    pub x: (f64, f64),
    /// Vertical extent.
    pub y: (f64, f64),
}

impl Default for Bounds {
    fn default() -> Self {
        Self { x: (f64::INFINITY, f64::NEG_INFINITY), y: (f64::INFINITY, f64::NEG_INFINITY) }
    }
}

impl Bounds {
    /// Widens the box to hold `p`.
    pub fn add(&mut self, p: (f64, f64)) {
        self.add_x(p.0);
        self.y = (self.y.0.min(p.1), self.y.1.max(p.1));
    }

    /// Widens the box horizontally to hold `x` (a vertical line).
    pub fn add_x(&mut self, x: f64) {
        self.x = (self.x.0.min(x), self.x.1.max(x));
    }

    /// The viewport for a plot of `plot` pixels (w, h): this box grown by 7 % of its
    /// larger side on every side (to at least `2 min_half` m across), then widened along
    /// one axis so that a metre spans as many pixels horizontally as vertically.
    pub fn fit(&self, plot: (u32, u32), min_half: f64) -> Bounds {
        let centre = |(lo, hi): (f64, f64)| if lo <= hi { 0.5 * (lo + hi) } else { 0.0 };
        let span = |(lo, hi): (f64, f64)| if lo <= hi { hi - lo } else { 0.0 };
        let (cx, cy) = (centre(self.x), centre(self.y));
        let side = span(self.x).max(span(self.y)).max(2.0 * min_half);
        let (wx, wy) = (span(self.x) + 0.14 * side, span(self.y) + 0.14 * side);
        let (w, h) = (f64::from(plot.0.max(1)), f64::from(plot.1.max(1)));
        let per_metre = (w / wx).min(h / wy);
        let (hx, hy) = (0.5 * w / per_metre, 0.5 * h / per_metre);
        Bounds { x: (cx - hx, cx + hx), y: (cy - hy, cy + hy) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_circling_pivot_circles_and_others_do_not() {
        let mut circle = Circling::new(1.0);
        for k in 0..40 {
            // A ramp: at rest first, then faster and faster.
            let phi = 0.01 * (k as f64 - 10.0).max(0.0).powi(2);
            circle.push(k as f64, &[0.1 * phi.cos(), 0.1 * phi.sin(), 0.0]);
        }
        assert_eq!(circle.verdict(), Ok(()));
        let mut fixed = Circling::new(1.0);
        fixed.push(0.0, &[0.0, 0.0, 0.0]);
        assert_eq!(fixed.verdict(), Err("it is on the axis at t = 0 s".into()));
        let mut shaken = Circling::new(1.0);
        for k in 0..10 {
            shaken.push(k as f64, &[0.05 * (k as f64 + 0.5).sin(), 0.0, 0.0]);
        }
        assert!(shaken.verdict().unwrap_err().starts_with("its azimuth jumps by 3.142 rad"));
        let mut resting = Circling::new(1.0);
        resting.push(0.0, &[0.1, 0.0, 0.0]);
        resting.push(1.0, &[0.1, 0.0, 0.0]);
        assert_eq!(resting.verdict(), Err("it does not turn about the axis".into()));
    }

    #[test]
    fn the_co_rotating_view_turns_the_pivot_onto_the_positive_x_axis() {
        let pivot = [0.0, -0.2, 0.0];
        let p = Projection::CoRotating.point(&pivot, TurningFrame::of_pivot(&pivot));
        assert!((p.0 - 0.2).abs() < 1e-15 && p.1 == 0.0, "{p:?}");
    }

    #[test]
    fn the_viewport_holds_the_box_with_equal_scales() {
        let mut b = Bounds::default();
        b.add((-0.1, -1.0));
        b.add((0.3, 0.0));
        let v = b.fit((500, 400), 0.01);
        assert!(v.x.0 < -0.1 && v.x.1 > 0.3 && v.y.0 < -1.0 && v.y.1 > 0.0, "{v:?}");
        let (sx, sy) = (500.0 / (v.x.1 - v.x.0), 400.0 / (v.y.1 - v.y.0));
        assert!((sx - sy).abs() < 1e-9 * sx);
        // The tall side fills the height but for the margins.
        assert!((v.y.1 - v.y.0) < 1.2);
    }
}
