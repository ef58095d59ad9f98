"""Every window of a dynamic fit at once, in the Rust core.

:func:`allanite.fit` on a dynamic result fits the same model, on the same τ, with the same design matrix,
EDF and covariance blocks, to every window; only the estimates differ. :func:`fit_windows` hands the shared
parts and all the windows' estimates to ``allanite._core.fit_windows``, which runs the per-window fit of
:mod:`allanite.model._fitcore` (``fit_core``: the IRLS start, the GLS iteration with SQUAREM steps, the
coefficient covariance) step for step on the core's threads, without the GIL. A window whose fit takes a
branch only the Python path has (an indefinite covariance, a fit that ends at zero, an NNLS that does
not settle) comes back flagged; the caller refits it there.

Long calls run in pieces of :data:`PIECE` windows, with a ``tqdm.auto`` bar over them (``progress``, as
everywhere in the library); Ctrl-C stops a piece within ~50 ms.
"""

from __future__ import annotations

import math

import numpy as np

from .. import _core
from .._progress import StepBar

__all__ = ["PIECE", "fit_windows"]

#: Windows per core call (≈ 0.1 s): the bar moves between pieces.
PIECE = 16384


def fit_windows(
    avar,
    design,
    nu_terms,
    *,
    start_col,
    irls_iter,
    max_iter,
    gls_tol,
    irls_rtol,
    rho,
    log2_tau,
    blocks,
    stoch,
    ramp,
    progress=None,
    workers=0,
):
    """Fit every row of ``avar`` (windows × τ, finite, floored at 1e-300).

    ``design``, ``nu_terms``: (τ × terms); ``blocks``: the covariance blocks ``(S, T)`` of overlapping
    estimates (the GLS fit) or None (the independent-weights fit); ``stoch``/``ramp``: columns of the
    stochastic terms and of R. Returns ``(theta, cov, chi2, iterations, status)``: θ (windows × terms,
    squared coefficients), covariance (windows × terms × terms), χ², passes made, and 0 where the window
    was fitted or a non-zero code where the caller must refit it.
    """
    avar = np.ascontiguousarray(avar, dtype=np.float64)
    n_windows, k = avar.shape[0], design.shape[1]
    s_blk = t_blk = None
    if blocks is not None:
        s_blk = np.ascontiguousarray(blocks[0], dtype=np.float64).ravel()
        t_blk = np.ascontiguousarray(blocks[1], dtype=np.float64).ravel()
    args = (
        np.ascontiguousarray(design, dtype=np.float64),
        np.ascontiguousarray(nu_terms, dtype=np.float64),
        int(start_col),
        int(irls_iter),
        int(max_iter),
        float(gls_tol),
        float(irls_rtol),
        [float(v) for v in rho],
        [float(v) for v in log2_tau],
        s_blk,
        t_blk,
        [int(c) for c in stoch],
        None if ramp is None else int(ramp),
        int(workers),
    )
    pieces = max(1, math.ceil(n_windows / PIECE))
    if pieces == 1:  # no bar (a static curve's fit is one window: even a disabled bar costs as much as its fit)
        out = np.asarray(_core.fit_windows(avar, *args)).reshape(n_windows, k + k * k + 3)
    else:
        out = np.empty((n_windows, k + k * k + 3))
        with StepBar(progress, n_windows, "noise fit per window", unit="window") as bar:
            for p in range(pieces):
                lo, hi = p * PIECE, min(n_windows, (p + 1) * PIECE)
                out[lo:hi] = _core.fit_windows(avar[lo:hi], *args)
                bar.add(hi - lo)
    theta = out[:, :k]
    cov = out[:, k : k + k * k].reshape(n_windows, k, k)
    chi2, iterations, status = out[:, -3], out[:, -2].astype(np.int64), out[:, -1].astype(np.int64)
    return theta, cov, chi2, iterations, status
