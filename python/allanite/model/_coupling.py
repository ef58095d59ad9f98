"""A channel regression's tests (:mod:`allanite.model.channels`): the coupling's likelihood ratio, the channel and
its quadrature against no coupling (:func:`coupling_test`), and the optional terms, each by its own nested test at
its own share of the level — the quadratic (run also where the coupling's test fails: :func:`quadratic_test`), then
a d(ch)/dt term or a lag, never both (:func:`optional_terms`).
Whittle's frequency-domain likelihood (:mod:`allanite.model._whittle`) throughout."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from scipy.stats import chi2
from scipy.stats import f as f_dist

from . import _whittle as wh
from ._edge import edge_factor
from ._lag import exact_lag, lag_profile, lag_test
from ._recent import Small
from ._regressors import regressor_design
from ._shares import TERM_SHARE

__all__ = [
    "LAG_MARGIN",
    "LAG_STATE_PRICE",
    "BOOT_COST",
    "BOOT_DRAWS",
    "coupling_test",
    "quadratic_test",
    "optional_terms",
    "level_test",
    "bootstrap_scale",
]

#: A lag and a d(ch)/dt term that both describe the channel's phase fit "within noise" of each other when their
#: 2Δℓ differ by at most this (≈ χ²₁'s 95 % quantile, 3.84): the sign of r/c then chooses (:func:`_lag_or_rate`).
LAG_MARGIN = 4.0
#: The lag model weighed against the d(ch)/dt term carries one number more, the lag's state at the record's first
#: sample (:func:`_lag_fit_in_time`): its 2Δℓ is taken less this (Akaike's price of a number, 2).
LAG_STATE_PRICE = 2.0
#: The coupling's F(2, ν) reference is calibrated by a parametric bootstrap when its threshold exceeds the one of
#: a known noise level (χ²₂) by more than this factor: a Satterthwaite ν under ≈ 20 at refine's α.
BOOT_COST = 4.0 / 3.0
#: Null draws of the bootstrap.
BOOT_DRAWS = 200


def _f_test(stat: float, dof: float, alpha: float) -> dict:
    return {
        "statistic": float(stat),
        "threshold": float(f_dist.isf(alpha, 1, dof)),
        "alpha": float(alpha),
        "dof": float(dof),
        "p_value": float(f_dist.sf(max(stat, 0.0), 1, dof)),
    }


def _new_direction(bands, design, s) -> np.ndarray:
    """The last regressor of ``design`` made orthogonal to the others (GLS metric), as a combination."""
    info = design.gram(bands, 1.0 / s)[0]
    v = np.zeros(len(design))
    v[-1] = 1.0
    if len(design) > 1:
        v[:-1] = -np.linalg.solve(info[:-1, :-1], info[:-1, -1])
    return v


def _nested(bands, design, fit_small, alpha, edge: bool = True, bartlett: float | None = None) -> tuple[dict, dict]:
    """Likelihood-ratio test of the last regressor of ``design`` (both models refitted, noise included; the larger
    one never below the smaller: :func:`allanite.model._whittle.nested_fit`), its reference widened by the
    record's edge factor along the new direction (:func:`allanite.model._edge.edge_factor`, at the smaller
    model's noise; ``edge`` False: not here — the caller widens it). The reference is F(1, ν), or with
    ``bartlett`` χ²₁ times that factor (:func:`level_test`)."""
    big = wh.nested_fit(bands, design, fit_small)
    v = _new_direction(bands, design, big["s"])
    dof = wh.noise_dof(bands, big, wh.band_info(bands, design, v))
    test = _f_test(2.0 * (big["loglik"] - fit_small["loglik"]), dof, alpha)
    ref = (lambda x: f_dist.sf(x, 1, dof)) if bartlett is None else (lambda x: chi2.sf(x / bartlett, 1))
    if bartlett is not None:
        test |= {"threshold": bartlett * float(chi2.isf(alpha, 1)), "bartlett": bartlett}
        test |= {"reference": "χ²₁ × Bartlett's factor (the coupling's in-phase bootstrap)"}
        test["p_value"] = float(ref(max(test["statistic"], 0.0)))
    if edge and bands.source is not None:
        widen = _edge_if_passing(test["statistic"], test["threshold"], bands, fit_small, design, v)
        k = widen["factor"]
        test |= {"threshold": test["threshold"] * k, "edge": widen}
        test["p_value"] = float(ref(max(test["statistic"], 0.0) / k))
    return test, big


def _edge_if_passing(stat: float, threshold: float, bands, fit, design, directions) -> dict:
    """The record's edge factor (:func:`allanite.model._edge.edge_factor`) where the statistic passes the reference
    without it; else ``{"factor": 1.0, "computed": False}`` — a factor ≥ 1 can only turn an acceptance into a
    rejection, so below the threshold it changes nothing and its transforms (≈ 2 FFTs of the record per
    direction) are not spent: on a clean record the tests almost never pass."""
    if stat <= threshold:
        return {"factor": 1.0, "ratios": [], "computed": False}
    e = edge_factor(bands, fit, design, directions)
    return {"factor": e["factor"], "ratios": e["ratios"], "computed": True}


def _pair_statistic(bands, null) -> tuple[float, dict]:
    """2Δℓ of the channel and its quadrature against ``null`` (both models' noise refitted), and the pair's fit."""
    one = np.ones(bands.m.size)
    big = wh.nested_fit(bands, wh.Design([0, 0], [one, -1j * one]), null)
    return 2.0 * (big["loglik"] - null["loglik"]), big


def _null_bands(bands, s, rng):
    """Band sums of a record of pure noise of level ``s`` per band beside the same channel (regressor 0): in each
    band the DFT's component along the channel (one complex normal, its sum g = √(s·G)·w) and the rest of its
    power (s · Gamma(m − 1)) — what Whittle's likelihood takes the record to be, drawn exactly."""
    g00 = np.maximum(bands.G[:, 0, 0].real, 0.0)
    has = (g00 > 0).astype(np.float64)
    nb = bands.m.size
    w = has * (rng.standard_normal(nb) + 1j * rng.standard_normal(nb)) / math.sqrt(2.0)
    rest_dof = bands.m - has
    rest = np.where(rest_dof > 0, rng.gamma(np.maximum(rest_dof, 1e-9), 1.0), 0.0)
    g = (np.sqrt(s * g00) * w)[:, None]
    return dataclasses.replace(bands, q=s * (np.abs(w) ** 2 + rest), g=g, G=bands.G[:, :1, :1], compiled=True)


def bootstrap_scale(bands, null, seed: int = 0) -> tuple[float, float]:
    """Bartlett's factors of the coupling's statistic (the pair, 2 dof) and of the in-phase one (1 dof) under the
    null: their means over :data:`BOOT_DRAWS` records of the null fit's noise beside the same channel
    (:func:`_null_bands`; the noise refitted in every draw from a cold start, as on the record: the noise fit's
    optimum depends on where it starts — started at the null fit's amounts, a 3600-sample record's factor read 0.9
    where 2.5 cold) over χ²'s means 2 and 1 — each at least 1. Seeded: the same record gets the same thresholds
    (within a refine found again, not drawn again: the draws read the bands' counts, the channel's power, the
    noise model's shapes and the null's noise level)."""
    key = Small.key(bands.m, bands.G[:, :1, :1], bands.par, bands.basis, null["s"], seed, BOOT_DRAWS)
    hit = _SCALES.get(key)
    if hit is None:
        hit = _SCALES.put(key, _bootstrap_scale(bands, null, seed))
    return hit


#: Bartlett's factors by the bootstrap's inputs, within a refine: where the coupling is not kept, unexplained's
#: channel check tests the same record beside the same channel at the same null fit (the same draws, refitted).
_SCALES = Small(8)


def _bootstrap_scale(bands, null, seed: int) -> tuple[float, float]:
    rng = np.random.default_rng(seed)
    one = regressor_design([], bands.m.size)
    total = np.zeros(2)
    for _ in range(BOOT_DRAWS):
        b = _null_bands(bands, null["s"], rng)
        fit0 = wh.joint_fit(b, wh.Design([], []))
        total += (_pair_statistic(b, fit0)[0], 2.0 * (wh.nested_fit(b, one, fit0)["loglik"] - fit0["loglik"]))
    return max(1.0, float(total[0]) / BOOT_DRAWS / 2.0), max(1.0, float(total[1]) / BOOT_DRAWS)


def coupling_test(bands, null, alpha) -> tuple[dict, dict, dict]:
    """The coupling's test: the channel and its quadrature (Hilbert transform) jointly against no coupling — the
    likelihood ratio 2Δℓ (both models' noise refitted) against 2·F(2, ν) at ``alpha``; ν the Satterthwaite count
    of the channel's information (:func:`allanite.model._whittle.noise_dof`) at the in-phase fit, as the channel's
    test alone had it — the quadrature's information is the same (in band space it is the channel's DFT times −i,
    orthogonal to it and of the same power in every band). Not the count at the pair's own fit: where ν is a few
    (a diurnal temperature, one cycle in the record) the noise refitted beside the quadrature moved it 3.2 → 2.2
    and the threshold 102 → 379 (blind suite 4's 24 h log, its coupling lost).

    Why two degrees of freedom: a channel that reaches the rate through a lag (a thermistor behind the sensing
    element) arrives shifted in phase, and only cos φ of it lines up with the channel itself — at a 600 s lag on
    a 1667 s cycle (66°) the lag-0 test read 6.8 against 12.6 on a coupling 11× its detectable size and
    accepted 0 of 12 records; the pair spans every phase of each band, so a lag (or a pure d(ch)/dt term, or a
    lead) is seen at whatever phase it arrives. One fixed threshold (no maximum over a grid of lags), at the
    same share of ``level`` (docs/channels.md, "The coupling's test").

    Where ν is small the F(2, ν) reference itself is the weak link: it takes the noise level to be a χ²_ν/ν
    estimate independent of the statistic, and at ν ≈ 3 (a 30-min 200 Hz record whose temperature rises with a
    400 s time constant) its threshold is 120 where 2000 null records of the same channel and noise read ≤ 9.4 at
    that α — a coupling at 27.7 was lost. When 2·F(2, ν) exceeds χ²₂'s threshold by more than :data:`BOOT_COST`
    (the reference costs that much power), the reference is χ²₂ scaled by Bartlett's factor from a parametric
    bootstrap under the null fit (:func:`bootstrap_scale`, ``reference`` and ``bartlett`` in the test; ``dof``
    stays the Satterthwaite count, still the coefficient's interval's).

    Returns (the test, the in-phase 1-dof test — what this test was before, kept for the record and for the
    coefficient's interval —, the in-phase fit, from which the optional terms are tested)."""
    in_phase, fit = _nested(bands, regressor_design([], bands.m.size), null, alpha, edge=False)
    stat, big = _pair_statistic(bands, null)
    dof = in_phase["dof"]
    threshold = float(2.0 * f_dist.isf(alpha, 2, dof))
    calibration: dict = {"reference": "2·F(2, ν), ν Satterthwaite"}
    bootstrap = threshold > BOOT_COST * chi2.isf(alpha, 2)
    scale = scale_1 = 1.0
    if bootstrap:
        scale, scale_1 = bootstrap_scale(bands, null)
        threshold = scale * float(chi2.isf(alpha, 2))
        calibration = {"reference": f"χ²₂ × Bartlett's factor, parametric bootstrap ({BOOT_DRAWS} draws)"}
        calibration["bartlett"] = scale
        # the in-phase test alone (unexplained's channel check runs it beside the pair) the same way, χ²₁
        in_phase = in_phase | {"threshold": scale_1 * float(chi2.isf(alpha, 1)), "bartlett": scale_1}
    edges = _pair_edges(bands, null, (stat, threshold), (in_phase["statistic"], in_phase["threshold"]))
    f2 = f1 = 1.0
    if edges is not None:
        calibration["edge"], in_phase = edges[0], in_phase | {"edge": edges[1]}
        f2, f1 = edges[0]["factor"], edges[1]["factor"]
        threshold *= f2
        in_phase["threshold"] *= f1
    in_stat = max(in_phase["statistic"], 0.0)
    if bootstrap:
        p_value = float(chi2.sf(max(stat, 0.0) / scale / f2, 2))
        in_phase["p_value"] = float(chi2.sf(in_stat / scale_1 / f1, 1))
    else:
        p_value = float(f_dist.sf(max(stat, 0.0) / f2 / 2.0, 2, dof))
        in_phase["p_value"] = float(f_dist.sf(in_stat / f1, 1, dof))
    test = {
        "statistic": float(stat),
        "threshold": threshold,
        "alpha": float(alpha),
        "dof": float(dof),
        "p_value": p_value,
        "phase_deg": float(np.degrees(np.arctan2(big["c"][1], big["c"][0]))),
        "in_phase": {
            key: in_phase[key]
            for key in ("statistic", "threshold", "dof", "p_value", "bartlett", "edge")
            if key in in_phase
        },
    } | calibration
    return test, in_phase, fit


def _pair_edges(bands, null, pair: tuple, one: tuple) -> tuple[dict, dict] | None:
    """The edge factors of the pair's test and of the in-phase one, each (statistic, threshold) before it, from one
    computation at the null fit (the in-phase direction is the pair's first): each where its statistic passes
    without it (:func:`_edge_if_passing`), else 1. None where ``bands`` carries no source."""
    if bands.source is None:
        return None
    skip = {"factor": 1.0, "ratios": [], "computed": False}
    if pair[0] <= pair[1] and one[0] <= one[1]:
        return skip, skip
    ones = np.ones(bands.m.size)
    e = edge_factor(bands, null, wh.Design([0, 0], [ones, -1j * ones]), np.eye(2))
    e1 = {"factor": max(1.0, float(e["exact"][0, 0] / e["whittle"][0, 0])), "computed": True}
    e2 = {"factor": e["factor"], "ratios": e["ratios"], "computed": True}
    return (e2 if pair[0] > pair[1] else skip), (e1 if one[0] > one[1] else skip)


def quadratic_test(bands, fit, alpha) -> tuple[dict, dict]:
    """The quadratic's nested test: (ch − mean)² beside the channel against the channel alone (``fit``, the
    in-phase fit), 2Δℓ against F(1, ν) at ``alpha`` (its :data:`TERM_SHARE` of the level once the coupling is
    accepted; where the coupling's test fails, its :data:`FIRST_QUADRATIC` part of the coupling's α). Returns (the
    test with ``kept``, the fit with both columns). Run whether or not the coupling's own test accepts
    (docs/channels.md, "A turnover temperature"): a bias on (T − T₀)² with T₀ inside the swing has almost no
    linear part."""
    nb = bands.m.size
    t_q, big = _nested(bands, regressor_design(["quadratic"], nb), fit, alpha)
    return t_q | {"kept": t_q["statistic"] > t_q["threshold"]}, big


def optional_terms(bands, fit, terms, level, grid, z2, quadratic=None, bartlett=None, *, timed):
    """Quadratic first (``quadratic``: its :func:`quadratic_test` already run), then d(ch)/dt or a lag (never
    both), then — where a d(ch)/dt term alone was kept — the level term itself (:func:`level_test`).
    ``bartlett``: the coupling's in-phase Bartlett factor where its reference was the bootstrap, for the level
    test's. ``timed(keys, lag_s)``: the record's band sums beside the channel lagged in time and the lag's decay
    after it (:func:`allanite.model._lag_time.lag_bands` with ``state``), for weighing a lag against a d(ch)/dt
    term (:func:`_lag_or_rate`).
    Returns (kept keys, fit, lag_s, tests)."""
    nb = bands.m.size
    keys: list = []
    tests: dict = {}
    if "quadratic" in terms:
        q_alpha = TERM_SHARE["quadratic"] * level
        tests["quadratic"], big = quadratic if quadratic is not None else quadratic_test(bands, fit, q_alpha)
        if tests["quadratic"]["kept"]:
            keys, fit = ["quadratic"], big
    design = regressor_design(keys, nb)
    rate_ok, fit_r = False, None
    if "rate_coefficient" in terms:
        t_r, fit_r = _nested(
            bands, regressor_design(keys + ["rate_coefficient"], nb), fit, TERM_SHARE["rate_coefficient"] * level
        )
        rate_ok = t_r["statistic"] > t_r["threshold"]
        tests["rate_coefficient"] = t_r | {"kept": rate_ok}
    lag_s = None
    if "lag_s" in terms:
        t_l = lag_test(bands, design, fit, TERM_SHARE["lag_s"] * level, grid)
        tests["lag_s"] = t_l | {"kept": False}
        if t_l["statistic"] > t_l["threshold"] or rate_ok:
            best, interval = lag_profile(bands, design, fit["s"], grid, z2)
            tests["lag_s"] |= {"lag_s": best, "interval": interval}
            if not rate_ok or _lag_or_rate(keys, fit, fit_r, tests, timed, (grid[0], grid[-1])) == "lag":
                tests["lag_s"]["kept"] = True
                rate_ok, lag_s = False, best
    if rate_ok:
        keys, fit = keys + ["rate_coefficient"], fit_r
    # only beside a d(ch)/dt term alone: a kept lag is the channel's own coupling (c·L_T[ch]), and beside a kept
    # quadratic the level term stays (level_test's docstring)
    if keys == ["rate_coefficient"] and lag_s is None:
        tests["coefficient"], fit = level_test(bands, keys, fit, TERM_SHARE["coefficient"] * level, bartlett)
    return keys, fit, lag_s, tests


def level_test(bands, keys, fit, alpha, bartlett: float | None = None) -> tuple[dict, dict]:
    """The level term's nested test where a d(ch)/dt term (``keys``) carries part of the coupling: the channel
    itself beside it against it alone, 2Δℓ against F(1, ν) at ``alpha`` (its :data:`TERM_SHARE` of the level) —
    or, where the coupling's own reference was the parametric bootstrap (``bartlett``: its in-phase factor,
    :func:`coupling_test`), against χ²₁ times that factor, as the coupling's in-phase test is —, the reference
    widened by the record's edge factor where it passes, as every nested test's. Returns (the test with ``kept``,
    the fit kept: ``fit`` — with the level term — where the test passes, else the model without it, its
    coefficients in the order of ``keys``).

    Why: the coupling's own test (the channel and its quadrature, any phase) accepts a coupling that reaches the
    rate only through d(T)/dt — a fibre-optic gyro's Shupe effect, in quadrature with T on every cycle — and the
    level term was then carried whatever the record said of it, so a d(T)/dt-only coupling was reported with a
    level coefficient that is not there (blind9's FOG: 1.47·10⁻⁵ °/s per °C beside the 0.0237 rate coefficient,
    truth 0; 20 of 20 replicas). A term is claimed only by its own test, the level term too once another carries
    the coupling (docs/channels.md, "The level term").

    Not beside a kept quadratic: (ch − mean)² alone is a parabola about the record's mean, an origin the sensor
    does not know — the linear part is what places the turnover — and over a channel that swings once the two are
    collinear: on blind4's cold start (2.5·10⁻⁴ °/s per °C, 5·10⁻⁵ per °C²) the level term failed beside the
    quadratic, was dropped, and the quadratic alone held out at 1.8·10⁵ %.

    Why the bootstrap's reference where the coupling had it: where ν is small (two daily cycles under flicker and
    rate random walk, ν ≈ 10) F(1, ν) at 0.1 % is 21 where χ²₁'s is 10.8, while the coupling's bootstrap found the
    null statistic at χ²'s size (factor 1.0–1.1)."""
    nb = bands.m.size
    small = wh.joint_fit(bands, regressor_design(keys, nb, level=False))
    design = regressor_design(keys, nb, level=False).plus(0, np.ones(nb))
    test, _big = _nested(bands, design, small, alpha, bartlett=bartlett)
    kept = test["statistic"] > test["threshold"]
    return test | {"kept": bool(kept)}, (fit if kept else small)


def _lag_or_rate(keys, fit, fit_r, tests, timed, bounds: tuple) -> str:
    """Where the d(ch)/dt term passed its test (a phase term beside the channel is established), which of the two
    descriptions of it is kept: ``"lag"`` (the pure lag model c·L_T[ch], the channel lagged in time:
    :func:`_lag_fit_in_time`) or ``"rate"`` (c·ch + r·d(ch)/dt, ``fit_r``) — never both; the choice written into
    ``tests`` (``against_rate``: the lag model's 2Δℓ over the rate model; ``lag_in_time_s``: the T it was weighed
    at; ``rate_over_coefficient``: r/c, s; ``tie``; ``why``). Both models have two numbers (c, T against c, r),
    so the larger likelihood is kept; within :data:`LAG_MARGIN` of each other the record cannot tell them apart at
    the one frequency a cycling channel has (both are a phase shift there), and the sign of the phase decides:
    r/c < 0 is a delay — what a first-order lag is (r ≈ −c·T) — so the lag; r/c > 0 a lead, which no lag makes,
    so the rate term. ``fit``: the model without either (its noise the start of both). The lag model's 2Δℓ is
    taken less :data:`LAG_STATE_PRICE` for its one more number, the lag's state at the first sample.

    Why not the lag's own test first: over a grid of T it pays for the search (the arc length's upcrossings), and
    on a 600 s lag (100 Hz × 10⁶, a 3333 s cycle) it read 13.8 against 20.3 where the rate term read 22.0 against
    14.8 — the lag never stood a chance, the rate term was kept with the coefficient at −52 % (blind9). The lag
    needs no test of its own here: it stands in for a term whose test passed, at the same count of numbers, so on
    a record without coupling it can be kept no more often than the rate term was (docs/channels.md, "A lag or a
    d(ch)/dt term").

    Why in time (r14lagrate): the rate model's d(ch)/dt column is the channel differentiated in time, so it
    describes a cycle's leakage into the neighbouring bins of the tapered transform exactly; the lag weighed as
    the channel's bins times the lag's response at each bin's own frequency did not (a cycle's leakage is
    lagged at the cycle's frequency, not its neighbours'), and that misfit, a few units of 2Δℓ in each bin
    beside a strong cycle, decided the choice: a 150 s lag on a 1000 s cycle (ωT = 0.94, mems50) lost to the
    rate term on 18 of 40 records, the coefficient then −46 %; in time the lag is kept on all 18 (by more than
    :data:`LAG_MARGIN` on 15), the coefficient's median error +0.2 % (benches/results/r14lagrate.md). And with its
    state free: a lag that ran before the record began (a log started while the temperature cycles) leaves
    e^{−t/T} times the difference between its output and the channel at the first sample, which a lag started in
    equilibrium cannot fit and a memoryless d(ch)/dt term does not need — a 4775 s lag on a 10⁴ s cycle (ωT = 3,
    1 Hz × 10⁵) lost to the rate term by 48 and 162 started in equilibrium, won by 15 and 16 free (its price
    paid)."""
    t_l, t_r = tests["lag_s"], tests["rate_coefficient"]
    lag_s, fit_l = _lag_fit_in_time(keys, fit, t_l, timed, bounds)
    margin = 2.0 * (float(fit_l["loglik"]) - float(fit_r["loglik"])) - LAG_STATE_PRICE
    c, r = float(fit_r["c"][0]), float(fit_r["c"][-1])
    ratio = r / c if c != 0.0 else math.copysign(math.inf, r)
    tie = abs(margin) <= LAG_MARGIN
    lag = margin > LAG_MARGIN or (tie and ratio < 0.0)
    t_l |= {"against_rate": margin, "lag_in_time_s": lag_s, "rate_over_coefficient": ratio, "tie": tie}
    sides = f"2Δℓ {margin:+.3g} of the lag over the d(ch)/dt term, r/c {ratio:.3g} s"
    if tie:
        why = f"the two fit within {LAG_MARGIN:g} of each other ({sides}): " + (
            "a delay (r/c < 0), which a lag is" if lag else "a lead (r/c > 0), which no lag is"
        )
    else:
        why = f"it fits better ({sides})"
    (t_l if lag else t_r)["why"] = "kept over the " + ("d(ch)/dt term: " if lag else "lag: ") + why
    (t_r if lag else t_l)["why"] = ("the lag" if lag else "the d(ch)/dt term") + " kept in its place: " + why
    if lag:
        t_r["kept"] = False
    return "lag" if lag else "rate"


def _lag_fit_in_time(keys, fit, t_l, timed, bounds: tuple) -> tuple[float, dict]:
    """The pure lag model on the band sums of the channel lagged in time, its state at the first sample free
    (``timed(keys, T)``: the lag's decay e^{−t/T} the column after the model's): T refined from the profile's
    (``t_l["lag_s"]``) at ``fit``'s noise (:func:`allanite.model._lag.exact_lag`, as the removal's), then
    coefficients and noise fitted jointly at that T — the better of a cold start and one from ``fit``'s noise (the
    noise fit's optimum depends on where it starts: on one mems50 record the cold start ended 130 below).
    Returns (T, the fit)."""
    nb = fit["s"].size
    design = regressor_design(keys, nb)
    design = design.plus(len(design), np.ones(nb))

    def objective(lag_s: float) -> float:
        info, sc = design.gram(timed(keys, lag_s), 1.0 / fit["s"])
        return float(sc @ np.linalg.solve(info, sc))

    lag_s = exact_lag(objective, float(t_l["lag_s"]), tuple(t_l["interval"]), bounds)[0]
    b = timed(keys, lag_s)
    cold = wh.joint_fit(b, design)
    start = wh.joint_fit(b, design, fixed_s=fit["s"]) | {"amounts": fit["amounts"]}
    warm = wh.joint_fit(b, design, start=start)
    return lag_s, (warm if warm["loglik"] > cold["loglik"] else cold)
