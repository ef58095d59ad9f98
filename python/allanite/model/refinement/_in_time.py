"""The removals in time of a refinement, before its curve effects: every removal of :data:`.removals.REMOVALS`
among the candidates, in order, each on the samples the ones before it left, kept where the held-out error
falls (or its own held-out test in time passes) and, for a test in time alone, where it moves the Allan curve.
Each kept removal's step is scored along the chain once the curve effects are in (:mod:`._final`).
"""

from __future__ import annotations

from ...analysis import avar
from ..channels import terms_before_after
from ..periodic import sinusoid_lines
from ._run import RunState
from ._slow_lines import FAST_LINES_MAX, lines_component, lines_in_differences, lines_less, slow_lines
from .curvefit import Curve, noise_fit, solve
from .removals import REMOVALS, Removal, RemovalContext
from .result import Step
from .scoring import MATERIAL_Z, curve_change_z

__all__ = ["TimeRemovals"]


class TimeRemovals(RunState):
    """A refinement's removals in time (:meth:`remove_in_time`), on :class:`._run.RunState`."""

    def remove_in_time(self, candidates, chans) -> None:
        """Every removal of :data:`REMOVALS` among ``candidates``, in order, each on the samples the ones
        before it left — and only of an effect among them (the line search's lone and few-cycle lines are
        ``"sinusoid"`` removals: without that candidate they are not taken, as the curve's sinusoids are not)."""
        if self.y is None:
            return
        # the channels even where their regression may not be taken: a drift a channel explains is no drift (with
        # the regression a candidate the channel takes it; without, it is left to be said in ``unexplained``)
        ctx = RemovalContext(self.y, self.fs, self.curve, self.sol, self.start, chans, self.level, self.consider)
        for name, remover in REMOVALS.items():
            if name not in candidates:
                continue
            for rem in remover(ctx):
                if rem.effect not in candidates:  # a line the line search tests in time is a "sinusoid"
                    continue
                if self.remove(rem):
                    ctx.y, ctx.curve, ctx.sol = self.y, self.curve, self.sol
                elif rem.family is not None:
                    self.declined_families.append(rem.family)
        self.line_search = ctx.lines
        if "drift" in candidates and not any(rem.effect == "drift" for _st, rem, *_r in self.removed):
            self.drift_beside_slow_lines(ctx)
        elif self.removed and self.removed[-1][1].effect == "drift":
            self.drift_confirmed_beside_lines(ctx)
        if "outliers" in candidates and not any(rem.effect == "outliers" for _st, rem, *_r in self.removed):
            self.outliers_beside_lines(ctx)

    def drift_confirmed_beside_lines(self, ctx: RemovalContext) -> None:
        """A drift taken (the last removal) tested once more where the line search found lone lines: on the
        samples less the strongest (least squares at their frequencies), its null from that record's curve; where
        its statistic is not beyond the threshold there, the drift is put back. The drift's threshold comes from
        the five-term fit of the record's curve, and a strong line bends that fit — ``benches/refine_blind9.py``'s
        4 Hz line 8× the per-sample σ read as a white term 9× the true one beside no flicker or random walk, and
        block means a flicker and a random walk scatter passed the threshold so set (statistic 22.8 against 15.7;
        362 less the line)."""
        assert self.y is not None
        if ctx.lines is None:
            return
        freqs = [d["f0"] for d in sinusoid_lines(ctx.lines, families=self.declined_families)][:FAST_LINES_MAX]
        if not freqs:
            return
        _st, rem, *_rest = self.removed[-1]
        y_back = self.y + rem.component
        found: list = []
        less = self._less(lines_less(y_back, self.fs, freqs), ctx, lambda _e, entry: found.append(entry))
        if (
            any(True for _r in REMOVALS["drift"](less))
            or not found
            or not found[-1]["statistic"] <= found[-1]["threshold"]
        ):
            return  # taken there too, or turned down there by a later check than the test's own: kept as it was
        self.removed.pop()
        self.y, self.result = y_back, avar(y_back, self.fs, taus=self.result.tau)
        self.curve, self.heldout = self.build(self.result, y_back)
        self.sol = solve(self.curve, self.start, self.effects)
        ctx.y, ctx.curve, ctx.sol = self.y, self.curve, self.sol
        why = f"not found on the samples less the lines at {', '.join(f'{f:.4g}' for f in freqs)} Hz"
        self.consider("drift", rem.params | {"rejected": why, "beside_lines": found[-1]})

    def outliers_beside_lines(self, ctx: RemovalContext) -> None:
        """The outlier test once more where the line search found lone lines strong in the first differences
        (:func:`._slow_lines.lines_in_differences`): on the samples less those lines (least squares at their
        frequencies), their materiality judged on that record's curve and five-term fit. A strong line in the
        differences raises the robust scale the test's cut is set in, so only the largest spikes pass it, and in
        the curve it inflates the white term whose standard errors the materiality is measured in
        (``benches/refine_blind9.py``'s 80 spikes of 8–15 σ on a 4 Hz line 8× the per-sample σ: 44 flagged at
        0.107, moving the curve by 0.06 standard errors, turned down; less the line, 80 flagged at 0.047). The
        lines stay in the samples for the curve's candidates; only the spikes found are removed."""
        assert self.y is not None
        freqs = lines_in_differences(ctx.lines, self.y, self.fs, self.declined_families)
        if not freqs:
            return
        said = lambda effect, entry: self.consider(effect, entry | {"beside_lines_hz": freqs})  # noqa: E731
        less = self._less(lines_less(self.y, self.fs, freqs), ctx, said)
        for rem in REMOVALS["outliers"](less):
            rem.evidence["beside_lines_hz"] = freqs
            self.remove(rem, basis=(less.curve, less.sol, less.y))

    def drift_beside_slow_lines(self, ctx: RemovalContext) -> None:
        """The drift test once more where the line search found lone lines slow enough to move the drift test's
        block means (a period over two blocks): on the samples less those lines (least squares at their
        frequencies), its null from that record's curve. A slow line left in the block means inflates the
        five-term fit's slow terms, which set the drift's threshold, and the line's swing is the block means'
        scatter the warm-up is weighed against (``benches/refine_blind8.py``'s warm-up beside a 500 s line:
        statistic 748 against 961 with the line, taken as a 0.0205·e^{−t/906 s} without it). The lines stay in
        the samples for the ``"sinusoid"`` curve candidate; only a drift found is removed."""
        assert self.y is not None
        slow = slow_lines(ctx.lines, self.y.size / self.fs, self.declined_families)
        if not slow:
            return
        less = self._less(self.y - lines_component(self.y, self.fs, slow), ctx, self.consider)
        for rem in REMOVALS["drift"](less):
            rem.evidence["beside_lines_hz"] = [float(f) for f in slow]
            self.remove(rem)

    def _less(self, y_less, ctx: RemovalContext, consider) -> RemovalContext:
        """The removals' context on ``y_less`` (the samples less some lines): its curve, the five-term fit on it,
        ``consider`` where what is turned down there is said — the retests beside lines are each run on one."""
        c_less, _h = self.build(avar(y_less, self.fs, taus=self.result.tau), None)
        s_less = solve(c_less, self.start, self.effects)
        return RemovalContext(
            y_less, self.fs, c_less, s_less, self.start, ctx.channels, self.level, consider, effects=ctx.effects
        )

    def remove(self, rem: Removal, basis: tuple | None = None) -> bool:
        """Remove ``rem.component`` if the held-out error falls (or its held-out test in time passes); else
        record it among the considered. Its step is scored once the curve effects are in (:meth:`score`).
        ``basis``: (curve, fit, samples) its materiality is judged on in place of the record's own."""
        y, start, effects, heldout = self.y, self.start, self.effects, self.heldout
        assert y is not None
        ho_b = heldout.error(start, effects) if heldout is not None else None
        ho_a, parts_a = (None, None)
        if heldout is not None:
            ho_a, parts_a = heldout.error_parts(start, effects, remove=rem.refit, on_raw=rem.on_raw)
        if rem.heldout_in_time is not None:
            rem.evidence["heldout_variance_ratio"] = rem.heldout_in_time
            rejected = not rem.heldout_in_time < 1.0
        else:
            rejected = ho_b is not None and ho_a is not None and not ho_a < ho_b
        if rejected:
            why = f"held-out error {ho_b} → {ho_a} %, variance ratio {rem.heldout_in_time}"
            self.consider(rem.effect, rem.params | {"rejected": why, "test": rem.evidence["test"]})
            return False
        if ho_b is not None:  # on the samples as they were, the five terms alone
            rem.evidence["heldout_test"] = {"before": ho_b, "after": ho_a}
        # the corrected samples' curve and split only for a removal the held-out test kept (one Allan curve of the
        # record and two of its halves saved per removal turned down)
        y_new = y - rem.component
        res_new = avar(y_new, self.fs, taus=self.result.tau)
        c_new, h_new = self.build(res_new, y_new)
        params = dict(rem.params)
        s_new = solve(c_new, start, effects)
        if rem.on_curve and not self.moves_curve(rem, c_new, basis):
            return False
        # the noise terms fitted with the component in the samples and without it, side by side: what the
        # start model had taken of it (a temperature swing into B, K and R)
        rem.evidence["terms_before_after"] = terms_before_after(
            noise_fit(self.curve, start, effects, self.sol, self.result, self.unit, 0.683),
            noise_fit(c_new, start, effects, s_new, res_new, self.unit, 0.683),
        )
        st = Step(
            effect=rem.effect,
            params=params,
            intervals=rem.intervals,
            evidence=rem.evidence,
            before={},
            after={},
            truth_error=self.truth_error(rem.effect, params),
            final_params=dict(params),
            final_intervals=dict(rem.intervals),
        )
        parts = None
        if self.split0 is not None and heldout is self.split0 and not self.removed:
            # the record's own split, nothing removed before: the held-out test's parts are these (its raw parts,
            # this refit), made once — the refit evaluated on both parts and their four curves were made twice
            parts = parts_a
        elif self.split0 is not None:
            parts = self.split0.corrected(self.removed[-1][4] if self.removed else self.raw, rem.refit, rem.on_raw)
        self.removed.append((st, rem, self.curve.avar - c_new.avar, c_new, parts))
        self.y, self.result, self.curve, self.heldout = y_new, res_new, c_new, h_new
        self.sol = s_new
        return True

    def moves_curve(self, rem: Removal, c_new: Curve, basis: tuple | None = None) -> bool:
        """Whether removing ``rem`` moves an estimate of the record's Allan curve by at least
        :data:`.scoring.MATERIAL_Z` of its standard errors (:func:`.scoring.curve_change_z`, under the model so
        far). A removal whose test is in time alone (impulsive noise: a tail beyond the Gaussian's) may be real
        yet immaterial to the curve — one sample of 10⁶ beyond 7 σ on an ADIS16405 accelerometer moves τ₀'s
        estimate by 0.04 of its standard error — and then is no step of the model. Not the curve's error: the
        model's white term takes white-like spikes, and removing true spikes can raise it (scoring's note)."""
        curve, sol = self.curve, self.sol
        if basis is not None:  # judged on other samples (the record less strong lines): their curve, with and without
            curve, sol, samples = basis
            c_new, _h = self.build(avar(samples - rem.component, self.fs, taus=self.result.tau), None)
        z, tau = curve_change_z(curve, sol, curve.avar - c_new.avar)
        if z >= MATERIAL_Z:
            rem.evidence["curve_change"] = {"z": z, "tau": tau, "material_z": MATERIAL_Z}
            return True
        why = f"moves the Allan curve by {z:.2g} standard errors at most (τ {tau:.3g} s), < {MATERIAL_Z:g}"
        self.consider(rem.effect, rem.params | {"rejected": why, "test": rem.evidence["test"]})
        return False
