//! One live chain: a 3D chain in unit link directions whose pivot the page steers
//! ([`Steered`]), stepped by [`RodMidpoint`](pendulum_core::RodMidpoint) at a fixed step in real time.

use nalgebra::{Dyn, U3, Vector3};
use pendulum_core::integrate::{Integrator, State};
use pendulum_core::{Chain, Directions, Drive, Steered};
use pendulum_experiment::{IntegratorKind, Method, directions_integrator};
use serde::{Deserialize, Serialize};

/// The step, s: four per frame of a 60 Hz display. The midpoint rule is exact on the rods
/// and stable over the chain's fast modes, so the step is set by the motion shown, not
/// by the chain's stiffness.
pub const STEP: f64 = 1.0 / 240.0;
/// The rate at which the pivot's centre follows the pointer, 1/s (settles in ≈ 0.2 s).
pub const HAND_RATE: f64 = 20.0;
/// The rate at which the circle's radius and speed follow the controls, 1/s (≈ 2 s).
pub const CIRCLE_RATE: f64 = 2.0;
/// The largest circling speed the page may ask for, rad/s.
pub const MAX_SPEED: f64 = 60.0;
/// The largest damping the page may ask for, N·m·s.
pub const MAX_DAMPING: f64 = 1.0;

/// What the page asks for, one JSON object per message: `{"omega": 6}`,
/// `{"radius": 0.02}`, `{"damping": 3e-4}`, `{"target": [x, y, z]}` (the pivot's centre,
/// m), `"restart"` (the chain hanging at rest again), or `{"selftest": …}` (the page's
/// self-test result, printed by the server).
#[derive(Debug, Deserialize)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
pub enum Control {
    /// The circling speed aimed at, rad/s.
    Omega(f64),
    /// The circle's radius aimed at, m.
    Radius(f64),
    /// Every link's damping λ, N·m·s.
    Damping(f64),
    /// Where the pivot's centre heads, m.
    Target([f64; 3]),
    /// The chain hanging at rest at the present pivot.
    Restart,
    /// The page's self-test result.
    Selftest(serde_json::Value),
}

/// What the page is sent after each frame's steps.
#[derive(Debug, Serialize)]
pub struct Frame {
    /// Simulated time, s.
    pub t: f64,
    /// The pivot then every mass, x, y, z each, m.
    pub points: Vec<f32>,
    /// The centre the pivot circles, m.
    pub centre: [f64; 3],
    /// Where the centre heads, m.
    pub target: [f64; 3],
    /// The pivot's azimuth about the centre, rad.
    pub phase: f64,
    /// The circle's radius now, m.
    pub radius: f64,
    /// Circling speed now, rad/s.
    pub omega: f64,
    /// The radius and speed the pivot heads for, m and rad/s.
    pub aims: [f64; 2],
    /// Every link's damping, N·m·s.
    pub damping: f64,
    /// The inertial-frame energy H, J.
    pub energy: f64,
    /// Steps taken as halves (a link turning fast or Newton slow) since the start.
    pub halved: u64,
    /// The share of one core the simulation took over the last second (none in the first).
    pub load: Option<f64>,
    /// Links, kg and m, for the page's labels: n, total mass, reach.
    pub chain: [f64; 3],
    /// What went wrong in this frame's steps, if anything.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

/// A live chain and its steered pivot.
pub struct Session {
    model: Directions<U3, Steered>,
    /// The implicit midpoint rule on the rods (the run library's `midpoint`).
    integrator: Box<dyn Integrator<Directions<U3, Steered>> + Send>,
    state: State<Dyn>,
}

impl Session {
    /// The chain's length Σ l_i, m.
    fn reach(&self) -> f64 {
        self.model.chain().lengths().sum()
    }

    /// The chain hanging at rest under a pivot at rest at the origin, the pivot heading
    /// for a circle of `radius` (m) at `omega` (rad/s), every link damped by `damping`.
    pub fn new(chain: Chain<Dyn>, damping: f64, radius: f64, omega: f64) -> Result<Self, String> {
        let drive = Steered::new(HAND_RATE, CIRCLE_RATE).map_err(|e| e.to_string())?;
        let model = Directions::new(chain).with_drive(drive);
        let state = State::new(0.0, model.hanging());
        let integrator = directions_integrator(Method::of_kind(IntegratorKind::Midpoint), &model)
            .map_err(|e| e.to_string())?;
        let mut session = Self { model, integrator, state };
        for control in [Control::Damping(damping), Control::Radius(radius), Control::Omega(omega)] {
            session.apply(control)?;
        }
        Ok(session)
    }

    /// Simulated time, s.
    pub fn t(&self) -> f64 {
        self.state.t()
    }

    /// Steps on to the last step boundary not after `t` (s). A step that fails even when
    /// halved (a pivot flung beyond what the step resolves) restarts the chain hanging at
    /// rest, and says so.
    pub fn run_until(&mut self, t: f64) -> Result<(), String> {
        while self.state.t() + STEP <= t + 1e-9 {
            if let Err(e) = self.integrator.step(&self.model, &mut self.state, STEP) {
                self.restart();
                return Err(format!("the step failed ({e}); the chain restarts hanging at rest"));
            }
        }
        Ok(())
    }

    /// Applies what the page asked for; a value out of range is refused with a sentence
    /// naming it, and changes nothing.
    pub fn apply(&mut self, control: Control) -> Result<(), String> {
        let (t, reach) = (self.state.t(), self.reach());
        let drive = self.model.drive_mut();
        match control {
            Control::Omega(w) if w.is_finite() && w.abs() <= MAX_SPEED => drive.set_speed(t, w),
            Control::Omega(w) => {
                return Err(format!("omega {w} rad/s is outside −{MAX_SPEED}…{MAX_SPEED} rad/s"));
            }
            Control::Radius(r) if (0.0..=reach).contains(&r) => drive.set_radius(t, r),
            Control::Radius(r) => {
                return Err(format!("radius {r} m is outside 0…{reach:.4} m (the chain's length)"));
            }
            Control::Damping(d) if (0.0..=MAX_DAMPING).contains(&d) => {
                let chain = self.model.chain();
                let chain = chain.clone().with_damping(&vec![d; chain.links()]).map_err(|e| e.to_string())?;
                let drive = self.model.drive().clone();
                self.model = Directions::new(chain).with_drive(drive);
                Ok(())
            }
            Control::Damping(d) => return Err(format!("damping {d} N·m·s is outside 0…{MAX_DAMPING} N·m·s")),
            Control::Target(p) => {
                let p = Vector3::from(p);
                if !p.iter().all(|v| v.is_finite()) {
                    return Err(format!("target {p:?} is not finite"));
                }
                // Within the chain's length of the origin: the chain stays in view.
                let far = p.norm() / reach;
                drive.steer(t, if far > 1.0 { p / far } else { p })
            }
            Control::Restart => {
                self.restart();
                Ok(())
            }
            Control::Selftest(_) => Ok(()),
        }
        .map_err(|e| e.to_string())
    }

    /// The chain hanging straight down at rest under the pivot's present centre.
    fn restart(&mut self) {
        let t = self.state.t();
        self.state = State::new(t, self.model.hanging());
    }

    /// The frame to send, with the simulation's `load` (share of a core).
    pub fn frame(&self, load: Option<f64>, error: Option<String>) -> Frame {
        let (t, x) = (self.state.t(), self.state.x());
        let drive = self.model.drive();
        let pivot = drive.position(t);
        let mut points: Vec<f32> = pivot.iter().map(|v| *v as f32).collect();
        for p in self.model.positions(t, x) {
            points.extend(p.iter().map(|v| *v as f32));
        }
        let (radius, omega) = drive.circle(t);
        Frame {
            t,
            points,
            centre: drive.centre(t).into(),
            target: drive.target().into(),
            phase: drive.phase(t),
            radius,
            omega,
            aims: drive.circle_target().into(),
            damping: self.model.chain().damping().max(),
            energy: self.model.inertial_energy(t, x),
            halved: self.integrator.stats().halved_steps,
            load,
            chain: [self.model.chain().links() as f64, self.model.chain().masses().sum(), self.reach()],
            error,
        }
    }

    /// The state, for tests.
    #[cfg(test)]
    fn x(&self) -> &nalgebra::DVector<f64> {
        self.state.x()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn whirl() -> Session {
        let chain = Chain::<Dyn>::uniform(100, 0.01, 0.01, 9.81).unwrap();
        Session::new(chain, 3e-4, 0.02, 6.0).unwrap()
    }

    #[test]
    fn the_pivot_goes_where_it_is_steered_and_the_rods_hold() {
        let mut s = whirl();
        s.apply(Control::Target([0.3, 0.0, 0.1])).unwrap();
        s.run_until(3.0).unwrap();
        assert!((s.t() - 3.0).abs() < 1e-9, "t = {}", s.t());
        let f = s.frame(None, None);
        assert!((Vector3::from(f.centre) - Vector3::new(0.3, 0.0, 0.1)).norm() < 1e-3, "{:?}", f.centre);
        assert!(
            (f.radius - 0.02).abs() < 0.02 * 0.05 && (f.omega - 6.0).abs() < 0.3,
            "{} {}",
            f.radius,
            f.omega
        );
        assert_eq!(f.points.len(), 3 * 101);
        for i in 0..100 {
            let u = s.x().fixed_rows::<3>(3 * i).norm();
            assert!((u - 1.0).abs() < 1e-9, "|u_{i}| = {u}");
        }
        // The chain hangs below the pivot and has been swung: its tip is off the vertical.
        let tip = &f.points[300..303];
        assert!(tip[2] < 0.1 && (tip[0] - 0.3).abs() > 1e-4, "{tip:?}");
    }

    #[test]
    fn out_of_range_controls_are_refused_by_name() {
        let mut s = whirl();
        for (control, word) in [
            (Control::Omega(f64::NAN), "omega NaN"),
            (Control::Omega(100.0), "omega 100"),
            (Control::Radius(2.0), "radius 2 m"),
            (Control::Damping(-1.0), "damping -1"),
            (Control::Target([0.0, f64::INFINITY, 0.0]), "not finite"),
        ] {
            let e = s.apply(control).unwrap_err();
            assert!(e.contains(word), "{e}");
        }
        // A target beyond the chain's length is brought within it.
        s.apply(Control::Target([5.0, 0.0, 0.0])).unwrap();
        assert!((s.model.drive().target() - Vector3::new(1.0, 0.0, 0.0)).norm() < 1e-12);
    }

    #[test]
    fn a_damping_change_keeps_the_motion() {
        let mut s = whirl();
        s.run_until(0.5).unwrap();
        let before = s.frame(None, None);
        s.apply(Control::Damping(0.01)).unwrap();
        let after = s.frame(None, None);
        assert_eq!(before.points, after.points);
        assert_eq!(after.damping, 0.01);
        s.run_until(1.0).unwrap();
    }
}
