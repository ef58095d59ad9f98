"""What a noise-model fit returns: :class:`NoiseFit` of one curve, :class:`CoefficientSeries` of every window
of a dynamic result, each :class:`Coefficient` with its interval (θ ± z·SE on θ = coefficient², clipped at 0,
square-rooted) and the datasheet read-offs of the curve.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._display import RichDisplay, Summary, Table, fmt_ci, fmt_range, thin
from .._dist import norm_ppf
from ..errors import ParameterError
from ..plot import plot_coefficient_series, plot_fit  # matplotlib only when a figure is drawn
from ..results import AllanResult
from ..units import accel_unit_name, coefficient_unit, report_unit
from ._fitcore import edf_per_tau
from .terms import TERM_NAMES, design_matrix


@dataclass(frozen=True)
class Coefficient:
    """One fitted coefficient.

    ``value`` and ``ci`` are in the input unit's base form (for °/s samples: Q in °, N in °/√s,
    B in °/s, K in °/s^1.5, R in °/s²); ``ieee`` and ``ieee_ci`` in IEEE-952 units
    (``ieee_unit``: °, °/√h, °/h, °/h^1.5, °/h²) when the input unit is known — for an accelerometer's unit
    (m/s², g, …) in its report units (m/s, m/s/√h, µg, m/s/h^1.5, m/s/h²: :func:`allanite.units.accel_report_unit`).
    """

    name: str
    value: float
    ci: tuple
    unit: str | None = None
    ieee: float | None = None
    ieee_ci: tuple | None = None
    ieee_unit: str | None = None

    def __repr__(self) -> str:
        u = f" {self.unit}" if self.unit else ""
        s = f"{self.name} = {self.value:.4g}{u} [{self.ci[0]:.4g}, {self.ci[1]:.4g}]"
        if self.ieee is not None and self.ieee_ci is not None:
            s += f" = {self.ieee:.4g} {self.ieee_unit} [{self.ieee_ci[0]:.4g}, {self.ieee_ci[1]:.4g}]"
        return s


def report_header(unit) -> tuple:
    """The two report-unit columns' headers: IEEE-952's for a gyro (or no unit), the accelerometer's otherwise."""
    if accel_unit_name(unit) is not None:
        return ("accelerometer units [interval]", "accelerometer unit")
    return ("IEEE-952 [interval]", "IEEE unit")


def coefficient_table(coefficients: dict, caption: str, unit=None) -> Table:
    """The coefficients as a display table: value [interval] in base form and in IEEE-952 units (an
    accelerometer's ``unit``: in its report units)."""
    rows = []
    for c in coefficients.values():
        ieee = "—" if c.ieee is None or c.ieee_ci is None else fmt_ci(c.ieee, *c.ieee_ci)
        rows.append(
            [
                c.name,
                TERM_NAMES.get(c.name, ""),
                fmt_ci(c.value, *c.ci),
                c.unit or "base form",
                ieee,
                c.ieee_unit or "—",
            ]
        )
    return Table(("term", "", "value [interval]", "unit", *report_header(unit)), rows, caption)


@dataclass(frozen=True, repr=False, eq=False)
class NoiseFit(RichDisplay):
    """The fitted model: coefficients with intervals, the fitted curve and the residuals.

    Attributes
    ----------
    coefficients : dict
        Term name → :class:`Coefficient`.
    tau, avar, edf : ndarray
        The τ used in the fit, the estimates there and their equivalent degrees of freedom.
    model : ndarray
        Fitted Allan variance at ``tau``; ``components`` maps each term to its share.
    z : ndarray
        Residual per τ in units of the estimate's standard deviation: (σ̂² − σ²_model)/(σ²_model·√(2/ν)).
    chi2, dof, chi2_dof, p_value : float
        Goodness of fit: χ² of the residuals (whitened by the estimates' covariance across τ for
        overlapping results — neighbouring z are correlated, so this is not Σz² —, Σz² otherwise),
        degrees of freedom = points − active terms, its p-value.
    readoffs : dict
        Datasheet read-offs from the full curve: ``adev_at_1s`` (ARW read-off, °/√s for °/s input:
        σ(1 s)·√1 s), ``adev_min``, ``tau_at_min`` and ``bias_instability_readoff`` = min/0.664.
    confidence : float
        Level of the intervals.
    notes : tuple of str
        What the fit decided on its own (e.g. the τ range chosen by ``tau_range="auto"``).
    method : str
        ``"gls"`` — generalized least squares with the estimates' exact covariance across τ (overlapping
        results); ``"wls"`` — independent weights with the octave-correlation sandwich (classic, Theo).
    """

    coefficients: dict
    terms: tuple
    tau: np.ndarray
    m: np.ndarray
    avar: np.ndarray
    edf: np.ndarray
    model: np.ndarray
    components: dict
    z: np.ndarray
    chi2: float
    dof: int
    chi2_dof: float
    p_value: float
    readoffs: dict
    fs: float
    confidence: float
    unit: str | None = None
    iterations: int = 0
    method: str = "wls"
    notes: tuple = ()
    theta: np.ndarray = field(default=None)  # type: ignore[arg-type]  # always set by fit
    covariance: np.ndarray = field(default=None)  # type: ignore[arg-type]

    def curve(self, tau) -> np.ndarray:
        """The fitted Allan variance at any τ (s)."""
        tau = np.asarray(tau, dtype=np.float64)
        m = np.maximum(1.0, tau * self.fs)  # real m: a smooth curve between the integer points
        return design_matrix(tau, m, self.fs, self.terms) @ self.theta

    def component(self, name: str, tau) -> np.ndarray:
        """One term's Allan variance at τ (s)."""
        tau = np.asarray(tau, dtype=np.float64)
        m = np.maximum(1.0, tau * self.fs)  # real m: a smooth curve between the integer points
        k = self.terms.index(name)
        return design_matrix(tau, m, self.fs, (name,))[:, 0] * self.theta[k]

    def __repr__(self) -> str:
        lines = [
            f"NoiseFit({len(self.tau)} τ, {self.method.upper()}, χ²/dof = {self.chi2_dof:.3g}, p = {self.p_value:.3g}, "
            f"{self.confidence:.1%} intervals)"
        ]
        lines += [f"  {c!r}" for c in self.coefficients.values()]
        lines += [f"  note: {n}" for n in self.notes]
        return "\n".join(lines)

    def plot(self, ax=None, **kwargs):
        """ADEV estimates with the fitted model and each term as its own line."""
        return plot_fit(self, ax=ax, **kwargs)

    def _summary(self) -> Summary:
        ro = self.readoffs or {}
        u = f" {self.unit}" if self.unit else ""
        facts: list = [
            ("fitted", f"{len(self.tau)} τ, {fmt_range(self.tau, 's')} ({self.method.upper()})"),
            ("goodness", f"χ²/dof = {self.chi2_dof:.3g} (dof {self.dof}), p = {self.p_value:.3g}"),
            ("intervals", f"{self.confidence:.1%}"),
        ]
        if ro.get("adev_at_1s") is not None:
            facts.append(("σ(1 s) read-off", f"{ro['adev_at_1s']:.4g}{u}"))
        if ro.get("adev_min") is not None:
            facts.append(
                (
                    "σ minimum read-off",
                    f"{ro['adev_min']:.4g}{u} at τ = {ro['tau_at_min']:.4g} s; "
                    f"÷ 0.664 = {ro['bias_instability_readoff']:.4g}{u}",
                )
            )
        return Summary(
            title="NoiseFit",
            what=_fit_what(self.unit),
            facts=facts,
            tables=[coefficient_table(self.coefficients, "coefficients", self.unit)],
            notes=list(self.notes),  # what the fit decided itself, e.g. "fitted from τ ≥ 0.16 s (tau_range='auto')"
            figure=self._draw_small,
        )

    def _draw_small(self, ax) -> None:
        """The inline figure: the estimates and the fitted model (≤ MAX_POINTS points each)."""
        i = thin(len(self.tau))
        ax.loglog(self.tau[i], np.sqrt(self.avar[i]), "k.", ms=3, label="estimate")
        grid = np.geomspace(self.tau[0], self.tau[-1], 120)
        ax.loglog(grid, np.sqrt(np.maximum(self.curve(grid), 0.0)), "C3-", lw=1, label="model")
        ax.set_xlabel("τ (s)")
        ax.set_ylabel("ADEV")
        ax.legend(fontsize="small", frameon=False)


def _fit_what(unit) -> str:
    acc = accel_unit_name(unit)
    if acc is not None:
        what = "velocity random walk, bias instability, …"
        return f"noise model fitted to an accelerometer's Allan variance ({acc}: {what})"
    return "IEEE-952 noise model fitted to the Allan variance" + ("" if unit else " (unit unknown)")


@dataclass(frozen=True, repr=False, eq=False)
class CoefficientSeries(RichDisplay):
    """Coefficients fitted in every window of a dynamic result (paper 002's 2-D representation).

    ``values``, ``ci_low``, ``ci_high`` map term → array over ``t`` (input unit's base form);
    ``ieee`` maps term → array in IEEE-952 units (``ieee_units``) when the unit is known (an accelerometer's:
    its report units, m/s/√h, µg, …);
    ``notes`` says what the fit decided on its own (the τ cut of ``tau_range="auto"``).
    """

    t: np.ndarray
    terms: tuple
    values: dict
    ci_low: dict
    ci_high: dict
    chi2_dof: np.ndarray
    confidence: float
    unit: str | None = None
    ieee: dict | None = None
    ieee_units: dict | None = None
    notes: tuple = ()

    def __repr__(self) -> str:
        parts = ", ".join(f"{k} median {np.median(v):.3g}" for k, v in self.values.items())
        return f"CoefficientSeries({self.t.size} windows: {parts})"

    def plot(self, axes=None, ieee: bool = True):
        """Each coefficient against time, with its interval band."""
        return plot_coefficient_series(self, axes=axes, ieee=ieee)

    def _summary(self) -> Summary:
        values, units = (
            self.values,
            {k: coefficient_unit(k, self.unit) if self.unit else "base form" for k in self.terms},
        )
        ieee = self.ieee is not None and self.ieee_units is not None
        if self.ieee is not None and self.ieee_units is not None:
            values, units = self.ieee, self.ieee_units
        rows: list = []
        for k in self.terms:
            unit = units[k]
            v: np.ndarray = np.asarray(values[k], dtype=np.float64)
            # a window whose non-negative fit put the term at 0 has not resolved it (only an upper bound)
            ok = v[np.asarray(self.values[k]) > 0]
            resolved = f"{ok.size} of {v.size}"
            if ok.size == 0:
                rows.append([k, TERM_NAMES.get(k, ""), resolved, None, None, None, None, unit])
                continue
            lo, hi = float(ok.min()), float(ok.max())
            rows.append([k, TERM_NAMES.get(k, ""), resolved, float(np.median(ok)), lo, hi, hi / lo, unit])
        chi = np.asarray(self.chi2_dof, dtype=float)
        facts: list = [
            ("windows", f"{self.t.size}, centred {fmt_range(self.t, 's')}"),
            ("terms", "+".join(self.terms)),
            ("intervals", f"{self.confidence:.1%} per window"),
            ("χ²/dof", f"median {np.nanmedian(chi):.3g}, max {np.nanmax(chi):.3g}" if chi.size else "—"),
        ]
        return Summary(
            title="CoefficientSeries",
            what="noise coefficients fitted in every window of a dynamic result",
            facts=facts,
            tables=[
                Table(
                    ("term", "", "resolved in", "median", "min over t", "max over t", "max/min", "unit"),
                    rows,
                    "over the windows that resolved the term; "
                    + (_series_units(self.unit) if ieee else "base form of the samples' unit"),
                )
            ],
            notes=list(self.notes)
            + ["a window that did not resolve a term has only an upper bound (ci_high), left out of the table"],
            figure=self._draw_small,
        )

    def _draw_small(self, ax) -> None:
        """The inline figure: each coefficient over time relative to its median (≤ MAX_POINTS points)."""
        j = thin(self.t.size)
        for n, k in enumerate(self.terms):
            v = np.asarray(self.values[k], dtype=float)
            ok = v > 0  # resolved windows only
            if ok.sum() >= max(2, v.size // 2):
                shown = np.where(ok, v, np.nan)[j]
                ax.semilogy(self.t[j], shown / np.median(v[ok]), f"C{n}-", lw=1, label=k)
        ax.set_xlabel("t (s)")
        ax.set_ylabel("coefficient / median")
        ax.legend(fontsize="small", frameon=False, ncol=len(self.terms))


def _series_units(unit) -> str:
    return "the accelerometer's report units" if accel_unit_name(unit) is not None else "IEEE-952 units"


def interval(theta_k, var_k, zq, inflate):
    """(low, high) of a coefficient from θ_k = coefficient² and its variance: θ ± z·SE·inflate,
    clipped at 0, square-rooted."""
    se = math.sqrt(max(var_k, 0.0)) * inflate if np.isfinite(var_k) else math.inf
    lo = max(0.0, theta_k - zq * se)
    hi = theta_k + zq * se
    return math.sqrt(lo), math.sqrt(hi) if np.isfinite(hi) else math.inf


#: σ_min is read off only where the estimate has at least this many equivalent degrees of freedom for
#: flicker rate noise (the bias-instability floor where σ_min sits): the ADEV is then known to ≈ ±22 %.
#: The last τ of a curve (a few clusters; Theo points reaching 75 % of the record) have ν ≈ 1–5: their
#: scatter, not the sensor, would set the minimum.
READOFF_MIN_EDF = 10.0


def readoffs(result: AllanResult, adev_row: np.ndarray) -> dict:
    """Datasheet read-offs of one ADEV curve: σ(1 s), σ_min and where, σ_min/0.664.

    σ_min is searched over the τ whose estimate has ν ≥ :data:`READOFF_MIN_EDF` for flicker rate noise
    (``readoff_tau_max`` is the longest such τ): a minimum at a τ with ν ≈ 1 is the estimate's scatter.
    """
    tau = result.tau
    out: dict[str, Any] = {}
    if tau[0] <= 1.0 <= tau[-1]:
        # log-log interpolation between the neighbours of 1 s (exact when 1 s is on the grid)
        out["adev_at_1s"] = float(np.exp(np.interp(0.0, np.log(tau), np.log(adev_row))))
        out["adev_at_1s_interpolated"] = not np.any(np.isclose(tau, 1.0))
    else:
        out["adev_at_1s"] = None
        out["adev_at_1s_interpolated"] = None
    src = result.estimator if result.source is None else np.asarray(result.source)
    window = getattr(result, "window", None) or result.n_samples
    nu = edf_per_tau(np.full(tau.size, -1), np.asarray(result.m), window + 1, src)
    usable = np.flatnonzero(nu >= READOFF_MIN_EDF)
    if usable.size == 0:
        usable = np.arange(tau.size)
    i = int(usable[np.argmin(np.asarray(adev_row)[usable])])
    out["readoff_tau_max"] = float(tau[usable[-1]])
    out["adev_min"] = float(adev_row[i])
    out["tau_at_min"] = float(tau[i])
    out["bias_instability_readoff"] = float(adev_row[i] / 0.664)
    return out


def z_quantile(confidence) -> float:
    """The two-sided normal quantile of a confidence level (1.0 for 68.3 %)."""
    if (
        isinstance(confidence, bool)
        or not isinstance(confidence, (int, float, np.floating))
        or not 0.0 < float(confidence) < 1.0
    ):
        raise ParameterError(f"confidence must be a level strictly between 0 and 1, got {confidence!r}")
    return float(norm_ppf(0.5 + float(confidence) / 2.0))


def coefficients(terms, theta, cov, zq, inflate, unit) -> dict:
    """Term → :class:`Coefficient` from θ = coefficient² and its covariance (intervals θ ± z·SE,
    widened by ``inflate``, clipped at 0, square-rooted); IEEE-952 values when ``unit`` is known."""
    coeffs = {}
    for k, name in enumerate(terms):
        value = math.sqrt(theta[k])
        ci = interval(theta[k], cov[k, k], zq, inflate)
        if unit is not None:
            q = report_unit(name, value, unit)  # an accelerometer's: its report units (m/s/√h, µg, …)
            lo = report_unit(name, ci[0], unit).value
            hi = report_unit(name, ci[1], unit).value if np.isfinite(ci[1]) else math.inf
            coeffs[name] = Coefficient(name, value, ci, coefficient_unit(name, unit), q.value, (lo, hi), q.unit)
        else:
            coeffs[name] = Coefficient(name, value, ci)
    return coeffs


def intervals(theta, var, zq, inflate):
    """:func:`interval` of many coefficients at once: arrays (low, high)."""
    se = np.where(np.isfinite(var), np.sqrt(np.maximum(var, 0.0)) * inflate, np.inf)
    with np.errstate(invalid="ignore"):
        hi = theta + zq * se
        return np.sqrt(np.maximum(0.0, theta - zq * se)), np.where(np.isfinite(hi), np.sqrt(hi), np.inf)
