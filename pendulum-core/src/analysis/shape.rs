//! The shape a whirled chain takes: a 3D chain in unit directions whose pivot turns about
//! the vertical ([`Turning`]), seen in the frame turning with the pivot — its plane, node
//! count, tip radius and lag; whether it has settled; and the damped steady shape nearest
//! it, with that shape's stability.
//!
//! **Frame.** With the pivot at `p(t) = R (cos φ(t), sin φ(t), 0)`, a mass at `r` in the
//! lab sits at `r̃ = Rot_z(−φ(t)) (r − p) + (R, 0, 0)` in the co-rotating frame: the pivot at
//! `(R, 0, 0)`, the rotation axis the z axis, gravity along −z. A relative equilibrium
//! (a steady shape turning rigidly with the pivot) stands still there.
//!
//! **Plane and profile** ([`WhirlShape`]). The shape's plane is the vertical plane through
//! the axis at the azimuth `α` that best fits the masses (least squares over the masses,
//! unweighted): with `S = Σ_i (x̃_i, ỹ_i)ᵀ(x̃_i, ỹ_i)`, `α = ½ atan2(2 S_xy, S_xx − S_yy)`,
//! taken in `(−π/2, π/2]` so that the pivot's side is positive. In it, mass `i` has the
//! signed radial coordinate `s_i = r̃_i·e` (m, `e = (cos α, sin α, 0)`: signed distance
//! from the axis), the depth `d_i = −z̃_i` below the pivot (m) and the out-of-plane offset
//! `o_i = r̃_i·(e_z × e)` (m, positive ahead in the sense of positive rotation).
//!
//! **Nodes** (the seed document's convention, as [`SteadyShape::nodes`]): the pivot is a
//! node, and so is every crossing of the rotation axis along the chain. The crossings are
//! the sign changes of `s_1 … s_n`, from mass 1 to the tip (exact zeros skipped; the rod
//! from the pivot to mass 1 is not looked at, the pivot's own offset `R` does not count):
//! `nodes = axis_crossings + 1`. A chain hanging to one side has 1 node; the k-th free
//! steady shape has k.
//!
//! **Settled** ([`ShapeTracker`], [`Settling`]). Over the last `K` drive periods
//! (`window = K · 2π / |φ̇(t)|`, `t` the latest sample) the drift is the largest
//! displacement of any mass in the co-rotating frame between a kept sample and the latest,
//! `drift = max_{s, i} |r̃_i(s) − r̃_i(t)|` (m); the chain has settled when the kept history
//! covers the window and `drift ≤ tolerance · L` (`L = Σ l_i`). Defaults
//! ([`ShapeOptions`]): `K = 5`, `tolerance = 1e-3`.
//!
//! **Nearest steady shape** ([`NearestSteady`]). The damped relative equilibrium of the
//! chain on [`Circle`]`(R, φ̇(t))` nearest the latest shape ([`relative_equilibrium`],
//! Newton from the latest shape's link angles), its distance to the latest shape
//! (`max_i |r̃_i − r̃_i^eq|`, m) and its spectrum's largest real part, the growth rate
//! (1/s, [`relative_spectrum_near_origin`]); stable when below `growth_tolerance · |ω|`.
//!
//! [`SteadyShape::nodes`]: crate::analysis::steady_branches::SteadyShape::nodes

use std::collections::VecDeque;
use std::f64::consts::TAU;

use nalgebra::{DVector, U3, Vector3};

use crate::analysis::modes::sign_changes;
use crate::analysis::relative_equilibrium::{
    RelativeEquilibrium, relative_equilibrium, relative_spectrum_near_origin,
};
use crate::drive::{Circle, Turning};
use crate::error::{Error, Result};
use crate::kinematics::TurningFrame;
use crate::models::directions::Directions;

/// A chain's shape in the co-rotating frame (module docs: frame, plane, profile, nodes).
/// All lengths in m, angles in rad; one entry per mass, mass 1 (below the pivot) first.
#[derive(Debug, Clone, PartialEq)]
pub struct WhirlShape {
    /// Co-rotating positions `r̃_i` (pivot at `(R, 0, 0)`, axis along z), m.
    pub positions: Vec<Vector3<f64>>,
    /// Azimuth `α` of the fitted vertical plane through the axis, rad, in `(−π/2, π/2]`
    /// (0: the plane of the axis and the pivot; negative: behind the pivot for `ω > 0`).
    pub plane_azimuth: f64,
    /// Signed radial coordinates `s_i = r̃_i·e` in the plane (signed distance from the
    /// axis, positive on the pivot's side), m.
    pub radial: Vec<f64>,
    /// Depths `d_i = −z̃_i` below the pivot, m.
    pub depth: Vec<f64>,
    /// Out-of-plane offsets `o_i = r̃_i·(e_z × e)`, m.
    pub offsets: Vec<f64>,
    /// Sign changes of `s_1 … s_n`: crossings of the rotation axis below the pivot.
    pub axis_crossings: usize,
    /// `axis_crossings + 1`: the nodes, the pivot counted (the seed's convention).
    pub nodes: usize,
    /// Horizontal distance of the last mass from the axis, `|(x̃_n, ỹ_n)|`, m.
    pub tip_radius: f64,
    /// The out-of-plane lag: the largest distance of a mass from the fitted plane,
    /// `max_i |o_i|`, m.
    pub out_of_plane: f64,
}

impl WhirlShape {
    /// The shape of masses at the co-rotating positions `r̃_i` (m; z up, the pivot at
    /// height 0 and the axis along z).
    ///
    /// Errors: [`Error::InvalidSteady`] for no positions, [`Error::NonFinite`]
    /// (`what = "positions"`, index `3i + k`) for a non-finite coordinate.
    pub fn from_positions(positions: Vec<Vector3<f64>>) -> Result<Self> {
        let Some(tip) = positions.last() else {
            return Err(Error::InvalidSteady {
                what: "number of masses",
                requirement: "at least 1",
                value: 0.0,
            });
        };
        if let Some((index, &value)) =
            positions.iter().flat_map(|r| r.iter()).enumerate().find(|(_, v)| !v.is_finite())
        {
            return Err(Error::NonFinite { what: "positions", index, value });
        }
        let tip_radius = tip.x.hypot(tip.y);
        let (sxx, syy, sxy) = positions
            .iter()
            .fold((0.0, 0.0, 0.0), |(a, b, c), r| (a + r.x * r.x, b + r.y * r.y, c + r.x * r.y));
        let mut alpha = 0.5 * (2.0 * sxy).atan2(sxx - syy);
        if alpha <= -std::f64::consts::FRAC_PI_2 {
            alpha += std::f64::consts::PI;
        }
        let (s, c) = alpha.sin_cos();
        let radial: Vec<f64> = positions.iter().map(|r| c * r.x + s * r.y).collect();
        let offsets: Vec<f64> = positions.iter().map(|r| -s * r.x + c * r.y).collect();
        let depth = positions.iter().map(|r| -r.z).collect();
        let axis_crossings = sign_changes(&radial);
        let out_of_plane = offsets.iter().fold(0.0_f64, |m, o| m.max(o.abs()));
        Ok(Self {
            positions,
            plane_azimuth: alpha,
            radial,
            depth,
            offsets,
            axis_crossings,
            nodes: axis_crossings + 1,
            tip_radius,
            out_of_plane,
        })
    }

    /// The largest distance between corresponding masses of two shapes,
    /// `max_i |r̃_i − r̃'_i|`, m (over the shorter of the two).
    pub fn distance(&self, other: &WhirlShape) -> f64 {
        max_distance(&self.positions, &other.positions)
    }
}

fn max_distance(a: &[Vector3<f64>], b: &[Vector3<f64>]) -> f64 {
    a.iter().zip(b).map(|(p, q)| (p - q).norm()).fold(0.0, f64::max)
}

/// The co-rotating positions `r̃_i = Rot_z(−φ(t)) (r_i − p(t)) + (R, 0, 0)` (m) of the
/// chain's masses in the state `x` at time `t` (s).
///
/// Errors: [`Error::LengthMismatch`] / [`Error::NonFinite`] for a bad state or time.
pub fn co_rotating_positions<Dr: Turning>(
    model: &Directions<U3, Dr>,
    t: f64,
    x: &DVector<f64>,
) -> Result<Vec<Vector3<f64>>> {
    model.check_state(x)?;
    check_time(t)?;
    Ok(turned(model, t, x))
}

/// [`co_rotating_positions`] of a checked state.
fn turned<Dr: Turning>(model: &Directions<U3, Dr>, t: f64, x: &DVector<f64>) -> Vec<Vector3<f64>> {
    let drive = model.drive();
    let frame = TurningFrame::at(drive.phase(t));
    let radius = drive.radius();
    model
        .relative_positions(x)
        .into_iter()
        .map(|r| {
            let (x, y) = frame.place(radius, r.x, r.y);
            Vector3::new(x, y, r.z)
        })
        .collect()
}

fn check_time(t: f64) -> Result<()> {
    if t.is_finite() { Ok(()) } else { Err(Error::NonFinite { what: "t", index: 0, value: t }) }
}

/// The [`WhirlShape`] of the state `x` at time `t` (s): no history, no steady shape.
///
/// Errors: those of [`co_rotating_positions`].
pub fn whirl_shape<Dr: Turning>(model: &Directions<U3, Dr>, t: f64, x: &DVector<f64>) -> Result<WhirlShape> {
    WhirlShape::from_positions(co_rotating_positions(model, t, x)?)
}

/// What the shape analysis may take as settled and as stable (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShapeOptions {
    /// `K`: the settle window in drive periods `2π/|φ̇(t)|` at the latest sample. Default 5.
    pub periods: f64,
    /// Settled when the drift is at most `tolerance · L` (`L` the chain's length). Default
    /// `1e-3`.
    pub tolerance: f64,
    /// Samples a [`ShapeTracker`] keeps per window, at least `window / snapshots` apart
    /// (memory: at most `2·snapshots + 2` position sets of `n` masses). Default 64.
    pub snapshots: usize,
    /// A steady shape counts as stable when its growth rate is below
    /// `growth_tolerance · |ω|` (1/s). Default `1e-6`: above the round-off of the
    /// central-difference spectrum (undamped, spectrally stable shapes show real parts of
    /// `1e-13 |ω|`, up to `1e-7 |ω|` at `R = 0`, where turning the shape about the axis is
    /// a neutral direction; unit tests), while a growth that slow would take `10⁶/2π` drive
    /// periods to e-fold, longer than any run; the damped shapes of the lightly damped
    /// chains of `docs/rotating-chain.md` decay at `1e-3 |ω|` and faster.
    pub growth_tolerance: f64,
}

impl Default for ShapeOptions {
    fn default() -> Self {
        Self { periods: 5.0, tolerance: 1e-3, snapshots: 64, growth_tolerance: 1e-6 }
    }
}

impl ShapeOptions {
    /// Errors: [`Error::InvalidSteady`] naming a non-positive or non-finite `periods`, a
    /// negative or non-finite `tolerance` or `growth_tolerance`, or zero `snapshots`.
    pub fn check(&self) -> Result<()> {
        let bad = |what, requirement, value| Err(Error::InvalidSteady { what, requirement, value });
        if !(self.periods.is_finite() && self.periods > 0.0) {
            return bad("settle periods", "finite and positive", self.periods);
        }
        if !(self.tolerance.is_finite() && self.tolerance >= 0.0) {
            return bad("settle tolerance", "finite and non-negative", self.tolerance);
        }
        if self.snapshots == 0 {
            return bad("snapshots per window", "at least 1", 0.0);
        }
        if !(self.growth_tolerance.is_finite() && self.growth_tolerance >= 0.0) {
            return bad("growth tolerance", "finite and non-negative", self.growth_tolerance);
        }
        Ok(())
    }
}

/// Whether the chain has settled (module docs): drift over the last `K` drive periods.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settling {
    /// `max_{s, i} |r̃_i(s) − r̃_i(t)|` over the kept samples `s` in the window, m.
    pub drift: f64,
    /// `tolerance · L`, m.
    pub threshold: f64,
    /// `K · 2π / |φ̇(t)|`, s (infinite when the pivot does not turn at `t`).
    pub window: f64,
    /// The history reaches back over the whole window (none of it discarded).
    pub covered: bool,
    /// `covered` and `drift ≤ threshold`.
    pub settled: bool,
}

/// The damped steady shape nearest a chain's shape (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct NearestSteady {
    /// The speed it turns at, `φ̇(t)` of the drive at the latest sample, rad/s.
    pub omega: f64,
    /// The relative equilibrium on [`Circle`]`(R, ω)` (angles, state at its `t = 0`).
    pub equilibrium: RelativeEquilibrium,
    /// Its shape (co-rotating positions, nodes, ...), for comparison and plotting.
    pub shape: WhirlShape,
    /// `max_i |r̃_i − r̃_i^eq|` to the shape it was sought from, m.
    pub distance: f64,
    /// Largest real part of its damped spectrum, 1/s (negative: every mode decays).
    pub growth_rate: f64,
    /// `growth_tolerance · |ω|`, 1/s: growth rates of smaller magnitude are zero within
    /// the spectrum's round-off.
    pub rate_bound: f64,
    /// `growth_rate < rate_bound`.
    pub stable: bool,
}

/// The damped relative equilibrium nearest `shape` (the chain's co-rotating shape at `t`),
/// at the drive's radius and speed `φ̇(t)`: Newton ([`relative_equilibrium`]) from the
/// link angles of `shape` — `u_i = (r̃_i − r̃_{i−1}) / |…|` (`r̃_0 = (R, 0, 0)`),
/// `θ_i = atan2(u_x, −u_z)`, `ψ_i = asin u_y` — then its spectrum
/// (those eigenvalues that can grow, [`relative_spectrum_near_origin`]). Costs `O(n²)`
/// model evaluations and dense `2n × 2n` LU factors.
///
/// Errors: [`Error::LengthMismatch`] when `shape` has not one position per link;
/// [`Error::SteadyNotConverged`] when Newton fails (no steady shape near this one); those
/// of [`Circle::new`] and [`ShapeOptions::check`].
pub fn nearest_steady<Dr: Turning>(
    model: &Directions<U3, Dr>,
    t: f64,
    shape: &WhirlShape,
    options: &ShapeOptions,
) -> Result<NearestSteady> {
    options.check()?;
    check_time(t)?;
    let n = model.links();
    if shape.positions.len() != n {
        return Err(Error::LengthMismatch { what: "positions", expected: n, got: shape.positions.len() });
    }
    let (radius, omega) = (model.drive().radius(), model.drive().rate(t));
    let steady = Directions::<U3>::new(model.chain().clone()).with_drive(Circle::new(radius, omega)?);
    let mut previous = Vector3::new(radius, 0.0, 0.0);
    let guess: Vec<(f64, f64)> = shape
        .positions
        .iter()
        .map(|r| {
            let u = (r - previous).normalize();
            previous = *r;
            (u.x.atan2(-u.z), u.y.clamp(-1.0, 1.0).asin())
        })
        .collect();
    let equilibrium = relative_equilibrium(&steady, &guess)?;
    let eq_shape = WhirlShape::from_positions(turned(&steady, 0.0, &equilibrium.state))?;
    let growth_rate = relative_spectrum_near_origin(&steady, &equilibrium)?
        .iter()
        .map(|z| z.re)
        .fold(f64::NEG_INFINITY, f64::max);
    Ok(NearestSteady {
        omega,
        distance: eq_shape.distance(shape),
        shape: eq_shape,
        equilibrium,
        growth_rate,
        rate_bound: options.growth_tolerance * omega.abs(),
        stable: growth_rate < options.growth_tolerance * omega.abs(),
    })
}

/// Everything the shape analysis says about a chain at its latest sample.
#[derive(Debug, Clone, PartialEq)]
pub struct ShapeReport {
    /// Time of the latest sample, s.
    pub t: f64,
    /// The pivot's angular speed `φ̇(t)`, rad/s.
    pub omega: f64,
    /// The pivot's radius `R`, m.
    pub radius: f64,
    /// The chain's shape at `t`: co-rotating positions, plane, nodes, tip radius, lag.
    pub shape: WhirlShape,
    /// Drift over the last `K` periods and whether it settled.
    pub settling: Settling,
    /// The damped steady shape nearest, or why none was found ([`nearest_steady`]).
    pub nearest: Result<NearestSteady>,
}

/// A bounded history of a run's samples for the shape analysis: feed it every sample (or
/// every few) with [`push`](Self::push), ask for [`settling`](Self::settling) (cheap) or the
/// full [`report`](Self::report) at any time.
///
/// It keeps the latest state and the co-rotating positions of samples at least
/// `window / snapshots` apart within the current window (module docs), at most
/// `2·snapshots + 2` of them (thinned by half beyond that): `O(n · snapshots)` memory
/// whatever the run's length, `O(n)` work per sample.
///
/// ```
/// use nalgebra::{Dyn, U3};
/// use pendulum_core::integrate::{Integrator, Projected, Rk4, State};
/// use pendulum_core::{Chain, Circle, Directions, ShapeOptions, ShapeTracker};
///
/// let chain = Chain::<Dyn>::uniform(4, 0.25, 0.25, 9.81).unwrap().with_damping(&[0.1; 4]).unwrap();
/// let model = Directions::<U3>::new(chain).with_drive(Circle::new(0.02, 2.5).unwrap());
/// let mut tracker = ShapeTracker::new(&model, ShapeOptions::default()).unwrap();
/// let mut state = State::new(0.0, model.hanging());
/// let mut solver = Projected::new(Rk4::new(&model));
/// for _ in 0..5000 {
///     solver.step(&model, &mut state, 4e-3).unwrap();
///     tracker.push(state.t(), state.x()).unwrap();
/// }
/// let report = tracker.report().unwrap();
/// assert_eq!(report.shape.nodes, 1);
/// assert!(report.nearest.unwrap().stable);
/// ```
#[derive(Debug, Clone)]
pub struct ShapeTracker<'a, Dr> {
    model: &'a Directions<U3, Dr>,
    options: ShapeOptions,
    snapshots: VecDeque<(f64, Vec<Vector3<f64>>)>,
    latest: Option<(f64, DVector<f64>)>,
    first: f64,
    discarded: f64,
}

impl<'a, Dr: Turning> ShapeTracker<'a, Dr> {
    /// An empty history of `model`'s run.
    ///
    /// Errors: those of [`ShapeOptions::check`].
    pub fn new(model: &'a Directions<U3, Dr>, options: ShapeOptions) -> Result<Self> {
        options.check()?;
        Ok(Self {
            model,
            options,
            snapshots: VecDeque::new(),
            latest: None,
            first: f64::NAN,
            discarded: f64::NEG_INFINITY,
        })
    }

    /// The options.
    pub fn options(&self) -> &ShapeOptions {
        &self.options
    }

    /// The latest sample `(t, x)`, if any.
    pub fn latest(&self) -> Option<(f64, &DVector<f64>)> {
        self.latest.as_ref().map(|(t, x)| (*t, x))
    }

    /// Number of position sets kept (bounded, see the type's docs).
    pub fn kept(&self) -> usize {
        self.snapshots.len()
    }

    /// `K · 2π / |φ̇(t)|`, s (infinite at `φ̇ = 0`).
    fn window(&self, t: f64) -> f64 {
        self.options.periods * TAU / self.model.drive().rate(t).abs()
    }

    /// Adds the sample `x` at time `t` (s), later than the previous one.
    ///
    /// Errors: [`Error::LengthMismatch`] / [`Error::NonFinite`] for a bad state or time,
    /// [`Error::InvalidSteady`] (`what = "sample time"`) when `t` is not after the previous
    /// sample. A refused sample leaves the history as it was.
    pub fn push(&mut self, t: f64, x: &DVector<f64>) -> Result<()> {
        self.model.check_state(x)?;
        check_time(t)?;
        if let Some((last, _)) = &self.latest
            && t <= *last
        {
            let requirement = "later than the previous sample";
            return Err(Error::InvalidSteady { what: "sample time", requirement, value: t });
        }
        let window = self.window(t);
        let spacing = window / self.options.snapshots as f64;
        if self.snapshots.back().is_none_or(|(tb, _)| t - tb >= spacing) {
            self.snapshots.push_back((t, turned(self.model, t, x)));
        }
        match &mut self.latest {
            Some((tl, xl)) => {
                *tl = t;
                xl.copy_from(x);
            }
            None => {
                self.first = t;
                self.latest = Some((t, x.clone()));
            }
        }
        while self.snapshots.front().is_some_and(|(tf, _)| *tf < t - window) {
            let (tf, _) = self.snapshots.pop_front().expect("checked non-empty");
            self.discarded = self.discarded.max(tf);
        }
        if self.snapshots.len() > 2 * self.options.snapshots + 2 {
            // Thin by half, keeping the oldest and the newest.
            let last = self.snapshots.len() - 1;
            let mut index = 0;
            self.snapshots.retain(|_| {
                let keep = index % 2 == 0 || index == last;
                index += 1;
                keep
            });
        }
        Ok(())
    }

    /// The drift over the last `K` periods and whether the chain settled (module docs).
    ///
    /// Errors: [`Error::InvalidSteady`] (`what = "samples"`) before the first sample.
    pub fn settling(&self) -> Result<Settling> {
        let (t, x) = self.latest_or_error()?;
        Ok(self.settling_at(t, &turned(self.model, t, x)))
    }

    fn latest_or_error(&self) -> Result<(f64, &DVector<f64>)> {
        self.latest().ok_or(Error::InvalidSteady { what: "samples", requirement: "at least 1", value: 0.0 })
    }

    fn settling_at(&self, t: f64, now: &[Vector3<f64>]) -> Settling {
        let window = self.window(t);
        let start = t - window;
        let drift = self
            .snapshots
            .iter()
            .filter(|(ts, _)| *ts >= start)
            .map(|(_, r)| max_distance(r, now))
            .fold(0.0, f64::max);
        let threshold = self.options.tolerance * self.model.chain().lengths().sum();
        let covered = self.first <= start && self.discarded <= start;
        Settling { drift, threshold, window, covered, settled: covered && drift <= threshold }
    }

    /// The full analysis at the latest sample: its [`WhirlShape`], the [`Settling`] and the
    /// [`nearest_steady`] shape (`O(n²)` model evaluations and an `O(n³)` eigensolve;
    /// a failed search is reported in [`ShapeReport::nearest`], not as an error).
    ///
    /// Errors: [`Error::InvalidSteady`] (`what = "samples"`) before the first sample.
    pub fn report(&self) -> Result<ShapeReport> {
        let (t, x) = self.latest_or_error()?;
        let shape = WhirlShape::from_positions(turned(self.model, t, x))?;
        let settling = self.settling_at(t, &shape.positions);
        let nearest = nearest_steady(self.model, t, &shape, &self.options);
        let drive = self.model.drive();
        Ok(ShapeReport { t, omega: drive.rate(t), radius: drive.radius(), shape, settling, nearest })
    }
}

/// [`ShapeTracker::report`] of the samples `(t, x)` in increasing time (the recent part of
/// a run: at least the last `K` drive periods for a settled verdict).
///
/// Errors: those of [`ShapeTracker::new`], [`ShapeTracker::push`] (naming the first bad
/// sample) and [`ShapeTracker::report`] (no samples).
pub fn shape_report<Dr: Turning>(
    model: &Directions<U3, Dr>,
    samples: &[(f64, DVector<f64>)],
    options: &ShapeOptions,
) -> Result<ShapeReport> {
    let mut tracker = ShapeTracker::new(model, *options)?;
    for (t, x) in samples {
        tracker.push(*t, x)?;
    }
    tracker.report()
}

#[cfg(test)]
mod tests;
