"""allantools 2024.6's own test suite, complete, under allantools itself and under allanite.compat:
outcome counts per test file, wall and CPU time of each run. Includes the slow cases CI leaves out
(``DESELECTED`` in benches/_allantools_sdist.py).

Run: ``python benches/compat_suite.py`` (≈ 10 min) → ``benches/results/compat_suite.{json,md}``. The
sdist comes from PyPI (tests/allantools_sdist.py, sha256 pinned, cached in ~/.cache/allanite); both runs
use benches/_allantools_suite_plugin.py (np.random seeded per test; under compat the real allantools is
blocked). Nothing asserts anything about speed.
"""

from __future__ import annotations

import json
import os
import resource
import tempfile
from pathlib import Path

import _allantools_sdist as allantools_sdist
import _common

TARGETS = ("allantools", "compat")


def _children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run() -> dict:
    root = allantools_sdist.unpacked(allantools_sdist.cache_dir() / "unpacked")
    out: dict = {"machine": _common.machine_info(), "sha256": allantools_sdist.SHA256, "runs": {}}
    with tempfile.TemporaryDirectory() as tmp:
        for target in TARGETS:
            cpu0, load0 = _children_cpu(), os.getloadavg()[0]
            rep = allantools_sdist.run_suite(root, target, Path(tmp) / f"{target}.json")
            slowest = sorted(rep["outcomes"].items(), key=lambda kv: -kv[1]["duration"])[:10]
            out["runs"][target] = {
                "seconds": rep["seconds"],
                "cpu_seconds": _children_cpu() - cpu0,
                # the suite runs in a child process, so the load average (1 min) brackets the run instead of
                # _common.OtherLoad, which would count the child as "other"
                "loadavg_1min_start_end": [load0, os.getloadavg()[0]],
                "per_file": allantools_sdist.per_file(rep),
                "not_passed": {k: v for k, v in rep["outcomes"].items() if v["outcome"] in ("failed", "error")},
                "slowest": [(k, v["duration"]) for k, v in slowest],
                "deselected_in_ci": {n: rep["outcomes"][n] for n in allantools_sdist.DESELECTED},
                "real_allantools_loaded": rep["real_allantools_loaded"],
            }
            _common.log(f"{target}: {rep['seconds']:.0f} s wall, {out['runs'][target]['cpu_seconds']:.0f} s CPU")
    return out


def _cell(counts: dict) -> str:
    order = ("passed", "failed", "error", "skipped", "xfailed", "xpassed")
    return ", ".join(f"{counts[k]} {k}" for k in order if counts.get(k))


def markdown(rep: dict) -> str:
    m, runs = rep["machine"], rep["runs"]
    files = sorted(set(runs["allantools"]["per_file"]) | set(runs["compat"]["per_file"]))
    lines = [
        "# allantools 2024.6's test suite: allantools vs allanite.compat",
        "",
        f"Recorded by `benches/compat_suite.py` on {m.get('date_utc')}; {m.get('cpu_count')} CPUs, load average at "
        f"start {', '.join(f'{v:.1f}' for v in (m.get('loadavg_start') or []))}. sdist sha256 `{rep['sha256']}`. "
        "The complete suite (CI leaves out the slow cases listed in docs/compat.md), np.random seeded per test.",
        "",
        "| run | wall s | CPU s (the pytest process) | load average (1 min) at start, end |",
        "|---|---:|---:|---:|",
    ]
    for t in TARGETS:
        r = runs[t]
        lines.append(
            f"| {t} | {r['seconds']:.0f} | {r['cpu_seconds']:.0f} | "
            f"{r['loadavg_1min_start_end'][0]:.1f}, {r['loadavg_1min_start_end'][1]:.1f} |"
        )
    lines += ["", "| test file | allantools 2024.6 | allanite.compat |", "|---|---|---|"]
    for f in files:
        lines.append(
            f"| {f} | {_cell(runs['allantools']['per_file'].get(f, {}))} | {_cell(runs['compat']['per_file'].get(f, {}))} |"
        )
    lines += ["", "Slow cases left out of CI (outcomes and seconds, per run; parametrized cases together):", ""]
    groups: dict[str, list[str]] = {}
    for n in allantools_sdist.DESELECTED:
        groups.setdefault(n.split("[")[0], []).append(n)
    for base, nodes in groups.items():
        cells = []
        for t in TARGETS:
            recs = [runs[t]["deselected_in_ci"][n] for n in nodes]
            counts: dict[str, int] = {}
            for r in recs:
                counts[r["outcome"]] = counts.get(r["outcome"], 0) + 1
            cells.append(f"{t} {_cell(counts)} {sum(r['duration'] for r in recs):.1f} s")
        what = f"`{base}` ({len(nodes)} cases)" if len(nodes) > 1 else f"`{base}`"
        lines.append(f"- {what}: {', '.join(cells)}")
    for t in TARGETS:
        bad = runs[t]["not_passed"]
        lines += ["", f"Not passed under {t}: {', '.join(f'`{k}`' for k in bad) if bad else 'none'}."]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    rep = run()
    out = _common.HERE / "results"
    (out / "compat_suite.json").write_text(json.dumps(rep, indent=1) + "\n", encoding="utf-8")
    (out / "compat_suite.md").write_text(markdown(rep), encoding="utf-8")
    print(markdown(rep))
