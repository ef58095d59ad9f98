"""One curve's noise-model fit, the solver behind :func:`allanite.model.fitting.fit`: generalized least squares
with the overlapping estimates' exact covariance across τ (:mod:`allanite.model._covariance`), or iteratively
reweighted least squares with independent weights and an octave-correlation sandwich (classic, Theo family);
non-negative throughout (:mod:`allanite.model._nnls`). ``docs/FORMULAS.md`` §9.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ParameterError
from ..estimators.confidence import edf_of
from . import _covariance, _nnls
from .terms import TERM_ALPHA, design_matrix

#: Correlation of overlapping Allan variance estimates one octave apart, by noise type, measured on
#: 150 simulated records of 2^18 samples (log-AVAR at octave τ): white angle 0.42, white rate 0.53,
#: flicker rate 0.68, random-walk rate 0.87 (ramp: taken as random walk). Two estimates a factor r
#: apart are given ρ^|log2 r|. Classic estimates are less correlated; the same values are used
#: for them (conservative).
OCTAVE_CORRELATION = {"Q": 0.42, "N": 0.53, "B": 0.68, "K": 0.87, "R": 0.87}


def _estimate_correlation(tau, parts, terms, estimator) -> np.ndarray:
    """Correlation matrix of the Allan variance estimates at ``tau`` under the model mixture."""
    share = parts / np.maximum(parts.sum(axis=1, keepdims=True), 1e-300)
    rho = np.array([OCTAVE_CORRELATION[t] for t in terms])
    rho_tau = np.clip(share @ rho, 0.0, 0.99)  # per-τ octave correlation of the mixture
    lt = np.log2(tau)
    dist = np.abs(lt[:, None] - lt[None, :])
    # geometric mean of the two ends' octave correlations, to the power of the octave distance
    base = np.sqrt(np.outer(rho_tau, rho_tau))
    return np.where(dist == 0, 1.0, base**dist)


def edf_per_tau(alpha: np.ndarray, m: np.ndarray, n_points: int, estimator) -> np.ndarray:
    """ν per τ for one noise type. ``estimator``: a registry name, or a tuple naming the estimator of
    every τ (Theo-family results: Greenhall's EDF for Allan τ, Howe's Theo1 EDF for Theo τ)."""
    est = estimator if isinstance(estimator, str) else np.asarray(estimator)
    return np.asarray(edf_of(est, np.asarray(alpha), np.asarray(m, dtype=np.int64), int(n_points)), dtype=np.float64)


def nnls(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Non-negative least squares of ``a @ x ≈ b``, with the columns scaled first (:func:`._nnls.nnls`)."""
    return _nnls.nnls(a, b)


def fit_core(tau, m, avar, fs, n_points, estimator, terms, confidence, max_iter=50, edf_cache=None, *, share=None):
    """Fit one curve. Returns theta, covariance, model, edf, z, iterations, design, χ².

    Overlapping estimates on integer m ≤ n/2 get the generalized least-squares fit with their exact
    model covariance across τ (:func:`_fit_gls`); other estimators (classic, Theo family) the
    independent-weights fit with the octave-correlation sandwich (:func:`_fit_irls`). ``share``: a record with
    gaps, each τ's share of the gapless record's terms (:func:`scale_for_gaps`)."""
    check_gls_size(estimator, m)
    # The fit is linear in the variance: fitted on estimates scaled by a power of two near their peak (exact),
    # so that variances of 1e-300 or 1e300 (samples in extreme units) neither underflow nor overflow in the
    # squares and products of the weights; θ, its covariance and the model are scaled back.
    peak = float(np.max(avar))
    scale = math.ldexp(1.0, math.frexp(peak)[1]) if peak > 0 and math.isfinite(peak) else 1.0
    y = np.asarray(avar, dtype=np.float64) / scale
    if exact_covariance_applies(tau, m, fs, n_points, estimator):
        # a few independent-weights passes are enough for a start (and its EDF for a bare ramp)
        n_start = min(max_iter, GLS_START_ITER)
        start = _fit_irls(tau, m, y, fs, n_points, estimator, terms, confidence, n_start, edf_cache, share)
        out = _fit_gls(tau, m, y, fs, n_points, terms, start, max_iter, share)
    else:
        out = _fit_irls(tau, m, y, fs, n_points, estimator, terms, confidence, max_iter, edf_cache, share)
    theta, cov, model, nu, z, it, a, chi2 = out
    return theta * scale, cov * (scale * scale), model * scale, nu, z, it, a, chi2


def scale_for_gaps(share, nu_terms, blocks):
    """(EDF per τ and term, covariance blocks) of estimates that average only a ``share`` of a gapless record's
    terms (a record with gaps, :mod:`allanite.model._gapfit`): an average of fewer terms has its variance times
    1/share, so the EDF is scaled by the share and each covariance entry (i, j) by 1/√(share_i·share_j). ``share``
    None: both as they are."""
    if share is None:
        return nu_terms, blocks
    k = np.asarray(share, dtype=np.float64)
    nu_terms = nu_terms * k[:, None]
    if blocks is not None:
        w = 1.0 / np.sqrt(k)
        ww = np.outer(w, w)
        blocks = (blocks[0] * ww, blocks[1] * ww)
    return nu_terms, blocks


def check_gls_size(estimator, m) -> None:
    if isinstance(estimator, str) and estimator == "oavar" and m.size > MAX_GLS_TAU:
        raise ParameterError(
            f"{m.size} τ of an overlapping estimate would be fitted with their full covariance; at most "
            f"{MAX_GLS_TAU} are supported (the covariance costs ~n_τ² lag sums) — use thin=True, or a sparser "
            f"grid such as taus='exp'"
        )


def exact_covariance_applies(tau, m, fs, n_points, estimator) -> bool:
    return bool(
        isinstance(estimator, str)
        and estimator == "oavar"
        and np.allclose(tau * fs, m, rtol=1e-9)
        and np.all(m == np.round(m))
        and np.all(2 * m <= n_points - 1)
    )


#: The generalized least-squares iteration stops when no fitted value moves by more than this (relative).
GLS_TOL = 1e-7


#: The independent-weights iteration stops when no coefficient moves by more than this (relative) ...
IRLS_RTOL = 1e-7


#: ... and, as the start of the generalized least squares, after at most this many passes.
GLS_START_ITER = 8


#: At most this many τ are fitted with their full covariance (it costs ~n_τ² lag sums); more raise an
#: error with thin=False (the octave-thinned default never comes near it).
MAX_GLS_TAU = 160


def _chol(cov: np.ndarray) -> np.ndarray:
    """Cholesky factor of a model covariance, with a growing ridge if rounding made it indefinite."""
    d = np.sqrt(np.clip(np.diag(cov), 1e-300, None))
    corr = cov / np.outer(d, d)
    for ridge in (0.0, 1e-12, 1e-10, 1e-8, 1e-6, 1e-4):
        try:
            return np.linalg.cholesky(corr + ridge * np.eye(d.size)) * d[:, None]
        except np.linalg.LinAlgError:
            continue
    w, v = np.linalg.eigh(corr)
    return (v * np.sqrt(np.clip(w, 1e-4 * w.max(), None))) * d[:, None]


def _fit_gls(tau, m, avar, fs, n_points, terms, start, max_iter, share=None):
    """Generalized least squares with the estimates' exact covariance, iterated from the model.

    Σ(θ) = Cov(σ̂²(τ_i), σ̂²(τ_j)) under the fitted model (:mod:`allanite.model._covariance`: the
    overlapping estimator's second differences, each term's generalized covariance, summed over all
    lags), so correlated neighbours are neither overcounted nor thrown away. Each pass solves the
    non-negative least squares of the whitened problem L⁻¹Aθ ≈ L⁻¹σ̂² (Σ = LLᵀ) with Σ from the
    previous pass's coefficients — the quasi-likelihood estimating equation Aᵀ Σ⁻¹ (σ̂² − Aθ) = 0,
    which needs no independence and no thinning. Coefficient covariance: (AᵀΣ⁻¹A)⁻¹."""
    assemble, covariance_blocks = _covariance.assemble, _covariance.covariance_blocks

    theta0, _, _, nu0, _, _, a, _ = start
    s_blk, t_blk = scale_for_gaps(share, np.ones((m.size, 1)), covariance_blocks(m, int(n_points) - 1, fs, terms))[1]
    floor = 1e-12 * np.max(avar)

    def factor(theta):
        model = np.maximum(a @ theta, floor)
        cov = assemble(s_blk, t_blk, theta, terms)
        # a model without stochastic terms (a bare ramp) has no sampling variance: fall back to the
        # independent EDF variance there, so the problem stays well posed
        indep = 2.0 * model**2 / nu0
        bad = ~(np.diag(cov) > 1e-6 * indep)
        if bad.any():
            cov = cov + np.diag(np.where(bad, indep, 0.0))
        return _chol(cov), cov, model

    def step(theta):
        chol = factor(theta)[0]
        return nnls(np.linalg.solve(chol, a), np.linalg.solve(chol, avar))

    # convergence in model space: no τ's fitted value moves by more than GLS_TOL of itself (terms too
    # small to matter anywhere may still wander; they do not change the fit)
    def change(new, old):
        return float(np.max(np.abs(a @ (new - old)) / np.maximum(a @ new, floor)))

    theta = theta0.copy()
    if not theta.any():
        return start
    # The fixed-point map θ → step(θ) converges linearly, slowly where the model misfits (0.7–0.9 per
    # pass on real-sensor windows). SQUAREM (Varadhan & Roland 2008) extrapolates along the last two
    # steps: each cycle costs three passes and usually ends within a few cycles. Steps are measured in
    # model space (each θ_k scaled by its largest share of the curve) so no term dominates the norms.
    scale = np.max(a / np.maximum(avar, floor)[:, None], axis=0)
    theta, it = _squarem(step, change, theta, scale, max_iter)
    if not theta.any():
        return start
    return _gls_result(factor, theta, a, avar, len(terms), it)


def _squarem(step, change, theta, scale, max_iter):
    """The GLS passes θ → step(θ) from ``theta``, accelerated by SQUAREM, until ``change`` between passes is
    below GLS_TOL, θ is all zero or ``max_iter`` passes are spent; returns θ and the passes made. ``scale``
    puts each θ_k in model space for the extrapolation's norms."""
    it = 0
    while it < max_iter:
        t1 = step(theta)
        it += 1
        if not t1.any() or change(t1, theta) < GLS_TOL:
            theta = t1
            break
        t2 = step(t1)
        it += 1
        r = (t1 - theta) * scale
        v = (t2 - t1) * scale - r
        nv = float(np.linalg.norm(v))
        alpha = -1.0 if nv == 0.0 else min(-1.0, -float(np.linalg.norm(r)) / nv)
        jump = np.maximum(theta - 2.0 * alpha * (t1 - theta) + alpha**2 * (t2 - 2.0 * t1 + theta), 0.0)
        t3 = step(jump) if np.all(np.isfinite(jump)) and jump.any() else t2
        it += 1
        done = change(t3, t2) < GLS_TOL and change(t2, t1) < GLS_TOL
        theta = t3
        if done or not theta.any():
            break
    return theta, it


def _gls_result(factor, theta, a, avar, n_terms, it):
    """The fit at the converged ``theta``: theta, coefficient covariance (AᵀΣ⁻¹A)⁻¹ (an inactive term's
    variance as if it were freed alone), model, EDF, z, iterations, design, χ² under Σ(θ) from ``factor``."""
    chol, cov_y, model = factor(theta)
    aw = np.linalg.solve(chol, a)
    resid = np.linalg.solve(chol, avar - a @ theta)
    chi2 = float(resid @ resid)
    sd = np.sqrt(np.diag(cov_y))
    z = (avar - model) / sd
    nu = 2.0 * model**2 / sd**2  # equivalent degrees of freedom of each estimate under the model
    active = theta > 0
    cov = np.full((n_terms, n_terms), np.nan)
    idx = np.flatnonzero(active)
    cov[np.ix_(idx, idx)] = np.linalg.pinv(aw[:, idx].T @ aw[:, idx])
    for k in np.flatnonzero(~active):  # the variance each inactive term would have if freed alone
        j = np.append(idx, k)
        cov[k, k] = np.linalg.pinv(aw[:, j].T @ aw[:, j])[-1, -1]
    return theta, cov, model, nu, z, it, a, chi2


def _fit_irls(tau, m, avar, fs, n_points, estimator, terms, confidence, max_iter=50, edf_cache=None, share=None):
    """IRLS with independent weights for one curve. Returns theta, covariance, model, edf, z, iterations,
    design, χ².

    ``m`` are the estimator's averaging factors (for the EDF); the closed forms are evaluated at
    τ·fs, which is m for the Allan estimators and 0.75·m for Theo1-based points."""
    a = design_matrix(tau, tau * fs, fs, terms)
    nu_terms = _term_edfs(terms, m, n_points, estimator, {} if edf_cache is None else edf_cache)
    nu_terms = scale_for_gaps(share, nu_terms, None)[0]

    def edf_of(parts):
        # Mixture of independent noises: Var(σ̂²) ≈ Σ_k 2 s_k²/ν_k, so ν = (Σ s_k)² / Σ s_k²/ν_k —
        # continuous in the coefficients (an arg-max noise type would make the weights jump and the
        # iteration cycle between neighbouring solutions).
        tot = parts.sum(axis=1)
        den = np.sum(parts**2 / nu_terms, axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            nu = np.where(den > 0, tot**2 / den, nu_terms[:, 0])
        return nu

    # Start: weights from the estimates themselves, white-rate EDF.
    model = avar.copy()
    nu = nu_terms[:, terms.index("N")] if "N" in terms else nu_terms[:, 0]
    theta = np.zeros(len(terms))
    it = 0
    for it in range(1, max_iter + 1):
        w = nu / (2.0 * np.maximum(model, 1e-300) ** 2)
        sw = np.sqrt(w)
        new = nnls(a * sw[:, None], avar * sw)
        parts = a * new
        floor = 1e-12 * np.max(avar)
        new_model = np.maximum(parts.sum(axis=1), floor)
        done = np.allclose(new, theta, rtol=IRLS_RTOL, atol=0.0)
        # Damped reweighting: weights from the geometric mean of the last two models. Undamped,
        # a term on the edge of significance can flip in and out every other iteration.
        model = new_model if it == 1 else np.sqrt(model * new_model)
        theta = new
        if new.any():
            nu = edf_of(parts)
        if done:
            break
    model = np.maximum((a * theta).sum(axis=1), 1e-12 * np.max(avar))
    w = nu / (2.0 * model**2)
    z = (avar - model) * np.sqrt(w)
    cov = _sandwich_covariance(tau, a, theta, w, nu, model, terms, estimator)
    return theta, cov, model, nu, z, it, a, float(np.sum(z**2))


def _term_edfs(terms, m, n_points, estimator, cache: dict) -> np.ndarray:
    """(τ, term) EDF of each term's noise type at every τ (Greenhall), kept in ``cache`` across the windows
    of a dynamic fit."""
    nu_terms = []
    for t in terms:
        key = (TERM_ALPHA[t], tuple(m), n_points, estimator)
        if key not in cache:
            cache[key] = edf_per_tau(np.full(m.size, TERM_ALPHA[t]), m, n_points, estimator)
        nu_terms.append(cache[key])
    return np.column_stack(nu_terms)


def _sandwich_covariance(tau, a, theta, w, nu, model, terms, estimator) -> np.ndarray:
    """Covariance of the independent-weights fit's coefficients.

    The estimates have variances 2σ⁴/ν and are correlated across τ (overlapping estimates share data).
    The weighted fit treats them as independent, so its covariance is the sandwich
    (AᵀWA)⁻¹ AᵀW Σ W A (AᵀWA)⁻¹ with Σ = D R D — R from the octave correlations per noise type. An
    inactive term gets the variance it would have if freed alone with the active ones."""
    active = theta > 0
    cov = np.full((len(terms), len(terms)), np.nan)
    parts = a * theta
    corr = _estimate_correlation(tau, parts if theta.any() else a, terms, estimator)
    sd = np.sqrt(2.0 / nu) * model
    sigma = corr * np.outer(sd, sd)

    def sandwich(idx):
        aw = a[:, idx] * w[:, None]
        bread = np.linalg.pinv(aw.T @ a[:, idx])
        return bread @ (aw.T @ sigma @ aw) @ bread

    if active.any():
        idx = np.flatnonzero(active)
        cov[np.ix_(idx, idx)] = sandwich(idx)
    for k in np.flatnonzero(~active):
        idx = np.append(np.flatnonzero(active), k)
        cov[k, k] = sandwich(idx)[-1, -1]
    return cov
