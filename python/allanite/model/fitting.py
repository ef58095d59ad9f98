"""Fitting the IEEE-952 noise model to an Allan variance: weighted non-negative least squares in linear
variance space, iteratively reweighted by the model's own variance of each estimate.

The model and its terms: :mod:`allanite.model.terms`.

Why not a line fit in log-log space: ln σ̂² is biased low by ≈ 1/ν and its variance 2/ν makes the
few-cluster long-τ points weigh as much as the good ones (``docs/FORMULAS.md`` §9).

Overlapping estimates (the default estimator) are fitted by generalized least squares with their
exact covariance across τ under the model (:mod:`allanite.model._covariance`): neighbouring estimates share
most of their data, and the covariance says by how much, so the fit neither overcounts them nor
throws information away; it is recomputed from the fitted coefficients until they settle. The
coefficient covariance is then (AᵀΣ⁻¹A)⁻¹ and χ² is that of the whitened residuals. Classic and
Theo-family estimates are weighted by ν/(2σ⁴_model) (ν the equivalent degrees of freedom for the
noise type that dominates the model at that τ), with an octave-correlation model in the intervals.
By default only τ at least an octave apart enter either fit.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._display import RichDisplay, Summary, Table, fmt_ci, fmt_range, thin
from .._dist import chi2_sf, norm_ppf
from .._progress import show_progress
from .._validate import check_count, check_nonnegative, check_positive
from ..errors import ParameterError
from ..estimators import get as get_estimator
from ..estimators import names as estimator_names
from ..plot import plot_coefficient_series, plot_fit  # matplotlib only when a figure is drawn
from ..results import AllanResult, DynamicAllanResult
from ..units import coefficient_unit, ieee952, rate_unit
from . import _batched, _covariance
from ._fitcore import (
    GLS_START_ITER,
    GLS_TOL,
    IRLS_RTOL,
    MAX_GLS_TAU,
    OCTAVE_CORRELATION,
    check_gls_size,
    edf_per_tau,
    exact_covariance_applies,
    fit_core,
    nnls,
)
from ._tauselect import check_tau_range, estimator_key, row_medians, select_taus
from .terms import TERM_ALPHA, TERM_NAMES, TERMS, check_terms, design_matrix

__all__ = [
    "fit",
    "information_bound",
    "NoiseFit",
    "Coefficient",
    "CoefficientSeries",
    "TERMS",
    "edf_per_tau",
    "nnls",
    "interval",
    "readoffs",
    "z_quantile",
    "coefficients",
    "check_tau_range",
    "MAX_GLS_TAU",
    "row_medians",
]


@dataclass(frozen=True)
class Coefficient:
    """One fitted coefficient.

    ``value`` and ``ci`` are in the input unit's base form (for °/s samples: Q in °, N in °/√s,
    B in °/s, K in °/s^1.5, R in °/s²); ``ieee`` and ``ieee_ci`` in IEEE-952 units
    (``ieee_unit``: °, °/√h, °/h, °/h^1.5, °/h²) when the input unit is known.
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


def coefficient_table(coefficients: dict, caption: str) -> Table:
    """The coefficients as a display table: value [interval] in base form and in IEEE-952 units."""
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
    return Table(("term", "", "value [interval]", "unit", "IEEE-952 [interval]", "IEEE unit"), rows, caption)


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
            what="IEEE-952 noise model fitted to the Allan variance" + ("" if self.unit else " (unit unknown)"),
            facts=facts,
            tables=[coefficient_table(self.coefficients, "coefficients")],
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


@dataclass(frozen=True, repr=False, eq=False)
class CoefficientSeries(RichDisplay):
    """Coefficients fitted in every window of a dynamic result (paper 002's 2-D representation).

    ``values``, ``ci_low``, ``ci_high`` map term → array over ``t`` (input unit's base form);
    ``ieee`` maps term → array in IEEE-952 units (``ieee_units``) when the unit is known;
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
                    + ("IEEE-952 units" if ieee else "base form of the samples' unit"),
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
            q = ieee952(name, value, unit)
            lo = ieee952(name, ci[0], unit).value
            hi = ieee952(name, ci[1], unit).value if np.isfinite(ci[1]) else math.inf
            coeffs[name] = Coefficient(name, value, ci, coefficient_unit(name, unit), q.value, (lo, hi), q.unit)
        else:
            coeffs[name] = Coefficient(name, value, ci)
    return coeffs


def fit(
    result,
    *,
    terms=TERMS,
    unit=None,
    confidence: float = 0.683,
    thin: bool = True,
    tau_range=None,
    max_iter: int = 50,
    progress=None,
):
    """Fit the IEEE-952 noise terms to an Allan variance result.

    Parameters
    ----------
    result : AllanResult or DynamicAllanResult
        Static result → :class:`NoiseFit` (a list of them for several axes). Dynamic result →
        :class:`CoefficientSeries`, the coefficients of every window (a list for several axes).
        The result should be of the overlapping ("oavar") or classic ("avar") estimator.
    terms : sequence of {"Q", "N", "B", "K", "R"}
        Terms to fit (drop the ones the data cannot support).
    unit : str, optional
        Unit of the rate samples the result was computed from (e.g. "deg/s"); gives each
        coefficient its IEEE-952 value (``ieee``). Must be a rate unit.
    confidence : float
        Level of the coefficient intervals (default 68.3 %).
    thin : bool
        Use only τ at least an octave apart (default), so correlated neighbours do not overcount
        information; ``False`` uses every τ of the result.
    tau_range : (float, float) or "auto", optional
        Fit only τ in [low, high] seconds (either may be None). Real sensors are often not white
        at the shortest τ (anti-alias filters, vibration lines): those points carry the largest
        EDF and can dominate a fit of a model that does not describe them. ``"auto"``: fit all τ,
        and if the model does not describe them (χ²/dof > ``AUTO_CHI2_DOF``), drop the shortest τ
        an octave at a time — up to τ = ``AUTO_MAX_CUT_M`` samples — until it does (or take the cut
        with the lowest χ²/dof); the choice is stated in ``NoiseFit.notes``. For a dynamic result
        the cut is chosen on the windows' median curve and applied to every window.
    max_iter : int
        Reweighting iterations at most.
    progress : bool, optional
        Dynamic results: a ``tqdm.auto`` bar over the windows when there are more than
        ``allanite.model._batched.PIECE`` of them — None (default) shows it in a notebook or a terminal,
        True always, False never. It appears only after a second.

    Notes
    -----
    Overlapping ("oavar") results, static or dynamic: generalized least squares with the estimates'
    exact covariance across τ under the model (each term's generalized covariance summed over all
    lags of the overlapping second differences; a deterministic ramp enters through its cross term
    with the noise), iterated from the fitted coefficients; non-negative; coefficient covariance
    (AᵀΣ⁻¹A)⁻¹. On 100 simulated records per set (``benches/noise_fit.py``: Q, N, B with K or R) the
    68.3 % intervals cover the truth in 59–83 % of runs for every term (59–77 % is what a correct
    interval gives with 100 runs), and the RMS error is 0.94–1.25 × the record's Cramér–Rao bound
    (:func:`information_bound`). ``thin=False`` fits every τ with its full covariance (at most
    ``MAX_GLS_TAU`` of them; ~4 s to build the covariance for 160 τ, cached afterwards).

    Classic ("avar") and Theo-family results: weights ν/(2σ⁴) from Greenhall's (or Howe's Theo1) EDF,
    and the sandwich covariance (AᵀWA)⁻¹AᵀWΣWA(AᵀWA)⁻¹ with an octave-correlation model for Σ
    (``OCTAVE_CORRELATION``) — approximate: intervals ~1.3× too narrow for B and K in a four-term
    mixture.

    Either way the covariance is inflated by √(χ²/dof) when the model fits worse than its noise, and
    intervals are θ ± z·SE on θ = coefficient², clipped at zero, then square-rooted.

    A dynamic result's windows are fitted all at once in the Rust core, on all its threads (the same
    iteration as a static fit, step for step; ≈ 3–10 µs per window for five terms on the octave τ of
    a window); Ctrl-C stops it.

    Examples
    --------
    >>> import numpy as np, allanite
    >>> y = allanite.simulate(1_000_000, 100.0, N=0.01, K=1e-4, seed=3)
    >>> f = allanite.fit(allanite.avar(y, 100.0), terms=("N", "K"), unit="deg/s")
    >>> round(f.coefficients["N"].value, 3), f.coefficients["N"].ieee_unit
    (0.01, '°/√h')
    """
    terms = check_terms(terms)
    zq = z_quantile(confidence)
    auto = isinstance(tau_range, str)
    if auto and tau_range != "auto":
        raise ParameterError(f"tau_range must be a (low, high) pair of seconds or 'auto', got {tau_range!r}")
    tau_range = (0.0, np.inf) if auto else check_tau_range(tau_range)
    if unit is not None:
        rate_unit(unit)
    show_progress(progress)  # a wrong value fails before any work
    if isinstance(result, DynamicAllanResult):
        _check_fit_estimator(result)
        if auto:
            return _fit_dynamic_auto(result, terms, unit, float(confidence), zq, thin, max_iter, progress)
        return _fit_dynamic(result, terms, unit, float(confidence), zq, thin, max_iter, tau_range, progress)
    if not isinstance(result, AllanResult):
        raise ParameterError(f"fit needs an AllanResult or DynamicAllanResult, got {type(result).__name__}")
    _check_fit_estimator(result)
    one = _fit_static_auto if auto else _fit_static_row
    args = (terms, unit, float(confidence), zq, thin, max_iter) + (() if auto else (tau_range,))
    if result.avar.ndim == 2:
        return [one(result, row, *args) for row in result.avar]
    return one(result, result.avar, *args)


#: A fit this much worse than its noise says so in ``NoiseFit.notes``.
MISFIT_CHI2_DOF = 10.0

#: ``tau_range="auto"`` accepts the first lower τ cut at which the model fits this well ...
AUTO_CHI2_DOF = 3.0
#: ... and cuts at most the τ up to this many samples (anti-alias filters and correlated sampling
#: colour the first few octaves; a misfit further out is the model's, not the front end's).
AUTO_MAX_CUT_M = 64


def _auto_cuts(result, avar_row, thin, n_terms):
    """Lower τ cuts to try: none, then each fitted τ in turn (an octave at a time) up to AUTO_MAX_CUT_M samples,
    keeping at least n_terms + 3 τ."""
    idx = select_taus(result.tau, avar_row, thin, n_terms, "the result")
    tau, m = result.tau[idx], result.m[idx]
    cuts = [0.0]
    for k in range(1, tau.size):
        if m[k] > AUTO_MAX_CUT_M or tau.size - k < n_terms + 3:
            break
        cuts.append(float(tau[k]) * (1.0 - 1e-9))
    return cuts, float(tau[0])


def _auto_choose(cuts, fit_at):
    """The first cut whose fit has χ²/dof ≤ AUTO_CHI2_DOF, else the lowest χ²/dof; (cut, fit, uncut fit)."""
    first = best = None
    for cut in cuts:
        f = fit_at(cut)
        if first is None:
            first = f
        if best is None or f[1] < best[1][1]:
            best = (cut, f)
        if f[1] <= AUTO_CHI2_DOF:
            return cut, f, first, True
    return best[0], best[1], first, False


def _auto_note(cut, chi2_dof, first_chi2_dof, tau0, ok):
    if cut == 0.0:
        return (
            ()
            if ok
            else (
                f"tau_range='auto': no cut of the shortest τ (up to {AUTO_MAX_CUT_M} samples) brought "
                f"χ²/dof to ≤ {AUTO_CHI2_DOF:g}; all τ kept (χ²/dof {chi2_dof:.3g})",
            )
        )
    what = (
        ""
        if ok
        else f" (the lowest χ²/dof of the cuts up to {AUTO_MAX_CUT_M} samples; none reached ≤ {AUTO_CHI2_DOF:g})"
    )
    return (
        f"fitted from τ ≥ {cut * (1 + 1e-9):.4g} s (tau_range='auto'){what}: with all τ from {tau0:.4g} s the "
        f"model gave χ²/dof {first_chi2_dof:.3g}, here {chi2_dof:.3g} — the shortest τ are not described by these "
        f"terms (anti-alias filtering, vibration lines or correlated samples are the usual causes)",
    )


def _fit_static_auto(result, avar_row, terms, unit, confidence, zq, thin, max_iter):
    avar_row = np.asarray(avar_row, dtype=np.float64)
    cuts, tau0 = _auto_cuts(result, avar_row, thin, len(terms))

    def fit_at(cut):
        f = _fit_static_row(result, avar_row, terms, unit, confidence, zq, thin, max_iter, (cut, np.inf))
        return f, f.chi2_dof

    cut, (f, chi), (_, chi0), ok = _auto_choose(cuts, fit_at)
    return dataclasses.replace(f, notes=_auto_note(cut, chi, chi0, tau0, ok) + f.notes)


def _fit_dynamic_auto(result, terms, unit, confidence, zq, thin, max_iter, progress=None):
    rows = [result.avar] if result.avar.ndim == 2 else list(result.avar)
    out = []
    for rows_avar in rows:
        med = row_medians(rows_avar)
        stat = result.static_row(med, n_samples=result.window)
        cuts, tau0 = _auto_cuts(stat, med, thin, len(terms))

        def fit_at(cut, stat=stat, med=med):
            f = _fit_static_row(stat, med, terms, unit, confidence, zq, thin, max_iter, (cut, np.inf))
            return f, f.chi2_dof

        cut, (_, chi), (_, chi0), ok = _auto_choose(cuts, fit_at)
        single = dataclasses.replace(result, avar=rows_avar)
        s = _fit_dynamic(single, terms, unit, confidence, zq, thin, max_iter, (cut, np.inf), progress)
        out.append(dataclasses.replace(s, notes=_auto_note(cut, chi, chi0, tau0, ok)))
    return out[0] if result.avar.ndim == 2 else out


def _check_fit_estimator(result) -> None:
    """The result's values must estimate the Allan variance (the registry's ``estimates_allan``)."""
    if result.estimator == "theo1":
        raise ParameterError(
            "fit needs Allan-variance estimates; raw Theo1 is biased against the Allan variance by "
            "a noise-type-dependent factor: use estimator='theobr' or 'theoh'"
        )
    if not get_estimator(result.estimator).estimates_allan:
        raise ParameterError(f"fit supports the estimators {fit_estimators()}, not {result.estimator!r}")


def fit_estimators() -> tuple[str, ...]:
    """Estimators whose values estimate the Allan variance, so that :func:`fit` accepts them (raw Theo1
    does not: it is biased by a noise-type-dependent factor, which TheoBR's kf removes)."""
    return tuple(n for n in estimator_names() if get_estimator(n).estimates_allan)


def _fit_static_row(result, avar_row, terms, unit, confidence, zq, thin, max_iter, tau_range):
    avar_row = np.asarray(avar_row, dtype=np.float64)
    idx = select_taus(result.tau, avar_row, thin, len(terms), "the result", tau_range)
    tau, m, y = result.tau[idx], result.m[idx].astype(np.float64), avar_row[idx]
    theta, cov, model, nu, z, it, a, chi2 = fit_core(
        tau, m, y, result.fs, result.n_samples + 1, estimator_key(result, idx), terms, confidence, max_iter
    )
    n_active = int(np.count_nonzero(theta > 0))
    dof = max(1, tau.size - n_active)
    chi2_dof = chi2 / dof
    inflate = max(1.0, math.sqrt(chi2_dof))
    coeffs = coefficients(terms, theta, cov, zq, inflate, unit)
    notes = ()
    if chi2_dof > MISFIT_CHI2_DOF:
        notes = (
            f"χ²/dof {chi2_dof:.3g}: these terms do not describe the estimates (intervals widened by "
            f"√(χ²/dof) = {inflate:.3g}); look at z, restrict tau_range, or use tau_range='auto' when the "
            f"misfit is at the shortest τ",
        )
    return NoiseFit(
        coefficients=coeffs,
        terms=terms,
        tau=tau,
        m=m,
        avar=y,
        edf=nu,
        model=model,
        components={t: a[:, k] * theta[k] for k, t in enumerate(terms)},
        z=z,
        chi2=chi2,
        dof=dof,
        chi2_dof=chi2_dof,
        p_value=float(chi2_sf(chi2, dof)),
        readoffs=readoffs(result, np.sqrt(avar_row)),
        fs=result.fs,
        confidence=confidence,
        unit=unit,
        iterations=it,
        theta=theta,
        covariance=cov,
        notes=notes,
        method="gls"
        if exact_covariance_applies(tau, m, result.fs, result.n_samples + 1, estimator_key(result, idx))
        else "wls",
    )


#: A dynamic result's window is flat when every Allan variance in it is at most this share of the result's
#: largest (its rounding residue is ~1e-38 of it; a real noise level 10⁶ lower in amplitude is 1e-12).
FLAT_FLOOR = 1e-24


def _fit_dynamic(result, terms, unit, confidence, zq, thin, max_iter, tau_range, progress=None):
    rows = [result.avar] if result.avar.ndim == 2 else list(result.avar)
    series = []
    for rows_avar in rows:
        # τ chosen on the windows' median curve: one flat window must not decide for all of them
        idx = select_taus(result.tau, row_medians(rows_avar), thin, len(terms), "the dynamic result", tau_range)
        y = np.ascontiguousarray(rows_avar[idx].T)  # windows × fitted τ
        bad = ~np.isfinite(y).all(axis=1)
        if bad.any():
            raise ParameterError(
                f"the dynamic result has a non-finite Allan variance in window {int(np.flatnonzero(bad)[0])}"
            )
        # a window whose samples are all equal (a sensor not yet streaming) has Allan variance 0; the core
        # returns its rounding residue, ~ε²·offset² (≈ 1e-38 of the record's largest value), not always an
        # exact 0: such a window is flat, not a fit (coefficients and intervals 0)
        finite = rows_avar[np.isfinite(rows_avar)]
        flat_floor = FLAT_FLOOR * (float(finite.max()) if finite.size else 0.0)
        fitted = ~np.all(y <= flat_floor, axis=1)
        theta, var, chi2 = np.zeros((y.shape[0], len(terms))), np.zeros((y.shape[0], len(terms))), np.zeros(y.shape[0])
        if fitted.any():
            fits = _window_fits(result, idx, np.maximum(y[fitted], 1e-300), terms, confidence, max_iter, progress)
            theta[fitted], var[fitted], chi2[fitted] = fits
        chi = chi2 / np.maximum(1, idx.size - np.count_nonzero(theta > 0, axis=1))
        inflate = np.maximum(1.0, np.sqrt(chi))
        vals, lo, hi = {}, {}, {}
        for k, t in enumerate(terms):
            vals[t] = np.sqrt(theta[:, k])
            lo[t], hi[t] = intervals(theta[:, k], var[:, k], zq, inflate)
        ieee = ieee_units = None
        if unit is not None:
            ieee = {t: ieee952(t, vals[t], unit).value for t in terms}
            ieee_units = {t: ieee952(t, 1.0, unit).unit for t in terms}
        series.append(
            CoefficientSeries(
                t=result.t,
                terms=terms,
                values=vals,
                ci_low=lo,
                ci_high=hi,
                chi2_dof=chi,
                confidence=confidence,
                unit=unit,
                ieee=ieee,
                ieee_units=ieee_units,
            )
        )
    return series[0] if result.avar.ndim == 2 else series


def intervals(theta, var, zq, inflate):
    """:func:`interval` of many coefficients at once: arrays (low, high)."""
    se = np.where(np.isfinite(var), np.sqrt(np.maximum(var, 0.0)) * inflate, np.inf)
    with np.errstate(invalid="ignore"):
        hi = theta + zq * se
        return np.sqrt(np.maximum(0.0, theta - zq * se)), np.where(np.isfinite(hi), np.sqrt(hi), np.inf)


def _window_fits(result, idx, y, terms, confidence, max_iter, progress):
    """θ, the variance of each θ_k and χ² of every window (rows of ``y``, the estimates at τ[idx]): the
    per-window fit of :func:`fit_core`, run for all windows at once in the core; a window it hands back
    is refitted here."""
    tau, m, fs = result.tau[idx], result.m[idx].astype(np.float64), result.fs
    n_points, est = result.window + 1, estimator_key(result, idx)
    check_gls_size(est, m)
    gls = exact_covariance_applies(tau, m, fs, n_points, est)
    nu_terms = np.column_stack([edf_per_tau(np.full(m.size, TERM_ALPHA[t]), m, n_points, est) for t in terms])
    theta, cov, chi2, _, status = _batched.fit_windows(
        y,
        design_matrix(tau, tau * fs, fs, terms),
        nu_terms,
        start_col=terms.index("N") if "N" in terms else 0,
        irls_iter=GLS_START_ITER,
        max_iter=max_iter,
        gls_tol=GLS_TOL,
        irls_rtol=IRLS_RTOL,
        rho=[OCTAVE_CORRELATION[t] for t in terms],
        log2_tau=np.log2(tau),
        blocks=_covariance.covariance_blocks(m, n_points - 1, fs, terms) if gls else None,
        stoch=[k for k, t in enumerate(terms) if t in _covariance.KERNEL_TERMS],
        ramp=terms.index("R") if "R" in terms else None,
        progress=progress,
    )
    back = np.flatnonzero(status)
    if back.size:
        theta[back], cov[back], chi2[back] = _window_fits_reference(result, idx, y[back], terms, confidence, max_iter)
    return theta, np.diagonal(cov, axis1=1, axis2=2), chi2


def _window_fits_reference(result, idx, y, terms, confidence, max_iter):
    """θ, covariance and χ² of each row of ``y`` by :func:`fit_core`, one window at a time (the reference
    of the batched fit, and the fit of the windows it hands back)."""
    tau, m = result.tau[idx], result.m[idx].astype(np.float64)
    est, cache = estimator_key(result, idx), {}
    theta = np.empty((y.shape[0], len(terms)))
    cov = np.empty((y.shape[0], len(terms), len(terms)))
    chi2 = np.empty(y.shape[0])
    for j in range(y.shape[0]):
        out = fit_core(tau, m, y[j], result.fs, result.window + 1, est, terms, confidence, max_iter, edf_cache=cache)
        theta[j], cov[j], chi2[j] = out[0], out[1], out[7]
    return theta, cov, chi2


def information_bound(n: int, fs: float, *, Q: float = 0.0, N: float = 0.0, B: float = 0.0, K: float = 0.0) -> dict:
    """How precisely a record of ``n`` rate samples at ``fs`` Hz can determine each noise coefficient at all.

    The Cramér–Rao bound, in the Whittle (periodogram) approximation of the Gaussian likelihood, on the
    relative standard deviation of each nonzero coefficient — Q, N, B, K in the input unit's base form,
    as :func:`fit` and :func:`~allanite.simulate` use them — that any unbiased estimator, from the Allan
    variance or otherwise, can reach. Use it to plan a logging campaign (how long until K is known to
    10 %?) and to judge a fit's intervals: ``fit``'s standard errors should not be far above it.

    The spectra are those of the sampled processes :func:`~allanite.simulate` makes (one-sided, rate
    samples, f_k = k·fs/n, k = 1 … n/2): Q: 8Q²sin²(πfτ0)/τ0; N: 2N²; B: B²/(πf); K:
    K²τ0²/(2sin²(πfτ0)). The Fisher information is I_pq = Σ_k ∂_pS·∂_qS/S² for θ = coefficient²,
    and the bound on a coefficient's relative SD is √(I⁻¹)_pp/(2θ_p). For a roughly normal estimate
    the median |relative error| is ≈ 0.674 times that. The rate ramp R is a deterministic trend, not a
    spectral term, and has no bound here.

    Returns a dict term → relative standard deviation (only the nonzero terms).

    Examples
    --------
    >>> import allanite
    >>> b = allanite.information_bound(1_000_000, 100.0, N=2e-3)   # white noise alone: 1/√(2n)
    >>> round(b["N"] * (2 * 1_000_000) ** 0.5, 6)
    1.0
    >>> b = allanite.information_bound(1_000_000, 100.0, Q=3.5e-4, N=2e-3, B=1e-3, K=6e-5)
    >>> round(100 * 0.674 * b["K"], 1)   # median |error| of K no unbiased estimator beats: 16 %
    16.4
    """
    n = int(check_count(n, "n", 4))
    tau0 = 1.0 / check_positive(fs, "fs")
    given = {"Q": Q, "N": N, "B": B, "K": K}
    terms = []
    theta = []
    for name, v in given.items():
        v = check_nonnegative(v, name)
        if v > 0:
            terms.append(name)
            theta.append(v * v)
    if not terms:
        raise ParameterError("information_bound needs at least one nonzero coefficient among Q, N, B, K")
    theta_arr = np.array(theta)
    info = np.zeros((len(terms), len(terms)))
    n_freq = n // 2
    chunk = 1 << 20
    for start in range(1, n_freq + 1, chunk):
        k = np.arange(start, min(n_freq, start + chunk - 1) + 1, dtype=np.float64)
        f = k * (fs / n)
        s2 = np.sin(np.pi * f * tau0) ** 2
        cols = {"Q": 8.0 * s2 / tau0, "N": np.full_like(f, 2.0), "B": 1.0 / (np.pi * f), "K": tau0 * tau0 / (2.0 * s2)}
        d = np.array([cols[t] for t in terms])
        spec = theta_arr @ d
        dw = d / spec
        info += dw @ dw.T
    cov = np.linalg.inv(info)
    return {t: float(math.sqrt(cov[i, i]) / (2.0 * theta_arr[i])) for i, t in enumerate(terms)}
