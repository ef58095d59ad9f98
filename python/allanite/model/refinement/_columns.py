"""The Allan curve a refinement fits and the columns of its design: the keys of effect columns (an effect's base
name, a bandwidth's filter kind and its white floor after the filter, a held coefficient), :class:`Curve` (τ, m,
estimates, its EDF per noise type and everything computed on it remembered), each column of Allan variance per
unit amplitude² and its EDF per τ, and :func:`design`, the terms' and effects' columns together. Below
:mod:`.curvefit`, which fits them and re-exports these names."""

from __future__ import annotations

import math

import numpy as np

from .. import fitting
from .._counter import active_counter
from .._declared import declared_of
from .._quantiser import active_quantiser
from .._sharp import sharp_of
from ..effects import EFFECTS, butterworth_order, filtered_white_avar, resonance_avar, split_notch
from ..terms import TERM_ALPHA, design_matrix

__all__ = [
    "base_name",
    "has_floor",
    "bw_kind",
    "res_kind",
    "FLOOR_TAG",
    "held_key",
    "held_theta",
    "held_coherent",
    "column",
    "Curve",
    "design",
    "edf_columns",
    "edf_of",
    "term_columns",
]


def base_name(key: str) -> str:
    """The effect of a column key ("bandwidth:single_pole" → "bandwidth")."""
    return key.split(":", 1)[0]


#: The tail of a bandwidth key whose N column stays beside a kind other than a Butterworth: a white floor after
#: the filter that the samples' spectrum shows and the Allan curve's fit agrees with (:func:`._rolloff.floor_choice`).
FLOOR_TAG = "|floor"


#: The tag of a resonance key's band-pass shape ("resonance:bp:8"; the Lorentzian pair's key is "resonance:8").
BANDPASS_TAG = "bp"


def res_kind(key: str) -> tuple[float, str]:
    """A resonance key's quality factor and shape ("resonance:8" → (8.0, "lorentzian"), "resonance:bp:8" →
    (8.0, "bandpass"): :data:`allanite.model.effects.RESONANCE_SHAPES`)."""
    shape, _sep, q = key.split(":", 1)[1].rpartition(":")
    return float(q), "bandpass" if shape == BANDPASS_TAG else "lorentzian"


def bw_kind(key: str) -> str:
    """The filter kind of a bandwidth key ("bandwidth:boxcar|floor" → "boxcar")."""
    return key.split(":", 1)[1].removesuffix(FLOOR_TAG)


def held_key(effect: str, theta: float, var: float, coherent: float | None = None) -> str:
    """The key of ``effect`` held at coefficient ``theta`` (amplitude², measured in the time domain) with
    variance ``var`` in every fit of the curve; ``coherent``: the share of ``theta`` whose phase carries across
    the whole record (a fixed, deterministic line — :func:`held_coherent`), left out when not measured."""
    tail = "" if coherent is None else f":{coherent!r}"
    return f"{effect}:held:{theta!r}:{var!r}{tail}"


def held_theta(key: str) -> tuple[float, float] | None:
    """(coefficient, its variance) of a held effect's key (:func:`held_key`), else None."""
    parts = key.split(":")
    if len(parts) in (4, 5) and parts[1] == "held":
        return float(parts[2]), float(parts[3])
    return None


def held_coherent(key: str) -> float:
    """The coherent share of a held effect's key (:func:`held_key`) in [0, 1]: 0 where not measured (not held,
    or held without it) — the whole effect is then treated as noise by the tests' covariance."""
    parts = key.split(":")
    if len(parts) == 5 and parts[1] == "held":
        return min(1.0, max(0.0, float(parts[4])))
    return 0.0


def column(key, p, curve):
    """Allan variance per unit amplitude² of effect ``key`` with nonlinear parameter ``p`` on ``curve`` (read-only:
    remembered by the curve, which every step's searches ask for the same grids)."""
    got = curve.cached(("column", key, float(p)))
    if got is None:
        got = curve.remember(("column", key, float(p)), _column(key, p, curve))
    return got


def _column(key, p, curve):
    base = base_name(key)
    tau = curve.tau
    if base == "bandwidth":
        return filtered_white_avar(tau, bw_kind(key), p, curve.fs)
    if base == "resonance":
        q, shape = res_kind(key)
        return resonance_avar(tau, p, q, curve.fs, shape)
    sig = EFFECTS[base].signature
    assert sig is not None
    return sig(tau, p, curve.fs)


def _alpha_of(key, p, tau):
    """Noise type each effect resembles at τ, for the EDF of the estimates."""
    alpha = EFFECTS[base_name(key)].alpha
    if alpha is None:
        return np.zeros(tau.size, dtype=int)
    return alpha(tau, p)


#: EDF per τ by (α, averaging factors, record length, estimator): the last :data:`_EDF_KEPT` computed.
_EDF: dict = {}
_EDF_KEPT = 64


class Curve:
    """One Allan curve to fit: τ, m, estimates, record length, estimator (for the EDF)."""

    def __init__(self, tau, m, avar, fs, n_points, estimator):
        self.tau, self.m, self.avar = tau, m, avar
        self.fs, self.n_points, self.estimator = fs, n_points, estimator
        self._edf: dict = {}
        self._memo: dict = {}
        self.n_eff = max(2.0, math.log2(tau[-1] / tau[0]) + 1.0)

    def edf(self, alpha: int) -> np.ndarray:
        """EDF of each estimate for noise type ``alpha`` (computed once per α — and once per averaging factors,
        record length and estimator: the curve of the samples a removal left, or of its held-out parts, has
        the same EDF as the curve before it)."""
        if alpha not in self._edf:
            est = self.estimator if isinstance(self.estimator, str) else tuple(self.estimator)
            key = (int(alpha), self.m.tobytes(), int(self.n_points), est)
            got = _EDF.get(key)
            if got is None:
                got = fitting.edf_per_tau(np.full(self.m.size, alpha), self.m, self.n_points, self.estimator)
                got.flags.writeable = False
                while len(_EDF) >= _EDF_KEPT:  # the oldest out (another thread may be at it too)
                    try:
                        del _EDF[next(iter(_EDF))]
                    except (KeyError, RuntimeError, StopIteration):
                        break
                _EDF[key] = got
            self._edf[alpha] = got
        return self._edf[alpha]

    def subset(self, idx):
        """The curve at the τ indexed by ``idx`` (the same object for the same ``idx``: its columns are
        remembered)."""
        key = ("subset", np.asarray(idx).tobytes())
        got = self.cached(key)
        if got is None:
            est = self.estimator if isinstance(self.estimator, str) else tuple(np.asarray(self.estimator)[idx])
            got = self.remember(key, Curve(self.tau[idx], self.m[idx], self.avar[idx], self.fs, self.n_points, est))
        return got

    def cached(self, key):
        """What :meth:`remember` kept under ``key``, or None (the curve's τ and estimates never change)."""
        return self._memo.get(key)

    def remember(self, key, value):
        """Keep ``value`` (an array is made read-only) for this curve under ``key``; returns it."""
        if isinstance(value, np.ndarray):
            value.flags.writeable = False
        self._memo[key] = value
        return value


def design(curve, terms, effects):
    """Columns of the terms and the effects [(key, nonlinear parameter)] on ``curve``, and each column's
    noise type per τ (for the EDF)."""
    tau = curve.tau
    a0 = term_columns(curve, terms)
    zeroed = [EFFECTS[base_name(key)].replaces for key, _p in effects if not has_floor(key)]
    if any(rep in terms for rep in zeroed):
        a0 = a0.copy()
        for rep in zeroed:
            if rep in terms:
                a0[:, list(terms).index(rep)] = 0.0
    quant = active_quantiser()
    if quant is not None and "N" in terms and any(has_floor(key) for key, _p in effects):
        # the floor after the filter is the output quantiser's error: its exact Allan variance (its lag
        # correlation where the quantum is coarse beside the filtered rate's change per sample)
        a0 = a0.copy()
        a0[:, list(terms).index("N")] *= quant.factor(np.rint(tau * curve.fs))
    cols = [a0] + [column(key, p, curve)[:, None] for key, p in effects]
    alphas = [np.full(tau.size, TERM_ALPHA[t]) for t in terms] + [_alpha_of(k, p, tau) for k, p in effects]
    return np.hstack(cols), alphas


def has_floor(key: str) -> bool:
    """Whether the term a bandwidth ``key`` carries keeps its own column beside it — white noise added after the filter
    (a quantised output's floor; the bandwidth's ``floor``): beside a Butterworth, whose stop band the samples' spectrum
    shows and a floor is flat in (and a sharp kind, :mod:`allanite.model._sharp`), and beside any other kind whose key
    carries :data:`FLOOR_TAG` — only where the spectrum above the roll-off shows a floor and the fit's floor agrees with
    it (:func:`._rolloff.floor_choice`), and beside a declared filter (``refine(..., filter=...)``: its shape is fixed,
    so the floor trades with nothing but white angle noise). Untagged, beside a single pole or a boxcar the term is
    replaced: there a floor trades with the pole's cutoff, the boxcar's span and white angle noise on the Allan curve
    (ADIS16405 run 5 gyro_y's boxcar read 1.41 → 1.61 samples with a floor of 0 and white angle noise in its place, run
    1 gyro_z's single pole beside a second resonance at 24.5 Hz)."""
    if base_name(key) != "bandwidth":
        return False
    if declared_of(bw_kind(key)) is not None:  # a declared filter: its output's quantisation kept as a floor
        return True
    base = split_notch(bw_kind(key))[0]  # a notch after it too
    return key.endswith(FLOOR_TAG) or butterworth_order(base) > 0 or sharp_of(base) is not None


def term_columns(curve, terms):
    """The terms' columns on ``curve`` (read-only, remembered by the curve); inside
    :func:`allanite.model._counter.counter_quantisation` the Q column is the delta-angle counter's exact one
    (3/τ² × :func:`~allanite.model._counter.counter_factor`)."""
    counter = active_counter()
    key = ("terms", tuple(terms), None if counter is None else counter.key)
    got = curve.cached(key)
    if got is None:
        tau = curve.tau
        got = design_matrix(tau, tau * curve.fs, curve.fs, terms)
        if counter is not None and "Q" in terms:
            got[:, list(terms).index("Q")] *= counter.factor(np.rint(tau * curve.fs))
        got = curve.remember(key, got)
    return got


def edf_columns(curve, alphas):
    """Each column's EDF per τ under its noise type per τ (``alphas``, as :func:`design` gives them)."""
    return np.column_stack([_edf_column(curve, al) for al in alphas])


def _edf_column(curve, al):
    """EDF per τ of a column whose noise type per τ is ``al`` (remembered by the curve)."""
    al = np.asarray(al)
    key = ("edf", al.dtype.str, al.tobytes())
    got = curve.cached(key)
    if got is None:
        nu = np.where(
            al == -2,
            curve.edf(-2),
            np.where(al == -1, curve.edf(-1), np.where(al == 2, curve.edf(2), curve.edf(0))),
        )
        got = curve.remember(key, nu)
    return got


def edf_of(curve, key, p):
    """EDF per τ of effect ``key``'s column at parameter ``p`` (:func:`_edf_column` of its noise types per τ;
    remembered by the curve under the effect and parameter, as its column is)."""
    got = curve.cached(("edf_of", key, float(p)))
    if got is None:
        got = curve.remember(("edf_of", key, float(p)), _edf_column(curve, _alpha_of(key, p, curve.tau)))
    return got
