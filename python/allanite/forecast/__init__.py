"""Forecasting a series of noise coefficients: grey GM(1,1), its improved form, and baselines.

Paper 004 (Li, Wang, Shen, Acta Optica Sinica 2020) fits the Allan noise terms frame by frame
(time-frame DAVAR) and forecasts each coefficient series with a grey GM(1,1) model: the first 60
frames build the model, the last 30 check it. This module gives

- :class:`GM11` — the traditional GM(1,1) (paper 004 eqs. 1–15);
- :class:`ImprovedGM11` — the paper's improvements, each one switchable: wavelet detection of breaks
  and bad values, wavelet smoothing, the metabolic (rolling) re-fit, the residual GM(1,1) correction
  (eqs. 16–18);
- baselines with the same interface: :class:`Persistence`, :class:`BuildMean`, :class:`LinearTrend`,
  :class:`Holt`;
- :func:`accuracy` (the posterior-variance ratio C, the small-error probability P and their grades) and
  :func:`score`, which judges a method on a build/check split against the **raw** held-out values,
  and also by paper 004's own rule, labelled.

Every model takes the series first and its options keyword-only, and exposes ``series``, ``fitted``
(the in-sample values x̂⁰), ``predict(h)``, ``accuracy`` and its fields ``C``, ``P``, ``c_grade``,
``grade``. Indices in this module are 0-based: ``series[0]`` is the paper's x⁰(1). The formulas and
conventions: ``docs/FORMULAS.md §11``.

Conventions (the literature is not uniform; each is a parameter):

``sd``
    ``"population"`` (divide by n, paper 004 eqs. 13–14) or ``"sample"`` (divide by n − 1).
    When S1 and S2 run over the same number of values, C does not depend on it; P can (its
    threshold is 0.6745·S1).
``include_first``
    Whether k = 1 (``series[0]``) counts in C and P. GM(1,1) reproduces x⁰(1) exactly, so counting
    it adds a zero residual. The textbook oracles (Liu & Lin's 2.874, 3.278, … example and the
    road-noise example) count it; paper 004 §3.2 step 3 leaves it out.

The package's modules: ``grades`` (C, P and their grades), ``grey`` (GM(1,1)), ``improved`` (the improved
GM(1,1)), ``baselines``, ``scoring`` (:func:`score`, :func:`compare`); every public name is importable
from ``allanite.forecast``.

Examples
--------
>>> from allanite.forecast import GM11, score, split
>>> build, check = split([1.0, 1.1, 1.25, 1.3, 1.45, 1.5, 1.62, 1.7, 1.85, 1.9], 7, 3)
>>> print(f"C = {score(GM11, build, check).honest.C:.3f}")
C = 0.466
"""

from .baselines import BuildMean, Holt, LinearTrend, Persistence
from .grades import C_GRADE_BOUNDS as C_GRADE_BOUNDS
from .grades import JOINT_GRADES as JOINT_GRADES
from .grades import Accuracy, accuracy, c_grade, joint_grade
from .grey import GM11, LevelRatio, level_ratio_test
from .improved import Detection, ImprovedGM11
from .scoring import Score, compare, default_methods, score, split

__all__ = [
    "GM11",
    "Accuracy",
    "BuildMean",
    "Detection",
    "Holt",
    "ImprovedGM11",
    "LevelRatio",
    "LinearTrend",
    "Persistence",
    "Score",
    "accuracy",
    "c_grade",
    "compare",
    "default_methods",
    "joint_grade",
    "level_ratio_test",
    "score",
    "split",
]
