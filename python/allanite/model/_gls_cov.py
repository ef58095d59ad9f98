"""The covariance a channel regression's intervals use (:mod:`allanite.model.channels`): the GLS coefficients'
error under the record's noise, where the noise fitted beside them is not taken as known.

Two things made the inverse Fisher information ``(2·Σ_b Re G_b/S_b)⁻¹`` at the fitted noise too small
(``benches/results/channel_interval_coverage.md``):

- *The noise beside the coefficients is fitted on their residual.* The coefficients take their own share of the
  power from the bands they are read in — one real degree of freedom each, half a complex bin —, and the noise
  model refitted on the residual lies that much low there: a channel cycling three times over the record puts
  its information in one or two bins, where the record's random walk or flicker level is set by a few bins, and
  the noise fitted beside a coupling through a 600 s lag read 0.87× (±0.02) of the noise-only fit in the cycle's
  band (0.83× at 300 s). It is the maximum-likelihood variance's bias (RSS/n where OLS divides by n − p), and the
  cure is the same — a restricted estimate: the noise refitted on the residual powers with what the coefficients
  took from each band given back, ``R_b + h_b·S_b``, ``h_b = tr(A⁻¹·Re G_b)/(2·S_b)`` the band's leverage (Σ_b
  h_b = p/2 complex bins), A = Σ_b Re G_b/S_b (:func:`restricted_noise`: 1.05× and 0.99× of the noise-only fit).
- *Whittle's bins are not independent at the record's edges* (:mod:`allanite.model._edge`): a channel that
  swings once lines up with the coherent term the differenced noise's ends leave in the lowest bins, and its
  score's variance was 1.5× (median; up to 3.5×) the ``½·Σ|Z|²/S`` the law gives it.

The covariance is the sandwich ``A⁻¹·E·A⁻¹``: A the estimator's own normal matrix (its weights 1/S at the fitted
noise — the point estimate is unchanged), E the exact covariance of its score u = Σ_b Re(Z̄_b·D_b)/S_b under the
restricted noise (:func:`allanite.model._edge.score_covariances`; Whittle's ``½·Σ Re G_b·P_b/S_b²`` where the bands
carry no regressors in time). Where the bins are independent and the noise is the fitted one, it is the inverse
Fisher information. The t quantile's ν stays the Satterthwaite count of the noise fit's own spread
(:func:`allanite.model._whittle.noise_dof`).
"""

from __future__ import annotations

import numpy as np

from . import _whittle as wh
from ._edge import score_covariances

__all__ = ["leverage", "restricted_noise", "interval_cov"]

#: Fixed-point steps of the restricted noise (each a warm-started noise fit); it settles in 3–5.
RESTRICTED_STEPS = 12


def leverage(bands: wh.Bands, design: wh.Design, s: np.ndarray) -> np.ndarray:
    """Per band, the share of a complex bin the GLS coefficients of ``design`` (weights 1/``s``) take from the
    residual in expectation, h_b = tr(A⁻¹·Re G_b)/(2·s_b); Σ_b h_b = p/2."""
    a_inv = np.linalg.inv(design.gram(bands, 1.0 / s)[0])
    h = np.zeros(bands.m.size)
    for i in range(len(design)):
        for j in range(len(design)):
            g = (np.conj(design.mult[i]) * design.mult[j] * bands.G[:, design.src[i], design.src[j]]).real
            h += a_inv[j, i] * g
    return np.maximum(h, 0.0) / (2.0 * s)


def restricted_noise(bands: wh.Bands, design: wh.Design, fit: dict) -> dict:
    """The noise refitted with the power the coefficients took given back: S the fixed point of the noise fit to
    ``R_b(ĉ) + h_b·S_b`` (:func:`leverage` at ``fit``'s noise, the estimator's weights). ``fit`` carries ``c`` (over
    ``design``'s first regressors; any further ones, a direction beside them, at 0), ``s`` and ``amounts``.
    Returns ``{"s", "amounts"}``; the own bands' levels are the record's (they are never refitted)."""
    s0 = np.asarray(fit["s"], dtype=np.float64)
    if not bands.par.any() or len(design) == 0:
        return {"s": s0, "amounts": fit.get("amounts")}
    c = np.zeros(len(design))
    c[: np.size(fit["c"])] = fit["c"]
    resid = wh.residual_power(bands, design, c)
    h = leverage(bands, design, s0)
    s, amounts = s0, fit.get("amounts")
    for _ in range(RESTRICTED_STEPS):
        s_new, amounts = wh.noise_psd(bands, resid + h * s, amounts)
        done = bool(np.max(np.abs(s_new / s - 1.0)) < 1e-6)
        s = s_new
        if done:
            break
    return {"s": s, "amounts": amounts}


def interval_cov(bands: wh.Bands, design: wh.Design, fit: dict, exact: bool = True) -> tuple[np.ndarray, dict]:
    """The coefficients' covariance for their intervals (module docstring): ``A⁻¹·E·A⁻¹`` at ``fit``'s weights,
    E the score's covariance under :func:`restricted_noise` — exact in time where ``bands`` carries an
    :class:`allanite.model._edge.EdgeSource`, Whittle's law otherwise. Returns (the covariance, the restricted
    noise). ``exact=False``: Whittle's law even where ``bands`` carries a source — for a coupling not accepted,
    whose interval decides nothing: the exact score's per-bin transforms raised a 10⁶-sample regression's traced
    peak from under 9.5× to 12.5× the record (``tests/test_refine_memory.py``). A singular A raises
    :class:`numpy.linalg.LinAlgError`."""
    s = np.asarray(fit["s"], dtype=np.float64)
    a_inv = np.linalg.inv(design.gram(bands, 1.0 / s)[0])
    noise = restricted_noise(bands, design, fit)
    if exact and getattr(bands, "source", None) is not None:
        e, _ = score_covariances(bands, fit, design, np.eye(len(design)), noise)
    else:
        e = 0.5 * wh.cross(bands, design, design, noise["s"] / s**2)
    if not np.all(np.isfinite(e)):
        return np.linalg.inv(2.0 * design.gram(bands, 1.0 / s)[0]), noise
    return a_inv @ e @ a_inv, noise
