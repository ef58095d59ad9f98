"""The ``"telegraph"`` removal in time: random telegraph (burst, popcorn) noise found by the kurtosis of its Allan
differences and removed as its decoded two-level switching (:mod:`allanite.model.telegraph`).

A telegraph has a Gauss–Markov spectrum, so the Allan curve takes it for a Gauss–Markov term; but its few long
visits to one level make the record's windows differ far more than a Gaussian process of the same spectrum's
do, and the change-point and mean-step checks, calibrated on Gaussian records, then fire on a stationary
process (``benches/refine_telegraph.py``: false change points on 4 of 10 telegraph records, a step of the mean
said on 9 of 10, none on their Gaussian twins). Removed in time, the samples left are the Gaussian rest.

Taken where (1) the kurtosis test passes at its share of ``level`` (:data:`.levels.TIME_SHARES`), (2) a second
level is decoded whose distance from the first is at least :data:`allanite.model.telegraph.SEPARATION` σ of the
blocks' noise, (3) each level is visited at least :data:`MIN_VISITS` times in full (a step or two of the mean is
not a telegraph), (3b) the dwells are not regular in both states (coefficient of variation below :data:`REGULAR_CV`:
a pulse train is a periodic effect, its lines for the periodic candidate or ``unexplained``), and (4) the samples
less the decoded switching pass the kurtosis test at the octave it fired at
— the two levels explain the heavy tail; a noise level that changes along the record, or spikes, leave it. The
loop's held-out test in time (refitting the amplitude on alternate blocks, the states fixed) and the materiality on
the Allan curve then decide, as for every removal. Where it is not separable (switching fast against the white
noise, levels buried) nothing is taken and the Gauss–Markov curve term stays.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from ...analysis import avar
from .. import telegraph as tg
from ._tracking import heldout_variance_ratio
from .calibrated import tested
from .levels import alpha

__all__ = ["MIN_VISITS", "REGULAR_CV", "telegraph_removal"]

#: Complete visits to each level the fit must see (its dwells' intervals come from their count).
MIN_VISITS = 3
#: Dwells this regular in both states (coefficient of variation below it; an exponential dwell's is 1) are a pulse
#: train's, a periodic effect: declined. Exponential dwells read below it in both states with probability ≈ 0.5 % at
#: three visits each (7.4 % each), 10⁻⁸ at ten (simulated).
REGULAR_CV = 0.3


def _declined(f: dict | None, y: np.ndarray, fs: float, r: dict) -> tuple[str | None, dict]:
    """Why the fit ``f`` is no telegraph (None if it is one), and the kurtosis of the samples less it at the octave
    the test found the tail at (test ``r``): the two levels must explain that tail. (At finer τ the visits shorter
    than the blocks it was read at, missed, may leave a tail of their own: on ``benches/refine_telegraph.py``'s seed
    5000 z 5.0 against 4.24 at τ 0.64 s, where the test's 30.9 stood at 1.28 s.)"""
    if f is None:
        return "no second level in the block means", {}
    if not f["separation"] >= tg.SEPARATION:
        return f"the levels stand {f['separation']:.3g} σ of the blocks' noise apart (< {tg.SEPARATION:g})", {}
    if min(f["visits"].values()) < MIN_VISITS:
        return f"complete visits {f['visits']} (< {MIN_VISITS} to each level)", {}
    cv = f["dwell_cv"]
    if all(c < REGULAR_CV for c in cv):  # NaN compares False: a state of one complete run is not judged regular
        return (
            f"the dwells are regular (coefficient of variation {cv[0]:.2g} low and {cv[1]:.2g} high; a telegraph's are "
            "exponential, ≈ 1): a pulse train, periodic"
        ), {}
    m = int(r["m"])
    less = y - f["component"]
    z, _ne, _g2 = tg.kurtosis_z(np.diff(less[: (less.size // m) * m].reshape(-1, m).mean(axis=1)))
    left = {"z": z, "threshold": r["threshold"], "tau": r["tau"]}
    if z > r["threshold"]:
        return "the samples less the two levels still fail the kurtosis test at its τ", left
    return None, left


def telegraph_removal(ctx) -> Iterator[dict]:
    """The ``Removal`` fields of a telegraph in ``ctx.y`` (a :class:`.removals.RemovalContext`), if one is found;
    what turned it down said through ``ctx.consider`` otherwise."""
    y, fs, a = ctx.y, ctx.fs, alpha("telegraph", ctx.level)
    r = tg.telegraph_test(y, fs, a)
    test = tested("kurtosis_z", r["z"], r["threshold"], a)
    if not r["accepted"]:
        ctx.consider("telegraph", {"test": test, "tau": r["tau"]})
        return
    f = tg.telegraph_fit(y, fs, r["m"])
    why, left = _declined(f, y, fs, r)
    if why is not None or f is None:
        ctx.consider("telegraph", {"test": test, "tau": r["tau"], "rejected": why, "after": left})
        return
    s, base = f["states"], f["baseline"]

    def refit(z, idx):  # the states as decoded on the whole record; the amplitude from the held-in samples
        r_in, s_in = z - base[idx], s[idx]
        amp = float(np.mean(r_in[s_in == 1]) - np.mean(r_in[s_in == 0])) if 0 < s_in.mean() < 1 else 0.0
        mean_s = float(np.mean(s))
        return lambda i: amp * (s[i] - mean_s)

    params = {k: f[k] for k in ("amplitude", "dwell_low", "dwell_high")}
    taus = np.asarray([o["tau"] for o in r["octaves"]] + [2.0 * r["octaves"][-1]["tau"]])
    evidence = {
        "domain": "time",
        "test": test,
        "tau": r["tau"],
        "octaves": r["octaves"],
        "block_samples": f["block"],
        "separation_sigma": f["separation"],
        "visits": f["visits"],
        "after": left,
        "gauss_markov_equivalent": tg.telegraph_gm(**params),
        "avar_tau_s": taus.tolist(),
        "avar_removed": avar(f["component"], fs, taus=taus).avar.tolist(),
        "avar_telegraph": tg.telegraph_avar(taus, **params).tolist(),
    }
    yield {
        "effect": "telegraph",
        "component": f["component"],
        "refit": refit,
        "params": params,
        "intervals": f["intervals"],
        "evidence": evidence,
        "n_fitted": 3,
        "heldout_in_time": heldout_variance_ratio(y, refit),
        "on_curve": True,
    }
