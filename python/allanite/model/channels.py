"""The rate regressed on another channel of the log (a temperature, an accelerometer), tested against the
record's own noise — slow channels and fast ones alike.

:func:`regress_channel` estimates the coupling and the noise together by Whittle's frequency-domain likelihood
(:mod:`allanite.model._whittle`): the record and the channel differenced and tapered, their DFT pooled into
bands, the noise PSD of the differenced record modelled by the IEEE-952 terms (Q, N, B, K, plus Gauss–Markov
terms) in the low bands and by each band's own level above. The coefficient is the generalised least-squares
estimate weighted by that PSD, the noise is refitted on y − ĉ·ch, and the two alternate until the likelihood
settles — the noise never takes the channel's share first. The test is the likelihood ratio 2Δℓ of the
channel and its quadrature (its Hilbert transform: every phase of each band) against no coupling, referred to
2·F(2, ν): ν is the effective number of degrees of freedom of the noise level the coupling is weighed against
(a Satterthwaite count from the noise fit's own covariance), so a channel that moves only at the lowest
frequencies, where a random walk's level is known to ±20 %, is tested as such — and where ν is so small that
2·F(2, ν) costs power (a temperature rising once within the record: ν ≈ 3, threshold ≈ 100), against χ²₂ times
Bartlett's factor from a parametric bootstrap of the statistic (:func:`allanite.model._coupling.bootstrap_scale`,
docs/channels.md). Every reference is widened where Whittle's independent bins understate the statistic's null
variance — a channel whose change sits at the record's edge, where the differenced noise's end term is coherent
across the lowest bins — by the exact variance of its score under the fitted noise (:mod:`allanite.model._edge`;
docs/channels.md, "The record's edges"). The quadrature is there for a
channel that reaches the rate shifted in phase — through a lag, a lead, a d(ch)/dt term — which a test of the
channel alone sees only as cos φ of its size (:func:`coupling_test`). O(N log N) (one FFT of the record and
one per regressor).

Why not within time blocks (the test it replaces, :func:`allanite.model.tracing.regression_fit`): de-meaning 8
blocks takes out the slow wander the channel and the noise share, and with it the slow channel itself — a
temperature that moves within one or two blocks leaves ≈ 1.25 effective degrees of freedom and a t threshold of
64. Here the wander is not removed but weighed: a random walk's and flicker's power at each frequency is in S.

A channel as loggers write it — quantised in value (0.5, 1/16, 1/340 °C), read at 1 Hz and held on a faster rate
log — is read back first as the quantity it samples (:mod:`allanite.model._staircase`: the quantum, the hold and
a slow staircase detected from the channel itself; the readings at their own instants, a staircase's crossings
between its steps): the hold's half-period delay, its d/dt spike train and a slow staircase's sawtooth are
measurement error of the regressor, and the optional terms fitted them (:attr:`ChannelRegression.form`,
docs/channels.md "Quantised and held channels").

Optional terms, each kept only by its own nested test at its own share of the level:

- ``quadratic`` — on (ch − mean)² (per channel unit²), the mean the channel's over the whole record
  (``terms["quadratic"]["t_ref"]``; the linear coefficient is then the slope there, :func:`centring`):
  likelihood ratio, F(1, ν); run also where the coupling's
  test fails, and where it passes then the coupling is accepted by it (a turnover temperature: a bias on
  (T − T₀)² with T₀ inside the swing has no linear part; T₀ = mean − b₁/(2·b₂) with its interval in
  ``terms["quadratic"]["turnover"]``; docs/channels.md "A turnover temperature");
- ``rate_coefficient`` — on d(ch)/dt (per channel unit/s, central differences): likelihood ratio, F(1, ν);
- ``lag_s`` — the rate follows the channel through a first-order lag of that time constant (s): the family
  c·ch + c_L·(L_T[ch] − ch)/T over T on a log grid (T → 0 is the d(ch)/dt direction), its largest score
  statistic against the t-process upcrossing bound (Davies 1987; Worsley 1994: P(F(1, ν) > u) +
  (V/π)·(1 + u/ν)^{−(ν−1)/2}, V the arc length of the whitened family over the grid). A lag and a d(ch)/dt
  term are nearly collinear — never both: where the rate term passes its test, the pure lag model c·L_T[ch]
  is weighed against it (two numbers each, the lag's state at the first sample one more, priced
  :data:`~allanite.model._coupling.LAG_STATE_PRICE`; the channel lagged in time) and the larger likelihood
  kept, within :data:`LAG_MARGIN` in 2Δℓ the phase's sign deciding (r/c < 0, a delay: the lag; r/c > 0, a
  lead: the rate term); where only the lag's test passes, the lag (docs/channels.md, "A lag or a d(ch)/dt
  term"). A lag not kept
  (and no d(ch)/dt term in its place) is still profiled: where the profile prefers a lag to none at the
  intervals' level, the removal takes the channel through it (:attr:`ChannelRegression.removal_lag_s`; the lag
  itself is reported as not resolved, under ``terms["lag_s"]["profiled"]``, not as a param) — at lag 0 the
  coupling's phase error stays in the residual (:mod:`allanite.model._lag`).

- the level term itself (``coefficient``), where a d(ch)/dt term alone is kept: the channel beside it against it
  alone, at its own :data:`TERM_SHARE` (:func:`allanite.model._coupling.level_test`) — a coupling through d(ch)/dt
  only (a fibre-optic gyro's Shupe effect) is reported with that term only (docs/channels.md, "The level term").

Intervals: the coefficients ±t_ν quantile × their standard error — the GLS estimator's sandwich under the noise
refitted with the power the coefficients took from their bands given back (a restricted estimate), the score's
variance exact at the record's edges (:mod:`allanite.model._gls_cov`: the inverse Fisher information at the
fitted noise covered 52–57 % at 68 %); where a lag is used, with the lag free (the lag is estimated from the same
record; :mod:`allanite.model._lag_time`); the lag from its profile likelihood in time, at that restricted noise
beside the lagged channel (docs/channels.md, "Intervals that cover").
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import partial
from itertools import islice

import numpy as np
from scipy.stats import t as t_dist

from .._validate import check_fs, check_probability
from ..errors import InputError, ParameterError
from . import _whittle as wh
from ._coupling import LAG_MARGIN, coupling_test, optional_terms, quadratic_test
from ._edge import EdgeSource
from ._gls_cov import interval_cov
from ._lag import lag_grid, lagged, unresolved_lag
from ._lag_time import lag_bands, lag_in_time
from ._regressors import (
    CHANNEL_SNR,
    channel_signal,
    read_channel,
    regressor_design,
    regressor_iter,
    regressors,
)
from ._rfft import band_limited
from ._shares import FIRST_QUADRATIC, TERM_SHARE
from ._staircase import ChannelForm, reconstructed

__all__ = [
    "regress_channel",
    "ChannelRegression",
    "heldout_ratio",
    "check_channel",
    "slow_share",
    "is_slow",
    "terms_before_after",
    "SUBTERMS",
    "TERM_SHARE",
    "SLOW_SHARE",
    "lagged",
    "LAG_MARGIN",
    "CHANNEL_SNR",
    "channel_signal",
    "centring",
]

#: Optional terms of a channel regression, in the order they are tried.
SUBTERMS = ("quadratic", "rate_coefficient", "lag_s")
#: Default per-record level and the default share of it for the coupling's test (refine's time-domain share).
LEVEL = 0.05
ALPHA = 0.075 * LEVEL
#: Share of the channel's information (Σ_b |Z_b|²/S_b) whose bands the held-out ratio is summed over.
HELDOUT_INFO = 0.99
#: A channel is slow when at least this share of its variance is between the means of 8 blocks in time (the
#: block test's blind spot, :func:`allanite.model.tracing.regression_fit`).
SLOW_SHARE = 0.5
#: Shortest record.
MIN_SAMPLES = 64


def check_channel(name: str, ch, n: int) -> np.ndarray:
    """The channel as float64 of the rate's length ``n``, finite and not constant, or an AllaniteError naming it.

    One sample per rate sample: a 1-D array or list of real numbers (a single column or row of a 2-D array too);
    a scalar, a string, None, a complex or multi-column array are refused, not converted."""
    what = f"channel {name!r} must be one real number per sample of the rate (a 1-D array of {n})"
    try:
        a = np.asarray(ch)
        x = a.astype(np.float64) if a.dtype.kind in "biuf" else None
    except (TypeError, ValueError):
        x = None
    if x is None:
        kind = type(ch).__name__ if not isinstance(ch, np.ndarray) else f"an array of dtype {ch.dtype}"
        raise ParameterError(f"{what}, got {kind}")
    if x.ndim == 0 or (x.ndim > 1 and sorted(x.shape)[-2] > 1):
        raise ParameterError(f"{what}, got shape {x.shape}")
    x = x.ravel()
    if x.size != n:
        raise ParameterError(f"channel {name!r} has {x.size} samples; the rate has {n}")
    bad = np.flatnonzero(~np.isfinite(x))
    if bad.size:
        raise InputError(
            f"channel {name!r} has non-finite samples ({bad.size}; the first at index {bad[0]}: {float(x[bad[0]])!r}); "
            "every sample must be finite"
        )
    if not np.ptp(x) > 0:
        raise ParameterError(
            f"channel {name!r} is constant (every sample {float(x[0])!r}): there is nothing to regress on"
        )
    return x


def slow_share(x, blocks: int = 8) -> float:
    """Share of the channel's variance that lies between the means of ``blocks`` blocks in time — what
    de-meaning each block (the within-block test) throws away. A temperature that rises once or wanders as a
    random walk: ≈ 0.9; a ±1 g multi-position profile turned every few minutes, an accelerometer's noise: ≈ 0."""
    x = np.asarray(x, dtype=np.float64)
    per = x.size // blocks
    xb = x[: per * blocks].reshape(blocks, per)
    total = float(np.sum((xb - xb.mean()) ** 2))
    within = float(np.sum((xb - xb.mean(axis=1, keepdims=True)) ** 2))
    return 1.0 - within / total if total > 0 else 0.0


def is_slow(x, blocks: int = 8) -> bool:
    """Whether a channel is slow (:data:`SLOW_SHARE`): tested by :func:`regress_channel`, not within blocks."""
    return slow_share(x, blocks) >= SLOW_SHARE


def terms_before_after(before, after) -> dict:
    """The noise terms of two :class:`~allanite.model.fitting.NoiseFit` — before and after a removal — side
    by side: ``{"terms": [...], "before": {term: (value, lo, hi)}, "after": {...}, "unit": ...}`` in the
    input unit's base form (IEEE-952 units where the fits have them, under ``"ieee"``)."""
    out: dict = {"terms": list(before.coefficients), "before": {}, "after": {}, "ieee": {"before": {}, "after": {}}}
    for key, f in (("before", before), ("after", after)):
        for name, c in f.coefficients.items():
            out[key][name] = (float(c.value), float(c.ci[0]), float(c.ci[1]))
            if c.ieee is not None and c.ieee_ci is not None:
                out["ieee"][key][name] = (float(c.ieee), float(c.ieee_ci[0]), float(c.ieee_ci[1]), c.ieee_unit)
    return out


def _check_rate(y, fs) -> tuple[np.ndarray, float]:
    fs = check_fs(fs)
    try:
        y = np.asarray(y, dtype=np.float64).ravel()
    except (TypeError, ValueError):
        raise InputError(f"the rate must be an array of numbers, got {type(y).__name__}") from None
    if y.size < MIN_SAMPLES:
        raise InputError(f"a channel regression needs at least {MIN_SAMPLES} samples, got {y.size}")
    bad = np.flatnonzero(~np.isfinite(y))
    if bad.size:
        raise InputError(f"the rate has non-finite samples (the first at index {bad[0]}: {y[bad[0]]!r})")
    return y, fs


@dataclass(frozen=True)
class ChannelRegression:
    """A channel's coupling into the rate, with its tests.

    ``params``: ``coefficient`` (rate unit per channel unit) and the optional terms kept — ``quadratic`` (per
    channel unit²), ``rate_coefficient`` (per channel unit/s), ``lag_s`` (s); ``intervals`` the same keys;
    ``test``: the coupling's likelihood ratio, the channel and its quadrature together (``statistic``, 2Δℓ),
    ``threshold`` (2·F(2, ν)), ``alpha``, ``dof`` (ν), ``p_value``, ``phase_deg`` (the phase by which the
    coupling follows the channel, positive for a lag) and ``in_phase`` (the channel alone: 2Δℓ against F(1, ν),
    the test before the quadrature was added), ``accepted_by`` (``"channel"``, or ``"quadratic"``: the
    quadratic's own test, under ``quadratic``, where the channel's failed — a turnover); ``terms``: each optional
    term's test (``statistic``, ``threshold``, ``alpha``, ``dof``, ``kept``, and why not; the quadratic's
    ``turnover``: T₀, whether inside the channel's range, its interval there; where kept, ``t_ref``: the channel's
    mean over the record, the value at which ``coefficient`` is the slope); ``accepted``: the coupling passed
    its test or the quadratic's (optional terms are tried only then).
    ``removal_lag_s``: the lag the component runs the channel through — the kept ``lag_s``, or a lag its test
    did not resolve but the profile prefers to none (``terms["lag_s"]["profiled"]``, not a param), or None.
    ``form``: how the channel was written (:class:`allanite.model._staircase.ChannelForm`: quantum, hold, a slow
    staircase); every use of the channel reads it back the same way first.
    """

    name: str
    accepted: bool
    params: dict
    intervals: dict
    test: dict
    terms: dict
    fs: float
    mean: float
    quad_mean: float
    noise: dict = field(default_factory=dict)
    signal_bands: list | None = None
    removal_lag_s: float | None = None
    form: ChannelForm = field(default_factory=ChannelForm)

    def columns(self, ch) -> np.ndarray:
        """The regressors of the kept terms, (k, n), for the channel samples ``ch`` (the whole record: a lag
        runs along it): the channel's signal bands (through the lag), then its square and its derivative where
        kept; the fit's means."""
        x = reconstructed(np.asarray(ch, dtype=np.float64), self.form)
        xs = band_limited(x, self.fs, self.signal_bands)
        cols = regressors(xs, self.mean, self.quad_mean, self.fs, self.removal_lag_s)
        keep = [i for i, k in ((0, "coefficient"), (1, "quadratic"), (2, "rate_coefficient")) if k in self.params]
        return np.array([cols[i] for i in keep])

    def lag_note(self) -> str | None:
        """In words, where the removal's lag is not a kept term: the lag profiled for the removal, or None."""
        prof = self.terms.get("lag_s", {}).get("profiled")
        if self.removal_lag_s is None or "lag_s" in self.params or prof is None:
            return None
        t = self.terms["lag_s"]
        lo, hi = prof["interval"]
        return (
            f"a lag not resolved at its test's level (statistic {t['statistic']:.3g} against {t['threshold']:.3g}); "
            f"the removal takes the channel through the profile's {prof['lag_s']:.4g} s (interval {lo:.4g}–{hi:.4g} s, "
            f"2Δℓ {prof['gain']:.3g} over no lag) — not claimed as a term"
        )

    def coefficients(self) -> np.ndarray:
        """The kept terms' coefficients, in the order of :meth:`columns`."""
        return np.array([self.params[k] for k in ("coefficient", "quadratic", "rate_coefficient") if k in self.params])

    def component(self, ch) -> np.ndarray:
        """What the coupling puts into the rate, for the channel samples ``ch`` (the whole record)."""
        return self.coefficients() @ self.columns(ch)

    def refit(self, samples, indices, ch):
        """The same terms (and lag) refitted on ``samples`` taken at ``indices`` of the record (a held-in part:
        alternate blocks joined end to end), the regressors built on the whole channel ``ch`` first; returns the
        component as a function of sample indices (for a held-out error in time)."""
        cols = self.columns(ch)
        z = np.asarray(samples, dtype=np.float64)
        sub = cols[:, np.asarray(indices)]
        n_use = wh.usable_length(z.size)
        bands = wh.spectra(z[:n_use], list(sub[:, :n_use]), self.fs)
        one = np.ones(bands.m.size)
        c = wh.joint_fit(bands, wh.Design(list(range(len(cols))), [one] * len(cols)))["c"]
        comp = c @ cols
        return lambda i: comp[np.asarray(i)]


def _params(fit, keys, dofs, confidence, lag, level: bool = True):
    """The kept terms' values and intervals (t quantile at each term's ν): the level term ``coefficient`` where
    ``level`` (its nested test kept it, or none was run), then the optional terms of ``keys``, then the lag."""
    names = ["coefficient"] * level + [k for k in ("quadratic", "rate_coefficient") if k in keys]
    params, intervals = {}, {}
    for i, k in enumerate(names):
        c, se = float(fit["c"][i]), math.sqrt(max(float(fit["cov"][i, i]), 0.0))
        half = float(t_dist.isf((1.0 - confidence) / 2.0, dofs[k])) * se
        params[k], intervals[k] = c, (c - half, c + half)
    if lag is not None:
        params["lag_s"], intervals["lag_s"] = lag
    return params, intervals


def regress_channel(
    y,
    ch,
    fs: float,
    *,
    name: str = "channel",
    alpha: float = ALPHA,
    level: float = LEVEL,
    terms=SUBTERMS,
    confidence: float = 0.683,
) -> ChannelRegression:
    """The rate ``y`` regressed on the channel ``ch`` against the record's own noise (module docstring).

    Parameters
    ----------
    y, ch : array_like
        Rate samples and the channel's samples (same length; a temperature, an accelerometer axis).
    fs : float
        Sampling rate, Hz.
    name : str
        The channel's name, for messages.
    alpha : float
        Level of the coupling's decision (default 0.375 %: refine's time-domain share of the 5 % per-record
        level): the channel and its quadrature at 1 − :data:`~allanite.model._shares.FIRST_QUADRATIC` of it, the
        quadratic where that fails at the rest (all of it to the pair when ``quadratic`` is not among ``terms``).
    level : float
        Per-record level; each optional term is tested at its :data:`TERM_SHARE` of it.
    terms : sequence of {"quadratic", "rate_coefficient", "lag_s"}
        Optional terms to try once the coupling is accepted (default all).
    confidence : float
        Level of the intervals (default 68.3 %).

    Returns
    -------
    ChannelRegression

    Examples
    --------
    >>> import numpy as np, allanite
    >>> from allanite.model.channels import regress_channel
    >>> t = np.arange(90_000.0)                                          # 25 h at 1 Hz
    >>> temp = 5 + 15 / (1 + np.exp(-(t - 30_000) / 2_500))              # °C, a warm-up in one block
    >>> y = allanite.simulate(t.size, 1.0, N=1.5e-3, B=1e-4, K=3e-6, seed=2) + 4.5e-4 * temp
    >>> r = regress_channel(y, temp, 1.0, name="temp")
    >>> r.accepted, round(r.params["coefficient"] * 1e4, 1)            # rad/s per °C, ×1e4
    (True, 4.4)
    """
    y, fs = _check_rate(y, fs)
    x = check_channel(name, ch, y.size)
    alpha, level = check_probability(alpha, "alpha"), check_probability(level, "level")
    confidence = check_probability(confidence)
    terms = _check_subterms(terms)
    y, form, floor, sig, xs, t_ref, mean, quad_mean, bands = channel_bands(y, x, fs)
    null = wh.joint_fit(bands, wh.Design([], []))
    # where the quadratic is tried beside it, the coupling's α is shared: the pair gets 1 − FIRST_QUADRATIC of it
    a_quad = FIRST_QUADRATIC * alpha if "quadratic" in terms else 0.0
    test, in_phase, fit = coupling_test(bands, null, alpha - a_quad)
    accepted, quad = _first_test(bands, fit, test, a_quad, terms)
    keys, lag_s, tests, removal_lag = [], None, {}, None
    if accepted:
        z2 = float(t_dist.isf((1.0 - confidence) / 2.0, in_phase["dof"])) ** 2
        boot = test["in_phase"].get("bartlett") if "bartlett" in test else None  # the coupling's bootstrap factor
        grid = lag_grid(y.size, fs)
        timed = partial(lag_bands, y, xs, (mean, quad_mean), fs, state=True)  # (keys, T): lagged in time
        keys, fit, lag_s, tests = optional_terms(bands, fit, terms, level, grid, z2, quad, boot, timed=timed)
        removal_lag = lag_s if lag_s is not None else _removal_lag(bands, fit, keys, tests, grid, z2)
        if removal_lag is not None:
            removal_lag, fit = lag_in_time(y, xs, (mean, quad_mean), fs, keys, fit["s"], tests["lag_s"], z2)
    level_kept = tests.get("coefficient", {}).get("kept", True)  # False where the level term's own test dropped it
    if removal_lag is None:
        design = regressor_design(keys, bands.m.size, level_kept)
        fit = fit | {"cov": interval_cov(bands, design, fit, exact=accepted)[0]}
    lag = (removal_lag, tests["lag_s"]["interval"]) if lag_s is not None else None
    dofs = {"coefficient": in_phase["dof"]} | {k: tests[k]["dof"] for k in keys}
    params, intervals = _params(fit, keys, dofs, confidence, lag, level_kept)
    if "quadratic" in keys:  # the turnover and the slope's reference in the channel's own frame (centring())
        span = (float(xs.min()) + t_ref - mean, float(xs.max()) + t_ref - mean)
        tests["quadratic"] |= {"t_ref": t_ref, "turnover": _turnover(fit, t_ref, span, dofs, confidence)}
    # the noise amounts are not read as IEEE-952 terms: over the parametric bands' few octaves K, B and the GM shapes
    # trade against each other (their sum is what is used); the terms before/after come from the Allan fits
    noise = {"channel_noise": math.sqrt(floor), "whittle_loglik_gain": float(fit["loglik"] - null["loglik"])}
    return ChannelRegression(
        name, bool(accepted), params, intervals, test, tests, fs, mean, quad_mean, noise, sig, removal_lag, form
    )


def channel_bands(y: np.ndarray, x: np.ndarray, fs: float) -> tuple:
    """The record and channel as :func:`regress_channel` tests them: both cut to the usable length, the channel's
    form detected and read back, its signal bands, the band-limited channel ``xs`` with the channel's mean over
    the whole record ``t_ref`` and its centring (that mean in ``xs``'s frame, :func:`centring`: the channel read
    back whole once, here, for both) and mean square about it, and the Whittle band sums of ``y`` with the three
    regressors. Returns (y, form, floor, sig, xs, t_ref, mean, quad_mean, bands)."""
    n_use = wh.usable_length(y.size)
    form, floor, sig, xs = read_channel(x[:n_use], fs)
    t_ref, mean = centring(x, xs, form)
    y = y[:n_use]
    quad_mean = float(np.mean((xs - mean) ** 2))
    bands = wh.spectra(y, regressor_iter(xs, mean, quad_mean, fs, None), fs)
    bands.source = EdgeSource(lambda i: next(islice(regressor_iter(xs, mean, quad_mean, fs, None), i, None)))
    return y, form, floor, sig, xs, t_ref, mean, quad_mean, bands


def centring(x: np.ndarray, xs: np.ndarray, form: ChannelForm) -> tuple[float, float]:
    """Where the linear coefficient is the slope when a quadratic is kept: ``t_ref``, the channel's mean over the
    whole record as read back (``x`` all of it; :func:`allanite.model._staircase.reconstructed`), and that value
    in the frame of ``xs`` (the band-limited channel over the usable prefix, :func:`channel_bands`), which the
    regressors are centred on. Returns (t_ref, the centring in ``xs``'s frame).

    Why not ``xs``'s own mean (before r13swing): that is the mean over the usable prefix only
    (:func:`allanite.model._whittle.usable_length` drops up to 2.3 % at the end above 10⁶ samples: 4671 of 10⁶), and
    b₁·(x − m) + b₂·(x − m)² has the slope b₁ at x = m, so the reported coefficient was the slope at a value the
    user never asked for, 2·b₂·δm away: on a temperature going once 10 → 40 → 10 °C over 4·10⁶ samples (blind10's
    float32 gyro) the dropped end near 10 °C put m 0.07 °C above the record's mean, +4 % of the linear coefficient
    (docs/channels.md, "The linear coefficient beside a quadratic"). ``xs`` is offset from the channel by what its
    band limit took (0.14 °C on blind4's cold start), hence the frame. Without a lag, the columns' span — and so
    every test and the removed component — does not depend on m (d(x − m)² = dx² − 2m·dx)."""
    xr = reconstructed(x, form)
    t_ref = float(np.mean(xr))
    return t_ref, t_ref + float(np.mean(xs)) - float(np.mean(xr[: xs.size]))


def _first_test(bands, fit, test: dict, a_quad: float, terms) -> tuple[bool, tuple | None]:
    """Whether the coupling is accepted: by its own test (the channel and its quadrature), or — where that
    fails and ``quadratic`` is among ``terms`` — by the quadratic's nested test at ``a_quad`` (its part of the
    coupling's α, :data:`allanite.model._shares.FIRST_QUADRATIC`)
    (:func:`allanite.model._coupling.quadratic_test`), written into ``test`` (``"quadratic"``, and
    ``"accepted_by"``: ``"channel"`` or ``"quadratic"``). Returns (accepted, the quadratic's (test, fit) when run
    here, for :func:`optional_terms` not to run it again).

    Why: a bias on (T − T₀)² with the turnover T₀ inside the swing has almost no linear part — the channel's test
    read 0.19 against 13.7 on a 4·10⁻⁵ °/s per °C² turnover at 25 °C of a 15–35 °C cycle, and the quadratic was
    never tried. Its α is part of the coupling's own: the coupling is accepted by either test, so the two together
    spend the coupling's α (r10wnull; before, the quadratic's 0.1 % was spent beside it on every record with a
    slow channel — docs/channels.md, "A turnover temperature")."""
    if test["statistic"] > test["threshold"]:
        test["accepted_by"] = "channel"
        return True, None
    if "quadratic" not in terms:
        return False, None
    t_q, big = quadratic_test(bands, fit, a_quad)
    test["quadratic"] = {k: t_q[k] for k in ("statistic", "threshold", "alpha", "dof", "p_value")}
    if not t_q["kept"]:
        return False, None
    test["accepted_by"] = "quadratic"
    return True, (t_q | {"accepted_the_coupling": True}, big)


def _turnover(fit, mean: float, span: tuple[float, float], dofs: dict, confidence: float) -> dict:
    """The channel's value where the fitted b₁·(x − mean) + b₂·(x − mean)² is flat, T₀ = mean − b₁/(2·b₂), with a
    delta-method interval (t quantile at the quadratic's ν): ``{"value", "interval", "inside"}`` — ``inside``
    when T₀ lies within the channel's range ``span`` (a turnover temperature; outside it the curve is only bent
    and T₀ an extrapolation, reported without an interval)."""
    b1, b2 = float(fit["c"][0]), float(fit["c"][1])
    if b2 == 0.0:
        return {"value": None, "interval": None, "inside": False}
    t0 = mean - b1 / (2.0 * b2)
    inside = span[0] <= t0 <= span[1]
    if not inside:
        return {"value": t0, "interval": None, "inside": False}
    g = np.array([-1.0 / (2.0 * b2), b1 / (2.0 * b2 * b2)])
    se = math.sqrt(max(float(g @ np.asarray(fit["cov"])[:2, :2] @ g), 0.0))
    half = float(t_dist.isf((1.0 - confidence) / 2.0, dofs["quadratic"])) * se
    return {"value": t0, "interval": (t0 - half, t0 + half), "inside": True}


def _check_subterms(terms) -> tuple:
    """``terms`` as a tuple of names of :data:`SUBTERMS` (one name alone too), or a ParameterError naming the
    first unknown one."""
    terms = (terms,) if isinstance(terms, str) else tuple(terms)
    bad = [t for t in terms if t not in SUBTERMS]
    if bad:
        raise ParameterError(f"unknown channel regression term {bad[0]!r}; allowed: {', '.join(SUBTERMS)}")
    return terms


def _removal_lag(bands, fit, keys, tests, grid, z2) -> float | None:
    """The lag the removal takes when the lag's test did not keep one (and no d(ch)/dt term stands in for it):
    the profile's best T where it beats no lag by more than the intervals' 2Δℓ
    (:func:`allanite.model._lag.unresolved_lag`), recorded under ``tests["lag_s"]["profiled"]``; else None (the
    channel as it is).

    Why: a coefficient fitted at lag 0 on a channel that reaches the rate through a lag leaves c·(L_T[ch] − ch)
    in the residual. On a 1 Hz × 10⁵ FOG-like record (rate random walk dominating) with the temperature through
    900 s, the lag's test reads 2.27 against 16.5 (it cannot claim the lag), and the removal at lag 0 raised
    the chain's held-out error 2.13 → 2.76 %; with the profiled 498 s 1.28 %, at the true 900 s 0.79 %
    (docs/channels.md, "A lag not resolved")."""
    if "lag_s" not in tests or "rate_coefficient" in keys:
        return None
    prof = unresolved_lag(bands, regressor_design(keys, bands.m.size), fit["s"], grid, z2)
    tests["lag_s"]["profiled"] = prof
    return float(prof["lag_s"]) if prof["used"] else None


def _informative(info: np.ndarray) -> np.ndarray:
    """Mask of the fewest bands that together hold HELDOUT_INFO of ``info``."""
    order = np.argsort(-info)
    n = int(np.searchsorted(np.cumsum(info[order]), HELDOUT_INFO * info.sum())) + 1
    mask = np.zeros(info.size, dtype=bool)
    mask[order[:n]] = True
    return mask


def heldout_ratio(y, ch, fs: float, reg: ChannelRegression) -> float:
    """Held out across frequency: the coupling (the same terms and lag) fitted on the even DFT bins predicts the
    odd ones and back — each side's noise-weighted residual power Σ_b R_b/S_b (S from that side's own noise fit)
    with the other side's coefficients, over the same without any coupling; mean of the two ways. Below 1: the
    coupling carries over. Summed over the bands that hold :data:`HELDOUT_INFO` of the channel's information
    (elsewhere the coupling changes nothing, and thousands of bands of noise would only dilute the ratio).

    Why across frequency, not in time: a temperature that moves once (a warm-up, a door opened) moves in one
    half or one block of the record only, and no split in time leaves it in both parts; its spectrum, though,
    spreads over many bins, and interleaved bins of the noise are nearly independent (the Whittle
    approximation the test rests on).

    But a channel cycling a whole number of times puts nearly all its power in one DFT bin, so into one side of
    that split: the side without it estimates nothing, and its way reads the estimate's noise (a temperature
    cycling 3 times, coupled at LR 50 against 12: 1.09 and 1.01; three cycles over a 2000 s record at 2 kHz,
    99.7 % of the information on the odd bins: 0.89 and 5.4, rejected; ``benches/results/refine_blind2.md``).
    Such a channel is in both halves of the record. So the split is the one that leaves more of the channel's
    information (Σ_b G_b/S_b of its column) on its poorer side: the even and odd bins, or the record's two
    halves in time (each half's own spectrum and noise fit)."""
    y, fs = _check_rate(y, fs)
    n_use = wh.usable_length(y.size)
    y, x = y[:n_use], reconstructed(check_channel(reg.name, ch, y.size)[:n_use], reg.form)
    xs = band_limited(x, fs, reg.signal_bands)
    cols = regressors(xs, reg.mean, reg.quad_mean, fs, reg.removal_lag_s)
    split = [wh.spectra(y, cols, fs, parity) for parity in (0, 1)]
    half = wh.usable_length(n_use // 2)
    halves = [wh.spectra(y[a : a + half], [c[a : a + half] for c in cols], fs) for a in (0, n_use - half)]
    return min((_two_ways(sides, list(reg.params)) for sides in (split, halves)), key=lambda v: -v[1])[0]


def _two_ways(sides: list, keys: list) -> tuple[float, float]:
    """(mean of the two ways' held-out ratios, the poorer side's share of the channel's information) of a split
    into two sides' band sums (:func:`heldout_ratio`)."""
    level = "coefficient" in keys  # the level term, where its nested test dropped it, is not refitted either
    coefs = [wh.joint_fit(b, regressor_design(keys, b.m.size, level))["c"] for b in sides]
    noise = [wh.joint_fit(b, wh.Design([], []))["s"] for b in sides]
    info = [float(np.sum(b.G[:, 0, 0].real / s)) for b, s in zip(sides, noise, strict=True)]
    ratios = []
    for held, s, c_other in ((sides[0], noise[0], coefs[1]), (sides[1], noise[1], coefs[0])):
        d = regressor_design(keys, held.m.size, level)
        use = _informative(held.G[:, 0, 0].real / s)
        ratios.append(float(np.sum(wh.residual_power(held, d, c_other)[use] / s[use]) / np.sum(held.q[use] / s[use])))
    total = sum(info)
    return float(np.mean(ratios)), (min(info) / total if total > 0 and np.isfinite(total) else 0.0)
