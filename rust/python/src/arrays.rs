//! numpy in and out: the input columns as contiguous slices, the kernels' flat results as shaped arrays.

use crate::{allanite_error, input_error};
use numpy::ndarray::{Array2, Array3};
use numpy::{Element, IntoPyArray, PyArray2, PyArray3, PyReadonlyArray1};
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
