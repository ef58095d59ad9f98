"""A line of few cycles: a sinusoid of 3 to 18 cycles in the record, below the Welch line search's reach.

The line search (:func:`allanite.model.lines.find_lines`) reaches down to 18/T (T the record): three half-record
segments, a bin's neighbours beyond the window's main lobe. Below it a daily line in a record of a few days (a
tiltmeter's, a clock's, a thermal day/night cycle) has no neighbourhood to stand out of, and there the spectrum of
the noise is red (flicker, random walk), so a periodogram of white-noise law mistakes the noise for lines.

:func:`slow_line_test` tests it in time: the record's :data:`BLOCKS` block means (each block's mean, every
frequency tested is far below their Nyquist) are fitted as a constant, a ramp and settling drifts
(:data:`SETTLING`) under a noise of three parts — white, random walk and flicker (a fractionally integrated
noise, d = :data:`FLICKER_D`) — by restricted maximum likelihood; under that covariance every frequency from
:data:`SCAN_CYCLES`/T to the search's floor is tested by the generalised least-squares χ² of a sinusoid beside
those terms (2 degrees of freedom), and the record's statistic is the largest over a grid of quarter-cycle steps.
Its null law is drawn, not assumed: the whitened block means are independent unit normals under the null, so
:data:`DRAWS` draws of them through the same projections give the maximum's law with the scan's look-elsewhere in
it; the line is found where the statistic passes that law's (1 − ``alpha``/2) quantile and its frequency is at least
:data:`MIN_CYCLES`/T (a maximum below is a power rising toward 0 Hz, not a line: ``below_band``).

The noise is read twice (:data:`READINGS`), each reading tested at ``alpha``/2 (Bonferroni: the test's false-alarm
probability stays ``alpha``). The first reading is the scan above. Its noise, fitted without the line, takes part of
a line's own low-frequency power as random walk or flicker: a daily line of 0.02 under flicker FM over 5 days was
found on 0 of 20 records under that fit, 14 of 20 under the fit of the same noise without the line (round r14slowred).
The second reading lets the noise be fitted again beside the line: its statistic is the likelihood ratio (maximum
likelihood, the noise's three parts refitted in both models) of the null's fixed effects with and without a
sinusoid at the first scan's best frequency. Its null law is a parametric bootstrap: :data:`BOOT_DRAWS` block-mean
records drawn from the first reading's fitted noise (white, random walk and flicker, no line), each read as the
record is — the noise fitted, the scan, its best frequency, both maximum-likelihood fits — so the draws carry the
estimator's own spread; their quantiles (:data:`BOOT_QUANTILES`) are matched by an affine map to the first reading's
maximum law (its :data:`DRAWS` known-covariance draws), whose tail then gives the α/2 threshold and the p-value (the
bootstrap alone cannot reach α/2 = 2·10⁻⁴; the ratio's law is that maximum's, stretched: on a clock null its
quantiles 0.5–0.99 lie on one line against the maximum's, slope 1.45). The bootstrap runs only where the ratio
passes the maximum's own (1 − α/2) quantile (the map never lowers a threshold below it), so a clean record pays one
more pair of fits, not the draws. The fits (:mod:`allanite.model._slowfit`) take the deviances' gradients in ln r
analytically, and the draws' restricted fits start from one grid evaluated for all draws at once.

A line of few cycles and a slow drift are nearly collinear: the result says how much of the line's whitened signal
the constant, the ramp and the settling drifts cannot take (``separable``), and its amplitude's interval is the
generalised least squares' beside them.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.linalg import cho_factor, cho_solve, solve_triangular

from .._blas import one_thread
from ..errors import ParameterError
from ._slowfit import FLICKER_D, LOG_R_BOUNDS, ml_fit, noise_parts, reml_fit, reml_starts

__all__ = ["slow_line_test", "MIN_CYCLES", "BLOCKS", "DRAWS", "FLICKER_D", "LOG_R_BOUNDS"]

#: The fewest cycles in the record a line is found at.
MIN_CYCLES = 3.0
#: The scan starts lower, at this many cycles: a maximum below :data:`MIN_CYCLES` is a power that rises toward the
#: lowest frequencies — a slow wander or a deterministic excursion the null's drifts do not take (a temperature's
#: coupling over 25 h read as 3.0 cycles), not a line standing out of its neighbours — and finds nothing.
SCAN_CYCLES = 2.0
#: Block means the record is read as (their Nyquist, BLOCKS/2 cycles, far above the 18 the test reaches).
BLOCKS = 128
#: Draws of the whitened null the scan's maximum is calibrated with.
DRAWS = 20_000
#: The two readings of the noise the scan is tested under, each at half the test's α (Bonferroni): the scan under
#: the noise fitted without the line (``"whole"``), and the likelihood ratio with the noise refitted beside the
#: scan's best sinusoid (``"refit"``), calibrated by a parametric bootstrap.
READINGS = ("whole", "refit")
#: The bootstrap's records (each: one restricted and two maximum-likelihood fits of the noise).
BOOT_DRAWS = 120
#: The quantiles of the bootstrap's ratios matched (least squares, affine) to the first reading's maximum's.
BOOT_QUANTILES = tuple(np.linspace(0.5, 0.95, 10))
#: The scan's step, cycles in the record.
STEP_CYCLES = 0.25
#: The settling drifts beside the constant and the ramp in the null: e^{−t/τ} at these τ/T (a warm-up's, a
#: tiltmeter's settling, any exponential between, as their span), so that a drift is not read as a line.
SETTLING = (0.01, 0.03, 0.1, 0.3)


def _nuisance(t: np.ndarray, length: float) -> np.ndarray:
    """The null's fixed effects at block times ``t``: a constant, a ramp and the settling drifts of
    :data:`SETTLING`."""
    t0 = t - t[0]
    cols = [np.ones_like(t), (t - t.mean()) / length] + [np.exp(-t0 / (s * length)) for s in SETTLING]
    return np.column_stack(cols)


def _noise_fit(z: np.ndarray, x: np.ndarray, parts: tuple, start: np.ndarray | None = None) -> tuple:
    """The null's covariance of the block means (REML from ``start``, by default the best of a grid; σ²
    included) and its (r₁, r₂)."""
    r = np.exp(reml_fit(z, x, parts, start))
    cov = np.eye(z.size) + r[0] * parts[0] + r[1] * parts[1]
    c = cho_factor(cov, lower=True)
    beta = np.linalg.lstsq(x.T @ cho_solve(c, x), x.T @ cho_solve(c, z), rcond=None)[0]
    e = z - x @ beta
    sigma2 = float(e @ cho_solve(c, e)) / (z.size - x.shape[1])
    return sigma2 * cov, r


def _sincos(t: np.ndarray, f: float) -> np.ndarray:
    return np.column_stack([np.sin(2 * np.pi * f * t), np.cos(2 * np.pi * f * t)])


def _whitened_basis(lw: np.ndarray, t: np.ndarray, x0w_q: np.ndarray, freqs: np.ndarray) -> np.ndarray:
    """Per frequency an orthonormal pair: the whitened sinusoid's columns less their part in the whitened
    constant and ramp (the null's fixed effects), shape (m, 2·len(freqs)) — the pairs all at once, each
    orthonormalised by Gram–Schmidt twice (the pair's plane is what the scan reads, not its axes)."""
    phase = 2 * np.pi * np.outer(t, freqs)
    cw = solve_triangular(lw, np.concatenate([np.sin(phase), np.cos(phase)], axis=1), lower=True)
    cw -= x0w_q @ (x0w_q.T @ cw)
    a, b = cw[:, : freqs.size], cw[:, freqs.size :]
    a = a / np.linalg.norm(a, axis=0)
    for _ in range(2):
        b = b - a * np.sum(a * b, axis=0)
    out = np.empty((t.size, 2 * freqs.size))
    out[:, 0::2], out[:, 1::2] = a, b / np.linalg.norm(b, axis=0)
    return out


def _scan_max(w: np.ndarray, basis: np.ndarray) -> np.ndarray:
    """The scan's statistic (largest χ² over the frequencies) of each row of whitened block means ``w``."""
    proj = w @ basis
    return np.max(proj[:, 0::2] ** 2 + proj[:, 1::2] ** 2, axis=1)


def _block_means(y: np.ndarray, fs: float, blocks: int) -> tuple[np.ndarray, np.ndarray, float]:
    """``blocks`` block means of ``y`` (the remainder samples at the end left out), their mid-times (s), and the
    block's length (s)."""
    m = y.size // blocks
    z = np.asarray(y[: m * blocks], dtype=np.float64).reshape(blocks, m).mean(axis=1)
    t = (np.arange(blocks) + 0.5) * m / fs
    return z, t, m / fs


def slow_line_test(
    y: np.ndarray, fs: float, alpha: float, f_max: float | None = None, seed: int = 0, calibrate: bool = False
) -> dict | None:
    """A line of :data:`MIN_CYCLES` to ``f_max``·T cycles (default 18) in ``y`` (rate samples at ``fs``), tested at
    false-alarm probability ``alpha`` per record under the fitted white, random-walk and flicker noise of its block
    means (see the module's docstring). None where the record holds fewer than :data:`BLOCKS` × 8 samples or the
    band is empty.

    Each of the two readings (:data:`READINGS`) is tested at α/2. The null's draws are skipped (unless
    ``calibrate``) where neither statistic reaches −2·ln(α/2), one frequency's χ²₂ quantile, below the maximum's:
    then ``threshold`` is that bound and ``p_value`` None; the second reading's bootstrap is skipped where its ratio
    does not pass the first reading's maximum law's (1 − α/2) quantile (its ``p_value`` None, the quantile its
    ``threshold``), and where the first reading has found the line (its ``threshold`` None).

    Returns ``accepted``, ``statistic`` and ``threshold`` (of the reading that decided, ``reading``: the first's
    unless only the second found the line), ``alpha``, ``p_value`` (Bonferroni, twice the smaller of the readings'
    p-values computed; None where none was), ``readings`` (per reading its ``statistic``, ``threshold``,
    ``p_value``, ``accepted``; the second's ``bootstrap``: its draws and the affine map's ``offset`` and
    ``slope``), ``f0`` (Hz, the scan's maximum refined) and ``f0_sd``, ``cycles``, ``amplitude`` and
    ``amplitude_sd`` (generalised least squares beside a constant, a ramp and settling drifts, the block means'
    averaging undone, under the deciding reading's noise), ``phase`` (rad, of A·sin(2πf0·t + φ), t from the first
    sample), ``separable``, ``noise`` (the deciding reading's relative random-walk and flicker variances) and
    ``band_hz``."""
    if not (isinstance(alpha, (int, float)) and 0.0 < alpha < 1.0):
        raise ParameterError(f"alpha must be a probability in (0, 1), got {alpha!r}")
    if not (isinstance(fs, (int, float)) and math.isfinite(fs) and fs > 0.0):
        raise ParameterError(f"fs must be a positive finite sampling rate (Hz), got {fs!r}")
    with one_thread():  # small matrices, many products: OpenBLAS's threads cost more than they give (_blas)
        return _tested(np.asarray(y, dtype=np.float64), float(fs), float(alpha), f_max, seed, calibrate)


def _tested(y: np.ndarray, fs: float, alpha: float, f_max: float | None, seed: int, calibrate: bool) -> dict | None:
    """:func:`slow_line_test` on checked arguments: both readings of the noise (:data:`READINGS`), each at α/2."""
    n = y.size
    length = n / fs
    f_max = 18.0 / length if f_max is None else float(f_max)
    f_min = MIN_CYCLES / length
    if n < 8 * BLOCKS or not f_max > f_min:
        return None
    z, t, tb = _block_means(y, fs, BLOCKS)
    x0 = _nuisance(t, length)
    freqs = np.arange(SCAN_CYCLES / length, f_max + 1e-12 / length, STEP_CYCLES / length)
    half = alpha / 2.0
    whole = _whole(z, t, x0, freqs)
    ratio = _ratio(z, t, x0, freqs, whole)
    stats = (float(whole["chi"].max()), ratio["lr"])
    bound = -2.0 * math.log(half)  # one frequency's (1 − α/2) quantile: below the maximum's (and the map's)
    draws = _null_draws(whole["basis"], seed) if calibrate or max(stats) > bound else None
    first = _judged(stats[0], draws, half, bound)
    bests = (float(freqs[int(np.argmax(whole["chi"]))]), ratio["f"])
    first["below"] = bests[0] < f_min - 1e-9 * f_min  # the maximum below MIN_CYCLES: power rising toward 0 Hz
    first["accepted"] = bool(first["statistic"] > first["threshold"]) and not first["below"]
    if first["accepted"] and not calibrate:  # the second reading could not change the decision: not read
        second = {"statistic": stats[1], "threshold": None, "p_value": None, "bootstrap": None, "accepted": False}
    else:
        second = _refit_judged(z, t, x0, freqs, whole, ratio, draws, half, seed, calibrate)
        second["accepted"] = bool(second["statistic"] > second["threshold"]) and not bests[1] < f_min - 1e-9 * f_min
    second["below"] = bests[1] < f_min - 1e-9 * f_min
    runs = [first, second]
    i = 1 if runs[1]["accepted"] and not runs[0]["accepted"] else 0  # the first reading's, unless only the other
    lw = whole["lw"] if i == 0 else np.linalg.cholesky(ratio["cov"])
    fit = _line_fit(z, t, x0, lw, bests[i], length, tb)
    p_values = [u["p_value"] for u in runs if u["p_value"] is not None]
    r = whole["r"] if i == 0 else ratio["r"]
    return fit | {
        "accepted": any(u["accepted"] for u in runs),
        "below_band": bool(runs[i]["below"]),
        "statistic": runs[i]["statistic"],
        "threshold": runs[i]["threshold"],
        "alpha": float(alpha),
        "p_value": min(1.0, 2.0 * min(p_values)) if p_values else None,  # Bonferroni over the two readings
        "reading": READINGS[i],
        "readings": {READINGS[k]: {key: v for key, v in u.items() if key != "below"} for k, u in enumerate(runs)},
        "cycles": fit["f0"] * length,
        "noise": {"random_walk": float(r[0]), "flicker": float(r[1])},
        "band_hz": (float(f_min), float(f_max)),
        "scanned_hz": (float(freqs[0]), float(f_max)),
    }


def _whole(z: np.ndarray, t: np.ndarray, x0: np.ndarray, freqs: np.ndarray, start: np.ndarray | None = None) -> dict:
    """The first reading: the noise's REML fit beside the null's fixed effects ``x0`` (from ``start``, by default
    the best of a grid), and the scan under it — ``chi`` (the χ² at each of ``freqs``), ``basis`` (the whitened
    sinusoids), ``lw`` (the covariance's Cholesky factor), ``r`` (the relative random-walk and flicker variances)
    and ``parts`` (those two parts' covariances)."""
    parts = noise_parts(z.size)
    cov, r = _noise_fit(z, x0, parts, start)
    lw = np.linalg.cholesky(cov)
    x0w_q, _ = np.linalg.qr(solve_triangular(lw, x0, lower=True))
    basis = _whitened_basis(lw, t, x0w_q, freqs)
    zw = solve_triangular(lw, z, lower=True)
    zw -= x0w_q @ (x0w_q.T @ zw)
    proj = zw @ basis
    return {"chi": proj[0::2] ** 2 + proj[1::2] ** 2, "basis": basis, "lw": lw, "r": r, "parts": parts}


def _null_draws(basis: np.ndarray, seed: int) -> np.ndarray:
    """:data:`DRAWS` draws of the first reading's scan maximum under its null (whitened block means i.i.d.
    N(0, 1)): the scan's look-elsewhere in its law."""
    rng = np.random.default_rng(seed)
    return np.concatenate([_scan_max(rng.standard_normal((DRAWS // 4, basis.shape[0])), basis) for _ in range(4)])


def _judged(stat: float, draws: np.ndarray | None, alpha: float, bound: float) -> dict:
    """A statistic against draws of its null law at ``alpha``; without draws (the statistic below ``bound``, a
    lower bound of the law's quantile) that bound is the threshold and the p-value is None."""
    if draws is None:
        return {"statistic": stat, "threshold": bound, "p_value": None}
    p = float((1 + np.count_nonzero(draws >= stat)) / (1 + draws.size))
    return {"statistic": stat, "threshold": float(np.quantile(draws, 1.0 - alpha)), "p_value": p}


def _ratio(z: np.ndarray, t: np.ndarray, x0: np.ndarray, freqs: np.ndarray, whole: dict, bootstrap=False) -> dict:
    """The second reading's statistic: the likelihood ratio of the null's fixed effects ``x0`` with and without a
    sinusoid at the first reading's best frequency, the noise refitted in each (maximum likelihood, started at
    the first reading's fit) — ``lr``, ``f`` (Hz), ``cov`` (the noise beside the sinusoid) and its ``r``."""
    parts = whole["parts"]
    f = float(freqs[int(np.argmax(whole["chi"]))])
    d0, th0 = ml_fit(z, x0, parts, np.log(np.maximum(whole["r"], 1e-300)))
    x1 = np.column_stack([x0, _sincos(t, f)])
    d1, th1 = ml_fit(z, x1, parts, th0)
    if bootstrap:  # a draw's ratio is all its reading gives
        return {"lr": max(d0 - d1, 0.0), "f": f}
    r = np.exp(th1)
    cov = np.eye(z.size) + r[0] * parts[0] + r[1] * parts[1]
    c = cho_factor(cov, lower=True)
    e = z - x1 @ np.linalg.lstsq(x1.T @ cho_solve(c, x1), x1.T @ cho_solve(c, z), rcond=None)[0]
    sigma2 = float(e @ cho_solve(c, e)) / (z.size - x1.shape[1])
    return {"lr": max(d0 - d1, 0.0), "f": f, "cov": sigma2 * cov, "r": r}


def _refit_judged(z, t, x0, freqs, whole, ratio, draws, alpha, seed, calibrate) -> dict:
    """The second reading's ratio judged at ``alpha``: against the first reading's maximum law (``draws``)
    stretched by the affine map that matches it to the bootstrap's ratios (:func:`_boot_map`), never below it.
    No bootstrap where the ratio does not pass that law's own (1 − ``alpha``) quantile (unless ``calibrate``): the
    quantile is then the threshold and the p-value None."""
    lr = ratio["lr"]
    if draws is None:  # both statistics below one frequency's bound
        return {"statistic": lr, "threshold": -2.0 * math.log(alpha), "p_value": None, "bootstrap": None}
    floor = float(np.quantile(draws, 1.0 - alpha))
    if not calibrate and lr <= floor:
        return {"statistic": lr, "threshold": floor, "p_value": None, "bootstrap": None}
    a, b = _boot_map(z, t, x0, freqs, whole, draws, seed)
    mapped = np.maximum(draws, a + b * draws)
    out = _judged(lr, mapped, alpha, floor)
    return out | {"bootstrap": {"draws": BOOT_DRAWS, "offset": a, "slope": b}}


def _boot_map(z, t, x0, freqs, whole, draws, seed) -> tuple[float, float]:
    """The affine map (offset, slope ≥ 0) from the first reading's maximum law (``draws``) to the second
    reading's ratio under the null, matched on :data:`BOOT_QUANTILES` by least squares: the ratios of
    :data:`BOOT_DRAWS` block-mean records drawn from the first reading's fitted noise (no line), each read as the
    record is — the noise's fit (its start the best of the grid, evaluated for all draws at once), the scan, its
    best frequency, the two maximum-likelihood fits."""
    rng = np.random.default_rng(seed + 1)
    zs = whole["lw"] @ rng.standard_normal((BOOT_DRAWS, z.size)).T  # a draw a column
    starts = reml_starts(zs, x0, whole["parts"])  # the noise fits' grid, one factorisation a point for all draws
    boot = np.empty(BOOT_DRAWS)
    for k in range(BOOT_DRAWS):
        zk = np.ascontiguousarray(zs[:, k])
        boot[k] = _ratio(zk, t, x0, freqs, _whole(zk, t, x0, freqs, starts[k]), bootstrap=True)["lr"]
    q = np.array(BOOT_QUANTILES)
    slope, offset = np.polyfit(np.quantile(draws, q), np.quantile(boot, q), 1)
    return float(offset), float(max(slope, 0.0))


def _gls(zw: np.ndarray, xw: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Coefficients and their covariance of whitened least squares (unit noise variance)."""
    xtx_inv = np.linalg.inv(xw.T @ xw)
    return xtx_inv @ (xw.T @ zw), xtx_inv


def _line_fit(z, t, x0, lw, f0, length, tb) -> dict:
    """The line at the scan's best frequency refined (the GLS χ² on a fine grid within a quarter cycle), its
    amplitude, phase and their SDs (GLS beside the null's fixed effects ``x0``; the frequency's SD from the
    linearised model's derivative column) and the share of it those effects cannot take."""
    k = x0.shape[1]
    zw = solve_triangular(lw, z, lower=True)

    def design(f: float) -> np.ndarray:
        return np.column_stack([x0, _sincos(t, f)])

    def chi2(f: float) -> float:
        xw = solve_triangular(lw, design(f), lower=True)
        beta, _c = _gls(zw, xw)
        return float(zw @ zw - (xw @ beta) @ zw)

    fine = f0 + np.linspace(-STEP_CYCLES, STEP_CYCLES, 21) / length
    f0 = float(min(fine, key=chi2))
    xw = solve_triangular(lw, design(f0), lower=True)
    beta, cov = _gls(zw, xw)
    s, c = float(beta[k]), float(beta[k + 1])
    # the frequency's SD: the model's derivative in f, 2πt(s·cos − c·sin), a fifth column (Gauss–Newton)
    d = 2 * np.pi * t * (s * np.cos(2 * np.pi * f0 * t) - c * np.sin(2 * np.pi * f0 * t))
    _b5, cov5 = _gls(zw, np.column_stack([xw, solve_triangular(lw, d, lower=True)]))
    f_var = float(cov5[-1, -1])
    gain = float(abs(np.sinc(f0 * tb)))  # a block mean's gain on a sinusoid (np.sinc(x) = sin(πx)/(πx))
    amp = math.hypot(s, c)
    g = np.array([s, c]) / max(amp, 1e-300)
    amp_sd = math.sqrt(max(float(g @ cov[k:, k:] @ g), 0.0))
    # how much of the line's whitened signal the constant, the ramp and the settling drifts cannot take
    sig = xw[:, k:] @ beta[k:]
    qd, _ = np.linalg.qr(xw[:, :k])
    left = sig - qd @ (qd.T @ sig)
    return {
        "f0": f0,
        "f0_sd": math.sqrt(max(f_var, 0.0)),
        "amplitude": amp / gain,
        "amplitude_sd": amp_sd / gain,
        "phase": math.atan2(c, s),
        "separable": float(left @ left / max(float(sig @ sig), 1e-300)),
    }
