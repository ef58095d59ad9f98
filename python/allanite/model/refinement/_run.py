"""One refinement under way (:class:`RunState`): the samples and their curve as removals change them, the model
so far, the steps, what was considered and turned down — and the chain every step is scored along. The removals
in time (:mod:`._in_time`) and the final scoring and result (:mod:`._final`) build on it; :mod:`.loop` adds the
curve steps and runs them in order.
"""

from __future__ import annotations

import numpy as np

from ...errors import ParameterError
from .. import tracing
from ._inputs import heldout_note, resolve_tau_range
from .calibrated import curve_test
from .curvefit import Curve, solve, theta_terms
from .result import Step
from .scoring import chain_metrics, heldout_split, informative, settle_chi2

__all__ = ["RunState"]


class RunState:
    """One refinement under way: the samples and their curve as removals change them, the model so far, the
    steps, and what was considered and turned down.

    Every step is scored on the original record's Allan curve (``curve0``) and held out on its alternate blocks
    (``split0``), along one chain: each step's "before" is the previous step's "after", the first "before" the
    start's, the last "after" the final model's. The curve effects come first in it, fitted on the record's
    own curve; then the removals in time (removed from the samples before the curve effects were searched, so
    that those are found on the corrected samples), each scored with every curve effect in the model — a
    removed component's exact Allan variance, AVAR(y) − AVAR(y − components), part of it, and held out with
    the removals refitted on each held-in part; change points last. The held-out comparison that accepted a
    step (on the samples as they were when it was tested, or per segment for change points) is kept in its
    ``evidence["heldout_test"]`` where it differs."""

    def __init__(self, y, result, start, tau_range, level, truth, unit=None):
        self.y, self.result, self.start, self.level, self.truth = y, result, start, level, truth
        self.y0 = y  # the samples as given: removals replace self.y, never change it in place
        self.unit = unit
        self.lo, self.hi = resolve_tau_range(tau_range, result, start)
        keep = (result.tau >= self.lo) & (result.tau <= self.hi) & (result.avar > 0)
        if keep.sum() < len(start) + 3:
            raise ParameterError(
                f"{int(keep.sum())} usable τ points; refining {len(start)} terms needs at least {len(start) + 3}"
            )
        self.keep = keep
        self.est = result.estimator if result.source is None else tuple(np.asarray(result.source)[keep])
        self.fs = result.fs
        self.curve, self.heldout = self.build(result, y)
        self.note = heldout_note(y, self.heldout)
        self.sol = self.start_sol = solve(self.curve, start, [])
        # the chain's χ² on the tests' thinned τ and covariance (exact for samples or overlapping estimates)
        self.thin = tracing.thin_indices(self.curve.tau)
        self.exact = y is not None or (isinstance(self.est, str) and self.est == "oavar")
        # in-sample RMS ADEV error: on the τ whose estimate is informative under the five-term fit (fixed for
        # the whole refinement, so every before/after compares the same τ)
        self.scored = informative(self.curve.tau, self.sol.nu)
        # the original record: what every step is scored on
        self.result0, self.curve0, self.split0 = result, self.curve, self.heldout
        self.raw = self.split0.raw_parts() if self.split0 is not None else None
        self.state = self.chain(self.sol, [])  # (metrics, GLS χ², terms' coefficients) of the model so far
        self.start_heldout = self.state[0]["heldout_rms_adev_pct"]
        self.effects: list = []  # curve effects [(key, nonlinear parameter)], steps[j] ↔ effects[j]
        self.steps: list = []
        self.lines: list = []  # per curve step: the spectral line it came from, or None
        self.channels: dict = {}  # the channels as given (for a line's gain: ._line_gain)
        # per time effect removed before the curve effects: (step, removal, its own change of the curve, the
        # curve after it, the held-out parts with the removals so far refitted on them)
        self.removed: list = []
        self.states: list = [self.state]  # the chain: the model before the first step and after each
        self.change_points: list = []
        self.segments = None  # the change points' segments (._segments.Segments), once they are accepted
        self.considered: dict[str, list] = {}
        self.line_search: dict | None = None  # the periodic removal's line search, for the sinusoid candidate
        self.declined_families: list = []  # line families the removal in time turned down: their lines stay
        self.offered_lines: list | None = None  # the sinusoid candidate's lines (Hz); None: the candidate not run

    def build(self, res, samples):
        """The curve (and, with samples, the held-out split) of ``res``'s estimates in the τ range."""
        keep = self.keep
        c = Curve(res.tau[keep], res.m[keep].astype(np.float64), res.avar[keep], self.fs, res.n_samples + 1, self.est)
        if samples is None:
            return c, None
        m_all = np.asarray(res.m, dtype=np.int64)
        return c, heldout_split(samples, self.fs, m_all, self.lo, self.hi, self.start)

    def chain(self, sol, effects, curve=None, n_removed=0, parts=None) -> tuple:
        """The model ``sol`` (terms plus ``effects``, fitted on ``curve``: the record's, or the one the removals
        left, with ``n_removed`` numbers fitted by them) scored on the record's curve, held out with ``parts``
        (the raw parts when None): (metrics, GLS χ², the terms' coefficients √θ)."""
        curve = self.curve0 if curve is None else curve
        ho = None
        if self.split0 is not None:
            ho = self.split0.predict(self.raw if parts is None else parts, self.start, effects)
        change = self.curve0.avar - curve.avar
        metrics, pending = chain_metrics(self.curve0, sol, change, n_removed, ho, self.scored, self.thin)
        # χ² under the model's own covariance, as the calibrated test at that stage takes it (the removals'
        # components are fitted, not drawn: the residual on the record's curve is the corrected curve's)
        chi2 = settle_chi2(metrics, pending, curve_test(curve, self.thin, sol, self.start, effects, self.exact))
        return metrics, chi2, np.sqrt(np.maximum(theta_terms(sol, self.start, effects), 0.0))

    def advance(self, st: Step, state: tuple) -> None:
        """Score ``st`` from the chain's last state to ``state``."""
        st.before, st.after = dict(self.state[0]), dict(state[0])
        st.delta_chi2_eff = float(self.state[1] - state[1])
        self.state = state
        self.states.append(state)

    def consider(self, effect: str, entry: dict) -> None:
        self.considered.setdefault(effect, []).append(entry)

    def truth_error(self, effect: str, params: dict) -> dict | None:
        """Relative errors of the numeric parameters ``truth`` gives for ``effect``."""
        if not self.truth or effect not in self.truth:
            return None
        return {
            k: params[k] / v - 1
            for k, v in self.truth[effect].items()
            if k in params and isinstance(params[k], (int, float)) and v
        }
