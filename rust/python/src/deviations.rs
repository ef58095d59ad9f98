//! The other deviations (allanite-core `deviations`): MVAR, Hadamard and total variances, their gap-aware
//! and sliding-window forms, MTIE and TIE rms.

use crate::{allanite_error, as_i64, contiguous, run_interruptible, to_2d, to_3d};
use crate::{per_axis_and_m, per_axis_m_and_window};
use allanite_core::deviations;
use numpy::{PyArray2, PyArray3, PyReadonlyArray1};
use pyo3::prelude::*;

pub(crate) fn parse_kind(py: Python<'_>, s: &str, allowed: &[&str]) -> PyResult<deviations::Kind> {
    use deviations::Kind;
    let kind = match s {
        "oavar" => Some(Kind::Oavar),
        "mvar" => Some(Kind::Mvar),
        "hvar" => Some(Kind::Hvar),
        "ohvar" => Some(Kind::Ohvar),
        "totvar" => Some(Kind::Totvar),
        "mtotvar" => Some(Kind::Mtotvar),
        "htotvar" => Some(Kind::Htotvar),
        _ => None,
    };
    match kind {
        Some(k) if allowed.contains(&s) => Ok(k),
        _ => Err(allanite_error(
            py,
            format!("unknown estimator {s:?}; allowed: {}", allowed.join(", ")),
        )),
    }
}

/// One deviation of each whole rate record at every averaging factor: shape (axes, len(ms)).
///
/// `estimator`: 'mvar', 'hvar', 'ohvar', 'totvar', 'mtotvar' or 'htotvar' (variances for τ0 = 1,
/// no bias correction). NaN and ±inf are rejected.
#[pyfunction]
#[pyo3(signature = (columns, ms, estimator, workers))]
pub(crate) fn deviation_static<'py>(
    py: Python<'py>,
    columns: Vec<PyReadonlyArray1<'py, f64>>,
    ms: Vec<usize>,
    estimator: &str,
    workers: usize,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let kind = parse_kind(
        py,
        estimator,
        &["mvar", "hvar", "ohvar", "totvar", "mtotvar", "htotvar"],
    )?;
    per_axis_and_m(py, &columns, ms.len(), workers, |cols, cancel| {
        deviations::static_deviation_cancellable(cols, &ms, kind, cancel)
    })
}

/// Time total variance (τ²/3)·MTOTVAR, τ = m·tau0, of each rate record: shape (axes, len(ms)).
#[pyfunction]
#[pyo3(signature = (columns, ms, tau0, workers))]
pub(crate) fn ttotvar_static<'py>(
    py: Python<'py>,
    columns: Vec<PyReadonlyArray1<'py, f64>>,
    ms: Vec<usize>,
    tau0: f64,
    workers: usize,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    per_axis_and_m(py, &columns, ms.len(), workers, |cols, cancel| {
        deviations::static_ttotvar_cancellable(cols, &ms, tau0, cancel)
    })
}

/// Gap-aware OAVAR/MVAR/OHVAR (and classic AVAR/HVAR: "avar", "hvar") of rate records with NaN-marked gaps: (values, counts), each of
/// shape (axes, len(ms)); counts (int64) are the complete terms used; no term gives NaN, 0.
#[pyfunction]
#[pyo3(signature = (columns, ms, estimator, workers))]
#[allow(clippy::type_complexity)]
pub(crate) fn deviation_gaps<'py>(
    py: Python<'py>,
    columns: Vec<PyReadonlyArray1<'py, f64>>,
    ms: Vec<usize>,
    estimator: &str,
    workers: usize,
) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<i64>>)> {
    // classic AVAR and HVAR: the OAVAR and OHVAR terms that start at multiples of m
    let (name, classic) = match estimator {
        "avar" => ("oavar", true),
        "hvar" => ("ohvar", true),
        other => (other, false),
    };
    let kind = parse_kind(
        py,
        name,
        &["oavar", "mvar", "ohvar", "totvar", "mtotvar", "htotvar"],
    )?;
    let slices = contiguous(py, &columns)?;
    let (values, counts) = run_interruptible(py, workers, |cancel| {
        deviations::gap_deviation_cancellable(&slices, &ms, kind, classic, cancel)
    })?;
    Ok((
        to_2d(py, slices.len(), ms.len(), values)?,
        to_2d(py, slices.len(), ms.len(), as_i64(counts))?,
    ))
}

/// Overlapping Hadamard variance of every sliding window: shape (axes, len(ms), windows).
#[pyfunction]
#[pyo3(signature = (columns, window, hop, ms, workers))]
pub(crate) fn ohvar_dynamic<'py>(
    py: Python<'py>,
    columns: Vec<PyReadonlyArray1<'py, f64>>,
    window: usize,
    hop: usize,
    ms: Vec<usize>,
    workers: usize,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    per_axis_m_and_window(py, &columns, ms.len(), workers, |cols, _cancel| {
        deviations::dynamic_ohvar(cols, window, hop, &ms)
    })
}

/// (values, counts) of a gap-aware whole-record estimate.
type ValuesCounts2<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<i64>>);

/// (values, counts) of a gap-aware sliding-window estimate.
type ValuesCounts3<'py> = (Bound<'py, PyArray3<f64>>, Bound<'py, PyArray3<i64>>);

/// Gap-aware OAVAR or OHVAR of every sliding window (NaN marks a missing rate sample): values and
/// complete-term counts, each of shape (axes, len(ms), windows).
#[pyfunction]
#[pyo3(signature = (columns, window, hop, ms, estimator, workers))]
pub(crate) fn deviation_gaps_dynamic<'py>(
    py: Python<'py>,
    columns: Vec<PyReadonlyArray1<'py, f64>>,
    window: usize,
    hop: usize,
    ms: Vec<usize>,
    estimator: &str,
    workers: usize,
) -> PyResult<ValuesCounts3<'py>> {
    let kind = parse_kind(py, estimator, &["oavar", "ohvar"])?;
    let slices = contiguous(py, &columns)?;
    let (values, counts, n_win) = run_interruptible(py, workers, |cancel| {
        deviations::gap_dynamic(&slices, window, hop, &ms, kind, cancel)
    })?;
    let shape = (slices.len(), ms.len(), n_win);
    Ok((to_3d(py, shape, values)?, to_3d(py, shape, as_i64(counts))?))
}

/// Gap-aware MTIE or TIE rms of phase records with the prefix counts of missing rate samples:
/// (values, kept windows), each of shape (axes, len(ms)).
#[pyfunction]
#[pyo3(signature = (phases, gaps, ms, estimator, workers))]
pub(crate) fn tie_gaps<'py>(
    py: Python<'py>,
    phases: Vec<PyReadonlyArray1<'py, f64>>,
    gaps: Vec<PyReadonlyArray1<'py, u64>>,
    ms: Vec<usize>,
    estimator: &str,
    workers: usize,
) -> PyResult<ValuesCounts2<'py>> {
    let mtie = match estimator {
        "mtie" => true,
        "tierms" => false,
        other => {
            return Err(allanite_error(
                py,
                format!("unknown estimator {other:?}; allowed: mtie, tierms"),
            ))
        }
    };
    let slices = contiguous(py, &phases)?;
    let g: Vec<&[u64]> = gaps
        .iter()
        .map(|a| a.as_slice())
        .collect::<std::result::Result<_, _>>()
        .map_err(|e| allanite_error(py, format!("gap counts must be contiguous: {e}")))?;
    let (values, counts) = run_interruptible(py, workers, |_cancel| {
        deviations::tie_gaps(&slices, &g, &ms, mtie)
    })?;
    Ok((
        to_2d(py, slices.len(), ms.len(), values)?,
        to_2d(py, slices.len(), ms.len(), as_i64(counts))?,
    ))
}

/// MTIE of each *phase* record (windows of m + 1 points): shape (axes, len(ms)).
#[pyfunction]
#[pyo3(signature = (columns, ms, workers))]
pub(crate) fn mtie_phase<'py>(
    py: Python<'py>,
    columns: Vec<PyReadonlyArray1<'py, f64>>,
    ms: Vec<usize>,
    workers: usize,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    per_axis_and_m(py, &columns, ms.len(), workers, |cols, _cancel| {
        deviations::mtie(cols, &ms)
    })
}

/// TIE rms of each *phase* record: shape (axes, len(ms)).
#[pyfunction]
#[pyo3(signature = (columns, ms, workers))]
pub(crate) fn tierms_phase<'py>(
    py: Python<'py>,
    columns: Vec<PyReadonlyArray1<'py, f64>>,
    ms: Vec<usize>,
    workers: usize,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    per_axis_and_m(py, &columns, ms.len(), workers, |cols, _cancel| {
        deviations::tie_rms(cols, &ms)
    })
}
