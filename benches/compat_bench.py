"""allanite.compat against allantools: time per function on the same data and τ grid (octave), and the
largest difference between their results; then allanite alone on a long record.

Run: ``python benches/compat_bench.py`` (a few minutes) → ``benches/results/compat.json`` and
``benches/results/compat.md``; ``--datasets``: every deviation on the records of allantools' own test suite
(benches/_compat_datasets.py) → ``benches/results/compat_datasets.{json,md}``. Sizes: each allantools function at the largest N it finishes in about a
minute or less (its MTOTDEV/TTOTDEV/HTOTDEV/Theo1 are pure-Python O(N²) loops, so they get small N to keep
the run bounded); allanite alone at 10^7 where its own cost allows (MTOTDEV/TTOTDEV/HTOTDEV cost O(N·m) per τ,
Theo1 O(N²): 10^5). Frequency data, white + random-walk FM. Times are wall seconds, best of ``REPEATS``
for allanite and one run for allantools; the CPU time used by other processes is recorded (the machine is
shared). Nothing here asserts anything about speed.
"""

from __future__ import annotations

import contextlib
import io
import json
import sys

import numpy as np

import _common
from allanite import compat

SEED = 18
REPEATS = 3
#: N for the comparison with allantools (its cost, not ours, sets these)
VS_N = {
    "adev": 10**6,
    "oadev": 10**6,
    "mdev": 10**6,
    "tdev": 10**6,
    "hdev": 10**6,
    "ohdev": 10**6,
    "totdev": 10**6,
    "mtie": 5 * 10**4,
    "tierms": 10**6,
    "mtotdev": 2000,
    "ttotdev": 2000,
    "htotdev": 2000,
    "theo1": 10**4,
}
#: N for allanite alone
ALONE_N = {name: (10**5 if name in ("mtotdev", "ttotdev", "htotdev", "theo1") else 10**7) for name in VS_N}


def record(n: int, rng: np.random.Generator) -> np.ndarray:
    return 1e-10 * (rng.standard_normal(n) + 0.01 * np.cumsum(rng.standard_normal(n)))


def main(quick: bool = False) -> dict:
    import allantools

    rng = np.random.default_rng(SEED)
    scale = 100 if quick else 1
    rows = {}
    for name, n in VS_N.items():
        n = max(200, n // scale)
        y = record(n, rng)
        ours = getattr(compat, name)
        theirs = getattr(allantools, name)
        with _common.OtherLoad() as load:
            t_ours, _, r_ours = _common.timed(lambda: ours(y, rate=1.0, data_type="freq", taus="octave"), REPEATS, True)
            with contextlib.redirect_stdout(io.StringIO()):
                t_at, _, r_at = _common.timed(lambda: theirs(y, rate=1.0, data_type="freq", taus="octave"), 1)
        diff = max(_common.max_rel_diff(a, np.asarray(b, dtype=np.float64)) for a, b in zip(r_ours, r_at) if len(b))
        rows[name] = {
            "n": n,
            "tau_points": int(len(r_ours[0])),
            "allanite_s": t_ours,
            "allantools_s": t_at,
            "speedup": t_at / t_ours,
            "max_rel_diff": diff,
            "other_processes_cpu_fraction": load.fraction,
        }
        _common.log(f"{name:8s} N={n:>8d}: allanite {t_ours:.4f} s, allantools {t_at:.3f} s, diff {diff:.1e}")
    alone = {}
    for name, n in ALONE_N.items():
        n = max(200, n // scale)
        y = record(n, rng)
        fn = getattr(compat, name)
        with _common.OtherLoad() as load:
            t, _, r = _common.timed(lambda: fn(y, rate=1.0, data_type="freq", taus="octave"), 1)
        alone[name] = {
            "n": n,
            "tau_points": int(len(r[0])),
            "seconds": t,
            "other_processes_cpu_fraction": load.fraction,
        }
        _common.log(f"{name:8s} alone N={n:>9d}: {t:.3f} s")
    import allantools as at

    return {
        "machine": _common.machine_info(),
        "allantools_version": at.__version__,
        "repeats": REPEATS,
        "vs_allantools": rows,
        "allanite_alone": alone,
    }


def _fmt_n(n: int) -> str:
    e = int(np.log10(n))
    return f"10^{e}" if 10**e == n else f"{n:,}"


def markdown(rep: dict) -> str:
    m = rep["machine"]
    lines = [
        "# allanite.compat vs allantools",
        "",
        f"Recorded by `benches/compat_bench.py` on {m.get('date_utc')}; {m.get('cpu_count')} CPUs, load average at "
        f"start {', '.join(f'{x:.1f}' for x in (m.get('loadavg_start') or []))} (a machine shared with other jobs: "
        "the last column is the CPU time other processes used meanwhile, as a share of all CPUs). allantools "
        f'{rep["allantools_version"]}. Frequency data, octave τ grid, `data_type="freq"`; allanite best of '
        f"{rep['repeats']}, allantools one run. 'max rel. diff' is the largest relative difference over all four "
        "returned arrays.",
        "",
        "| function | N | τ points | allantools s | allanite s | speed-up | max rel. diff | other load |",
        "|---|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for name, r in rep["vs_allantools"].items():
        lines.append(
            f"| {name} | {_fmt_n(r['n'])} | {r['tau_points']} | {r['allantools_s']:.3g} | {r['allanite_s']:.3g} | "
            f"{r['speedup']:.3g}× | {r['max_rel_diff']:.1e} | {100 * (r['other_processes_cpu_fraction'] or 0):.0f} % |"
        )
    lines += [
        "",
        "allanite alone (same functions, octave grid, one run):",
        "",
        "| function | N | τ points | allanite s | other load |",
        "|---|---:|---:|---:|---:|",
    ]
    for name, r in rep["allanite_alone"].items():
        lines.append(
            f"| {name} | {_fmt_n(r['n'])} | {r['tau_points']} | {r['seconds']:.3g} | "
            f"{100 * (r['other_processes_cpu_fraction'] or 0):.0f} % |"
        )
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    if "--datasets" in sys.argv:
        import _compat_datasets

        rep = _compat_datasets.run()
        out = _common.HERE / "results"
        (out / "compat_datasets.json").write_text(json.dumps(rep, indent=1) + "\n", encoding="utf-8")
        (out / "compat_datasets.md").write_text(_compat_datasets.markdown(rep), encoding="utf-8")
        print(_compat_datasets.markdown(rep))
        sys.exit(0)
    quick = "--quick" in sys.argv
    rep = main(quick)
    if not quick:
        out = _common.HERE / "results"
        (out / "compat.json").write_text(json.dumps(rep, indent=1) + "\n", encoding="utf-8")
        (out / "compat.md").write_text(markdown(rep), encoding="utf-8")
    print(markdown(rep))
