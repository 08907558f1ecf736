//! numpy arrays with a leading batch axis: `(..., k)` in, the states as rows, and rows of
//! results back out in the same leading shape.

use numpy::{PyArray1, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;

use crate::errors::invalid;

/// A batch of rows of `width` numbers: the leading shape and the rows, row-major.
pub struct Rows {
    /// The shape before the last axis (empty for one row).
    pub lead: Vec<usize>,
    /// Row after row.
    pub data: Vec<f64>,
    /// Numbers per row.
    pub width: usize,
}

impl Rows {
    /// Number of rows.
    pub fn count(&self) -> usize {
        self.lead.iter().product()
    }

    /// Row `i`.
    pub fn row(&self, i: usize) -> &[f64] {
        &self.data[i * self.width..(i + 1) * self.width]
    }

    /// `what` as rows of `width`: an array (or anything numpy takes) whose last axis has
    /// `width` entries. Errors name `what` and say what was expected.
    pub fn read(what: &str, value: &Bound<'_, PyAny>, width: usize) -> PyResult<Self> {
        let Numbers { shape, data } = Numbers::read_unchecked(what, value)?;
        let Some((&last, lead)) = shape.split_last() else {
            return Err(invalid(format!(
                "{what}: a scalar, expected an array whose last axis has {width} entries"
            )));
        };
        if last != width {
            return Err(invalid(format!("{what}: the last axis has {last} entries, expected {width}")));
        }
        finite(what, &data)?;
        Ok(Self { lead: lead.to_vec(), data, width })
    }

    /// `what` as rows matching `like`'s leading shape: `None` gives zeros, one row
    /// (shape `(width,)`) is used for every row of `like`.
    pub fn read_like(
        what: &str,
        value: Option<&Bound<'_, PyAny>>,
        width: usize,
        like: &Rows,
    ) -> PyResult<Self> {
        let Some(value) = value.filter(|v| !v.is_none()) else {
            return Ok(Self { lead: like.lead.clone(), data: vec![0.0; like.count() * width], width });
        };
        let rows = Self::read(what, value, width)?;
        if rows.lead == like.lead {
            return Ok(rows);
        }
        if rows.lead.is_empty() {
            let data = rows.data.iter().copied().cycle().take(like.count() * width).collect();
            return Ok(Self { lead: like.lead.clone(), data, width });
        }
        Err(invalid(format!(
            "{what}: the leading shape {:?} is not that of q, {:?} (give one row for all, or one per state)",
            rows.lead, like.lead
        )))
    }
}

/// Finite numbers of any shape (one number: shape `()`), in C order.
#[derive(Debug, Clone, PartialEq)]
pub struct Numbers {
    pub shape: Vec<usize>,
    pub data: Vec<f64>,
}

impl Numbers {
    /// `what` as numpy reads it (`numpy.asarray(value, "float64")`); errors name `what`
    /// and the first number that is not finite.
    pub fn read(what: &str, value: &Bound<'_, PyAny>) -> PyResult<Self> {
        let numbers = Self::read_unchecked(what, value)?;
        finite(what, &numbers.data)?;
        Ok(numbers)
    }

    /// [`read`](Self::read), the numbers not checked.
    fn read_unchecked(what: &str, value: &Bound<'_, PyAny>) -> PyResult<Self> {
        let array: PyReadonlyArrayDyn<'_, f64> = value
            .extract()
            .or_else(|_| {
                let np = value.py().import("numpy")?;
                np.call_method1("asarray", (value, "float64"))?.extract()
            })
            .map_err(|_| invalid(format!("{what}: not an array of numbers")))?;
        // `as_slice` is memory order, which is the rows' order only for C order (a
        // Fortran-ordered array is contiguous too); otherwise the logical order.
        let data: Vec<f64> = match array.as_slice() {
            Ok(contiguous) if array.is_c_contiguous() => contiguous.to_vec(),
            _ => array.as_array().iter().copied().collect(),
        };
        Ok(Self { shape: array.shape().to_vec(), data })
    }

    /// The numbers as an array of their shape.
    pub fn to_array<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let (lead, tail) = self.shape.split_at(self.shape.len().saturating_sub(1));
        match tail {
            [] => Ok(self.data[0].into_pyobject(py)?.into_any()),
            _ => Ok(array(py, self.data.clone(), lead, tail)?.into_any()),
        }
    }

    /// One group of `width` numbers per state of the leading shape `lead` (`width = 1` for
    /// one number a state): the same group for all (shape `(width,)`, or `()` when
    /// `width = 1`), or one per state (shape `lead + (width,)`, or `lead` when `width = 1`).
    /// Errors name `what` and the shapes.
    pub fn per_state(&self, what: &str, width: usize, lead: &[usize]) -> PyResult<Vec<&[f64]>> {
        let group = [width];
        self.per_state_shaped(what, if width == 1 { &[] } else { &group }, lead)
    }

    /// [`per_state`](Self::per_state) for groups of shape `group` (the numbers of one
    /// state: `(m, 3)` positions, say): shape `group` for all, or `lead + group`.
    pub fn per_state_shaped(&self, what: &str, group: &[usize], lead: &[usize]) -> PyResult<Vec<&[f64]>> {
        let count: usize = lead.iter().product();
        let each: Vec<usize> = lead.iter().chain(group).copied().collect();
        if self.shape == group {
            return Ok(vec![&self.data[..]; count]);
        }
        if self.shape == each {
            let width = group.iter().product::<usize>().max(1);
            return Ok(self.data.chunks_exact(width).collect());
        }
        Err(invalid(format!(
            "{what}: shape {:?} is neither {group:?} (one for all) nor {each:?} (one per state)",
            self.shape
        )))
    }
}

/// An error naming `what` and the first number of `data` that is not finite.
fn finite(what: &str, data: &[f64]) -> PyResult<()> {
    match data.iter().find(|v| !v.is_finite()) {
        Some(v) => Err(invalid(format!("{what}: {v} is not finite"))),
        None => Ok(()),
    }
}

/// `data` as an array of shape `lead + tail`.
pub fn array<'py, T: numpy::Element>(
    py: Python<'py>,
    data: Vec<T>,
    lead: &[usize],
    tail: &[usize],
) -> PyResult<Bound<'py, PyArrayDyn<T>>> {
    let shape: Vec<usize> = lead.iter().chain(tail).copied().collect();
    let flat = PyArray1::from_vec(py, data);
    if shape.len() == 1 {
        return Ok(flat.to_dyn().clone());
    }
    flat.reshape(shape)
}

/// A per-link value as given: one number (a list of one) or a sequence of numbers;
/// [`pendulum_experiment::options::expand`] makes it one per link.
pub fn per_link(what: &str, value: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
    if let Ok(v) = value.extract::<f64>() {
        return Ok(vec![v]);
    }
    value.extract().map_err(|_| invalid(format!("{what}: not a number or a sequence of numbers")))
}

/// `value` as numbers: one number, or a non-empty sequence.
pub fn numbers(what: &str, value: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
    if let Ok(x) = value.extract::<f64>() {
        return Ok(vec![x]);
    }
    let v = value
        .extract::<Vec<f64>>()
        .map_err(|_| invalid(format!("{what}: a number or a sequence of numbers")))?;
    if v.is_empty() {
        return Err(invalid(format!("{what}: an empty sequence")));
    }
    Ok(v)
}
