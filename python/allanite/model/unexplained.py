"""What a fitted model still misses: calibrated checks of the final model, domain by domain.

:func:`allanite.refine` ends with a model; ``Refinement.unexplained`` says where the data still disagree with
it. Each check here is a test at its own share of the per-record ``level`` (so that on a complete model the list
is empty but at that rate) that returns the regions it could not explain, each a dict with

- ``"domain"``: where the evidence is (``"allan"``, ``"psd"``, ``"time"``, ``"channels"``);
- ``"tau"``: (lo, hi) in s — the Allan-curve τ range the misfit spans;
- ``"band_hz"``: (lo, hi) — the frequencies it corresponds to (≈ 1/(2τ_hi) … 1/(2τ_lo), refined on the
  residual's PSD where the samples are at hand; ``None`` for curve-only input);
- ``"chi2_dof"``: the misfit over that τ range (GLS χ² per estimate, ≫ 1 where the model misses);
- ``"statistic"``, ``"threshold"``, ``"alpha"``: the test that found it.

The Allan-curve check (:func:`curve_regions`) scans every run of up to three octaves of consecutive τ (4 per
octave): the GLS χ² of the final model's residual over the run — with the covariance of the estimates across τ
and the model's fitted directions projected out, as the acceptance test has them (:class:`ScoreTest`) —
standardised by its own bootstrap mean and spread, maximised over the runs; the threshold is the (1 − α) quantile
of that maximum on curves drawn from the final model (the look-elsewhere effect is in it). Unlike the acceptance
test's non-negative columns it is two-sided: a model that over-predicts a range misses it too.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.linalg import solve_triangular
from scipy.stats import chi2 as chi2_dist
from scipy.stats import norm

from .tracing import ScoreTest

__all__ = ["curve_regions", "tau_band", "describe_region", "MAX_RUN"]

#: Longest run of consecutive thinned τ a region is tested over (12 = three octaves at 4 per octave).
MAX_RUN = 12


def _runs(n: int, max_run: int) -> list[tuple[int, int]]:
    return [(i, j) for i in range(n) for j in range(i, min(n, i + max_run))]


def _projected(test: ScoreTest, r: np.ndarray) -> np.ndarray:
    """The GLS residual in τ space: the model's fitted directions (``test.q``, whitened) removed."""
    rw = solve_triangular(test.chol, r, lower=True)
    if test.q.shape[1]:
        rw = rw - test.q @ (test.q.T @ rw)
    return test.chol @ rw


def _run_chi2(cov: np.ndarray, r: np.ndarray, runs) -> np.ndarray:
    """GLS χ² of ``r`` (n_tau, k) over each run, with the run's own covariance block: (n_runs, k)."""
    out = np.empty((len(runs), r.shape[1]))
    for n, (i, j) in enumerate(runs):
        blk = cov[i : j + 1, i : j + 1]
        c = np.linalg.cholesky(blk + 1e-12 * np.trace(blk) / blk.shape[0] * np.eye(blk.shape[0]))
        w = solve_triangular(c, r[i : j + 1], lower=True)
        out[n] = np.sum(w * w, axis=0)
    return out


def curve_regions(
    test: ScoreTest, obs: np.ndarray, tau: np.ndarray, alpha: float, n_boot: int = 1000, seed: int = 0
) -> tuple[list[dict], dict]:
    """Runs of τ where ``obs`` departs from ``test.model`` beyond what the estimates' scatter allows.

    Returns (regions, test summary): regions disjoint, largest misfit first (empty when the maximum standardised
    run χ² stays below its (1 − α) bootstrap quantile); the summary holds the statistic, threshold and α."""
    n = tau.size
    runs = _runs(n, MAX_RUN)
    cov = test.chol @ test.chol.T
    rng = np.random.default_rng(seed)
    z = test.corr_chol @ rng.standard_normal((n, n_boot))
    ystar = test.model[:, None] * chi2_dist.ppf(norm.cdf(z), test.nu[:, None]) / test.nu[:, None]
    boot = _run_chi2(cov, _projected(test, ystar - test.model[:, None]), runs)
    mu, sd = boot.mean(axis=1), np.maximum(boot.std(axis=1), 1e-12)
    thr = float(np.quantile(np.max((boot - mu[:, None]) / sd[:, None], axis=0), 1.0 - alpha))
    data = _run_chi2(cov, _projected(test, (obs - test.model)[:, None]), runs)[:, 0]
    zs = (data - mu) / sd
    summary = {"statistic": float(zs.max()), "threshold": thr, "alpha": alpha}
    regions: list[dict] = []
    taken = np.zeros(n, dtype=bool)
    for k in np.argsort(-zs):
        if zs[k] <= thr:
            break
        i, j = runs[k]
        if taken[i : j + 1].any():
            continue
        taken[i : j + 1] = True
        regions.append(
            {
                "domain": "allan",
                "tau": (float(tau[i]), float(tau[j])),
                "band_hz": None,
                "chi2_dof": float(data[k] / (j - i + 1)),
                "statistic": float(zs[k]),
                "threshold": thr,
                "alpha": alpha,
            }
        )
    return regions, summary


def tau_band(tau_lo: float, tau_hi: float, fs: float) -> tuple[float, float]:
    """The frequencies an Allan τ range mostly responds to: ≈ 1/(2τ_hi) … 1/(2τ_lo), within (0, fs/2]."""
    return (0.5 / tau_hi, min(0.5 / tau_lo, 0.5 * fs))


def describe_region(reg: dict) -> str:
    """One region in words: "τ 0.2–3 s (≈ 0.17–2.5 Hz), χ²/dof 12"."""
    lo, hi = reg["tau"]
    text = f"τ {_num(lo)}–{_num(hi)} s" if hi > lo else f"τ {_num(lo)} s"
    band = reg.get("band_hz")
    if band is not None:
        text += f" (≈ {_num(band[0])}–{_num(band[1])} Hz)"
    what = reg.get("what")
    if what:
        text += f": {what}"
    if reg.get("chi2_dof") is not None:
        text += f", χ²/dof {_num(reg['chi2_dof'])}"
    return text


def _num(v: float) -> str:
    if v == 0 or not math.isfinite(v):
        return f"{v:g}"
    digits = max(0, 1 - int(math.floor(math.log10(abs(v)))))
    return f"{v:.{digits}f}" if abs(v) < 1000 else f"{v:.3g}"
