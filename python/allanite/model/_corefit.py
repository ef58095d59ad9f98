"""One curve's noise-model fit in the Rust core: :func:`fit_curve` is :func:`~allanite.model._fitcore.fit_core`
(same arguments, same eight results) run by the core's per-window kernel (:mod:`allanite.model._batched`, the
iteration of ``fit_core`` step for step) on a single row.

The core returns θ, its covariance, χ² and the passes made; the model, the EDF and the normalised residuals of
each τ follow from θ here, as ``fit_core`` forms them at its end: for the generalized least squares from the
diagonal of the estimates' covariance Σ(θ) (with the independent-weights start's ν where a bare ramp leaves Σ
without variance — that start is one more core call, the same passes), for the independent-weights fit from
the mixture's EDF. A fit the core hands back (an indefinite Σ, a fit at θ = 0, an NNLS that does not settle)
and estimates below 1e-300 (which the core floors) are fitted by ``fit_core`` itself. ``tests/test_core_fit.py``
checks the two paths agree within 10 × ``GLS_TOL``.
"""

from __future__ import annotations

import math

import numpy as np

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
    scale_for_gaps,
)
from ._recent import Suffixes
from .terms import TERM_ALPHA, design_matrix

__all__ = ["fit_curve"]


def fit_curve(tau, m, avar, fs, n_points, estimator, terms, confidence, max_iter=50, edf_cache=None, *, share=None):
    """:func:`~allanite.model._fitcore.fit_core` in the core: theta, covariance, model, edf, z, iterations,
    design, χ². ``share``: per τ, the share of a gapless record's terms the estimate averages (a record with
    gaps), its EDF scaled by it and its covariance by 1/√(share_i·share_j) (:func:`scale_for_gaps`)."""
    check_gls_size(estimator, m)
    y = np.asarray(avar, dtype=np.float64)
    if not (np.all(np.isfinite(y)) and np.all(y >= 1e-300)):
        return fit_core(tau, m, avar, fs, n_points, estimator, terms, confidence, max_iter, edf_cache, share=share)
    terms = tuple(terms)
    a = design_matrix(tau, tau * fs, fs, terms)
    nu_terms = _nu_terms(m, n_points, estimator, terms, edf_cache)
    gls = exact_covariance_applies(tau, m, fs, n_points, estimator)
    blocks = _covariance.covariance_blocks(m, int(n_points) - 1, fs, terms) if gls else None
    nu_terms, blocks = scale_for_gaps(share, nu_terms, blocks)
    shared = dict(
        start_col=terms.index("N") if "N" in terms else 0,
        irls_iter=GLS_START_ITER,
        gls_tol=GLS_TOL,
        irls_rtol=IRLS_RTOL,
        rho=[OCTAVE_CORRELATION[t] for t in terms],
        log2_tau=np.log2(tau),
        stoch=[k for k, t in enumerate(terms) if t in _covariance.KERNEL_TERMS],
        ramp=terms.index("R") if "R" in terms else None,
        progress=False,
        workers=1,  # one row: a pool of one thread starts soonest
    )
    theta, cov, chi2, it, status = _batched.fit_windows(
        y[None], a, nu_terms, max_iter=max_iter, blocks=blocks, **shared
    )
    theta, cov = theta[0], cov[0]
    if status[0] != 0 or not theta.any():
        return fit_core(tau, m, avar, fs, n_points, estimator, terms, confidence, max_iter, edf_cache, share=share)
    # fit_core's own scaling (a power of two near the peak: exact), so that Σ(θ) neither under- nor overflows
    peak = float(np.max(y))
    scale = math.ldexp(1.0, math.frexp(peak)[1])
    ys, th = y / scale, theta / scale
    model = np.maximum(a @ th, 1e-12 * np.max(ys))
    if blocks is None:
        nu = _mixture_edf(a * th, nu_terms)
        z = (ys - model) * np.sqrt(nu / (2.0 * model**2))
    else:
        # the start's ν (a bare ramp's variance): the independent-weights passes alone, as fit_core starts
        start = _batched.fit_windows(
            y[None], a, nu_terms, max_iter=min(max_iter, GLS_START_ITER), blocks=None, **shared
        )[0][0]
        var = _sigma_diagonal(blocks, th, terms)
        indep = 2.0 * model**2 / _mixture_edf(a * (start / scale), nu_terms)
        var = var + np.where(~(var > 1e-6 * indep), indep, 0.0)
        sd = np.sqrt(var)
        z = (ys - model) / sd
        nu = 2.0 * model**2 / sd**2
    return theta, cov, model * scale, nu, z, int(it[0]), a, float(chi2[0])


def _nu_terms(m, n_points, estimator, terms, edf_cache) -> np.ndarray:
    """EDF of each term's noise type at every τ (τ × terms), remembered in ``edf_cache`` as ``fit_core`` does,
    and for the last few (α, m, n, estimator) here: ``tau_range="auto"`` fits the same curve with its shortest τ
    cut one at a time, and each τ's EDF depends on its own averaging factor only (a suffix is sliced)."""
    cache = {} if edf_cache is None else edf_cache
    cols = []
    for t in terms:
        key = (TERM_ALPHA[t], tuple(m), n_points, estimator)
        if key not in cache:
            cache[key] = _recent_edf(key)
        cols.append(cache[key])
    return np.column_stack(cols)


def _recent_edf(key) -> np.ndarray:
    alpha, m, n_points, estimator = key
    rest = (alpha, n_points, estimator)
    hit = _RECENT_EDF.find(m, rest) if isinstance(estimator, str) else None
    if hit is not None:
        nu, k = hit
        return nu[k:]
    nu = edf_per_tau(np.full(len(m), alpha), np.asarray(m, dtype=np.float64), n_points, estimator)
    nu.flags.writeable = False
    return _RECENT_EDF.put(m, rest, nu)


#: The EDF columns last computed, by (α, m, n, estimator); where a request's m ends one, it is sliced from it.
_RECENT_EDF = Suffixes(16)


def _mixture_edf(parts: np.ndarray, nu_terms: np.ndarray) -> np.ndarray:
    """ν of a mixture of independent noises: (Σ s_k)² / Σ s_k²/ν_k (``_fit_irls``'s ``edf_of``)."""
    tot = parts.sum(axis=1)
    den = np.sum(parts**2 / nu_terms, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(den > 0, tot**2 / den, nu_terms[:, 0])


def _sigma_diagonal(blocks, theta: np.ndarray, terms) -> np.ndarray:
    """The diagonal of Σ(θ) (:func:`allanite.model._covariance.assemble`) without forming Σ."""
    s_blk, t_blk = blocks
    stoch = [k for k, t in enumerate(terms) if t in _covariance.KERNEL_TERMS]
    th = theta[stoch]
    s_diag = np.diagonal(s_blk, axis1=2, axis2=3)  # (p, q, τ)
    var = np.einsum("p,q,pqi->i", th, th, s_diag)
    if "R" in terms:
        var = var + float(theta[terms.index("R")]) * np.einsum("p,pi->i", th, np.diagonal(t_blk, axis1=1, axis2=2))
    return var
