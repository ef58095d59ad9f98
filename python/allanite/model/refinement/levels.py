"""The false-alarm budget of :func:`allanite.refine`: one ``level`` per record, shared among its tests.

Every calibrated test spends its own share of ``level`` (its α = share × level); the Allan-curve score test
(the maximum over every curve family, bootstrapped) takes what the others leave. A new test is one entry
in :data:`SHARES` (a test of its own) or :data:`TIME_SHARES` (a time-domain removal, by its effect name),
calibrated with the rest on clean records (``benches/refine_false_alarms.py``).
"""

from __future__ import annotations

__all__ = [
    "LEVEL",
    "LINE_SHARE",
    "CHANGE_POINT_SHARE",
    "TIME_SHARE",
    "UNEXPLAINED_SHARES",
    "SHARES",
    "TIME_SHARES",
    "share",
    "alpha",
]

#: Default false-alarm level per record (clean record: probability that anything is added).
LEVEL = 0.05
#: Share of ``level`` spent on spectral lines (the Welch PSD's χ² test, Bonferroni over the bins).
LINE_SHARE = 0.2
#: Share of ``level`` spent on change points of the noise level along the record.
CHANGE_POINT_SHARE = 0.2
#: Share of ``level`` for each time-domain test (regression on channels, drift).
TIME_SHARE = 0.075

#: Share of ``level`` spent on saying what the final model still misses (``Refinement.unexplained``), split
#: between its checks: the Allan curve, lines in the PSD, a drift in time.
UNEXPLAINED_SHARES = {"allan": 0.075, "psd": 0.025, "time": 0.025}

#: Tests with a share of their own, by name (the Allan-curve test, ``"curve"``, takes the rest).
SHARES = {
    "lines": LINE_SHARE,
    "change_point": CHANGE_POINT_SHARE,
    **{f"unexplained:{k}": v for k, v in UNEXPLAINED_SHARES.items()},
}
#: The share of each time-domain removal, by effect name (one entry per removal of ``removals.REMOVALS``).
TIME_SHARES = {"drift": TIME_SHARE, "regression": TIME_SHARE}


def share(test: str) -> float:
    """The share of ``level`` spent on ``test`` (a key of :data:`SHARES` or :data:`TIME_SHARES`, or ``"curve"``:
    what the others leave)."""
    if test in SHARES:
        return SHARES[test]
    if test in TIME_SHARES:
        return TIME_SHARES[test]
    if test != "curve":
        raise KeyError(test)
    rest = 1.0
    for v in SHARES.values():
        rest -= v
    return rest - sum(TIME_SHARES.values())


def alpha(test: str, level: float) -> float:
    """The false-alarm probability ``test`` may spend on one record: its share of ``level``."""
    return level * share(test)
