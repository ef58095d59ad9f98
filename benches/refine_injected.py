#!/usr/bin/env python3
"""``allanite.refine`` on data with an undeclared effect in it — the injected-effect table of issue 16.

Every record gets one (or two) effects the five-term model lacks — simulated, or injected into real ADIS16405
noise (run and axis named) — and is refined with the **default call** ``refine(y, 100.0)`` (``channels=`` for the
g-sensitivity case). Per record: what was found, each injected effect's parameter errors against the truth, and
that step's χ²/dof, in-sample RMS ADEV error and held-out RMS ADEV error before → after. The same records are
asserted in ``tests/test_refine.py`` and ``tests/test_refine_domains.py``; this script writes the numbers.

Usage::

    python benches/refine_injected.py            # -> benches/results/refine_injected.{json,md}
    python benches/refine_injected.py --quick    # the simulated records only, to a temporary folder
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

import numpy as np
from scipy import signal

import _common
import allanite
from allanite.model.tracing import regression_fit

HERE = Path(__file__).resolve().parent
FS = 100.0


def _adis(run, cols):
    path = _common.shared_data_dir() / "adis16405" / f"adis16405_run{run}_100Hz.csv.gz"
    if not path.is_file():
        return None
    log = allanite.read_log(path, fs=FS, columns=cols, unit="deg/s")
    return np.asarray(log.data, dtype=np.float64).reshape(-1, len(cols)).T


def _within(a, b, blocks=8):
    """Σ a·b over blocks in time, each block de-meaned (the products `regression_fit` is made of)."""
    per = a.size // blocks
    a = a[: per * blocks].reshape(blocks, per)
    b = b[: per * blocks].reshape(blocks, per)
    return float(np.sum((a - a.mean(axis=1, keepdims=True)) * (b - b.mean(axis=1, keepdims=True))))


def _narrowband(n, f_r, q, sigma, seed):
    rho = np.exp(-np.pi * f_r / (q * FS) + 2j * np.pi * f_r / FS)
    rng = np.random.default_rng(seed)
    e = (rng.normal(size=n) + 1j * rng.normal(size=n)) * np.sqrt(1 - abs(rho) ** 2)
    return sigma * signal.lfilter([1], [1, -rho], e).real


def cases(quick: bool):
    """(name, samples or None, truth, kwargs) — simulated first, then real ADIS noise."""
    out = _simulated_cases()
    if quick:
        return out
    y5 = _adis(5, ["gyro_y"])
    g2 = _adis(2, ["gyro_x", "acc_z"])
    y6 = _adis(6, ["gyro_x"])
    y3 = _adis(3, ["gyro_x"])
    if y5 is None or g2 is None or y6 is None or y3 is None:
        print("ADIS16405 logs not found: the real-noise rows are left out (set ALLANITE_SHARED_DATA)")
        return out
    (y5,), (gx, az), (y6,), (y3,) = y5, g2, y6, y3
    t = np.arange(y5.size) / FS
    out += _adis_filter_cases(y5, t) + _adis_channel_cases(gx, az)
    white = np.random.default_rng(3).normal(size=y6.size) * np.where(t >= 6000.0, 2 * np.std(np.diff(y6)), 0.0)
    out += [
        (
            "ADIS run 6 x + white noise ×3 from 6000 s",
            y6 + white,
            {"change_point": {"t": 6000.0}},
            {},
        ),
        (
            "ADIS run 3 x + warm-up 0.2 °/s·e^{−t/600 s}",
            y3 + 0.2 * np.exp(-t / 600.0),
            {"drift": {"amplitude": 0.2, "T": 600.0}},
            {},
        ),
    ]
    return out


def _simulated_cases() -> list:
    """The simulated records: each effect alone on N + K, and a GM with a sinusoid at once."""
    t4 = np.arange(400_000) / FS
    out = [
        (
            "sim GM σ 5e-3, T_c 10 s (N, K), 10⁶",
            allanite.simulate(1_000_000, FS, N=2e-3, K=2e-5, gauss_markov=[(5e-3, 10.0)], seed=11),
            {"gauss_markov": {"sigma": 5e-3, "tc": 10.0}},
            {},
        ),
        (
            "sim sinusoid 3e-3 at 0.05 Hz, 4·10⁵",
            allanite.simulate(400_000, FS, N=2e-3, K=2e-5, sinusoid=[(3e-3, 0.05)], seed=4),
            {"sinusoid": {"amplitude": 3e-3, "f0": 0.05}},
            {},
        ),
        (
            "sim single pole 8 Hz on N + K, 4·10⁵",
            signal.lfilter(
                [1 - np.exp(-2 * np.pi * 8 / FS)],
                [1, -np.exp(-2 * np.pi * 8 / FS)],
                allanite.simulate(400_000, FS, N=2e-3, K=2e-5, seed=3),
            ),
            {"bandwidth": {"cutoff": 8.0}},
            {},
        ),
        (
            "sim resonance σ 1e-2 at 12 Hz, Q 4 (N, K), 4·10⁵",
            allanite.simulate(400_000, FS, N=2e-3, K=2e-5, seed=4) + _narrowband(400_000, 12.0, 4.0, 1e-2, 7),
            {"resonance": {"sigma": 1e-2, "f0": 12.0}},
            {},
        ),
        (
            "sim variance step: N ×3 from 1234.5 s (K), 3·10⁵",
            allanite.simulate(300_000, FS, N=[(0.0, 2e-3), (1234.5, 6e-3)], K=2e-5, seed=5),
            {"change_point": {"t": 1234.5}},
            {},
        ),
        (
            "sim warm-up 0.03·e^{−t/400 s} (N, K), 4·10⁵",
            allanite.simulate(400_000, FS, N=2e-3, K=2e-5, seed=6) + 0.03 * np.exp(-t4 / 400.0),
            {"drift": {"amplitude": 0.03, "T": 400.0}},
            {},
        ),
        (
            "sim GM (5 s) + sinusoid (0.02 Hz) at once, 10⁶",
            allanite.simulate(
                1_000_000, FS, N=2e-3, K=1e-5, gauss_markov=[(5e-3, 5.0)], sinusoid=[(4e-3, 0.02)], seed=21
            ),
            {"gauss_markov": {"sigma": 5e-3, "tc": 5.0}, "sinusoid": {"amplitude": 4e-3, "f0": 0.02}},
            {},
        ),
    ]
    return out


def _adis_filter_cases(y5, t) -> list:
    """ADIS run 5 y with a sinusoid added, and through a moving average and a single pole."""
    return [
        (
            "ADIS run 5 y + 0.03 °/s at 0.02 Hz (issue 16)",
            y5 + 0.03 * np.sin(2 * np.pi * 0.02 * t + 0.3),
            {"sinusoid": {"amplitude": 0.03, "f0": 0.02}},
            {},
        ),
        (
            "ADIS run 5 y through an 8-tap moving average (cascade −3 dB at 5.46 Hz)",
            signal.lfilter(np.ones(8) / 8, [1], y5 - y5.mean()),
            {"bandwidth": {"cutoff": 5.46}},
            {},
        ),
        (
            "ADIS run 5 y through a 5 Hz single pole",
            signal.lfilter([1 - np.exp(-2 * np.pi * 5 / FS)], [1, -np.exp(-2 * np.pi * 5 / FS)], y5 - y5.mean()),
            {"bandwidth": {"cutoff": 5.0}},
            {},
        ),
    ]


def _adis_channel_cases(gx, az) -> list:
    """ADIS run 2 x with a Gauss–Markov process and/or a g-sensitivity to acc_z (`channels=`)."""
    gm = allanite.simulate(gx.size, FS, gauss_markov=[(0.05, 20.0)], seed=8)
    base = regression_fit(gx, az)["coefficient"]
    # a multi-position test: acc_z turned between +1 g and −1 g every 200–600 s (the log's own acc_z noise kept);
    # the gyro responds to the true acceleration at 0.01 °/s/g. The regression's expected coefficient is the
    # least-squares value of that response plus gyro_x's own coupling to acc_z's noise (`base`), within the
    # regression's 8 blocks as `regression_fit` forms it.
    edges = np.cumsum(np.random.default_rng(5).uniform(200, 600, size=400) * FS).astype(int)
    tumble = np.where(np.searchsorted(edges, np.arange(gx.size), side="right") % 2 == 0, 1.0, -1.0)
    tumble -= tumble.mean()
    ch_t = az - az.mean() + tumble
    tumble_truth = _within(0.01 * tumble + base * az, ch_t) / _within(ch_t, ch_t)
    tumble_truth3 = _within(0.03 * tumble + base * az, ch_t) / _within(ch_t, ch_t)
    return [
        (
            "ADIS run 2 x + GM (0.05 °/s, 20 s)",
            gx + gm,
            {"gauss_markov": {"sigma": 0.05, "tc": 20.0}},
            {},
        ),
        (
            "ADIS run 2 x + GM + 2 °/s/g × acc_z (`channels=`)",
            gx + gm + 2.0 * az,
            {"gauss_markov": {"sigma": 0.05, "tc": 20.0}, "regression": {"coefficient": 2.0 + base}},
            {"channels": {"acc_z": az}},
        ),
        (
            "ADIS run 2 x + 0.01 °/s/g × a multi-position acc_z (±1 g every 200–600 s, `channels=`)",
            gx + 0.01 * tumble,
            {"regression": {"coefficient": tumble_truth}},
            {"channels": {"acc_z": az - az.mean() + tumble}},
        ),
        (
            "ADIS run 2 x + GM (0.05 °/s, 20 s) + 0.03 °/s/g × the multi-position acc_z (`channels=`)",
            gx + gm + 0.03 * tumble,
            {"gauss_markov": {"sigma": 0.05, "tc": 20.0}, "regression": {"coefficient": tumble_truth3}},
            {"channels": {"acc_z": az - az.mean() + tumble}},
        ),
    ]


def _pct(v):
    return "n/a" if v is None else f"{v:.3g}"


def run(quick: bool, out: Path) -> dict:
    rows = []
    for name, y, truth, kw in cases(quick):
        t0 = time.perf_counter()
        r = allanite.refine(y, FS, truth=truth, **kw)
        secs = time.perf_counter() - t0
        steps = []
        for st in r.steps:
            if st.effect not in truth:
                continue
            errs = st.truth_error or {}
            before, after = st.before, st.after
            if "window_levels" in st.evidence:  # a change point: what found it, on the windows' levels
                w, ho = st.evidence["window_levels"], st.evidence.get("heldout_test") or {}
                before = w["before"] | {"heldout_rms_adev_pct": ho.get("before")}
                after = w["after"] | {"heldout_rms_adev_pct": ho.get("after")}
            steps.append(
                {
                    "effect": st.effect,
                    "params": {k: v if isinstance(v, str) else float(v) for k, v in st.params.items()},
                    "final_params": {k: v if isinstance(v, str) else float(v) for k, v in st.final_params.items()},
                    "truth_error": {k: float(v) for k, v in errs.items()},
                    "before": {k: before.get(k) for k in ("chi2_dof", "rms_adev_pct", "heldout_rms_adev_pct")},
                    "after": {k: after.get(k) for k in ("chi2_dof", "rms_adev_pct", "heldout_rms_adev_pct")},
                }
            )
        missed = sorted(set(truth) - {s["effect"] for s in steps})
        rows.append({"record": name, "found": r.found, "steps": steps, "missed": missed, "seconds": secs})
        print(name, r.found, "missed" if missed else "", f"{secs:.1f} s", flush=True)
    report = {"rows": rows, "machine": _common.machine_info()}
    out.mkdir(parents=True, exist_ok=True)
    (out / "refine_injected.json").write_text(json.dumps(report, indent=1, default=float))
    lines = [
        "# `refine` on data with an undeclared effect (default call)",
        "",
        "Written by `benches/refine_injected.py`. Each record holds effects the five-term model lacks; "
        "`refine(y, 100.0)` (with `channels=` for the g-sensitivity rows). Per injected effect: its parameter "
        "errors against the truth (change point: distance as a fraction of the record; amplitudes from the final "
        "joint refit, a spectral line's from the samples) and its step's χ²/dof, in-sample RMS ADEV error and "
        "held-out RMS ADEV error (alternate blocks) before → after, on the record's Allan curve (each step's "
        "before is the previous step's after; a removal in time is part of the model through what it changed in "
        "the curve). A change point leaves that curve as it is: its row shows what found it, the Allan variance "
        "of 16 windows against one level vs piecewise levels, held out per segment.",
        "",
        "| record | found | injected effect | parameter errors | χ²/dof | RMS ADEV % | held-out RMS ADEV % |",
        "|---|---|---|---|---|---|---|",
    ]
    for row in rows:
        first = True
        for st in row["steps"]:
            errs = ", ".join(f"{k} {100 * v:+.1f} %" for k, v in st["truth_error"].items()) or "—"
            b, a = st["before"], st["after"]
            lines.append(
                f"| {row['record'] if first else ''} | {', '.join(row['found']) if first else ''} | {st['effect']} "
                f"| {errs} | {_pct(b['chi2_dof'])} → {_pct(a['chi2_dof'])} "
                f"| {_pct(b['rms_adev_pct'])} → {_pct(a['rms_adev_pct'])} "
                f"| {_pct(b['heldout_rms_adev_pct'])} → {_pct(a['heldout_rms_adev_pct'])} |"
            )
            first = False
        for eff in row["missed"]:
            lines.append(
                f"| {row['record'] if first else ''} | {', '.join(row['found']) if first else ''} "
                f"| {eff} | **not found** | | | |"
            )
            first = False
    (out / "refine_injected.md").write_text("\n".join(lines) + "\n")
    return report


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--out", type=Path, default=None)
    a = ap.parse_args(argv)
    out = a.out or (Path(tempfile.mkdtemp()) if a.quick else HERE / "results")
    run(a.quick, out)
    print(f"written to {out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
