"""The segments between refine's change points: each one's Allan variance, which τ each change point changed
and by what factor, and which of the record's Allan-curve departures the louder segments alone carry.

A change of the noise level leaves the record's Allan curve a length-weighted mean of its segments' curves.
Where the louder segments carry a noise outside the five terms — a pump's band noise on for a few stretches, a
vibration burst — the whole record's curve departs from the model only because of them: the quiet (base-level)
segments, joined, fit the model. :func:`explained_regions` says which of the ``"allan"`` check's regions that
is: it runs the same check, at the same share of ``level``, on the base segments' own curve with the model
refitted there (the same terms and effects); a region of the record's check that the base segments' check does
not find again, at τ where the louder segments' Allan variance differs from the base segments' (by more than
3 SE of their estimates), is the change points' — it is said on their steps (``evidence["explains"]``), not in
``unexplained``. Only regions are taken out: the check on the base segments adds none, so no false alarm can
come from it, and without change points nothing changes.

Each segment's Allan variance is its own overlapping estimate at octave averaging factors up to 1/16 of the
shortest segment (the white-rate EDF for the SE of log σ̂², as the change-point search's floor). The base
segments: the quietest one (lowest mean log AVAR over those τ) and every segment within 3 SE of it at each τ up
to 1/64 of the shortest segment; they must hold at least half the record (``BASE_SHARE``), or nothing is taken —
a short base has too few terms to say that a departure the whole record shows is not its own.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from ...analysis import avar
from .. import fitting, tracing
from ._curve_checks import allan_check
from ._missing_context import MissingContext
from .curvefit import Curve, solve

__all__ = ["Segments", "explained_regions"]

#: the shortest segment whose Allan variance is read (samples)
MIN_SEGMENT = 64
#: the share of the record the base segments must hold for their check to take a region: at least half, so that
#: it has at least half the record's terms (ADIS16405 run 5 acc_z: a base of 916 s in 10⁴ s did not show a
#: departure at τ 30–60 ms that the whole record did, its louder segment 1.05× the base at 20 ms)
BASE_SHARE = 0.5
#: |z| of a difference of two log-AVAR estimates that counts as a level difference
Z_DIFFER = 3.0


class Segments:
    """The segments of ``y`` between change ``times`` (s): bounds (samples), octave m, log AVAR and its variance
    (segments × τ), and which segments are at the base (lowest) level."""

    def __init__(self, y: np.ndarray, fs: float, times) -> None:
        edges = [0] + sorted({int(round(t * fs)) for t in times if 0 < t * fs < y.size}) + [y.size]
        self.bounds = [(a, b) for a, b in zip(edges[:-1], edges[1:]) if b > a]
        self.fs = fs
        short = min(b - a for a, b in self.bounds)
        self.m = 2.0 ** np.arange(max(1, int(math.log2(max(short // 16, 1))) + 1))
        self.tau = self.m / fs
        self.lav = np.empty((len(self.bounds), self.m.size))
        self.var = np.empty_like(self.lav)
        for s, (a, b) in enumerate(self.bounds):
            av = avar(y[a:b], fs, taus=self.tau).avar
            self.lav[s] = np.log(np.maximum(av, 1e-300))
            nu = fitting.edf_per_tau(np.zeros(self.m.size, dtype=int), self.m, b - a + 1, "oavar")
            self.var[s] = 2.0 / np.maximum(nu, 1.0)
        self.base = self._base()

    @classmethod
    def of(cls, y: np.ndarray, fs: float, times) -> Segments | None:
        """The segments between change ``times``; None without a change point or where a segment is shorter than
        ``MIN_SEGMENT`` samples (too few for its own Allan variance)."""
        edges = [0] + sorted({int(round(t * fs)) for t in times if 0 < t * fs < y.size}) + [y.size]
        if len(edges) < 3 or min(np.diff(edges)) < MIN_SEGMENT:
            return None
        return cls(y, fs, times)

    def _base(self) -> np.ndarray:
        """True at the base segments: the quietest and those within ``Z_DIFFER`` SE of it at every τ up to 1/64
        of the shortest segment (more degrees of freedom than the longest τ here)."""
        short = min(b - a for a, b in self.bounds)
        sel = self.m <= max(1, short // 64)
        ref = int(np.argmin(self.lav[:, sel].mean(axis=1)))
        z = (self.lav[:, sel] - self.lav[ref, sel]) / np.sqrt(self.var[:, sel] + self.var[ref, sel])
        base = np.all(np.abs(z) <= Z_DIFFER, axis=1)
        base[ref] = True
        return base

    def times(self, which: np.ndarray) -> list:
        """The segments ``which`` selects, as (start, end) times (s)."""
        return [(a / self.fs, b / self.fs) for (a, b), w in zip(self.bounds, which) if w]

    def ratio_across(self, k: int) -> dict:
        """Change point ``k`` (between segments k and k + 1): the Allan deviation after / before at each τ of
        both, its 95 % interval (the estimates' EDF), and the τ where the change is largest in SE."""
        d = (self.lav[k + 1] - self.lav[k]) / 2.0
        se = np.sqrt(self.var[k + 1] + self.var[k]) / 2.0
        i = int(np.argmax(np.abs(d) / se))
        ratio, lo, hi = np.exp(d), np.exp(d - 1.96 * se), np.exp(d + 1.96 * se)
        return {
            "tau_s": self.tau.tolist(),
            "ratio": ratio.tolist(),
            "interval95": np.column_stack([lo, hi]).tolist(),
            "largest": {
                "tau_s": float(self.tau[i]),
                "ratio": float(ratio[i]),
                "interval95": (float(lo[i]), float(hi[i])),
                "z": float(d[i] / se[i]),
            },
        }

    def louder_at(self, lo: float, hi: float) -> dict | None:
        """Where the non-base segments' log AVAR differs from the base segments' pooled one by more than
        ``Z_DIFFER`` SE at a τ of the segments' grid within (lo/2, 2·hi): {tau_s, adev_ratio, z, segments} at the
        largest |z|; None where none does (or no grid τ lies there)."""
        near = np.flatnonzero((self.tau >= lo / 2) & (self.tau <= 2 * hi))
        other = np.flatnonzero(~self.base)
        if near.size == 0 or other.size == 0:
            return None
        w = 1.0 / self.var[self.base][:, near]
        pooled = np.sum(w * self.lav[self.base][:, near], axis=0) / np.sum(w, axis=0)
        pooled_var = 1.0 / np.sum(w, axis=0)
        z = (self.lav[other][:, near] - pooled) / np.sqrt(self.var[other][:, near] + pooled_var)
        s, j = np.unravel_index(int(np.argmax(np.abs(z))), z.shape)
        if not abs(z[s, j]) > Z_DIFFER:
            return None
        return {
            "tau_s": float(self.tau[near[j]]),
            "adev_ratio": float(np.exp((self.lav[other[s], near[j]] - pooled[j]) / 2.0)),
            "z": float(z[s, j]),
            "segments": self.times(~self.base),
        }

    def base_share(self) -> float:
        """The share of the record the base segments hold."""
        n = sum(b - a for a, b in self.bounds)
        return sum(b - a for (a, b), w in zip(self.bounds, self.base) if w) / n

    def base_samples(self, y: np.ndarray) -> np.ndarray:
        """The base segments' samples, joined in time order."""
        return np.concatenate([y[a:b] for (a, b), w in zip(self.bounds, self.base) if w])


def explained_regions(ctx: MissingContext, regions: list[dict], a: float) -> tuple[list, list]:
    """Split the ``"allan"`` check's ``regions`` into (kept, the change points'): a region is the change points'
    where the same check at ``a`` on the base segments' own curve (the model refitted there) finds no region
    overlapping it and the louder segments' Allan variance differs from the base's near its τ
    (:meth:`Segments.louder_at`). Each region the change points take carries ``louder`` (that difference) and
    ``base_segments``. Nothing is taken without change points, samples, louder segments, a base of at least
    ``BASE_SHARE`` of the record or enough base samples for 8 of the curve's τ."""
    seg = ctx.memo.get("segments")
    if not regions or ctx.y is None or not isinstance(seg, Segments) or seg.base.all():
        return regions, []
    if seg.base_share() < BASE_SHARE:  # a short base cannot resolve what the whole record shows
        return regions, []
    base = _base_check(ctx, seg, a)
    if base is None:
        return regions, []
    kept, taken = [], []
    for r in regions:
        lo, hi = r["tau"]
        again = any(lo <= q["tau"][1] * (1 + 1e-9) and q["tau"][0] <= hi * (1 + 1e-9) for q in base)
        louder = None if again else seg.louder_at(lo, hi)
        if louder is None:
            kept.append(r)
        else:
            taken.append(r | {"louder": louder, "base_segments": seg.times(seg.base)})
    return kept, taken


def _base_check(ctx: MissingContext, seg: Segments, a: float) -> list | None:
    """The ``"allan"`` check's regions on the base segments' joined samples: their curve at the record curve's
    τ up to 1/9 of their length, the terms and effects refitted on it; None where fewer than 8 τ remain."""
    assert ctx.y is not None
    yb = seg.base_samples(ctx.y)
    cur = ctx.curve
    idx = np.flatnonzero(cur.m <= yb.size // 9)
    if idx.size < 8:
        return None
    est = cur.estimator if isinstance(cur.estimator, str) else tuple(np.asarray(cur.estimator)[idx])
    av = np.maximum(avar(yb, ctx.fs, taus=cur.tau[idx]).avar, 1e-300)
    curve = Curve(cur.tau[idx], cur.m[idx], av, ctx.fs, yb.size + 1, est)
    sol = solve(curve, ctx.start, ctx.effects)
    sub = replace(ctx, curve=curve, thin=tracing.thin_indices(curve.tau), sol=sol, y=yb, memo={})
    return allan_check(sub, a)
