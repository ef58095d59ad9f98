"""The ``"steps"`` check of :mod:`.missing`: does the mean of the final samples step at one or several times?

:mod:`._mean_step` tests one split of the record against a null refitted without that step; with steps of
opposite signs at several times one split's two sides mix them, and the steps left in the record keep the refitted
random walk (K) high, so its null covers them (blind3's +2.5, −4, +3·10⁻³ °/s at 0.2, 0.5, 0.8 T: silent). A
null refitted without several located steps fails the other way: removing steps that are not there lowers K, and
clean records are rejected too often (an experiment: 1.0 % at α 3.1·10⁻⁴).

This check does not hang on K. A step is a few *outlying increments* of the block means; the increments of white
noise, flicker, random walk or a Gauss–Markov term are Gaussian, and their scale is taken from the record itself:

- For each of :data:`STEP_BLOCKS` block lengths L = T/n: the means of blocks of L at a stride of L/2, their
  increments Δⱼ = B_{j+2} − Bⱼ (adjacent blocks; a step anywhere in the record sits within L/4 of a block
  boundary, so one increment carries ≥ 3/4 of it), ``z_n`` = max |Δⱼ − med Δ| / s, s the SD of Δ taken from
  its :data:`KEEP` smallest in size — the median removes a ramp, and a few steps move the scale not at all.
- The statistic: the largest ``z_n / q_n`` over the lengths, ``q_n`` the median of ``z_n`` in the null (one
  scale for several lengths, which differ in how many increments they hold).
- Its null: the statistic of records simulated at the half-block rate under the final model, its slow terms at
  the upper end the curve allows (:func:`.curvefit.upper_theta`, as the drift check's null) —
  max(:data:`MIN_BOOT`, :data:`BOOT_PER_ALPHA`/α) records, the (1 − α) quantile by the rank rule. The statistic
  is nearly pivotal (a ratio of the record's own increments): at 3·10⁵ samples and α 1.6·10⁻⁴ its threshold reads
  2.25 under white noise alone, 2.25 under flicker alone, 2.47 under random walk alone and 2.28 under a mix (each
  length's median within 1.5 %), so the steps a fit has absorbed into K barely move it.
- The steps, step-down: at the length of the largest ratio, every run of increments beyond the threshold is one
  step, placed where the difference of the means over L after and before it is largest (to L/:data:`FINE`), its
  size that difference; the steps removed, the statistic again against the same threshold, until it holds.
  Block means of the samples less the steps are the samples' block means less the steps' (closed form): no
  record-length array until the steps are said (:func:`_departure`, one copy of the record).
- Said only where the steps matter: their exact Allan variance (of the located steps together, at the curve's
  τ) must move the model refitted without them beyond the final model's held-out error at some τ (the mean
  check's rule); the entry's τ range is where it does.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from ...analysis import avar
from .._medians import median_by_sort
from ..tracing import block_means, simulated_block_mean_chunks
from .curvefit import Curve, chi2_dof_between, solve, theta_terms, upper_theta
from .words import heldout_clause

__all__ = [
    "STEP_BLOCKS",
    "FINE",
    "increment_z",
    "steps_statistic",
    "null_ratios",
    "locate_steps",
    "steps_check",
]

#: Block counts along the record (the block lengths T/n tested; Bonferroni-free: one maximum, one null).
STEP_BLOCKS = (32, 64, 128)
#: Resolution of a located step: L/FINE.
FINE = 16
#: Fewest samples in a half block of the finest length (so its means are Gaussian; shorter records use fewer
#: lengths, none below 32 blocks).
MIN_HALF = 16
BOOT_PER_ALPHA = 2
MIN_BOOT = 2000
#: Share of the increments (the smallest in size) their scale is taken from.
KEEP = 0.75
#: The SD of a standard normal truncated to its central KEEP (the scale's constant: E[Z²; |Z| < z₀]/KEEP).
_Z0 = 1.1503493803760079  # the normal's (1 + KEEP)/2 quantile
_KEEP_SD = math.sqrt(1.0 - 2.0 * _Z0 * math.exp(-(_Z0**2) / 2) / math.sqrt(2 * math.pi) / KEEP)
#: Most steps located (the step-down's rounds stop there).
MOST_STEPS = 6
#: Most simulated records (2²² half-block means in all, drawn :data:`.tracing.SIM_CHUNK` at a time): below
#: α ≈ 1/(MAX_BOOT + 1) the threshold is the largest null statistic.
MAX_BOOT = 2**22 // (2 * STEP_BLOCKS[-1])


def _blocks(size: int) -> tuple[int, ...]:
    return tuple(n for n in STEP_BLOCKS if size // (2 * n) >= MIN_HALF)


def _scale(d: np.ndarray) -> np.ndarray:
    """The increments' SD (columns) from the :data:`KEEP` smallest in size: a few steps beyond them move it not
    at all, and it scatters far less than a median absolute deviation (its null's tail is lighter)."""
    k = max(2, int(KEEP * d.shape[0]))
    a = np.partition(np.abs(d), k - 1, axis=0)[:k]
    return np.sqrt(np.mean(a * a, axis=0)) / _KEEP_SD


def increment_z(half: np.ndarray, blocks: tuple[int, ...]) -> tuple[np.ndarray, list]:
    """``z_n`` for each n of ``blocks`` (rows) from the half-block means ``half`` of the finest n (2n rows,
    records in columns; coarser lengths are pairs of them), and each length's standardised increments."""
    g = np.asarray(half, dtype=np.float64)
    if g.ndim == 1:
        g = g[:, None]
    zs, incs = [], []
    for _ in blocks:  # finest first
        b = 0.5 * (g[:-1] + g[1:])
        d = b[2:] - b[:-2]
        d = d - median_by_sort(d, axis=0)  # np.median's numbers, one sort (its partition: 5× slower)
        s = _scale(d)
        # no scale (most increments exactly zero: a record stuck between rounding levels): no evidence either way
        z = np.where(s > 0, np.abs(d) / np.where(s > 0, s, 1.0), 0.0)
        zs.append(np.max(z, axis=0))
        incs.append(z)
        g = 0.5 * (g[0::2] + g[1::2])
    return np.array(zs[::-1]), incs[::-1]


def steps_statistic(z: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """max over lengths of ``z_n / q_n`` (``z``: lengths × records) and the length's index where it is reached."""
    r = np.asarray(z) / np.maximum(np.asarray(q), 1e-300)[:, None]
    j = np.argmax(r, axis=0)
    return r[j, np.arange(r.shape[1])], j


def null_ratios(size: int, fs: float, terms, theta, alpha: float, seed: int = 7919) -> dict:
    """The null of :func:`steps_statistic` for ``size`` samples at ``fs`` under the five-term model ``theta``:
    ``q`` (each length's median ``z_n``), ``threshold`` (the rank rule's (1 − α) quantile of the statistic), the
    number of records drawn, the lengths and the statistic's ``draws`` (sorted)."""
    blocks = _blocks(size)
    half = size // (2 * blocks[-1])
    if not any(float(v) > 0 for t, v in zip(terms, theta) if t in ("N", "B", "K", "R")):
        terms, theta = ("N",), [1.0]  # nothing at the block rate (a model of lines or a Gauss–Markov term): white
    n_boot = min(MAX_BOOT, max(MIN_BOOT, math.ceil(BOOT_PER_ALPHA / alpha)))
    # a chunk of records at a time: their z (3 numbers a record) kept, not their means and increments (2²² of
    # each at the cap, ≈ 240 MB with the simulation's transforms at once)
    chunks = simulated_block_mean_chunks(2 * blocks[-1], half, fs, terms, theta, n_boot, seed)
    z = np.concatenate([increment_z(sims, blocks)[0] for sims in chunks], axis=1)
    q = np.median(z, axis=1)
    stats = np.sort(steps_statistic(z, q)[0])
    thr = float(stats[min(math.ceil((n_boot + 1) * (1.0 - alpha)), n_boot) - 1])
    return {"q": q, "threshold": thr, "n_boot": n_boot, "blocks": blocks, "draws": stats}


def locate_steps(
    y: np.ndarray, n: int, z: np.ndarray, cut: float, found: Sequence[tuple[int, float]] = ()
) -> list[tuple[int, float]]:
    """(first sample after the step, size) of each run of increments ``z`` (of length T/n at stride L/2) beyond
    ``cut``: placed within ±L/2 of the run's largest increment's block boundary where the mean over L after less
    the mean over L before is largest in size (on means of L/:data:`FINE` of ``y`` less the steps ``found``)."""
    hot = np.flatnonzero(z > cut)
    if hot.size == 0:
        return []
    runs = np.split(hot, np.flatnonzero(np.diff(hot) > 2) + 1)
    per = y.size // (2 * n)  # samples per half block
    fper = max(1, 2 * per // FINE)  # samples per fine mean
    nf = y.size // fper
    fm = np.cumsum(np.r_[0.0, y[: nf * fper].reshape(nf, fper).mean(axis=1) - _step_means(found, fper, nf)])
    span = round(2 * per / fper)  # fine means per block of L
    out = []
    for run in runs:
        j = int(run[np.argmax(z[run])])
        centre = round((j + 2) * per / fper)  # the boundary between the increment's two blocks
        ks = np.arange(max(span, centre - span // 2), min(fm.size - 1 - span, centre + span // 2) + 1)
        if ks.size == 0:
            continue
        diff = (fm[ks + span] - fm[ks]) / span - (fm[ks] - fm[ks - span]) / span
        k = int(ks[np.argmax(np.abs(diff))])
        out.append((k * fper, float(diff[np.argmax(np.abs(diff))])))
    return out


def _step_means(steps: Sequence[tuple[int, float]], per: int, count: int) -> np.ndarray:
    """The means of ``count`` consecutive blocks of ``per`` samples of the steps' component (d from sample
    ``index`` on, summed over the steps): each block holds the share of its samples at or after each index."""
    edges = np.arange(count, dtype=np.float64)[:, None] * per
    out = np.zeros(count)
    for index, d in steps:
        out += d * np.clip((edges[:, 0] + per - index) / per, 0.0, 1.0)
    return out


def _departure(ctx: Any, steps: list[tuple[int, float]]) -> np.ndarray:
    """How far (%) the located steps' own Allan variance (together, cross terms included) moves the final model
    refitted without them (refine's fit on the exact curve of the samples less the steps), at each τ."""
    cur = ctx.curve
    comp = np.zeros(ctx.y.size)  # the one record-length array: the steps, then the samples less them
    for index, d in steps:
        comp[index:] += d
    s_av = np.asarray(avar(comp, ctx.fs, taus=cur.tau).avar, dtype=np.float64)
    np.negative(comp, out=comp)
    comp += ctx.y
    av = np.asarray(avar(comp, ctx.fs, taus=cur.tau).avar, dtype=np.float64)
    del comp
    sol = solve(Curve(cur.tau, cur.m, av, cur.fs, cur.n_points, cur.estimator), ctx.start, ctx.effects)
    return 100.0 * (np.sqrt(1.0 + s_av / np.maximum(sol.model, 1e-300)) - 1.0)


def _words(steps: list[tuple[int, float]], fs: float, unit: str | None) -> str:
    u = f" {unit}" if unit else ""
    parts = [f"by {d:.2g}{u} at t ≈ {index / fs:.6g} s" for index, d in steps]
    return "the mean steps " + ("; ".join(parts) if len(parts) < 3 else "; ".join(parts[:-1]) + "; and " + parts[-1])


def step_down(y: np.ndarray, null: dict) -> tuple[list[tuple[int, float]], dict]:
    """The located steps of ``y`` (by time) and the first round's statistic, step-down: while the statistic of
    the samples less the steps so far exceeds the threshold, the runs beyond it at the length of the largest
    ratio are further steps (at most :data:`MOST_STEPS`; a step within a block of one found is not a new one).
    The first round is the test; later rounds face the same threshold, which holds for every position of the
    record and so for those that remain (a step-down maximum test: removing a found step lowers the robust scale
    that the steps left had shared with it)."""
    blocks = null["blocks"]
    steps: list[tuple[int, float]] = []
    first: dict[str, Any] = {}
    half, per = block_means(y, 2 * blocks[-1])  # half blocks of the finest length
    while len(steps) < MOST_STEPS:
        z, incs = increment_z(half - _step_means(steps, per, half.size), blocks)
        stat, j = steps_statistic(z, null["q"])
        if not first:
            first = {"statistic": float(stat[0]), "block": 0}
        if not stat[0] > null["threshold"]:
            break
        i = int(j[0])
        block = y.size // blocks[i]
        new = [
            (k, d)
            for k, d in locate_steps(y, blocks[i], incs[i][:, 0], null["threshold"] * float(null["q"][i]), steps)
            if all(abs(k - k0) > block for k0, _ in steps)
        ][: MOST_STEPS - len(steps)]
        if not new:
            break
        first["block"] = first["block"] or block
        steps += new
    return sorted(steps), first


def steps_check(ctx: Any, a: float) -> list[dict]:
    """One entry when the final samples' mean steps at one or several times (the module docstring's test at ``a``)
    and the steps move the Allan deviation beyond the held-out error: ``"steps"`` [(t s, size)], ``"t"`` the
    span from the first step to the end, ``"departure_pct"`` the largest move of the Allan deviation; else
    nothing."""
    y = ctx.y
    if y is None or not _blocks(y.size):
        return []
    theta = upper_theta(ctx.curve, ctx.sol, ctx.start, ctx.effects, theta_terms(ctx.sol, ctx.start, ctx.effects))
    null = null_ratios(y.size, ctx.fs, ctx.start, theta, a)
    steps, test = step_down(np.asarray(y, dtype=np.float64), null)
    if not steps:
        return []
    dep = _departure(ctx, steps)
    big = np.flatnonzero(dep > float(ctx.heldout_pct or 0.0))
    if big.size == 0:
        return []
    tau = ctx.curve.tau
    lo, hi = float(tau[big[0]]), float(tau[big[-1]])
    i_top = int(np.argmax(dep))
    pct = float(dep[i_top])
    what = (
        _words(steps, ctx.fs, ctx.unit)
        + f" (together they raise the Allan deviation by {pct:.0f} % at τ {float(tau[i_top]):.4g} s"
        + heldout_clause(ctx.heldout_pct)
        + ")"
    )
    return [
        {
            "domain": "steps",
            "tau": (lo, hi),
            "t": (steps[0][0] / ctx.fs, y.size / ctx.fs),
            "band_hz": (0.5 / hi, 0.5 / lo),
        }
        | {"chi2_dof": chi2_dof_between(tau, ctx.sol.z, lo, hi), "what": what}
        | {"steps": [(index / ctx.fs, d) for index, d in steps], "block_s": test["block"] / ctx.fs}
        | {"departure_pct": pct, "heldout_pct": ctx.heldout_pct}
        | {"statistic": test["statistic"], "threshold": null["threshold"], "alpha": a}
    ]
