//! The streaming variance of a growing phase record (allanite-core `streaming`).

use crate::{contiguous_one, core_error, parameter_error};
use allanite_core::streaming::{Stream, StreamKind};
use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;

/// A streaming overlapping Allan ("oavar"), overlapping Hadamard ("ohvar") or time ("tvar")
/// variance of a growing phase record: push points, read the values (τ0 = 1) at every averaging
/// factor. `pending`: factors added automatically (each at 2m + 1 points), increasing.
#[pyclass(module = "allanite._core")]
pub(crate) struct StreamingVariance {
    inner: Stream,
}

#[pymethods]
impl StreamingVariance {
    #[new]
    #[pyo3(signature = (kind, ms, pending))]
    fn new(py: Python<'_>, kind: &str, ms: Vec<usize>, pending: Vec<usize>) -> PyResult<Self> {
        let kind = match kind {
            "oavar" => StreamKind::Oavar,
            "ohvar" => StreamKind::Ohvar,
            "tvar" => StreamKind::Tvar,
            other => {
                return Err(parameter_error(
                    py,
                    format!(
                        "unknown streaming variance {other:?}; allowed: 'oavar', 'ohvar', 'tvar'"
                    ),
                ))
            }
        };
        let inner = Stream::new(kind, &ms, &pending).map_err(|e| core_error(py, e))?;
        Ok(StreamingVariance { inner })
    }

    /// Appends one phase point.
    fn push(&mut self, py: Python<'_>, x: f64) -> PyResult<()> {
        self.inner.push(x).map_err(|e| core_error(py, e))
    }

    /// Appends phase points in order (those before a non-finite one are kept).
    fn extend(&mut self, py: Python<'_>, xs: PyReadonlyArray1<'_, f64>) -> PyResult<()> {
        let x = contiguous_one(py, &xs)?;
        self.inner.extend(x).map_err(|e| core_error(py, e))
    }

    /// Adds an averaging factor, exact over the points already held.
    fn add_factor(&mut self, py: Python<'_>, m: usize) -> PyResult<()> {
        self.inner.add_factor(m).map_err(|e| core_error(py, e))
    }

    /// The averaging factors, in the order they were added.
    fn factors(&self) -> Vec<usize> {
        self.inner.factors()
    }

    /// Terms closed at each averaging factor.
    fn counts(&self) -> Vec<u64> {
        self.inner.counts()
    }

    /// The variance at each averaging factor for τ0 = 1 (NaN before its first term).
    fn values<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.inner.values().into_pyarray(py)
    }

    /// The phase points held (a copy).
    fn phase<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.inner.phase().to_vec().into_pyarray(py)
    }

    fn __len__(&self) -> usize {
        self.inner.phase().len()
    }
}
