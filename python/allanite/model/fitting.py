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

Here: :func:`fit`, the fit of a static curve and ``tau_range="auto"``. Its parts, each a module of its own (their
public names are importable from here too): the one-curve solver (``_fitcore``; run in the Rust core by ``_corefit``,
``fit_core``'s iteration step for step), which τ enter a fit
(``_tauselect``), what a fit returns (``_fitresult``: :class:`NoiseFit`, :class:`CoefficientSeries`), the windows
of a dynamic result (``_dynamicfit``) and the Cramér–Rao bound (``_bound``: :func:`information_bound`).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .._dist import chi2_sf
from .._progress import show_progress
from .._validate import check_choice
from ..errors import ParameterError
from ..estimators import get as get_estimator
from ..estimators import names as estimator_names
from ..results import AllanResult, DynamicAllanResult
from ..units import check_sensor_unit
from ._bound import information_bound
from ._corefit import fit_curve
from ._dynamicfit import FLAT_FLOOR as FLAT_FLOOR
from ._dynamicfit import fit_dynamic
from ._fitcore import GLS_START_ITER as GLS_START_ITER
from ._fitcore import GLS_TOL as GLS_TOL
from ._fitcore import IRLS_RTOL as IRLS_RTOL
from ._fitcore import MAX_GLS_TAU, edf_per_tau, exact_covariance_applies, nnls
from ._fitcore import OCTAVE_CORRELATION as OCTAVE_CORRELATION
from ._fitresult import READOFF_MIN_EDF as READOFF_MIN_EDF
from ._fitresult import Coefficient, CoefficientSeries, NoiseFit, coefficients, interval, readoffs, z_quantile
from ._fitresult import coefficient_table as coefficient_table
from ._fitresult import intervals as intervals
from ._gapfit import GAPS, gap_row
from ._tauselect import check_tau_range, estimator_key, row_medians, select_taus
from .terms import TERMS, check_terms

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
    gaps: str = "error",
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
        coefficient its IEEE-952 value (``ieee``). A gyro's rate unit (an angle unit for increments), or an
        accelerometer's (``"m/s^2"``, ``"g"``, ``"mg"``, … — :data:`allanite.units.ACCEL_UNITS`): ``ieee`` is
        then in the accelerometer's report units (:func:`allanite.units.accel_report_unit`: N a velocity
        random walk in m/s/√h, B in µg, K an acceleration random walk in m/s/h^1.5), ``value`` in base form
        (that unit and seconds, as for a gyro).
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
    gaps : {"error", "skip"}
        A static result of a record with NaN-marked gaps (``avar(..., gaps="skip")``, ``result.missing`` > 0)
        is fitted from the terms its curve kept: each τ's EDF (and its covariance across τ) is the gapless
        record's scaled by the share of terms kept at that τ, ``n / n_full`` — the variance of an average of
        fewer terms, exact when the gaps are short against the stretches between them, optimistic when they are
        closer than 2τ, so τ that kept under 10 % of the terms are left out (``allanite.model._gapfit.MIN_SHARE``)
        — and ``notes`` states how many samples were missing and which τ were left out. A τ with no complete
        term (n = 0) is an error by default (``"error"``); ``"skip"`` leaves such τ out (said in ``notes``).

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
    a window); Ctrl-C stops it. A static curve is fitted by the same kernel (≈ 1 ms per curve with its
    Python around it; ``tau_range="auto"`` fits up to seven), the Python iteration only for what the
    kernel hands back.

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
        check_sensor_unit(unit)
    show_progress(progress)  # a wrong value fails before any work
    check_choice(gaps, "gaps", GAPS)
    if isinstance(result, DynamicAllanResult):
        _check_fit_estimator(result)
        if auto:
            return _fit_dynamic_auto(result, terms, unit, float(confidence), zq, thin, max_iter, progress)
        return fit_dynamic(result, terms, unit, float(confidence), zq, thin, max_iter, tau_range, progress)
    if not isinstance(result, AllanResult):
        raise ParameterError(f"fit needs an AllanResult or DynamicAllanResult, got {type(result).__name__}")
    _check_fit_estimator(result)
    one = _fit_static_auto if auto else _fit_static_row
    args = (terms, unit, float(confidence), zq, thin, max_iter) + (() if auto else (tau_range,))

    def one_row(row, axis):
        sub, row, share, notes = gap_row(result, np.asarray(row, dtype=np.float64), axis, gaps)
        f = one(sub, row, *args, share=share)
        return dataclasses.replace(f, notes=notes + f.notes) if notes else f

    if result.avar.ndim == 2:
        return [one_row(row, a) for a, row in enumerate(result.avar)]
    return one_row(result.avar, None)


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


def _fit_static_auto(result, avar_row, terms, unit, confidence, zq, thin, max_iter, share=None):
    avar_row = np.asarray(avar_row, dtype=np.float64)
    cuts, tau0 = _auto_cuts(result, avar_row, thin, len(terms))

    def fit_at(cut):
        f = _fit_static_row(result, avar_row, terms, unit, confidence, zq, thin, max_iter, (cut, np.inf), share)
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
        s = fit_dynamic(single, terms, unit, confidence, zq, thin, max_iter, (cut, np.inf), progress)
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


def _fit_static_row(result, avar_row, terms, unit, confidence, zq, thin, max_iter, tau_range, share=None):
    """One row's fit; ``share``: the share of terms kept per τ of a record with gaps (:mod:`._gapfit`)."""
    avar_row = np.asarray(avar_row, dtype=np.float64)
    idx = select_taus(result.tau, avar_row, thin, len(terms), "the result", tau_range)
    tau, m, y = result.tau[idx], result.m[idx].astype(np.float64), avar_row[idx]
    theta, cov, model, nu, z, it, a, chi2 = fit_curve(
        tau,
        m,
        y,
        result.fs,
        result.n_samples + 1,
        estimator_key(result, idx),
        terms,
        confidence,
        max_iter,
        share=None if share is None else share[idx],
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
