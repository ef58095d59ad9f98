//! Theo1 of whole records and of sliding windows (allanite-core `theo`).

use crate::{per_axis_and_m, per_axis_m_and_window};
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
    per_axis_and_m(py, &columns, ms.len(), workers, |cols, cancel| {
        static_theo1_cancellable(cols, &ms, cancel)
    })
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
    per_axis_m_and_window(py, &columns, ms.len(), workers, |cols, cancel| {
        dynamic_theo1_cancellable(cols, window, hop, &ms, cancel)
    })
}
