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

import math

import numpy as np
from scipy.optimize import nnls

from .. import tracing
from .curvefit import Curve, Solution, base_name, design, held_coherent, held_theta, term_columns, theta_terms

__all__ = ["N_BOOT", "curve_test", "line_cross_vectors", "noise_psd", "nearest_terms", "residual_evidence", "tested"]

#: Bootstrap draws of the Allan-curve test's null distribution.
N_BOOT = 1000
#: The exact five-term covariance is scaled to the whole model only where the terms are at least this share of
#: it at every τ of the test (:func:`curve_test`).
TERMS_FLOOR = 1e-6


def curve_test(curve: Curve, thin: np.ndarray, sol: Solution, start, effects, exact: bool) -> tracing.ScoreTest:
    """The score test for one more column on the thinned τ ``thin`` of ``curve``, under the solution ``sol``
    of the terms ``start`` plus ``effects``; ``exact``: the five terms' covariance across τ in closed form
    (samples, or the overlapping estimator), else the octave-correlation model.

    The estimates' covariance is the noise's: the exact covariance of the five terms nearest the model's noise,
    scaled to it. A spectral line's coherent part (a fixed sinusoid, :func:`.curvefit.held_coherent`) is no
    noise: it adds to the estimates only its cross term with the noise (:func:`line_cross_vectors`), so it is
    left out of that scaling and its cross term's covariance added. Scaled like noise, a strong line gave the
    estimates where it dominates the scatter of a noise many times larger and the correlation of whichever term
    is left there: white noise plus a 0.042 °/s line at 2.9 Hz on a 7.3 Hz record (3.9× the noise's σ per
    sample) read GLS χ²/dof 5.9 after the exact sinusoid was taken, and a stand-in Gauss–Markov term was added
    (``benches/line_covariance.py``: the whitened estimates' χ²/n 5.75 scaled, 0.99 so). A line whose phase
    or amplitude wanders keeps the noise's covariance for its incoherent share."""
    sub = curve.subset(thin)
    a_terms = term_columns(sub, start)
    theta_t = theta_terms(sol, start, effects)
    a_thin, _ = design(sub, start, effects)
    model = sol.model[thin]
    lines = _coherent_lines(a_thin, sol.theta, start, effects) if exact else []
    rest = np.maximum(model - sum(share * col for col, share, _a2, _f in lines), 1e-300) if lines else model
    if effects and exact:
        theta_t = nearest_terms(a_terms, rest, theta_t)
    model_t = np.maximum(a_terms @ theta_t, 1e-300)
    cov_t = None
    # the effects' variance is the five terms' covariance scaled by model/terms: where the terms carry (next to)
    # nothing of the model (a curve-only fit whose effects took every τ: LN200 accelerometer z) the scaling
    # blows up (EDF ~1e298, overflow); there the octave-correlation model with each estimate's EDF is used
    if exact and np.all(model_t >= TERMS_FLOOR * rest):
        cov_t = tracing.exact_covariance(sub.m.astype(np.int64), curve.n_points - 1, curve.fs, start, theta_t)
        if lines:
            s = rest / model_t
            cov_t = cov_t * np.outer(s, s)
            for v in line_cross_vectors(lines, curve.fs, curve.n_points - 1, start, theta_t):
                cov_t += np.outer(v, v)
            model_t = model  # the covariance is the whole model's now: ScoreTest scales it by 1
    return tracing.ScoreTest(model, model_t, sol.nu[thin], sub.tau, a_thin[:, sol.theta > 0], cov_t)


def _coherent_lines(a: np.ndarray, theta: np.ndarray, start, effects) -> list:
    """(Allan-variance column at its coefficient, coherent share, amplitude², f0) of each held line in the
    model whose coherent share is positive (``a``: the columns, terms then effects, under ``theta``)."""
    k = len(start)
    out = []
    for j, (key, p) in enumerate(effects):
        share, held = held_coherent(key), held_theta(key)
        if base_name(key) == "sinusoid" and share > 0 and held is not None and theta[k + j] > 0:
            out.append((a[:, k + j] * theta[k + j], share, held[0], float(p)))
    return out


def line_cross_vectors(lines: list, fs: float, n: int, terms, theta) -> list:
    """Per coherent line (:func:`_coherent_lines`), the vector v whose v·vᵀ is the covariance across τ of its
    cross term with the noise. With y = l + w the estimate at m is L_m + 2⟨Δ_m l, Δ_m w⟩/(2K) + the noise's
    own; the cross term is linear in w (no covariance with the noise's quadratic part for Gaussian noise), and
    for a tone of amplitude A through the Allan difference filter H_m, Δ_mᵀΔ_m l ≈ |H_m(f₀)|²·l with
    |H_m|² = 4L_m/A², so it is L_m·ε with one ε = 4⟨l, w⟩/(A²N) for every τ: Var ε = 8·P(f₀)/(A²N), P the
    noise's PSD per sample at f₀ (:func:`noise_psd`; σ² for white noise). Of a line with coherent share c
    (its power A², its fixed part's c·A²) the fixed part's: v = c·L_m·√(8P/(c·A²·N)). Exact for white noise
    (one rank-one term per line; two lines' ε are uncorrelated); the record's ends add a little with rate random
    walk (simulated, ``benches/line_covariance.py``: whitened χ²/n 1.73 on 8192 samples, 1.16 on 65 536;
    the exact sum uᵀΣu 0.97)."""
    out = []
    for col, share, a2, f0 in lines:
        p = noise_psd(terms, theta, f0, fs)
        out.append(col * np.sqrt(8.0 * share * p / (a2 * max(n, 1))))
    return out


def noise_psd(terms, theta, f0: float, fs: float) -> float:
    """The five terms' two-sided PSD at ``f0`` per sample (σ² for white noise: N²·f_s; unit²): white angle
    4Q²f_s²·sin²(πf₀/f_s), white rate N²f_s, flicker B²f_s/(2πf₀), a sampled rate random walk
    K²/(4f_s·sin²(πf₀/f_s)); the ramp is no stationary noise (0)."""
    s2 = math.sin(math.pi * f0 / fs) ** 2
    per = {
        "Q": lambda c: 4.0 * c * fs**2 * s2,
        "N": lambda c: c * fs,
        "B": lambda c: c * fs / (2.0 * math.pi * f0),
        "K": lambda c: c / (4.0 * fs * max(s2, 1e-300)),
        "R": lambda c: 0.0,
    }
    return float(sum(per[t](float(c)) for t, c in zip(terms, theta)))


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
