#!/usr/bin/env python3
"""Paper 004's Tables 1 and 3, as a function: forecast per-frame noise coefficients, GM(1,1) vs the rest.

Paper 004 (Li, Wang, Shen, Acta Optica Sinica 2020) fits the five Allan terms in each of 90 consecutive
frames, builds a forecast on the first 60 and checks it on the last 30. Its Table 1 (traditional GM(1,1))
gives C ≈ 0.49–0.59, its Table 3 (improved GM(1,1)) C ≈ 0.14–0.28.

:func:`forecast_table` takes ``{term: per-frame values}`` and returns, for every method, the C and P of its
30-frame forecast against the **raw** check values ("honest"), the same by paper 004's rule ("paper
rule": a-posteriori values over build + check, x⁰(1) left out, the build part judged against the series
the model fitted — the smoothed one for the improved model) and, for the improved model only, against
check values smoothed together with the build part ("vs smoothed", which is what smoothing the whole
record before splitting gives; not a fair score). RMSE and bias are given too: C ignores a constant
offset (any constant forecast has C = 1 exactly).

Methods: traditional GM(1,1); improved GM(1,1) with all steps, and with each step alone (so each step's
effect is visible); persistence; build mean; linear trend; Holt.

A term whose series has values ≤ 0 (the fit did not resolve it) is reported as not forecastable.

The demo (``python benches/paper004_forecast.py``) runs it on synthetic coefficient series that really
drift (see :func:`synthetic_coefficients`): ARW rising 30 % along a warm-up curve (scenario ``warmup``:
mostly in the build part; ``steady``: almost linear, still rising in the check part), bias instability
stepping once by 20 %, the other terms constant, each with multiplicative (log-normal) frame-to-frame
estimation noise of a size typical of a per-frame Allan fit (Q 5 %, N 3 % / 1 %, B 10 %, K 25 %,
R 40 %). A "true curve (oracle)" row forecasts with the noise-free truth: the best C this check part
allows. ``--seeds S`` repeats it over S seeds and reports the mean and spread of C (a C from 30 values is
itself noisy) and the median RMSE relative to persistence. ``--out FILE`` also writes the markdown.

Usage::

    python benches/paper004_forecast.py                 # one seed, tables on stdout
    python benches/paper004_forecast.py --seeds 50      # + mean ± SD of C over 50 seeds (≈ 30 s);
                                                        #   recorded in benches/results/paper004_synthetic.md
"""

from __future__ import annotations

import argparse
import functools
import math
import sys
from collections.abc import Mapping
from typing import Any, Callable

import numpy as np

from allanite.errors import AllaniteError
from allanite.forecast import (
    GM11,
    BuildMean,
    Holt,
    ImprovedGM11,
    LinearTrend,
    Persistence,
    accuracy,
    score,
    split,
)

ALL_OFF = {"detect": False, "smooth": False, "metabolic": False, "residual": False}


def default_methods() -> dict[str, Callable[..., Any]]:
    """Name → model factory, in table order."""
    return {
        "GM(1,1)": GM11,
        "improved GM(1,1)": ImprovedGM11,
        "  detect only": functools.partial(ImprovedGM11, **{**ALL_OFF, "detect": True}),
        "  smooth only": functools.partial(ImprovedGM11, **{**ALL_OFF, "smooth": True}),
        "  metabolic only": functools.partial(ImprovedGM11, **{**ALL_OFF, "metabolic": True}),
        "  residual only": functools.partial(ImprovedGM11, **{**ALL_OFF, "residual": True}),
        "persistence": Persistence,
        "build mean": BuildMean,
        "linear trend": LinearTrend,
        "Holt": Holt,
    }


def forecast_table(
    coefficients: Mapping[str, Any],
    *,
    build: int = 60,
    check: int = 30,
    methods: Mapping[str, Callable[..., Any]] | None = None,
    sd: str = "population",
    truth: Mapping[str, Any] | None = None,
) -> dict[str, Any]:
    """C/P of every method's forecast of every coefficient series.

    Parameters
    ----------
    coefficients : mapping
        Term name → per-frame values (at least ``build + check``; 90 in paper 004).
    build, check : int
        The split (paper 004: 60 / 30).
    methods : mapping, optional
        Name → model factory; default :func:`default_methods`.
    sd : {"population", "sample"}
    truth : mapping, optional
        Term → the noise-free per-frame values (simulations only). Adds a row "true curve (oracle)" whose
        forecast is the truth itself: the best C any method could reach on this check part.

    Returns
    -------
    dict
        ``{"terms": [...], "methods": [...], "cells": {method: {term: cell}}, "skipped": {term: reason}}``;
        a cell holds ``C``, ``P``, ``c_grade``, ``grade`` (honest), ``C_paper``, ``P_paper``,
        ``c_grade_paper``, ``rmse``, ``bias``, ``C_smoothed`` (improved model only, else None),
        ``C_insample`` (the build-part fit against the series the model fitted: the smoothed one for the
        improved model — no forecast involved) and ``notes``.
    """
    methods = dict(methods or default_methods())
    if truth is not None:
        methods["true curve (oracle)"] = None  # filled per term below
    out: dict[str, Any] = {"terms": [], "methods": list(methods), "cells": {m: {} for m in methods}, "skipped": {}}
    for term, values in coefficients.items():
        x = np.asarray(values, dtype=np.float64)
        b, c = split(x, build, check)
        nonpos = np.flatnonzero(x[: build + check] <= 0)
        if nonpos.size:
            out["skipped"][term] = f"{nonpos.size} frame(s) at or below 0 (term not resolved): not forecastable"
            continue
        out["terms"].append(term)
        smoothed_check = None
        for name, factory in methods.items():
            if factory is None:
                factory = functools.partial(_Oracle, truth=np.asarray(truth[term], dtype=np.float64))
            try:
                s = score(factory, b, c, sd=sd, name=name)
            except AllaniteError as exc:
                out["cells"][name][term] = {"error": str(exc)}
                continue
            cell = {
                "C": s.honest.C,
                "P": s.honest.P,
                "c_grade": s.honest.c_grade,
                "grade": s.honest.grade,
                "C_paper": s.paper_rule.C,
                "P_paper": s.paper_rule.P,
                "c_grade_paper": s.paper_rule.c_grade,
                "rmse": s.rmse,
                "bias": s.bias,
                "C_smoothed": None,
                "C_insample": (
                    s.model.accuracy_processed.C if isinstance(s.model, ImprovedGM11) else s.model.accuracy.C
                ),
                "notes": list(getattr(s.model, "notes", [])),
            }
            if isinstance(s.model, ImprovedGM11) and s.model.steps["smooth"]:
                if smoothed_check is None:
                    whole = ImprovedGM11(x[: build + check], **{**ALL_OFF, "detect": True, "smooth": True})
                    smoothed_check = whole.processed[build:]
                cell["C_smoothed"] = accuracy(smoothed_check, s.forecast, sd=sd).C
            out["cells"][name][term] = cell
    return out


class _Oracle:
    """'Forecast' = the true noise-free curve (simulation only): the floor of C on a check part."""

    name = "true curve (oracle)"

    def __init__(self, series: Any, *, truth: np.ndarray) -> None:
        self.n = len(series)
        self.fitted = truth[: self.n]
        self.truth = truth
        self.accuracy = accuracy(series, self.fitted)

    def predict(self, h: int) -> np.ndarray:
        return self.truth[self.n : self.n + h]


def _fmt(v: float | None, nd: int = 2) -> str:
    if v is None:
        return "—"
    if not math.isfinite(v):
        return "inf"
    return f"{v:.{nd}f}"


def to_markdown(table: Mapping[str, Any], *, title: str = "") -> str:
    """Three tables: honest C (grade) and P; paper-rule C (grade); RMSE/bias; plus C vs smoothed check."""
    terms, methods, cells = table["terms"], table["methods"], table["cells"]
    lines = [f"### {title}" if title else ""]

    def block(head: str, fn: Callable[[dict], str]) -> None:
        lines.append("")
        lines.append(f"**{head}**")
        lines.append("")
        lines.append("| method | " + " | ".join(terms) + " |")
        lines.append("|---|" + "---|" * len(terms))
        for m in methods:
            row = []
            for t in terms:
                cell = cells[m].get(t)
                row.append("error" if cell is None or "error" in cell else fn(cell))
            label = m.strip() if not m.startswith("  ") else "&nbsp;&nbsp;" + m.strip()
            lines.append(f"| {label} | " + " | ".join(row) + " |")

    block(
        "honest: C (Table 2 grade) / P of the forecast vs the raw check values",
        lambda c: f"{_fmt(c['C'])} ({c['c_grade']}) / {_fmt(c['P'])}",
    )
    block(
        "paper 004's rule: C (grade) / P over build fit + check forecast, x⁰(1) left out",
        lambda c: f"{_fmt(c['C_paper'])} ({c['c_grade_paper']}) / {_fmt(c['P_paper'])}",
    )
    block(
        "in-sample C (grade) of the build-part fit against the series the model fitted (no forecast)",
        lambda c: f"{_fmt(c['C_insample'])} ({'1234'[min(3, sum(c['C_insample'] >= b for b in (0.35, 0.5, 0.65)))]})",
    )
    block("RMSE / bias (check − forecast) vs the raw check values", lambda c: f"{c['rmse']:.3g} / {c['bias']:+.2g}")
    lines.append("")
    lines.append(
        "C of the improved forecast against check values smoothed together with the build part "
        "(not honest): "
        + ", ".join(
            f"{t} {_fmt(cells['improved GM(1,1)'][t].get('C_smoothed'))}"
            for t in terms
            if "improved GM(1,1)" in cells and t in cells["improved GM(1,1)"]
        )
    )
    for t, why in table["skipped"].items():
        lines.append(f"- {t}: {why}")
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------------------------------------- demo

#: term → (nominal value, relative frame noise); units as the rest of allanite's fit output
SYNTH = {"Q": (2.0e-6, 0.05), "N": (0.10, 0.03), "B": (1.0, 0.10), "K": (0.5, 0.25), "R": (0.05, 0.40)}

#: scenario → (warm-up time constant of the ARW rise in frames, relative frame noise of N)
SCENARIOS = {"warmup": (45.0, 0.03), "steady": (400.0, 0.01)}


def synthetic_coefficients(
    seed: int = 0, frames: int = 90, scenario: str = "warmup"
) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    """Per-frame coefficient series that drift, and their noise-free truth.

    ARW rises 30 % over the record along 1 − e^{−t/τ} (scaled to reach +30 % at the last frame):
    ``warmup`` τ = 45 frames (most of the rise in the build part, ≈ 4 % left in the check part, N frame
    noise 3 %); ``steady`` τ = 400 frames (almost a straight line, ≈ 10 % rise in the check part, N
    frame noise 1 %). Bias instability steps +20 % at frame 45; Q, K, R constant. Each value is the
    truth times exp(σ·ε − σ²/2), ε standard normal, σ the term's relative frame noise (``SYNTH``)."""
    tau, n_noise = SCENARIOS[scenario]
    rng = np.random.default_rng(seed)
    k = np.arange(frames, dtype=np.float64)
    warm = (1 - np.exp(-k / tau)) / (1 - np.exp(-(frames - 1) / tau))
    trend = {
        "Q": np.ones(frames),
        "N": 1 + 0.3 * warm,
        "B": np.where(k >= 45, 1.2, 1.0),
        "K": np.ones(frames),
        "R": np.ones(frames),
    }
    out, truth = {}, {}
    for term, (nominal, sigma) in SYNTH.items():
        if term == "N":
            sigma = n_noise
        truth[term] = nominal * trend[term]
        out[term] = truth[term] * np.exp(sigma * rng.standard_normal(frames) - 0.5 * sigma**2)
    return out, truth


def _mean_table(tables: list[dict[str, Any]]) -> str:
    t0 = tables[0]
    terms, methods = t0["terms"], t0["methods"]

    def rows(head: str, fn: Callable[[str, str], str]) -> list[str]:
        out = ["", head, "", "| method | " + " | ".join(terms) + " |", "|---|" + "---|" * len(terms)]
        for m in methods:
            label = m.strip() if not m.startswith("  ") else "&nbsp;&nbsp;" + m.strip()
            out.append(f"| {label} | " + " | ".join(fn(m, t) for t in terms) + " |")
        return out

    def vals(m: str, t: str, key: str) -> np.ndarray:
        return np.array([tb["cells"][m][t][key] for tb in tables if key in tb["cells"][m].get(t, {})])

    def c_cell(m: str, t: str) -> str:
        cs, cp = vals(m, t, "C"), vals(m, t, "C_paper")
        return f"{np.mean(cs):.2f} ± {np.std(cs):.2f} ({100 * np.mean(cs < 0.5):.0f} %) [{np.mean(cp):.2f}]"

    def r_cell(m: str, t: str) -> str:
        r = vals(m, t, "rmse") / vals("persistence", t, "rmse")
        return f"{np.median(r):.2f}"

    lines = rows(
        f"**honest C over {len(tables)} seeds: mean ± SD (share of seeds with C < 0.5, grade 1–2); "
        "paper-rule C mean in brackets**",
        c_cell,
    )
    lines += rows(
        f"**RMSE of the 30-frame forecast / RMSE of persistence, median over {len(tables)} seeds "
        "(< 1: better than the last value)**",
        r_cell,
    )
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--seeds", type=int, default=0, help="also average C over this many seeds")
    ap.add_argument(
        "--scenario", choices=sorted(SCENARIOS), action="append", help="synthetic scenario(s); default both"
    )
    ap.add_argument("--out", default=None, help="write the markdown here too")
    args = ap.parse_args(argv)
    text = ""
    for scen in args.scenario or ["warmup", "steady"]:
        coeffs, truth = synthetic_coefficients(args.seed, scenario=scen)
        text += to_markdown(
            forecast_table(coeffs, truth=truth), title=f"synthetic '{scen}', seed {args.seed}, 60 build / 30 check"
        )
        if args.seeds:
            tables = []
            for sd in range(args.seeds):
                c, t = synthetic_coefficients(sd, scenario=scen)
                tables.append(forecast_table(c, truth=t))
            text += _mean_table(tables)
        text += "\n"
    sys.stdout.write(text)
    if args.out:
        with open(args.out, "w", encoding="utf-8") as fh:
            fh.write(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
