"""What a weighted fit of the Allan curve says of the noise terms: their squared coefficients (a bandwidth's N
in place of the N column's, :func:`theta_terms`), the slow terms raised to the upper end of what the curve
allows (:func:`upper_theta`, a time-domain test's null model), and the :class:`~allanite.model.NoiseFit` a
solution becomes, with the effects' amplitudes among its coefficients (:func:`noise_fit`). Below
:mod:`.curvefit`, which re-exports these names."""

from __future__ import annotations

import math

import numpy as np
from scipy.stats import chi2 as chi2_dist

from .. import fitting
from ..effects import EFFECTS, shaped_q_factor
from ._columns import base_name, design, held_theta

__all__ = ["upper_theta", "upper_models", "theta_terms", "effect_column_name", "noise_fit"]


def _upper_ends(curve, sol, terms, effects, slow, delta_chi2):
    """For each slow term of ``slow`` in ``terms``: (its index, its upper end v, the other columns' coefficients
    refitted at v — None where no v is allowed). The upper end is the largest v on a log grid below what alone
    would explain a point, with the others refitted (weighted NNLS, the fit's weights), whose χ² rises by at most
    ``delta_chi2`` (in effective points: the dense curve's points are strongly correlated, so the rise allowed
    on its χ² is scaled by points / n_eff, as the fit's covariance counts them). A held effect's column (a
    line measured in the time domain) stays at its coefficient and is left out of the columns returned."""
    a, _ = design(curve, terms, effects)
    w = np.sqrt(sol.nu / (2.0 * sol.model**2))
    held = [len(terms) + j for j, (key, _p) in enumerate(effects) if held_theta(key) is not None]
    y = curve.avar - a[:, held] @ sol.theta[held] if held else curve.avar
    a = np.delete(a, held, axis=1) if held else a
    aw, yw = a * w[:, None], y * w
    chi_min = float(np.sum((yw - aw @ fitting.nnls(aw, yw)) ** 2))
    delta_chi2 = delta_chi2 * curve.tau.size / curve.n_eff
    out = []
    for name in slow:
        if name not in terms:
            continue
        j = list(terms).index(name)
        col = aw[:, j]
        others = np.delete(aw, j, axis=1)
        top = float(np.min(curve.avar / np.maximum(a[:, j], 1e-300)))  # alone it would explain a point
        best: tuple[float, np.ndarray | None] = (0.0, None)
        for v in top * np.geomspace(1e-4, 1.0, 41):
            r = yw - v * col
            c = fitting.nnls(others, r)
            if float(np.sum((r - others @ c) ** 2)) - chi_min <= delta_chi2:
                best = (float(v), c)
        out.append((j, best[0], best[1]))
    return out


def upper_theta(curve, sol, terms, effects, theta, slow=("B", "K"), delta_chi2=4.0):
    """``theta`` with each slow term (flicker, random walk of rate) raised to the upper end of what the curve
    allows: the largest value with the others refitted (weighted NNLS, the fit's weights) whose χ² rises by
    at most ``delta_chi2`` (≈ 2σ; in effective points). A null model for a time-domain test must not leave
    out a random walk the curve merely could not pin down: one that is there makes warm-up-like wander in the
    block means. Every slow term is raised at once (a corner the curve need not allow together: see
    :func:`upper_models` for the models it does allow)."""
    out = theta.copy()
    for j, v, _c in _upper_ends(curve, sol, terms, effects, slow, delta_chi2):
        out[j] = max(out[j], v)
    return out


def upper_models(curve, sol, terms, effects, theta, slow=("B", "K"), delta_chi2=4.0):
    """The profile of the slow terms' upper ends: for each slow term in ``terms``, the terms' squared
    coefficients with that term at its upper end (as :func:`upper_theta`) and the *others refitted there* — a
    model the curve allows (χ² within ``delta_chi2`` effective points of its minimum), where
    :func:`upper_theta` raises every slow term at once. ``theta`` (the fit's) is the model where no slow term
    is in ``terms``. A test whose threshold rises with each slow term holds its level at the largest
    threshold over these models, as at any one of them."""
    k = len(terms)
    held = {k + j for j, (key, _p) in enumerate(effects) if held_theta(key) is not None}
    free = [i for i in range(sol.theta.size) if i not in held]
    out = []
    for j, v, c in _upper_ends(curve, sol, terms, effects, slow, delta_chi2):
        if c is None:
            continue
        full = np.asarray(sol.theta, dtype=np.float64).copy()
        full[free] = np.insert(c, j, v)
        out.append(_terms_of(full, terms, effects))
    return out or [np.asarray(theta, dtype=np.float64)[:k].copy()]


def theta_terms(sol, terms, effects):
    """Squared coefficients of the terms (a bandwidth's N — the white noise before its filter — in place of the N
    column's: zeroed, or where :func:`has_floor` keeps it the floor after the filter, the bandwidth's ``floor``)."""
    return _terms_of(sol.theta, terms, effects)


def _terms_of(coef, terms, effects):
    """:func:`theta_terms` of the solution's coefficient vector ``coef`` (terms, then one per effect)."""
    k = len(terms)
    theta = np.array(coef[:k], dtype=np.float64)
    for j, (key, p) in enumerate(effects):
        rep = EFFECTS[base_name(key)].replaces
        if rep in ("N", "Q") and rep in terms:
            theta[list(terms).index(rep)] = coef[k + j] * _replaced_scale(key, p)
    return theta


def _replaced_scale(key, p) -> float:
    """The replaced term's squared coefficient per unit of the effect's: 1 for a bandwidth (its N is the white
    noise before the filter), C(2k − 2, k − 1) for shaped quantisation of order k (the white angle noise its
    curve shows from m = k on: :func:`allanite.model.effects.shaped_q_factor`)."""
    return shaped_q_factor(p) if base_name(key) == "shaped_quantisation" else 1.0


def _coefficients(sol, terms, effects, unit, zq, inflate) -> tuple[dict, np.ndarray, np.ndarray]:
    """The terms' coefficients (a bandwidth's N reported as N) and each effect's amplitude, with intervals."""
    k = len(terms)
    theta = sol.theta[:k].copy()
    cov = sol.cov[:k, :k].copy()
    # a bandwidth carries the white rate noise N (before the filter): report it as N; shaped quantisation the white
    # angle noise its curve shows from m = k on: report that as Q
    for j, (key, p) in enumerate(effects):
        rep = EFFECTS[base_name(key)].replaces
        if rep in ("N", "Q") and rep in terms:
            i_n, scale = list(terms).index(rep), _replaced_scale(key, p)
            theta[i_n] = sol.theta[k + j] * scale
            cov[i_n, :] = cov[:, i_n] = np.nan
            cov[i_n, i_n] = sol.cov[k + j, k + j] * scale**2
    coeffs = fitting.coefficients(terms, theta, cov, zq, inflate, unit)
    for j, (key, _param) in enumerate(effects):
        i = k + j
        name = effect_column_name(key, j, effects)
        # a column's amplitude is in the rate unit (σ, A), but a bandwidth's is the white noise N before the
        # filter: N's unit (rate unit·√s), not the rate unit; shaped quantisation's q is in Q's unit
        rep = EFFECTS[base_name(key)].replaces
        coeffs[name] = fitting.Coefficient(
            name=name,
            value=float(math.sqrt(max(sol.theta[i], 0.0))),
            ci=fitting.interval(sol.theta[i], sol.cov[i, i], zq, inflate),
            unit=coeffs[rep].unit if rep in ("N", "Q") and rep in coeffs else unit,
        )
    return coeffs, theta, cov


def effect_column_name(key, j, effects) -> str:
    """The name of effect ``j``'s column among a fit's coefficients and components (numbered when the same
    effect is in the model more than once)."""
    name = base_name(key) if base_name(key) != "regression" else key.replace(":", "_")
    return f"{name}{j + 1}" if sum(base_name(e[0]) == base_name(key) for e in effects) > 1 else name


def noise_fit(curve, terms, effects, sol, result, unit, confidence, removed=None):
    """A NoiseFit for the solution, with the effects' parameters among the coefficients.

    ``removed``: (change, numbers, [(name, own change)]) when components were removed from the samples before
    ``sol`` was fitted: ``curve`` is then the original record's, the model ``sol``'s plus ``change`` (what the
    removals changed in the Allan curve, AVAR(y) − AVAR(y − components)), its χ² on ``curve`` with the
    removals' fitted ``numbers`` off the degrees of freedom, and each removal's own change one of the
    components."""
    zq = fitting.z_quantile(confidence)
    k = len(terms)
    inflate = max(1.0, math.sqrt(sol.chi2_dof))
    coeffs, theta, cov = _coefficients(sol, terms, effects, unit, zq, inflate)
    comps = {t: sol.a[:, i] * sol.theta[i] for i, t in enumerate(terms)}
    for j, (key, _param) in enumerate(effects):
        comps[effect_column_name(key, j, effects)] = sol.a[:, k + j] * sol.theta[k + j]
    model, z, chi2, dof = sol.model, sol.z, sol.chi2, sol.dof
    if removed is not None:
        change, numbers, own = removed
        comps.update(own)
        model = np.maximum(sol.model + change, 1e-300)
        z = (curve.avar - model) * np.sqrt(sol.nu / (2.0 * model**2))
        chi2, dof = float(np.sum(z**2)), max(1, sol.dof - numbers)
    readoffs = fitting.readoffs(result, np.sqrt(np.atleast_2d(result.avar)[0]))
    return fitting.NoiseFit(
        coefficients=coeffs,
        terms=terms,
        tau=curve.tau,
        m=curve.m,
        avar=curve.avar,
        edf=sol.nu,
        model=model,
        components=comps,
        z=z,
        chi2=chi2,
        dof=dof,
        chi2_dof=chi2 / max(1, dof),
        p_value=float(chi2_dist.sf(chi2, dof)),
        readoffs=readoffs,
        fs=curve.fs,
        confidence=confidence,
        unit=unit,
        iterations=0,
        theta=theta,
        covariance=cov,
    )
