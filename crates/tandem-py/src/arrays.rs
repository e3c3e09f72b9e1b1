//! NumPy in and out.
//!
//! In: a float64 array is read in place (a borrowed view, no copy before the one into the
//! owned buffer the Rust types keep); other real dtypes (integers, float32) are converted to
//! float64 first; lists are converted with `numpy.asarray`. Ragged nesting, a wrong number of
//! dimensions and non-real dtypes (bool where numbers are expected, complex, object, strings)
//! are [`Error::Input`] naming the argument and what was found.
//!
//! Out: arrays are built from an owned `Vec` whose buffer NumPy takes over (no copy).

use numpy::ndarray::{Array2, ArrayView2};
use numpy::prelude::*;
use numpy::{PyArray1, PyArray2, PyArrayDyn, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArray};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::errors::{Error, Result};

/// `x` as a NumPy array (`numpy.asarray` for anything that is not one already), or an
/// [`Error::Input`] for ragged nesting.
fn as_ndarray<'py>(x: &Bound<'py, PyAny>, what: &str) -> Result<Bound<'py, PyUntypedArray>> {
    if let Ok(a) = x.cast::<PyUntypedArray>() {
        return Ok(a.clone());
    }
    let py = x.py();
    let converted = py
        .import("numpy")
        .and_then(|np| np.call_method1("asarray", (x,)))
        .map_err(|e| {
            let why = if e.is_instance_of::<PyValueError>(py) {
                format!(
                    "ragged or malformed nesting ({}); every row needs the same number of values",
                    e.value(py)
                )
            } else {
                format!("cannot convert to an array: {}", e.value(py))
            };
            Error::input(what, why)
        })?;
    converted.cast_into::<PyUntypedArray>().map_err(|_| {
        Error::input(
            what,
            "numpy.asarray did not return an array (is numpy installed correctly?)",
        )
    })
}

/// Shape as text, `(3, 4)`.
fn shape_text(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// `x` as a NumPy array with `ndim` dimensions, or an [`Error::Input`] naming `what`, the
/// shape found and `expected` (the meaning of the axes).
fn with_ndim<'py>(
    x: &Bound<'py, PyAny>,
    what: &str,
    ndim: usize,
    expected: &str,
) -> Result<Bound<'py, PyUntypedArray>> {
    let a = as_ndarray(x, what)?;
    if a.ndim() != ndim {
        return Err(Error::input(
            what,
            format!(
                "{}-D array of shape {}, expected a {ndim}-D array ({expected})",
                a.ndim(),
                shape_text(a.shape())
            ),
        ));
    }
    Ok(a)
}

/// `x` as a float64 array with `ndim` dimensions: integers and other floats converted, any
/// other dtype or number of dimensions an error naming `what` and `expected` (the meaning
/// of the axes, for the message).
fn real_array<'py>(
    x: &Bound<'py, PyAny>,
    what: &str,
    ndim: usize,
    expected: &str,
) -> Result<Bound<'py, PyArrayDyn<f64>>> {
    let a = with_ndim(x, what, ndim, expected)?;
    let dtype = a.dtype();
    let kind = dtype.kind();
    if let Ok(f) = a.cast::<PyArrayDyn<f64>>() {
        return Ok(f.clone());
    }
    if !matches!(kind, b'f' | b'i' | b'u') {
        return Err(Error::input(
            what,
            format!(
                "dtype {dtype}, expected real numbers (float64; integer and float32 arrays are \
                 converted)"
            ),
        ));
    }
    a.call_method1("astype", ("float64",))
        .and_then(|c| Ok(c.cast_into::<PyArrayDyn<f64>>()?))
        .map_err(|e| {
            Error::input(
                what,
                format!("cannot convert dtype {dtype} to float64: {e}"),
            )
        })
}

/// A 2-D real array (rows × columns), row-major, copied once into an owned buffer.
pub(crate) fn matrix(x: &Bound<'_, PyAny>, what: &str, axes: &str) -> Result<(Vec<f64>, usize)> {
    let a = real_array(x, what, 2, axes)?;
    let a: Bound<'_, PyArray2<f64>> = a
        .cast_into()
        .map_err(|_| Error::input(what, "not a 2-D array"))?;
    let view: PyReadonlyArray2<'_, f64> = a.readonly();
    let cols = view.shape()[1];
    // `as_slice` accepts Fortran order too, whose memory order is not the row-major order
    // wanted here: only a C-contiguous array is copied as one slice.
    let values = match view.as_slice() {
        Ok(s) if a.is_c_contiguous() => s.to_vec(),
        _ => logical_order(view.as_array()),
    };
    Ok((values, cols))
}

/// The elements of a 2-D view in row-major (logical) order.
fn logical_order(v: ArrayView2<'_, f64>) -> Vec<f64> {
    v.iter().copied().collect()
}

/// A 1-D real array.
pub(crate) fn vector(x: &Bound<'_, PyAny>, what: &str, axis: &str) -> Result<Vec<f64>> {
    let a = real_array(x, what, 1, axis)?;
    let a: Bound<'_, PyArray1<f64>> = a
        .cast_into()
        .map_err(|_| Error::input(what, "not a 1-D array"))?;
    let view: PyReadonlyArray1<'_, f64> = a.readonly();
    Ok(match view.as_slice() {
        Ok(s) => s.to_vec(),
        Err(_) => view.as_array().iter().copied().collect(),
    })
}

/// A 1-D array of flags: dtype bool, or integers that are all 0 or 1.
pub(crate) fn flags(x: &Bound<'_, PyAny>, what: &str, axis: &str) -> Result<Vec<bool>> {
    let a = with_ndim(x, what, 1, axis)?;
    let dtype = a.dtype();
    if let Ok(b) = a.cast::<PyArray1<bool>>() {
        return Ok(b.readonly().as_array().iter().copied().collect());
    }
    if !matches!(dtype.kind(), b'i' | b'u') {
        return Err(Error::input(
            what,
            format!("dtype {dtype}, expected flags (bool, or integers 0/1)"),
        ));
    }
    let values = vector(a.as_any(), what, axis)?;
    values
        .iter()
        .enumerate()
        .map(|(k, &v)| match v {
            0.0 => Ok(false),
            1.0 => Ok(true),
            _ => Err(Error::input(
                what,
                format!("entry {k} is {v}; flags must be 0 or 1"),
            )),
        })
        .collect()
}

/// A 2-D array of flags (dtype bool), row-major, and its number of columns.
pub(crate) fn flag_matrix(
    x: &Bound<'_, PyAny>,
    what: &str,
    axes: &str,
) -> Result<(Vec<bool>, usize)> {
    let a = as_ndarray(x, what)?;
    let Ok(b) = a.cast::<PyArray2<bool>>() else {
        return Err(Error::input(
            what,
            format!(
                "{}-D array of dtype {} and shape {}, expected a 2-D bool array ({axes})",
                a.ndim(),
                a.dtype(),
                shape_text(a.shape())
            ),
        ));
    };
    let view = b.readonly();
    let cols = view.shape()[1];
    Ok((view.as_array().iter().copied().collect(), cols))
}

/// A signal for alignment: a 2-D real array (samples × channels), or a 1-D one as a single
/// channel. Returns the sample-major values and the channel count.
pub(crate) fn signal(x: &Bound<'_, PyAny>, what: &str) -> Result<(Vec<f64>, usize)> {
    if as_ndarray(x, what)?.ndim() == 1 {
        Ok((vector(x, what, "samples")?, 1))
    } else {
        matrix(x, what, "samples × channels")
    }
}

/// A 1-D float64 array of `values` (NumPy takes over the buffer).
pub(crate) fn out_vector<'py>(py: Python<'py>, values: Vec<f64>) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_vec(py, values)
}

/// A 1-D bool array.
pub(crate) fn out_flags<'py>(py: Python<'py>, values: Vec<bool>) -> Bound<'py, PyArray1<bool>> {
    PyArray1::from_vec(py, values)
}

/// A `rows × cols` float64 array from row-major `values` (NumPy takes over the buffer).
///
/// # Errors
/// [`Error::Input`] if `values.len()` is not `rows · cols` (a bug of the caller).
pub(crate) fn out_matrix<T: numpy::Element>(
    py: Python<'_>,
    values: Vec<T>,
    cols: usize,
) -> Result<Bound<'_, PyArray2<T>>> {
    let rows = values.len().checked_div(cols).unwrap_or(0);
    let a = Array2::from_shape_vec((rows, cols), values)
        .map_err(|e| Error::Panic(format!("array of {cols} columns: {e}")))?;
    Ok(PyArray2::from_owned_array(py, a))
}

/// A value as Python's `repr` writes it (for `__repr__`).
pub(crate) trait PyRepr {
    /// The `repr` text.
    fn repr(&self) -> String;
}

impl PyRepr for f64 {
    fn repr(&self) -> String {
        format!("{self:?}")
    }
}

impl PyRepr for bool {
    fn repr(&self) -> String {
        PyBool(*self).to_string()
    }
}

impl PyRepr for String {
    fn repr(&self) -> String {
        format!("'{self}'")
    }
}

/// A bool shown as Python shows it (`True`, `False`).
pub(crate) struct PyBool(pub(crate) bool);

impl std::fmt::Display for PyBool {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(if self.0 { "True" } else { "False" })
    }
}

/// A list as Python's `repr` writes it: `[1.0, 2.5]`, `[True, False]`, `['x', 'y']`.
pub(crate) fn repr_list<T: PyRepr>(items: &[T]) -> String {
    let inner: Vec<String> = items.iter().map(PyRepr::repr).collect();
    format!("[{}]", inner.join(", "))
}
