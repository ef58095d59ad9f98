"""Noise identification and χ² bounds against every Stable32 ADEV/OADEV table in ../shared/data/stable32.

A test helper (imported by ``tests/test_noise_id_stable32.py``) and a script that prints the
agreement tables of ``docs/confidence.md``::

    ALLANITE_SHARED_DATA=/path/to/shared/data python tests/stable32_noise_id.py

For every row of every table it runs ``allanite.avar(x, fs, input=..., taus=AF/fs,
estimator=...).with_confidence(x, **convention)`` — the way a user gets intervals — and compares
the identified α with Stable32's Alpha column and the relative bounds (bound/σ) with Stable32's
Min/Max Sigma over Sigma (relative, because the OCXO octave tables were run on a normalised copy
whose σ differs from the record's by ~5e-4; see test_reference_values.py).

Conventions compared (``CONVENTIONS``): the default call; Stable32's χ² and confidence settings; and
both as they were before the fallback rule (``fallback="none"``, the old default ``b1_n="averages"``).
"""

from __future__ import annotations

import functools
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))  # run as a script: find the test modules

import allanite  # noqa: E402
from allanite.estimators.confidence import ONE_SIGMA  # noqa: E402
from conftest import shared_data_dir  # noqa: E402
from test_confidence import BOUND_TABLES, read_stable32  # noqa: E402

#: dataset -> (record file, column, input kind, fs in Hz); see each folder's SOURCE.txt.
DATASETS = {
    "phasedat": ("phasedat/PHASE.DAT", 0, "angle", 1.0),
    "ocxo": ("ocxo/ocxo_frequency.txt", 0, "rate", 1.0),  # Hz; y = (f − 1e7)/1e7
    "cs5071a": ("cs5071a/5071A_phase.txt.gz", 0, "angle", 1.0),
    "gps1pps": ("gps1pps/gps_1pps_phase_data.txt.gz", 0, "angle", 1.0),
    "tic-floor": ("tic-floor/tic_phase.txt", 0, "angle", 1.0),
    "sr87/freq": ("sr87/freq/freq_data.txt", 1, "rate", 0.4),  # timestamp, y; τ0 = 2.5 s as Stable32 used it
    "sr87/phase": ("sr87/phase/phase_data.txt", 0, "angle", 0.4),
    "sr87/phase0": ("sr87/phase0/phase0_data.txt", 0, "angle", 0.4),
}


def _tables() -> list:
    out = [
        ("phasedat/phase_dat_oadev_octave.txt", "phasedat", "oavar"),
        ("phasedat/phase_dat_adev_octave.txt", "phasedat", "avar"),
        ("phasedat/phase_dat_oadev.txt", "phasedat", "oavar"),
        ("phasedat/phase_dat_adev.txt", "phasedat", "avar"),
        ("ocxo/oadev_octave.txt", "ocxo", "oavar"),
        ("ocxo/adev_octave.txt", "ocxo", "avar"),
        ("ocxo/stable32_oadev_alltau.txt", "ocxo", "oavar"),
        ("ocxo/stable32_adev_alltau.txt", "ocxo", "avar"),
        ("cs5071a/oadev_decade.txt", "cs5071a", "oavar"),
        ("cs5071a/adev_decade.txt", "cs5071a", "avar"),
        ("cs5071a/oadev_all.txt", "cs5071a", "oavar"),
        ("cs5071a/adev_all.txt", "cs5071a", "avar"),
        ("gps1pps/stable32_OADEV_octave.txt", "gps1pps", "oavar"),
        ("gps1pps/stable32_ADEV_decade.txt", "gps1pps", "avar"),
        ("tic-floor/tic_oadev.txt", "tic-floor", "oavar"),
        ("tic-floor/tic_adev.txt", "tic-floor", "avar"),
    ]
    for ds in ("sr87/freq", "sr87/phase", "sr87/phase0"):
        for grid in ("octave", "decade", "many"):
            out += [(f"{ds}/{grid}/oadev.txt", ds, "oavar"), (f"{ds}/{grid}/adev.txt", ds, "avar")]
    return out


#: (table, dataset, estimator): all 34 ADEV/OADEV tables of the shared data.
TABLES = _tables()

#: The issue's check: the last 3 rows of each of the 9 tables with bounds (27 rows).
ISSUE_TABLES = [name for name, *_ in BOUND_TABLES]
ISSUE_ROWS = 3

#: with_confidence keyword sets compared.
CONVENTIONS = {
    "default": {},
    "stable32": {"confidence": ONE_SIGMA, "chi2": "stable32"},
    "before, default": {"b1_n": "averages", "fallback": "none"},
    "before, stable32": {"b1_n": "terms", "fallback": "none", "confidence": ONE_SIGMA, "chi2": "stable32"},
}

SIGMA_TYPE = {"oavar": "Overlapping Allan", "avar": "Allan"}


@dataclass(frozen=True)
class Rows:
    """One table compared: per-row arrays."""

    table: str
    estimator: str
    m: np.ndarray
    points: np.ndarray  # τ-intervals in the record, ⌊samples/m⌋
    alpha_s32: np.ndarray
    alpha: np.ndarray
    has_bounds: bool
    sigma_s32: np.ndarray  # printed Sigma
    lo_s32: np.ndarray  # Min Sigma / Sigma
    hi_s32: np.ndarray  # Max Sigma / Sigma
    lo: np.ndarray  # ours, bound / σ
    hi: np.ndarray
    edf: np.ndarray  # ours, ν per row

    @property
    def same(self) -> np.ndarray:
        return self.alpha == self.alpha_s32

    @property
    def bound_err(self) -> np.ndarray:
        """max(|lo/lo_s32 − 1|, |hi/hi_s32 − 1|) per row (NaN where the table has no bounds)."""
        if not self.has_bounds:
            return np.full(self.m.shape, np.nan)
        return np.maximum(np.abs(self.lo / self.lo_s32 - 1), np.abs(self.hi / self.hi_s32 - 1))


@functools.cache
def load(folder: str, dataset: str):
    """(samples, input kind, fs) of a dataset, read once."""
    rel, col, kind, fs = DATASETS[dataset]
    v = np.loadtxt(Path(folder) / rel, comments="#", ndmin=2)[:, col]
    if dataset == "ocxo":
        v = (v - 1.0e7) / 1.0e7  # exact subtraction first (Sterbenz), then the scale
    return v, kind, fs


def available(s32: Path) -> bool:
    return all((s32 / DATASETS[ds][0]).is_file() for ds in DATASETS) and all((s32 / t).is_file() for t, *_ in TABLES)


def compare(s32: Path, table: str, dataset: str, estimator: str, **kwargs) -> Rows:
    """Our α and relative bounds at every row of one table, with ``with_confidence(x, **kwargs)``."""
    t = read_stable32(s32 / table)
    assert t["header"].get("Sigma Type") == SIGMA_TYPE[estimator], (table, t["header"].get("Sigma Type"))
    x, kind, fs = load(str(s32), dataset)
    r = allanite.avar(x, fs, input=kind, taus=t["m"] / fs, estimator=estimator).with_confidence(x, **kwargs)
    assert np.array_equal(r.m, t["m"]), table
    lo, hi = r.adev_ci
    n = x.size if kind == "rate" else x.size - 1
    has = bool(np.all(t["lo"] > 0))
    with np.errstate(divide="ignore", invalid="ignore"):
        return Rows(
            table=table,
            estimator=estimator,
            m=t["m"],
            points=n // t["m"],
            alpha_s32=t["alpha"],
            alpha=np.asarray(r.alpha),
            has_bounds=has,
            sigma_s32=t["sigma"],
            lo_s32=t["lo"] / t["sigma"],
            hi_s32=t["hi"] / t["sigma"],
            lo=lo / r.adev,
            hi=hi / r.adev,
            edf=np.asarray(r.edf),
        )


def compare_all(s32: Path, convention: str) -> list:
    return [compare(s32, *row, **CONVENTIONS[convention]) for row in TABLES]


def summary(rows: list) -> dict:
    """Agreement counts on the three row sets, and the largest bound difference where α agrees / overall."""

    def count(select):
        same = np.concatenate([r.same[select(r)] for r in rows])
        return int(same.sum()), int(same.size)

    def worst(select, agree_only):
        errs = [r.bound_err[select(r) & (r.same if agree_only else True)] for r in rows if r.has_bounds]
        e = np.concatenate(errs) if errs else np.array([])
        return float(np.nanmax(e)) if e.size else float("nan")

    last3 = lambda r: (np.arange(r.m.size) >= r.m.size - ISSUE_ROWS) & (r.table in ISSUE_TABLES)
    bounds = lambda r: np.full(r.m.size, r.has_bounds)
    every = lambda r: np.ones(r.m.size, bool)
    b1 = lambda r: r.points < 30
    return {
        "issue 27 rows": count(last3),
        "tables with bounds": count(bounds),
        "all rows": count(every),
        "B1 rows (< 30 intervals)": count(b1),
        "ACF rows": count(lambda r: ~b1(r)),
        "bounds, issue rows, α agrees": worst(last3, True),
        "bounds, issue rows, all": worst(last3, False),
        "bounds, all tables, α agrees": worst(bounds, True),
        "bounds, all tables, all": worst(bounds, False),
    }


def differences(rows: list) -> list:
    """(table, m, points, Stable32 α, our α) for every row where α differs."""
    return [
        (r.table, int(m), int(k), int(a), int(b))
        for r in rows
        for m, k, a, b in zip(r.m[~r.same], r.points[~r.same], r.alpha_s32[~r.same], r.alpha[~r.same])
    ]


def issue_rows(results: dict) -> list:
    """Markdown rows for the issue's 27 rows: α and the worst bound difference per convention."""
    names = ("before, default", "before, stable32", "default")
    by = {c: {r.table: r for r in results[c]} for c in names}
    lines = []
    for table in ISSUE_TABLES:
        ref = by["default"][table]
        for i in range(ref.m.size - ISSUE_ROWS, ref.m.size):
            cells = [f"{by[c][table].alpha[i]:+d} ({by[c][table].bound_err[i]:.1%})" for c in names]
            lines.append(
                f"| {table} | {ref.m[i]} | {ref.points[i]} | {ref.alpha_s32[i]:+d} | " + " | ".join(cells) + " |"
            )
    return lines


def main() -> None:
    s32 = shared_data_dir() / "stable32"
    if not available(s32):
        sys.exit(f"Stable32 tables or records not found under {s32} (set ALLANITE_SHARED_DATA)")
    results = {c: compare_all(s32, c) for c in CONVENTIONS}
    keys = list(summary(results["default"]))
    print("| | " + " | ".join(CONVENTIONS) + " |")
    print("|---" * (len(CONVENTIONS) + 1) + "|")
    for k in keys:
        cells = []
        for c in CONVENTIONS:
            v = summary(results[c])[k]
            cells.append(f"{v[0]}/{v[1]}" if isinstance(v, tuple) else f"{v:.2g}")
        print(f"| {k} | " + " | ".join(cells) + " |")
    print("\n| table | AF | τ-intervals | Stable32 α | before, default | before, Stable32 settings | now |")
    print("|---|---|---|---|---|---|---|")
    print("\n".join(issue_rows(results)))
    for c in ("default", "before, default"):
        diffs = differences(results[c])
        print(f"\n{c}: {len(diffs)} rows differ (table, AF, τ-intervals, Stable32 α, ours)")
        for d in diffs:
            print("  ", *d)


if __name__ == "__main__":
    main()
