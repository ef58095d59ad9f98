"""Clipped and held samples — two checks of ``Refinement.unexplained`` on the record as it was given.

Both look at the samples refine was given (before any removal in time), at their share of ``level``
(:data:`.levels.UNEXPLAINED_SHARES`, ``"clipped"`` and ``"held"``), and neither changes the model: the samples
stay as they are, and the entry says what they are. A clipped stretch is not excluded because refine has no
value to put in its place (the rate beyond the rail is unknown; a model of censored samples is outside the
Allan model) and because the change point and the curve's misfit it causes are then said too, beside the
cause; a held sample is one innovation lost, its effect on the Allan variance at τ₀ the held fraction.
Samples an accepted removal replaced (the ``"outliers"`` step's, ``MissingContext.replaced``) are left out of
both: they are no longer in the record, and said by that step (a logger's dropped packets written as 0.0 are
its smallest value, in runs, but replaced as impulsive noise they are neither a rail nor held samples).

- ``"clipped"`` — samples at the record's largest (or smallest) value. Continuous samples tie at an extreme
  with probability 0; quantised ones do, but beyond the distribution's mode the density falls towards the
  extreme, so the extreme value holds no more samples than the next value inward (for a lattice the next
  lattice point) but by chance: the count at the extreme, given the two counts, is at most Binomial(n, ½).
  Samples piled at a rail exceed that by far, in runs where the signal stays beyond the rail, scattered where
  white noise crosses it (a continuous record clipped at 3σ: 1364 samples at the rail, one next to it). Each
  rail is tested at a quarter of the share (one-sided binomial); the other half goes to runs of one value
  longer than the record's own ties give, wherever they sit (:func:`longest_null_run`).
- ``"held"`` — consecutive samples exactly equal (a sample repeated by a driver that missed an output).
  Continuous samples never repeat; quantised ones do at a rate their step and noise give: on the lattice of
  the differences (step q, the smallest non-zero difference, or the float32 spacing for float32-exact samples)
  the counts n₀, n₁, n₂ of differences 0, ±q, ±2q follow a smooth density, and the log-quadratic through
  n₁, n₂ predicts n₀ = n₁·(n₁/n₂)^⅓ (a discrete Gaussian's exactly; within 7 % on the 36 ADIS16405 channels,
  whose accelerometers have noise of 1.2–1.7 steps). Ties beyond 1.25× that prediction, with a Poisson
  probability at most the check's α, are said. Where the noise is below one step (n₂ < 20 while n₁ is not)
  the quantisation alone makes most ties: nothing can be told and nothing is said. Ties inside a clipped run
  are the clipping's. A repeated sample ties with the one before, not with the one before that, while the
  quantisation ties samples two apart at least as often as neighbours wherever successive samples are not
  positively correlated: the null is the larger of the prediction and the ties at lag 2
  (:func:`lag2_ties`). That is what a delta-angle counter's output needs (the angle quantised, the rate its
  differences: Q-dominated, anti-correlated, a few levels): there the lattice's shape is not a smooth
  density's (n₂ raised by the −1, +1 pairs the differencing makes), the log-quadratic predicts 0.55× the
  ties, and the ties at lag 2 are 1.03× those at lag 1.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from scipy.stats import binom, poisson

from .levels import alpha
from .words import span_text

#: A :class:`.missing.MissingContext` (not imported: :mod:`.missing` imports this module's checks).
MissingContext = Any

__all__ = [
    "clipped_check",
    "held_check",
    "rail_runs",
    "equal_runs",
    "longest_null_run",
    "quality_flags",
    "tie_counts",
    "expected_ties",
    "lag2_ties",
    "MIN_COUNT",
    "HELD_MARGIN",
]

#: Counts below this on the difference lattice (n₁, n₂) are too few to read its shape from.
MIN_COUNT = 20
#: Held samples are said only beyond this multiple of the ties the quantisation predicts (the prediction's
#: own error: ≤ 7 % on the ADIS16405 channels, quantised white noise of ≥ 0.7 steps within a few %).
HELD_MARGIN = 1.25
#: Spans of a rail (or of ties) said by their times at most; more are counted.
MAX_SPANS = 3


def rail_runs(at: np.ndarray) -> list[tuple[int, int]]:
    """Runs (start, stop) of consecutive True in ``at``, stop exclusive.

    Examples
    --------
    >>> rail_runs(np.array([0, 1, 1, 0, 1, 0, 0, 1, 1, 1], dtype=bool))
    [(1, 3), (4, 5), (7, 10)]
    """
    edges = np.diff(np.concatenate([[0], at.astype(np.int8), [0]]))
    return list(zip(np.flatnonzero(edges == 1).tolist(), np.flatnonzero(edges == -1).tolist()))


def _spans(runs: list[tuple[int, int]]) -> list[tuple[int, int]]:
    """Runs merged where the gap between two is at most 4× the longer of the span so far and the next run (a
    rail left for a moment by the noise is one stretch at the rail)."""
    out: list[tuple[int, int]] = []
    for a, b in runs:
        if out and a - out[-1][1] <= 4 * max(b - a, out[-1][1] - out[-1][0]):
            out[-1] = (out[-1][0], b)
        else:
            out.append((a, b))
    return out


def _rail(y: np.ndarray, top: bool, a: float, keep: np.ndarray | None = None) -> dict | None:
    """The binomial test at one rail (the largest value, or the smallest, of the samples ``keep`` holds; all
    where None): None unless it rejects."""
    kept = y if keep is None else y[keep]
    if kept.size < 3:
        return None
    v = float(kept.max() if top else kept.min())
    at = y == v if keep is None else (y == v) & keep
    n_ext = int(np.count_nonzero(at))
    if n_ext < 2 or n_ext == kept.size:
        return None
    inner = y[~at] if keep is None else y[keep & ~at]
    w = float(inner.max() if top else inner.min())
    n_next = int(np.count_nonzero(inner == w))
    p = float(binom.sf(n_ext - 1, n_ext + n_next, 0.5))
    if not p <= a:
        return None
    runs = rail_runs(at)
    return {"value": v, "count": n_ext, "next": n_next, "p": p, "runs": runs, "at": at, "top": top}


def equal_runs(y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(start, stop) index arrays of the runs of two or more exactly equal consecutive samples, stop exclusive.

    Examples
    --------
    >>> equal_runs(np.array([1.0, 2.0, 2.0, 2.0, 3.0, 3.0]))
    (array([1, 4]), array([4, 6]))
    """
    e = np.diff(np.concatenate([[0], (np.diff(y) == 0).astype(np.int8), [0]]))
    return np.flatnonzero(e == 1), np.flatnonzero(e == -1) + 1


def longest_null_run(n: int, ties: int, a: float) -> int:
    """The shortest run of equal samples that ``n`` samples with ``ties`` exact ties give with probability at
    most ``a``: N·p^(L−1) ≤ a with p = √(ties/n) — the square root because ties cluster (a quantised value
    near the mean repeats more often than the average tie rate says: the ADIS16405 accelerometers' longest
    runs, 10–19, reach p^(L−1)·N ≈ 10⁻¹ at the plain rate); at least 3.

    Examples
    --------
    >>> longest_null_run(1_000_000, 45_000, 1e-4), longest_null_run(1_000_000, 0, 1e-4)
    (16, 3)
    """
    if ties <= 0:
        return 3
    p = math.sqrt(min(ties / max(n - 1, 1), 1.0 - 1e-12))
    return max(3, math.ceil(math.log(a / n) / math.log(p) + 1))


def _stuck(y: np.ndarray, a: float, replaced: np.ndarray | None = None) -> dict | None:
    """Runs of equal samples too long for the record's own tie rate (:func:`longest_null_run` at ``a``); a run
    whose every sample a removal ``replaced`` is not one (nor are its ties counted)."""
    s, t = equal_runs(y)
    if replaced is not None and s.size:
        c = np.concatenate([[0], np.cumsum(replaced, dtype=np.int64)])
        own = (c[t] - c[s]) < (t - s)
        s, t = s[own], t[own]
    if not s.size:
        return None
    ties = int(np.sum(t - s - 1))
    lmin = longest_null_run(y.size, ties, a)
    long = (t - s) >= lmin
    if not long.any():
        return None
    return {"runs": list(zip(s[long].tolist(), t[long].tolist())), "min_len": lmin}


def quality_flags(y: np.ndarray, a: float, replaced: np.ndarray | None = None) -> tuple[list[dict], dict | None]:
    """The rails that reject (each at ``a``/4) and the runs too long for the quantisation (at ``a``/2), among
    the samples no removal ``replaced`` (True where one did; None: none): a logger's dropped packets written as
    0.0, once the outliers step has replaced them, are neither a rail nor a stuck run."""
    if replaced is not None and not replaced.any():
        replaced = None
    keep = None if replaced is None else ~replaced
    rails = [r for top in (True, False) if (r := _rail(y, top, a / 4, keep)) is not None]
    return rails, _stuck(y, a / 2, replaced)


def _flags(ctx: MissingContext, y: np.ndarray, a: float) -> tuple[list[dict], dict | None]:
    """:func:`quality_flags` once per context (the held check leaves the clipped check's samples out)."""
    memo = getattr(ctx, "memo", None)
    replaced = getattr(ctx, "replaced", None)
    if memo is None:
        return quality_flags(y, a, replaced)
    if ("quality", a) not in memo:
        memo[("quality", a)] = quality_flags(y, a, replaced)
    return memo[("quality", a)]


def _stretches(ctx: MissingContext, spans: list[tuple[int, int]]) -> str:
    """ ", in 3 stretches: t a–b, c–d, e–f s" (the first :data:`MAX_SPANS`); nothing for one stretch — the
    entry's ``"t"``, said before its words, is that stretch."""
    if len(spans) < 2:
        return ""
    text = ", ".join(span_text(i / ctx.fs, j / ctx.fs) for i, j in spans[:MAX_SPANS])
    more = f" and {len(spans) - MAX_SPANS} more" if len(spans) > MAX_SPANS else ""
    return f", in {len(spans)} stretches: t {text}{more} s"


def clipped_check(ctx: MissingContext, a: float) -> list[dict]:
    """Samples piled at the record's largest or smallest value (each rail at ``a``/4), and runs of one value
    too long for the record's quantisation (at ``a``/2, :func:`longest_null_run`) elsewhere: one entry per
    clipped rail (``"value"``, ``"samples"`` at it, ``"runs"`` of two or more) and one for the long runs
    (``"samples"`` in them, ``"runs"``, the longest's ``"value"``); ``"t"`` the first and last time (s from
    the first sample)."""
    y = ctx.samples
    if y is None or y.size < 3:
        return []
    rails, stuck = _flags(ctx, y, a)
    out = [_rail_entry(ctx, r, a / 4) for r in rails]
    at_rail = np.zeros(y.size, dtype=bool)
    for r in rails:
        at_rail |= r["at"]
    if stuck is not None:
        runs = [(i, j) for i, j in stuck["runs"] if not at_rail[i]]
        if runs:
            out.append(_stuck_entry(ctx, y, runs, stuck["min_len"], a / 2))
    return out


def _entry(ctx: MissingContext, t: tuple[float, float], what: str) -> dict:
    tau = float(ctx.curve.tau[0])
    return {"domain": "clipped", "tau": (tau, tau), "t": t, "band_hz": None, "chi2_dof": None, "what": what}


def _rail_entry(ctx: MissingContext, r: dict, a: float) -> dict:
    """A clipped rail (:func:`_rail`) as an entry of ``unexplained``; its statistic −log₁₀ p against −log₁₀ a."""
    spans = _spans(r["runs"])
    long = [(i, j) for i, j in r["runs"] if j - i >= 2]
    in_runs = sum(j - i for i, j in long)
    what = (
        f"the record is clipped at {r['value']:.6g}{_unit(ctx)}: {r['count']} samples at its "
        f"{'largest' if r['top'] else 'smallest'} value ({in_runs} in {len(long)} run"
        f"{'' if len(long) == 1 else 's'} of two or more; {r['next']} at the next value inward)"
        f"{_stretches(ctx, spans)} — left in the record"
    )
    return _entry(ctx, (spans[0][0] / ctx.fs, spans[-1][1] / ctx.fs), what) | {
        "value": r["value"],
        "samples": r["count"],
        "runs": len(long),
        "statistic": -math.log10(max(r["p"], 1e-300)),
        "threshold": -math.log10(a),
        "alpha": a,
    }


def _stuck_entry(ctx: MissingContext, y: np.ndarray, runs: list[tuple[int, int]], min_len: int, a: float) -> dict:
    """Runs of one value longer than ``min_len`` (not at a clipped rail) as an entry; its statistic the
    longest run's length against ``min_len``."""
    i0, j0 = max(runs, key=lambda r: r[1] - r[0])
    n_in = sum(j - i for i, j in runs)
    what = (
        f"the record holds one value for {j0 - i0} samples in a row at {y[i0]:.6g}{_unit(ctx)} "
        f"({n_in} samples in {len(runs)} run{'s' if len(runs) > 1 else ''} of ≥ {min_len}, "
        f"longer than its quantisation gives){_stretches(ctx, runs)}: clipped or stuck — left in the record"
    )
    return _entry(ctx, (runs[0][0] / ctx.fs, runs[-1][1] / ctx.fs), what) | {
        "value": float(y[i0]),
        "samples": n_in,
        "runs": len(runs),
        "statistic": float(j0 - i0),
        "threshold": float(min_len),
        "alpha": a,
    }


def tie_counts(y: np.ndarray, skip: np.ndarray | None = None) -> dict:
    """The differences of ``y`` on their lattice: ``n0`` (exact ties), ``n1``, ``n2`` (differences of ±1 and ±2
    steps, halved: one side's count), the tie indices ``ties`` (i where y[i] == y[i − 1]) and the ``step`` (the
    smallest non-zero |difference|; per pair the float32 spacing where that is larger and the samples are
    float32-exact). Pairs with ``skip`` True at either end are left out.

    Examples
    --------
    >>> c = tie_counts(np.array([0.0, 1.0, 1.0, 3.0, 2.0, 2.0, 2.0]))
    >>> c["n0"], c["n1"], c["n2"], c["step"]
    (3, 1.0, 0.5, 1.0)
    """
    y = np.asarray(y, dtype=np.float64)
    # one record-length array of differences, made absolute in place; indices only where a pair is left out
    # (a 4·10⁶ record's transient here was 4.75× the record with an index per pair and copies of |d|)
    if skip is not None and skip.any():
        idx: np.ndarray | None = np.flatnonzero(~(skip[1:] | skip[:-1]))
        ad = np.abs(np.diff(y)[idx])
    else:
        idx = None
        ad = np.diff(y)
        np.abs(ad, out=ad)
    pos = np.flatnonzero(ad == 0)
    ties = (pos if idx is None else idx[pos]) + 1
    q = float(np.min(ad, where=ad > 0, initial=np.inf))
    if not np.isfinite(q):
        return {"n0": int(ties.size), "n1": 0.0, "n2": 0.0, "ties": ties, "step": 0.0}
    f32 = bool(np.all(y.astype(np.float32) == y))  # float32 samples: the spacing grows with the magnitude
    # only the differences within 2.5 steps of 0 can count (the largest step the record's magnitudes give)
    top = max(q, float(np.spacing(np.float32(max(abs(float(y.max())), abs(float(y.min()))))))) if f32 else q
    near = np.flatnonzero((ad > 0) & (ad <= 2.5 * top))
    sel, a_near = (near if idx is None else idx[near]), ad[near]
    step: float | np.ndarray = q
    if f32:
        big = np.maximum(np.abs(y[sel + 1]), np.abs(y[sel]))
        step = np.maximum(q, np.spacing(big.astype(np.float32)).astype(np.float64))
    k = a_near / step
    kr = np.round(k)
    on = np.abs(k - kr) < 1e-6
    return {
        "n0": int(ties.size),
        "n1": float(np.count_nonzero(on & (kr == 1))) / 2,
        "n2": float(np.count_nonzero(on & (kr == 2))) / 2,
        "ties": ties,
        "step": q,
    }


def expected_ties(n1: float, n2: float) -> float | None:
    """Ties the quantisation predicts from the one-sided counts at ±1 and ±2 steps: n₁·(n₁/n₂)^⅓ (the
    log-quadratic through them), n₁ where the grid is fine beside the noise (n₁ < :data:`MIN_COUNT`: a smooth
    density has as many ties as single steps), None where the noise is below one step (n₂ too few).

    Examples
    --------
    >>> round(expected_ties(1000.0, 800.0), 1), expected_ties(3.0, 0.0), expected_ties(500.0, 4.0)
    (1077.2, 3.0, None)
    """
    if n1 < MIN_COUNT:
        return n1
    if n2 < MIN_COUNT:
        return None
    return n1 * (n1 / n2) ** (1.0 / 3.0)


def lag2_ties(y: np.ndarray, skip: np.ndarray | None = None) -> int:
    """Samples equal to the one two before (y[i] == y[i − 2]), triples with ``skip`` True anywhere left out.

    Examples
    --------
    >>> lag2_ties(np.array([0.0, 1.0, 0.0, 1.0, 2.0, 1.0]))
    3
    """
    y = np.asarray(y, dtype=np.float64)
    if y.size < 3:
        return 0
    eq = y[2:] == y[:-2]
    if skip is not None and skip.any():
        eq &= ~(skip[2:] | skip[1:-1] | skip[:-2])
    return int(np.count_nonzero(eq))


def held_check(ctx: MissingContext, a: float) -> list[dict]:
    """Consecutive equal samples beyond what the quantisation predicts (the larger of :func:`expected_ties`
    and :func:`lag2_ties`, × :data:`HELD_MARGIN`), at a Poisson probability ≤ ``a``; samples at a clipped rail
    left out."""
    y = ctx.samples
    if y is None or y.size < 3:
        return []
    skip = np.zeros(y.size, dtype=bool)  # the clipped check's samples are its own
    rails, stuck = _flags(ctx, y, alpha("unexplained:clipped", ctx.level))
    for r in rails:
        skip |= r["at"]
    for i, j in [] if stuck is None else stuck["runs"]:
        skip[i:j] = True
    replaced = getattr(ctx, "replaced", None)
    if replaced is not None:  # samples a removal replaced (the outliers step's) are its own
        skip |= replaced
    c = tie_counts(y, skip)
    exp = expected_ties(c["n1"], c["n2"])
    if exp is None or c["n0"] < 10:
        return []
    exp = max(exp, float(lag2_ties(y, skip)))  # quantisation ties at every lag; a repeat at lag 1 only
    null = HELD_MARGIN * max(exp, 0.5)
    thr = float(poisson.isf(a, null)) + 1
    if not c["n0"] >= thr:
        return []
    n = y.size
    excess = c["n0"] - exp
    what = f"{100 * excess / n:.2g} % of the samples repeat the one before ({c['n0']} exact repeats"
    what += f", {exp:.3g} expected from the quantisation step {c['step']:.3g})" if exp >= 1 else ")"
    ties = c["ties"]
    if c["n0"] > 2 * exp and ties.size >= 3:
        gap = float(np.median(np.diff(ties))) / ctx.fs
        what += f", every ≈ {gap:.3g} s"
    what += ": the output rate drops or repeats samples"
    tau = float(ctx.curve.tau[0])
    return [
        {"domain": "held", "tau": (tau, tau), "t": (ties[0] / ctx.fs, ties[-1] / ctx.fs), "band_hz": None}
        | {"chi2_dof": None, "what": what, "repeats": c["n0"], "expected": exp, "fraction": excess / n}
        | {"statistic": float(c["n0"]), "threshold": thr, "alpha": a}
    ]


def _unit(ctx: MissingContext) -> str:
    return f" {ctx.unit}" if ctx.unit else ""
