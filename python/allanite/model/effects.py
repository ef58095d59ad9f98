"""Effects the five-term noise model lacks — one registry entry each.

An effect is what :func:`allanite.refine` may add to a fitted model when the residual asks for it:
its parameters with their units, and how it is found — by its Allan-variance signature on the curve
(``kind="curve"``: an amplitude fitted linearly, one nonlinear parameter searched on a grid), or in
the samples along time (``kind="time"``: change points). Adding an effect is one entry here.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

__all__ = ["Effect", "EFFECTS", "gm_avar", "sinusoid_avar", "describe"]


def gm_avar(tau: np.ndarray | float, tc: float) -> np.ndarray:
    """Allan variance of a first-order Gauss–Markov rate of unit variance and correlation time ``tc``:
    (T_c/τ)²·(2τ/T_c − 3 + 4e^{−τ/T_c} − e^{−2τ/T_c}) (IEEE Std 952 App. C)."""
    tau = np.asarray(tau, dtype=np.float64)
    x = tau / tc
    big = (2 * x - 3 + 4 * np.exp(-x) - np.exp(-2 * x)) / np.maximum(x, 1e-300) ** 2
    small = (2.0 / 3.0) * x - 0.5 * x * x + (7.0 / 30.0) * x**3  # series: no cancellation for x ≪ 1
    return np.where(x < 1e-2, small, big)


def sinusoid_avar(tau: np.ndarray | float, f0: float) -> np.ndarray:
    """Allan variance of a unit-amplitude rate sinusoid of frequency ``f0``: sin⁴(πf0τ)/(πf0τ)²."""
    u = np.pi * f0 * np.asarray(tau, dtype=np.float64)
    return np.sin(u) ** 4 / u**2


@dataclass(frozen=True)
class Effect:
    """One candidate effect.

    Attributes
    ----------
    name : str
        What ``candidates=`` and ``Step.effect`` call it.
    label : str
        Its name in words, for reports.
    kind : {"curve", "time"}
        Found on the Allan curve by its signature, or in the samples along time.
    params : tuple of (name, unit, meaning)
        The parameters a :class:`~allanite.model.refinement.Step` reports, in order; "rate unit" is
        the samples' rate unit. For curve effects the first is the amplitude (fitted linearly), the
        second the nonlinear parameter.
    description : str
        What it is, with its Allan-variance form.
    signature : callable, optional
        ``signature(tau, p)``: Allan variance per unit amplitude squared (curve effects).
    alpha : callable, optional
        ``alpha(tau, p)``: the power-law noise type it resembles at each τ (for the estimates' EDF).
    search : callable, optional
        ``search(tau_min, tau_max)``: the grid of the nonlinear parameter to search.
    """

    name: str
    label: str
    kind: str
    params: tuple[tuple[str, str, str], ...]
    description: str
    signature: Callable[[np.ndarray, float], np.ndarray] | None = None
    alpha: Callable[[np.ndarray, float], np.ndarray] | None = None
    search: Callable[[float, float], np.ndarray] | None = None

    @property
    def param_names(self) -> tuple[str, ...]:
        return tuple(p[0] for p in self.params)


EFFECTS: dict[str, Effect] = {
    e.name: e
    for e in (
        Effect(
            "gauss_markov",
            "Gauss–Markov",
            "curve",
            (
                ("sigma", "rate unit", "standard deviation of the Gauss–Markov rate"),
                ("tc", "s", "correlation time T_c"),
            ),
            "first-order Gauss–Markov rate: σ²·(T_c/τ)²·(2τ/T_c − 3 + 4e^{−τ/T_c} − e^{−2τ/T_c}); a bump near "
            "τ ≈ 1.89·T_c, T_c searched in [τ_min, τ_max/4] so the bump lies inside the curve",
            signature=gm_avar,
            alpha=lambda tau, tc: np.where(tau < tc, -2, 0),
            search=lambda tmin, tmax: np.geomspace(tmin, tmax / 4.0, 40),
        ),
        Effect(
            "sinusoid",
            "sinusoid",
            "curve",
            (("amplitude", "rate unit", "amplitude A of the rate sinusoid"), ("f0", "Hz", "frequency f0")),
            "rate sinusoid A·sin(2πf0t): A²·sin⁴(πf0τ)/(πf0τ)², nulls at τ = k/f0; f0 ≥ 2/τ_max so that two "
            "nulls fall inside the curve",
            signature=sinusoid_avar,
            alpha=lambda tau, f0: np.zeros(np.asarray(tau).size, dtype=int),
            search=lambda tmin, tmax: np.geomspace(2.0 / tmax, 0.5 / tmin, 120),
        ),
        Effect(
            "change_point",
            "changes of noise level",
            "time",
            (("t", "s", "time of a step in the noise level, from the start of the record"),),
            "a step in the Allan variance of non-overlapping windows along the record (all τ jointly), located "
            "to the sample by a two-segment likelihood; needs the samples",
        ),
    )
}


def describe() -> str:
    """The candidates as a numpydoc-style list: name, parameters with units, what each is."""
    lines = []
    for e in EFFECTS.values():
        params = ", ".join(f"``{n}`` ({u})" for n, u, _ in e.params)
        lines.append(f"        - ``{e.name!r}`` — {params}: {e.description}.")
    return "\n".join(lines)
