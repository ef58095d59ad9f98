//! Sums over parts of a record, for the callers that hold a record in parts (allanite.dask) or
//! combine its sums themselves: compensated means, block-average autocorrelation sums, exact-angle
//! second-difference sums.

use crate::{
    contiguous, contiguous_one, input_error, parameter_error, run_interruptible, to_2d, to_3d,
};
use allanite_core::compensated_sum_from;
use allanite_core::{angle_term_sums_cancellable, AngleChunk};
use numpy::{PyArray2, PyArray3, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

/// Neumaier's compensated sum of each column continued from `state` ((sum, compensation) per axis):
/// the new state per axis. Fed a record's parts in order, it ends at the state whose (s + c) / n is
/// the core's centring value of the whole record, bit for bit (allanite-core `compensated_sum_from`).
#[pyfunction]
#[pyo3(signature = (columns, state))]
pub(crate) fn compensated_sums(
    py: Python<'_>,
    columns: Vec<PyReadonlyArray1<'_, f64>>,
    state: Vec<(f64, f64)>,
) -> PyResult<Vec<(f64, f64)>> {
    let slices = contiguous(py, &columns)?;
    if state.len() != slices.len() {
        return Err(parameter_error(
            py,
            format!(
                "{} states given for {} axes: one (sum, compensation) per axis is needed",
                state.len(),
                slices.len()
            ),
        ));
    }
    Ok(py.detach(|| {
        slices
            .iter()
            .zip(state)
            .map(|(c, st)| compensated_sum_from(c, st))
            .collect()
    }))
}

/// Sums of the lag-1 autocorrelation of the block averages of `x` less `mu` at each of `ms` and of
/// their differences up to `dmax` (allanite-core `block_acf`): shape (len(ms), dmax + 1, 5) — Σw, Σw²,
/// Σ w_j w_(j+1), first and last w (NaN where empty).
#[pyfunction]
#[pyo3(signature = (x, mu, ms, dmax, workers))]
pub(crate) fn block_lag1_sums<'py>(
    py: Python<'py>,
    x: PyReadonlyArray1<'py, f64>,
    mu: f64,
    ms: Vec<usize>,
    dmax: usize,
    workers: usize,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let s = contiguous_one(py, &x)?;
    let values = run_interruptible(py, workers, |cancel| {
        allanite_core::block_acf::block_lag1_sums(s, mu, &ms, dmax, cancel)
    })?;
    to_3d(
        py,
        (ms.len(), dmax + 1, allanite_core::block_acf::STATS),
        values,
    )
}

/// Σ (X[i+2m] − 2X[i+m] + X[i])² in quanta² per plan item (m, i0, i1) and axis, X the exact angle of
/// the chunks given (rate samples (samples, axes) C-contiguous, each with its record start and exact
/// angle offset per axis: whole quanta and remainder), q = 2^q_exp: shape (items, axes). The kernel
/// of allanite.dask.avar (allanite-core `angle_term_sums_cancellable`).
#[pyfunction]
#[pyo3(signature = (blocks, starts, off_w, off_r, q_exp, plan, classic, workers))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn angle_term_sums<'py>(
    py: Python<'py>,
    blocks: Vec<PyReadonlyArray2<'py, f64>>,
    starts: Vec<usize>,
    off_w: Vec<Vec<i64>>,
    off_r: Vec<Vec<f64>>,
    q_exp: i32,
    plan: Vec<(usize, usize, usize)>,
    classic: bool,
    workers: usize,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let n = blocks.len();
    if starts.len() != n || off_w.len() != n || off_r.len() != n || n == 0 {
        return Err(parameter_error(
            py,
            format!(
                "{n} blocks, {} starts, {} and {} offsets: one of each per block is needed",
                starts.len(),
                off_w.len(),
                off_r.len()
            ),
        ));
    }
    let n_axes = blocks[0].as_array().ncols();
    let mut chunks = Vec::with_capacity(n);
    for (j, b) in blocks.iter().enumerate() {
        let y = b.as_slice().map_err(|_| {
            input_error(
                py,
                format!("block {j} is not a C-contiguous float64 (samples, axes) array"),
            )
        })?;
        if b.as_array().ncols() != n_axes {
            return Err(input_error(
                py,
                format!(
                    "block {j} has {} axes, block 0 has {n_axes}",
                    b.as_array().ncols()
                ),
            ));
        }
        chunks.push(AngleChunk {
            start: starts[j],
            y,
            off_w: &off_w[j],
            off_r: &off_r[j],
        });
    }
    let values = run_interruptible(py, workers, |cancel| {
        angle_term_sums_cancellable(&chunks, n_axes, q_exp, &plan, classic, cancel)
    })?;
    to_2d(py, plan.len(), n_axes, values)
}
