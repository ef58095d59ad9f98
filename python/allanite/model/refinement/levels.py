"""The false-alarm budget of :func:`allanite.refine`: one ``level`` per record, shared among its tests.

Every calibrated test spends its own share of ``level`` (its α = share × level); the Allan-curve score test
(the maximum over every curve family, bootstrapped) takes what the others leave. A new test is one entry
in :data:`SHARES` (a test of its own) or :data:`TIME_SHARES` (a time-domain removal, by its effect name),
calibrated with the rest on clean records (``benches/refine_false_alarms.py``).
"""

from __future__ import annotations

from .._shares import LINE_GAIN_SHARE, TERM_SHARE, WANDER_SHARE

__all__ = [
    "LEVEL",
    "LINE_SHARE",
    "SLOW_LINE_SHARE",
    "CHANGE_POINT_SHARE",
    "TIME_SHARE",
    "OUTLIER_SHARE",
    "TELEGRAPH_SHARE",
    "UNEXPLAINED_SHARES",
    "SAMPLE_CHECKS",
    "SHARES",
    "TIME_SHARES",
    "CONDITIONAL_SHARES",
    "share",
    "alpha",
]

#: Default false-alarm level per record (clean record: probability that anything is added).
LEVEL = 0.05
#: Share of ``level`` spent on spectral lines (the Welch PSD's F test, Bonferroni over the bins): one search
#: for the lone ``"sinusoid"`` lines and the ``"periodic"`` families alike (a family's lattice points are tested
#: only after a line was found, so under the null they spend nothing more). Measured over 640 null records:
#: benches/results/periodic_outliers_null.md.
LINE_SHARE = 0.2
#: Share of ``level`` spent on a line of few cycles (3 to 18 in the record), below the spectral search's lowest bin:
#: its test in time under the block means' fitted white, random-walk and flicker noise
#: (:func:`allanite.model.slowline.slow_line_test`). 0.008 is what the Allan-curve test's rest can give without moving
#: its bootstrap critical value (the 988th of 1001 draws at level 0.05); its null: benches/results/r13slowline.md.
SLOW_LINE_SHARE = 0.008
#: Share of ``level`` spent on change points of the noise level along the record.
CHANGE_POINT_SHARE = 0.2
#: Share of ``level`` for each time-domain test (regression on channels, drift).
TIME_SHARE = 0.075
#: Share of ``level`` for the outlier test (clusters of large differences against twice their Gaussian
#: expectation, Bonferroni over its cuts): proposed 0.05 (α = 0.25 % at level 0.05); its power on spikes and
#: heavy tails is far above what the share costs (benches/results/periodic_outliers_power.md).
OUTLIER_SHARE = 0.05
#: Share of ``level`` for the telegraph test (the Allan differences' kurtosis, Bonferroni over the octaves):
#: 0.002 is what the Allan-curve test's rest can give without moving its bootstrap critical value (the 988th of
#: 1001 draws at level 0.05); its null on Gaussian records of Gauss–Markov and flicker spectra:
#: benches/results/telegraph_null.md.
TELEGRAPH_SHARE = 0.002

#: Share of ``level`` spent on saying what the final model still misses (``Refinement.unexplained``), split
#: between its checks: the Allan curve, lines in the PSD, a drift in time, a step of the mean, steps of the mean
#: at several times, the noise level along the record, a coupling to a channel left in the samples, a dependence on
#: a channel's value that no kept term models, impulsive
#: noise left in them, clipped and held samples in the record as given
#: (:data:`allanite.model.refinement.missing.CHECKS`).
UNEXPLAINED_SHARES = {
    # "line" takes 0.0125 of "allan": a line whose amplitude changes shows in the curve's misfit too, but the
    # dedicated phasor test is far stronger; it spends nothing without an accepted line.
    "allan": 0.0375,
    "line": 0.0125,
    "psd": 0.025,
    # "mean" (one step of the mean) takes half of "time" (a warm-up drift): both test the record's block means
    # for a deterministic change of the mean, so on a clean record they look at the same wander (flicker, rate
    # random walk) and their false alarms come together — the pair spends what the drift check alone did.
    # "steps" (steps at several times: outlying increments of the block means) takes half of "mean"'s.
    "time": 0.00625,
    "mean": 0.003125,
    "steps": 0.003125,
    "level": 0.0125,
    # "channel_shape" (the residual's dependence on a slow channel's value beyond its kept terms: steps at its
    # quantiles, :mod:`allanite.model._shape`) takes half of what "channels" (a coupling left, linear) had: the
    # two look at the same channel, and a record with a channel spends what the linear check alone did
    # (docs/channels.md, "A coupling no term models"; benches/results/channel_shape_null.md)
    "channels": 0.00625,
    "channel_shape": 0.00625,
    "outliers": 0.0125,
    # clipped and held samples (:mod:`._quality`): exact-count tests on the samples as given, far from their
    # thresholds on clean records (0 of 889: the 613 of benches/refine_false_alarms.py, quantised and float32
    # records, the 36 ADIS16405 channels; benches/results/refine_quality_null.md); their 0.005 comes from the
    # Allan-curve test's rest, whose bootstrap critical value (the 988th of 1001 draws at level 0.05) does not move.
    "clipped": 0.0025,
    "held": 0.0025,
}
#: The checks that need the samples; on curve-only input their shares go to the ``"fit"`` check (the GLS χ²
#: of the whole curve, two-sided), so that curve-only input spends the same share on ``unexplained``.
SAMPLE_CHECKS = (
    "psd",
    "time",
    "mean",
    "steps",
    "level",
    "channels",
    "channel_shape",
    "outliers",
    "line",
    "clipped",
    "held",
)

#: Tests with a share of their own, by name (the Allan-curve test, ``"curve"``, takes the rest).
SHARES = {
    "lines": LINE_SHARE,
    "slow_lines": SLOW_LINE_SHARE,
    "change_point": CHANGE_POINT_SHARE,
    **{f"unexplained:{k}": v for k, v in UNEXPLAINED_SHARES.items()},
}
#: The share of each time-domain removal, by effect name (one entry per removal of ``removals.REMOVALS``; the
#: ``"periodic"`` removal spends the ``"lines"`` share).
TIME_SHARES = {
    "outliers": OUTLIER_SHARE,
    "drift": TIME_SHARE,
    "regression": TIME_SHARE,
    "telegraph": TELEGRAPH_SHARE,
}
#: Tests run only once another has accepted its effect — a slow channel's optional terms (quadratic,
#: d(channel)/dt, lag; :data:`allanite.model.channels.TERM_SHARE`), each at this share of ``level``. On a
#: clean record they never run unless the regression itself is a false alarm, so they take nothing from the
#: per-record budget; on a record with a linear coupling each is the rate of naming a term that is not there
#: (0 of 600 each, benches/results/channel_regression.md). The level term itself (``"regression:coefficient"``)
#: is tested where a d(channel)/dt term alone is kept beside it, at the whole level: its share is the rate of
#: keeping a level term that is not there (benches/results/r13rate.md; docs/channels.md, "The level term").
#: The quadratic is also tried where the coupling's own
#: test fails (a turnover temperature has no linear part); there it is part of the coupling's decision and spends
#: part of the regression's :data:`TIME_SHARE` (:data:`allanite.model._shares.FIRST_QUADRATIC` of it, the channel
#: and its quadrature the rest), not a share beside it (docs/channels.md, "A turnover temperature").
CONDITIONAL_SHARES = {f"regression:{k}": v for k, v in TERM_SHARE.items()}
#: An accepted line family's fundamental tracked (:mod:`allanite.model.wander`): conditional on the family, as above.
CONDITIONAL_SHARES["periodic:wander"] = WANDER_SHARE
#: A notch after an accepted roll-off (:mod:`.refinement._notch`): tried only once the bandwidth step has its
#: kind, so on a record without a roll-off it spends nothing; on a filtered record without a notch it is the rate
#: of naming one (benches/results/notch_null.md).
CONDITIONAL_SHARES["bandwidth:notch"] = 0.02
#: An accepted line's amplitude following a given channel (:mod:`.refinement._line_gain`): conditional on the line.
CONDITIONAL_SHARES["sinusoid:gain"] = LINE_GAIN_SHARE
#: ``unexplained``'s check that an accepted line follows a channel no regression uses
#: (:mod:`.refinement._channel_follows`): run only once a line is accepted and channels are given — conditional on the
#: line, as the gain's test; its rate on lines beside channels that do not carry them:
#: benches/results/channel_follows_null.md.
CONDITIONAL_SHARES["unexplained:follows"] = LINE_GAIN_SHARE


def share(test: str) -> float:
    """The share of ``level`` spent on ``test`` (a key of :data:`SHARES`, :data:`TIME_SHARES` or
    :data:`CONDITIONAL_SHARES`, ``"unexplained:fit"`` — curve-only input's share of the checks that need the
    samples, :data:`SAMPLE_CHECKS` —, or ``"curve"``: what the others leave — the conditional ones take
    nothing)."""
    if test in SHARES:
        return SHARES[test]
    if test in TIME_SHARES:
        return TIME_SHARES[test]
    if test in CONDITIONAL_SHARES:
        return CONDITIONAL_SHARES[test]
    if test == "unexplained:fit":  # curve-only input: the shares of the checks it cannot run
        return sum(UNEXPLAINED_SHARES[k] for k in SAMPLE_CHECKS)
    if test != "curve":
        raise KeyError(test)
    rest = 1.0
    for v in SHARES.values():
        rest -= v
    return rest - sum(TIME_SHARES.values())


def alpha(test: str, level: float) -> float:
    """The false-alarm probability ``test`` may spend on one record: its share of ``level``."""
    return level * share(test)
