"""Non-negative least squares for the many small weighted fits of a noise model (a few hundred τ, a few columns).

A fit of an Allan curve reweights and solves again some thirty times, and :func:`allanite.refine` runs thousands
of such fits: on problems this small the argument checks of ``scipy.optimize.nnls`` cost as much as the solve.
:func:`nnls` calls the same Lawson–Hanson routine directly (bit-identical results, the same errors for
non-finite input and for too many iterations) when this SciPy exposes it with the expected signature, checked
once on a small problem against the public function; otherwise it calls the public one.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["nnls", "nnls_rows", "raw_solver"]

_SOLVER: list[Callable] = []


def _public(a: np.ndarray, b: np.ndarray, maxiter: int) -> np.ndarray:
    from scipy.optimize import nnls as scipy_nnls

    return scipy_nnls(a, b, maxiter=maxiter)[0]


def _pick() -> Callable:
    """The routine behind ``scipy.optimize.nnls`` (no checks: the caller's) if it is there and agrees with it on
    a small problem, else the public function."""
    try:
        from scipy.optimize._slsqplib import nnls as raw  # the routine scipy.optimize.nnls wraps
    except ImportError:
        return _public
    a = np.array([[1.0, 0.5], [0.2, 1.0], [0.3, 0.1]])
    b = np.array([1.0, -2.0, 0.5])
    try:
        x, _rnorm, info = raw(a, b, 100)
        ok = info != 3 and np.array_equal(np.asarray(x), _public(a, b, 100))
    except Exception:  # another signature in another SciPy: the public function
        return _public
    if not ok:
        return _public

    def direct(a: np.ndarray, b: np.ndarray, maxiter: int) -> np.ndarray:
        x, _rnorm, info = raw(a, b, maxiter)
        if info == 3:
            raise RuntimeError("Maximum number of iterations reached.")
        return np.asarray(x)

    return direct


def raw_solver() -> Callable:
    """``solver(a, b, maxiter) -> x``: the Lawson–Hanson NNLS of ``scipy.optimize.nnls`` (``a`` C-contiguous
    float64, ``a`` and ``b`` finite), without its wrapper where that is safe."""
    if not _SOLVER:
        _SOLVER.append(_pick())
    return _SOLVER[0]


def nnls_rows(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """NNLS of each ``a[g] @ x ≈ b[g]`` (``a`` G × n × k, ``b`` G × n), columns scaled to unit norm first
    (columns span many decades in τ: the scaling keeps each problem well conditioned). Returns G × k."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    if not (np.isfinite(a).all() and np.isfinite(b).all()):
        raise ValueError("array must not contain infs or NaNs")
    scale = np.sqrt(np.add.reduce(a * a, axis=1))  # np.linalg.norm(a[g], axis=0), bit for bit
    scale[scale == 0] = 1.0
    an = a / scale[:, None, :]
    solver, maxiter = raw_solver(), 50 * a.shape[2]
    return np.stack([solver(an[g], b[g], maxiter) for g in range(a.shape[0])]) / scale


def nnls(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Non-negative least squares of ``a @ x ≈ b``, with the columns scaled to unit norm first."""
    b = np.asarray(b)
    if b.ndim == 2 and b.shape[1] == 1:  # a column, as scipy.optimize.nnls takes it
        b = b.ravel()
    return nnls_rows(np.asarray(a)[None], b[None])[0]
