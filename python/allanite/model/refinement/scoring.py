"""Errors of a model on an Allan curve: in-sample (χ²/dof, RMS z, RMS ADEV error) and held out.

RMS ADEV errors (in-sample and held out) are scored on 4 τ per octave whose estimate is informative (EDF ≥ 50
under the five-term fit: ±10 %); beyond, the estimate's own scatter, not the model, would decide the score.

The held-out error: the record is cut into :data:`HELDOUT_BLOCKS` blocks, the odd and the even ones joined end
to end; the model fitted on one part's Allan curve predicts the other's (both ways, RMS ADEV error averaged).
A time-domain removal is refitted on the held-in part's samples; change points are held out per segment, one
after another on the same targets (:func:`segments_heldout`).
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import solve_triangular
from scipy.stats import chi2 as chi2_dist

from ...analysis import avar
from .. import tracing
from .._recent import Recent
from .curvefit import Curve, Solution, design, solve

__all__ = [
    "HELDOUT_BLOCKS",
    "HELDOUT_MIN_EDF",
    "HELDOUT_AGREE",
    "rms_adev_pct",
    "informative",
    "chain_metrics",
    "settle_chi2",
    "MATERIAL_Z",
    "curve_change_z",
    "Split",
    "heldout_split",
    "segments_heldout",
]

#: Blocks for the held-out error (odd blocks predict even ones and back).
HELDOUT_BLOCKS = 8
#: RMS ADEV errors: only τ whose ADEV estimate is within ±10 % (EDF ≥ 50 under the five-term fit).
HELDOUT_MIN_EDF = 50.0
#: Held-out error: only τ where the two parts' own ADEV agree within this fraction.
HELDOUT_AGREE = 0.2


#: A model Allan variance below this share of the observed one counts as this share (:func:`rms_adev_pct`): a
#: held-out prediction that a removal's correction drives to zero or below otherwise read 3·10¹⁴⁷ % (floored at
#: 10⁻³⁰⁰; ``benches/refine_blind9.py``'s spikes on a line) — now at most 10⁶ % per τ, still the worst of any.
MODEL_FLOOR = 1e-8


def rms_adev_pct(obs, model) -> float:
    """RMS relative error (%) of the Allan deviation ``sqrt(model)`` against ``sqrt(obs)``; a model at or below
    :data:`MODEL_FLOOR` of ``obs`` is taken at that floor (a prediction of nothing: 10⁶ % at that τ)."""
    obs = np.asarray(obs, dtype=np.float64)
    model = np.maximum(model, MODEL_FLOOR * obs)
    return float(100 * np.sqrt(np.mean((np.sqrt(obs / model) - 1) ** 2)))


def informative(tau, nu) -> np.ndarray:
    """The τ an RMS ADEV error is scored on: 4 per octave (each octave weighs alike, not the dense grid's
    points) whose estimate is itself within ±10 % — EDF ≥ 50 under the five-term fit's own noise mix (white
    at short τ; far fewer for flicker and random walk at long τ). Beyond, the estimate's own scatter would
    decide the score. Falls back to every thinned τ if fewer than 4 qualify."""
    thin = tracing.thin_indices(tau)
    mask = np.zeros(tau.size, dtype=bool)
    mask[thin] = True
    good = mask & (nu >= HELDOUT_MIN_EDF)
    return good if np.count_nonzero(good) >= 4 else mask


#: A removal judged by a test in time alone (impulsive noise) is a step of the model only if it moves an estimate of
#: the record's Allan curve by at least this many of its standard errors (:func:`curve_change_z`).
MATERIAL_Z = 2.0


def curve_change_z(curve: Curve, sol: Solution, change) -> tuple[float, float]:
    """How far a removal moves the Allan curve, in the estimates' own scatter: the largest |Δ(τ)|/SE(τ), Δ =
    ``change`` = AVAR(y) − AVAR(y − component), SE = model·√(2/ν) under the fit ``sol`` of ``curve`` (the
    samples as they were); returns (that z, its τ). Impulsive noise is white-like: the model's white term takes
    it, so the record's curve error does not tell whether it matters — on 2·10⁵ samples with 30 spikes of 10 σ
    the five terms fit the spiky curve *better* (χ²/dof 1.25, held-out 3.5 %) than the cleaned one (1.41, 4.0 %;
    the record without spikes 1.45, 3.9 %), while N is 1.1 % too high with them (z = 4 at τ₀). One sample beyond
    7 σ of 10⁶ moves τ₀'s estimate by 0.04 of its standard error."""
    se = np.maximum(sol.model, 1e-300) * np.sqrt(2.0 / np.maximum(sol.nu, 1e-12))
    z = np.abs(np.asarray(change, dtype=np.float64)) / se
    i = int(np.argmax(z))
    return float(z[i]), float(curve.tau[i])


def chain_metrics(curve0: Curve, sol: Solution, change, n_removed: int, heldout, scored, thin) -> tuple[dict, tuple]:
    """Errors of a model on the original record's Allan curve ``curve0`` — the one every step is scored on, so
    that each step's "before" is the previous step's "after".

    The model is the noise model ``sol`` (fitted on the curve the removals so far left) plus what they changed
    in the curve, ``change`` = AVAR(y) − AVAR(y − components): their own Allan variance and their cross terms
    with the rest of the record, exactly — a regression's component is *not* independent of the noise (a
    channel's coupling varies across frequency, so the residual keeps a band-by-band cross term that the
    component's own variance misses). Returns the metrics known now — RMS ADEV error on ``scored``, ``heldout``
    as given — and what :func:`settle_chi2` needs with the model's covariance: the residual on the
    thinned τ ``thin`` and its degrees of freedom (the thinned τ less the model's fitted numbers and the
    ``n_removed`` numbers the removals fitted) and the count of fitted numbers (:func:`settle_chi2`'s AIC)."""
    model = np.maximum(sol.model + change, 1e-300)
    n_par = curve0.tau.size - sol.dof  # the fit's coefficients in use and its effects' parameters
    metrics = {
        "chi2_dof": None,
        "rms_z": None,
        "rms_adev_pct": rms_adev_pct(curve0.avar[scored], model[scored]),
        "p_value": None,
        "heldout_rms_adev_pct": heldout,
        "deviance": None,
        "aic": None,
    }
    n_fit = n_par + n_removed
    return metrics, ((curve0.avar - model)[thin], max(1, thin.size - n_fit), n_fit)


def settle_chi2(metrics: dict, pending: tuple, test) -> float:
    """Fill ``metrics``' χ²/dof, RMS z and p-value in place: the generalised least-squares χ² of the residual
    ``pending`` = (residual on the thinned τ, dof) under the covariance ``test`` whitens with — the model's own,
    as the calibrated test at that stage takes it (:func:`.calibrated.curve_test`: the exact covariance of the
    estimates across τ, cross terms of the noise types included, for samples or overlapping estimates; with an
    effect in the model, the five terms' nearest the model's curve; a line's coherent part by its cross term with
    the noise). A goodness of fit of each model by the tests' standard, not an objective the chain minimises: the
    covariance moves with the model, and a step the
    score test and the held-out error accept can raise it (ADIS16405 run 5 y + a 0.02 Hz sinusoid 1300 → 1352,
    held out falling; run 1 z's last, weak resonance 200 → 216). One covariance for the whole chain (the final
    model's) would judge the models before a removal against a noise that lacks the removed component's cross
    terms (the temperature log's start read 3.4·10⁴). Not χ² with the EDF variances 2·model²/ν over the dense
    τ: those leave out the cross terms (up to 2.4× too small at mid τ) and the correlation across τ, and rank
    models otherwise than the
    tests — a temperature the five terms absorb read 0.45 before its removal and 1.28 after, where the tests'
    covariance reads 5.3 → 1.7 (the true noise model 1.25). ``rms_z`` is the RMS of the whitened residual; the
    p-value χ²'s under χ²(dof) (the thinned estimates' marginals are skewed at long τ: a guide, the calibrated
    tests decide).

    ``deviance``: χ² + ln det Σ under that covariance, −2 ln L of the estimates' Gaussian density less n·ln 2π
    (n the thinned τ, the same for every model of the chain: only its differences along one chain mean
    anything; ln det Σ carries the record's unit). χ² alone is no likelihood when Σ moves with the model: a
    model that takes a coupling into its slow terms (a g-sensitivity into K) widens its own long-τ variances
    and so shrinks its own χ² — on ``benches/refine_blind12.py``'s g-sensitive gyro the absorbed start beat
    the true component removed on χ²/dof (1.05 against 1.21) and lost by 34 in deviance. ``aic``: the deviance
    + 2 × the fitted numbers (the terms in use, the effects' parameters, the removals' numbers): on 127 records
    of five blind rows the truth's is below the absorbed start's on all, and a false removal (a least-squares
    coupling to the channel, on the records less their component) lowers it on 11 — χ²/dof 96 and 12
    (``benches/results/chain_yardstick.md``). Returns χ² (its points are independent once whitened)."""
    resid, dof, n_fit = pending
    white = solve_triangular(test.chol, resid, lower=True)
    chi2 = float(white @ white)
    deviance = chi2 + 2.0 * float(np.sum(np.log(np.diag(test.chol))))
    metrics.update(
        chi2_dof=chi2 / dof,
        rms_z=float(np.sqrt(np.mean(white**2))),
        p_value=float(chi2_dist.sf(chi2, dof)),
        deviance=deviance,
        aic=deviance + 2.0 * n_fit,
    )
    return chi2


class _PartIndex:
    """The sample indices of a :class:`Split`'s two parts (``idx[parity]``), made when asked: held through a refine
    as arrays they were the record's size again in int64 (0.8 GB at 10⁸ samples), and only a removal's refit on
    the parts asks for them."""

    def __init__(self, per: int, n_blocks: int, size: int):
        self.per, self.n_blocks, self.size = per, n_blocks, size

    def blocks(self, parity: int) -> range:
        return range(parity, self.n_blocks, 2)

    def __getitem__(self, parity: int) -> np.ndarray:
        # each block's first index plus 0 … per − 1: the blocks' ranges joined, in one broadcast sum
        first = np.asarray(self.blocks(parity), dtype=np.int64) * self.per
        return (first[:, None] + np.arange(self.per, dtype=np.int64)).ravel()[: self.size]


class Split:
    """Alternate blocks in time (odd ↔ even) for the held-out error.

    Each part's blocks are joined end to end (samples keep their true times); the model fitted on one part's
    Allan curve predicts the other part's, both ways. Interleaved parts share the record's slow changes (a
    noise level that steps, a warm-up), so the score asks whether the model carries over, not whether the
    two halves of a non-stationary record agree at long τ. A time effect is fitted on one part's samples
    and removed from both. Joining keeps τ up to part/9 (a warm-up's time scale) where an Allan curve per
    block would stop at block/9; the seams affect the model with and without an effect alike."""

    def __init__(self, y, fs, grid_m, lo, hi, estimator, n_blocks, terms):
        self.y = y
        per = y.size // n_blocks
        self.fs, self.estimator = fs, estimator
        size = per * (n_blocks // 2)  # the shorter part's (odd blocks'), the longer cut to it
        self.idx = _PartIndex(per, n_blocks, size)
        m = grid_m[grid_m <= size // 9]
        tau = m / fs
        keep = (tau >= lo) & (tau <= hi)
        if np.count_nonzero(keep) < 8:
            raise ValueError("too few τ in range for held-out blocks")
        self.m, self.size = m[keep], size
        self.curves = [self.curve(self.part(f)) for f in (0, 1)]
        self.scored = informative(self.curves[0].tau, solve(self.curves[0], terms, []).nu)
        # ... and where the record reproduces itself: the two parts' own ADEV agree within ±20 % (twice the
        # ±10 % of EDF 50). Beyond, the parts differ more than their estimates scatter (a non-stationary
        # record, an under-estimated EDF at long τ), no model predicts both, and the score would be decided
        # by which model happens to sit nearer the other part's values there.
        agree = np.abs(np.sqrt(self.curves[0].avar / self.curves[1].avar) - 1.0) <= HELDOUT_AGREE
        if np.count_nonzero(self.scored & agree) >= 4:
            self.scored &= agree

    def curve(self, z):
        """The Allan curve of one part's samples ``z`` on the split's τ (the last few remembered, with the fits
        on them: a removal leaves most parts' samples as they were, and the split is made again after it)."""
        z = np.asarray(z)
        key = (self.m.tobytes(), float(self.fs), int(self.size), str(self.estimator))
        got = _CURVES.get(z, key)
        if got is None:
            av = np.maximum(avar(z, self.fs, taus=self.m / self.fs).avar, 1e-300)
            av.flags.writeable = False  # shared by every split that asks for these samples' curve
            curve = Curve(self.m / self.fs, self.m.astype(np.float64), av, self.fs, self.size + 1, self.estimator)
            got = _CURVES.put(z, key, curve)
        return got

    def part(self, parity: int) -> np.ndarray:
        """The samples of part ``parity`` (its blocks joined), made when asked: held through a refine, the two
        parts were the record's size again, and only the removals' held-out refits read them."""
        per = self.idx.per
        return np.concatenate([self.y[j * per : (j + 1) * per] for j in self.idx.blocks(parity)])[: self.size]

    def raw_parts(self) -> list:
        """Per direction (held-in part f → held-out part h), nothing removed yet: the held-in samples and their
        curve, the held-out samples and their curve, and no change of the curve to add back — the start of
        :meth:`corrected`."""
        return [
            {"zf": None, "cf": self.curves[f], "zh": None, "ch": self.curves[h], "extra": 0.0}
            for f, h in ((0, 1), (1, 0))
        ]

    def corrected(self, parts: list, refit, on_raw: bool) -> list:
        """``parts`` with one more removal, refitted on each held-in part's (already corrected) samples:
        ``refit(samples, indices)`` returns the component as a function of sample indices. The model is then
        fitted on the corrected held-in curve and predicts the held-out part's *raw* curve with what the removals
        changed in the curve added back — for ``on_raw`` the change they made to the held-in part's curve, else
        the change the held-in fit makes to the held-out part's curve, AVAR(z_h) − AVAR(z_h − g(h)) (a warm-up
        both parts share, whose held-out change the held-in part's own does not carry over to)."""
        out = []
        for (f, h), p in zip(((0, 1), (1, 0)), parts):
            zf0 = p["zf"] if p["zf"] is not None else self.part(f)  # None: the raw part's samples
            zh0 = p["zh"] if p["zh"] is not None else self.part(h)
            g = refit(zf0, self.idx[f])
            zf, zh = zf0 - g(self.idx[f]), zh0 - g(self.idx[h])
            del zf0
            cf = self.curve(zf)
            if on_raw:
                ch, change = None, p["cf"].avar - cf.avar
            else:
                ch = self.curve(zh)
                change = (p["ch"] if p["ch"] is not None else self.curve(zh0)).avar - ch.avar
            out.append({"zf": zf, "cf": cf, "zh": zh, "ch": ch, "extra": p["extra"] + change})
        return out

    def predict(self, parts: list, terms, effects, scored=None) -> float:
        """RMS ADEV error (%) of the model fitted on each corrected held-in part (plus what the removals changed
        in the curve) predicting the other part's raw curve, both ways: the held-out error on the original
        record, removals refitted on the held-in samples; over the τ ``scored`` (a mask; the split's own by
        default)."""
        scored = self.scored if scored is None else scored
        errs = []
        for h, p in zip((1, 0), parts):
            ch = self.curves[h]
            sol = solve(p["cf"], terms, effects)
            a_h, _ = design(ch, terms, effects)
            pred = np.maximum(a_h @ sol.theta + p["extra"], 1e-300)
            errs.append(rms_adev_pct(ch.avar[scored], pred[scored]))
        return float(np.mean(errs))

    def error_below(self, terms, effects, tau_max: float) -> float:
        """:meth:`error` (nothing removed) over the split's τ ≤ ``tau_max`` alone, NaN where there are none: the
        held-out error where an effect's column differs from the term it replaces (shaped quantisation's first
        averaging factors, :func:`._choose.choose`)."""
        scored = self.curves[0].tau <= tau_max * (1 + 1e-9)
        if not scored.any():
            return float("nan")
        return self.predict(self.raw_parts(), terms, effects, scored)

    def error(self, terms, effects, remove=None, on_raw=False) -> float:
        """RMS ADEV error (%) of one part's model predicting the other's *raw* curve, both ways; ``remove(samples,
        indices)`` fits a component on the held-in part and returns it as a function of sample indices.

        With ``remove``, the model is fitted on the held-in part's corrected curve and predicts the held-out part's
        raw curve with what the correction changed in the curve added back (:meth:`corrected`, :meth:`predict`):
        for ``on_raw`` the change to the held-in part's curve, else the change the held-in fit makes to the
        held-out part's own curve — so that "before" and "after" are scored on the same curve, as the chain
        scores them. Scored on the held-out part's corrected curve instead (as this test was until r13heldout),
        the relative error of a slow regression's "after" was taken on a curve the removal had lowered where the
        component dominates: ``benches/refine_blind10.py``'s humidity read 1.91 → 5.31 % here while the chain
        read 1.91 → 2.65 % (``benches/results/r13heldout.md``)."""
        return self.error_parts(terms, effects, remove, on_raw)[0]

    def error_parts(self, terms, effects, remove=None, on_raw=False) -> tuple:
        """:meth:`error` and the parts it was scored with (:meth:`corrected`'s, or :meth:`raw_parts`'): a removal
        kept on the record's own split goes on from those same parts (``_in_time.TimeRemovals.remove``)."""
        parts = self.raw_parts()
        if remove is not None:
            parts = self.corrected(parts, remove, on_raw)
        return self.predict(parts, terms, effects), parts


#: The held-out parts' curves last made (:meth:`Split.curve`), of parts up to 4·10⁶ samples: six, so that a removal's
#: four corrected parts (its held-out error, both ways) are still there when its step's parts are made again after
#: the new split's two (``_in_time.TimeRemovals.remove``; with four, all four were made twice).
_CURVES = Recent(6, 4_000_000)


def heldout_split(y, fs, m_all, lo, hi, terms):
    """Alternate blocks of the record for the held-out error, or None if the record is too short."""
    try:
        return Split(y, fs, m_all, lo, hi, "oavar", HELDOUT_BLOCKS, terms)
    except ValueError:
        return None


def segments_heldout(whole: Split, y, fs, m_all, lo, hi, terms, effects, times):
    """Held-out error of change points at ``times`` (s), one after another: [without any, with the first, …,
    with all], or None if a segment is too short.

    The targets stay the same along the list: each final segment (between all the change points) gets its own
    alternate blocks, and its held-out part's Allan curve is predicted by the model fitted on the held-in part
    of the segment that contains it when only the first n change points cut the record (n = 0: the whole
    record's held-in part; n = all: the segment's own). Mean over both ways, segments weighted by their
    length. So the first value and the last compare the model without and with every change point (a change
    point that is not real leaves the segments alike, and the segment's model, fitted on less data, predicts no
    better), and change point n's before and after are entries n and n + 1 — a chain, each one's before the
    previous one's after."""
    cuts = sorted(int(round(t * fs)) for t in times)
    splits: dict = {(0, y.size): whole}
    fits: dict = {}

    def held_in(a: int, b: int, f: int):  # the model fitted on segment a..b's held-in part f
        if (a, b) not in splits:
            splits[(a, b)] = heldout_split(y[a:b], fs, m_all, lo, hi, terms)
        if splits[(a, b)] is None:
            return None
        if (a, b, f) not in fits:
            fits[(a, b, f)] = solve(splits[(a, b)].curves[f], terms, effects).theta
        return fits[(a, b, f)]

    edges = [0] + cuts + [y.size]
    out = np.zeros(len(cuts) + 1)
    for a, b in zip(edges[:-1], edges[1:]):
        if held_in(a, b, 0) is None:
            return None
        seg = splits[(a, b)]
        for f, h in ((0, 1), (1, 0)):
            a_h, _ = design(seg.curves[h], terms, effects)
            obs = seg.curves[h].avar[seg.scored]
            for n in range(len(cuts) + 1):
                cut_n = [0] + cuts[:n] + [y.size]
                j = max(i for i, e in enumerate(cut_n) if e <= a)
                theta = held_in(cut_n[j], cut_n[j + 1], f)
                if theta is None:
                    return None
                pred = np.maximum(a_h @ theta, 1e-300)[seg.scored]
                out[n] += 0.5 * (b - a) / y.size * rms_adev_pct(obs, pred)
    return [float(v) for v in out]
