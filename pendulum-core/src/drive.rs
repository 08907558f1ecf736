//! Prescribed pivot motion `p(t)` and time-dependent torques `σ(t)`: the inputs of a
//! driven chain, plugged into [`FirstOrder`](crate::systems::FirstOrder) through [`Driven`].
//!
//! A driven pivot enters the equations of motion only through its acceleration `p̈(t)`
//! (in the pivot's frame it acts as the time-dependent gravity `g⃗ − p̈(t)`, `docs/conventions.md`);
//! the energy accounting ([`Accounted`](crate::energy::Accounted)) also needs `p(t)` and `ṗ(t)`.
//! Vectors live in the model's space: `(x, y)` with y up for planar models, `(x, y, z)`
//! with z up for spatial ones.

use std::borrow::Cow;

use nalgebra::{DefaultAllocator, Dim, DimName, OVector, U1, U3, Vector3, allocator::Allocator};

use crate::error::{Error, Result};
use crate::model::{Inputs, InputsAt};

mod sampled;
mod steered;
pub use sampled::Sampled;
pub use steered::Steered;

/// A prescribed pivot motion: position `p(t)` (m), velocity `ṗ(t)` (m/s) and acceleration
/// `p̈(t)` (m/s²) in the model's space `S` (`U2` planar, `U3` spatial).
///
/// The three must be consistent (`ṗ = dp/dt`, `p̈ = dṗ/dt`) for the energy balance of
/// [`Accounted`](crate::energy::Accounted) to close; the dynamics use `p̈` only. The built-in
/// drives are [`Fixed`], [`Harmonic`], [`Circle`] and [`RampedCircle`] (spatial, both
/// [`Turning`]), [`Sampled`] (the spline through sampled positions), [`Steered`]
/// (steered while it runs) and [`FnDrive`] (closures);
/// implement the trait for any other motion. `&D` and `Box<D>` (also `Box<dyn Drive<S>>`,
/// to choose a drive at run time) are drives when `D` is.
pub trait Drive<S: DimName>
where
    DefaultAllocator: Allocator<S>,
{
    /// Pivot position `p(t)`, m.
    fn position(&self, t: f64) -> OVector<f64, S>;
    /// Pivot velocity `ṗ(t)`, m/s.
    fn velocity(&self, t: f64) -> OVector<f64, S>;
    /// Pivot acceleration `p̈(t)`, m/s².
    fn acceleration(&self, t: f64) -> OVector<f64, S>;
    /// `(ṗ(t), p̈(t))` at once, equal bit for bit to the two calls: a drive may share their
    /// work (the circles compute `sin`, `cos` of the phase once).
    fn velocity_and_acceleration(&self, t: f64) -> (OVector<f64, S>, OVector<f64, S>) {
        (self.velocity(t), self.acceleration(t))
    }
    /// `(p(t), ṗ(t))` at once, equal bit for bit to the two calls (an energy needs both;
    /// the circles share `sin`, `cos` of the phase).
    fn position_and_velocity(&self, t: f64) -> (OVector<f64, S>, OVector<f64, S>) {
        (self.position(t), self.velocity(t))
    }
}

impl<S: DimName, D: Drive<S> + ?Sized> Drive<S> for &D
where
    DefaultAllocator: Allocator<S>,
{
    fn position(&self, t: f64) -> OVector<f64, S> {
        (**self).position(t)
    }
    fn velocity(&self, t: f64) -> OVector<f64, S> {
        (**self).velocity(t)
    }
    fn acceleration(&self, t: f64) -> OVector<f64, S> {
        (**self).acceleration(t)
    }
    fn velocity_and_acceleration(&self, t: f64) -> (OVector<f64, S>, OVector<f64, S>) {
        (**self).velocity_and_acceleration(t)
    }
    fn position_and_velocity(&self, t: f64) -> (OVector<f64, S>, OVector<f64, S>) {
        (**self).position_and_velocity(t)
    }
}

impl<S: DimName, D: Drive<S> + ?Sized> Drive<S> for Box<D>
where
    DefaultAllocator: Allocator<S>,
{
    fn position(&self, t: f64) -> OVector<f64, S> {
        (**self).position(t)
    }
    fn velocity(&self, t: f64) -> OVector<f64, S> {
        (**self).velocity(t)
    }
    fn acceleration(&self, t: f64) -> OVector<f64, S> {
        (**self).acceleration(t)
    }
    fn velocity_and_acceleration(&self, t: f64) -> (OVector<f64, S>, OVector<f64, S>) {
        (**self).velocity_and_acceleration(t)
    }
    fn position_and_velocity(&self, t: f64) -> (OVector<f64, S>, OVector<f64, S>) {
        (**self).position_and_velocity(t)
    }
}

/// The pivot at rest at the origin: `p = ṗ = p̈ = 0`. A drive in any space.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Fixed;

impl<S: DimName> Drive<S> for Fixed
where
    DefaultAllocator: Allocator<S>,
{
    fn position(&self, _t: f64) -> OVector<f64, S> {
        OVector::zeros()
    }
    fn velocity(&self, _t: f64) -> OVector<f64, S> {
        OVector::zeros()
    }
    fn acceleration(&self, _t: f64) -> OVector<f64, S> {
        OVector::zeros()
    }
}

/// `InvalidDrive` unless `value` is finite (and `≥ 0` when `non_negative`).
fn check_parameter(what: &'static str, value: f64, non_negative: bool) -> Result<f64> {
    if !value.is_finite() {
        return Err(Error::InvalidDrive { what, requirement: "finite", value });
    }
    if non_negative && value < 0.0 {
        return Err(Error::InvalidDrive { what, requirement: "finite and non-negative", value });
    }
    Ok(value)
}

/// Harmonic oscillation of the pivot along a fixed direction `d̂`:
/// ```text
/// p(t) = A sin(ωt + φ) d̂,   ṗ(t) = A ω cos(ωt + φ) d̂,   p̈(t) = −A ω² sin(ωt + φ) d̂
/// ```
/// with amplitude `A ≥ 0` (m), angular frequency `ω ≥ 0` (rad/s) and phase `φ` (rad).
/// Kapitza's pendulum is the vertical case, [`Harmonic::vertical`].
#[derive(Debug, Clone, PartialEq)]
pub struct Harmonic<S: DimName>
where
    DefaultAllocator: Allocator<S>,
{
    direction: OVector<f64, S>,
    amplitude: f64,
    angular_frequency: f64,
    phase: f64,
}

impl<S: DimName> Harmonic<S>
where
    DefaultAllocator: Allocator<S>,
{
    /// Oscillation along `direction` (normalized here; any non-zero finite length),
    /// amplitude `A` (m), angular frequency `ω` (rad/s), phase `φ` (rad).
    ///
    /// Errors: [`Error::InvalidDrive`] naming the value when the direction is zero or
    /// not finite (`what = "direction norm"`), `A` or `ω` is negative or not finite, or
    /// `φ` is not finite.
    pub fn new(
        direction: OVector<f64, S>,
        amplitude: f64,
        angular_frequency: f64,
        phase: f64,
    ) -> Result<Self> {
        let norm = direction.norm();
        if !(norm.is_finite() && norm > 0.0) {
            let requirement = "finite and positive";
            return Err(Error::InvalidDrive { what: "direction norm", requirement, value: norm });
        }
        Ok(Self {
            direction: direction / norm,
            amplitude: check_parameter("amplitude", amplitude, true)?,
            angular_frequency: check_parameter("angular frequency", angular_frequency, true)?,
            phase: check_parameter("phase", phase, false)?,
        })
    }

    /// Oscillation along the vertical (the last axis: y planar, z spatial), the drive of
    /// Kapitza's pendulum. Errors as [`new`](Harmonic::new).
    pub fn vertical(amplitude: f64, angular_frequency: f64, phase: f64) -> Result<Self> {
        let mut up = OVector::<f64, S>::zeros();
        up[S::dim() - 1] = 1.0;
        Self::new(up, amplitude, angular_frequency, phase)
    }

    /// The unit direction `d̂`.
    pub fn direction(&self) -> &OVector<f64, S> {
        &self.direction
    }

    /// Amplitude `A`, m.
    pub fn amplitude(&self) -> f64 {
        self.amplitude
    }

    /// Angular frequency `ω`, rad/s.
    pub fn angular_frequency(&self) -> f64 {
        self.angular_frequency
    }

    /// Phase `φ`, rad.
    pub fn phase(&self) -> f64 {
        self.phase
    }
}

impl<S: DimName> Drive<S> for Harmonic<S>
where
    DefaultAllocator: Allocator<S>,
{
    fn position(&self, t: f64) -> OVector<f64, S> {
        let arg = self.angular_frequency * t + self.phase;
        &self.direction * (self.amplitude * arg.sin())
    }
    fn velocity(&self, t: f64) -> OVector<f64, S> {
        let arg = self.angular_frequency * t + self.phase;
        &self.direction * (self.amplitude * self.angular_frequency * arg.cos())
    }
    fn acceleration(&self, t: f64) -> OVector<f64, S> {
        let (w, arg) = (self.angular_frequency, self.angular_frequency * t + self.phase);
        &self.direction * (-self.amplitude * w * w * arg.sin())
    }
}

/// The pivot moving on a horizontal circle (the x–y plane, z up) about the origin,
/// counter-clockwise seen from above for `ω > 0`:
/// ```text
/// p(t) = R (cos ωt, sin ωt, 0),   ṗ(t) = R ω (−sin ωt, cos ωt, 0),
/// p̈(t) = −R ω² (cos ωt, sin ωt, 0)
/// ```
/// with radius `R ≥ 0` (m) and angular frequency `ω` (rad/s, either sign). Spatial
/// models only.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Circle {
    radius: f64,
    angular_frequency: f64,
}

impl Circle {
    /// A circle of radius `R` (m) traversed at `ω` (rad/s).
    ///
    /// Errors: [`Error::InvalidDrive`] when `R` is negative or not finite or `ω` is not
    /// finite.
    pub fn new(radius: f64, angular_frequency: f64) -> Result<Self> {
        Ok(Self {
            radius: check_parameter("radius", radius, true)?,
            angular_frequency: check_parameter("angular frequency", angular_frequency, false)?,
        })
    }

    /// Radius `R`, m.
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// Angular frequency `ω`, rad/s.
    pub fn angular_frequency(&self) -> f64 {
        self.angular_frequency
    }
}

impl Circle {
    /// `(sin φ, cos φ)` of the phase `φ = ωt` (rad) at `t` (s).
    fn turn(&self, t: f64) -> (f64, f64) {
        (self.angular_frequency * t).sin_cos()
    }

    /// `p = R (cos φ, sin φ, 0)` (m) from `(sin φ, cos φ)`.
    fn position_from(&self, (s, c): (f64, f64)) -> Vector3<f64> {
        Vector3::new(c, s, 0.0) * self.radius
    }

    /// `ṗ = Rω (−sin φ, cos φ, 0)` (m/s) from `(sin φ, cos φ)`.
    fn velocity_from(&self, (s, c): (f64, f64)) -> Vector3<f64> {
        Vector3::new(-s, c, 0.0) * (self.radius * self.angular_frequency)
    }

    /// `p̈ = −Rω² (cos φ, sin φ, 0)` (m/s²) from `(sin φ, cos φ)`.
    fn acceleration_from(&self, (s, c): (f64, f64)) -> Vector3<f64> {
        let w = self.angular_frequency;
        Vector3::new(c, s, 0.0) * (-self.radius * w * w)
    }
}

impl Drive<U3> for Circle {
    fn position(&self, t: f64) -> Vector3<f64> {
        self.position_from(self.turn(t))
    }
    fn velocity(&self, t: f64) -> Vector3<f64> {
        self.velocity_from(self.turn(t))
    }
    fn acceleration(&self, t: f64) -> Vector3<f64> {
        self.acceleration_from(self.turn(t))
    }
    fn velocity_and_acceleration(&self, t: f64) -> (Vector3<f64>, Vector3<f64>) {
        let turn = self.turn(t);
        (self.velocity_from(turn), self.acceleration_from(turn))
    }
    fn position_and_velocity(&self, t: f64) -> (Vector3<f64>, Vector3<f64>) {
        let turn = self.turn(t);
        (self.position_from(turn), self.velocity_from(turn))
    }
}

/// A spatial pivot drive that turns about the vertical: the pivot on the horizontal circle
/// of radius `R` about the z axis, at the azimuth `φ(t)` (the phase, rad, from +x,
/// counter-clockwise seen from above):
/// ```text
/// p(t) = R (cos φ, sin φ, 0),   ṗ(t) = R φ̇ (−sin φ, cos φ, 0),
/// p̈(t) = R φ̈ (−sin φ, cos φ, 0) − R φ̇² (cos φ, sin φ, 0)
/// ```
/// Implementations must move the pivot so; the frame turning with the pivot (the lab frame
/// turned by `−φ(t)` about z, the pivot at `(R, 0, 0)`) is where the steady shapes of a
/// whirled chain stand still ([`ShapeTracker`](crate::analysis::ShapeTracker) analyses
/// them). [`Circle`] turns at a constant rate, [`RampedCircle`] ramps its rate; `&T` and
/// `Box<T>` (also `Box<dyn Turning>`) turn when `T` does. Turning drives are `Send + Sync`,
/// so that batches of whirls run on all cores.
pub trait Turning: Drive<U3> + Send + Sync {
    /// The pivot's azimuth `φ(t)`, rad (unwrapped: continuous in `t`, not reduced mod 2π).
    fn phase(&self, t: f64) -> f64;
    /// Its rate `φ̇(t)`, rad/s: the angular speed of the turning frame.
    fn rate(&self, t: f64) -> f64;
    /// The circle's radius `R`, m.
    fn radius(&self) -> f64;
}

impl<T: Turning + ?Sized> Turning for &T {
    fn phase(&self, t: f64) -> f64 {
        (**self).phase(t)
    }
    fn rate(&self, t: f64) -> f64 {
        (**self).rate(t)
    }
    fn radius(&self) -> f64 {
        (**self).radius()
    }
}

impl<T: Turning + ?Sized> Turning for Box<T> {
    fn phase(&self, t: f64) -> f64 {
        (**self).phase(t)
    }
    fn rate(&self, t: f64) -> f64 {
        (**self).rate(t)
    }
    fn radius(&self) -> f64 {
        (**self).radius()
    }
}

/// `φ = ωt`, `φ̇ = ω`.
impl Turning for Circle {
    fn phase(&self, t: f64) -> f64 {
        self.angular_frequency * t
    }
    fn rate(&self, _t: f64) -> f64 {
        self.angular_frequency
    }
    fn radius(&self) -> f64 {
        self.radius
    }
}

/// The pivot on a horizontal circle of radius `R` (m) about the z axis with its angular
/// speed ramped linearly from `ω0` to `ω1` (rad/s, either sign, either order: up, down,
/// from or to rest) over `T` seconds from `t = 0`, then held at `ω1`:
/// ```text
/// φ̇(t) = ω0 + (ω1 − ω0) t / T,     φ(t) = ω0 t + (ω1 − ω0) t² / (2T)     (0 ≤ t < T)
/// φ̇(t) = ω1,                      φ(t) = φ(T) + ω1 (t − T)             (t ≥ T)
/// φ̇(t) = ω0,                      φ(t) = ω0 t                          (t < 0)
/// ```
/// with `φ(T) = (ω0 + ω1) T / 2` and `φ̈ = (ω1 − ω0)/T` during the ramp, 0 outside it;
/// `p`, `ṗ`, `p̈` follow from `φ` as for every [`Turning`] drive. `φ`, `φ̇`, `p` and `ṗ` are
/// continuous; `φ̈` and `p̈` jump at `t = 0` and `t = T` (taking there the value after the
/// jump, which a run starting at `t = 0` needs). `ω0 = ω1` moves the pivot as
/// [`Circle`]`(R, ω0)`.
///
/// A fixed-step integrator loses its order on the step across a jump of `p̈`: RK4 runs
/// through the ramp are first order in `h` there (the energy balance of `Accounted` closes
/// as `O(h·R|φ̈|)`, unit test), fourth order elsewhere.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RampedCircle {
    radius: f64,
    initial_speed: f64,
    final_speed: f64,
    duration: f64,
}

impl RampedCircle {
    /// Radius `R` (m), speed ramped from `ω0` to `ω1` (rad/s) over `T` (s).
    ///
    /// Errors: [`Error::InvalidDrive`] naming the value when `R` is negative or not finite
    /// (`"radius"`), `ω0` or `ω1` is not finite (`"initial angular speed"`,
    /// `"final angular speed"`), or `T` is not finite and positive (`"ramp duration"`).
    pub fn new(radius: f64, initial_speed: f64, final_speed: f64, duration: f64) -> Result<Self> {
        let radius = check_parameter("radius", radius, true)?;
        let initial_speed = check_parameter("initial angular speed", initial_speed, false)?;
        let final_speed = check_parameter("final angular speed", final_speed, false)?;
        if !(duration.is_finite() && duration > 0.0) {
            let requirement = "finite and positive";
            return Err(Error::InvalidDrive { what: "ramp duration", requirement, value: duration });
        }
        Ok(Self { radius, initial_speed, final_speed, duration })
    }

    /// Radius `R`, m.
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// The speed at the start of the ramp `ω0`, rad/s.
    pub fn initial_speed(&self) -> f64 {
        self.initial_speed
    }

    /// The speed from the end of the ramp on `ω1`, rad/s.
    pub fn final_speed(&self) -> f64 {
        self.final_speed
    }

    /// The ramp's duration `T`, s.
    pub fn duration(&self) -> f64 {
        self.duration
    }

    /// `(φ, φ̇, φ̈)` at `t` (rad, rad/s, rad/s²).
    fn angle(&self, t: f64) -> (f64, f64, f64) {
        let (w0, w1, duration) = (self.initial_speed, self.final_speed, self.duration);
        let spin = (w1 - w0) / duration;
        if t < 0.0 {
            (w0 * t, w0, 0.0)
        } else if t < duration {
            (w0 * t + 0.5 * spin * t * t, w0 + spin * t, spin)
        } else {
            (0.5 * (w0 + w1) * duration + w1 * (t - duration), w1, 0.0)
        }
    }
}

impl RampedCircle {
    /// `p = R (cos φ, sin φ, 0)` (m) from `(sin φ, cos φ)`.
    fn position_from(&self, (s, c): (f64, f64)) -> Vector3<f64> {
        Vector3::new(c, s, 0.0) * self.radius
    }

    /// `ṗ = R φ̇ (−sin φ, cos φ, 0)` (m/s) from `(φ, φ̇, φ̈)` and `(sin φ, cos φ)`.
    fn velocity_from(&self, (_, rate, _): (f64, f64, f64), (s, c): (f64, f64)) -> Vector3<f64> {
        Vector3::new(-s, c, 0.0) * (self.radius * rate)
    }

    /// `p̈ = R φ̈ (−sin φ, cos φ, 0) − R φ̇² (cos φ, sin φ, 0)` (m/s²), the same way.
    fn acceleration_from(&self, (_, rate, spin): (f64, f64, f64), (s, c): (f64, f64)) -> Vector3<f64> {
        (Vector3::new(-s, c, 0.0) * spin - Vector3::new(c, s, 0.0) * (rate * rate)) * self.radius
    }
}

impl Drive<U3> for RampedCircle {
    fn position(&self, t: f64) -> Vector3<f64> {
        self.position_from(self.angle(t).0.sin_cos())
    }
    fn velocity(&self, t: f64) -> Vector3<f64> {
        let angle = self.angle(t);
        self.velocity_from(angle, angle.0.sin_cos())
    }
    fn acceleration(&self, t: f64) -> Vector3<f64> {
        let angle = self.angle(t);
        self.acceleration_from(angle, angle.0.sin_cos())
    }
    fn velocity_and_acceleration(&self, t: f64) -> (Vector3<f64>, Vector3<f64>) {
        let angle = self.angle(t);
        let turn = angle.0.sin_cos();
        (self.velocity_from(angle, turn), self.acceleration_from(angle, turn))
    }
    fn position_and_velocity(&self, t: f64) -> (Vector3<f64>, Vector3<f64>) {
        let angle = self.angle(t);
        let turn = angle.0.sin_cos();
        (self.position_from(turn), self.velocity_from(angle, turn))
    }
}

impl Turning for RampedCircle {
    fn phase(&self, t: f64) -> f64 {
        self.angle(t).0
    }
    fn rate(&self, t: f64) -> f64 {
        self.angle(t).1
    }
    fn radius(&self) -> f64 {
        self.radius
    }
}

/// A user-supplied pivot motion: three closures of time `t` (s) giving `p(t)` (m),
/// `ṗ(t)` (m/s) and `p̈(t)` (m/s²).
///
/// Their consistency is the caller's responsibility (only `p̈` moves the chain; the
/// energy balance needs all three).
#[derive(Clone, Copy)]
pub struct FnDrive<P, V, A> {
    position: P,
    velocity: V,
    acceleration: A,
}

impl<P, V, A> FnDrive<P, V, A> {
    /// The drive `(p, ṗ, p̈)` from three closures.
    pub fn new(position: P, velocity: V, acceleration: A) -> Self {
        Self { position, velocity, acceleration }
    }
}

impl<P, V, A> std::fmt::Debug for FnDrive<P, V, A> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("FnDrive { .. }")
    }
}

impl<S: DimName, P, V, A> Drive<S> for FnDrive<P, V, A>
where
    DefaultAllocator: Allocator<S>,
    P: Fn(f64) -> OVector<f64, S>,
    V: Fn(f64) -> OVector<f64, S>,
    A: Fn(f64) -> OVector<f64, S>,
{
    fn position(&self, t: f64) -> OVector<f64, S> {
        (self.position)(t)
    }
    fn velocity(&self, t: f64) -> OVector<f64, S> {
        (self.velocity)(t)
    }
    fn acceleration(&self, t: f64) -> OVector<f64, S> {
        (self.acceleration)(t)
    }
}

/// Generalized torques as a function of time: `σ(t)` (N·m), one per coordinate of a
/// model with `D` coordinates (eq 26's `σ_d`; the spatial model's `σ_θi, σ_φi`).
///
/// [`ConstantTorque`] is the constant case; any closure `Fn(f64) -> OVector<f64, D>` is
/// a torque of time.
pub trait TorqueAt<D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    /// `σ(t)`, N·m.
    fn torque_at(&self, t: f64) -> Cow<'_, OVector<f64, D>>;
}

/// A constant torque vector `σ` (N·m).
#[derive(Debug, Clone, PartialEq)]
pub struct ConstantTorque<D: Dim>(pub OVector<f64, D>)
where
    DefaultAllocator: Allocator<D>;

impl<D: Dim> ConstantTorque<D>
where
    DefaultAllocator: Allocator<D>,
{
    /// No torque on any of the `dof` coordinates (use `model.dof()`).
    pub fn zeros(dof: D) -> Self {
        Self(OVector::zeros_generic(dof, U1))
    }
}

impl<D: Dim> TorqueAt<D> for ConstantTorque<D>
where
    DefaultAllocator: Allocator<D>,
{
    fn torque_at(&self, _t: f64) -> Cow<'_, OVector<f64, D>> {
        Cow::Borrowed(&self.0)
    }
}

impl<D: Dim, F: Fn(f64) -> OVector<f64, D>> TorqueAt<D> for F
where
    DefaultAllocator: Allocator<D>,
{
    fn torque_at(&self, t: f64) -> Cow<'_, OVector<f64, D>> {
        Cow::Owned(self(t))
    }
}

/// A driven pivot and time-dependent torques together: the [`InputsAt`] of a driven
/// chain, `inputs(t) = (σ(t), p̈(t))`.
///
/// ```
/// use nalgebra::{DVector, Dyn, U2};
/// use pendulum_core::integrate::{Integrator, Rk4, State};
/// use pendulum_core::{Chain, ConstantTorque, Driven, FirstOrder, Harmonic, Planar};
///
/// let model = Planar::new(Chain::<Dyn>::uniform(1, 1.0, 0.2, 9.81).unwrap());
/// let drive = Harmonic::<U2>::vertical(0.01, 400.0, 0.0).unwrap();
/// let system = FirstOrder::with_inputs(model, Driven::new(drive, ConstantTorque::zeros(Dyn(1))));
/// let mut state = State::new(0.0, system.state(&DVector::from_vec(vec![3.0]), &DVector::zeros(1)));
/// Rk4::new(&system).integrate(&system, &mut state, 0.1, 400).unwrap();
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Driven<Dr, T> {
    drive: Dr,
    torque: T,
}

impl<Dr, T> Driven<Dr, T> {
    /// The pivot motion `drive` with the torques `torque`.
    pub fn new(drive: Dr, torque: T) -> Self {
        Self { drive, torque }
    }

    /// The pivot motion.
    pub fn drive(&self) -> &Dr {
        &self.drive
    }

    /// The torques.
    pub fn torque(&self) -> &T {
        &self.torque
    }
}

impl<D: Dim, S: DimName, Dr: Drive<S>, T: TorqueAt<D>> InputsAt<D, S> for Driven<Dr, T>
where
    DefaultAllocator: Allocator<D> + Allocator<S>,
{
    fn inputs_at(&self, t: f64) -> Cow<'_, Inputs<D, S>> {
        Cow::Owned(Inputs {
            torque: self.torque.torque_at(t).into_owned(),
            pivot_acceleration: self.drive.acceleration(t),
        })
    }
}

#[cfg(test)]
mod tests;
