//! Theo1 of whole records and of sliding windows (allanite-core `theo`).

use crate::{contiguous, run_interruptible, to_2d, to_3d};
use allanite_core::{dynamic_theo1_cancellable, static_theo1_cancellable};
use numpy::{PyArray2, PyArray3, PyReadonlyArray1};
use pyo3::prelude::*;

/// Theo1 of each whole rate record at every (even) averaging factor: shape (axes, len(ms)).
#[pyfunction]
#[pyo3(signature = (columns, ms, workers))]
pub(crate) fn theo1_static<'py>(
    py: Python<'py>,
    columns: Vec<PyReadonlyArray1<'py, f64>>,
    ms: Vec<usize>,
    workers: usize,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let slices = contiguous(py, &columns)?;
    let values = run_interruptible(py, workers, |cancel| {
        static_theo1_cancellable(&slices, &ms, cancel)
    })?;
    to_2d(py, slices.len(), ms.len(), values)
}

/// Theo1 of every sliding window at every (even) averaging factor: shape (axes, len(ms), windows).
#[pyfunction]
#[pyo3(signature = (columns, window, hop, ms, workers))]
pub(crate) fn theo1_dynamic<'py>(
    py: Python<'py>,
    columns: Vec<PyReadonlyArray1<'py, f64>>,
    window: usize,
    hop: usize,
    ms: Vec<usize>,
    workers: usize,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let slices = contiguous(py, &columns)?;
    let (values, n_win) = run_interruptible(py, workers, |cancel| {
        dynamic_theo1_cancellable(&slices, window, hop, &ms, cancel)
    })?;
    to_3d(py, (slices.len(), ms.len(), n_win), values)
}
