"""The per-case summary of the channel benches' seeded replicas (``channel_lag_bias.py``,
``channel_interval_coverage.py``): each case's records and acceptances, and per parameter the error's spread,
the 68 % interval's median half-width and its coverage with a Clopper–Pearson interval (the 95 % interval's
too where the rows carry it). Imported as ``import _coverage_summary`` by the scripts beside it (``benches/``
is a folder of scripts: Python puts it first on ``sys.path``)."""

from __future__ import annotations

import math

import numpy as np
from scipy.stats import beta


def cp(k: int, n: int) -> tuple[float, float]:
    """The 95 % Clopper–Pearson interval of k successes in n."""
    lo = 0.0 if k == 0 else float(beta.ppf(0.025, k, n - k + 1))
    hi = 1.0 if k == n else float(beta.ppf(0.975, k + 1, n - k))
    return lo, hi


def median_ci(x: np.ndarray) -> tuple[float, float, float]:
    """Median and its 95 % order-statistic interval (binomial ranks)."""
    x = np.sort(x)
    n = x.size
    k = int(max(0, math.floor(n / 2 - 0.98 * math.sqrt(n))))
    return float(np.median(x)), float(x[k]), float(x[min(n - 1, n - 1 - k)])


def parameter(have: list, centre: bool = False) -> dict:
    """One parameter's rows (each ``{"error", "covered", "width"}``, ``"covered95"`` optional) summarised: ``n``,
    where ``centre`` the error's median (with its 95 % interval) and mean, its s.d., the 68 % coverage
    (covered, n, CP low, CP high), the median half-width, and the 95 % coverage where the rows have it."""
    err = np.array([h["error"] for h in have])
    c68 = sum(h["covered"] for h in have)
    out: dict = {"n": len(have)}
    if centre:
        out |= {"median_error": median_ci(err), "mean_error": float(err.mean())}
    out |= {
        "sd_error": float(err.std(ddof=1)) if err.size > 1 else float("nan"),
        "coverage": (c68, len(have), *cp(c68, len(have))),
        "median_half_width": float(np.median([h["width"] for h in have])),
    }
    if "covered95" in have[0]:
        c95 = sum(h["covered95"] for h in have)
        out["coverage95"] = (c95, len(have), *cp(c95, len(have)))
    return out


def summary(rows: list, params, kept: tuple = (), centre: bool = False) -> dict:
    """Per case (in the rows' order): ``records``, ``accepted``, how many kept each term of ``kept`` (where
    given), each parameter of ``params(case)`` that some row has (:func:`parameter`), the median CPU seconds."""
    out: dict = {}
    for case in dict.fromkeys(r["case"] for r in rows):
        rs = [r for r in rows if r["case"] == case]
        s: dict = {"records": len(rs), "accepted": sum(r["accepted"] for r in rs)}
        if kept:
            s["kept"] = {k: sum(k in r["kept"] for r in rs) for k in kept}
        for k in params(case):
            have = [r[k] for r in rs if k in r]
            if have:
                s[k] = parameter(have, centre)
        s["cpu_s"] = float(np.median([r["cpu_s"] for r in rs]))
        out[case] = s
    return out
