//! The `allanite._core` extension module: numpy in, numpy out, GIL released around the work.
//! Nothing else lives here — validation with friendly messages happens in Python, the arithmetic in
//! allanite-core, and core errors come back as the matching `allanite.errors` class (`InputError`,
//! `ParameterError`; both ValueErrors).
//!
//! Every long call goes through [`run_interruptible`], so Ctrl-C stops it: a kernel takes a
//! `&Cancel` (see allanite_core::cancel) and the binding calls it as
//! `run_interruptible(py, workers, |cancel| kernel_cancellable(..., cancel))`.

use allanite_core::dynamic_hann_cancellable;
use allanite_core::phase_terms::{self, TermSum};
use allanite_core::streaming::{Stream, StreamKind};
use allanite_core::text;
use allanite_core::{angle_term_sums_cancellable, AngleChunk};
use allanite_core::{
    compensated_sum_from, dynamic_avar_part_cancellable, dynamic_avar_ranged_cancellable,
};
use allanite_core::{
    deviations, dynamic_avar_cancellable, dynamic_theo1_cancellable, run_in_pool_interruptible,
    static_theo1_cancellable, Cancel, CoreError, Estimator, Method, Request,
};
use numpy::ndarray::{Array2, Array3};
use numpy::{
    Element, IntoPyArray, PyArray1, PyArray2, PyArray3, PyReadonlyArray1, PyReadonlyArray2,
    PyReadonlyArray3, PyUntypedArrayMethods,
};
use pyo3::prelude::*;
use std::time::Duration;

mod phase_grid;

/// How often the calling thread looks for a pending signal while the workers run: often enough
/// for Ctrl-C to land well within a second, rarely enough that taking the GIL costs nothing.
const SIGNAL_POLL: Duration = Duration::from_millis(50);

/// `allanite.errors.<class_name>(msg)`; falls back to ValueError if the package is absent.
fn allanite_error_of(py: Python<'_>, class_name: &str, msg: String) -> PyErr {
    let made = py
        .import("allanite.errors")
        .and_then(|m| m.getattr(class_name))
        .and_then(|cls| cls.call1((msg.clone(),)));
    match made {
        Ok(instance) => PyErr::from_value(instance),
        Err(_) => pyo3::exceptions::PyValueError::new_err(msg),
    }
}

/// Raises `allanite.errors.AllaniteError(msg)`; falls back to ValueError if the package is absent.
fn allanite_error(py: Python<'_>, msg: String) -> PyErr {
    allanite_error_of(py, "AllaniteError", msg)
}

/// `allanite.errors.ParameterError(msg)`: a bad argument.
fn parameter_error(py: Python<'_>, msg: String) -> PyErr {
    allanite_error_of(py, "ParameterError", msg)
}

/// `allanite.errors.InputError(msg)`: bad samples.
fn input_error(py: Python<'_>, msg: String) -> PyErr {
    allanite_error_of(py, "InputError", msg)
}

/// Each core error as its `allanite.errors` class, message unchanged.
fn core_error(py: Python<'_>, e: CoreError) -> PyErr {
    let class_name = match &e {
        CoreError::TooShort { .. } | CoreError::NonFinite { .. } | CoreError::InvalidInput(_) => {
            "InputError"
        }
        CoreError::InvalidParameter(_) => "ParameterError",
        CoreError::Cancelled => {
            return pyo3::exceptions::PyKeyboardInterrupt::new_err(e.to_string());
        }
    };
    allanite_error_of(py, class_name, e.to_string())
}

/// Runs a core kernel on `workers` rayon threads (0: rayon's default) with the GIL released, and
/// makes it interruptible: while the workers run, this thread takes the GIL every `SIGNAL_POLL`
/// to run Python's signal handlers (`check_signals`; a no-op off the main thread). If a handler
/// raises (Ctrl-C: KeyboardInterrupt), the kernel's `Cancel` flag is set, the workers are waited
/// for (they stop at their next check), and the handler's exception is returned. Core errors come
/// back as their `allanite.errors` classes.
///
/// Every kernel of this module goes through here: `job` receives the flag and passes it on.
fn run_interruptible<R: Send>(
    py: Python<'_>,
    workers: usize,
    job: impl FnOnce(&Cancel) -> allanite_core::Result<R> + Send,
) -> PyResult<R> {
    let outcome = py.detach(|| {
        run_in_pool_interruptible(workers, SIGNAL_POLL, job, || {
            Python::attach(|py| py.check_signals())
        })
    })?;
    outcome.map_err(|e| core_error(py, e))
}

/// `values` (row-major) as a (rows, cols) numpy array.
fn to_2d<'py, T: Element>(
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
fn to_3d<'py, T: Element>(
    py: Python<'py>,
    shape: (usize, usize, usize),
    values: Vec<T>,
) -> PyResult<Bound<'py, PyArray3<T>>> {
    let arr = Array3::from_shape_vec(shape, values)
        .map_err(|e| allanite_error(py, format!("internal shape error: {e}")))?;
    Ok(arr.into_pyarray(py))
}

/// Term counts as int64, numpy's index type.
fn as_i64(counts: Vec<u64>) -> Vec<i64> {
    counts.into_iter().map(|c| c as i64).collect()
}

fn parse_estimator(py: Python<'_>, s: &str) -> PyResult<Estimator> {
    match s {
        "oavar" => Ok(Estimator::Overlapping),
        "avar" => Ok(Estimator::Classic),
        other => Err(parameter_error(
            py,
            format!("unknown estimator {other:?}; allowed: 'oavar', 'avar'"),
        )),
    }
}

fn parse_method(py: Python<'_>, s: &str) -> PyResult<Method> {
    match s {
        "fast" => Ok(Method::Fast),
        "naive" => Ok(Method::Naive),
        other => Err(parameter_error(
            py,
            format!("unknown method {other:?}; allowed: 'fast', 'naive'"),
        )),
    }
}

/// The arguments every dynamic Allan call shares, checked in this order: the estimator, the method,
/// then every axis contiguous.
fn dynamic_args<'a>(
    py: Python<'_>,
    columns: &'a [PyReadonlyArray1<'_, f64>],
    estimator: &str,
    method: &str,
) -> PyResult<(Vec<&'a [f64]>, Estimator, Method)> {
    let estimator = parse_estimator(py, estimator)?;
    let method = parse_method(py, method)?;
    Ok((contiguous(py, columns)?, estimator, method))
}

/// The core's request of a dynamic call.
fn request<'a>(
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
fn davar<'py>(
    py: Python<'py>,
    columns: Vec<PyReadonlyArray1<'py, f64>>,
    window: usize,
    hop: usize,
    ms: Vec<usize>,
    estimator: &str,
    method: &str,
    workers: usize,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let (slices, estimator, method) = dynamic_args(py, &columns, estimator, method)?;
    let req = request(&slices, window, hop, &ms, estimator, method);
    let (values, n_win) =
        run_interruptible(py, workers, |cancel| dynamic_avar_cancellable(&req, cancel))?;
    to_3d(py, (slices.len(), ms.len(), n_win), values)
}

/// [`davar`] and the range of every (axis, m) row of the result: (values, ranges), ranges of shape
/// (axes, len(ms), 3) holding each row's largest value, smallest value and 1.0 where a value is not
/// finite (allanite-core `dynamic_avar_ranged_cancellable`; the rows of a hop-1 surface are noted while
/// in cache, so that the caller's range check need not read the surface again).
#[pyfunction]
#[pyo3(signature = (columns, window, hop, ms, estimator, method, workers))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn davar_ranged<'py>(
    py: Python<'py>,
    columns: Vec<PyReadonlyArray1<'py, f64>>,
    window: usize,
    hop: usize,
    ms: Vec<usize>,
    estimator: &str,
    method: &str,
    workers: usize,
) -> PyResult<(Bound<'py, PyArray3<f64>>, Bound<'py, PyArray3<f64>>)> {
    let (slices, estimator, method) = dynamic_args(py, &columns, estimator, method)?;
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
fn davar_part<'py>(
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
    let (slices, estimator, method) = dynamic_args(py, &columns, estimator, method)?;
    let req = request(&slices, window, hop, &ms, estimator, method);
    let (values, n_win) = run_interruptible(py, workers, |cancel| {
        dynamic_avar_part_cancellable(&req, &mus, first_window, n_windows, cancel)
    })?;
    to_3d(py, (slices.len(), ms.len(), n_win), values)
}

/// Samples between the places a record of `n` samples × `n_axes` may be cut into [`davar_part`] parts
/// that give the whole call's values bit for bit: the hop where the call streams its sums, a phase
/// segment's windows × hop on its phase path (allanite-core `part_grid`). For allanite.dask's chunks.
#[pyfunction]
#[pyo3(signature = (n, n_axes, window, hop, estimator, method))]
fn part_grid(
    py: Python<'_>,
    n: usize,
    n_axes: usize,
    window: usize,
    hop: usize,
    estimator: &str,
    method: &str,
) -> PyResult<usize> {
    let estimator = parse_estimator(py, estimator)?;
    let method = parse_method(py, method)?;
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

/// Neumaier's compensated sum of each column continued from `state` ((sum, compensation) per axis):
/// the new state per axis. Fed a record's parts in order, it ends at the state whose (s + c) / n is
/// the core's centring value of the whole record, bit for bit (allanite-core `compensated_sum_from`).
#[pyfunction]
#[pyo3(signature = (columns, state))]
fn compensated_sums(
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
fn block_lag1_sums<'py>(
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
fn angle_term_sums<'py>(
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

/// Hann-weighted overlapping Allan variance of every window at every averaging factor, for every
/// axis (paper 002; docs/FORMULAS.md §10): shape (axes, len(ms), windows). `window == len(record)`
/// gives the static estimator. Every m must leave M = window + 1 − 2m ≥ 3 terms.
#[pyfunction]
#[pyo3(signature = (columns, window, hop, ms, method, workers))]
fn davar_hann<'py>(
    py: Python<'py>,
    columns: Vec<PyReadonlyArray1<'py, f64>>,
    window: usize,
    hop: usize,
    ms: Vec<usize>,
    method: &str,
    workers: usize,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let method = parse_method(py, method)?;
    let slices = contiguous(py, &columns)?;
    let req = request(&slices, window, hop, &ms, Estimator::Overlapping, method);
    let (values, n_win) =
        run_interruptible(py, workers, |cancel| dynamic_hann_cancellable(&req, cancel))?;
    to_3d(py, (slices.len(), ms.len(), n_win), values)
}

/// The noise-model fit of every window (allanite-core `fit::fit_windows`): `avar` (windows, n_tau) at
/// the fitted τ; what the windows share as in `fit::Problem` (covariance blocks flattened, absent for
/// the IRLS fit). Returns (windows, n_terms + n_terms² + 3): θ, covariance, χ², iterations, status.
#[pyfunction]
#[pyo3(signature = (avar, design, nu_terms, start_col, irls_iter, max_iter, gls_tol, irls_rtol, rho, log2_tau, s_blk, t_blk, stoch, ramp, workers))]
#[allow(clippy::too_many_arguments)]
fn fit_windows<'py>(
    py: Python<'py>,
    avar: PyReadonlyArray2<'py, f64>,
    design: PyReadonlyArray2<'py, f64>,
    nu_terms: PyReadonlyArray2<'py, f64>,
    start_col: usize,
    irls_iter: usize,
    max_iter: usize,
    gls_tol: f64,
    irls_rtol: f64,
    rho: Vec<f64>,
    log2_tau: Vec<f64>,
    s_blk: Option<PyReadonlyArray1<'py, f64>>,
    t_blk: Option<PyReadonlyArray1<'py, f64>>,
    stoch: Vec<usize>,
    ramp: Option<usize>,
    workers: usize,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (y, a, nu) = (
        c_slice(py, &avar, "avar")?,
        c_slice(py, &design, "design")?,
        c_slice(py, &nu_terms, "nu_terms")?,
    );
    let blocks = match (&s_blk, &t_blk) {
        (Some(s), Some(t)) => Some((s.as_slice()?, t.as_slice()?)),
        _ => None,
    };
    let (n_tau, n_terms) = (design.shape()[0], design.shape()[1]);
    let problem = allanite_core::fit::Problem {
        n_tau,
        n_terms,
        design: a,
        nu_terms: nu,
        start_col,
        irls_iter,
        max_iter,
        gls_tol,
        irls_rtol,
        rho: &rho,
        log2_tau: &log2_tau,
        gls: blocks.map(|(s, t)| allanite_core::fit::Gls {
            s_blk: s,
            t_blk: t,
            stoch: &stoch,
            ramp,
        }),
    };
    let n_windows = avar.shape()[0];
    let values = run_interruptible(py, workers, |cancel| {
        allanite_core::fit::fit_windows(&problem, y, cancel)
    })?;
    let width = allanite_core::fit::record_width(n_terms);
    to_2d(py, n_windows, width, values)
}

/// `refine`'s reweighted NNLS of one curve on many designs (allanite-core `fit::curves`): `design` and
/// `nu_cols` (designs, n_tau, n_cols), `y` and `nu0` (n_tau), `fixed` (n_cols: a held column's
/// coefficient, NaN for a fitted one). Returns θ (designs, n_cols) and ν (designs, n_tau). Errors as
/// `scipy.optimize.nnls`'s: ValueError for a non-finite weighted problem, RuntimeError when the NNLS
/// does not settle.
#[pyfunction]
#[pyo3(signature = (design, nu_cols, y, nu0, fixed, max_iter, floor, rtol))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn irls_curves<'py>(
    py: Python<'py>,
    design: PyReadonlyArray3<'py, f64>,
    nu_cols: PyReadonlyArray3<'py, f64>,
    y: PyReadonlyArray1<'py, f64>,
    nu0: PyReadonlyArray1<'py, f64>,
    fixed: PyReadonlyArray1<'py, f64>,
    max_iter: usize,
    floor: f64,
    rtol: f64,
) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>)> {
    use allanite_core::fit::curves::{irls_curves as run, CurveDesigns, CurveFitError};
    let shape = design.shape().to_vec();
    let (g_n, n, k) = (shape[0], shape[1], shape[2]);
    let contiguous =
        |what: &str| parameter_error(py, format!("{what} must be a C-contiguous float64 array"));
    let (a, nc) = (
        design.as_slice().map_err(|_| contiguous("design"))?,
        nu_cols.as_slice().map_err(|_| contiguous("nu_cols"))?,
    );
    let (yv, nv, fv) = (
        y.as_slice().map_err(|_| contiguous("y"))?,
        nu0.as_slice().map_err(|_| contiguous("nu0"))?,
        fixed.as_slice().map_err(|_| contiguous("fixed"))?,
    );
    if nu_cols.shape() != shape.as_slice() || yv.len() != n || nv.len() != n || fv.len() != k {
        return Err(parameter_error(
            py,
            format!("irls_curves: nu_cols must be shaped as design {shape:?}, y and nu0 of {n} τ, fixed of {k} columns"),
        ));
    }
    let p = CurveDesigns {
        n_designs: g_n,
        n_tau: n,
        n_cols: k,
        design: a,
        nu_cols: nc,
        y: yv,
        nu0: nv,
        fixed: fv,
        max_iter,
        floor,
        rtol,
    };
    let (theta, nu) = py.detach(|| run(&p)).map_err(|e| match e {
        CurveFitError::NonFinite => {
            pyo3::exceptions::PyValueError::new_err("array must not contain infs or NaNs")
        }
        CurveFitError::MaxIter => {
            pyo3::exceptions::PyRuntimeError::new_err("Maximum number of iterations reached.")
        }
    })?;
    Ok((to_2d(py, g_n, k, theta)?, to_2d(py, g_n, n, nu)?))
}

fn c_slice<'a>(
    py: Python<'_>,
    a: &'a PyReadonlyArray2<'_, f64>,
    what: &str,
) -> PyResult<&'a [f64]> {
    a.as_slice()
        .map_err(|_| parameter_error(py, format!("{what} must be a C-contiguous float64 array")))
}

fn contiguous<'a>(
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
fn contiguous_one<'a>(py: Python<'_>, a: &'a PyReadonlyArray1<'_, f64>) -> PyResult<&'a [f64]> {
    Ok(contiguous(py, std::slice::from_ref(a))?[0])
}

/// Theo1 of each whole rate record at every (even) averaging factor: shape (axes, len(ms)).
#[pyfunction]
#[pyo3(signature = (columns, ms, workers))]
fn theo1_static<'py>(
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
fn theo1_dynamic<'py>(
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

fn parse_kind(py: Python<'_>, s: &str, allowed: &[&str]) -> PyResult<deviations::Kind> {
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
fn deviation_static<'py>(
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
    let slices = contiguous(py, &columns)?;
    let values = run_interruptible(py, workers, |cancel| {
        deviations::static_deviation_cancellable(&slices, &ms, kind, cancel)
    })?;
    to_2d(py, slices.len(), ms.len(), values)
}

/// Time total variance (τ²/3)·MTOTVAR, τ = m·tau0, of each rate record: shape (axes, len(ms)).
#[pyfunction]
#[pyo3(signature = (columns, ms, tau0, workers))]
fn ttotvar_static<'py>(
    py: Python<'py>,
    columns: Vec<PyReadonlyArray1<'py, f64>>,
    ms: Vec<usize>,
    tau0: f64,
    workers: usize,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let slices = contiguous(py, &columns)?;
    let values = run_interruptible(py, workers, |cancel| {
        deviations::static_ttotvar_cancellable(&slices, &ms, tau0, cancel)
    })?;
    to_2d(py, slices.len(), ms.len(), values)
}

/// Gap-aware OAVAR/MVAR/OHVAR (and classic AVAR/HVAR: "avar", "hvar") of rate records with NaN-marked gaps: (values, counts), each of
/// shape (axes, len(ms)); counts (int64) are the complete terms used; no term gives NaN, 0.
#[pyfunction]
#[pyo3(signature = (columns, ms, estimator, workers))]
#[allow(clippy::type_complexity)]
fn deviation_gaps<'py>(
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
fn ohvar_dynamic<'py>(
    py: Python<'py>,
    columns: Vec<PyReadonlyArray1<'py, f64>>,
    window: usize,
    hop: usize,
    ms: Vec<usize>,
    workers: usize,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let slices = contiguous(py, &columns)?;
    let (values, n_win) = run_interruptible(py, workers, |_cancel| {
        deviations::dynamic_ohvar(&slices, window, hop, &ms)
    })?;
    to_3d(py, (slices.len(), ms.len(), n_win), values)
}

/// (values, counts) of a gap-aware whole-record estimate.
type ValuesCounts2<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<i64>>);

/// (values, counts) of a gap-aware sliding-window estimate.
type ValuesCounts3<'py> = (Bound<'py, PyArray3<f64>>, Bound<'py, PyArray3<i64>>);

/// Gap-aware OAVAR or OHVAR of every sliding window (NaN marks a missing rate sample): values and
/// complete-term counts, each of shape (axes, len(ms), windows).
#[pyfunction]
#[pyo3(signature = (columns, window, hop, ms, estimator, workers))]
fn deviation_gaps_dynamic<'py>(
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
fn tie_gaps<'py>(
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
fn mtie_phase<'py>(
    py: Python<'py>,
    columns: Vec<PyReadonlyArray1<'py, f64>>,
    ms: Vec<usize>,
    workers: usize,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let slices = contiguous(py, &columns)?;
    let values = run_interruptible(py, workers, |_cancel| deviations::mtie(&slices, &ms))?;
    to_2d(py, slices.len(), ms.len(), values)
}

/// TIE rms of each *phase* record: shape (axes, len(ms)).
#[pyfunction]
#[pyo3(signature = (columns, ms, workers))]
fn tierms_phase<'py>(
    py: Python<'py>,
    columns: Vec<PyReadonlyArray1<'py, f64>>,
    ms: Vec<usize>,
    workers: usize,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let slices = contiguous(py, &columns)?;
    let values = run_interruptible(py, workers, |_cancel| deviations::tie_rms(&slices, &ms))?;
    to_2d(py, slices.len(), ms.len(), values)
}

/// (sums, counts) of a phase-domain term kernel as two float64/int64 arrays.
fn term_sums<'py>(
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
fn pvar_phase<'py>(
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
fn allan_covariance_phase<'py>(
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
fn oavar_phase_gaps<'py>(
    py: Python<'py>,
    phase: PyReadonlyArray1<'py, f64>,
    ms: Vec<usize>,
    workers: usize,
) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<i64>>)> {
    let x = contiguous_one(py, &phase)?;
    let sums = run_interruptible(py, workers, |_c| phase_terms::oavar_phase_gap_sums(x, &ms))?;
    Ok(term_sums(py, sums))
}

/// A streaming overlapping Allan ("oavar"), overlapping Hadamard ("ohvar") or time ("tvar")
/// variance of a growing phase record: push points, read the values (τ0 = 1) at every averaging
/// factor. `pending`: factors added automatically (each at 2m + 1 points), increasing.
#[pyclass(module = "allanite._core")]
struct StreamingVariance {
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

/// The columns `cols` (sorted) of the data lines of `text[offset:]` as a (rows, len(cols)) array, or
/// None where a line is outside the fast path's grammar (allanite-core `text::parse_decimal_table`:
/// plain decimal numbers, `delimiter` one ASCII character or None for whitespace). The caller then
/// reads the text the slow way, which names the problem.
#[pyfunction]
#[pyo3(signature = (text, offset, delimiter, ncols, cols))]
fn parse_decimal_table<'py>(
    py: Python<'py>,
    text: &[u8],
    offset: usize,
    delimiter: Option<char>,
    ncols: usize,
    cols: Vec<usize>,
) -> PyResult<Option<Bound<'py, PyArray2<f64>>>> {
    let delim = match delimiter {
        None => None,
        Some(c) if c.is_ascii() => Some(c as u8),
        Some(_) => return Ok(None),
    };
    let body = text.get(offset..).unwrap_or(&[]);
    let parsed = py.detach(|| text::parse_decimal_table(body, delim, ncols, &cols));
    let Some((values, rows)) = parsed else {
        return Ok(None);
    };
    let arr = Array2::from_shape_vec((rows, cols.len()), values)
        .map_err(|e| allanite_error(py, format!("parse_decimal_table: {e}")))?;
    Ok(Some(arr.into_pyarray(py)))
}

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(davar, m)?)?;
    m.add_function(wrap_pyfunction!(davar_ranged, m)?)?;
    m.add_function(wrap_pyfunction!(davar_hann, m)?)?;
    m.add_function(wrap_pyfunction!(fit_windows, m)?)?;
    m.add_function(wrap_pyfunction!(irls_curves, m)?)?;
    m.add_function(wrap_pyfunction!(phase_grid::phase_bins, m)?)?;
    m.add_function(wrap_pyfunction!(phase_grid::add_waveform, m)?)?;
    m.add_function(wrap_pyfunction!(davar_part, m)?)?;
    m.add_function(wrap_pyfunction!(part_grid, m)?)?;
    m.add_function(wrap_pyfunction!(compensated_sums, m)?)?;
    m.add_function(wrap_pyfunction!(block_lag1_sums, m)?)?;
    m.add_function(wrap_pyfunction!(parse_decimal_table, m)?)?;
    m.add_function(wrap_pyfunction!(angle_term_sums, m)?)?;
    m.add_function(wrap_pyfunction!(theo1_static, m)?)?;
    m.add_function(wrap_pyfunction!(theo1_dynamic, m)?)?;
    m.add_function(wrap_pyfunction!(deviation_static, m)?)?;
    m.add_function(wrap_pyfunction!(ttotvar_static, m)?)?;
    m.add_function(wrap_pyfunction!(deviation_gaps, m)?)?;
    m.add_function(wrap_pyfunction!(ohvar_dynamic, m)?)?;
    m.add_function(wrap_pyfunction!(deviation_gaps_dynamic, m)?)?;
    m.add_function(wrap_pyfunction!(tie_gaps, m)?)?;
    m.add_function(wrap_pyfunction!(mtie_phase, m)?)?;
    m.add_function(wrap_pyfunction!(tierms_phase, m)?)?;
    m.add_function(wrap_pyfunction!(pvar_phase, m)?)?;
    m.add_function(wrap_pyfunction!(allan_covariance_phase, m)?)?;
    m.add_function(wrap_pyfunction!(oavar_phase_gaps, m)?)?;
    m.add_class::<StreamingVariance>()?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
