"""Tracing a residual in more than one domain, and a calibrated test for adding an effect.

Used by :func:`allanite.refine`:

- lines of the spectrum: :mod:`allanite.model.lines` (the search, the families) and :mod:`allanite.model.periodic`.
- :func:`drift_fit` — an exponential warm-up a·e^{−t/T} on block means along the record.
- :func:`regression_fit` — the rate regressed on another channel, with a block-jackknife interval;
  :func:`band_regression` — the same band by band (octaves), where the coupling differs across frequency.
- :class:`ScoreTest` — a generalised-least-squares score (likelihood-ratio in the linearised model)
  statistic for adding one non-negative column to the fitted Allan-variance model, with the covariance of
  the estimates across τ (exact for the five terms and the overlapping estimator, docs/FORMULAS.md §5 via
  :mod:`allanite.model._covariance`, variances included; effects enter by scaling it with the model's level),
  and its null distribution by a parametric bootstrap: Allan curves drawn from the fitted model with χ²
  marginals of the estimates' variances tied by a Gaussian copula of their correlation. The maximum of the
  statistic over every candidate family's columns is bootstrapped, so the look-elsewhere effect is in the
  threshold.
"""

from __future__ import annotations

import contextvars
import math
from concurrent.futures import ThreadPoolExecutor

import numpy as np
from scipy import signal
from scipy.linalg import solve_triangular
from scipy.optimize import minimize_scalar

from . import _chi2_draws, _covariance
from ._chunked import welch_mean
from ._null_records import block_rate_record
from ._recent import Recent

__all__ = [
    "drift_fit",
    "drift_component",
    "drift_threshold",
    "simulated_block_means",
    "simulated_block_mean_chunks",
    "block_means",
    "regression_fit",
    "gm_autocorrelation",
    "rolloff_psd",
    "regression_heldout",
    "band_regression",
    "band_component",
    "ScoreTest",
    "thin_indices",
]

#: Block means a drift is fitted to.
DRIFT_BLOCKS = 500
#: Octave-to-octave correlation of Allan estimates where no exact covariance applies (curves only).
OCTAVE_RHO = 0.68


def _drift_stat(b, tb, length, with_interval=False):
    """Warm-up c + r·t + a·e^{−t/T} against the ramp c + r·t on block means: statistic n·ln(RSS_ramp/RSS)."""
    nb = b.size
    base = np.column_stack([np.ones(nb), tb])
    r0 = b - base @ np.linalg.lstsq(base, b, rcond=None)[0]
    rss0 = float(r0 @ r0)

    def rss(lt):
        a = np.column_stack([base, np.exp(-tb / math.exp(lt))])
        coef = np.linalg.lstsq(a, b, rcond=None)[0]
        r = b - a @ coef
        return float(r @ r), coef

    grid = np.linspace(math.log(length / 200), math.log(length / 2), 24)
    vals = [rss(g)[0] for g in grid]
    j = int(np.argmin(vals))
    lo, hi = grid[max(0, j - 1)], grid[min(grid.size - 1, j + 1)]
    res = minimize_scalar(lambda lt: rss(lt)[0], bounds=(lo, hi), method="bounded", options={"xatol": 1e-3})
    lt = float(res.x)
    r_min, coef = rss(lt)
    stat = nb * math.log(rss0 / max(r_min, 1e-300))
    out = {"statistic": stat, "T": math.exp(lt), "amplitude": float(coef[2]), "at_edge": j in (0, grid.size - 1)}
    if with_interval:
        # T and a where nb·ln(RSS) rises by ≤ 1 over its minimum (a profile likelihood interval)
        fine = np.linspace(lt - 1.5, lt + 1.5, 61)
        d = nb * np.log(np.array([rss(v)[0] for v in fine]) / r_min)
        ok = fine[d <= 1.0]
        out["T_interval"] = (math.exp(ok.min()), math.exp(ok.max())) if ok.size else (out["T"], out["T"])
        a_sd = abs(out["amplitude"]) / math.sqrt(max(stat, 1e-12))
        out["amplitude_interval"] = (out["amplitude"] - a_sd, out["amplitude"] + a_sd)
    return out


def block_means(y: np.ndarray, n_blocks: int) -> tuple[np.ndarray, int]:
    """The means of ``n_blocks`` consecutive blocks of ``y`` (at most one sample each) and the samples per block;
    the samples past the last whole block are left out."""
    nb = min(n_blocks, y.size)
    per = y.size // nb
    return y[: nb * per].reshape(nb, per).mean(axis=1), per


def drift_fit(y: np.ndarray, fs: float, n_blocks: int = DRIFT_BLOCKS) -> dict:
    """Least-squares warm-up c + r·t + a·e^{−t/T} on block means (T from L/200 to L/2, L the record), with
    the statistic nb·ln(RSS_ramp/RSS_warm-up) against a ramp (a constant slope is the R term, not a drift)."""
    b, per = block_means(y, n_blocks)
    tb = (np.arange(b.size) * per + 0.5 * (per - 1)) / fs
    return _drift_stat(b, tb, y.size / fs, with_interval=True)


def drift_component(y: np.ndarray, t: np.ndarray, length: float, pieces: int = 1, n_blocks: int = DRIFT_BLOCKS // 2):
    """The warm-up a·e^{−t/T} fitted (as in :func:`drift_fit`) on samples ``y`` taken at times ``t`` (s): the
    ``pieces`` equal runs of consecutive samples (a part of alternate blocks) are each cut into block means,
    so no block straddles a seam. Returns the component as a function of time, for the held-out error."""
    per_piece = max(1, n_blocks // pieces)
    run = y.size // pieces
    per = max(1, run // per_piece)
    use = per_piece * per
    yb = y[: pieces * run].reshape(pieces, run)[:, :use].reshape(-1, per)
    tb = t[: pieces * run].reshape(pieces, run)[:, :use].reshape(-1, per)
    d = _drift_stat(yb.mean(axis=1), tb.mean(axis=1), length)
    a, t_c = d["amplitude"], d["T"]
    return lambda tt: a * np.exp(-np.asarray(tt) / t_c)


def _grid_stats(b: np.ndarray, tb: np.ndarray, length: float) -> np.ndarray:
    """The drift statistic on the T grid only, for many records at once (columns of ``b``): per T the exponential
    made orthogonal to the ramp (twice, for round-off), so that RSS(T) = RSS_ramp − (eᵀr)² for every record in
    one product."""
    nb = b.shape[0]
    base = np.column_stack([np.ones(nb), tb])
    q0 = np.linalg.qr(base)[0]
    r0 = b - q0 @ (q0.T @ b)
    rss0 = np.sum(r0 * r0, axis=0)
    grid = np.linspace(math.log(length / 200), math.log(length / 2), 24)
    e = np.exp(-tb[:, None] / np.exp(grid)[None, :])
    for _ in range(2):
        e = e - q0 @ (q0.T @ e)
    e = e / np.linalg.norm(e, axis=0)
    c = e.T @ r0
    best = np.min(rss0[None, :] - c * c, axis=0)
    return nb * np.log(rss0 / np.maximum(best, 1e-300))


def drift_threshold(n: int, fs: float, terms, theta, alpha: float, n_boot: int = 1000, seed: int = 0) -> float:
    """(1 − α) quantile of the drift statistic on records of the fitted five-term model (parametric bootstrap).

    Only the block means matter, so the records are simulated at the block rate (white rate, flicker and
    random walk of rate keep their coefficients; white angle noise averages out), all at once as the
    consecutive pieces of one long record; the statistic is taken on the T grid (the observed one is refined
    between grid points, so the test errs on the safe side by at most that refinement)."""
    nb = min(DRIFT_BLOCKS, n)
    per = n // nb
    tb = (np.arange(nb) * per + 0.5 * (per - 1)) / fs
    b = simulated_block_means(nb, per, fs, terms, theta, n_boot, seed)
    return float(np.quantile(_grid_stats(b, tb, n / fs), 1.0 - alpha))


#: Most block-rate samples simulated at once for a null (2 MB each; the simulation's transient, the flicker's
#: transforms over twice that length, ≈ 10× it). Larger nulls are drawn as chunks of records of this many samples.
SIM_CHUNK = 2**18


def simulated_block_mean_chunks(nb: int, per: int, fs: float, terms, theta, n_boot: int, seed: int):
    """:func:`simulated_block_means` a chunk of records at a time (the mean and steps checks' nulls): arrays
    (nb, k), k records each, ``n_boot`` in all. Up to :data:`SIM_CHUNK` samples (nb · n_boot) one chunk, exactly
    :func:`simulated_block_means`; beyond, each chunk the consecutive pieces of its own long record of
    ``SIM_CHUNK // nb`` records (the last chunk its first pieces only), chunk i drawn from the seed (``seed``,
    i). A null's memory no longer grows with its records (2²² samples at once were ≈ 240 MB with the flicker's
    transforms); each record is, as before, a piece of a record ≥ 2¹⁸ block-rate samples long."""
    coef = {t: math.sqrt(max(float(v), 0.0)) for t, v in zip(terms, theta)}
    terms4 = {t: coef.get(t, 0.0) for t in ("N", "B", "K", "R")}
    if nb * n_boot <= SIM_CHUNK:
        long = block_rate_record(nb * n_boot, fs / per, **terms4, seed=seed)
        yield np.asarray(long, dtype=np.float64).reshape(n_boot, nb).T
        return
    each = max(1, SIM_CHUNK // nb)

    def chunk(i: int, first: int) -> np.ndarray:
        long = block_rate_record(nb * each, fs / per, **terms4, seed=np.random.default_rng([seed, i]))
        k = min(each, n_boot - first)
        return np.asarray(long[: nb * k], dtype=np.float64).reshape(k, nb).T

    yield from _prefetched(chunk, list(enumerate(range(0, n_boot, each))))


def _prefetched(make, args: list):
    """``make(*a)`` for each ``a`` of ``args`` in order, the next one drawn on a second thread while the caller
    reads this one: each chunk has its own generator (:func:`simulated_block_mean_chunks`), so the numbers are
    the same in any order, and NumPy's draws and FFTs release the GIL — on two cores the null's simulation
    overlaps its statistics. One chunk ahead at most (its memory, ≈ 20 MB); the context (the flicker's memory,
    :func:`allanite.model._null_records.sharing`) is the caller's."""
    if len(args) < 2:
        yield from (make(*a) for a in args)
        return
    with ThreadPoolExecutor(max_workers=1) as pool:
        ahead = pool.submit(contextvars.copy_context().run, make, *args[0])
        for a in args[1:]:
            done = ahead.result()
            ahead = pool.submit(contextvars.copy_context().run, make, *a)
            yield done
        yield ahead.result()


def simulated_block_means(nb: int, per: int, fs: float, terms, theta, n_boot: int, seed: int) -> np.ndarray:
    """Block means (``nb`` blocks of ``per`` samples at ``fs``) of ``n_boot`` records of the five-term model
    ``theta`` (squared coefficients of ``terms``), shape (nb, n_boot): simulated at the block rate fs/per (white
    rate, flicker and random walk of rate keep their coefficients; white angle noise averages out), all at once
    as the consecutive pieces of one long record — the drift check's null (5·10⁵ samples; the mean and steps
    checks' larger nulls are drawn a chunk at a time, :func:`simulated_block_mean_chunks`)."""
    coef = {t: math.sqrt(max(float(v), 0.0)) for t, v in zip(terms, theta)}
    terms4 = {t: coef.get(t, 0.0) for t in ("N", "B", "K", "R")}
    long = block_rate_record(nb * n_boot, fs / per, **terms4, seed=seed)
    return np.asarray(long, dtype=np.float64).ravel().reshape(n_boot, nb).T


def gm_autocorrelation(y: np.ndarray, fs: float, tc: float) -> dict | None:
    """A Gauss–Markov term's correlation time from the residual's autocorrelation in time (evidence in a
    second domain for a term found on the Allan curve).

    Means of blocks Δ ≈ T_c/4 long, the ramp removed: white noise of any level adds nothing to their
    autocovariance at lags ≥ 1, and a GM adds σ_b²·φ^k with φ = e^{−Δ/T_c} (the block averaging scales every
    lag ≥ 1 alike), so φ̂ = R(2)/R(1) and T̂_c = −Δ/ln φ̂. None if fewer than 50 blocks fit; ``tc`` NaN when
    the autocovariance does not decay like a GM's (R(1) ≤ 0 or R(2) ∉ (0, R(1)))."""
    per = max(1, int(round(tc * fs / 4.0)))
    nb = y.size // per
    if nb < 50:
        return None
    b = y[: nb * per].reshape(nb, per).mean(axis=1)
    k = np.arange(nb, dtype=np.float64)
    b = b - np.polyval(np.polyfit(k, b, 1), k)
    r0, r1, r2 = float(b @ b) / nb, float(b[:-1] @ b[1:]) / nb, float(b[:-2] @ b[2:]) / nb
    dt = per / fs
    tc_hat = -dt / math.log(r2 / r1) if 0.0 < r2 < r1 else float("nan")
    return {"tc": tc_hat, "block_s": dt, "blocks": nb, "lag1": r1 / r0 if r0 > 0 else float("nan")}


def rolloff_psd(y: np.ndarray, fs: float, r: np.ndarray) -> dict:
    """A bandwidth's roll-off checked in the spectrum (evidence in a second domain for a filter found on the
    Allan curve): the Welch PSD's power at 0.40–0.48·f_s over its power at 0.02–0.10·f_s, measured and as the
    filter with normalised autocorrelation ``r`` predicts for white input (r₀ + 2Σ r_l cos 2πfl/f_s)."""
    nper = int(min(4096, 2 ** int(math.log2(max(y.size // 8, 256)))))
    f, p = _rolloff_welch(np.asarray(y, dtype=np.float64), float(fs), nper)
    hi, lo = (f >= 0.40 * fs) & (f <= 0.48 * fs), (f >= 0.02 * fs) & (f <= 0.10 * fs)
    lags = np.arange(1, r.size)

    def model(fr):
        return r[0] + 2.0 * np.cos(2.0 * np.pi * np.outer(fr / fs, lags)) @ r[1:]

    return {
        "measured": float(p[hi].mean() / p[lo].mean()),
        "predicted": float(model(f[hi]).mean() / model(f[lo]).mean()),
        "bands_hz": (0.02 * fs, 0.10 * fs, 0.40 * fs, 0.48 * fs),
    }


#: The Welch PSDs of :func:`rolloff_psd`, of records up to 4·10⁶ samples: each curve step's bandwidth candidates
#: and the accepted bandwidth's evidence ask for the same samples' spectrum, each with another filter's prediction.
_WELCH = Recent(2, 4_000_000)


def _rolloff_welch(y: np.ndarray, fs: float, nper: int) -> tuple[np.ndarray, np.ndarray]:
    """``signal.welch`` of the de-meaned ``y``, a chunk of segments at a time (:func:`._chunked.welch_mean`: no
    record-size copies; within 1e-12 of scipy's), remembered by content within a refine call; read-only."""
    got = _WELCH.get(y, (fs, nper))
    if got is None:
        f, p = welch_mean(y, fs, nper, float(y.mean()))
        f.flags.writeable = p.flags.writeable = False
        got = _WELCH.put(y, (fs, nper), (f, p))
    return got


def regression_fit(y: np.ndarray, ch: np.ndarray, n_blocks: int = 8) -> dict:
    """Least-squares coefficient of the rate on a channel *within* blocks, with a batch-means standard error.

    The record is cut into ``n_blocks`` blocks in time and each block is de-meaned on its own (y and the
    channel): the coefficient is the pooled within-block estimate Σ ỹ·x̃ / Σ x̃², and its SE the batch means of
    the blocks' scores s_j = Σ_{i∈j} (ỹ − c·x̃)·x̃: √(Σ s_j² · B/(B − 1)) / Σ x̃². Its t has ν − 1 degrees of
    freedom, ν = (Σ_j d_j)² / Σ_j d_j² the effective number of blocks (d_j = Σ_{i∈j} x̃²; Satterthwaite): B − 1
    when every block sees the channel alike, fewer when a few blocks carry it (a turn of the table in some).

    Why within blocks: a persistent channel (a ±1 g multi-position profile, a temperature, a random walk)
    regressed on persistent noise (flicker, random walk of rate) makes spurious coefficients; de-meaning each
    block takes out most of that shared slow wander, and weighting the blocks by their own channel variance
    lets the blocks that see a change (a turn of the table) carry the estimate. Measured on 300 null records
    (benches/regression_null.py, ``benches/results/regression_null.md``): false alarms near the 0.375 % refine
    allows (the per-block-coefficient SE it replaces: 2 %), and a t of ≈ 200 on a simulated 0.01 °/s/g
    multi-position test where the replaced SE gave 1.3.
    The few samples past the last whole block (< n_blocks) are left out.
    """
    per = y.size // n_blocks
    yb = np.asarray(y[: per * n_blocks], dtype=np.float64).reshape(n_blocks, per)
    xb = np.asarray(ch[: per * n_blocks], dtype=np.float64).reshape(n_blocks, per)
    yc = yb - yb.mean(axis=1, keepdims=True)
    xc = xb - xb.mean(axis=1, keepdims=True)
    d = np.sum(xc * xc, axis=1)
    den = float(np.sum(d))
    if not den > 0:
        return {"coefficient": 0.0, "se": float("nan"), "dof": 1.0}
    coef = float(np.sum(yc * xc)) / den
    scores = np.sum((yc - coef * xc) * xc, axis=1)
    se = math.sqrt(float(np.sum(scores**2)) * n_blocks / (n_blocks - 1)) / den if n_blocks > 1 else float("nan")
    dof = max(1.0, den**2 / float(np.sum(d**2)) - 1.0)
    return {"coefficient": coef, "se": se, "dof": dof}


def regression_heldout(y: np.ndarray, ch: np.ndarray, fs: float | None = None, alpha: float | None = None) -> float:
    """Held-out test of a regression in time: each half's residual variance with the other half's coefficient,
    over its raw variance (mean of the two ways; < 1 means the coefficient carries over). With ``fs`` and
    ``alpha``: the other half's band regression (:func:`band_regression`) instead of one coefficient."""
    h = y.size // 2
    parts = [(y[:h], ch[:h]), (y[h:], ch[h:])]
    ratios = []
    for (yf, cf), (yh, chh) in ((parts[0], parts[1]), (parts[1], parts[0])):
        yh0, ch0 = yh - yh.mean(), chh - chh.mean()
        if fs is None or alpha is None:
            comp = regression_fit(yf, cf, 2)["coefficient"] * ch0
        else:
            comp = band_component(ch0, band_regression(yf, cf, fs, alpha)["used"])
        ratios.append(float(np.var(yh0 - comp) / np.var(yh0)))
    return float(np.mean(ratios))


#: Blocks of the batch-means error of a band's coefficient; a band is formed only where each block holds
#: ≥ 8 of its widest smoothing windows.
BAND_BLOCKS = 8


def _bands(x: np.ndarray, levels: int):
    """Octave bands of ``x`` that sum to it exactly: S_{k−1} − S_k for k = 1 … levels, S_k the zero-phase
    (forward–backward) 4th-order Butterworth low-pass of ``x`` at fs/2^(k+1) (S_0 = x), then the remainder
    S_levels. Yields one band at a time (each the record's length)."""
    prev = x
    for k in range(1, levels + 1):
        sos = signal.butter(4, 2.0**-k, "low", output="sos")  # cutoff fs/2^(k+1): 2^-k of Nyquist
        cur = signal.sosfiltfilt(sos, x)
        yield prev - cur
        prev = cur
    yield prev


def band_levels(n: int) -> int:
    """Smoothing levels for a record of ``n`` samples: 2^levels · 8 · BAND_BLOCKS ≤ n (at least 1)."""
    return max(1, int(math.floor(math.log2(max(2, n // (8 * BAND_BLOCKS))))))


def band_regression(y: np.ndarray, ch: np.ndarray, fs: float, alpha: float) -> dict:
    """The rate regressed on a channel band by band (octaves, zero-phase Butterworth), for a coupling that
    differs across frequency — a g-sensitivity seen through slow attitude changes and a vibration coupling
    seen through the channel's noise, say.

    Every band of the channel (and the same band of the rate) gives its own least-squares coefficient and a
    batch-means standard error over :data:`BAND_BLOCKS` blocks in time. A band keeps its own coefficient only
    where it differs from the whole-record coefficient by more than the two-sided t quantile (BAND_BLOCKS − 1
    degrees of freedom) at ``alpha`` Bonferroni-split over the bands; elsewhere the whole-record coefficient
    stands. With one coefficient for every band the component is exactly ``coefficient · (ch − mean)``
    (the bands sum to the channel).

    Returns ``coefficient`` and ``se`` (:func:`regression_fit`), ``bands``: one dict per band (``f_lo``,
    ``f_hi`` in Hz, ``coefficient``, ``se``, ``own``: whether it keeps its coefficient), and ``used``: the
    coefficient applied to each band.
    """
    from scipy.stats import t as t_dist

    whole = regression_fit(y, ch, BAND_BLOCKS)
    c0 = whole["coefficient"]
    levels = band_levels(y.size)
    thr = float(t_dist.isf(alpha / (2 * (levels + 1)), BAND_BLOCKS - 1))
    yc, cc = y - y.mean(), ch - ch.mean()
    per = y.size // BAND_BLOCKS
    bands, used = [], []
    for k, (yb, cb) in enumerate(zip(_bands(yc, levels), _bands(cc, levels)), start=1):
        den = float(cb @ cb)
        ck = float(yb @ cb) / den if den > 0 else 0.0
        parts = []
        for j in range(BAND_BLOCKS):
            sl = slice(j * per, (j + 1) * per)
            d = float(cb[sl] @ cb[sl])
            if d > 0:
                parts.append(float(yb[sl] @ cb[sl]) / d)
        se = float(np.std(parts, ddof=1) / math.sqrt(len(parts))) if len(parts) > 1 else math.inf
        own = bool(den > 0 and se > 0 and abs(ck - c0) / se > thr)
        f_hi = fs / 2**k  # band k: fs/2^(k+1) … fs/2^k; the remainder (k = levels + 1): 0 … fs/2^k
        f_lo = fs / 2 ** (k + 1) if k <= levels else 0.0
        bands.append({"f_lo": f_lo, "f_hi": f_hi, "coefficient": ck, "se": se, "own": own})
        used.append(ck if own else c0)
    return {"coefficient": c0, "se": whole["se"], "bands": bands, "used": used, "threshold": thr}


def band_component(ch_centred: np.ndarray, used) -> np.ndarray:
    """Σ_k used[k] · band_k(ch): the component a :func:`band_regression` removes (``ch_centred`` de-meaned)."""
    levels = len(used) - 1
    if all(u == used[0] for u in used):
        return used[0] * ch_centred
    out = np.zeros_like(ch_centred, dtype=np.float64)
    for u, b in zip(used, _bands(ch_centred, levels)):
        out += u * b
    return out


def thin_indices(tau: np.ndarray, per_octave: int = 4) -> np.ndarray:
    """Indices of ``tau`` (sorted) nearest to a grid of ``per_octave`` points per octave, unique."""
    n_oct = math.log2(tau[-1] / tau[0])
    target = np.geomspace(tau[0], tau[-1], max(2, int(round(n_oct * per_octave)) + 1))
    idx = np.unique(np.clip(np.searchsorted(tau, target), 0, tau.size - 1))
    return idx


def _psd_cholesky(corr: np.ndarray) -> np.ndarray:
    """Cholesky factor of a correlation matrix; if rounding (or the effects' approximate share of the
    covariance) left it indefinite, of its nearest positive definite correlation (eigenvalues clipped)."""
    try:
        return np.linalg.cholesky(corr + 1e-9 * np.eye(corr.shape[0]))
    except np.linalg.LinAlgError:
        w, v = np.linalg.eigh(corr)
        w = np.maximum(w, 1e-6 * max(float(w.max()), 1e-300))
        c = (v * w) @ v.T
        d = np.sqrt(np.diag(c))
        return np.linalg.cholesky(c / np.outer(d, d) + 1e-9 * np.eye(corr.shape[0]))


class ScoreTest:
    """GLS score statistic for one more non-negative column, and its bootstrap threshold.

    With ``cov_terms`` the estimates' variances are the exact ones too, not 2·model²/ν: the EDF of a mixture
    combined per term leaves out the cross terms between the noise types, and under-states the variance of
    a mid-τ estimate of white + flicker + random walk up to 2.4× (simulated N + B + K, 2·10⁵ samples) — a
    statistic whitened by it is inflated against its own bootstrap, which then rejects far above its α
    (``benches/results/refine_calibration.md``). The bootstrap's χ² marginals take the EDF of the exact
    variance, 2·model²/var.

    Parameters
    ----------
    tau : the thinned τ (s)
    model : the current model on those τ
    model_terms : the current model's five-term part (its covariance is exact; effects scale it)
    nu : EDF of each estimate (used where no exact covariance is given)
    columns : (n_tau, k) active columns of the current model (projected out: the refit absorbs them)
    cov_terms : (n_tau, n_tau) exact covariance of the five-term part, or None (octave-correlation model)
    """

    def __init__(self, model, model_terms, nu, tau, columns, cov_terms=None):
        self.model = model
        if cov_terms is not None:
            s = model / np.maximum(model_terms, 1e-300)
            c = cov_terms * np.outer(s, s)
            d = np.sqrt(np.maximum(np.diag(c), 1e-300))
            corr = c / np.outer(d, d)
            nu = 2.0 * (np.maximum(model, 1e-300) / d) ** 2
        else:
            lt = np.log2(tau)
            corr = OCTAVE_RHO ** np.abs(lt[:, None] - lt[None, :])
        sd = model * np.sqrt(2.0 / nu)
        self.corr_chol = _psd_cholesky(0.5 * (corr + corr.T))
        self.nu = nu
        self.chol = self.corr_chol * sd[:, None]  # Σ = D R D
        xw = solve_triangular(self.chol, columns, lower=True) if columns.size else np.zeros((tau.size, 0))
        self.q = np.linalg.qr(xw)[0] if xw.shape[1] else np.zeros((tau.size, 0))
        self._draws: dict[tuple[int, int], np.ndarray] = {}

    def _perp(self, v):
        vw = solve_triangular(self.chol, v, lower=True)
        return vw - self.q @ (self.q.T @ vw)

    def directions(self, cols: np.ndarray) -> np.ndarray:
        """Unit whitened directions of candidate columns (n_tau, n_cols) orthogonal to the model's."""
        cp = self._perp(cols)
        cw = solve_triangular(self.chol, cols, lower=True)
        nrm = np.linalg.norm(cp, axis=0)
        keep = nrm > 1e-3 * np.maximum(np.linalg.norm(cw, axis=0), 1e-300)
        return (cp[:, keep] / nrm[keep]).T

    def statistic(self, y: np.ndarray, col: np.ndarray) -> float:
        """(c⊥ᵀ Σ⁻¹ r)₊² / (c⊥ᵀ Σ⁻¹ c⊥) for residual r = y − model: Δχ² of the GLS fit when the column is added."""
        u = self.directions(col[:, None])
        if u.size == 0:
            return 0.0
        rp = self._perp((y - self.model)[:, None])[:, 0]
        return float(max(0.0, float(u[0] @ rp)) ** 2)

    def max_statistic(self, y: np.ndarray, family: np.ndarray) -> float:
        """The largest :meth:`statistic` over the columns of ``family`` (n_tau, n_cols); 0 if the model spans
        them all."""
        u = self.directions(family)
        if u.size == 0:
            return 0.0
        rp = self._perp((y - self.model)[:, None])[:, 0]
        return float(np.max(np.maximum(u @ rp, 0.0) ** 2))

    def null_maxima(self, family: np.ndarray, n_boot: int = 1000, seed: int = 0) -> np.ndarray:
        """The maximum statistic over ``family`` (n_tau, n_cols) on ``n_boot`` curves drawn from the model:
        χ²_ν/ν marginals, Gaussian copula with the estimates' correlation (empty if the model spans them)."""
        u = self.directions(family)
        if u.size == 0:
            return np.zeros(0)
        rp = self._perp(self._drawn(n_boot, seed))
        return np.max(np.maximum(u @ rp, 0.0) ** 2, axis=0)

    def _drawn(self, n_boot: int, seed: int) -> np.ndarray:
        """``n_boot`` curves drawn from the model, minus the model (drawn once per (n_boot, seed), for every
        family and for :meth:`null_chi2`)."""
        if (n_boot, seed) not in self._draws:
            rng = np.random.default_rng(seed)
            z = self.corr_chol @ rng.standard_normal((self.model.size, n_boot))
            ystar = self.model[:, None] * _chi2_draws.scaled_quantiles(z, self.nu)
            self._draws[(n_boot, seed)] = ystar - self.model[:, None]
        return self._draws[(n_boot, seed)]

    def gls_chi2(self, y: np.ndarray) -> float:
        """The GLS χ² of the residual y − model once the model's fitted directions are refitted (projected out):
        a two-sided measure of the whole curve's misfit, beside the one-sided score of one more column."""
        rp = self._perp((y - self.model)[:, None])[:, 0]
        return float(rp @ rp)

    def null_chi2(self, n_boot: int = 1000, seed: int = 0) -> np.ndarray:
        """:meth:`gls_chi2` of ``n_boot`` curves drawn from the model (the same draws as :meth:`null_maxima`)."""
        rp = self._perp(self._drawn(n_boot, seed))
        return np.sum(rp**2, axis=0)

    def threshold(self, family: np.ndarray, alpha: float, n_boot: int = 1000, seed: int = 0) -> float:
        """(1 − α) quantile of the maximum statistic over ``family`` (n_tau, n_cols) on curves drawn from
        the model (:meth:`null_maxima`): the ⌈(n_boot + 1)(1 − α)⌉-th smallest draw, the Monte-Carlo test's
        critical value — a statistic exchangeable with the draws exceeds it with probability at most α (an
        interpolated quantile of 1000 draws at α = 0.25 % is exceeded with probability ≈ 0.35 %)."""
        stat = np.sort(self.null_maxima(family, n_boot, seed))
        if not stat.size:
            return math.inf
        k = math.ceil((stat.size + 1) * (1.0 - alpha) - 1e-9)
        return float(stat[min(k, stat.size) - 1])


def exact_covariance(m, n_samples, fs, terms, theta) -> np.ndarray:
    """Covariance of overlapping AVAR estimates at ``m`` for the five-term model ``theta`` (squared
    coefficients ordered as ``terms``)."""
    s_blk, t_blk = _covariance.covariance_blocks(m, n_samples, fs, terms)
    return _covariance.assemble(s_blk, t_blk, theta, terms)
