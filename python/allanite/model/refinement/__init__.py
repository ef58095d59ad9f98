"""Close the loop: find what a fitted noise model lacks, add that effect, report the error before and after.

:func:`refine` fits the starting IEEE-952 model (weighted least squares in variance space, as
:func:`allanite.fit`), then traces what it leaves in more than one domain and tries each candidate effect
of the registry :data:`allanite.model.effects.EFFECTS`:

- on the **Allan curve**, by signature (closed forms, ``docs/FORMULAS.md`` §5): ``"bandwidth"`` — the
  sensor's low-pass on its white rate noise (single pole, moving-average or Bartlett FIR, a boxcar of
  any span, a single pole after a short boxcar, or a Butterworth of order 2 to 6), exact in discrete time,
  replacing the N column; ``"gauss_markov"`` — a bump, T_c in [5·τ_min, τ_max/4]; ``"resonance"`` —
  narrowband noise, a PSD hump at f_r with quality factor Q (near the shortest τ, tried after the bandwidth);
  and, for curve-only input, ``"sinusoid"`` (nulls at τ = k/f0, f0 ≥ 2/τ_max);
- in the **PSD** (Welch) for spectral lines: a lone line is a ``"sinusoid"`` (f0 refined on the samples, its
  amplitude the line's power, held in every fit of the curve); a family of lines (harmonics, sidebands) is
  ``"periodic"``, removed in time, and so is a lone line whose frequency wanders (one line, its phase tracked);
- in **time**: ``"outliers"`` (impulsive samples, replaced), ``"drift"`` (warm-up a·e^{−t/T} on block means)
  and ``"change_point"`` (steps of the noise level along the record);
- in **other channels** of the log (``channels=``): ``"regression"`` — the rate regressed on each, band by
  band (octaves) where the coupling differs across frequency (:func:`allanite.model.tracing.band_regression`);
  a slow channel (a temperature) by a Whittle GLS against the record's own noise
  (:mod:`allanite.model.channels`).

Every curve effect enters the model as a non-negative column of Allan variance; the time-domain ones
(outliers, drift, regression, line families) are removed from the samples, and the model adds back what the
removal changed in the curve, AVAR(y) − AVAR(y − component) (own variance and cross terms, exactly). Every step
is scored on the record's own Allan curve along one chain — each step's before is the previous step's after,
the last after the final model's (curve effects first, then the removals in time with every curve effect in the
model, then change points). A candidate is **accepted** only if

1. a calibrated test says the residual asks for it: the GLS score statistic on ~4 τ per octave with the
   covariance of the estimates across τ (exact for the five terms, :mod:`allanite.model._covariance`),
   above the (1 − α) quantile of its maximum over all candidate families under the fitted model
   (parametric bootstrap, :class:`allanite.model.tracing.ScoreTest`); spectral lines by their own
   F test on the Welch PSD (Bonferroni over the bins); each removal in time by its own test; α splits the
   per-record ``level`` (:mod:`allanite.model.refinement.levels`);
2. its parameter is not pinned at the edge of its search range and its amplitude is positive;
3. χ²/dof of the dense curve falls; and
4. the **held-out** error falls: the record is cut into 8 blocks, the odd and the even ones joined end to end;
   the model with and without the effect is fitted on one part's Allan curve and predicts the other's (both
   ways, RMS ADEV error averaged, on the τ whose estimate is within ±10 %). A drift or regression is refitted
   on the held-in part's samples; change points are held out per segment (each segment's own alternate
   blocks, predicted by the segment's model vs the one-level model). Curve-only input has no held-out error
   (reported as None) and relies on the calibrated test.

RMS ADEV errors (in-sample and held out) are scored on 4 τ per octave whose estimate is informative (EDF ≥ 50
under the five-term fit: ±10 %); beyond, the estimate's own scatter, not the model, would decide the score.

Nonlinear parameters (T_c, cutoff, f0 on curves) are found by a grid search with the linear coefficients
by weighted NNLS at each grid point, then refined by a bounded scalar search; their intervals come from the
profile of χ² (Δχ²_eff = 1). The loop stops when no candidate is accepted or after ``MAX_STEPS`` curve effects (removals
in time, change points and spectral lines held at their measured power do not count).

After the last step every domain's calibrated check runs once more against the final model, each at its own
share of ``level``: what a check still finds is said in ``Refinement.unexplained``, not added
(:mod:`allanite.model.refinement.missing`).
"""

from ..effects import gm_avar, sinusoid_avar
from .result import Refinement, Step

#: Names whose modules load SciPy's signal, stats and optimize (the loop, its levels): on first use, so that
#: what only shows a refinement (the report's summary, :mod:`.result`) does not pay for them.
_LAZY = {"refine": "loop", "CANDIDATES": "loop", "LEVEL": "levels"}


def __getattr__(name: str):
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = ["refine", "Refinement", "Step", "gm_avar", "sinusoid_avar", "CANDIDATES", "LEVEL"]
