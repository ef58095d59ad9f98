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
it; the line is found where the statistic passes that law's (1 − ``alpha``) quantile and its frequency is at least
:data:`MIN_CYCLES`/T (a maximum below is a power rising toward 0 Hz, not a line: ``below_band``).

A line of few cycles and a slow drift are nearly collinear: the result says how much of the line's whitened signal
the constant, the ramp and the settling drifts cannot take (``separable``), and its amplitude's interval is the
generalised least squares' beside them.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.linalg import cho_factor, cho_solve, solve_triangular
from scipy.optimize import minimize

from .._blas import one_thread
from ..errors import ParameterError

__all__ = ["slow_line_test", "MIN_CYCLES", "BLOCKS", "DRAWS"]

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
#: The flicker part's fractional difference (d → ½ is 1/f; below it the noise is stationary).
FLICKER_D = 0.45
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


def _flicker_cov(m: int) -> np.ndarray:
    """Autocorrelation of fractionally integrated noise (d = FLICKER_D) at lags 0 … m−1, as a Toeplitz matrix."""
    k = np.arange(1, m)
    rho = np.concatenate([[1.0], np.cumprod((k - 1 + FLICKER_D) / (k - FLICKER_D))])
    idx = np.abs(np.arange(m)[:, None] - np.arange(m)[None, :])
    return rho[idx]


def _parts(m: int) -> tuple[np.ndarray, np.ndarray]:
    """The random walk's (its variance 1 at the record's end) and the flicker's covariance of m block means."""
    i = np.arange(m)
    rw = (np.minimum(i[:, None], i[None, :]) + 1.0) / m
    return rw, _flicker_cov(m)


def _reml(z: np.ndarray, x: np.ndarray, parts: tuple, logr: np.ndarray) -> float:
    """−2 × the restricted log-likelihood of ``z`` (fixed effects ``x``) under σ²(I + r₁·RW + r₂·flicker), σ²
    profiled out."""
    r = np.exp(np.clip(logr, -30.0, 30.0))
    cov = np.eye(z.size) + r[0] * parts[0] + r[1] * parts[1]
    try:
        c = cho_factor(cov, lower=True)
    except np.linalg.LinAlgError:
        return float("inf")
    ci_x, ci_z = cho_solve(c, x), cho_solve(c, z)
    xtx = x.T @ ci_x
    beta = np.linalg.solve(xtx, x.T @ ci_z)
    rss = float(z @ ci_z - (x.T @ ci_z) @ beta)
    dof = z.size - x.shape[1]
    logdet = 2.0 * float(np.sum(np.log(np.diag(c[0]))))
    return dof * math.log(max(rss / dof, 1e-300)) + logdet + float(np.linalg.slogdet(xtx)[1])


def _noise_fit(z: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The null's covariance of the block means (REML, σ² included) and its (r₁, r₂)."""
    parts = _parts(z.size)
    grid = [np.array([a, b]) for a in (-8.0, -2.0, 4.0) for b in (-8.0, -2.0, 4.0)]
    start = min(grid, key=lambda g: _reml(z, x, parts, g))
    res = minimize(lambda g: _reml(z, x, parts, g), start, method="L-BFGS-B", bounds=[(-20.0, 12.0)] * 2)
    r = np.exp(res.x)
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
    constant and ramp (the null's fixed effects), shape (m, 2·len(freqs))."""
    out = np.empty((t.size, 2 * freqs.size))
    for i, f in enumerate(freqs):
        cw = solve_triangular(lw, _sincos(t, f), lower=True)
        cw -= x0w_q @ (x0w_q.T @ cw)
        q, _r = np.linalg.qr(cw)
        out[:, 2 * i : 2 * i + 2] = q
    return out


def _scan_max(w: np.ndarray, basis: np.ndarray) -> np.ndarray:
    """The scan's statistic (largest χ² over the frequencies) of each row of whitened block means ``w``."""
    proj = w @ basis
    return np.max(proj[:, 0::2] ** 2 + proj[:, 1::2] ** 2, axis=1)


def _null_quantile(basis: np.ndarray, alpha: float, seed: int) -> tuple[float, np.ndarray]:
    """The scan maximum's (1 − ``alpha``) quantile under the null (whitened block means i.i.d. N(0, 1)), and
    the draws."""
    rng = np.random.default_rng(seed)
    draws = np.concatenate([_scan_max(rng.standard_normal((DRAWS // 4, basis.shape[0])), basis) for _ in range(4)])
    return float(np.quantile(draws, 1.0 - alpha)), draws


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

    The null's draws are skipped (unless ``calibrate``) where the statistic does not reach −2·ln α, one
    frequency's χ²₂ quantile, below the maximum's: then ``threshold`` is that bound and ``p_value`` None.

    Returns ``accepted``, ``statistic`` (the scan's largest χ², 2 dof), ``threshold``, ``alpha``, ``p_value`` (of
    the draws), ``f0`` (Hz, the scan's maximum refined) and ``f0_sd``, ``cycles``, ``amplitude`` and
    ``amplitude_sd`` (generalised least squares beside a constant, a ramp and settling drifts, the block means'
    averaging undone), ``phase`` (rad, of A·sin(2πf0·t + φ), t from the first sample), ``separable``, ``noise``
    (the null fit's relative random-walk and flicker variances) and ``band_hz``."""
    if not (isinstance(alpha, (int, float)) and 0.0 < alpha < 1.0):
        raise ParameterError(f"alpha must be a probability in (0, 1), got {alpha!r}")
    if not (isinstance(fs, (int, float)) and math.isfinite(fs) and fs > 0.0):
        raise ParameterError(f"fs must be a positive finite sampling rate (Hz), got {fs!r}")
    with one_thread():  # small matrices, many products: OpenBLAS's threads cost more than they give (_blas)
        return _tested(np.asarray(y, dtype=np.float64), float(fs), float(alpha), f_max, seed, calibrate)


def _tested(y: np.ndarray, fs: float, alpha: float, f_max: float | None, seed: int, calibrate: bool) -> dict | None:
    """:func:`slow_line_test` on checked arguments."""
    n = y.size
    length = n / fs
    f_max = 18.0 / length if f_max is None else float(f_max)
    f_min = MIN_CYCLES / length
    if n < 8 * BLOCKS or not f_max > f_min:
        return None
    f_scan = SCAN_CYCLES / length
    z, t, tb = _block_means(y, fs, BLOCKS)
    x0 = _nuisance(t, length)
    cov, r = _noise_fit(z, x0)
    lw = np.linalg.cholesky(cov)
    x0w_q, _ = np.linalg.qr(solve_triangular(lw, x0, lower=True))
    freqs = np.arange(f_scan, f_max + 1e-12 / length, STEP_CYCLES / length)
    basis = _whitened_basis(lw, t, x0w_q, freqs)
    zw = solve_triangular(lw, z, lower=True)
    zw -= x0w_q @ (x0w_q.T @ zw)
    stats = _scan_max(zw[None, :], basis)[0]
    if calibrate or stats > -2.0 * math.log(alpha):
        thr, draws = _null_quantile(basis, alpha, seed)
        p_value: float | None = float((1 + np.count_nonzero(draws >= stats)) / (1 + draws.size))
    else:  # below one frequency's (1 − α) quantile: below the maximum's, no draws needed
        thr, p_value = -2.0 * math.log(alpha), None
    proj = zw @ basis
    best = float(freqs[int(np.argmax(proj[0::2] ** 2 + proj[1::2] ** 2))])
    fit = _line_fit(z, t, x0, lw, best, length, tb)
    below = best < f_min - 1e-9 / length  # the maximum below MIN_CYCLES: power rising toward 0 Hz, no line
    return fit | {
        "accepted": bool(stats > thr) and not below,
        "below_band": bool(below),
        "statistic": float(stats),
        "threshold": thr,
        "alpha": float(alpha),
        "p_value": p_value,
        "cycles": fit["f0"] * length,
        "noise": {"random_walk": float(r[0]), "flicker": float(r[1])},
        "band_hz": (float(f_min), float(f_max)),
        "scanned_hz": (float(f_scan), float(f_max)),
    }


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
