//! The noise-model fits in the core: every window's fit and `refine`'s reweighted NNLS of one curve on
//! many designs (allanite-core `fit`).

use crate::{c_slice, parameter_error, run_interruptible, to_2d};
use numpy::{
    PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3, PyUntypedArrayMethods,
};
use pyo3::prelude::*;

/// The noise-model fit of every window (allanite-core `fit::fit_windows`): `avar` (windows, n_tau) at
/// the fitted τ; what the windows share as in `fit::Problem` (covariance blocks flattened, absent for
/// the IRLS fit). Returns (windows, n_terms + n_terms² + 3): θ, covariance, χ², iterations, status.
#[pyfunction]
#[pyo3(signature = (avar, design, nu_terms, start_col, irls_iter, max_iter, gls_tol, irls_rtol, rho, log2_tau, s_blk, t_blk, stoch, ramp, workers))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn fit_windows<'py>(
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

/// The reweighted NNLS's failures as `scipy.optimize.nnls` raises them: ValueError for a non-finite
/// weighted problem, RuntimeError when the NNLS does not settle (`irls_curves` and `whittle_noise`).
fn fit_error(e: allanite_core::fit::curves::CurveFitError) -> PyErr {
    use allanite_core::fit::curves::CurveFitError;
    match e {
        CurveFitError::NonFinite => {
            pyo3::exceptions::PyValueError::new_err("array must not contain infs or NaNs")
        }
        CurveFitError::MaxIter => {
            pyo3::exceptions::PyRuntimeError::new_err("Maximum number of iterations reached.")
        }
    }
}

/// `refine`'s reweighted NNLS of one curve on many designs (allanite-core `fit::curves`): `design` and
/// `nu_cols` (designs, n_tau, n_cols), `y` and `nu0` (n_tau), `fixed` (n_cols: a held column's
/// coefficient, NaN for a fitted one). Returns θ (designs, n_cols) and ν (designs, n_tau). Errors as
/// `scipy.optimize.nnls`'s: ValueError for a non-finite weighted problem, RuntimeError when the NNLS
/// does not settle.
#[pyfunction]
#[pyo3(signature = (design, nu_cols, y, nu0, fixed, max_iter, floor, rtol))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
pub(crate) fn irls_curves<'py>(
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
    use allanite_core::fit::curves::{irls_curves as run, CurveDesigns};
    let shape = design.shape().to_vec();
    let (g_n, n, k) = (shape[0], shape[1], shape[2]);
    let (a, nc) = (
        c_slice(py, &design, "design")?,
        c_slice(py, &nu_cols, "nu_cols")?,
    );
    let (yv, nv, fv) = (
        c_slice(py, &y, "y")?,
        c_slice(py, &nu0, "nu0")?,
        c_slice(py, &fixed, "fixed")?,
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
    let (theta, nu) = py.detach(|| run(&p)).map_err(fit_error)?;
    Ok((to_2d(py, g_n, k, theta)?, to_2d(py, g_n, n, nu)?))
}

/// The Whittle noise fit's reweighted NNLS (allanite-core `fit::whittle`): `shapes` (bands, k) scaled
/// as Python scales them, `power`, `root_m` and the first pass's level `s_start` per band. Returns
/// (amounts, level per band). Errors as `scipy.optimize.nnls`'s: ValueError for a non-finite weighted
/// problem, RuntimeError when the NNLS does not settle. A fit is some tens of microseconds: the GIL
/// is kept, and Ctrl-C is seen between fits.
#[pyfunction]
#[pyo3(signature = (shapes, power, root_m, s_start, max_iter, rtol))]
#[allow(clippy::type_complexity)]
pub(crate) fn whittle_noise<'py>(
    py: Python<'py>,
    shapes: PyReadonlyArray2<'py, f64>,
    power: PyReadonlyArray1<'py, f64>,
    root_m: PyReadonlyArray1<'py, f64>,
    s_start: PyReadonlyArray1<'py, f64>,
    max_iter: usize,
    rtol: f64,
) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>)> {
    let (nb, k) = (shapes.shape()[0], shapes.shape()[1]);
    let a = c_slice(py, &shapes, "shapes")?;
    let (p, r, s) = (
        c_slice(py, &power, "power")?,
        c_slice(py, &root_m, "root_m")?,
        c_slice(py, &s_start, "s_start")?,
    );
    if p.len() != nb || r.len() != nb || s.len() != nb {
        return Err(parameter_error(
            py,
            format!("whittle_noise: power, root_m and s_start must have one value per band ({nb})"),
        ));
    }
    let (coef, level) = allanite_core::fit::whittle::whittle_noise(a, k, p, r, s, max_iter, rtol)
        .map_err(fit_error)?;
    Ok((PyArray1::from_vec(py, coef), PyArray1::from_vec(py, level)))
}
