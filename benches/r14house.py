#!/usr/bin/env python3
"""House-keeping without result changes (r14house), checked: every field of what the changed code returns, this
checkout against a baseline, bit for bit.

The changes: ``channels.channel_bands`` hands ``t_ref`` to ``regress_channel`` (the channel was read back whole a
second time when a quadratic was kept), ``refine`` takes ``after_curve`` once for the change points and
``unexplained``, ``report.build.build_report`` split by concern, ``_edge``'s DFT grid built in one place, and the
channel benches' per-case summaries shared (``_coverage_summary``). None may move a number, so each record is
dumped whole — every dataclass field, dict and list; floats as their hex (bit-exact), arrays as their shape, dtype
and SHA-256 — in a fresh process with the baseline's ``python/`` (``git archive`` of :data:`BASELINE`, this
checkout's compiled core copied in: ``bench_refine_cost._baseline_python``) and with this checkout's, and the two
dumps compared leaf by leaf. Records (none of them the ADIS16405's rates or lengths):

- default ``refine`` on a 10 Hz gyro beside a 1/16 °C staircase temperature held 1 s with a quadratic coupling; a
  1 Hz warm-up with a plain temperature, a quadratic and a 200 s lag; ``tests/test_line_gain.py``'s 2 Hz line
  whose amplitude follows a temperature; a 0.37 Hz family of five harmonics at 50 Hz; white noise doubling at
  60 % of a 20 Hz record beside a Gauss–Markov term; and the gained line beside a Gauss–Markov term and a step
  that its candidates (sinusoid, regression) cannot model, so that ``unexplained`` speaks;
- ``regress_channel`` with a kept quadratic on a plain, a held (25 samples) and a slow-staircase temperature;
- ``build_report`` with a refinement on the gained line's channel (its ``summary()`` but its creation time);
- the two channel benches' summaries of their recorded rows (``results/channel_lag_bias.json``,
  ``results/channel_interval_coverage_{before,after}.json``).

Beside them, why the channel is still read back whole once (``centring``) next to ``read_channel``'s read of the
usable prefix: the prefix's reconstruction is not the whole's cut short (its last hold, a staircase's last
crossings), counted on 10⁶-sample held and staircase channels — reusing the whole's would move the regressors.

Usage::

    python benches/r14house.py                       # -> benches/results/r14house.md/.json
    python benches/r14house.py --baseline /tmp/x/python --out /tmp/y
"""

from __future__ import annotations

import argparse
import dataclasses
import hashlib
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
#: main before r14house (its house-keeping's parent)
BASELINE = "d858d37"


def dump(o, depth: int = 0):
    """``o`` as JSON, every float as its hex, every array as (shape, dtype, SHA-256 of its bytes)."""
    if depth > 40:
        return "<deep>"
    if isinstance(o, (bool, type(None), str, int)):
        return o
    if isinstance(o, float):
        return float.hex(o)
    if isinstance(o, np.generic):
        return dump(o.item(), depth + 1)
    if isinstance(o, np.ndarray):
        a = np.ascontiguousarray(o)
        return {"shape": list(a.shape), "dtype": str(a.dtype), "sha256": hashlib.sha256(a.tobytes()).hexdigest()}
    if isinstance(o, dict):
        return {str(k): dump(v, depth + 1) for k, v in o.items()}
    if isinstance(o, (list, tuple)):
        return [dump(v, depth + 1) for v in o]
    if dataclasses.is_dataclass(o) and not isinstance(o, type):
        return {"__cls": type(o).__name__} | {
            f.name: dump(getattr(o, f.name), depth + 1) for f in dataclasses.fields(o)
        }
    if hasattr(o, "__dict__"):
        return {"__cls": type(o).__name__} | {k: dump(v, depth + 1) for k, v in vars(o).items() if k[0] != "_"}
    return f"<{type(o).__name__}>" if callable(o) else repr(o)


def _staircase_quad(seed: int = 1):
    import allanite

    rng = np.random.default_rng(seed)
    n, fs = 200_000, 10.0
    t = np.arange(n) / fs
    temp = 25 - 15 * np.cos(2 * np.pi * t / t[-1])
    logged = np.repeat(np.round((temp[::10] + 0.01 * rng.standard_normal(n // 10)) * 16) / 16, 10)[:n]
    y = allanite.simulate(n, fs, N=2e-3, B=2e-4, K=2e-6, seed=seed) + 2e-4 * (temp - 25) + 3e-5 * (temp - 22) ** 2
    return y, fs, {"channels": {"temp": logged}}


def _plain_quad_lag(seed: int = 2):
    import allanite

    rng = np.random.default_rng(seed)
    n, fs = 90_000, 1.0
    t = np.arange(n) / fs
    temp = 5 + 20 / (1 + np.exp(-(t - 30_000) / 4_000)) + 3 * np.sin(2 * np.pi * t / 20_000)
    lagged = np.interp(t - 200.0, t, temp)
    y = allanite.simulate(n, fs, N=1.5e-3, B=1e-4, K=3e-6, seed=seed) + 4e-4 * lagged + 2e-5 * (lagged - 15) ** 2
    return y, fs, {"channels": {"temp": temp + 0.02 * rng.standard_normal(n)}}


def _line_gain(seed: int = 3):
    rng = np.random.default_rng(seed)
    n, fs = 30_000, 50.0
    t = np.arange(n) / fs
    temp = 25.0 + 10.0 * np.sin(2 * np.pi * 1.5 * t / t[-1])
    line = 0.02 * (1.0 + 0.02 * (temp - temp.mean())) * np.sin(2 * np.pi * 2.0 * t + 0.7)
    return line + 0.01 * rng.standard_normal(n), fs, {"channels": {"temp": temp + 0.01 * rng.standard_normal(n)}}


def _line_gain_unexplained(seed: int = 3):
    import allanite

    y, fs, kw = _line_gain(seed)
    t = np.arange(y.size) / fs
    y = y + allanite.simulate(y.size, fs, gauss_markov=[(0.02, 2.0)], seed=9) + 0.05 * (t > 300)
    return y, fs, kw | {"candidates": ("sinusoid", "regression")}


def _family(seed: int = 4):
    import allanite

    n, fs = 150_000, 50.0
    t = np.arange(n) / fs
    y = allanite.simulate(n, fs, N=3e-3, B=3e-4, seed=seed)
    for h, a in zip(range(1, 6), (4e-3, 2.5e-3, 1.5e-3, 1e-3, 7e-4)):
        y = y + a * np.sin(2 * np.pi * 0.37 * h * t + 0.3 * h)
    return y, fs, {}


def _change_point(seed: int = 5):
    import allanite

    n, fs = 120_000, 20.0
    y = allanite.simulate(n, fs, N=2e-3, K=1e-5, gauss_markov=[(2e-3, 30.0)], seed=seed)
    w = allanite.simulate(n, fs, N=4e-3, seed=seed + 100)
    y[int(0.6 * n) :] += w[int(0.6 * n) :]
    return y, fs, {}


RECORDS = {
    "staircase temperature, quadratic (10 Hz × 2·10⁵)": _staircase_quad,
    "plain temperature, quadratic, 200 s lag (1 Hz × 9·10⁴)": _plain_quad_lag,
    "a 2 Hz line with a gain on temp (50 Hz × 3·10⁴)": _line_gain,
    "the gained line, a GM and a step left unexplained": _line_gain_unexplained,
    "a 0.37 Hz family of 5 harmonics (50 Hz × 1.5·10⁵)": _family,
    "white noise doubling at 60 %, a GM (20 Hz × 1.2·10⁵)": _change_point,
}


def _regressions() -> dict:
    """``regress_channel`` on three forms of one temperature, each with a quadratic coupling."""
    import allanite
    from allanite.model.channels import regress_channel

    rng = np.random.default_rng(7)
    n, fs = 60_000, 5.0
    t = np.arange(n) / fs
    temp = 20 + 12 * np.sin(2 * np.pi * t / t[-1] * 0.8)
    y = allanite.simulate(n, fs, N=1e-3, B=1e-4, seed=7) + 3e-4 * (temp - 20) + 4e-5 * (temp - 18) ** 2
    forms = {
        "plain": temp + 0.02 * rng.standard_normal(n),
        "held 25 samples": np.repeat(temp[::25] + 0.02 * rng.standard_normal(n // 25), 25)[:n],
        "slow staircase, 1/8": np.repeat(np.round(temp[::5] * 8) / 8, 5)[:n],
    }
    return {name: dump(regress_channel(y, ch, fs, name="temp")) for name, ch in forms.items()}


def _report() -> dict:
    from allanite.report import build_report

    y, fs, kw = _line_gain()
    rep = build_report(
        y[:, None], fs, unit="deg/s", window=3000, hop=600, refine=True, channels=kw["channels"], progress=False
    )
    s = rep.summary()
    s.pop("created", None)
    return dump(s)


def _bench_summaries() -> dict:
    """The two channel benches' summaries of their recorded rows, by the benches of ``R14HOUSE_BENCHES`` (the
    side's own ``benches/``; the rows are this checkout's)."""
    sys.path.insert(0, os.environ.get("R14HOUSE_BENCHES", str(HERE)))
    import channel_interval_coverage as cic
    import channel_lag_bias as clb

    res = HERE / "results"
    out = {"channel_lag_bias": dump(clb.summary(json.loads((res / "channel_lag_bias.json").read_text())["rows"]))}
    for tag in ("before", "after"):
        rows = json.loads((res / f"channel_interval_coverage_{tag}.json").read_text())["rows"]
        out[f"channel_interval_coverage_{tag}"] = dump(cic.summary(rows))
    return out


def worker(out: Path) -> None:
    """Every record dumped, in this process's allanite and benches (``PYTHONPATH``, ``cwd``)."""
    import allanite

    got, cpu = {}, {}
    for name, make in RECORDS.items():
        y, fs, kw = make()
        c0 = time.process_time()
        r = allanite.refine(y, fs, progress=False, **kw)
        cpu[name] = time.process_time() - c0
        got[name] = dump(r) | {"params_text": [r.params_text(s) for s in r.steps]}
        got[name]["effects_found"] = [s.effect for s in r.steps]
    got["regress_channel"] = _regressions()
    got["build_report summary"] = _report()
    got["bench summaries"] = _bench_summaries()
    out.write_text(json.dumps({"results": got, "cpu_s": cpu}, sort_keys=True))


def _differences(a, b, path: str = "") -> list[str]:
    if isinstance(a, dict) and isinstance(b, dict):
        keys = [f"{path}: keys {sorted(set(a) ^ set(b))}"] if set(a) != set(b) else []
        return keys + [d for k in sorted(set(a) & set(b)) for d in _differences(a[k], b[k], f"{path}/{k}")]
    if isinstance(a, list) and isinstance(b, list):
        size = [f"{path}: {len(a)} → {len(b)} entries"] if len(a) != len(b) else []
        return size + [d for i, (u, v) in enumerate(zip(a, b)) for d in _differences(u, v, f"{path}[{i}]")]
    return [] if a == b else [f"{path}: {str(a)[:60]} → {str(b)[:60]}"]


def _leaves(o) -> int:
    if isinstance(o, dict):
        return sum(_leaves(v) for v in o.values())
    if isinstance(o, list):
        return sum(_leaves(v) for v in o)
    return 1


def prefix_reads() -> list:
    """Samples of the usable prefix where its own reconstruction differs from the whole channel's cut short, on
    10⁶-sample temperatures at 100 Hz held 1 s and quantised to a slow staircase."""
    from allanite.model import _whittle as wh
    from allanite.model._staircase import channel_form, reconstructed

    rng = np.random.default_rng(3)
    n = 1_000_000
    t = np.arange(n) / 100.0
    temp = 20 + 12 * np.sin(2 * np.pi * t / t[-1] * 0.8)
    chans = {
        "held 1 s": np.repeat(temp[::100] + 0.02 * rng.standard_normal(n // 100), 100)[:n],
        "staircase 1/16 °C, held 1 s": np.repeat(np.round(temp[::100] * 16) / 16, 100)[:n],
    }
    out = []
    for name, x in chans.items():
        nu = wh.usable_length(n)
        form = channel_form(x[:nu])
        differ = np.flatnonzero(reconstructed(x[:nu], form) != reconstructed(x, form)[:nu])
        out.append({"channel": name, "usable": nu, "differ": int(differ.size), "first": int(differ[0])})
    return out


def _baseline_benches(ref: str) -> Path:
    """``benches/`` of ``ref`` (with the ``tests/`` its suites import), exported beside its ``python/``
    (``bench_refine_cost._baseline_python``)."""
    root = Path(tempfile.gettempdir()) / f"allanite-baseline-{ref}"
    if not (root / "tests").exists():
        root.mkdir(parents=True, exist_ok=True)
        cmd = ["git", "-C", str(REPO), "archive", ref, "benches", "tests"]
        archive = subprocess.run(cmd, check=True, capture_output=True)
        subprocess.run(["tar", "-x", "-C", str(root)], input=archive.stdout, check=True)
    return root / "benches"


def _run(python_dir: Path, benches: Path, tmp: Path, tag: str) -> dict:
    out = tmp / f"{tag}.json"
    env = os.environ | {"PYTHONPATH": str(python_dir), "R14HOUSE_BENCHES": str(benches)}
    subprocess.run([sys.executable, __file__, "--worker", str(out)], check=True, env=env, cwd=HERE)
    return json.loads(out.read_text())


def _page(rows: list, reads: list, base: str, load: tuple) -> str:
    import _common

    m = _common.machine_info()
    lines = [
        "# r14house: house-keeping without result changes",
        "",
        f"Written by `benches/r14house.py` (its docstring: the records and why): allanite at {m['git_commit']} against "
        f"the baseline {base}, {m['date_utc'][:16]} UTC, {m['cpus_usable']} CPUs, 1-minute load {load[0]:.1f} at "
        f"the start and {load[1]:.1f} at the end (shared with other work). Each side in a fresh process; every "
        "field dumped (floats as hex, arrays as SHA-256) and compared leaf by leaf.",
        "",
        "| what | effects found | leaves compared | leaves that differ |",
        "|---|---|---|---|",
    ]
    for r in rows:
        lines.append(f"| {r['what']} | {r['effects'] or '—'} | {r['leaves']} | {r['differ']} |")
    lines += [
        "",
        "The channel is still read back whole once (`channels.centring`) beside `read_channel`'s read of the usable "
        "prefix (`_whittle.usable_length`): the prefix's own reconstruction is not the whole's cut short, so the "
        "whole's cannot stand in for it without moving the regressors:",
        "",
        "| 10⁶ samples at 100 Hz | usable prefix | samples that differ | first at |",
        "|---|---|---|---|",
    ]
    lines += [f"| {r['channel']} | {r['usable']:,} | {r['differ']} | {r['first']:,} |" for r in reads]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--baseline", type=Path, help="python/ folder of the baseline checkout (with its core)")
    ap.add_argument("--out", type=Path, default=HERE / "results")
    ap.add_argument("--worker", type=Path, help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.worker:
        worker(a.worker)
        return 0
    import bench_refine_cost

    base = a.baseline or bench_refine_cost._baseline_python(BASELINE)
    base_benches = base.parent / "benches" if a.baseline else _baseline_benches(BASELINE)
    load0 = os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as tmp:
        before = _run(base, base_benches, Path(tmp), "before")
        after = _run(REPO / "python", HERE, Path(tmp), "after")
    rows = []
    for what, b in before["results"].items():
        diff = _differences(b, after["results"].get(what))
        effects = ", ".join(b.get("effects_found", [])) if isinstance(b, dict) else ""
        rows.append({"what": what, "effects": effects, "leaves": _leaves(b), "differ": len(diff), "first": diff[:5]})
        print(f"{what}: {rows[-1]['leaves']} leaves, {len(diff)} differ", flush=True)
    reads = prefix_reads()
    a.out.mkdir(parents=True, exist_ok=True)
    page = _page(rows, reads, a.baseline and str(a.baseline) or BASELINE, (load0, os.getloadavg()[0]))
    (a.out / "r14house.md").write_text(page)
    cpu = {"before": before["cpu_s"], "after": after["cpu_s"]}
    (a.out / "r14house.json").write_text(json.dumps({"rows": rows, "prefix_reads": reads, "cpu_s": cpu}, indent=1))
    print(page)
    return 0 if all(r["differ"] == 0 for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
