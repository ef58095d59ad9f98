//! numpy in and out: the input columns as contiguous slices, the kernels' flat results as shaped arrays,
//! and the one shape most bindings have — contiguous axes in, a kernel run, an (axes, len(ms)[, windows])
//! array out ([`per_axis_and_m`], [`per_axis_m_and_window`]).

use crate::{allanite_error, input_error, parameter_error, run_interruptible};
use allanite_core::Cancel;
use numpy::ndarray::{Array2, Array3, Dimension};
use numpy::{Element, IntoPyArray, PyArray2, PyArray3, PyReadonlyArray, PyReadonlyArray1};
use pyo3::prelude::*;

/// `values` (row-major) as a (rows, cols) numpy array.
pub(crate) fn to_2d<'py, T: Element>(
    py: Python<'py>,
    rows: usize,
    cols: usize,
    values: Vec<T>,
) -> PyResult<Bound<'py, PyArray2<T>>> {
    let arr = Array2::from_shape_vec((rows, cols), values)
        .map_err(|e| allanite_error(py, format!("internal shape error: {e}")))?;
    Ok(arr.into_pyarray(py))
}

/// `values` (row-major) as a numpy array of `shape`.
pub(crate) fn to_3d<'py, T: Element>(
    py: Python<'py>,
    shape: (usize, usize, usize),
    values: Vec<T>,
) -> PyResult<Bound<'py, PyArray3<T>>> {
    let arr = Array3::from_shape_vec(shape, values)
        .map_err(|e| allanite_error(py, format!("internal shape error: {e}")))?;
    Ok(arr.into_pyarray(py))
}

/// Term counts as int64, numpy's index type.
pub(crate) fn as_i64(counts: Vec<u64>) -> Vec<i64> {
    counts.into_iter().map(|c| c as i64).collect()
}

/// The input columns as contiguous slices, or InputError "axis {a} is not a contiguous float64 array".
pub(crate) fn contiguous<'a>(
    py: Python<'_>,
    columns: &'a [PyReadonlyArray1<'_, f64>],
) -> PyResult<Vec<&'a [f64]>> {
    let mut slices: Vec<&[f64]> = Vec::with_capacity(columns.len());
    for (a, c) in columns.iter().enumerate() {
        let s = c
            .as_slice()
            .map_err(|_| input_error(py, format!("axis {a} is not a contiguous float64 array")))?;
        slices.push(s);
    }
    Ok(slices)
}

/// [`contiguous`] of one array (named axis 0 in the error).
pub(crate) fn contiguous_one<'a>(
    py: Python<'_>,
    a: &'a PyReadonlyArray1<'_, f64>,
) -> PyResult<&'a [f64]> {
    Ok(contiguous(py, std::slice::from_ref(a))?[0])
}

/// numpy's name of an element type, for the messages of [`c_slice`].
pub(crate) trait DtypeName {
    const NAME: &'static str;
}

impl DtypeName for f64 {
    const NAME: &'static str = "float64";
}

impl DtypeName for i64 {
    const NAME: &'static str = "int64";
}

/// An argument array of any dimension as its C-order slice, or ParameterError "{what} must be a
/// C-contiguous {dtype} array".
pub(crate) fn c_slice<'a, T: Element + DtypeName, D: Dimension>(
    py: Python<'_>,
    a: &'a PyReadonlyArray<'_, T, D>,
    what: &str,
) -> PyResult<&'a [T]> {
    a.as_slice().map_err(|_| {
        parameter_error(
            py,
            format!("{what} must be a C-contiguous {} array", T::NAME),
        )
    })
}

/// A kernel of whole records: `columns` checked [`contiguous`], `kernel` run on them interruptibly
/// (`run_interruptible`), its flat values returned as an (axes, `n_ms`) array.
pub(crate) fn per_axis_and_m<'py>(
    py: Python<'py>,
    columns: &[PyReadonlyArray1<'_, f64>],
    n_ms: usize,
    workers: usize,
    kernel: impl FnOnce(&[&[f64]], &Cancel) -> allanite_core::Result<Vec<f64>> + Send,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let slices = contiguous(py, columns)?;
    let values = run_interruptible(py, workers, |cancel| kernel(&slices, cancel))?;
    to_2d(py, slices.len(), n_ms, values)
}

/// A kernel of sliding windows: as [`per_axis_and_m`], the kernel returning (values, windows) and the
/// result an (axes, `n_ms`, windows) array.
pub(crate) fn per_axis_m_and_window<'py>(
    py: Python<'py>,
    columns: &[PyReadonlyArray1<'_, f64>],
    n_ms: usize,
    workers: usize,
    kernel: impl FnOnce(&[&[f64]], &Cancel) -> allanite_core::Result<(Vec<f64>, usize)> + Send,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let slices = contiguous(py, columns)?;
    let (values, n_win) = run_interruptible(py, workers, |cancel| kernel(&slices, cancel))?;
    to_3d(py, (slices.len(), n_ms, n_win), values)
}
