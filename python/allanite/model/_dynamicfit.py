"""The noise-model fit of every window of a dynamic result: τ chosen on the windows' median curve, the windows
fitted all at once in the Rust core (:mod:`allanite.model._batched`, the iteration of
:func:`~allanite.model._fitcore.fit_core` step for step), a window it hands back refitted one at a time; flat
windows (a sensor not yet streaming) are not fitted.
"""

from __future__ import annotations

import numpy as np

from ..errors import ParameterError
from ..units import report_unit
from . import _batched, _covariance
from ._fitcore import (
    GLS_START_ITER,
    GLS_TOL,
    IRLS_RTOL,
    OCTAVE_CORRELATION,
    check_gls_size,
    edf_per_tau,
    exact_covariance_applies,
    fit_core,
)
from ._fitresult import CoefficientSeries, intervals
from ._tauselect import estimator_key, row_medians, select_taus
from .terms import TERM_ALPHA, design_matrix

#: A dynamic result's window is flat when every Allan variance in it is at most this share of the result's
#: largest (its rounding residue is ~1e-38 of it; a real noise level 10⁶ lower in amplitude is 1e-12).
FLAT_FLOOR = 1e-24


def fit_dynamic(result, terms, unit, confidence, zq, thin, max_iter, tau_range, progress=None):
    rows = [result.avar] if result.avar.ndim == 2 else list(result.avar)
    series = []
    for rows_avar in rows:
        # τ chosen on the windows' median curve: one flat window must not decide for all of them
        idx = select_taus(result.tau, row_medians(rows_avar), thin, len(terms), "the dynamic result", tau_range)
        y = np.ascontiguousarray(rows_avar[idx].T)  # windows × fitted τ
        bad = ~np.isfinite(y).all(axis=1)
        if bad.any():
            raise ParameterError(
                f"the dynamic result has a non-finite Allan variance in window {int(np.flatnonzero(bad)[0])}"
            )
        # a window whose samples are all equal (a sensor not yet streaming) has Allan variance 0; the core
        # returns its rounding residue, ~ε²·offset² (≈ 1e-38 of the record's largest value), not always an
        # exact 0: such a window is flat, not a fit (coefficients and intervals 0)
        finite = rows_avar[np.isfinite(rows_avar)]
        flat_floor = FLAT_FLOOR * (float(finite.max()) if finite.size else 0.0)
        fitted = ~np.all(y <= flat_floor, axis=1)
        theta, var, chi2 = np.zeros((y.shape[0], len(terms))), np.zeros((y.shape[0], len(terms))), np.zeros(y.shape[0])
        if fitted.any():
            fits = window_fits(result, idx, np.maximum(y[fitted], 1e-300), terms, confidence, max_iter, progress)
            theta[fitted], var[fitted], chi2[fitted] = fits
        chi = chi2 / np.maximum(1, idx.size - np.count_nonzero(theta > 0, axis=1))
        inflate = np.maximum(1.0, np.sqrt(chi))
        vals, lo, hi = {}, {}, {}
        for k, t in enumerate(terms):
            vals[t] = np.sqrt(theta[:, k])
            lo[t], hi[t] = intervals(theta[:, k], var[:, k], zq, inflate)
        ieee = ieee_units = None
        if unit is not None:
            ieee = {t: report_unit(t, vals[t], unit).value for t in terms}
            ieee_units = {t: report_unit(t, 1.0, unit).unit for t in terms}
        series.append(
            CoefficientSeries(
                t=result.t,
                terms=terms,
                values=vals,
                ci_low=lo,
                ci_high=hi,
                chi2_dof=chi,
                confidence=confidence,
                unit=unit,
                ieee=ieee,
                ieee_units=ieee_units,
            )
        )
    return series[0] if result.avar.ndim == 2 else series


def window_fits(result, idx, y, terms, confidence, max_iter, progress):
    """θ, the variance of each θ_k and χ² of every window (rows of ``y``, the estimates at τ[idx]): the
    per-window fit of :func:`fit_core`, run for all windows at once in the core; a window it hands back
    is refitted here."""
    tau, m, fs = result.tau[idx], result.m[idx].astype(np.float64), result.fs
    n_points, est = result.window + 1, estimator_key(result, idx)
    check_gls_size(est, m)
    gls = exact_covariance_applies(tau, m, fs, n_points, est)
    nu_terms = np.column_stack([edf_per_tau(np.full(m.size, TERM_ALPHA[t]), m, n_points, est) for t in terms])
    theta, cov, chi2, _, status = _batched.fit_windows(
        y,
        design_matrix(tau, tau * fs, fs, terms),
        nu_terms,
        start_col=terms.index("N") if "N" in terms else 0,
        irls_iter=GLS_START_ITER,
        max_iter=max_iter,
        gls_tol=GLS_TOL,
        irls_rtol=IRLS_RTOL,
        rho=[OCTAVE_CORRELATION[t] for t in terms],
        log2_tau=np.log2(tau),
        blocks=_covariance.covariance_blocks(m, n_points - 1, fs, terms) if gls else None,
        stoch=[k for k, t in enumerate(terms) if t in _covariance.KERNEL_TERMS],
        ramp=terms.index("R") if "R" in terms else None,
        progress=progress,
    )
    back = np.flatnonzero(status)
    if back.size:
        theta[back], cov[back], chi2[back] = window_fits_reference(result, idx, y[back], terms, confidence, max_iter)
    return theta, np.diagonal(cov, axis1=1, axis2=2), chi2


def window_fits_reference(result, idx, y, terms, confidence, max_iter):
    """θ, covariance and χ² of each row of ``y`` by :func:`fit_core`, one window at a time (the reference
    of the batched fit, and the fit of the windows it hands back)."""
    tau, m = result.tau[idx], result.m[idx].astype(np.float64)
    est, cache = estimator_key(result, idx), {}
    theta = np.empty((y.shape[0], len(terms)))
    cov = np.empty((y.shape[0], len(terms), len(terms)))
    chi2 = np.empty(y.shape[0])
    for j in range(y.shape[0]):
        out = fit_core(tau, m, y[j], result.fs, result.window + 1, est, terms, confidence, max_iter, edf_cache=cache)
        theta[j], cov[j], chi2[j] = out[0], out[1], out[7]
    return theta, cov, chi2
