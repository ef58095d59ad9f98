"""The reweighted NNLS of an Allan curve's model, for one design or many at once.

:func:`allanite.refine` fits a curve thousands of times: per step, every grid point of every candidate's
nonlinear parameter, its refinement and its profile interval, each fit some thirty reweighting passes. The fits
of one grid differ in one column only; run together, the passes share their array work and only the small NNLS
solves stay one per design. Each design's arithmetic is the one it would get alone (element by element, the
same reductions in the same order), so the batch gives the same numbers bit for bit as fitting the designs one
at a time — ``tests/test_refine_cost.py`` checks it.

The Rust core runs the same loop (``allanite._core.irls_curves``: each design alone, the designs on its
threads, without the GIL) some ten times faster; :func:`irls` uses it when the core has it. Its NNLS is the
core's Lawson–Hanson routine, not SciPy's, so its numbers agree with this module's loop to rounding (a design
may stop a pass earlier or later where a coefficient's change sits at :data:`RTOL`): ``tests/test_refine_irls.py``
bounds the difference, ``benches/results/refine.json`` records refine's answers with it.
"""

from __future__ import annotations

import numpy as np

from ... import _core
from .._nnls import nnls_rows, raw_solver

__all__ = ["irls", "irls_python", "chi2_at", "COMPILED"]

#: Relative change of every coefficient below which the reweighting stops (np.allclose(rtol=1e-6, atol=0)).
RTOL = 1e-6
#: The Rust core's loop, or None where the core lacks it (then :func:`irls` is :func:`irls_python`).
COMPILED = getattr(_core, "irls_curves", None)


def irls(a: np.ndarray, nu_cols: np.ndarray, y: np.ndarray, nu0: np.ndarray, max_iter: int, floor: float, held=None):
    """:func:`irls_python` in the Rust core where it has it (the same loop; the numbers to rounding)."""
    compiled = COMPILED
    if compiled is None:
        return irls_python(a, nu_cols, y, nu0, max_iter, floor, held)
    k = a.shape[2]
    fixed = np.full(k, np.nan)
    for i, (th, _var) in (held or {}).items():
        fixed[i] = th
    f64 = np.float64
    return compiled(
        np.ascontiguousarray(a, dtype=f64),
        np.ascontiguousarray(nu_cols, dtype=f64),
        np.ascontiguousarray(y, dtype=f64),
        np.ascontiguousarray(nu0, dtype=f64),
        fixed,
        int(max_iter),
        float(floor),
        RTOL,
    )


def irls_python(
    a: np.ndarray, nu_cols: np.ndarray, y: np.ndarray, nu0: np.ndarray, max_iter: int, floor: float, held=None
):
    """Reweighted NNLS of the curve ``y`` (n τ) on each design ``a[g]`` (G × n × k): weights ν/(2·model²), the
    model damped geometrically between passes, ν per τ from the columns' shares of the model and their EDF
    ``nu_cols[g]`` (ν starts at ``nu0``); a design stops once no coefficient moved by more than :data:`RTOL`.
    ``held`` {column: (coefficient, variance)}: columns at a coefficient measured elsewhere (a spectral line's
    power), part of the model and of ν, not fitted (:func:`_irls_held`). Returns the coefficients (G × k) and
    the EDF per τ (G × n) each design stopped at."""
    g_n, n, k = a.shape
    if held:
        return _irls_held(a, nu_cols, y, nu0, max_iter, floor, held)
    if g_n == 1:
        theta1, nu1 = _irls_one(a[0], nu_cols[0], y, nu0, max_iter, floor)
        return theta1[None], nu1[None]
    theta = np.zeros((g_n, k))
    model = np.tile(np.asarray(y, dtype=np.float64), (g_n, 1))
    nu = np.tile(np.asarray(nu0, dtype=np.float64), (g_n, 1))
    live = np.arange(g_n)
    for it in range(max_iter):
        whole = live.size == g_n
        a_l, m_l, nu_l, th_l = (a, model, nu, theta) if whole else (a[live], model[live], nu[live], theta[live])
        sw = np.sqrt(nu_l / (2.0 * np.maximum(m_l, floor) ** 2))
        new = nnls_rows(a_l * sw[:, :, None], y * sw)
        parts = a_l * new[:, None, :]
        new_model = np.maximum(parts.sum(axis=2), floor)
        done = np.all(np.abs(new - th_l) <= RTOL * np.abs(th_l), axis=1)
        model[live] = new_model if it == 0 else np.sqrt(m_l * new_model)
        theta[live] = new
        moved = np.asarray(new.any(axis=1))
        if moved.any():
            upd = _combined_edf(parts, nu_cols if whole else nu_cols[live], parts.sum(axis=2), nu_l)
            nu[live] = np.where(moved[:, None], upd, nu_l)
        live = live[~done]
        if live.size == 0:
            break
    return theta, nu


def _irls_one(a: np.ndarray, nu_cols: np.ndarray, y: np.ndarray, nu: np.ndarray, max_iter: int, floor: float):
    """:func:`irls` of one design (n × k): the same arithmetic in fewer array operations."""
    y = np.asarray(y, dtype=np.float64)
    if not (np.isfinite(a).all() and np.isfinite(y).all()):
        raise ValueError("array must not contain infs or NaNs")
    solver, maxiter = raw_solver(), 50 * a.shape[1]
    theta = np.zeros(a.shape[1])
    model = y.copy()
    for it in range(max_iter):
        sw = np.sqrt(nu / (2.0 * np.maximum(model, floor) ** 2))
        if not np.isfinite(sw).all():
            raise ValueError("array must not contain infs or NaNs")
        aw = a * sw[:, None]
        scale = np.sqrt(np.add.reduce(aw * aw, axis=0))
        scale[scale == 0] = 1.0
        new = solver(aw / scale, y * sw, maxiter) / scale
        parts = a * new
        tot = parts.sum(axis=1)
        new_model = np.maximum(tot, floor)
        done = bool(np.all(np.abs(new - theta) <= RTOL * np.abs(theta)))
        model = new_model if it == 0 else np.sqrt(model * new_model)
        theta = new
        if new.any():
            nu = _combined_edf(parts, nu_cols, tot, nu)
        if done:
            break
    return theta, nu


def _irls_held(a, nu_cols, y, nu0, max_iter, floor, held):
    """:func:`irls` of designs (G × n × k) whose ``held`` columns stay at their coefficients: the others fitted
    to the curve less the held columns' part, the weights and ν from the whole model. The designs run together
    as in :func:`irls` (each one's arithmetic the one it would get alone: the same numbers bit for bit)."""
    g_n, _n, k = a.shape
    y = np.asarray(y, dtype=np.float64)
    fixed = np.zeros(k)
    for i, (th, _var) in held.items():
        fixed[i] = th
    free = np.ones(k, dtype=bool)
    free[list(held)] = False
    a_free = a[:, :, free]
    y_free = np.stack([y - a[g] @ fixed for g in range(g_n)])
    solver, maxiter = raw_solver(), 50 * int(free.sum())
    theta = np.tile(fixed, (g_n, 1))
    model = np.tile(y, (g_n, 1))
    nu = np.tile(np.asarray(nu0, dtype=np.float64), (g_n, 1))
    live = np.arange(g_n)
    for it in range(max_iter):
        rows = slice(None) if live.size == g_n else live  # the designs still reweighting
        m_l, nu_l, th_l = model[rows], nu[rows], theta[rows]
        sw = np.sqrt(nu_l / (2.0 * np.maximum(m_l, floor) ** 2))
        new = np.tile(fixed, (live.size, 1))
        if free.any():
            aw = a_free[rows] * sw[:, :, None]
            scale = np.sqrt(np.add.reduce(aw * aw, axis=1))
            scale[scale == 0] = 1.0
            an, b = aw / scale[:, None, :], y_free[rows] * sw
            new[:, free] = np.stack([solver(an[g], b[g], maxiter) for g in range(live.size)]) / scale
        parts = a[rows] * new[:, None, :]
        tot = parts.sum(axis=2)
        done = np.all(np.abs(new - th_l) <= RTOL * np.abs(th_l), axis=1)
        model[rows] = np.maximum(tot, floor) if it == 0 else np.sqrt(m_l * np.maximum(tot, floor))
        theta[rows] = new
        moved = np.asarray(new.any(axis=1))
        if moved.any():
            nu[rows] = np.where(moved[:, None], _combined_edf(parts, nu_cols[rows], tot, nu_l), nu_l)
        live = live[~done]
        if live.size == 0:
            break
    return theta, nu


def chi2_at(y: np.ndarray, a: np.ndarray, theta: np.ndarray, nu: np.ndarray, floor: float) -> float:
    """χ² of the normalised residuals of the model ``a @ theta`` (floored) with EDF ``nu``, as the solution's."""
    model = np.maximum(a @ theta, floor)
    w = nu / (2.0 * model**2)
    z = (y - model) * np.sqrt(w)
    return float(np.sum(z**2))


def _combined_edf(parts, nu_cols, tot, nu):
    """The model's EDF per τ from its terms' parts (last axis) and each term's EDF: tot² / Σ part²/ν_term
    (Satterthwaite), ``nu`` kept where no term contributes."""
    den = np.sum(parts**2 / nu_cols, axis=-1)
    return np.where(den > 0, tot**2 / np.maximum(den, 1e-300), nu)
