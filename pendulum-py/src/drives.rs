//! `pendulum.Harmonic`, `pendulum.Circle` and `pendulum.Sampled`: pivot drives for
//! `Chain.integrate` and `Chain.trajectory`, their parameters one for all states or one per
//! state, read into one core drive per state (`Harmonic`, `Circle`, `Sampled`) that moves
//! the pivot within a call.

use nalgebra::{DimName, OVector, U2, U3, Vector2, Vector3};
use pendulum_core::Drive;
use pyo3::prelude::*;
use pyo3::types::PyTuple;

use crate::arrays::Numbers;
use crate::errors::{core_error, invalid};

/// The pivot oscillating along a line: `p(t) = A sin(ωt + φ) d̂` (m), `d̂` the unit
/// `direction` (default: the vertical, y up planar, z up in directions), amplitude
/// `A ≥ 0` (m), angular frequency `ω ≥ 0` (rad/s), phase `φ` (rad). Each parameter is one
/// number for all states or an array of the states' leading shape (`direction`: that
/// shape plus one axis of 2 or 3 components): a Kapitza pendulum per state, each shaken
/// at its own frequency, say.
#[pyclass(module = "pendulum._pendulum", name = "Harmonic", frozen)]
#[derive(Debug, Clone)]
pub struct Harmonic {
    amplitude: Numbers,
    omega: Numbers,
    phase: Numbers,
    direction: Option<Numbers>,
}

/// The pivot on the horizontal circle `p(t) = R (cos φ, sin φ, 0)` (m) about the vertical
/// (z up), radius `R ≥ 0` (m), at the angular speed `φ̇ = ω` (rad/s, positive
/// counter-clockwise seen from above) or, given `ramp_time` `T` (s), ramped linearly from
/// `ramp_from` (rad/s, default 0) at `t = 0` to `ω` at `t = T` and held there (the ramped
/// whirl of `Run` and `whirls`); each parameter one number for all states or an array of
/// the states' leading shape: the whirled chain, `model="directions"` only.
#[pyclass(module = "pendulum._pendulum", name = "Circle", frozen)]
#[derive(Debug, Clone)]
pub struct Circle {
    radius: Numbers,
    omega: Numbers,
    /// `T` and `ω0` of a ramp, if any.
    ramp: Option<(Numbers, Numbers)>,
}

/// The pivot on the cubic spline through sampled positions (`pendulum_core::Sampled`):
/// `times` (s, increasing, shape `(m,)`), `positions` (m, shape `(m, 2)` planar or
/// `(m, 3)` in directions, one path for all states, or the states' leading shape plus
/// `(m, D)`, one per state) and `end_velocities` (m/s, shape `(2, D)` or leading shape plus
/// `(2, D)`: the velocities at the first and last sample; `None`, the natural spline,
/// `p̈ = 0` there). Outside its samples the pivot moves on in a straight line at its end
/// velocity: at rest, if that is zero. A motion of one's own (measured, planned, computed
/// elsewhere) as a drive, with no Python called while the chains run.
#[pyclass(module = "pendulum._pendulum", name = "Sampled", frozen)]
#[derive(Debug, Clone)]
pub struct Sampled {
    times: Numbers,
    positions: Numbers,
    end_velocities: Option<Numbers>,
}

/// `what`'s numbers, each checked by `valid` (a requirement in words when not).
fn checked(
    what: &str,
    value: &Bound<'_, PyAny>,
    valid: impl Fn(f64) -> Option<&'static str>,
) -> PyResult<Numbers> {
    let numbers = Numbers::read(what, value)?;
    for &x in &numbers.data {
        if let Some(requirement) = valid(x) {
            return Err(invalid(format!("{what}: {x:?} is {requirement}")));
        }
    }
    Ok(numbers)
}

/// `None` for a number `≥ 0`, else why not.
fn non_negative(x: f64) -> Option<&'static str> {
    (x < 0.0).then_some("negative")
}

#[pymethods]
impl Harmonic {
    #[new]
    #[pyo3(signature = (amplitude, omega, phase = None, direction = None))]
    fn new(
        amplitude: &Bound<'_, PyAny>,
        omega: &Bound<'_, PyAny>,
        phase: Option<&Bound<'_, PyAny>>,
        direction: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let phase = match phase.filter(|p| !p.is_none()) {
            Some(p) => Numbers::read("phase", p)?,
            None => Numbers { shape: vec![], data: vec![0.0] },
        };
        let direction = match direction.filter(|d| !d.is_none()) {
            None => None,
            Some(d) => {
                let d = Numbers::read("direction", d)?;
                let width = d.shape.last().copied().unwrap_or(0);
                if !(2..=3).contains(&width) {
                    return Err(invalid(format!(
                        "direction: the last axis has {width} entries, expected 2 (planar) or 3 (directions)"
                    )));
                }
                if let Some(zero) = d.data.chunks_exact(width).find(|v| v.iter().all(|x| *x == 0.0)) {
                    return Err(invalid(format!("direction: {zero:?} has no direction")));
                }
                Some(d)
            }
        };
        Ok(Self {
            amplitude: checked("amplitude", amplitude, non_negative)?,
            omega: checked("omega", omega, non_negative)?,
            phase,
            direction,
        })
    }

    /// Amplitude `A` (m), as given.
    #[getter]
    fn amplitude<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.amplitude.to_array(py)
    }

    /// Angular frequency `ω` (rad/s), as given.
    #[getter]
    fn omega<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.omega.to_array(py)
    }

    /// Phase `φ` (rad), as given.
    #[getter]
    fn phase<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.phase.to_array(py)
    }

    /// The direction of oscillation as given (not normalised), `None` for the vertical.
    #[getter]
    fn direction<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.direction.as_ref().map(|d| d.to_array(py)).transpose()
    }

    fn __repr__(&self) -> String {
        let direction = self.direction.as_ref().map_or("None".to_string(), describe);
        format!(
            "Harmonic(amplitude={}, omega={}, phase={}, direction={direction})",
            describe(&self.amplitude),
            describe(&self.omega),
            describe(&self.phase)
        )
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let (py, me) = (slf.py(), slf.get());
        let args = (me.amplitude(py)?, me.omega(py)?, me.phase(py)?, me.direction(py)?);
        Ok((slf.get_type().into_any(), args.into_pyobject(py)?))
    }
}

#[pymethods]
impl Circle {
    #[new]
    #[pyo3(signature = (radius, omega, ramp_time = None, ramp_from = None))]
    fn new(
        radius: &Bound<'_, PyAny>,
        omega: &Bound<'_, PyAny>,
        ramp_time: Option<&Bound<'_, PyAny>>,
        ramp_from: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let (ramp_time, ramp_from) = (ramp_time.filter(|v| !v.is_none()), ramp_from.filter(|v| !v.is_none()));
        let ramp = match (ramp_time, ramp_from) {
            (None, None) => None,
            (None, Some(_)) => return Err(invalid("ramp_from: a ramp needs its ramp_time (s)")),
            (Some(time), from) => {
                let time = checked("ramp_time", time, |t| (t <= 0.0).then_some("not a positive time (s)"))?;
                let from = match from {
                    Some(from) => Numbers::read("ramp_from", from)?,
                    None => Numbers { shape: vec![], data: vec![0.0] },
                };
                Some((time, from))
            }
        };
        Ok(Self {
            radius: checked("radius", radius, non_negative)?,
            omega: Numbers::read("omega", omega)?,
            ramp,
        })
    }

    /// The ramp's duration `T` (s), as given; `None` for a steady speed.
    #[getter]
    fn ramp_time<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.ramp.as_ref().map(|(time, _)| time.to_array(py)).transpose()
    }

    /// The speed the ramp starts from `ω0` (rad/s), as given; `None` for a steady speed.
    #[getter]
    fn ramp_from<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.ramp.as_ref().map(|(_, from)| from.to_array(py)).transpose()
    }

    /// Radius `R` (m), as given.
    #[getter]
    fn radius<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.radius.to_array(py)
    }

    /// Angular frequency `ω` (rad/s), as given.
    #[getter]
    fn omega<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.omega.to_array(py)
    }

    fn __repr__(&self) -> String {
        let ramp = match &self.ramp {
            None => String::new(),
            Some((time, from)) => format!(", ramp_time={}, ramp_from={}", describe(time), describe(from)),
        };
        format!("Circle(radius={}, omega={}{ramp})", describe(&self.radius), describe(&self.omega))
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let (py, me) = (slf.py(), slf.get());
        let args = (me.radius(py)?, me.omega(py)?, me.ramp_time(py)?, me.ramp_from(py)?);
        Ok((slf.get_type().into_any(), args.into_pyobject(py)?))
    }
}

#[pymethods]
impl Sampled {
    #[new]
    #[pyo3(signature = (times, positions, end_velocities = None))]
    fn new(
        times: &Bound<'_, PyAny>,
        positions: &Bound<'_, PyAny>,
        end_velocities: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let times = Numbers::read("times", times)?;
        let [count] = times.shape[..] else {
            return Err(invalid(format!("times: shape {:?}, expected (m,), one time a sample", times.shape)));
        };
        let positions = Numbers::read("positions", positions)?;
        match positions.shape[..] {
            [.., rows, 2 | 3] if rows == count => {}
            _ => {
                return Err(invalid(format!(
                    "positions: shape {:?}, expected ({count}, 2) or ({count}, 3) for {count} times, or one such \
                     path per state",
                    positions.shape
                )));
            }
        }
        let end_velocities =
            end_velocities.filter(|v| !v.is_none()).map(|v| Numbers::read("end_velocities", v));
        let sampled = Self { times, positions, end_velocities: end_velocities.transpose()? };
        // Every path checked now (its times, its spline), each state's as the run reads it:
        // the states' leading shape is the positions' or else the end velocities'.
        let lead_of = |n: &Numbers| n.shape[..n.shape.len().saturating_sub(2)].to_vec();
        let mut lead = lead_of(&sampled.positions);
        if let (true, Some(ends)) = (lead.is_empty(), &sampled.end_velocities) {
            lead = lead_of(ends);
        }
        let lead = &lead[..];
        match sampled.dim() {
            2 => sampled.drives::<U2>(lead).map(|_| ())?,
            _ => sampled.drives::<U3>(lead).map(|_| ())?,
        }
        Ok(sampled)
    }

    /// The sample times (s), as given.
    #[getter]
    fn times<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.times.to_array(py)
    }

    /// The sampled positions (m), as given.
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.positions.to_array(py)
    }

    /// The velocities at the first and last sample (m/s), as given; `None` for the
    /// natural spline.
    #[getter]
    fn end_velocities<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.end_velocities.as_ref().map(|v| v.to_array(py)).transpose()
    }

    fn __repr__(&self) -> String {
        let (t, count) = (&self.times.data, self.times.data.len());
        let ends = self.end_velocities.as_ref().map_or("None".to_string(), describe);
        format!(
            "Sampled({count} samples from {} to {} s, positions={}, end_velocities={ends})",
            t[0],
            t[count - 1],
            describe(&self.positions)
        )
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let (py, me) = (slf.py(), slf.get());
        let args = (me.times(py)?, me.positions(py)?, me.end_velocities(py)?);
        Ok((slf.get_type().into_any(), args.into_pyobject(py)?))
    }
}

impl Sampled {
    /// The components of a position: 2 or 3.
    fn dim(&self) -> usize {
        self.positions.shape[self.positions.shape.len() - 1]
    }

    /// One core drive in `S` per state of the leading shape `lead`.
    fn drives<S: DimName>(&self, lead: &[usize]) -> PyResult<Vec<pendulum_core::Sampled<S>>>
    where
        nalgebra::DefaultAllocator: nalgebra::allocator::Allocator<S>,
    {
        let (dim, count) = (S::DIM, self.times.data.len());
        if self.dim() != dim {
            let model = if dim == 2 { "model='planar'" } else { "model='directions'" };
            return Err(invalid(format!("positions: {} components, {model} takes {dim}", self.dim())));
        }
        let positions = self.positions.per_state_shaped("positions", &[count, dim], lead)?;
        let ends = match &self.end_velocities {
            None => None,
            Some(v) => Some(v.per_state_shaped("end_velocities", &[2, dim], lead)?),
        };
        let vectors =
            |rows: &[f64]| rows.chunks_exact(dim).map(OVector::<f64, S>::from_column_slice).collect();
        let build = |k: usize| {
            let (times, path) = (self.times.data.clone(), vectors(positions[k]));
            match &ends {
                None => pendulum_core::Sampled::new(times, path),
                Some(ends) => {
                    let [start, end]: [OVector<f64, S>; 2] =
                        [&ends[k][..dim], &ends[k][dim..]].map(OVector::from_column_slice);
                    pendulum_core::Sampled::with_end_velocities(times, path, start, end)
                }
            }
        };
        // A path given once for all states is built once, its clones sharing its samples.
        let same = |k: usize| {
            std::ptr::eq(positions[k], positions[k - 1])
                && ends.as_ref().is_none_or(|ends| std::ptr::eq(ends[k], ends[k - 1]))
        };
        let mut drives: Vec<pendulum_core::Sampled<S>> = Vec::with_capacity(positions.len());
        for k in 0..positions.len() {
            let drive = match drives.last() {
                Some(previous) if same(k) => previous.clone(),
                _ => build(k).map_err(core_error)?,
            };
            drives.push(drive);
        }
        Ok(drives)
    }
}

/// A number as itself, an array by its shape.
fn describe(numbers: &Numbers) -> String {
    match numbers.shape.as_slice() {
        [] => format!("{:?}", numbers.data[0]),
        shape => format!("<array of shape {shape:?}>"),
    }
}

/// A drive given to a run: [`Harmonic`], [`Circle`] or [`Sampled`].
#[derive(Debug, Clone)]
pub enum Given {
    Harmonic(Harmonic),
    Circle(Circle),
    Sampled(Sampled),
}

impl Given {
    /// `value` as a drive: `None` (or Python's `None`) for none.
    pub fn read(value: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Self>> {
        let Some(value) = value.filter(|v| !v.is_none()) else { return Ok(None) };
        if let Ok(h) = value.cast::<Harmonic>() {
            return Ok(Some(Self::Harmonic(h.get().clone())));
        }
        if let Ok(c) = value.cast::<Circle>() {
            return Ok(Some(Self::Circle(c.get().clone())));
        }
        if let Ok(p) = value.cast::<Sampled>() {
            return Ok(Some(Self::Sampled(p.get().clone())));
        }
        let kind = value.get_type().name().map_or_else(|_| "?".to_string(), |n| n.to_string());
        Err(invalid(format!(
            "drive: a {kind}, expected pendulum.Harmonic, pendulum.Circle or pendulum.Sampled"
        )))
    }

    /// One planar drive per state of the leading shape `lead`.
    pub fn planar(&self, lead: &[usize]) -> PyResult<Vec<PlanarPivot>> {
        match self {
            Self::Harmonic(h) => Ok(h.drives(lead)?.into_iter().map(PlanarPivot::Harmonic).collect()),
            Self::Sampled(p) => Ok(p.drives(lead)?.into_iter().map(PlanarPivot::Sampled).collect()),
            Self::Circle(_) => Err(invalid(
                "drive: pendulum.Circle turns the pivot about the vertical, in 3D: model='directions' only",
            )),
        }
    }

    /// One drive of the chain in directions per state of the leading shape `lead`.
    pub fn spatial(&self, lead: &[usize]) -> PyResult<Vec<Pivot>> {
        Ok(match self {
            Self::Harmonic(h) => h.drives(lead)?.into_iter().map(Pivot::Harmonic).collect(),
            Self::Circle(c) => c.drives(lead)?,
            Self::Sampled(p) => p.drives(lead)?.into_iter().map(Pivot::Sampled).collect(),
        })
    }
}

impl Circle {
    /// One core drive per state of the leading shape `lead`: [`pendulum_core::Circle`], or
    /// [`pendulum_core::RampedCircle`] with a ramp.
    fn drives(&self, lead: &[usize]) -> PyResult<Vec<Pivot>> {
        let (radius, omega) =
            (self.radius.per_state("radius", 1, lead)?, self.omega.per_state("omega", 1, lead)?);
        let drives: Result<Vec<Pivot>, _> = match &self.ramp {
            None => (0..radius.len())
                .map(|k| pendulum_core::Circle::new(radius[k][0], omega[k][0]).map(Pivot::Circle))
                .collect(),
            Some((time, from)) => {
                let (time, from) =
                    (time.per_state("ramp_time", 1, lead)?, from.per_state("ramp_from", 1, lead)?);
                (0..radius.len())
                    .map(|k| {
                        pendulum_core::RampedCircle::new(radius[k][0], from[k][0], omega[k][0], time[k][0])
                            .map(Pivot::Ramped)
                    })
                    .collect()
            }
        };
        drives.map_err(core_error)
    }
}

impl Harmonic {
    /// One core drive in `S` per state of the leading shape `lead`.
    fn drives<S: DimName>(&self, lead: &[usize]) -> PyResult<Vec<pendulum_core::Harmonic<S>>>
    where
        nalgebra::DefaultAllocator: nalgebra::allocator::Allocator<S>,
    {
        let dim = S::DIM;
        let count: usize = lead.iter().product();
        let vertical: Vec<f64> = (0..dim).map(|k| if k + 1 == dim { 1.0 } else { 0.0 }).collect();
        let directions = match &self.direction {
            None => vec![&vertical[..]; count],
            Some(d) if d.shape.last() != Some(&dim) => {
                let model = if dim == 2 { "model='planar'" } else { "model='directions'" };
                let given = d.shape.last().copied().unwrap_or(0);
                return Err(invalid(format!("direction: {given} components, {model} takes {dim}")));
            }
            Some(d) => d.per_state("direction", dim, lead)?,
        };
        let amplitude = self.amplitude.per_state("amplitude", 1, lead)?;
        let omega = self.omega.per_state("omega", 1, lead)?;
        let phase = self.phase.per_state("phase", 1, lead)?;
        (0..count)
            .map(|k| {
                let d = OVector::<f64, S>::from_column_slice(directions[k]);
                pendulum_core::Harmonic::new(d, amplitude[k][0], omega[k][0], phase[k][0])
            })
            .collect::<Result<_, _>>()
            .map_err(core_error)
    }
}

/// `impl Drive<$space> for $name`, each method passed to the variant's drive.
macro_rules! drive_of_variants {
    ($name:ident in $space:ty, $vector:ty: $($variant:ident),+) => {
        impl Drive<$space> for $name {
            fn position(&self, t: f64) -> $vector {
                match self { $(Self::$variant(d) => d.position(t)),+ }
            }
            fn velocity(&self, t: f64) -> $vector {
                match self { $(Self::$variant(d) => d.velocity(t)),+ }
            }
            fn acceleration(&self, t: f64) -> $vector {
                match self { $(Self::$variant(d) => d.acceleration(t)),+ }
            }
            fn velocity_and_acceleration(&self, t: f64) -> ($vector, $vector) {
                match self { $(Self::$variant(d) => d.velocity_and_acceleration(t)),+ }
            }
            fn position_and_velocity(&self, t: f64) -> ($vector, $vector) {
                match self { $(Self::$variant(d) => d.position_and_velocity(t)),+ }
            }
        }
    };
}

/// The pivot drive of a planar chain in a run.
#[derive(Debug, Clone)]
pub enum PlanarPivot {
    Harmonic(pendulum_core::Harmonic<U2>),
    Sampled(pendulum_core::Sampled<U2>),
}

drive_of_variants!(PlanarPivot in U2, Vector2<f64>: Harmonic, Sampled);

/// The pivot drive of a chain in directions in a run.
#[derive(Debug, Clone)]
pub enum Pivot {
    Harmonic(pendulum_core::Harmonic<U3>),
    Circle(pendulum_core::Circle),
    Ramped(pendulum_core::RampedCircle),
    Sampled(pendulum_core::Sampled<U3>),
}

drive_of_variants!(Pivot in U3, Vector3<f64>: Harmonic, Circle, Ramped, Sampled);
