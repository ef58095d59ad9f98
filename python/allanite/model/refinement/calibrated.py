"""The calibrated tests' glue: the Allan-curve score test of a fitted solution and its bootstrap threshold,
and what the residual looked like when a test fired.

The statistic is the GLS score for one more non-negative column on ~4 τ per octave with the covariance of
the estimates across τ (exact for the five terms, :mod:`allanite.model._covariance`); its threshold the
(1 − α) quantile of its maximum over every candidate family under the fitted model (parametric bootstrap,
:class:`allanite.model.tracing.ScoreTest`), so the look-elsewhere effect is in it. α is the curve's share of
``level`` (:mod:`.levels`); the other domains' tests (spectral lines, drift, regression, change points) are
in :mod:`allanite.model.tracing` and :mod:`.changes`, each at its own share.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import nnls

from .. import tracing
from ..terms import design_matrix
from .curvefit import Curve, Solution, design, theta_terms

__all__ = ["N_BOOT", "curve_test", "nearest_terms", "residual_evidence", "tested"]

#: Bootstrap draws of the Allan-curve test's null distribution.
N_BOOT = 1000
#: The exact five-term covariance is scaled to the whole model only where the terms are at least this share of
#: it at every τ of the test (:func:`curve_test`).
TERMS_FLOOR = 1e-6


def curve_test(curve: Curve, thin: np.ndarray, sol: Solution, start, effects, exact: bool) -> tracing.ScoreTest:
    """The score test for one more column on the thinned τ ``thin`` of ``curve``, under the solution ``sol``
    of the terms ``start`` plus ``effects``; ``exact``: the five terms' covariance across τ in closed form
    (samples, or the overlapping estimator), else the octave-correlation model."""
    sub = curve.subset(thin)
    a_terms = design_matrix(sub.tau, sub.m, curve.fs, start)
    theta_t = theta_terms(sol, start, effects)
    if effects and exact:
        theta_t = nearest_terms(a_terms, sol.model[thin], theta_t)
    model_t = np.maximum(a_terms @ theta_t, 1e-300)
    cov_t = None
    # the effects' variance is the five terms' covariance scaled by model/terms: where the terms carry (next to)
    # nothing of the model (a curve-only fit whose effects took every τ: LN200 accelerometer z) the scaling
    # blows up (EDF ~1e298, overflow); there the octave-correlation model with each estimate's EDF is used
    if exact and np.all(model_t >= TERMS_FLOOR * sol.model[thin]):
        cov_t = tracing.exact_covariance(sub.m.astype(np.int64), curve.n_points - 1, curve.fs, start, theta_t)
    a_thin, _ = design(sub, start, effects)
    return tracing.ScoreTest(sol.model[thin], model_t, sol.nu[thin], sub.tau, a_thin[:, sol.theta > 0], cov_t)


def nearest_terms(a_terms: np.ndarray, model: np.ndarray, theta_t: np.ndarray) -> np.ndarray:
    """The terms' coefficients whose curve is nearest ``model`` (relative least squares, non-negative) — the
    noise whose exact covariance stands in for a model with effects, scaled to it (:class:`ScoreTest`). The
    terms' own part scaled up would give an effect the correlation across τ of whichever term is left there:
    at τ ≫ T_c a Gauss–Markov term is white-like, yet beside a small K it took K's random-walk correlation,
    and a correct five terms + GM read GLS χ²/dof 5.1 on 1e6 samples (1.6 with the nearest terms' covariance).
    ``theta_t`` (the terms' own part) where the fit fails."""
    w = a_terms / np.maximum(model, 1e-300)[:, None]
    try:
        theta, _ = nnls(w, np.ones(model.size))
    except RuntimeError:
        return theta_t
    return theta if np.any(theta > 0) else theta_t


def residual_evidence(curve: Curve, sol: Solution) -> dict:
    """Where the residual is: runs of same-signed |z| > 2, and the τ of the largest |z|."""
    z = sol.z
    runs = []
    i = 0
    while i < z.size:
        if abs(z[i]) > 2:
            j = i
            while j + 1 < z.size and abs(z[j + 1]) > 2 and np.sign(z[j + 1]) == np.sign(z[i]):
                j += 1
            runs.append(
                {
                    "tau_from": float(curve.tau[i]),
                    "tau_to": float(curve.tau[j]),
                    "sign": int(np.sign(z[i])),
                    "points": int(j - i + 1),
                }
            )
            i = j + 1
        else:
            i += 1
    k = int(np.argmax(np.abs(z)))
    return {"runs_beyond_2sigma": runs, "max_abs_z": float(abs(z[k])), "tau_of_max": float(curve.tau[k])}


def tested(statistic: str, value: float, threshold: float, alpha: float) -> dict:
    """A step's ``evidence["test"]``: which statistic, its value, the threshold it had to pass and the α
    (share of ``level``) that threshold spends."""
    return {statistic: value, "threshold": threshold, "alpha": alpha}
