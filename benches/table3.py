#!/usr/bin/env python3
"""Paper 000's Table 3, reproduced: DAVAR vs fast DAVAR vs improved fast DAVAR, and what users use instead.

Paper 000 (Zhang, Wang, Wang, Gao, Acta Optica Sinica 2015), Table 3 — Matlab 7.11 on a 3 GHz Core 2 Duo,
seconds, for N = 1e3 / 1e4 / 1e5 samples: DAVAR 5.34 / 217.12 / 8970.28, fast DAVAR 0.73 / 2.36 / 76.27,
improved fast DAVAR 0.43 / 0.85 / 8.27.

What one run measures (one seeded white-noise record, standard normal, fs = 100 Hz; each N uses the
record's first N samples; window W = N/10, hop = 1; every allanite call with ``workers=1``):

- ``naive``    — DAVAR: ``allanite.davar(method="naive", taus="all")``: every window recomputed from
                 scratch at every m = 1 … W/2 (paper 000 writes m = 1 … N_w/2 − 1; allanite's "all" grid
                 also has m = W/2, a single term per window — 1 of W/2 rows).
- ``fast``     — fast DAVAR: ``allanite.davar(method="fast", taus="all")``, same m.
- ``improved`` — improved fast DAVAR: ``allanite.davar(method="fast", taus="exp")``, paper 000 §4.2's
                 exponential grid (100 points up to W/9, duplicates dropped).
- ``prefix_all`` / ``prefix_exp`` — ``allanite._reference.davar_prefix``: the vectorised NumPy DAVAR a
                 user would write (global prefix sums), on the same two grids.
- ``allantools_all`` / ``allantools_exp`` — ``allantools.oadev(window, data_type="freq", taus=m/fs)``
                 called once per window, on the same two grids.

Every method's values are compared with every other's wherever they share (m, window): the maximum
relative difference per pair is reported (must be ≤ 1e-9).

Where a full run would take more than ~2 minutes (or its output would not fit in memory), a documented
sample is timed and extrapolated linearly — marked "extrapolated" everywhere:

- windows (naive, allantools): time per window × number of windows (each window is independent);
- averaging factors m (fast, prefix, naive and allantools at large W): each m's cost is independent of
  the others. For whole-record methods (fast, prefix) time per sampled m × number of m; for
  per-window methods (naive, allantools) scaled by the number of second-difference terms,
  Σ_all (W+1−2m) / Σ_sample (W+1−2m), which is what their cost is proportional to;
- per-call fixed costs (input checks and mean for allanite, the cumulative angle for the NumPy twin,
  the per-window angle of naive and allantools) are measured separately and not scaled.

Outputs that are too large for one call but are computed in full are split into chunks of m and the
chunk times summed ("chunked", not extrapolated).

The scaling part runs the improved fast DAVAR (window N/10, hop N/1000, exponential grid) for
N = 1e4 … 1e8 in a fresh subprocess per (N, workers), and reports wall time and the child's peak
resident memory (``ru_maxrss``), with 1 and 2 worker threads.

Usage::

    python benches/table3.py                      # full run (≈ 10 min) -> benches/results/table3.*, scaling.*
    python benches/table3.py --wait-idle 600      # first wait (≤ 600 s) for an idle machine
    python benches/table3.py --quick --out DIR    # CI smoke run (< 30 s): correctness, not speed
    python benches/table3.py --criterion          # only: cargo bench -p allanite-core -> results/criterion.md
"""

from __future__ import annotations

import argparse
import gc
import hashlib
import json
import math
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from _common import OtherLoad, log, machine_info, max_rel_diff, sample_starts, wait_idle

HERE = Path(__file__).resolve().parent
REPO = HERE.parent

SEED = 20240611
FS = 100.0
GiB = 2**30

#: Paper 000, Table 3 (s): DAVAR, fast DAVAR, improved fast DAVAR.
PAPER = {
    1_000: {"naive": 5.34, "fast": 0.73, "improved": 0.43},
    10_000: {"naive": 217.12, "fast": 2.36, "improved": 0.85},
    100_000: {"naive": 8970.28, "fast": 76.27, "improved": 8.27},
}

METHODS = {
    "naive": "DAVAR — allanite.davar(method='naive', taus='all')",
    "fast": "fast DAVAR — allanite.davar(method='fast', taus='all')",
    "improved": "improved fast DAVAR — allanite.davar(method='fast', taus='exp')",
    "prefix_all": "NumPy prefix-sum twin (_reference.davar_prefix), all m",
    "prefix_exp": "NumPy prefix-sum twin (_reference.davar_prefix), exp grid",
    "allantools_all": "allantools.oadev per window, all m",
    "allantools_exp": "allantools.oadev per window, exp grid",
}

# Per N: how much of each method is timed. None = everything; an integer = that many evenly spread
# windows or m values (see the module docstring for how they are scaled up).
#   naive_windows, naive_m     — windows and m of the naive DAVAR
#   fast_m                     — m of the fast DAVAR on the "all" grid (also the m sample of prefix_all,
#                                naive and allantools_all when they are sampled)
#   prefix_all_m, prefix_exp_m — m of the NumPy twin
#   at_all_windows, at_all_m, at_exp_windows — allantools per window
FULL = {
    "table": {
        1_000: dict(
            naive_windows=None,
            naive_m=None,
            fast_m=None,
            prefix_all_m=None,
            prefix_exp_m=None,
            at_all_windows=None,
            at_all_m=None,
            at_exp_windows=None,
        ),
        10_000: dict(
            naive_windows=None,
            naive_m=None,
            fast_m=None,
            prefix_all_m=None,
            prefix_exp_m=None,
            at_all_windows=200,
            at_all_m=None,
            at_exp_windows=1000,
        ),
        100_000: dict(
            naive_windows=100,
            naive_m=None,
            fast_m=None,
            prefix_all_m=None,
            prefix_exp_m=None,
            at_all_windows=20,
            at_all_m=None,
            at_exp_windows=200,
        ),
        1_000_000: dict(
            naive_windows=20,
            naive_m=100,
            fast_m=100,
            prefix_all_m=100,
            prefix_exp_m=None,
            at_all_windows=5,
            at_all_m=100,
            at_exp_windows=10,
        ),
        10_000_000: dict(
            naive_windows=10,
            naive_m=20,
            fast_m=20,
            prefix_all_m=20,
            prefix_exp_m=30,
            at_all_windows=3,
            at_all_m=20,
            at_exp_windows=3,
        ),
    },
    "chunk_bytes": 512 * 2**20,  # largest output of one timed call; above: chunks of m (see prewarm)
    "single_call_diagnostic": [100_000],  # also time the fast "all" grid as one call (output 3.35 GiB)
    "probe_windows": 100_000,  # windows kept per compared row (evenly strided)
    "probe_rows": 200,  # m values kept for comparisons when a grid was run in full
    "scaling": [10_000, 100_000, 1_000_000, 10_000_000, 100_000_000],
    "scaling_repeats": {100_000_000: 1},  # default 3 (best of)
}

QUICK = {
    "table": {
        1_000: dict(
            naive_windows=None,
            naive_m=None,
            fast_m=None,
            prefix_all_m=None,
            prefix_exp_m=None,
            at_all_windows=50,
            at_all_m=None,
            at_exp_windows=None,
        ),
        4_000: dict(
            naive_windows=10,
            naive_m=20,
            fast_m=20,
            prefix_all_m=20,
            prefix_exp_m=10,
            at_all_windows=3,
            at_all_m=20,
            at_exp_windows=5,
        ),
    },
    "chunk_bytes": 2**19,  # 512 KiB: exercises the chunked path
    "single_call_diagnostic": [1_000],
    "probe_windows": 1_000,
    "probe_rows": 50,
    "scaling": [10_000, 100_000],
    "scaling_repeats": {},
}

WORKERS = 1  # the table: one thread for every method (NumPy, allantools and the paper's Matlab are serial)


class Load(OtherLoad):
    """OtherLoad (_common) that also counts this process's finished children as its own."""

    @staticmethod
    def _self():
        t = os.times()
        return t.user + t.system + t.children_user + t.children_system


# ----------------------------------------------------------------------------------------------
# timing


def timed(fn, *, short: float = 1.0, max_repeats: int = 3):
    """Run ``fn``; if it took < ``short`` s, run it again, up to ``max_repeats`` runs in all (three times
    as many if the first took < 0.05 s).

    Returns (best seconds, every run's seconds, the last result). Only one result is alive at a time."""
    times, out = [], None
    while True:
        out = None
        gc.collect()
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
        # very short calls are noisy (thread-pool start, page faults): give them more tries
        limit = 3 * max_repeats if times[0] < 0.05 else max_repeats
        if len(times) >= limit or times[0] >= short:
            return min(times), times, out


def evenly(values: np.ndarray, count: int | None) -> np.ndarray:
    """``count`` elements of ``values`` spread evenly, first and last included (all if None)."""
    values = np.asarray(values)
    if count is None or count >= values.size:
        return values.copy()
    idx = np.unique(np.round(np.linspace(0, values.size - 1, count)).astype(np.int64))
    return values[idx]


def n_terms(window: int, ms) -> np.ndarray:
    """Overlapping second differences per window at each m: W + 1 − 2m."""
    return window + 1 - 2 * np.asarray(ms, dtype=np.int64)


# ----------------------------------------------------------------------------------------------
# what is kept for the comparisons


class Block:
    """Values of one method at the averaging factors ``ms`` (rows) and window indices ``ws``
    (columns; window j starts at sample j)."""

    __slots__ = ("ms", "ws", "vals")

    def __init__(self, ms, ws, vals):
        self.ms = np.asarray(ms, dtype=np.int64)
        self.ws = np.asarray(ws, dtype=np.int64)
        self.vals = np.asarray(vals, dtype=np.float64)
        assert self.vals.shape == (self.ms.size, self.ws.size), (self.vals.shape, self.ms.size, self.ws.size)


class Probe:
    """Which (m, window) pairs every method keeps: rows ``probe_m`` at the strided windows
    ``probe_w``, and every computed m at the sampled windows ``probe_j``."""

    def __init__(self, probe_m, probe_w, probe_j):
        self.m = np.unique(np.asarray(probe_m, dtype=np.int64))
        self.w = np.unique(np.asarray(probe_w, dtype=np.int64))
        self.j = np.unique(np.asarray(probe_j, dtype=np.int64))

    def keep(self, ms, values, ws=None) -> list[Block]:
        """Blocks of a (len(ms), windows) result; ``ws``: its window indices (default 0, 1, …)."""
        ms = np.asarray(ms, dtype=np.int64)
        if ws is None:
            ws = np.arange(values.shape[1])
        ws = np.asarray(ws, dtype=np.int64)
        out = []
        rows = np.flatnonzero(np.isin(ms, self.m))
        cw = np.flatnonzero(np.isin(ws, self.w))
        if rows.size and cw.size:
            out.append(Block(ms[rows], ws[cw], values[np.ix_(rows, cw)]))
        cj = np.flatnonzero(np.isin(ws, self.j))
        if cj.size:
            out.append(Block(ms, ws[cj], values[:, cj]))
        return out


def compare(blocks_a: list[Block], blocks_b: list[Block], m_split: int) -> dict:
    """Max relative difference |a − b| / |b| over every shared (m, window), also split at m ≤ ``m_split``
    (W/9: paper 000's largest τ, ≥ 9 clusters) and m > ``m_split``; numbers of values compared."""
    worst = {"all": None, "low": None, "high": None}
    count = {"all": 0, "low": 0, "high": 0}
    for a in blocks_a:
        for b in blocks_b:
            common, ia_m, ib_m = np.intersect1d(a.ms, b.ms, assume_unique=True, return_indices=True)
            if ia_m.size == 0:
                continue
            _, ia_w, ib_w = np.intersect1d(a.ws, b.ws, assume_unique=True, return_indices=True)
            if ia_w.size == 0:
                continue
            low = common <= m_split
            for part, sel in (("low", low), ("high", ~low)):
                if not sel.any():
                    continue
                d = max_rel_diff(a.vals[np.ix_(ia_m[sel], ia_w)], b.vals[np.ix_(ib_m[sel], ib_w)])
                for k in (part, "all"):
                    worst[k] = d if worst[k] is None else max(worst[k], d)
                n = int(sel.sum()) * ia_w.size
                count[part] += n
                count["all"] += n
    return {
        "max_rel_diff": worst["all"],
        "n_compared": count["all"],
        "max_rel_diff_m_le_w9": worst["low"],
        "n_compared_m_le_w9": count["low"],
        "max_rel_diff_m_gt_w9": worst["high"],
        "n_compared_m_gt_w9": count["high"],
    }


def checked_diff(pair: str, c: dict):
    """The difference the 1e-9 check applies to: every shared value, except for the NumPy prefix-sum
    twin, whose global cumulative sums cancel catastrophically when a window holds only a few terms
    (m near W/2): for it, m ≤ W/9 (the range paper 000 keeps, ≥ 9 clusters)."""
    return c["max_rel_diff_m_le_w9"] if "prefix" in pair else c["max_rel_diff"]


# ----------------------------------------------------------------------------------------------
# the methods


def allanite_fixed(allanite, y, method: str) -> float:
    """Per-call fixed cost of allanite.davar on this record: input checks and mean, no real work
    (window 2, one window, m = 1). Best of 3."""
    best, _, _ = timed(
        lambda: allanite.davar(y, FS, window=2, hop=y.size, taus=[1 / FS], method=method, workers=WORKERS), short=1e9
    )
    return best


def prewarm(nbytes: int) -> float:
    """Touch and free ``nbytes`` of fresh memory; returns the seconds it took.

    On this benchmark's VM, memory the guest has not used for a few seconds is handed back to the host,
    and touching it again costs ~3 s/GiB (vs ~0.25 s/GiB for the guest's own page faults). Touching the
    output's size just before a timed call keeps that hypervisor cost out of the DAVAR timings."""
    if nbytes < 64 * 2**20:
        return 0.0
    t0 = time.perf_counter()
    a = np.ones(int(nbytes) // 8)
    del a
    return time.perf_counter() - t0


def run_rows(name, fn, ms_timed, n_win, chunk_bytes, probe: Probe, fixed: float):
    """Time ``fn(ms)`` (hop-1 result, shape (len(ms), n_win)) for ``ms_timed``, in chunks of m if
    the output exceeds ``chunk_bytes``; each chunk's per-call fixed cost beyond the first is not
    counted (it would not be paid by one call). Returns (seconds, details, blocks)."""
    per_row = n_win * 8
    rows_per_chunk = max(1, int(chunk_bytes // per_row))
    chunks = [ms_timed[i : i + rows_per_chunk] for i in range(0, ms_timed.size, rows_per_chunk)]
    warm = prewarm(min(chunk_bytes, ms_timed.size * per_row) + 64 * 2**20)
    total, details, blocks = 0.0, [], []
    for ch in chunks:
        best, reps, out = timed(lambda: fn(ch))
        total += best
        details.append({"n_m": int(ch.size), "seconds": best, "repeats": reps})
        blocks += probe.keep(ch, out)
        del out
    if len(chunks) > 1:
        raw = total
        total = raw - (len(chunks) - 1) * min(fixed, 0.5 * raw / len(chunks))
        log(
            f"    {name}: {len(chunks)} chunks of ≤ {rows_per_chunk} m ({ms_timed.size * per_row / GiB:.2f} GiB "
            f"in all): {raw:.3g} s, {total:.3g} s without the extra calls' fixed cost"
        )
    return total, {"chunks": details, "prewarm_seconds": warm, "chunk_rows": rows_per_chunk}, blocks


class Grids:
    """One N's window, averaging factors and sampled windows, and what every method keeps (``probe``)."""

    def __init__(self, n, cfg, allanite, probe_rows, probe_windows):
        self.window = window = n // 10
        self.n_win = n_win = n - window + 1
        self.m_all = m_all = np.arange(1, window // 2 + 1, dtype=np.int64)
        self.m_exp = m_exp = np.round(allanite.tau_grid(window, FS, "exp") * FS).astype(np.int64)
        self.s_m = s_m = evenly(m_all, cfg["fast_m"]) if cfg["fast_m"] else None
        probe_m = np.union1d(m_exp, s_m if s_m is not None else evenly(m_all, probe_rows))

        # Sampled windows: naive uses a hop (windows 0, h, 2h, …); allantools evenly spread windows.
        if cfg["naive_windows"] is None:
            naive_hop = 1
        else:
            naive_hop = max(1, math.ceil((n_win - 1) / max(1, cfg["naive_windows"] - 1)))
        self.naive_hop = naive_hop
        self.naive_n = naive_n = (n - window) // naive_hop + 1
        self.j_naive = j_naive = np.arange(naive_n) * naive_hop
        j_at_all = sample_starts(n_win, cfg["at_all_windows"] or n_win)
        j_at_exp = sample_starts(n_win, cfg["at_exp_windows"] or n_win)
        stride = max(1, math.ceil(n_win / probe_windows))
        self.probe = Probe(
            probe_m,
            np.arange(0, n_win, stride),
            np.concatenate(
                [
                    j_naive if naive_hop > 1 else [],
                    j_at_all if cfg["at_all_windows"] else [],
                    j_at_exp if cfg["at_exp_windows"] else [],
                ]
            ).astype(np.int64),
        )

    def info(self, n) -> dict:
        m_all, m_exp, n_win = self.m_all, self.m_exp, self.n_win
        return {
            "n": n,
            "window": self.window,
            "hop": 1,
            "n_windows": n_win,
            "n_m_all": int(m_all.size),
            "n_m_exp": int(m_exp.size),
            "m_exp": [int(m) for m in m_exp],
            "all_grid_output_gib": m_all.size * n_win * 8 / GiB,
            "exp_grid_output_gib": m_exp.size * n_win * 8 / GiB,
        }


def measure_n(
    n, cfg, y_all, allanite, reference, allantools, chunk_bytes, probe_rows, probe_windows, single_call=False
):
    """Every method at one N. Returns (dict of measurements, dict of blocks)."""
    y = y_all[:n]
    g = Grids(n, cfg, allanite, probe_rows, probe_windows)
    window, n_win, m_all, m_exp, s_m, probe = g.window, g.n_win, g.m_all, g.m_exp, g.s_m, g.probe
    info = g.info(n)
    log(
        f"N = {n}: window {window}, {n_win} windows, all grid {m_all.size} m "
        f"({info['all_grid_output_gib']:.2f} GiB at hop 1), exp grid {m_exp.size} m"
    )
    res, blocks = {}, {}
    mem = int(chunk_bytes) + 1

    fixed_fast = allanite_fixed(allanite, y, "fast")
    fixed_naive = allanite_fixed(allanite, y, "naive")
    info["allanite_fixed_seconds"] = {"fast": fixed_fast, "naive": fixed_naive}

    def dav(ms, method, hop=1):
        return allanite.davar(
            y, FS, window=window, hop=hop, taus=ms / FS, method=method, workers=WORKERS, max_memory=mem
        ).avar

    # fast DAVAR, all m
    ms_t = m_all if s_m is None else s_m
    t, chunks, blocks["fast"] = run_rows(
        "fast", lambda ms: dav(ms, "fast"), ms_t, n_win, chunk_bytes, probe, fixed_fast
    )
    res["fast"] = scaled_rows(
        t, fixed_fast, ms_t.size, m_all.size, chunks, "allanite.davar(method='fast', hop=1, workers=1)"
    )
    if single_call and s_m is None:
        info["single_call_diagnostic"] = single_call_diagnostic(allanite, y, window, m_all.size * n_win * 8)
    # improved fast DAVAR, exp grid, always in full
    t, chunks, blocks["improved"] = run_rows(
        "improved", lambda ms: dav(ms, "fast"), m_exp, n_win, chunk_bytes, probe, fixed_fast
    )
    res["improved"] = scaled_rows(
        t, fixed_fast, m_exp.size, m_exp.size, chunks, "allanite.davar(method='fast', taus=exp grid, hop=1, workers=1)"
    )
    # DAVAR (naive), windows 0, h, 2h, …, m all or sampled
    if g.naive_hop == 1 and cfg["naive_m"] is None:
        t, chunks, blocks["naive"] = run_rows(
            "naive", lambda ms: dav(ms, "naive"), m_all, n_win, chunk_bytes, probe, fixed_naive
        )
        res["naive"] = scaled_rows(
            t, fixed_naive, m_all.size, m_all.size, chunks, "allanite.davar(method='naive', hop=1, workers=1)"
        )
    else:
        res["naive"], blocks["naive"] = naive_sampled(dav, g, cfg["naive_m"], fixed_naive)
    prefix_rows(reference, y, g, cfg, chunk_bytes, info, res, blocks)

    # allantools per window
    if allantools is not None:
        for key, grid, nw, count in (
            ("allantools_all", m_all, cfg["at_all_windows"], cfg["at_all_m"]),
            ("allantools_exp", m_exp, cfg["at_exp_windows"], None),
        ):
            ms_t = grid if count is None else (s_m if s_m is not None and count == s_m.size else evenly(grid, count))
            js = sample_starts(n_win, nw or n_win)
            res[key], blocks[key] = allantools_windows(allantools, y, window, n_win, js, grid, ms_t)
    for key, r in res.items():
        log(f"    {key:15s} {r['seconds']:12.4g} s{'  (extrapolated)' if r['extrapolated'] else ''}")
    return info, res, blocks


def single_call_diagnostic(allanite, y, window, nbytes) -> dict:
    """The whole "all" surface from one call, as a user would make it — once as it comes, once right after
    touching that much memory (see prewarm). A diagnostic, not used in the table."""
    diag = {"output_gib": nbytes / GiB}
    for label in ("as_is", "after_prewarm"):
        if label == "after_prewarm":
            diag["prewarm_seconds"] = prewarm(nbytes + 64 * 2**20)
        gc.collect()
        t0 = time.perf_counter()
        out = allanite.davar(
            y, FS, window=window, hop=1, taus="all", method="fast", workers=WORKERS, max_memory=nbytes + 1
        ).avar
        diag[f"seconds_{label}"] = time.perf_counter() - t0
        del out
    log(
        f"    fast, one call ({diag['output_gib']:.2f} GiB output): {diag['seconds_as_is']:.3g} s as is, "
        f"{diag['seconds_after_prewarm']:.3g} s after touching that memory ({diag['prewarm_seconds']:.3g} s)"
    )
    return diag


def naive_sampled(dav, g: Grids, naive_m, fixed_naive):
    """DAVAR (naive) timed on the windows 0, h, 2h, … (and a sample of m) and extrapolated to every window
    and m. Returns (its row, its kept block)."""
    window, n_win, m_all, naive_hop, naive_n = g.window, g.n_win, g.m_all, g.naive_hop, g.naive_n
    ms_n = m_all if naive_m is None else evenly(m_all, naive_m)
    best, reps, out = timed(lambda: dav(ms_n, "naive", naive_hop))
    blocks = [Block(ms_n, g.j_naive, out)]
    del out
    rec = {
        "how": "",
        "measured_seconds": best,
        "repeats": reps,
        "fixed_seconds": fixed_naive,
        "windows_timed": int(naive_n),
        "windows_total": int(n_win),
        "m_timed": int(ms_n.size),
        "m_total": int(m_all.size),
        "extrapolated": True,
        "call": f"allanite.davar(method='naive', hop={naive_hop}, workers=1)",
    }
    fixed_naive = min(fixed_naive, 0.5 * best)  # never let a noisy fixed cost swallow the work
    rec["fixed_seconds_used"] = fixed_naive
    if ms_n.size < m_all.size:
        # The per-window angle (O(W)) and the call's overhead do not grow with the number of m: time the
        # same windows with m = W/2 alone (one term per window); the difference is the sampled m's
        # work, scaled by the number of terms.
        a_best, a_reps, _ = timed(lambda: dav(np.array([window // 2]), "naive", naive_hop))
        a_best = min(a_best, best)
        angle = max(0.0, (a_best - fixed_naive) / naive_n)
        work = (best - a_best) / naive_n
        term_scale = (n_terms(window, m_all).sum() - 1) / max(1, n_terms(window, ms_n).sum() - 1)
        per_window_all = angle + work * term_scale
        rec.update(
            angle_call_seconds=a_best,
            angle_call_repeats=a_reps,
            angle_per_window_seconds=angle,
            term_scale=float(term_scale),
        )
        rec["how"] = (
            f"{naive_n} windows (hop {naive_hop}) × {ms_n.size} evenly spread m timed "
            f"({best:.3g} s), and the same windows at m = W/2 alone ({a_best:.3g} s: window angles "
            f"+ overhead); per window: angle + (difference / {naive_n}) × "
            f"Σ_all(W+1−2m)/Σ_sample(W+1−2m)"
            f" = {term_scale:.4g}; × {n_win} windows; + fixed {fixed_naive:.2g} s"
        )
    else:
        per_window_all = (best - fixed_naive) / naive_n
        rec["how"] = (
            f"{naive_n} windows (hop {naive_hop}) at every m timed ({best:.3g} s); "
            f"(time − fixed {fixed_naive:.2g} s) / {naive_n} × {n_win} windows + fixed"
        )
    rec["seconds"] = fixed_naive + per_window_all * n_win
    return rec, blocks


def prefix_rows(reference, y, g: Grids, cfg, chunk_bytes, info, res, blocks) -> None:
    """The NumPy prefix-sum twin on the all and exp grids, into ``res`` and ``blocks``."""
    window, n_win, s_m = g.window, g.n_win, g.s_m
    t0 = time.perf_counter()
    for _ in range(3):
        reference.angle_from_rate(y, FS)
    fixed_prefix = (time.perf_counter() - t0) / 3
    info["prefix_fixed_seconds"] = fixed_prefix

    def pref(ms):
        return reference.davar_prefix(y, FS, window, 1, ms)

    for key, grid, count in (
        ("prefix_all", g.m_all, cfg["prefix_all_m"]),
        ("prefix_exp", g.m_exp, cfg["prefix_exp_m"]),
    ):
        if count is None:
            ms_t = grid
        elif key == "prefix_all" and s_m is not None and count == s_m.size:
            ms_t = s_m
        else:
            ms_t = evenly(grid, count)
        t, chunks, blocks[key] = run_rows(key, pref, ms_t, n_win, chunk_bytes, g.probe, fixed_prefix)
        res[key] = scaled_rows(
            t,
            fixed_prefix,
            ms_t.size,
            grid.size,
            chunks,
            "allanite._reference.davar_prefix(hop=1)",
            fixed_name="cumulative angle",
        )


def scaled_rows(t, fixed, n_timed, n_total, det, call, fixed_name="input checks and mean"):
    """A whole-record method timed on ``n_timed`` of ``n_total`` m (each m costs about the same)."""
    chunks = det["chunks"]
    rec = {
        "call": call,
        "measured_seconds": t,
        **det,
        "m_timed": int(n_timed),
        "m_total": int(n_total),
        "fixed_seconds": fixed,
        "extrapolated": n_timed < n_total,
    }
    how = f"all {n_total} m timed" if n_timed == n_total else f"{n_timed} of {n_total} m timed"
    if len(chunks) > 1:
        how += (
            f" in {len(chunks)} calls of ≤ {det['chunk_rows']} m (outputs ≤ chunk size); sum of the call times "
            f"minus {len(chunks) - 1} × the fixed cost ({fixed:.2g} s [{fixed_name}])"
        )
    else:
        reps = chunks[0]["repeats"]
        if len(reps) > 1:
            how += f"; best of {len(reps)} runs"
    if n_timed < n_total:
        fixed = min(fixed, 0.5 * t)  # tiny (quick-mode) runs: never let a noisy fixed cost swallow the work
        rec["fixed_seconds_used"] = fixed
        rec["seconds"] = fixed + (t - fixed) * n_total / n_timed
        how += (
            f" ({t:.3g} s, evenly spread m); extrapolated: (time − fixed {fixed:.2g} s [{fixed_name}]) × "
            f"{n_total}/{n_timed} + fixed"
        )
    else:
        rec["seconds"] = t
    rec["how"] = how
    return rec


def allantools_windows(allantools, y, window, n_win, js, grid, ms_t):
    """allantools.oadev on windows ``js`` at ``ms_t``; extrapolated to every window and every m of ``grid``."""
    per_window, phase_times, blocks, missing, exact = [], [], [], 0, True
    term_scale = float(n_terms(window, grid).sum() / n_terms(window, ms_t).sum())
    taus = ms_t / FS
    for j in js:
        seg = y[int(j) : int(j) + window]
        t0 = time.perf_counter()
        allantools.frequency2phase(seg, FS)
        t_phase = time.perf_counter() - t0
        t0 = time.perf_counter()
        t_used, dev, _e, _n = allantools.oadev(seg, rate=FS, data_type="freq", taus=taus)
        t_call = time.perf_counter() - t0
        t_used = np.asarray(t_used, dtype=np.float64)
        m_used = np.round(t_used * FS).astype(np.int64)
        exact &= bool(np.all(np.isin(m_used, ms_t)))
        missing = max(missing, int(ms_t.size - m_used.size))
        blocks.append(Block(m_used, [int(j)], (np.asarray(dev, dtype=np.float64) ** 2)[:, None]))
        phase_times.append(t_phase)
        per_window.append(t_phase + max(0.0, t_call - t_phase) * term_scale)
    mean = float(np.mean(per_window))
    rec = {
        "call": "allantools.oadev(y[j:j+W], rate=fs, data_type='freq', taus=m/fs) per window",
        "windows_timed": int(len(js)),
        "windows_total": int(n_win),
        "m_timed": int(ms_t.size),
        "m_total": int(grid.size),
        "sample_windows": [int(j) for j in js[:50]],
        "mean_phase_seconds": float(np.mean(phase_times)),
        "term_scale": term_scale,
        "mean_per_window_seconds": mean,
        "seconds": mean * n_win,
        "extrapolated": len(js) < n_win or ms_t.size < grid.size,
        "taus_missing_from_allantools": missing,
        "taus_subset_of_requested": exact,
    }
    if not rec["extrapolated"]:
        rec["how"] = f"every window at every m, one run ({mean * n_win:.3g} s)"
    else:
        how = f"{len(js)} evenly spread windows"
        if ms_t.size < grid.size:
            how += (
                f" × {ms_t.size} evenly spread m; per window: phase (frequency2phase, timed alone) + the rest "
                f"× Σ_all(W+1−2m)/Σ_sample(W+1−2m) = {term_scale:.4g}"
            )
        else:
            how += " at every m"
        how += f"; mean per window {mean:.3g} s × {n_win} windows"
        rec["how"] = how
    if missing:
        rec["note"] = (
            f"allantools drops m with a single term (m = W/2): {missing} of the requested m not "
            f"returned; timed as called"
        )
    return rec, blocks


# ----------------------------------------------------------------------------------------------
# scaling (subprocess per measurement)


def vm_hwm() -> int:
    """This process's peak resident set (bytes), from /proc/self/status VmHWM.

    Not ``getrusage(RUSAGE_SELF).ru_maxrss``: on Linux that high-water mark lives in the signal struct,
    which fork copies and execve keeps, so a child started from a big parent reports the parent's peak.
    VmHWM belongs to the address space, which execve replaces: it is the child's own peak."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmHWM:"):
            return int(line.split()[1]) * 1024
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def child_scaling(n: int, workers: int, repeats: int) -> dict:
    """Runs in a fresh process: improved fast DAVAR, window N/10, hop N/1000, exp grid."""
    import resource

    import allanite

    y = np.random.default_rng(SEED).standard_normal(n)
    window, hop = n // 10, max(1, n // 1000)
    rss_before = vm_hwm()
    times, res = [], None
    for _ in range(repeats):
        res = None
        t0 = time.perf_counter()
        res = allanite.davar(y, FS, window=window, hop=hop, taus="exp", method="fast", workers=workers)
        times.append(time.perf_counter() - t0)
    peak = vm_hwm()
    ru_maxrss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    return {
        "n": n,
        "window": window,
        "hop": hop,
        "workers": workers,
        "n_m": int(res.m.size),
        "n_windows": int(res.avar.shape[1]),
        "seconds": min(times),
        "repeats": times,
        "input_bytes": int(y.nbytes),
        "output_bytes": int(res.avar.nbytes),
        "peak_rss_bytes": int(peak),
        "rss_before_call_bytes": int(rss_before),
        "call_extra_peak_bytes": int(peak - rss_before),
        "ru_maxrss_bytes": int(ru_maxrss),
        # bit-exact fingerprint (np.sum would not do: its SIMD pairwise order depends on the array's
        # alignment, so equal arrays can sum differently)
        "sha256": hashlib.sha256(np.ascontiguousarray(res.avar).tobytes()).hexdigest(),
        "fsum": math.fsum(res.avar.ravel().tolist()),
    }


def scaling(sizes, repeats_map, wait: float = 0.0) -> list[dict]:
    out = []
    for n in sizes:
        for w in (1, 2):
            idle = wait_idle(wait) if wait > 0 else None
            reps = repeats_map.get(n, 3)
            cmd = [sys.executable, str(Path(__file__).resolve()), "--_child-scaling", str(n), str(w), str(reps)]
            with Load() as ld:
                proc = subprocess.run(cmd, capture_output=True, text=True, timeout=1800)
            if proc.returncode != 0:
                raise RuntimeError(f"scaling child N={n} workers={w} failed:\n{proc.stderr[-3000:]}")
            r = json.loads(proc.stdout.strip().splitlines()[-1])
            r["other_processes_cpu_fraction"] = ld.fraction
            r["idle_wait"] = idle
            out.append(r)
            log(
                f"  scaling N={n:>11,} workers={w}: {r['seconds']:.4f} s, "
                f"peak RSS {r['peak_rss_bytes'] / 2**20:.0f} MiB"
                f" (before the call {r['rss_before_call_bytes'] / 2**20:.0f} MiB)"
            )
    by_n = {}
    for r in out:
        by_n.setdefault(r["n"], {})[r["workers"]] = r
    for n, d in by_n.items():
        if 1 in d and 2 in d:
            same = d[1]["sha256"] == d[2]["sha256"]
            d[1]["speedup_2_workers"] = d[2]["speedup_2_workers"] = d[1]["seconds"] / d[2]["seconds"]
            d[1]["bit_identical_1_vs_2"] = d[2]["bit_identical_1_vs_2"] = same
    return out


# ----------------------------------------------------------------------------------------------
# reports


def fmt_s(x, extrap=False) -> str:
    if x is None:
        return "—"
    if x >= 1e5:
        s = f"{x:.3g}"
    elif x >= 100:
        s = f"{x:,.0f}"
    elif x >= 0.01:
        s = f"{x:.3g}"
    else:
        s = f"{x:.2g}"
    return s + (" (extrap.)" if extrap else "")


def fmt_n(n: int) -> str:
    k = round(math.log10(n))
    return f"1e{k}" if 10**k == n else f"{n:,}"


def fmt_bytes(b) -> str:
    return f"{b / 2**30:.3g} GiB" if b >= 2**30 else (f"{b / 2**20:.3g} MiB" if b >= 2**20 else f"{b / 1024:.3g} KiB")


def fmt_ratio(x) -> str:
    if x is None or not math.isfinite(x):
        return "—"
    return f"{x:.1f}×" if x < 1000 else f"{x:,.0f}×"


def fmt_share(x) -> str:
    return "—" if x is None else f"{x:.0%}"


def fmt_diff(d) -> str:
    return "—" if d is None else ("0" if d == 0 else f"{d:.1e}")


PAIRS = [
    ("naive", "fast"),
    ("improved", "fast"),
    ("prefix_all", "fast"),
    ("allantools_all", "fast"),
    ("naive", "improved"),
    ("prefix_exp", "improved"),
    ("allantools_exp", "improved"),
    ("prefix_all", "naive"),
    ("allantools_all", "naive"),
    ("prefix_exp", "prefix_all"),
    ("allantools_all", "prefix_all"),
    ("allantools_exp", "prefix_exp"),
    ("allantools_exp", "allantools_all"),
]


def ratios(row):
    def sec(k):
        return row["methods"].get(k, {}).get("seconds")

    out = {}
    for key, (a, b) in {
        "naive_over_fast": ("naive", "fast"),
        "fast_over_improved": ("fast", "improved"),
        "naive_over_improved": ("naive", "improved"),
        "prefix_all_over_fast": ("prefix_all", "fast"),
        "prefix_exp_over_improved": ("prefix_exp", "improved"),
        "allantools_all_over_fast": ("allantools_all", "fast"),
        "allantools_exp_over_improved": ("allantools_exp", "improved"),
    }.items():
        sa, sb = sec(a), sec(b)
        out[key] = None if sa is None or sb is None or sb <= 0 else sa / sb
    p = PAPER.get(row["n"])
    out["paper_naive_over_fast"] = None if p is None else p["naive"] / p["fast"]
    out["paper_fast_over_improved"] = None if p is None else p["fast"] / p["improved"]
    return out


def write_markdown(report, path: Path):
    rows = report["table"]
    lines = _md_table(report) + _md_grids(rows) + _md_growth(rows) + _md_instead(rows) + _md_agreement(report)
    lines += _md_how(report) + _md_scaling(report)
    if report["mode"] == "quick":
        lines += ["_Quick mode: tiny sizes — a correctness smoke test of the script, not a timing result._", ""]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")


def _md_table(report) -> list[str]:
    """The page's head and the table itself: ours against paper 000 per N and method."""
    rows = report["table"]
    m = report["machine"]
    lines = [
        "# Paper 000, Table 3 — DAVAR vs fast DAVAR vs improved fast DAVAR",
        "",
        f"Generated by `python benches/table3.py{' --quick' if report['mode'] == 'quick' else ''}` on "
        f"{m['date_utc']}. Machine: {m['cpu_model']}, {m['cpus_usable']} usable cores; "
        f"Python {m['versions']['python']}, NumPy {m['versions']['numpy']}, allanite {m['versions']['allanite']}, "
        f"allantools {m['versions'].get('allantools')}, {m.get('rustc')}; git {m.get('git_commit')}. "
        f"Load average at start: {', '.join(f'{v:.2f}' for v in (m.get('loadavg_start') or []))}.",
        "",
        "Paper: Matlab 7.11 on a 3 GHz Core 2 Duo. Ours: white noise (standard normal, seed "
        f"{SEED}), window W = N/10, hop 1, one thread (`workers=1`) for every method. "
        '"(extrap.)" marks a time extrapolated from a timed sample (see *How each number was obtained*).',
        "",
        "| N | W | DAVAR (ours) | DAVAR (paper) | fast (ours) | fast (paper) | improved (ours) | improved (paper) | "
        "DAVAR / fast (ours) | (paper) | fast / improved (ours) | (paper) |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        me, p, q = r["methods"], PAPER.get(r["n"], {}), r["ratios"]

        def cell(k):
            d = me.get(k)
            return "—" if d is None else fmt_s(d["seconds"], d["extrapolated"])

        lines.append(
            f"| {fmt_n(r['n'])} | {r['window']:,} | {cell('naive')} | {fmt_s(p.get('naive'))} | {cell('fast')} | "
            f"{fmt_s(p.get('fast'))} | {cell('improved')} | {fmt_s(p.get('improved'))} | "
            f"{fmt_ratio(q['naive_over_fast'])} | {fmt_ratio(q['paper_naive_over_fast'])} | "
            f"{fmt_ratio(q['fast_over_improved'])} | {fmt_ratio(q['paper_fast_over_improved'])} |"
        )
    return lines


def _md_grids(rows) -> list[str]:
    """The other processes' CPU share per N, and the grids and window used."""
    lines: list[str] = []
    loads = [
        f"{fmt_n(r['n'])}: {r['other_processes_cpu_fraction']:.0%}"
        for r in rows
        if r.get("other_processes_cpu_fraction") is not None
    ]
    lines += [
        "",
        "Share of the CPUs used by other processes while each N ran (the machine is shared; 2 cores, our "
        "calls use one): " + ", ".join(loads) + ".",
        "",
        'Grids: DAVAR and fast DAVAR evaluate every m = 1 … W/2 (allanite\'s `taus="all"`; paper 000 writes '
        "m = 1 … N_w/2 − 1, one row fewer); improved fast DAVAR evaluates paper 000 §4.2's exponential grid "
        '(`taus="exp"`: 100 points up to m = W/9, duplicates dropped — the number of m is in the last table).',
        "",
        "Window: W = N/10 (paper 000 does not give one). It keeps ~0.9 N windows, so the DAVAR surface is as long "
        "as the record, and at N = 1e3 W/9 = 11 still leaves the exponential grid 11 τ.",
        "",
    ]
    return lines


def _md_growth(rows) -> list[str]:
    """Growth per decade of N against each method's work model (only where N grows by 10×)."""
    lines: list[str] = []
    decades = [(a, b) for a, b in zip(rows, rows[1:]) if b["n"] == 10 * a["n"]]
    if decades:
        head, rule = "| method |", "|---|"
        for a, b in decades:
            head += f" {fmt_n(a['n'])} → {fmt_n(b['n'])} (ours) |"
            rule += "---|"
            if a["n"] in PAPER and b["n"] in PAPER:
                head += " (paper) |"
                rule += "---|"
        lines += [
            "### Growth per decade of N (time at 10 N / time at N)",
            "",
            head + " work model, W = N/10 |",
            rule + "---|",
        ]
    models = {
        "naive": "(N − W + 1) windows × Σ_m (W + 1 − 2m) ≈ 0.9 N · W²/4 ∝ N³: ×1000",
        "fast": "W/2 values of m × O(N) each ∝ N²: ×100",
        "improved": "exp-grid size (56 → 92 m from W = 1e3 to 1e6) × O(N) ∝ N: ×10–13",
    }
    for k in ("naive", "fast", "improved") if decades else ():
        cells = []
        for a, b in decades:
            sa, sb = a["methods"].get(k, {}).get("seconds"), b["methods"].get(k, {}).get("seconds")
            cells.append(fmt_ratio(sb / sa) if sa and sb else "—")
            if b["n"] in PAPER and a["n"] in PAPER:
                cells.append(fmt_ratio(PAPER[b["n"]][k] / PAPER[a["n"]][k]))
        lines.append(f"| {k} | " + " | ".join(cells) + f" | {models[k]} |")
    return lines


def _md_instead(rows) -> list[str]:
    """What users would do instead: NumPy prefix sums and allantools on the same grids."""
    lines = [
        "",
        "## What users would do instead (same grids, same run, seconds)",
        "",
        "| N | fast DAVAR (ours) | NumPy prefix sums, all m | allantools per window, all m | improved (ours) | "
        "NumPy prefix sums, exp grid | allantools per window, exp grid |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        me, q = r["methods"], r["ratios"]

        def cell(k, ratio=None):
            d = me.get(k)
            if d is None:
                return "—"
            s = fmt_s(d["seconds"], d["extrapolated"])
            return s if ratio is None else f"{s} = {fmt_ratio(q[ratio])}"

        lines.append(
            f"| {fmt_n(r['n'])} | {cell('fast')} | {cell('prefix_all', 'prefix_all_over_fast')} | "
            f"{cell('allantools_all', 'allantools_all_over_fast')} | {cell('improved')} | "
            f"{cell('prefix_exp', 'prefix_exp_over_improved')} | "
            f"{cell('allantools_exp', 'allantools_exp_over_improved')} |"
        )
    return lines + ["", "(× = that method's time over allanite's on the same grid.)"]


def _md_agreement(report) -> list[str]:
    """The agreement of every pair of methods, and which differences the 1e-9 check covers."""
    rows = report["table"]
    lines = [
        "",
        "## Agreement (max relative difference |a − b| / |b| at every shared m and window kept)",
        "",
        "| a vs b | " + " | ".join(f"N = {fmt_n(r['n'])}" for r in rows) + " |",
        "|---|" + "---|" * len(rows),
    ]
    for a, b in PAIRS:
        cells = []
        for r in rows:
            c = r["agreement"].get(f"{a} vs {b}")
            if c is None or c["n_compared"] == 0:
                cells.append("—")
            elif "prefix" in a or "prefix" in b:
                hi = (
                    ""
                    if not c["n_compared_m_gt_w9"]
                    else f"; m > W/9: {fmt_diff(c['max_rel_diff_m_gt_w9'])} ({c['n_compared_m_gt_w9']:,})"
                )
                cells.append(f"m ≤ W/9: **{fmt_diff(c['max_rel_diff_m_le_w9'])}** ({c['n_compared_m_le_w9']:,}){hi}")
            else:
                cells.append(f"**{fmt_diff(c['max_rel_diff'])}** ({c['n_compared']:,})")
        if any(c != "—" for c in cells):
            lines.append(f"| {a} vs {b} | " + " | ".join(cells) + " |")
    worst = report["max_rel_diff_overall"]
    lines += [
        "",
        f"In parentheses: values compared; in bold: what the 1e-9 check applies to. Largest checked "
        f"difference: {fmt_diff(worst)} — {'within' if worst is not None and worst <= 1e-9 else 'NOT within'}"
        f" the 1e-9 tolerance. Every pair of allanite (naive, fast, improved) and allantools is checked at "
        "every shared value. The NumPy prefix-sum twin is checked at m ≤ W/9 (paper 000's range, ≥ 9 "
        "clusters): beyond, a window holds few terms (one at m = W/2) and its global cumulative sums, "
        "differenced, cancel catastrophically — its own rounding (`_reference.davar_prefix` says so), shown "
        "as the m > W/9 figure, not a disagreement among the others.",
        "",
        "Kept for comparison: every method's values at the m of the exp grid plus an evenly spread set of "
        'the "all" grid\'s m (or the timed sample), at evenly strided windows, and every computed m at the '
        "naive and allantools sample windows.",
        "",
    ]
    return lines


def _md_how(report) -> list[str]:
    """How each number was obtained: per N and method, the timing rule and the memory note."""
    rows = report["table"]
    lines = [
        "## How each number was obtained",
        "",
        "| N | method | seconds | extrapolated | how |",
        "|---|---|---|---|---|",
    ]
    for r in rows:
        for k, d in r["methods"].items():
            ex = "extrapolated" if d["extrapolated"] else "no"
            lines.append(f"| {fmt_n(r['n'])} | {k} | {fmt_s(d['seconds'])} | {ex} | {d['how']} |")
    full_n = max((r for r in rows if not r["methods"]["fast"]["extrapolated"]), key=lambda r: r["n"])
    lines += [
        "",
        "Timing: `time.perf_counter` around each call; a call under 1 s is repeated up to 3 times (under "
        "0.05 s: 9 times) and the best kept (every repeat is in the JSON). Fixed per-call costs are "
        "measured separately and not "
        "scaled when extrapolating.",
        "",
        f"Memory: a hop-1 surface is large (all m at N = {fmt_n(full_n['n'])}: "
        f"{full_n['all_grid_output_gib']:.2f}"
        f" GiB), so outputs are produced in calls of at most {fmt_bytes(report['setup']['chunk_bytes'])} "
        "(chunks of m; every value is computed, the times are summed, and the extra calls' fixed cost is "
        "subtracted), and that much memory is touched just before the first call. Reason: on this VM, memory "
        "the guest has not used for a few seconds goes back to the host, and touching it again costs "
        "~3 s/GiB — a hypervisor cost, not DAVAR's.",
    ]
    for r in rows:
        d = r.get("single_call_diagnostic")
        if d:
            lines.append(
                f"For scale, at N = {fmt_n(r['n'])} the fast DAVAR's whole surface "
                f"({d['output_gib']:.2f} GiB) "
                f"from one call took {d['seconds_as_is']:.3g} s as it came and "
                f"{d['seconds_after_prewarm']:.3g} s right after touching that much memory "
                f"({d['prewarm_seconds']:.3g} s), against {r['methods']['fast']['seconds']:.3g} s in "
                f"chunks (the table)."
            )
    lines.append("")
    return lines


def _md_scaling(report) -> list[str]:
    """The scaling rows (fresh process per row), when the report has them."""
    lines: list[str] = []
    sc = report.get("scaling")
    if sc:
        sr = report.get("scaling_run")
        lines += ["## Scaling — improved fast DAVAR, window N/10, hop N/1000, exp grid (fresh process per row)", ""]
        if sr:
            lines += [
                f"Run separately (`--scaling-only`) on {sr['date_utc']}, load average at start "
                f"{', '.join(f'{v:.2f}' for v in sr['loadavg_start'])}.",
                "",
            ]
        lines += [
            "| N | window | hop | m | windows | workers | seconds | ns per sample per m | speed-up 2 vs 1 | "
            "peak RSS (MiB) | RSS before call (MiB) | call's extra peak (MiB) | other processes' CPU share |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
        ]
        for s in sc:
            nsps = s["seconds"] / (s["n"] * s["n_m"]) * 1e9
            lines.append(
                f"| {fmt_n(s['n'])} | {s['window']:,} | {s['hop']:,} | {s['n_m']} | {s['n_windows']} | "
                f"{s['workers']} | {s['seconds']:.4g} | {nsps:.2f} | "
                f"{fmt_ratio(s.get('speedup_2_workers')) if s['workers'] == 2 else ''} | "
                f"{s['peak_rss_bytes'] / 2**20:,.0f} | {s['rss_before_call_bytes'] / 2**20:,.0f} | "
                f"{s['call_extra_peak_bytes'] / 2**20:,.0f} | "
                f"{fmt_share(s.get('other_processes_cpu_fraction'))} |"
            )
        lines += [
            "",
            "Peak RSS is the child's VmHWM (/proc/self/status; `ru_maxrss` is not used because on Linux a "
            "child started by fork + exec inherits its parent's high-water mark — recorded in the JSON "
            "anyway). It includes the Python interpreter, NumPy, allanite and the "
            'input record (8 bytes per sample); "before call" is the same after the record was generated; '
            "the difference is what the DAVAR call added at its peak. "
            + (
                "Results with 1 and 2 workers are bit-identical at every N (SHA-256 of the outputs equal)."
                if all(s.get("bit_identical_1_vs_2", True) for s in sc)
                else "Results with 1 and 2 workers are NOT bit-identical at N = "
                + ", ".join(sorted({fmt_n(s["n"]) for s in sc if s.get("bit_identical_1_vs_2") is False}))
                + "."
            ),
            "",
        ]
    return lines


def plot(report, out: Path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    _plot_table(report, out, plt)
    sc = report.get("scaling")
    if sc:
        _plot_scaling(sc, out, plt)


def _plot_table(report, out: Path, plt) -> None:
    """table3.png: every method's seconds against N, beside paper 000 Table 3."""
    rows = report["table"]
    fig, ax = plt.subplots(figsize=(11, 6))
    styles = {
        "naive": ("C3", "o", "DAVAR (naive)"),
        "fast": ("C0", "s", "fast DAVAR"),
        "improved": ("C2", "^", "improved fast DAVAR"),
        "prefix_all": ("C1", "D", "NumPy prefix sums, all m"),
        "prefix_exp": ("C1", "v", "NumPy prefix sums, exp"),
        "allantools_all": ("C4", "P", "allantools per window, all m"),
        "allantools_exp": ("C4", "X", "allantools per window, exp"),
    }
    for k, (c, mk, label) in styles.items():
        pts = [(r["n"], r["methods"][k]["seconds"], r["methods"][k]["extrapolated"]) for r in rows if k in r["methods"]]
        if not pts:
            continue
        ls = "-" if k in ("naive", "fast", "improved") else ":"
        ax.plot([p[0] for p in pts], [p[1] for p in pts], ls, color=c, lw=1.2, label=label)
        for n, s, ex in pts:
            ax.plot([n], [s], mk, color=c, mfc="none" if ex else c, ms=7)
    for k, mk in (("naive", "o"), ("fast", "s"), ("improved", "^")):
        ns = sorted(PAPER)
        ax.plot(ns, [PAPER[n][k] for n in ns], "--", color=styles[k][0], lw=1, alpha=0.6)
        ax.plot(
            ns,
            [PAPER[n][k] for n in ns],
            mk,
            color="k",
            mfc=styles[k][0],
            ms=9,
            alpha=0.5,
            label=f"paper 000 Table 3: {styles[k][2]}",
        )
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("record length N (samples); window N/10, hop 1")
    ax.set_ylabel("seconds")
    m = report["machine"]
    ax.set_title(
        f"DAVAR timing vs paper 000 Table 3 (Matlab, Core 2 Duo 3 GHz)\nours: {m['cpu_model']}, 1 thread"
        + (" — QUICK MODE" if report["mode"] == "quick" else ""),
        fontsize=9,
    )
    ax.grid(True, which="both", alpha=0.3)
    ax.plot([], [], "o", color="grey", mfc="none", label="hollow: extrapolated from a timed sample")
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0)
    fig.tight_layout()
    fig.savefig(out / "table3.png", dpi=120)
    plt.close(fig)


def _plot_scaling(sc, out: Path, plt) -> None:
    """scaling.png: the improved fast DAVAR's time and peak memory against N, 1 and 2 workers."""
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.5))
    for w, c in ((1, "C0"), (2, "C2")):
        pts = [s for s in sc if s["workers"] == w]
        a1.plot([s["n"] for s in pts], [s["seconds"] for s in pts], "o-", color=c, label=f"{w} worker(s)")
        a2.plot(
            [s["n"] for s in pts],
            [s["peak_rss_bytes"] / 2**20 for s in pts],
            "o-",
            color=c,
            label=f"peak RSS, {w} worker(s)",
        )
        a2.plot(
            [s["n"] for s in pts],
            [s["call_extra_peak_bytes"] / 2**20 for s in pts],
            "x:",
            color=c,
            label=f"added by the call, {w} worker(s)",
        )
    big = max(sc, key=lambda s: (s["n"], -s["workers"]))
    ns = np.array(sorted({s["n"] for s in sc}), dtype=float)
    a1.plot(ns, big["seconds"] * ns / big["n"], "k--", lw=0.8, alpha=0.6, label="∝ N")
    a2.plot(ns, ns * 8 / 2**20, "k--", lw=0.8, alpha=0.6, label="input record (8 B × N)")
    for a in (a1, a2):
        a.set_xscale("log")
        a.set_yscale("log")
        a.grid(True, which="both", alpha=0.3)
        a.set_xlabel("N (samples); window N/10, hop N/1000, exp grid")
        a.legend(fontsize=7)
    a1.set_ylabel("seconds")
    a2.set_ylabel("MiB")
    a1.set_title("improved fast DAVAR: time", fontsize=9)
    a2.set_title("peak resident memory of a fresh process", fontsize=9)
    fig.tight_layout()
    fig.savefig(out / "scaling.png", dpi=120)
    plt.close(fig)


# ----------------------------------------------------------------------------------------------
# criterion


def run_criterion(out: Path) -> None:
    """cargo bench -p allanite-core; the median time per bench id -> out/criterion.md."""
    cmd = ["cargo", "bench", "-p", "allanite-core"]
    log("running " + " ".join(cmd) + " (a few minutes)")
    load = os.getloadavg()
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, cwd=REPO, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    text = proc.stdout + "\n" + proc.stderr
    if proc.returncode != 0:
        raise SystemExit(f"cargo bench failed:\n{text[-3000:]}")
    rows, name = [], None
    for line in text.splitlines():
        mt = re.match(r"^(\S.*?)\s+time:\s+\[(.+?)\]", line)
        if mt is None:
            if re.match(r"^[A-Za-z0-9_]+/\S+$", line.strip()) and "time:" not in line:
                name = line.strip()
            mt2 = re.match(r"^\s+time:\s+\[(.+?)\]", line)
            if mt2 and name:
                rows.append([name, mt2.group(1), ""])
            mt3 = re.match(r"^\s+thrpt:\s+\[(.+?)\]", line)
            if mt3 and rows:
                rows[-1][2] = mt3.group(1)
            continue
        name = mt.group(1).strip()
        rows.append([name, mt.group(2), ""])
    m = machine_info()
    lines = [
        "# Criterion benches of the Rust core (`cargo bench -p allanite-core`)",
        "",
        f"Run {m['date_utc']} on {m['cpu_model']} ({m['cpus_usable']} usable cores), {m.get('rustc')}, git "
        f"{m.get('git_commit')}; load average at start {', '.join(f'{v:.2f}' for v in load)}; "
        f"{wall:.0f} s in all. Benches: `rust/core/benches/core_loops.rs` (one thread each).",
        "",
        "Times are criterion's [lower bound, estimate, upper bound] of the time per iteration.",
        "",
        "| bench id | time per iteration | throughput |",
        "|---|---|---|",
    ]
    for r in rows:
        lines.append(f"| `{r[0]}` | {r[1]} | {r[2] or '—'} |")
    lines += [
        "",
        "Rerun: `cargo bench -p allanite-core` (or `python benches/table3.py --criterion`, which also "
        "rewrites this file). Bench ids: `fast_one_m/<m>` — one averaging factor over 200 000 samples "
        "(window 40 000, hop 100); `davar_n1e5_w1e4/*` — DAVAR of 1e5 samples, window 1e4, "
        "paper 000's exponential grid, fast at hop 1 and 100, classic (non-overlapping) at hop 100, naive "
        "at hop 1000.",
        "",
    ]
    (out / "criterion.md").write_text("\n".join(lines), encoding="utf-8")
    log((out / "criterion.md").read_text(encoding="utf-8"))


# ----------------------------------------------------------------------------------------------


def rerun_scaling(quick: bool, out: Path | None, wait: float) -> dict:
    """Redo only the scaling part and merge it into an existing ``table3.json`` in ``out``."""
    cfg = QUICK if quick else FULL
    out = Path(out) if out is not None else HERE / "results"
    path = out / "table3.json"
    if not path.is_file():
        raise SystemExit(f"--scaling-only needs an existing {path}: run the full benchmark first")
    report = json.loads(path.read_text(encoding="utf-8"))
    log("scaling only (fresh process per measurement)")
    start = {"date_utc": machine_info()["date_utc"], "loadavg_start": list(os.getloadavg())}
    report["scaling"] = scaling(cfg["scaling"], cfg["scaling_repeats"], min(wait, 60.0) if wait else 0.0)
    report["scaling_run"] = {
        **start,
        "loadavg_end": list(os.getloadavg()),
        "note": "scaling re-run separately (--scaling-only) from the table",
    }
    path.write_text(json.dumps(report, indent=2, ensure_ascii=False) + "\n", encoding="utf-8")
    write_markdown(report, out / "table3.md")
    plot(report, out)
    log(f"updated {path}, table3.md, scaling.png")
    return report


def run(quick: bool, out: Path | None, wait: float, skip_scaling: bool = False) -> dict:
    import allanite
    from allanite import _reference

    cfg = QUICK if quick else FULL
    mode = "quick" if quick else "full"
    if out is None:
        out = Path(tempfile.mkdtemp(prefix="allanite-table3-")) if quick else HERE / "results"
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    try:
        import allantools
    except ImportError:
        allantools = None
        log("allantools not installed: its rows are skipped (pip install allantools)")
    idle = wait_idle(wait) if wait > 0 else None
    t_start = time.perf_counter()
    machine = machine_info()
    machine["idle_wait"] = idle
    sizes = sorted(cfg["table"])
    y = np.random.default_rng(SEED).standard_normal(max(sizes))
    table = []
    for n in sizes:
        idle_n = wait_idle(min(wait, 60.0)) if wait > 0 and n != sizes[0] else None
        table.append(table_row(n, cfg, y, allanite, _reference, allantools, idle_n))
    diffs = [v["checked"] for r in table for v in r["agreement"].values() if v["checked"] is not None]
    sc = None
    if not skip_scaling:
        log("scaling (fresh process per measurement)")
        sc = scaling(cfg["scaling"], cfg["scaling_repeats"], min(wait, 20.0))
    machine["loadavg_end"] = list(os.getloadavg())
    report = {
        "benchmark": "paper 000 Table 3",
        "mode": mode,
        "machine": machine,
        "data": {
            "kind": "white noise, standard normal",
            "seed": SEED,
            "generator": "numpy.random.default_rng",
            "fs": FS,
        },
        "setup": setup_record(cfg),
        "methods": METHODS,
        "paper": {
            "source": "paper 000 Table 3, Matlab 7.11, 3 GHz Core 2 Duo",
            "seconds": {str(k): v for k, v in PAPER.items()},
        },
        "table": table,
        "max_rel_diff_overall": max(diffs) if diffs else None,
        "scaling": sc,
        "total_seconds": time.perf_counter() - t_start,
    }
    (out / "table3.json").write_text(json.dumps(report, indent=2, ensure_ascii=False) + "\n", encoding="utf-8")
    write_markdown(report, out / "table3.md")
    plot(report, out)
    log("")
    log((out / "table3.md").read_text(encoding="utf-8"))
    log(
        f"wrote {out / 'table3.json'}, table3.md, table3.png{', scaling.png' if sc else ''} "
        f"({report['total_seconds']:.1f} s)"
    )
    return report


def table_row(n, cfg, y, allanite, reference, allantools, idle_n) -> dict:
    """One N of the table: every method measured (with the other processes' load) and every pair compared."""
    with Load() as ld:
        info, res, blocks = measure_n(
            n,
            cfg["table"][n],
            y,
            allanite,
            reference,
            allantools,
            cfg["chunk_bytes"],
            cfg["probe_rows"],
            cfg["probe_windows"],
            single_call=n in cfg.get("single_call_diagnostic", ()),
        )
    agreement = {}
    keys = list(res)
    for i, a in enumerate(keys):
        for b in keys[i + 1 :]:
            pair = (a, b) if (a, b) in PAIRS else (b, a)
            name = f"{pair[0]} vs {pair[1]}"
            c = compare(blocks[pair[0]], blocks[pair[1]], info["window"] // 9)
            c["checked"] = checked_diff(name, c)
            c["check_applies_to"] = "m ≤ W/9" if "prefix" in name else "every shared value"
            agreement[name] = c
    del blocks
    gc.collect()
    row = {
        **info,
        "methods": res,
        "agreement": agreement,
        "other_processes_cpu_fraction": ld.fraction,
        "idle_wait": idle_n,
        "paper_seconds": PAPER.get(n),
    }
    row["ratios"] = ratios(row)
    if ld.fraction is not None and ld.fraction > 0.05:
        log(f"  warning: other processes used {ld.fraction:.0%} of the CPUs during N = {n}")
    bad = {k: v for k, v in agreement.items() if v["checked"] is not None and not v["checked"] <= 1e-9}
    if bad:
        log(f"  DISAGREEMENT at N = {n}: {bad}")
    return row


def setup_record(cfg) -> dict:
    """The report's "setup": window, hop, workers, estimator, grids and the sampling per N."""
    return {
        "window": "N/10",
        "hop": 1,
        "workers": WORKERS,
        "estimator": "oavar (overlapping)",
        "grids": {
            "all": "m = 1 … W/2 (paper 000: 1 … W/2 − 1)",
            "exp": "paper 000 §4.2: 100 points m0·g^(i−1) up to W/9, rounded, duplicates dropped",
        },
        "sampling": {str(n): c for n, c in cfg["table"].items()},
        "chunk_bytes": cfg["chunk_bytes"],
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--quick", action="store_true", help="tiny sizes (< 30 s): a smoke test, not a timing result")
    ap.add_argument(
        "--out",
        type=Path,
        default=None,
        help="output folder (default benches/results; with --quick a temporary folder)",
    )
    ap.add_argument(
        "--wait-idle",
        type=float,
        default=0.0,
        metavar="SECONDS",
        help="first wait up to SECONDS for the CPUs to be idle (< 10%% busy for 3 s running)",
    )
    ap.add_argument("--no-scaling", action="store_true", help="skip the scaling part")
    ap.add_argument(
        "--scaling-only",
        action="store_true",
        help="redo only the scaling part, merged into the table3.json already in --out",
    )
    ap.add_argument(
        "--criterion",
        action="store_true",
        help="only run `cargo bench -p allanite-core` and write criterion.md to --out",
    )
    ap.add_argument("--_child-scaling", nargs=3, type=int, metavar=("N", "WORKERS", "REPEATS"), help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args._child_scaling:
        print(json.dumps(child_scaling(*args._child_scaling)))
        return 0
    if args.criterion:
        out = args.out or HERE / "results"
        out.mkdir(parents=True, exist_ok=True)
        run_criterion(out)
        return 0
    if args.scaling_only:
        rerun_scaling(args.quick, args.out, args.wait_idle)
        return 0
    report = run(quick=args.quick, out=args.out, wait=args.wait_idle, skip_scaling=args.no_scaling)
    worst = report["max_rel_diff_overall"]
    if worst is None or not worst <= 1e-9:
        log(f"FAILED: methods disagree (max relative difference {worst})")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
