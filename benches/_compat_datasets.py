"""allanite.compat vs allantools on the data sets of allantools 2024.6's own test suite (issue 31 item 6),
for ``benches/compat_bench.py --datasets``: every deviation of both on each record, octave τ grid, time
and largest relative difference. The records come from the sdist (benches/_allantools_sdist.py: PyPI,
sha256 pinned, cached outside the clone); nothing of allantools is stored here.

allantools' pure-Python loops cap the records it gets: MTOTDEV/TTOTDEV/HTOTDEV/Theo1 only the 1000-point
ones, PDEV ≤ 20 000 points, MTIE ≤ 60 000 (its rolling window costs O(N·m) per τ). allanite's own
MTOTDEV/TTOTDEV/HTOTDEV cost O(N·m) per τ, O(N²) on an octave grid, and run up to 20 000 points; its
Theo1 (O(N²)) up to 250 000.
"""

from __future__ import annotations

import contextlib
import gzip
import io
from pathlib import Path

import numpy as np

import _allantools_sdist as allantools_sdist
import _common
from allanite import compat

#: (name, file in the sdist's tests/, data_type, note)
DATASETS = [
    ("PHASE.DAT", "phasedat/PHASE.DAT", "phase", "Stable32's example phase record"),
    ("NBS14 1000", None, "freq", "NIST SP 1065's 1000-point frequency test record"),
    ("pink", "pink_frequency/pink_frequency.txt", "freq", "flicker-FM frequency record"),
    ("OCXO", "ocxo/ocxo_frequency.txt", "freq", "10 MHz OCXO vs H-maser, fractional frequency"),
    ("53230A TIC", "Keysight53230A_ti_noise_floor/tic_phase.txt", "phase", "counter noise floor, phase"),
    ("GPS 1PPS", "gps/gps_1pps_phase_data.txt.gz", "phase", "GPS receiver 1 PPS vs H-maser, phase"),
    ("Cs 5071A", "Cs5071A/5071A_phase.txt.gz", "phase", "Cs 5071A 1 PPS vs H-maser, phase"),
]
FUNCTIONS = [*compat.ESTIMATORS, "pdev", "mtie_phase_fast", "gradev", "gcodev"]
#: largest N allantools gets per function (its cost, not ours)
AT_MAX_N = {"mtotdev": 1001, "ttotdev": 1001, "htotdev": 1001, "theo1": 1001, "pdev": 20_000, "mtie": 60_000}
AT_MAX_N["mtie_phase_fast"] = AT_MAX_N["mtie"]
#: largest N allanite gets (the O(N²) estimators)
OURS_MAX_N = {"mtotdev": 20_000, "ttotdev": 20_000, "htotdev": 20_000, "theo1": 250_000}


def _read(path: Path) -> np.ndarray:
    opener = gzip.open if path.suffix == ".gz" else open
    with opener(path, "rt") as f:
        return np.array([float(line) for line in f if line.strip() and not line.startswith("#")])


def _nbs14() -> np.ndarray:
    """SP 1065's generator: n_{i+1} = 16807·n_i mod (2³¹ − 1), n_0 = 1234567890, scaled to [0, 1)."""
    n = [1234567890]
    for _ in range(999):
        n.append((16807 * n[-1]) % 2147483647)
    return np.array(n) / 2147483647.0


def records(root: Path) -> list[tuple[str, str, np.ndarray, str]]:
    out = []
    for name, rel, data_type, note in DATASETS:
        x = _nbs14() if rel is None else _read(root / "tests" / rel)
        if name == "OCXO":
            x = (x - 1e7) / 1e7  # Hz → fractional frequency, as its test does
        out.append((name, data_type, x, note))
    return out


def _call(lib, name: str, x: np.ndarray, data_type: str):
    fn = getattr(lib, "mtie" if (lib is not compat and name == "mtie_phase_fast") else name)
    if name == "gcodev":  # a second record of the same length: the first reversed
        return fn(x, x[::-1].copy(), rate=1.0, data_type=data_type, taus="octave")
    out = fn(x, rate=1.0, data_type=data_type, taus="octave")
    if name == "gradev":  # allantools' errors are NaN (docs/compat.md): compare τ, dev, n
        return out[0], out[1], out[3]
    return out


def run(repeats: int = 3) -> dict:
    import allantools

    root = allantools_sdist.unpacked(allantools_sdist.cache_dir() / "unpacked")
    rows = []
    for ds, data_type, x, _ in records(root):
        for name in FUNCTIONS:
            if x.size > OURS_MAX_N.get(name, x.size):
                continue
            row = {"dataset": ds, "function": name, "n": int(x.size)}
            with _common.OtherLoad() as load:
                t_ours, _, r_ours = _common.timed(lambda: _call(compat, name, x, data_type), repeats)
                if x.size <= AT_MAX_N.get(name, x.size):
                    with contextlib.redirect_stdout(io.StringIO()):
                        t_at, _, r_at = _common.timed(lambda: _call(allantools, name, x, data_type), 1)
                    row["allantools_s"] = t_at
                    row["speedup"] = t_at / t_ours
                    row["max_rel_diff"] = max(
                        _common.max_rel_diff(a, np.asarray(b, float)) for a, b in zip(r_ours, r_at)
                    )
            row.update(allanite_s=t_ours, tau_points=int(len(r_ours[0])), other_processes_cpu_fraction=load.fraction)
            rows.append(row)
            at_s = f"{row['allantools_s']:.3g} s" if "allantools_s" in row else "-"
            _common.log(f"{ds:11s} {name:15s} N={x.size:>7d}: allanite {t_ours:.4f} s, allantools {at_s}")
    return {
        "machine": _common.machine_info(),
        "allantools_version": allantools.__version__,
        "repeats": repeats,
        "rows": rows,
    }


def markdown(rep: dict) -> str:
    m = rep["machine"]
    lines = [
        "# allanite.compat vs allantools on allantools' own test data sets",
        "",
        f"Recorded by `benches/compat_bench.py --datasets` on {m.get('date_utc')}; {m.get('cpu_count')} CPUs, load "
        f"average at start {', '.join(f'{v:.1f}' for v in (m.get('loadavg_start') or []))} (a machine shared with "
        "other jobs: 'other load' is the CPU time other processes used meanwhile, as a share of all CPUs). allantools "
        f"{rep['allantools_version']}; the records of its 2024.6 sdist's tests/ (NBS14: generated). Octave τ grid; "
        f"allanite best of {rep['repeats']}, allantools one run ('-': not run, its pure-Python loop is too slow "
        "at this N; a function missing from a table is O(N²) in allanite too, see benches/_compat_datasets.py). 'max rel. diff' is the largest relative difference over the returned arrays (gradev: τ, dev, "
        "n — allantools' gradev errors are NaN; gcodev: the record against itself reversed; mtie_phase_fast "
        "against allantools' mtie, its own being unfinished).",
        "",
    ]
    for ds, _, _, note in DATASETS:
        sub = [r for r in rep["rows"] if r["dataset"] == ds]
        lines += [
            f"## {ds} — {note}, N = {sub[0]['n']:,}",
            "",
            "| function | τ points | allantools s | allanite s | speed-up | max rel. diff | other load |",
            "|---|---:|---:|---:|---:|---:|---:|",
        ]
        for r in sub:
            at_s = f"{r['allantools_s']:.3g}" if "allantools_s" in r else "-"
            sp = f"{r['speedup']:.3g}×" if "speedup" in r else "-"
            d = f"{r['max_rel_diff']:.1e}" if "max_rel_diff" in r else "-"
            load = 100 * (r["other_processes_cpu_fraction"] or 0)
            lines.append(
                f"| {r['function']} | {r['tau_points']} | {at_s} | {r['allanite_s']:.3g} | {sp} | {d} | {load:.0f} % |"
            )
        lines.append("")
    return "\n".join(lines)
