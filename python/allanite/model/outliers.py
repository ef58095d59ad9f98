"""Impulsive noise: samples beyond what Gaussian noise predicts, found on the differenced record.

:func:`outlier_test` — the test behind the ``"outliers"`` effect of :func:`allanite.refine`. The first
differences d_t = y_t − y_{t−1} of any Gaussian record are Gaussian, whatever its spectrum (white, flicker,
random walk, a ramp, a low-pass: a linear filter of Gaussian noise stays Gaussian; slow terms barely reach
the differences, so they hide nothing). Their scale is estimated robustly and locally — per block of 8192
differences, the block's own or its louder neighbour's (:func:`._robust_scale.local_scales`), and per fine block
of 512 where one is louder than its block (:func:`._robust_scale.burst_scales`), so a noise level that changes along
the record (a pump on for stretches, a truck passing) does not read as a heavy tail: the median absolute
difference, or — for quantised samples (every difference a multiple of a step L) — the σ of the Gaussian whose
differences, quantised, put the observed share of |d| ≤ jL (j where that share is nearest ½). With y quantised as y + u
(u uniform on a step, independent of d), P(|d_q| ≤ jL) = P(|d + U| < (j + ½)L), U uniform on (−L/2, L/2):
exact for the lattice however coarse (a Gaussian σ alone would miss a record whose differences are mostly 0
or ±1 step). The offsets are uniform when the samples wander over a step or more; a record whose samples'
standard deviation in a block is below :data:`COARSE` step (a quiet sensor toggling between two or three
codes) is not tested — no Gaussian model of the lattice describes it.

At each cut c of :data:`CUTS` (in those σ) the exceedances |d_t| > c·σ are counted as clusters (consecutive
exceedances are one: a spike makes two, a low-pass makes runs) and set against the Gaussian expectation
λ = Σ_blocks n_b·P(|d| > c·σ_b) (on a lattice, the lattice's own probability). Clusters are at most as many
as exceedances, so under the null they are at most Poisson(λ) (declustered extremes). A tail is called heavy
only beyond :data:`TAIL_FACTOR` (2) times the Gaussian count — real sensors' noise is slightly non-Gaussian
(the ADIS16405 gyros' differences hold 1.1–1.5× the Gaussian count at 3–4 σ over 10⁶ samples and none beyond
5.2 σ: no spikes, yet an exact Gaussian null rejects on two of them) — so
P(Poisson(2λ) ≥ count) ≤ ``alpha``/len(CUTS) accepts (Bonferroni over the cuts).

The samples then flagged, where the record is white from the shortest lag up to a level's span (σ_e²/σ_d² ≥
:data:`WHITE_RATIO` and τ·AVAR flat to :data:`WHITE_Z` standard errors up to at least :data:`LEVEL_SPAN` samples),
are those whose distance from the slow level (the mean over that span, on the sample's side of a step) is
beyond c*·σ of that distance — each sample on its own, as white noise's samples are independent, so that what
is left stays white; elsewhere (a low-pass, a random walk at the shortest lag, a roll-off or a line within the
span) the runs of 1 … :data:`MAX_RUN` samples off both outer neighbours at a cut c*: the differences into and out
of the run both beyond c*·σ_d (the lattice's next step on quantised samples) and of opposite signs, and each of
its samples beyond the cut from both — a lone spike, or spikes beside spikes of the same sign (a burst). Gaussian
samples are flagged in runs of L at most as often as the difference into the run exceeds the cut, so at most
L·λ(c*) samples per run length, for any spectrum (the lattice model holds for the differences; a low-passed
record's differences move together, so opposite signs are rarer still); λ sums that over the lone samples and
each longer length that flags a sample (a length that flags none puts no Gaussian sample among the flags) — c*
the lowest of
:data:`FLAG_CUTS` at which λ is at most 5 % of the flags (the flagged share is the outliers', not the Gaussian
tail's) and the flagged count is itself beyond Poisson(2λ) at the test's α per cut (one sample flagged where λ =
0.009, as on an ADIS16405 accelerometer's heavy tail, is a count twice the Gaussian's gives 1.7 % of the time).
:func:`allanite.refine` then removes them only where that moves an estimate of the record's Allan curve by two of
its standard errors or more — real impulsive samples too few to move the curve are no step of it. A spike's
neighbours (one large difference each), a step of the mean (one) and a good sample between two spikes of one sign
(off its own neighbours, not off those of the stretch of flagged samples around it) are not flagged.
:func:`replace_outliers` replaces each flagged sample by a draw from what Gaussian noise would have put there (the slow
level plus white noise as wide as the samples left where the noise is white at the shortest lag; the line between its
neighbours plus the second difference's noise elsewhere): how :func:`allanite.refine` refits the noise after removing
them. Sparse spikes are replaced cleanly. Heavy tails are not separable from the Gaussian core by any cut: the
contaminated samples inside it stay (N falls toward the core's, not to it); refine tests the samples left again and
flags on (``refinement.removals``). Flagging a heavy tail's samples off both neighbours would keep the wide samples that
sit beside one of the same sign — what is left then has a lag-1 correlation (0.084 for white noise with 20 % of its
samples 6× wider) that the shortest τ read as a low-pass.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.ndimage import median_filter
from scipy.stats import poisson

from . import _chunked
from ._recent import Recent
from ._robust_scale import burst_scales, robust_sigma
from ._robust_scale import lattice_sigma as _lattice_sigma  # noqa: F401 (its cache, asked by the tests)
from ._robust_scale import tail_cut as _tail

__all__ = [
    "outlier_test",
    "flag_at",
    "replace_outliers",
    "lattice_step",
    "robust_sigma",
    "CUTS",
    "FLAG_CUTS",
    "LEVEL_SPAN",
]

#: Cuts (in robust σ of the differences) at which exceedances are counted.
CUTS = (4.0, 5.0, 6.0, 7.0)
#: A heavy tail is a count beyond this multiple of the Gaussian expectation: the null is "at most
#: TAIL_FACTOR × λ", so that a sensor whose noise is only slightly non-Gaussian is not flagged (the
#: ADIS16405 gyros' differences hold 1.1–1.5× the Gaussian count at 3–4 σ, none beyond 5.2 σ: no spikes).
TAIL_FACTOR = 2.0
#: Samples per block of the replacement's scales and of the coarse-lattice check (at most MAX_BLOCKS blocks, at
#: least one); the test's and the flagging's scale is local (:func:`._robust_scale.burst_scales`).
BLOCK = 8192
MAX_BLOCKS = 64
#: Least spread of the samples (standard deviation per block, in quantisation steps) for the lattice model to
#: hold: the offsets y mod L are uniform only when the samples wander over a step or more. Measured on white
#: noise quantised with steps of 0.7 … 2 σ and offsets 0, ¼, ½ step (2·10⁶ samples): the count beyond 4 σ is
#: within 0.8–1.3× the model up to a step of 1.4 σ (std ≥ 0.7 step), 2.25× at 2 σ.
COARSE = 0.7
#: Cuts (σ of the differences) at which samples are flagged: the lowest at which Gaussian samples would make at
#: most EXCESS_SHARE of the flags.
FLAG_CUTS = (3.0, 3.5, 4.0, 4.5, 5.0, 6.0, 7.0, 8.0)
EXCESS_SHARE = 0.05
#: Longest run of samples flagged off its outer neighbours (spikes beside spikes of the same sign, a burst;
#: :func:`_off_neighbours`): the Gaussian samples so flagged are at most L·λ per run length L.
MAX_RUN = 4
#: Fewest samples of the slow level a white record's samples are flagged against and replaced around (the span
#: is as far as the record stays white, :func:`_white_span`; shorter, the rule off both neighbours).
LEVEL_SPAN = 65
#: Standard errors (white Gaussian noise's) by which τ·AVAR may depart from white for a record to count as white up
#: to that τ (:func:`_white_span`): the simulated white records of the sensor suite stay within 3, heavy tails
#: included; the ADIS16405 logs depart by 100–300 at m = 2.
WHITE_Z = 5.0
#: σ_e²/σ_d² at or above which a block's noise counts as white at the shortest lag (white 0.75, random walk 0.5,
#: smoother records less).
WHITE_RATIO = 0.65


def lattice_step(x: np.ndarray) -> float:
    """The quantisation step L of ``x``: the smallest nonzero |x| that recurs, if at least 99 % of the nonzero
    |x| are whole multiples of it (to 1e-6) — a few off-lattice values (the outliers themselves, added to a
    quantised record) do not hide the lattice; else 0 (continuous). The last few are remembered (the test and
    the replacement ask for the same record's)."""
    x = np.asarray(x, dtype=np.float64)
    got = _STEPS.get(x)
    return got if got is not None else _STEPS.put(x, (), _lattice_step(x))


#: What :func:`lattice_step` and :func:`_local` last found, by the samples' content (records up to 2·10⁶ samples).
_STEPS = Recent(2, 2_000_000)
_LOCALS = Recent(2, 2_000_000)


def _lattice_step(x: np.ndarray) -> float:
    # chunked (:mod:`._chunked`): the whole-array form's |x|, nonzero values, quotients and sort were ≈ 5 copies of
    # the record, the largest transient of a 10⁷-sample refine
    return _chunked.lattice_step(x)


def _blocks(n: int) -> list[slice]:
    nb = int(min(MAX_BLOCKS, max(1, n // BLOCK)))
    edges = np.linspace(0, n, nb + 1).astype(np.int64)
    return [slice(int(a), int(b)) for a, b in zip(edges[:-1], edges[1:])]


def _clusters(mask: np.ndarray) -> int:
    """Runs of consecutive True."""
    if mask.size == 0:
        return 0
    return int(np.count_nonzero(mask[1:] & ~mask[:-1]) + int(mask[0]))


def outlier_test(y: np.ndarray, fs: float, alpha: float) -> dict:
    """Test a record for samples beyond its Gaussian noise; flag them when the test accepts.

    Returns ``accepted`` (bool), ``cuts`` (per cut c: ``count`` of exceedance clusters, ``expected`` λ,
    ``p_value`` of the count under Poisson(TAIL_FACTOR·λ), ``p_gaussian`` under Poisson(λ)),
    ``alpha_per_cut``, ``step`` (the quantisation step, 0 if continuous), ``sigma_d`` (the differences'
    robust σ, median over blocks, rate unit) and, when accepted, ``cut`` (c*), ``flags`` (bool per sample),
    ``rate`` (flagged share of the samples) and ``threshold`` (rate unit, median over blocks: the cut at c* on
    the distance from the slow level, or on the differences); ``rule`` says which ("level" where the noise is
    white at the shortest lag, else "neighbours"). ``fs`` only labels the record (the test is on samples)."""
    y = np.asarray(y, dtype=np.float64)
    n = y.size
    out: dict = {"accepted": False, "cuts": [], "alpha_per_cut": alpha / len(CUTS), "fs": float(fs)}
    if n < 64:
        out["note"] = "too few samples"
        return out
    d = np.diff(y)
    step = lattice_step(d)
    out["step"] = step
    blocks, sig = burst_scales(d, step)  # each sample judged at its local scale (:mod:`._robust_scale`)
    out["sigma_d"] = float(np.nanmedian(sig)) if np.isfinite(sig).any() else float("nan")
    if not np.isfinite(sig).all():
        out["note"] = "a block of the differenced record has no spread (constant samples)"
        return out
    if step > 0:
        spread = min(float(np.std(y[b])) for b in _blocks(d.size))
        if not spread >= COARSE * step:
            # the quantisation offsets are uniform only when the samples wander over a step or more
            out["note"] = (
                f"quantisation too coarse for the test: the samples' standard deviation in a block is "
                f"{spread / step:.2g} step (< {COARSE:g})"
            )
            return out
    for c in CUTS:
        count, lam = 0, 0.0
        for b, s in zip(blocks, sig):
            cut, p = _tail(c, s, step)
            count += _clusters(np.abs(d[b]) > cut)  # per block: no record-length |d|
            lam += (b.stop - b.start) * p
        pv = float(poisson.sf(count - 1, TAIL_FACTOR * lam)) if count > 0 else 1.0
        pg = float(poisson.sf(count - 1, lam)) if count > 0 else 1.0
        out["cuts"].append({"c": c, "count": count, "expected": lam, "p_value": pv, "p_gaussian": pg})
    if not any(r["p_value"] <= out["alpha_per_cut"] for r in out["cuts"]):
        return out
    level = _level_residual(y, step)
    out["rule"] = "neighbours" if level is None else "level"
    for c in FLAG_CUTS:
        flags, lam, cut = _flags_of(y, d, blocks, sig, step, c, level)
        k = int(np.count_nonzero(flags))
        # Gaussian samples flagged: at most the differences beyond the cut, λ (exact for the lattice too); the
        # flagged count itself beyond what twice that gives, at the test's own α per cut (one sample where
        # λ = 0.009 is not: 1 − e^{−0.017} = 1.7 %)
        if k and lam <= EXCESS_SHARE * k and _flag_p(k, lam) <= out["alpha_per_cut"]:
            out.update(accepted=True, cut=c, flags=flags, rate=k / y.size, threshold=cut, expected_gaussian_flags=lam)
            return out
    out["note"] = "the differences' tail exceeds twice the Gaussian's, but too few samples stand off both neighbours"
    return out


def _flag_p(k: int, lam: float) -> float:
    """P(Poisson(TAIL_FACTOR·λ) ≥ k): the flagged count ``k`` against twice the Gaussian count of flags λ, as
    the clusters are tested."""
    return float(poisson.sf(k - 1, TAIL_FACTOR * lam))


def flag_at(y: np.ndarray, c: float) -> tuple[np.ndarray, float]:
    """Flags of the samples ``y`` at the cut ``c`` (σ of the differences, each block's local scale) and the number of
    Gaussian samples expected among them (λ): the flagging of :func:`outlier_test` at a given cut."""
    y = np.asarray(y, dtype=np.float64)
    d = np.diff(y)
    step = lattice_step(d)
    blocks, sig = burst_scales(d, step)
    if not np.isfinite(sig).all():
        return np.zeros(y.size, dtype=bool), 0.0
    flags, lam, _cut = _flags_of(y, d, blocks, sig, step, c, _level_residual(y, step))
    return flags, lam


def _level_residual(y: np.ndarray, step: float) -> tuple[np.ndarray, list, np.ndarray] | None:
    """For a record whose noise is white at the shortest lag (σ_e²/σ_d² ≥ :data:`WHITE_RATIO`, the median over
    blocks): each sample's distance from its slow level (the mean over :func:`_white_span` samples around it),
    the blocks and each block's robust σ of it; None for any other record (a low-pass, a random walk at the
    shortest τ: a smooth record's samples stand far off a level at its extremes). Not a short median: a level
    over fewer samples than the record is white for follows the white noise's own average, and a cut around it takes
    more samples from the side away from it — what is left keeps a share of that average, and a heavy tail's
    power comes back at long τ (+8.7 % τ·AVAR at 0.32 s, +38 % at 5 s with a 65-sample median)."""
    got = _LEVELS.get(y, (float(step),))
    if got is None:
        got = _LEVELS.put(y, (float(step),), (_level_residual_of(y, step),))
    return got[0]


#: What :func:`_level_residual` last found, by the samples' content and the step (records up to 2·10⁶ samples): the
#: record refine removed nothing from in time is tested again by the final check, at another level.
_LEVELS = Recent(2, 2_000_000)


def _level_residual_of(y: np.ndarray, step: float) -> tuple[np.ndarray, list, np.ndarray] | None:
    """:func:`_level_residual`, computed."""
    loc = _local(y, step)
    ratio = (loc["sigma_e"] / loc["sigma_d"]) ** 2
    ratio = ratio[np.isfinite(ratio)]
    if ratio.size == 0 or not float(np.median(ratio)) >= WHITE_RATIO:
        return None
    span = _white_span(y)
    if span < LEVEL_SPAN:
        return None
    r = y - _slow_level(y, np.zeros(y.size, dtype=bool), span)
    r.flags.writeable = False  # remembered (:data:`_LEVELS`): read only
    blocks, sig = burst_scales(r, step)
    return (r, blocks, sig) if np.isfinite(sig).all() and np.all(sig > 0) else None


#: What :func:`_flags` found per cut, by the samples' content (records up to 2·10⁶ samples): refine tests the raw
#: record at two levels (the removal's and the final check's share), each trying the same cuts in turn, with the
#: removal's passes and flaggings of other samples between them (four records kept; the flags as indices).
_FLAGGED = Recent(4, 2_000_000)


def _flags_of(y: np.ndarray, d: np.ndarray, blocks: list, sig: np.ndarray, step: float, c: float, level) -> tuple:
    """:func:`_flags` of the samples ``y`` (``d``, ``blocks``, ``sig``, ``step`` and ``level`` are ``y``'s, as
    :func:`outlier_test` derives them), remembered per cut; the flags a fresh array each time."""
    per_cut = _FLAGGED.get(y)
    if per_cut is None:
        per_cut = _FLAGGED.put(y, (), {})
    if c not in per_cut:
        if level is None and "summed" not in per_cut:  # the rule off both neighbours sums d once for every cut
            per_cut["summed"] = _summed(d)
            per_cut["abs"] = np.abs(d)  # and compares the same |d| with each cut
        flags, lam, cut = _flags(d, blocks, sig, step, c, level, per_cut.get("summed"), per_cut.get("abs"))
        per_cut[c] = (np.flatnonzero(flags), lam, cut)
    at, lam, cut = per_cut[c]
    flags = np.zeros(y.size, dtype=bool)
    flags[at] = True
    return flags, lam, cut


def _summed(d: np.ndarray) -> np.ndarray:
    """The samples less the first from their differences ``d`` (what :func:`_off_neighbours` compares)."""
    return np.concatenate([[0.0], np.cumsum(d)])


def _flags(d: np.ndarray, blocks: list, sig: np.ndarray, step: float, c: float, level, summed=None, absd=None) -> tuple:
    """(flags, λ, cut) at the cut c: the samples flagged, the Gaussian samples expected among them and the cut
    in the data's unit (median over blocks).

    White at the shortest lag (``level`` from :func:`_level_residual`): samples whose distance from their local
    level is beyond c·σ of that distance in their block (the lattice's next step on quantised samples) — each
    sample judged on its own, as white noise's samples are independent: so the flagged are a share of the
    samples, not of their neighbourhoods, and what is left stays white. The rule off both neighbours (below)
    keeps a heavy tail's wide samples that sit beside another of the same sign and takes the isolated ones: the
    record left had a lag-1 correlation of 0.084 (white 20 % of samples 6× wider), which the Allan curve's
    shortest τ read as a 38 Hz low-pass at 100 Hz.

    Any other record: runs of 1 … :data:`MAX_RUN` samples off both outer neighbours (:func:`_off_neighbours`),
    the differences into and out of the run beyond the cut (c·σ_d of its block) and of opposite signs. Gaussian
    samples are flagged in runs of L at most as often as a difference exceeds the cut, so λ is that count × the
    sum of the lone samples' 1 and each longer length that flags a sample — for any spectrum (a low-passed
    record's differences move together: opposite signs are rarer still); a spike's neighbours (one large
    difference each) and a step of the mean (one) are not flagged."""
    if level is not None:
        r, s_blocks, s_sig = level
        flags = np.zeros(r.size, dtype=bool)
        lam, cuts = 0.0, []
        for b, s_b in zip(s_blocks, s_sig):
            cut, p = _tail(c, s_b, step)
            flags[b] = np.abs(r[b]) > cut
            lam += (b.stop - b.start) * p
            cuts.append(cut)
        return flags, lam, _median_cut(cuts, s_blocks)
    cut_d = np.zeros(d.size)
    lam = 0.0
    for b, s_b in zip(blocks, sig):
        cut, p = _tail(c, s_b, step)
        cut_d[b] = cut
        lam += (b.stop - b.start) * p
    # a run of L samples is flagged at most once per difference into it beyond the cut: L·λ samples per length,
    # charged for the lone samples and for each longer length that flags a sample (one that flags none has put
    # no Gaussian sample among the flags)
    flags, lengths = _off_neighbours(d, cut_d, summed, absd)
    lam *= 1 + sum(lengths - {1})
    return flags, lam, _median_cut([_tail(c, s_b, step)[0] for s_b in sig], blocks)


def _median_cut(cuts: list, blocks: list) -> float:
    """The reported cut: the median over blocks of equal length; over the samples where a block was cut into fine
    blocks (:func:`._robust_scale.burst_scales`) — sixteen fine blocks of a burst are not sixteen blocks' say."""
    size = np.array([b.stop - b.start for b in blocks], dtype=np.float64)
    if size.max() - size.min() <= 1:
        return float(np.median(cuts))
    order = np.argsort(cuts)
    at = np.cumsum(size[order])
    return float(np.asarray(cuts)[order][int(np.searchsorted(at, 0.5 * at[-1]))])


def _off_neighbours(
    d: np.ndarray, cut_d: np.ndarray, summed: np.ndarray | None = None, absd: np.ndarray | None = None
) -> tuple[np.ndarray, set]:
    """Flags of the runs of 1 … :data:`MAX_RUN` samples that stand off both outer neighbours: the differences
    into and out of the run beyond the cut (``cut_d``, per difference) and of opposite signs, and every sample
    of the run beyond the cut from both outer neighbours on the run's side. A run of one is a lone spike (the
    rule off both neighbours); longer runs are spikes beside spikes of the same sign (a burst: 371 of the 372
    spikes the lone rule missed in ``benches/refine_blind2.py``'s bursts). Then, in each stretch of flagged
    samples, those not beyond the cut from both of the stretch's outer neighbours are unflagged: a good sample
    between two spikes of the same sign stands off both of its own neighbours, not off the stretch's. Returns the
    flags and the run lengths that flagged a sample no shorter run had. ``summed``: :func:`_summed` of ``d``, and
    ``absd`` its |d|, when the caller has them (the same for every cut)."""
    n = d.size + 1
    y = _summed(d) if summed is None else summed  # the samples less the first
    big = (np.abs(d) if absd is None else absd) > cut_d
    flags = np.zeros(n, dtype=bool)
    shortest = np.zeros(n, dtype=np.int8)  # the shortest run length that flagged each sample
    # a run starts only after a difference beyond the cut: its first samples t are taken from those alone (the
    # same runs as every t in 1 … n − run − 1, without passes over the whole record per run length)
    after_big = np.flatnonzero(big) + 1
    for run in range(1, MAX_RUN + 1):
        t = after_big[after_big < n - run]  # the run's first sample; d[t − 1] into it, d[t + run − 1] out of it
        if t.size == 0:
            break
        d_in, d_out, c = d[t - 1], d[t + run - 1], cut_d[t - 1]
        s = np.sign(d_in)
        ok = big[t - 1] & big[t + run - 1] & (np.sign(d_out) == -s)
        for j in range(run):
            ok &= (s * (y[t + j] - y[t - 1]) > c) & (s * (y[t + j] - y[t + run]) > c)
        for j in range(run):
            at = t[ok] + j
            shortest[at[~flags[at]]] = run
            flags[at] = True
    flags = _stretch_check(y, flags, cut_d)
    return flags, {int(v) for v in np.unique(shortest[flags])}


def _stretch_check(y: np.ndarray, flags: np.ndarray, cut_d: np.ndarray) -> np.ndarray:
    """``flags`` less the samples of each flagged stretch that are not beyond the cut from both of the
    stretch's outer (unflagged) neighbours on one side (:func:`_off_neighbours`). The stretches from the flagged
    samples' indices (a few thousand), not from passes over the record."""
    at = np.flatnonzero(flags)
    gap = np.flatnonzero(np.diff(at) != 1)  # a stretch ends after at[gap], the next starts at at[gap + 1]
    starts = at[np.concatenate([[0], gap + 1])] if at.size else at
    stops = at[np.concatenate([gap, [at.size - 1]])] + 1 if at.size else at
    long = stops - starts > 1
    out = flags.copy()
    for a, b in zip(starts[long], stops[long]):
        if a == 0 or b >= y.size:
            continue
        c = cut_d[a - 1]
        lo, hi = sorted((y[a - 1], y[b]))
        seg = y[a:b]
        out[a:b] = (seg > hi + c) | (seg < lo - c)
    return out


def _local(y: np.ndarray, step: float) -> dict:
    """Per sample: the robust σ of the second difference e_t = y_t − (y_{t−1} + y_{t+1})/2 (``sigma_e``) and of
    the first differences (``sigma_d``) in its block (for the replacement; read-only arrays, the last few
    remembered: the test and the replacement ask for the same record's)."""
    got = _LOCALS.get(y, (float(step),))
    if got is None:
        got = _LOCALS.put(y, (float(step),), _local_sigmas(y, step))
    return got


def _local_sigmas(y: np.ndarray, step: float) -> dict:
    e = np.zeros(y.size)
    e[1:-1] = y[1:-1] - 0.5 * (y[:-2] + y[2:])
    d = np.concatenate([[0.0], np.diff(y)])
    sig_e = np.full(y.size, np.inf)
    sig_d = np.full(y.size, np.inf)
    for b in _blocks(y.size):
        se, sd = robust_sigma(e[b], 0.5 * step), robust_sigma(d[b], step)
        if np.isfinite(se) and se > 0:
            sig_e[b] = se
        if np.isfinite(sd) and sd > 0:
            sig_d[b] = sd
    sig_e.flags.writeable = sig_d.flags.writeable = False
    return {"sigma_e": sig_e, "sigma_d": sig_d}


def _white_span(y: np.ndarray) -> int:
    """:func:`_white_span_of` ``y``, remembered (the test and the replacement ask for the same record's)."""
    got = _SPANS.get(y)
    return got if got is not None else _SPANS.put(y, (), _white_span_of(y))


def _white_span_of(y: np.ndarray) -> int:
    """The largest octave m (≤ 1/8 of the record) up to which ``y`` is white: τ·AVAR(m) (overlapping) within
    :data:`WHITE_Z` standard errors of white Gaussian noise's estimate (√(2/ν), ν ≈ 1.5·n/m) of m = 1's, at m
    and at every octave below it. The slow level a white record's samples are flagged against and replaced
    around is the mean over that span: below it white noise dominates, so a level over fewer samples would be
    mostly the white noise's own average; beyond it the record has structure (flicker, a line, a roll-off) a
    level must follow. The ADIS16405 logs depart by 100–300 SE at m = 2 (their 37 Hz roll-off): 1."""
    n = y.size
    x = np.concatenate([[0.0], np.cumsum(y - np.mean(y))])
    a1, span, m = 0.0, 1, 1
    while 3 * m < n // 8:
        d2 = x[2 * m :] - 2 * x[m:-m] + x[: -2 * m]
        a = float(np.mean(d2 * d2)) / (2.0 * m * m)
        if m == 1:
            a1 = a
        elif not (a1 > 0 and abs(m * a / a1 - 1.0) <= WHITE_Z * math.sqrt(2.0 * m / (1.5 * n))):
            break
        span, m = m, 2 * m
    return span


def _slow_level(y: np.ndarray, flags: np.ndarray, span: int, near: np.ndarray | None = None) -> np.ndarray:
    """Per sample: the mean of the unflagged samples over span/2 before it or over span/2 after it, whichever
    is nearer ``near`` (default: the sample itself) — the slow terms where the noise is white at the shortest
    lag, on the sample's own side of a step of the mean. Not a short median: a level over fewer samples than
    the span the record is white for is mostly the white noise's own average, which set into a tenth of the
    samples puts their white noise back at every τ beyond the span."""
    half = max(1, span // 2)
    cs_y = np.concatenate([[0.0], np.cumsum(np.where(flags, 0.0, y))])
    cs_w = np.concatenate([[0.0], np.cumsum((~flags).astype(np.float64))])
    i = np.arange(y.size)

    def mean(lo, hi):
        cnt = cs_w[hi] - cs_w[lo]
        return np.where(cnt > 0, (cs_y[hi] - cs_y[lo]) / np.maximum(cnt, 1.0), np.nan)

    before = mean(np.maximum(i - half, 0), i)
    after = mean(i + 1, np.minimum(i + 1 + half, y.size))
    before = np.where(np.isfinite(before), before, after)
    after = np.where(np.isfinite(after), after, before)
    ref = y if near is None else near
    level = np.where(np.abs(ref - before) <= np.abs(ref - after), before, after)
    return np.where(np.isfinite(level), level, y)


def _kept_sigma(r: np.ndarray, flags: np.ndarray) -> np.ndarray:
    """Per sample: the standard deviation of the unflagged samples' ``r`` in its block (0 where none is left)."""
    out = np.zeros(r.size)
    for b in _blocks(r.size):
        kept = r[b][~flags[b]]
        out[b] = float(np.std(kept)) if kept.size > 1 else 0.0
    return out


def replace_outliers(y: np.ndarray, flags: np.ndarray, seed: int = 0) -> np.ndarray:
    """``y`` with each flagged sample replaced by a draw from what Gaussian noise would have put there (fixed
    ``seed``: the same record gives the same samples).

    In a block whose noise is white at the shortest lag (σ_e²/σ_d² ≥ :data:`WHITE_RATIO`; 0.75 for white noise),
    in a record white up to at least :data:`LEVEL_SPAN` samples:
    the mean of the unflagged samples around it over the span the record is white for (:func:`_white_span`; the
    slow terms followed, not the white noise's own average: :func:`_slow_level`) plus white noise of the
    standard deviation the unflagged samples keep about it in the block — independent of its neighbours, as
    white noise is, and as wide as the samples left (a heavy tail's robust scale, taken on every sample, would
    make the replacements stand out of what is left). Elsewhere (a low-pass, a random
    walk at the shortest τ): the straight line between its nearest unflagged neighbours plus Gaussian noise of
    σ_e, the second difference's — the conditional law of a sample given its two neighbours for white noise and
    for a random walk alike, and nearly the line itself for a smooth (low-passed) record. A median alone would be
    smoother than the samples around it, which the Allan curve's shortest τ read as a low-pass."""
    y = np.asarray(y, dtype=np.float64)
    flags = np.asarray(flags, dtype=bool)
    if not flags.any():
        return y.copy()
    if not isinstance(seed, (int, np.integer)):
        return _replaced(y, flags, seed)
    key = (int(seed), np.flatnonzero(flags).tobytes())  # the removal's last pass and the final check ask again
    got = _REPLACED.get(y, key)
    if got is None:
        got = _REPLACED.put(y, key, _replaced(y, flags, seed))
        got.flags.writeable = False
    return got.copy()


#: :func:`replace_outliers`' and :func:`_white_span`'s last results, by the samples' content (records up to 2·10⁶).
_REPLACED = Recent(2, 2_000_000)
_SPANS = Recent(4, 2_000_000)


def _replaced(y: np.ndarray, flags: np.ndarray, seed) -> np.ndarray:
    """:func:`replace_outliers`' samples, computed."""
    out = y.copy()
    step = lattice_step(np.diff(y)) if y.size > 1 else 0.0
    loc = _local(y, step)
    se = np.where(np.isfinite(loc["sigma_e"]), loc["sigma_e"], 0.0)
    sd = np.where(np.isfinite(loc["sigma_d"]), loc["sigma_d"], np.inf)
    white = (se / sd) ** 2 >= WHITE_RATIO
    idx = np.flatnonzero(flags)
    good = np.flatnonzero(~flags)
    z = np.random.default_rng(seed).standard_normal(idx.size)
    span = _white_span(y)
    if span >= LEVEL_SPAN:  # white up to a level's span: the slow level, the spread of the samples left
        near = np.interp(np.arange(y.size), good, y[good]) if good.size else y
        slow = _slow_level(y, flags, span, near)
        level = slow[idx] + _kept_sigma(y - slow, flags)[idx] * z
    else:
        level = _running_median_at(y, idx, LEVEL_SPAN) + se[idx] / math.sqrt(1.5) * z
    line = (np.interp(idx, good, y[good]) if good.size else y[idx]) + se[idx] * z
    out[idx] = np.where(white[idx], level, line)
    return out


def _running_median_at(y: np.ndarray, idx: np.ndarray, size: int) -> np.ndarray:
    """``median_filter(y, size, mode="nearest")[idx]`` (odd ``size``): the median of the ``size`` samples around
    each of ``idx``, the record's end samples repeated beyond it — the same numbers (a middle order statistic
    either way), taken at the flagged samples alone where they are few instead of at every sample."""
    if idx.size * 8 > y.size or not np.isfinite(y).all():
        return median_filter(y, size=size, mode="nearest")[idx]
    half = size // 2
    padded = np.concatenate([np.full(half, y[0]), y, np.full(half, y[-1])])
    windows = np.lib.stride_tricks.sliding_window_view(padded, size)
    return np.median(windows[idx], axis=1)
