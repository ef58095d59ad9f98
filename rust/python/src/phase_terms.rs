//! Term sums and counts of the phase-domain kernels (allanite-core `phase_terms`): the caller divides.

use crate::{contiguous, contiguous_one, run_interruptible};
use allanite_core::phase_terms::{self, TermSum};
use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;

/// (sums, counts) of a phase-domain term kernel as two float64/int64 arrays.
pub(crate) fn term_sums<'py>(
    py: Python<'py>,
    sums: Vec<TermSum>,
) -> (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<i64>>) {
    let s: Vec<f64> = sums.iter().map(|t| t.sum).collect();
    let c: Vec<i64> = sums.iter().map(|t| t.count as i64).collect();
    (s.into_pyarray(py), c.into_pyarray(py))
}

/// Parabolic-variance term sums Σ u_i² and counts N − 2m of a *phase* record at every m ≥ 2.
#[pyfunction]
#[pyo3(signature = (phase, ms, workers))]
#[allow(clippy::type_complexity)]
pub(crate) fn pvar_phase<'py>(
    py: Python<'py>,
    phase: PyReadonlyArray1<'py, f64>,
    ms: Vec<usize>,
    workers: usize,
) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<i64>>)> {
    let x = contiguous_one(py, &phase)?;
    let sums = run_interruptible(py, workers, |_c| phase_terms::pvar_sums(x, &ms))?;
    Ok(term_sums(py, sums))
}

/// Σ of products of the overlapping second differences of two *phase* records, and counts.
#[pyfunction]
#[pyo3(signature = (phase1, phase2, ms, workers))]
#[allow(clippy::type_complexity)]
pub(crate) fn allan_covariance_phase<'py>(
    py: Python<'py>,
    phase1: PyReadonlyArray1<'py, f64>,
    phase2: PyReadonlyArray1<'py, f64>,
    ms: Vec<usize>,
    workers: usize,
) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<i64>>)> {
    let cols = [phase1, phase2];
    let xs = contiguous(py, &cols)?;
    let sums = run_interruptible(py, workers, |_c| {
        phase_terms::allan_covariance_sums(xs[0], xs[1], &ms)
    })?;
    Ok(term_sums(py, sums))
}

/// Σ (Δ²x)² over the overlapping second differences of a *phase* record whose three points are not
/// NaN, and their counts (allantools' gradev rule).
#[pyfunction]
#[pyo3(signature = (phase, ms, workers))]
#[allow(clippy::type_complexity)]
pub(crate) fn oavar_phase_gaps<'py>(
    py: Python<'py>,
    phase: PyReadonlyArray1<'py, f64>,
    ms: Vec<usize>,
    workers: usize,
) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<i64>>)> {
    let x = contiguous_one(py, &phase)?;
    let sums = run_interruptible(py, workers, |_c| phase_terms::oavar_phase_gap_sums(x, &ms))?;
    Ok(term_sums(py, sums))
}
