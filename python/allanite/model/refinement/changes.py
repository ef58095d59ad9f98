"""Change points: steps of the noise level along the record (needs the samples).

The Allan variances of 16 non-overlapping windows (octave τ), in logs, are split where the weighted
within-segment scatter falls most (binary segmentation, at most two changes); a split is kept when its gain
beats a penalty calibrated on clean records (``MIN_GAIN``), then located to the sample by a two-segment
likelihood of the squared m-sample differences at the τ of the largest gain. Its statistic is on the
windows' levels, not on the Allan curve: a change point's before/after says how the windows' piecewise-
constant levels without and with it (the earlier change points in both) describe them. On the record's own
Allan curve a change of noise level changes nothing: the curve of a record whose level steps is the
length-weighted mean of its segments' curves, a model of the same terms with pooled coefficients, which
the fit of the whole curve already is.
"""

from __future__ import annotations

import math

import numpy as np

from ...analysis import davar
from .. import fitting
from .result import Step

__all__ = ["MIN_GAIN", "N_WINDOWS", "change_points", "change_point_step", "locate"]

#: Kept for the change-point test's penalty (calibrated with it on clean records).
MIN_GAIN = 6.0
#: Windows along the record whose Allan variances are compared.
N_WINDOWS = 16


class _Levels:
    """log-AVAR of the windows (τ × windows) and the weight of each τ (1/var of log σ̂²)."""

    def __init__(self, y, fs, window):
        d = davar(y, fs, window=window, hop=window, taus="octave")
        self.tau, self.m = d.tau, d.m
        self.lav = np.log(np.maximum(d.avar, 1e-300))  # (tau, windows)
        # SD of log σ̂² per τ: from the EDF of the dominant noise (white rate is a fair middle)
        nu = fitting.edf_per_tau(np.zeros(d.m.size, dtype=int), d.m, window + 1, "oavar")
        # 1/var(log σ̂²): ν/2 for white rate, but long τ scatter more (fewer degrees of freedom for
        # flicker/random walk): take the larger of 2/ν and the robust scatter of consecutive windows
        # (median |difference|, insensitive to a few steps).
        mad = 1.4826 * np.median(np.abs(np.diff(self.lav, axis=1)), axis=1)
        self.w = 1.0 / np.maximum(2.0 / nu, mad**2 / 2.0)

    def _scatter(self, x, axis=None):
        return np.sum(self.w[:, None] * (x - x.mean(axis=1, keepdims=True)) ** 2, axis=axis)

    def best_split(self, a, b):
        """(gain, window index of the split, τ index of the largest gain) of the best split of windows a..b."""
        lav = self.lav
        seg = lav[:, a:b]
        best = (0.0, None, None)
        for j in range(a + 1, b):
            left, right = lav[:, a:j], lav[:, j:b]
            gain = self._scatter(seg) - (self._scatter(left) + self._scatter(right))
            if gain > best[0]:
                gain_tau = self._scatter(seg, axis=1) - self._scatter(left, axis=1) - self._scatter(right, axis=1)
                best = (gain, j, int(np.argmax(gain_tau)))
        return best

    def stats(self, segments, keep) -> dict:
        """χ²/dof, RMS z and RMS ADEV error (%) of the windows' levels about one level per segment."""
        parts, k = [], 0
        for a, b in segments:
            sel = np.arange(a, b)[keep[a:b]]
            if sel.size:
                r = self.lav[:, sel] - self.lav[:, sel].mean(axis=1, keepdims=True)
                parts.append(r)
                k += self.lav.shape[0]
        res = np.concatenate(parts, axis=1)
        z = res * np.sqrt(self.w)[:, None]
        return {
            "chi2_dof": float(np.sum(z**2) / max(1, z.size - k)),
            "rms_z": float(np.sqrt(np.mean(z**2))),
            "rms_adev_pct": float(100 * np.sqrt(np.mean((np.exp(res / 2) - 1) ** 2))),
        }


def _segment(lv: _Levels, y, fs, window, max_points) -> list:
    """Binary segmentation of the windows: [{t, interval, gain, tau, window_s, coarse_split_s}] by time."""
    # windows are independent but the τ of one window are correlated: penalise per octave count
    n_tau_eff = max(2.0, math.log2(lv.tau[-1] / lv.tau[0]) + 1.0)
    penalty = n_tau_eff * math.log(N_WINDOWS) + 4.0 * MIN_GAIN
    out: list = []
    stack = [(0, N_WINDOWS)]
    while stack and len(out) < max_points:
        a, b = stack.pop(0)
        if b - a < 3:
            continue
        gain, j, k_tau = lv.best_split(a, b)
        if j is None or gain < penalty:
            continue
        # locate at sample resolution with the squared differences at the τ of the largest gain
        m = int(lv.m[k_tau])
        lo_s, hi_s = a * window, b * window
        t_hat, t_int = locate(y[lo_s:hi_s], m, fs)
        t_abs = t_hat + lo_s / fs
        if any(abs(c["t"] - t_abs) < window / fs for c in out):
            continue
        out.append(
            {
                "t": t_abs,
                "interval": (t_int[0] + lo_s / fs, t_int[1] + lo_s / fs),
                "gain": float(gain),
                "tau": float(lv.tau[k_tau]),
                "window_s": window / fs,
                "coarse_split_s": j * window / fs,
            }
        )
        # search each side again, leaving out the window that straddles the change
        jw = int(t_abs * fs // window)
        stack += [(a, min(jw, j)), (max(jw + 1, j), b)]
    out.sort(key=lambda c: c["t"])
    return out


def change_points(y, fs, terms, max_points=2):
    """Level steps of the Allan variance along the record: [{t, interval, gain, tau, window_s, coarse_split_s,
    before, after}] by time, ``before``/``after`` the windows' levels about piecewise-constant levels without
    and with this change point, the earlier ones in both — a chain of its own: the first change point's before
    is one constant level, each next one's before the previous one's after (windows that straddle any change
    belong to no segment: left out of all)."""
    window = y.size // N_WINDOWS
    if window < 64:
        return []
    lv = _Levels(y, fs, window)
    out = _segment(lv, y, fs, window, max_points)
    cut = [int(c["t"] * fs // window) for c in out]
    keep = np.ones(N_WINDOWS, dtype=bool)
    keep[[j for j in cut if j < N_WINDOWS]] = False

    def levels(n: int) -> dict:  # the windows about one level per segment between the first n changes
        edges = [0] + sorted(cut[:n]) + [N_WINDOWS]
        return lv.stats([(a, b) for a, b in zip(edges[:-1], edges[1:])], keep)

    chain = [levels(n) for n in range(len(out) + 1)]
    for n, c in enumerate(out):
        c["before"], c["after"] = chain[n], chain[n + 1]
    return out


def locate(y, m, fs):
    """Change in the mean of the squared m-sample second differences: MLE split and 2-unit support.

    Each segment's mean square is floored at q²/6, the variance of the difference of two samples' rounding
    errors (Sheppard), when the terms are quantized (some exactly zero; q² their smallest non-zero value): a
    short segment of equal samples would otherwise read as zero noise, an unbounded likelihood that puts the
    split at an end of the span. The tail sums are summed from the end, not as total − head (which cancels to
    zero once the tail falls below the total's last digit)."""
    k = y.size // m
    b = y[: k * m].reshape(k, m).mean(axis=1)
    d0 = np.diff(b) ** 2
    d = d0 + 1e-300  # independent-ish terms at stride m
    n = d.size
    c = np.cumsum(d)
    tail = np.cumsum(d[::-1])[::-1]  # tail[i] = sum of d[i:]
    j = np.arange(2, n - 1)
    mu1 = c[j - 1] / j
    mu2 = tail[j] / (n - j)
    nonzero = d0[d0 > 0]
    if 0 < nonzero.size < n:  # quantized: no segment's mean square below the rounding's own
        floor = float(nonzero.min()) / 6.0
        mu1, mu2 = np.maximum(mu1, floor), np.maximum(mu2, floor)
    ll = -0.5 * (j * np.log(mu1) + (n - j) * np.log(mu2))  # exponential-family profile (χ²₁ terms)
    i = int(np.argmax(ll))
    ok = j[ll >= ll[i] - 2.0]

    def to_t(idx):  # boundary after term idx
        return (idx + 1) * m / fs

    return to_t(j[i]), (to_t(ok.min()) - m / fs, to_t(ok.max()) + m / fs)


def change_point_step(c: dict, heldout: list | None, truth: dict | None, duration_s: float) -> Step:
    """The step of change point ``c`` (:func:`change_points`), its before/after on the chain left to the loop.

    On the record's Allan curve a change of noise level changes nothing: the curve of the whole record is the
    length-weighted mean of its segments', a model of the same terms with pooled coefficients — the fit of the
    whole curve already —, so its before and after there are both the model so far, the same numbers by
    construction (``evidence["on_the_curve"]``). What found it is in its evidence, a chain of its own:
    ``window_levels`` (the windows' levels about piecewise levels without → with it, the earlier change points
    in both) and ``heldout_test`` (``heldout`` = [without, with]: the final segments' held-out parts predicted
    without → with it, :func:`.scoring.segments_heldout`). ``truth``: the true ``{"t": …}`` (s), for the error
    as a fraction of the record (``duration_s``)."""
    terr = None
    if truth is not None:
        terr = {"t": float(np.min(np.abs(np.atleast_1d(truth["t"]) - c["t"])) / duration_s)}
    c["before"]["heldout_rms_adev_pct"] = None if heldout is None else heldout[0]
    c["after"]["heldout_rms_adev_pct"] = None if heldout is None else heldout[1]
    evidence = {
        "domain": "time",
        "tau": c["tau"],
        "window_s": c["window_s"],
        "coarse_split_s": c["coarse_split_s"],
        "gain_chi2": c["gain"],
        "window_levels": {"before": dict(c["before"]), "after": dict(c["after"])},
        "on_the_curve": "a change of noise level leaves the record's Allan curve model as it is: before = after",
    }
    if heldout is not None:
        evidence["heldout_test"] = {"before": heldout[0], "after": heldout[1], "per": "segment"}
    params, intervals = {"t": c["t"]}, {"t": c["interval"]}
    return Step(
        effect="change_point",
        params=params,
        intervals=intervals,
        evidence=evidence,
        before={},
        after={},
        truth_error=terr,
        final_params=dict(params),
        final_intervals=dict(intervals),
    )
