//! The (dynamic) Allan variance: `davar` and its ranged, part-wise and Hann-weighted forms, and the
//! grid on which a record may be cut into parts (allanite-core `allan`, `oavar`, `taper`).

use crate::{parameter_error, per_axis_m_and_window, run_interruptible, to_3d};
use allanite_core::dynamic_hann_cancellable;
use allanite_core::{dynamic_avar_cancellable, Estimator, Method, Request};
use allanite_core::{dynamic_avar_part_cancellable, dynamic_avar_ranged_cancellable};
use numpy::{PyArray3, PyReadonlyArray1};
use pyo3::prelude::*;

pub(crate) fn parse_estimator(py: Python<'_>, s: &str) -> PyResult<Estimator> {
    match s {
        "oavar" => Ok(Estimator::Overlapping),
        "avar" => Ok(Estimator::Classic),
        other => Err(parameter_error(
            py,
            format!("unknown estimator {other:?}; allowed: 'oavar', 'avar'"),
        )),
    }
}

pub(crate) fn parse_method(py: Python<'_>, s: &str) -> PyResult<Method> {
    match s {
        "fast" => Ok(Method::Fast),
        "naive" => Ok(Method::Naive),
        other => Err(parameter_error(
            py,
            format!("unknown method {other:?}; allowed: 'fast', 'naive'"),
        )),
    }
}

/// The estimator and method every dynamic Allan call takes, checked in this order (the axes after them).
pub(crate) fn dynamic_args(
    py: Python<'_>,
    estimator: &str,
    method: &str,
) -> PyResult<(Estimator, Method)> {
    Ok((parse_estimator(py, estimator)?, parse_method(py, method)?))
}

/// The core's request of a dynamic call.
pub(crate) fn request<'a>(
    columns: &'a [&'a [f64]],
    window: usize,
    hop: usize,
    ms: &'a [usize],
    estimator: Estimator,
    method: Method,
) -> Request<'a> {
    Request {
        columns,
        window,
        hop,
        ms,
        estimator,
        method,
    }
}

/// Allan variance of every window at every averaging factor, for every axis.
///
/// `columns`: one contiguous float64 rate record per axis (equal lengths). Returns an array of shape
/// (axes, len(ms), windows). `window == len(record)` gives the static estimator.
#[pyfunction]
#[pyo3(signature = (columns, window, hop, ms, estimator, method, workers))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn davar<'py>(
    py: Python<'py>,
    columns: Vec<PyReadonlyArray1<'py, f64>>,
    window: usize,
    hop: usize,
    ms: Vec<usize>,
    estimator: &str,
    method: &str,
    workers: usize,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let (estimator, method) = dynamic_args(py, estimator, method)?;
    per_axis_m_and_window(py, &columns, ms.len(), workers, |cols, cancel| {
        dynamic_avar_cancellable(&request(cols, window, hop, &ms, estimator, method), cancel)
    })
}

/// [`davar`] and the range of every (axis, m) row of the result: (values, ranges), ranges of shape
/// (axes, len(ms), 3) holding each row's largest value, smallest value and 1.0 where a value is not
/// finite (allanite-core `dynamic_avar_ranged_cancellable`; the rows of a hop-1 surface are noted while
/// in cache, so that the caller's range check need not read the surface again).
#[pyfunction]
#[pyo3(signature = (columns, window, hop, ms, estimator, method, workers))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
pub(crate) fn davar_ranged<'py>(
    py: Python<'py>,
    columns: Vec<PyReadonlyArray1<'py, f64>>,
    window: usize,
    hop: usize,
    ms: Vec<usize>,
    estimator: &str,
    method: &str,
    workers: usize,
) -> PyResult<(Bound<'py, PyArray3<f64>>, Bound<'py, PyArray3<f64>>)> {
    let (estimator, method) = dynamic_args(py, estimator, method)?;
    let slices = crate::contiguous(py, &columns)?;
    let req = request(&slices, window, hop, &ms, estimator, method);
    let (values, n_win, ranges) = run_interruptible(py, workers, |cancel| {
        dynamic_avar_ranged_cancellable(&req, cancel)
    })?;
    let flat: Vec<f64> = ranges
        .iter()
        .flat_map(|r| [r.max, r.min, if r.non_finite { 1.0 } else { 0.0 }])
        .collect();
    Ok((
        to_3d(py, (slices.len(), ms.len(), n_win), values)?,
        to_3d(py, (slices.len(), ms.len(), 3), flat)?,
    ))
}

/// [`davar`] of the windows `first_window ..` of a record of `n_windows` windows, from a part of it
/// (`columns`: the record's samples from `first_window · hop` on) centred on the record's means
/// `mus`: the whole-record values, bit for bit when the part starts on the record's [`part_grid`]
/// (to a few ε elsewhere on the phase path; allanite-core `dynamic_avar_part_cancellable`). For
/// allanite.dask, whose blocks hold parts of a record.
#[pyfunction]
#[pyo3(signature = (columns, window, hop, ms, estimator, method, workers, mus, first_window, n_windows))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn davar_part<'py>(
    py: Python<'py>,
    columns: Vec<PyReadonlyArray1<'py, f64>>,
    window: usize,
    hop: usize,
    ms: Vec<usize>,
    estimator: &str,
    method: &str,
    workers: usize,
    mus: Vec<f64>,
    first_window: usize,
    n_windows: usize,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let (estimator, method) = dynamic_args(py, estimator, method)?;
    per_axis_m_and_window(py, &columns, ms.len(), workers, |cols, cancel| {
        let req = request(cols, window, hop, &ms, estimator, method);
        dynamic_avar_part_cancellable(&req, &mus, first_window, n_windows, cancel)
    })
}

/// Samples between the places a record of `n` samples × `n_axes` may be cut into [`davar_part`] parts
/// that give the whole call's values bit for bit: the hop where the call streams its sums, a phase
/// segment's windows × hop on its phase path (allanite-core `part_grid`). For allanite.dask's chunks.
#[pyfunction]
#[pyo3(signature = (n, n_axes, window, hop, estimator, method))]
pub(crate) fn part_grid(
    py: Python<'_>,
    n: usize,
    n_axes: usize,
    window: usize,
    hop: usize,
    estimator: &str,
    method: &str,
) -> PyResult<usize> {
    let (estimator, method) = dynamic_args(py, estimator, method)?;
    allanite_core::part_grid(n, n_axes, window, hop, estimator, method).ok_or_else(|| {
        parameter_error(
            py,
            format!(
                "no dynamic call of window {window} and hop {hop} on {n} samples × {n_axes} axes: \
                 2 ≤ window ≤ samples, hop ≥ 1 and at least one axis are needed"
            ),
        )
    })
}

/// Hann-weighted overlapping Allan variance of every window at every averaging factor, for every
/// axis (paper 002; docs/FORMULAS.md §10): shape (axes, len(ms), windows). `window == len(record)`
/// gives the static estimator. Every m must leave M = window + 1 − 2m ≥ 3 terms.
#[pyfunction]
#[pyo3(signature = (columns, window, hop, ms, method, workers))]
pub(crate) fn davar_hann<'py>(
    py: Python<'py>,
    columns: Vec<PyReadonlyArray1<'py, f64>>,
    window: usize,
    hop: usize,
    ms: Vec<usize>,
    method: &str,
    workers: usize,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let method = parse_method(py, method)?;
    per_axis_m_and_window(py, &columns, ms.len(), workers, |cols, cancel| {
        let req = request(cols, window, hop, &ms, Estimator::Overlapping, method);
        dynamic_hann_cancellable(&req, cancel)
    })
}
