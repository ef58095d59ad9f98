"""One registry of estimators, and one of window tapers.

Every estimator is one :class:`Estimator` entry: its name, what it computes, how its values relate
to the Allan variance, its equivalent degrees of freedom, and the functions that compute it for a
whole record (``static``) and for every sliding window (``dynamic``). The public entry points
(:func:`allanite.avar`, :func:`allanite.davar`), the confidence intervals, the noise-model fit and
the report all ask this table — so a new estimator is one new entry in the module of its family,
not edits in every module that names estimators.

A taper weights the terms inside a window (paper 002); :data:`TAPERS` says which estimators each
one applies to, so an invalid estimator × taper pair is refused in one place.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import ParameterError

__all__ = ["Computed", "Estimator", "Taper", "register", "get", "names", "register_taper", "get_taper", "TAPERS"]


@dataclass(frozen=True)
class Computed:
    """What an estimator's ``static`` or ``dynamic`` function returns: plain arrays.

    ``values`` is (axes, T) for a whole record, (axes, T, J) for J windows; ``tau``, ``n`` and ``m``
    are (T,); ``source`` (T,) names the estimator behind each τ for hybrid estimators (TheoH), and
    ``kf`` holds TheoBR's bias ratio, (axes,) or (axes, J); ``ranges`` (axes, T, 3), when the core noted
    them, each (axis, τ) row's largest and smallest value and 1.0 where one is not finite.
    """

    tau: np.ndarray
    values: np.ndarray
    n: np.ndarray
    m: np.ndarray
    source: np.ndarray | None = None
    kf: np.ndarray | None = None
    ranges: np.ndarray | None = None


@dataclass(frozen=True)
class Estimator:
    """One estimator of the Allan-variance family.

    Attributes
    ----------
    name : str
        The name users pass (``estimator="oavar"``).
    label : str
        What it is, in words (report titles, reprs).
    family : str
        ``"allan"``, ``"theo"``, … — estimators of one family share a module.
    static : callable, optional
        ``static(cols, fs, taus, workers, **options) -> Computed`` for whole records.
    dynamic : callable, optional
        ``dynamic(cols, fs, window, hop, taus, method, workers, **options) -> Computed`` for every
        window of ``window`` samples, ``hop`` apart.
    edf : callable, optional
        ``edf(alpha, m, n_phase) -> ν`` (arrays broadcast together): equivalent degrees of freedom of
        one estimate for noise type α; None where the estimator has no EDF model (raw Theo1).
    estimates_allan : bool
        Its values estimate the Allan variance itself (the noise-model fit accepts them).
    theo_tau : bool
        Its values belong to τ = 0.75·m/fs (Theo1's convention) rather than m/fs.
    options : mapping
        Extra keyword options the entry accepts, with their defaults (``kf_rule``, ``decimate``).
    methods : tuple of str
        ``method=`` values its dynamic form offers.
    noise_id : str
        The estimator whose term count (``b1_n="terms"``) and minimum of τ-intervals (``fallback``)
        the noise identification uses.
    resolve_m : callable, optional
        ``resolve_m(taus, n, fs) -> m`` — the averaging factors ``taus`` give on ``n`` samples, checked,
        before anything is computed (to size the output against the memory budget).
    unit_power : int
        Its values scale as the samples to this power (2 for variances): samples scaled by c give
        values scaled by c**unit_power.
    """

    name: str
    label: str
    family: str
    static: Callable[..., Computed] | None = None
    dynamic: Callable[..., Computed] | None = None
    edf: Callable[..., Any] | None = None
    estimates_allan: bool = True
    theo_tau: bool = False
    options: Mapping[str, Any] = field(default_factory=dict)
    methods: tuple[str, ...] = ("fast",)
    noise_id: str = "oavar"
    resolve_m: Callable[..., np.ndarray] | None = None
    unit_power: int = 2

    def check_options(self, given: Mapping[str, Any]) -> dict[str, Any]:
        """The options this estimator takes, from ``given`` (name → value as passed). A value other
        than the public default for an option the estimator does not take is refused, naming the
        estimators that do take it."""
        out = {}
        for key, value in given.items():
            if key in self.options:
                out[key] = value
            elif not _is_default(value, key):
                takers = [e.name for e in _ESTIMATORS.values() if key in e.options]
                raise ParameterError(f"{key} applies to the estimators {tuple(takers)}, not to estimator={self.name!r}")
        return out


#: The public default of each option: passing it to an estimator that does not take it is harmless.
_OPTION_DEFAULTS: dict[str, tuple[Any, ...]] = {"kf_rule": ("textbook",), "decimate": ("auto", 1, None)}


def _is_default(value: Any, key: str) -> bool:
    return any(value is d or (type(value) is type(d) and value == d) for d in _OPTION_DEFAULTS.get(key, ()))


_ESTIMATORS: dict[str, Estimator] = {}


def register(entry: Estimator) -> Estimator:
    """Add an estimator to the registry (once per name)."""
    if entry.name in _ESTIMATORS:
        raise ValueError(f"estimator {entry.name!r} is registered twice")
    _ESTIMATORS[entry.name] = entry
    for key in entry.options:
        _OPTION_DEFAULTS.setdefault(key, (entry.options[key],))
    return entry


def names(kind: str | None = None) -> tuple[str, ...]:
    """Registered estimator names, in registration order; ``kind="static"`` or ``"dynamic"`` keeps
    those with that form."""
    return tuple(n for n, e in _ESTIMATORS.items() if kind is None or getattr(e, kind) is not None)


def get(name: object, kind: str | None = None) -> Estimator:
    """The entry called ``name``; with ``kind``, one that has that form — else a ParameterError that
    lists the allowed names."""
    allowed = names(kind)
    if not isinstance(name, str) or name not in allowed:
        raise ParameterError(f"unknown estimator {name!r}; allowed: {', '.join(map(repr, allowed))}")
    return _ESTIMATORS[name]


@dataclass(frozen=True)
class Taper:
    """A window weighting of the terms inside each window.

    ``estimators``: the estimators it applies to (None: every one). ``static`` / ``dynamic``: the
    functions that compute the tapered estimator, with the signatures of :class:`Estimator`'s (no
    options); None for ``"rect"``, which is the estimator's own computation. ``edf_factor(m, window)``:
    the share of the untapered estimator's EDF a tapered estimate keeps (None: no EDF model).
    ``methods``: the ``method=`` values the dynamic form offers.
    """

    name: str
    label: str
    estimators: tuple[str, ...] | None = None
    static: Callable[..., Computed] | None = None
    dynamic: Callable[..., Computed] | None = None
    edf_factor: Callable[..., Any] | None = None
    methods: tuple[str, ...] = ("fast", "naive")


TAPERS: dict[str, Taper] = {}


def register_taper(entry: Taper) -> Taper:
    """Add a taper to the registry."""
    TAPERS[entry.name] = entry
    return entry


def get_taper(name: object, estimator: str) -> Taper:
    """The taper called ``name``, checked to apply to ``estimator``; otherwise a ParameterError that
    names the valid estimator × taper pairs."""
    if not isinstance(name, str) or name not in TAPERS:
        raise ParameterError(f"unknown taper {name!r}; allowed: {', '.join(map(repr, TAPERS))}")
    taper = TAPERS[name]
    if taper.estimators is not None and estimator not in taper.estimators:
        pairs = "; ".join(
            f"{t.name!r} with {'any estimator' if t.estimators is None else ', '.join(map(repr, t.estimators))}"
            for t in TAPERS.values()
        )
        raise ParameterError(f"taper {name!r} does not apply to estimator {estimator!r}; valid pairs: {pairs}")
    return taper


register_taper(Taper("rect", "rectangular (every term weighted equally)", edf_factor=lambda m, window: 1.0))
