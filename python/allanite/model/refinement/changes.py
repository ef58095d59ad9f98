"""Change points: steps of the noise level along the record (needs the samples).

The Allan variances of 16 non-overlapping windows (octave τ), in logs, are partitioned into segments of one
level each by optimal partitioning (exact dynamic programming over the windows): the partition minimises the
windows' weighted scatter about their segments' levels plus a penalty per change point, so it takes as many
change points as the evidence pays for — a pump or a fan switching on and off, several stretches — where the
binary segmentation before it took at most two and, on a stretch that switches on and off again, often none
(one split of an on/off/on pattern gains little). The penalty per change point is the one calibrated on clean
records for that search (τ count per octave × ln 16 + 4 ``MIN_GAIN``), kept: the criterion's false-alarm rate is
measured again by simulation on 400 clean records (``benches/change_points_null.py``; the search alone, before
refine's held-out check per segment). Each τ's weight is 1/var of a window's log σ̂², the larger of the EDF's
2/ν and the robust scatter of consecutive windows, read from their lower quartile (|difference| of |N(0, s²)|:
0.3186 s — a record with many changes has up to half its differences across one, which the median took for
scatter). Not re-read without the differences across the change points found: on the ADIS16405 accelerometers,
whose level wanders, each round took the largest differences out and found more (run 6 acc_z: 5 change points
where one round finds 3 and binary segmentation found none). Cost: the windows' Allan variances, O(N) per
τ; the partition O(16² × τ). Each change point is located to the sample by a two-segment likelihood of the
squared m-sample differences at the τ of its largest gain, within the window either side of its bound (the
partition put the change in one of those two: a change deeper in a segment would have moved the bound) and at
least an eighth of a window from that span's ends (a change there would have been the next bound, and the
likelihood favours a short segment at an end where the level wanders), not across every window between its
neighbours — there a short burst far from the bound won the two-segment likelihood (ADIS16405 run 1 acc_z: a 6 s
burst 2–8 s from the start, 4× the level at τ 0.16 s, located a bound at 1875 s at 7.8 s;
``benches/results/wander_measured.md``); a window straddling a change is a segment of its own where the
partition makes it one, so one change may come from two bounds: located within an eighth of a window of each other
(or with overlapping intervals) they are one. Two changes closer than that are one; a stretch shorter than a
window shows as one window's level.

Its statistic is on the windows' levels, not on the Allan curve: a change point's before/after says how the
windows' piecewise-constant levels without and with it, every other one in both, describe them. On the
record's own Allan curve a change of noise level changes nothing: the curve of a record whose level steps is
the length-weighted mean of its segments' curves, a model of the same terms with pooled coefficients, which
the fit of the whole curve already is. Where the louder segments carry a noise outside the five terms (band noise
switched on and off), the record's curve departs from that model only because of them: which of the ``"allan"``
check's departures those are, and the factor each change point made per τ, is :mod:`._segments`'s.
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
        self.floor = 2.0 / nu
        c = np.zeros((self.lav.shape[0], self.lav.shape[1] + 1))
        self.c1, self.c2 = c.copy(), c
        self.c1[:, 1:] = np.cumsum(self.lav, axis=1)
        self.c2[:, 1:] = np.cumsum(self.lav**2, axis=1)
        self.reweigh()

    def reweigh(self) -> None:
        """1/var(log σ̂²) per τ: ν/2 for white rate, but long τ scatter more (fewer degrees of freedom for
        flicker/random walk): the larger of 2/ν and the robust scatter of consecutive windows, read from their
        lower quartile (|difference| of |N(0, s²)|: 0.3186 s) — a record with many changes has up to half its
        differences across one, which the median took for the windows' own scatter (blind7's pump: 7 of 15)."""
        diffs = np.abs(np.diff(self.lav, axis=1))
        sd = np.quantile(diffs, 0.25, axis=1) / 0.3186
        self.w = 1.0 / np.maximum(self.floor, sd**2 / 2.0)

    def cost_tau(self, a, b) -> np.ndarray:
        """Weighted scatter of windows a..b about their mean, per τ."""
        s, q = self.c1[:, b] - self.c1[:, a], self.c2[:, b] - self.c2[:, a]
        return self.w * np.maximum(q - s**2 / (b - a), 0.0)

    def partition(self, penalty) -> list:
        """Window indices of the change points minimising the windows' weighted scatter about one level per
        segment + ``penalty`` per change point: optimal partitioning, exact (dynamic programming over the
        windows, O(windows² × τ)); a segment may be one window long."""
        nw = self.lav.shape[1]
        cost = np.full((nw + 1, nw + 1), np.inf)
        for a in range(nw):
            for b in range(a + 1, nw + 1):
                cost[a, b] = float(np.sum(self.cost_tau(a, b)))
        best, back = np.zeros(nw + 1), np.zeros(nw + 1, dtype=int)
        best[0] = -penalty
        for b in range(1, nw + 1):
            tot = best[:b] + cost[:b, b] + penalty
            back[b] = int(np.argmin(tot))
            best[b] = tot[back[b]]
        bounds, b = [], nw
        while b > 0:
            b = int(back[b])
            if b > 0:
                bounds.append(b)
        return sorted(bounds)

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


def penalty(lv: _Levels) -> float:
    """The penalty per change point: the windows are independent but the τ of one window are correlated, so
    the τ count per octave (``MIN_GAIN`` calibrated with it on clean records)."""
    n_tau_eff = max(2.0, math.log2(lv.tau[-1] / lv.tau[0]) + 1.0)
    return n_tau_eff * math.log(N_WINDOWS) + 4.0 * MIN_GAIN


def _bounds(lv: _Levels) -> list:
    """The change points' window indices: the windows' optimal partition at the calibrated penalty."""
    return lv.partition(penalty(lv))


def _segment(lv: _Levels, y, fs, window, max_points) -> list:
    """The change points of the windows' levels (:func:`_bounds`), each located to the sample within the window
    either side of its bound (its neighbours' bounds no nearer): [{t, interval, gain, tau, window_s,
    coarse_split_s}] by time."""
    bounds = _bounds(lv)
    edges = [0] + bounds + [N_WINDOWS]
    found = []
    for k, j in enumerate(bounds):
        a, b = edges[k], edges[k + 2]
        gain_tau = lv.cost_tau(a, b) - lv.cost_tau(a, j) - lv.cost_tau(j, b)
        found.append((float(np.sum(gain_tau)), j, int(np.argmax(gain_tau))))
    out: list = []
    for gain, j, k_tau in sorted(found, key=lambda f: -f[0]):
        if max_points is not None and len(out) >= max_points:
            break
        # locate at sample resolution with the squared differences at the τ of the largest gain, at most an
        # eighth of the span (two windows): the two-segment likelihood needs a few terms either side
        lo_s, hi_s = (j - 1) * window, (j + 1) * window  # its neighbours' bounds are no nearer
        m = min(int(lv.m[k_tau]), (hi_s - lo_s) // 8)
        t_hat, t_int = locate(y[lo_s:hi_s], m, fs, guard=window // 8)
        t_abs = t_hat + lo_s / fs
        interval = (t_int[0] + lo_s / fs, t_int[1] + lo_s / fs)
        same = [c for c in out if _same(c, t_abs, interval, window / fs)]
        if same:  # one found already: a window straddling a change is a segment of its own, two bounds
            same[0]["bounds"].append(j)
            continue
        out.append(
            {
                "t": t_abs,
                "interval": interval,
                "gain": gain,
                "tau": float(lv.tau[k_tau]),
                "window_s": window / fs,
                "coarse_split_s": j * window / fs,
                "bounds": [j],
            }
        )
    out.sort(key=lambda c: c["t"])
    return out


def _same(c: dict, t: float, interval: tuple, window_s: float) -> bool:
    """Whether a change located at ``t`` (``interval``) is change point ``c`` found again: their intervals
    overlap, or they lie within an eighth of a window (the windows' levels do not resolve two changes closer
    than that, and two spans' locations of one change differ by a few samples)."""
    overlap = interval[0] <= c["interval"][1] and c["interval"][0] <= interval[1]
    return overlap or abs(c["t"] - t) < window_s / 8


def change_points(y, fs, terms, max_points=None):
    """Level steps of the Allan variance along the record: [{t, interval, gain, tau, window_s, coarse_split_s,
    before, after}] by time (at most ``max_points``, the largest gains), ``before``/``after`` the windows'
    levels about piecewise-constant levels without and with this change point, every other one in both (the
    partition's own question: dropping any one of its change points raises the scatter by more than the
    penalty). The segments are the partition's (:func:`_bounds`): a window that straddles a change is a
    segment of its own where the partition made it one (a change point's bounds, one or two)."""
    window = y.size // N_WINDOWS
    if window < 64:
        return []
    lv = _Levels(y, fs, window)
    out = _segment(lv, y, fs, window, max_points)
    keep = np.ones(N_WINDOWS, dtype=bool)

    def levels(skip: int | None) -> dict:  # the windows about one level per segment, change point skip left out
        edges = [0] + sorted({j for i, c in enumerate(out) if i != skip for j in c["bounds"]}) + [N_WINDOWS]
        return lv.stats([(a, b) for a, b in zip(edges[:-1], edges[1:])], keep)

    after = levels(None)
    for n, c in enumerate(out):
        c["before"], c["after"] = levels(n), dict(after)
    for c in out:
        del c["bounds"]
    return out


def locate(y, m, fs, guard=0):
    """Change in the mean of the squared m-sample second differences: MLE split and 2-unit support, the split
    at least ``guard`` samples from either end of the span (where the span is longer than twice that).

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
    lo = max(2, int(math.ceil(guard / m)))
    lo = lo if 2 * lo <= n else 2
    j = np.arange(lo, n - lo + 1)
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
    construction (``evidence["on_the_curve"]``). What found it is in its evidence:
    ``window_levels`` (the windows' levels about piecewise levels without → with it, every other change point
    in both) and, a chain of its own, ``heldout_test`` (``heldout`` = [without, with]: the final segments'
    held-out parts predicted without → with it, :func:`.scoring.segments_heldout`). ``truth``: the true
    ``{"t": …}`` (s), for the error as a fraction of the record (``duration_s``)."""
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
