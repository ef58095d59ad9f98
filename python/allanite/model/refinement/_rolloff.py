"""The sensor's roll-off re-searched beside the terms that came after it.

The roll-off is accepted first (:func:`.candidates.choose`: the white noise every other column is judged
against), so its parameter is searched without the terms later steps add; a Gauss–Markov term's short-τ slope
or a resonance beside it then leaves the cutoff biased, and the final joint fit refits amplitudes only
(a 2nd-order Butterworth at 100 Hz with a Gauss–Markov term: 101.3 Hz at acceptance, a 1.8 % misfit at the
shortest τ that ``unexplained`` flags). Once the loop is done its parameter is searched again on its kind's grid
with every other effect in the model, and kept where χ² falls.
"""

from __future__ import annotations

from .candidates import bandwidth_grids
from .curvefit import Curve, Solution, base_name, search, solve


def research_rolloff(curve: Curve, start: tuple, effects: list, sol: Solution) -> tuple[list, Solution]:
    """(effects, solution) with the bandwidth's parameter re-searched beside the others on its kind's grid
    (:func:`.candidates.bandwidth_grids`); the same when there is none, when its best value sits at the edge of
    its grid, or when χ² does not fall."""
    j = next((i for i, (k, _p) in enumerate(effects) if base_name(k) == "bandwidth"), None)
    if j is None or len(effects) < 2:
        return effects, sol
    key = effects[j][0]
    kind = key.split(":", 1)[1]
    grid = bandwidth_grids(curve).get(kind)
    if grid is None:
        return effects, sol
    others = effects[:j] + effects[j + 1 :]
    p, _s, edge = search(curve, start, others, key, grid, continuous=kind not in ("moving_average", "bartlett"))
    if edge:
        return effects, sol
    new = effects[:j] + [(key, p)] + effects[j + 1 :]
    s_new = solve(curve, start, new)  # in the model's own column order
    return (new, s_new) if s_new.chi2 < sol.chi2 else (effects, sol)
