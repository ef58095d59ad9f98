"""Judging forecast methods on a build/check split, one series or a table of them (paper 004 §4)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from .._display import RichDisplay, Summary, Table
from ..errors import AllaniteError, InputError, ParameterError
from ._forecaster import accuracy_rows
from ._series import as_series, check_sd
from .baselines import BuildMean, Holt, LinearTrend, Persistence
from .grades import Accuracy, accuracy
from .grey import GM11
from .improved import ImprovedGM11

__all__ = ["Score", "compare", "default_methods", "score", "split"]


@dataclass(frozen=True)
class Score(RichDisplay):
    """A method judged on a build/check split.

    Attributes
    ----------
    name : str
    forecast : ndarray
        The method's forecast of the check part (built on the build part only).
    honest : Accuracy
        C, P of ``forecast`` against the **raw** check values (all of them).
    paper_rule : Accuracy
        Paper 004's rule: a-posteriori values over build and check together — the in-sample ``fitted``
        against the series the model was fitted to (``processed`` for the improved model, else the raw
        build), then ``forecast`` against the raw check — with x⁰(1) left out.
    rmse : float
        Root-mean-square forecast error against the raw check values.
    bias : float
        Mean of (check − forecast). C and P ignore a constant offset (S2 is the SD of e about its mean,
        so any constant forecast has C = 1 exactly); ``bias`` and ``rmse`` show it.
    model : object
        The fitted model.
    """

    name: str
    forecast: np.ndarray
    honest: Accuracy
    paper_rule: Accuracy
    rmse: float
    bias: float
    model: Any = field(repr=False)

    @property
    def differs(self) -> bool:
        """Whether the paper's rule gives another C (to 3 decimals) than the honest one."""
        return round(self.paper_rule.C, 3) != round(self.honest.C, 3)

    def _summary(self) -> Summary:
        notes = ["the paper's rule gives another C than the honest check"] if self.differs else []
        return Summary(
            title=f"Score · {self.name}",
            what="a forecast judged on a build/check split",
            facts=[
                ("forecast", f"{np.asarray(self.forecast).size} values of the check part"),
                ("RMSE", f"{self.rmse:.4g}"),
                ("bias (check − forecast)", f"{self.bias:.4g}"),
            ],
            tables=[
                Table(
                    ("check", "value", "grade"),
                    accuracy_rows(self.honest, "honest") + accuracy_rows(self.paper_rule, "paper's rule"),
                )
            ],
            notes=notes,
        )


def split(series: Any, build: int, check: int) -> tuple[np.ndarray, np.ndarray]:
    """The first ``build`` values and the ``check`` values after them; errors name what does not fit."""
    x = as_series(series, min_len=2)
    for nm, v in (("build", build), ("check", check)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)):
            raise ParameterError(f"{nm} = {v!r} must be an integer count of values")
    if build < 4:
        raise ParameterError(f"build = {build} is too small; GM(1,1) needs at least 4 values to build on")
    if check < 2:
        raise ParameterError(f"check = {check} is too small; C and P need at least 2 held-out values")
    if build + check > x.size:
        raise ParameterError(
            f"build + check = {build} + {check} = {build + check} exceeds the series length ({x.size})"
        )
    return x[:build].copy(), x[build : build + check].copy()


def score(
    method: Callable[..., Any],
    build: Any,
    check: Any,
    *,
    sd: str = "population",
    name: str | None = None,
) -> Score:
    """Build ``method`` on ``build``, forecast ``len(check)`` values, and score them.

    Parameters
    ----------
    method : callable
        A model class or factory called as ``method(build)`` (e.g. ``GM11``, ``Holt``,
        ``functools.partial(ImprovedGM11, smooth=False)``); the result needs ``fitted`` and ``predict(h)``.
    build, check : array_like
        The build part and the raw held-out check part (use :func:`split`).
    sd : {"population", "sample"}
    name : str, optional
        Label; defaults to the model's ``name``.

    Returns
    -------
    Score

    Examples
    --------
    >>> x = [1.0, 1.1, 1.25, 1.3, 1.45, 1.5, 1.62, 1.7, 1.85, 1.9]
    >>> build, check = split(x, 7, 3)
    >>> s = score(GM11, build, check)
    >>> print(f"{s.name}: C = {s.honest.C:.3f} ({s.honest.grade}), rmse = {s.rmse:.3f}")
    GM(1,1): C = 0.466 (qualified), rmse = 0.080
    """
    check_sd(sd)
    b = as_series(build, name="build")
    c = as_series(check, name="check", min_len=2)
    model = method(b)
    fc = np.asarray(model.predict(c.size), dtype=np.float64)
    if fc.shape != c.shape or not np.all(np.isfinite(fc)):
        raise InputError(f"{name or getattr(model, 'name', method)} gave a non-finite or mis-sized forecast")
    honest = accuracy(c, fc, sd=sd, include_first=True)
    basis = np.asarray(getattr(model, "processed", b), dtype=np.float64)
    paper = accuracy(np.concatenate([basis, c]), np.concatenate([model.fitted, fc]), sd=sd, include_first=False)
    e = c - fc
    return Score(
        str(name or getattr(model, "name", None) or method),
        fc,
        honest,
        paper,
        float(np.sqrt(np.mean(e * e))),
        float(np.mean(e)),
        model,
    )


def default_methods() -> dict[str, Callable[..., Any]]:
    """Name → model factory of the methods :func:`compare` judges, in table order: the traditional and the
    improved GM(1,1) (all steps on) and the four baselines."""
    return {
        "GM(1,1)": GM11,
        "improved GM(1,1)": ImprovedGM11,
        "persistence": Persistence,
        "build mean": BuildMean,
        "linear trend": LinearTrend,
        "Holt": Holt,
    }


def compare(
    series: Mapping[str, Any],
    build: int,
    check: int,
    *,
    methods: Mapping[str, Callable[..., Any]] | None = None,
    sd: str = "population",
    noise: Mapping[str, Any] | None = None,
) -> dict[str, Any]:
    """Judge every method on every series (e.g. one noise coefficient per time frame, paper 004 §4).

    Parameters
    ----------
    series : mapping
        Name (a noise term) → values, at least ``build + check`` of them (the first ``build + check`` are
        used). A series with a value ≤ 0 (a term the frame fits did not resolve) is not forecastable:
        it is listed in ``skipped`` with the reason and fed to no model.
    build, check : int
        The split: build on the first ``build`` values, forecast and check the next ``check`` (paper 004:
        60 / 30).
    methods : mapping, optional
        Name → factory called as ``factory(build_values)``; default :func:`default_methods`.
    sd : {"population", "sample"}
        SD convention of C and P.
    noise : mapping, optional
        Name → per-value standard error of the series itself (e.g. the frame fits' intervals). Adds
        ``se_check``, the RMS standard error over the check values, and ``rmse_over_se`` to every cell: a
        forecast cannot be expected to beat the estimation noise of the values it is checked against
        (≈ 1 means the forecast error is that noise).

    Returns
    -------
    dict
        ``{"build", "check", "sd", "terms", "methods", "cells": {method: {term: cell}}, "skipped": {term:
        reason}, "scatter": {term: robust SD of successive differences / √2}, "se_check": {term: …}}``. A
        cell holds the forecast (``forecast``), the in-sample ``fitted`` values, ``C``, ``P``, ``c_grade``,
        ``grade`` (honest: against the raw check values), ``C_paper``, ``P_paper``, ``c_grade_paper``,
        ``grade_paper`` (paper 004's rule, see :class:`Score`), ``rmse``, ``bias``, ``notes`` — or
        ``error`` when the method failed on that series.

    Raises
    ------
    ParameterError
        The split does not fit a series (``build`` < 4, ``check`` < 2, ``build + check`` > its length).
    InputError
        A series is not 1-D finite numbers, or is shorter than 4 values.

    Examples
    --------
    >>> x = 1.03 ** np.arange(12) + 0.02 * np.sin(2.0 * np.arange(12))  # exponential growth + a wiggle
    >>> t = compare({"N": x}, 8, 4)
    >>> for m in ("GM(1,1)", "persistence", "linear trend"):
    ...     c = t["cells"][m]["N"]
    ...     print(f"{m}: C = {c['C']:.2f} ({c['grade']}), rmse = {c['rmse']:.3f}")
    GM(1,1): C = 0.23 (good), rmse = 0.013
    persistence: C = 1.00 (fail), rmse = 0.090
    linear trend: C = 0.32 (good), rmse = 0.020
    """
    check_sd(sd)
    methods = default_methods() if methods is None else dict(methods)
    if not methods:
        raise ParameterError("methods is empty; give at least one name → model factory")
    cells: dict[str, dict[str, Any]] = {m: {} for m in methods}
    out: dict[str, Any] = {
        "build": build,
        "check": check,
        "sd": sd,
        "terms": [],
        "methods": list(methods),
        "cells": cells,
        "skipped": {},
        "scatter": {},
        "se_check": {},
    }
    for term, values in series.items():
        x = as_series(values, name=f"series[{term!r}]")
        b, c = split(x, build, check)
        used = x[: build + check]
        out["scatter"][term] = _scatter(used)
        se = None
        if noise is not None and term in noise:
            se = _check_noise(noise[term], term, build, check)
            out["se_check"][term] = se
        nonpos = np.flatnonzero(used <= 0)
        if nonpos.size:
            out["skipped"][term] = (
                f"{nonpos.size} of {used.size} values at or below 0 (first at index {int(nonpos[0])}): the term is "
                "not resolved there, so it is not forecastable (GM(1,1) needs positive values)"
            )
            continue
        out["terms"].append(term)
        for name, factory in methods.items():
            try:
                s = score(factory, b, c, sd=sd, name=name)
            except AllaniteError as exc:
                cells[name][term] = {"error": str(exc)}
                continue
            cells[name][term] = _cell(s, se)
    return out


def _scatter(used: np.ndarray) -> float:
    """Robust frame-to-frame scatter σ of ``used``: successive differences of independent noise have SD √2·σ."""
    d = np.diff(used)
    return float(1.4826 * np.median(np.abs(d - np.median(d))) / math.sqrt(2.0))


def _check_noise(values: Any, term: str, build: int, check: int) -> float:
    """RMS of a term's own standard errors over the check frames (``values`` has one per frame)."""
    se_all = np.asarray(values, dtype=np.float64)
    if se_all.shape[0] < build + check:
        raise InputError(f"noise[{term!r}] has {se_all.shape[0]} values; {build + check} needed")
    return float(np.sqrt(np.mean(se_all[build : build + check] ** 2)))


def _cell(s: Score, se: float | None) -> dict[str, Any]:
    """One cell of :func:`compare`'s table: a method's score on one series (``se``: the series' RMS standard
    error over the check values, when known)."""
    cell: dict[str, Any] = {
        "forecast": s.forecast,
        "fitted": np.asarray(s.model.fitted, dtype=np.float64),
        "C": s.honest.C,
        "P": s.honest.P,
        "c_grade": s.honest.c_grade,
        "grade": s.honest.grade,
        "C_paper": s.paper_rule.C,
        "P_paper": s.paper_rule.P,
        "c_grade_paper": s.paper_rule.c_grade,
        "grade_paper": s.paper_rule.grade,
        "rmse": s.rmse,
        "bias": s.bias,
        "notes": list(getattr(s.model, "notes", [])),
    }
    if isinstance(s.model, ImprovedGM11):
        cell["processed"] = s.model.processed
    if se is not None:
        cell["rmse_over_se"] = s.rmse / se if se > 0 else math.inf
    return cell
