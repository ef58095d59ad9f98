#!/usr/bin/env python3
"""Two ``refine.json`` (``benches/refine_measured.py``) or ``refine_sensors.json`` files compared field by field.

For a speed-up that changes numbers in their last digits (a compiled NNLS, a quantile table): the effects and steps
must be the same, every other string, int and bool equal; per numeric field the largest relative difference is
reported, the parameters' and intervals' (``params``, ``intervals``, ``final_params``, ``final_intervals``)
apart from the χ²/dof's (every ``chi2_dof``) and the rest's. Timings and loads are skipped.

Usage::

    python benches/compare_refine.py benches/results/refine.json /tmp/new/refine.json
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

SKIP = {"seconds", "load_1min", "load", "cpu", "wall"}
PARAMS = {"params", "intervals", "final_params", "final_intervals"}


def compare(a, b, path="", out=None) -> dict:
    """{"mismatch": [paths], "params"/"chi2"/"other": (largest relative difference, path)}."""
    out = out if out is not None else {"mismatch": [], "params": (0.0, ""), "chi2": (0.0, ""), "other": (0.0, "")}
    if isinstance(a, dict) and isinstance(b, dict):
        if set(a) != set(b):
            out["mismatch"].append(f"{path}: keys {sorted(set(a) ^ set(b))}")
        for k in sorted(set(a) & set(b)):
            if k not in SKIP:
                compare(a[k], b[k], f"{path}/{k}", out)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            out["mismatch"].append(f"{path}: {len(a)} → {len(b)} entries")
        for i, (u, v) in enumerate(zip(a, b)):
            compare(u, v, f"{path}[{i}]", out)
    elif isinstance(a, float) and isinstance(b, float) and not (isinstance(a, bool) or isinstance(b, bool)):
        if a == b or (math.isnan(a) and math.isnan(b)):
            return out
        rel = abs(a - b) / max(abs(a), abs(b), 1e-300) if math.isfinite(a) and math.isfinite(b) else math.inf
        parts = set(path.split("/"))
        kind = "params" if parts & PARAMS else "chi2" if path.endswith("chi2_dof") else "other"
        if rel > out[kind][0]:
            out[kind] = (rel, path)
    elif a != b and not (isinstance(a, (int, float)) and isinstance(b, (int, float)) and float(a) == float(b)):
        out["mismatch"].append(f"{path}: {a!r} → {b!r}")
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("before", type=Path)
    ap.add_argument("after", type=Path)
    a = ap.parse_args(argv)
    got = compare(json.loads(a.before.read_text()), json.loads(a.after.read_text()))
    for kind in ("params", "chi2", "other"):
        rel, where = got[kind]
        print(f"largest relative difference, {kind}: {rel:.3g}" + (f" ({where})" if where else ""))
    print(f"{len(got['mismatch'])} fields not equal" + "".join(f"\n  {m}" for m in got["mismatch"][:40]))
    return 1 if got["mismatch"] else 0


if __name__ == "__main__":
    raise SystemExit(main())
