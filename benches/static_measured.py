"""The static overlapping Allan variance on every measured ADIS16405 channel against an extended-precision
recomputation: the check that the single-word terms (used where a bound certifies them, see
``rust/core/src/oavar.rs``) keep every value exact on real sensor data, not only on simulations.

    python benches/static_measured.py            # all six runs × six channels → benches/results/static_measured.md

Needs the shared data (``ALLANITE_SHARED_DATA``, default ``../shared/data``); exits with a message
without them. Each channel: 10⁶ samples at 100 Hz, m = unique(round(1.2^k)) ≤ N/10. Times are best of 3
after a warm-up, allanite on its default workers; the reference is ``bench_engine.longdouble_oavar``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

import _common
import allanite
from bench_engine import longdouble_oavar

AXES = ("gyro_x", "gyro_y", "gyro_z", "acc_x", "acc_y", "acc_z")
FS = 100.0


def run(out: Path) -> list[dict]:
    data = _common.shared_data_dir() / "adis16405"
    if not data.is_dir():
        raise SystemExit(f"{data}: the shared ADIS16405 logs are not there (set ALLANITE_SHARED_DATA)")
    rows = []
    for k in range(1, 7):
        log = allanite.read_log(data / f"adis16405_run{k}_100Hz.csv.gz", fs=FS, columns=AXES)
        for a, ax in enumerate(AXES):
            x = np.ascontiguousarray(log.data[:, a], dtype=np.float64)
            ms = np.unique(np.round(1.2 ** np.arange(200)).astype(np.int64))
            ms = ms[ms <= x.size // 10]
            taus = ms / FS
            best, _reps, res = _common.timed(
                lambda x=x, taus=taus: allanite.avar(x, FS, taus=taus, estimator="oavar"), 3, warmup=True
            )
            ref = longdouble_oavar(x, ms).astype(np.float64)
            rel = float(np.max(np.abs(np.asarray(res.avar) - ref) / ref))
            rows.append(
                {"run": k, "channel": ax, "n": int(x.size), "taus": int(ms.size), "seconds": best, "max_rel": rel}
            )
            _common.log(f"run {k} {ax}: {best * 1e3:.1f} ms, max rel. diff {rel:.2e}")
    lines = [
        "# Static OAVAR on the measured ADIS16405 logs — `benches/static_measured.py`",
        "",
        f"{time.strftime('%Y-%m-%dT%H:%M:%S%z')} · allanite {allanite.__version__}",
        "",
        "Every channel of the six runs (10⁶ samples at 100 Hz each), m = unique(round(1.2^k)) ≤ N/10; allanite "
        "`avar(estimator='oavar')` on its default workers, best of 3 after a warm-up; max rel. diff against an "
        "extended-precision (np.longdouble) recomputation over every τ.",
        "",
        "| run | channel | τ | ms | max rel. diff |",
        "|---|---|---|---|---|",
    ]
    lines += [
        f"| {r['run']} | {r['channel']} | {r['taus']} | {r['seconds'] * 1e3:.1f} | {r['max_rel']:.1e} |" for r in rows
    ]
    worst = max(r["max_rel"] for r in rows)
    lines += ["", f"Largest difference over all {len(rows)} channels: {worst:.1e} (the promise: ≤ 1e-9)."]
    out.mkdir(parents=True, exist_ok=True)
    (out / "static_measured.md").write_text("\n".join(lines) + "\n", encoding="utf-8")
    _common.log(f"wrote {out / 'static_measured.md'}")
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument(
        "--out", type=Path, default=_common.HERE / "results", help="output folder (default benches/results)"
    )
    args = ap.parse_args(argv)
    run(args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
