//! `pendulum.HeavyString`: Kolodner's heavy rotating string, the continuum a uniform
//! chain approaches (`pendulum_core::RotatingString`), with numpy arrays.

use numpy::PyArray1;
use pendulum_core::RotatingString;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::core_error;

/// A heavy uniform string of ``length`` (m) under ``gravity`` (m/s²), turning rigidly at ω
/// about the vertical through its top, the top fixed on the axis (``radius = 0``) or
/// driven round a horizontal circle of ``radius`` (m). The continuum of a uniform chain of
/// many links: its critical speeds and tip radii approach the string's as 1/n.
#[pyclass(module = "pendulum._pendulum", name = "HeavyString", frozen)]
pub struct HeavyString {
    string: RotatingString,
    #[pyo3(get)]
    length: f64,
    #[pyo3(get)]
    gravity: f64,
    #[pyo3(get)]
    radius: f64,
}

#[pymethods]
impl HeavyString {
    #[new]
    #[pyo3(signature = (length = 1.0, gravity = 9.81, radius = 0.0))]
    fn new(length: f64, gravity: f64, radius: f64) -> PyResult<Self> {
        let string = RotatingString::new(length, gravity, radius).map_err(core_error)?;
        Ok(Self { string, length, gravity, radius })
    }

    /// The first ``count`` critical speeds ``ω_k = (j_{0,k}/2) √(g/L)``, rad/s, where the
    /// k-node branches of a fixed top leave the vertical.
    #[pyo3(signature = (count = 3))]
    fn critical_speeds<'py>(&self, py: Python<'py>, count: usize) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.string.critical_speeds(count))
    }

    /// Every steady shape at ``omega`` (rad/s), ordered by tip, each a dict: ``omega``,
    /// ``tip`` (signed distance of the free end from the axis, m; + on the pivot's side),
    /// ``tip_radius`` (m), ``nodes`` (the top and the axis crossings), and ``x``,
    /// ``depth`` (m: distance from the axis and depth below the top at 2001 points from
    /// the top down). A fixed top gives the shapes with tip > 0 (their mirror images turn
    /// too). The GIL is released while it solves.
    fn shapes_at<'py>(&self, py: Python<'py>, omega: f64) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let string = self.string;
        let shapes = py.detach(|| string.shapes_at(omega)).map_err(core_error)?;
        shapes
            .into_iter()
            .map(|s| {
                let d = PyDict::new(py);
                d.set_item("omega", s.omega)?;
                d.set_item("tip", s.tip)?;
                d.set_item("tip_radius", s.tip_radius())?;
                d.set_item("nodes", s.nodes)?;
                d.set_item("x", PyArray1::from_vec(py, s.x))?;
                d.set_item("depth", PyArray1::from_vec(py, s.depth))?;
                Ok(d)
            })
            .collect()
    }

    fn __repr__(&self) -> String {
        format!("HeavyString(length={}, gravity={}, radius={})", self.length, self.gravity, self.radius)
    }
}
