"""Which curve proposal a step accepts (:func:`choose`): its test passes, its parameter is not at the edge of its
range, its amplitude is positive, χ²/dof falls, and the held-out error falls — the sensor's roll-off, a
sigma-delta's shaped quantisation and spectral lines first, then by statistic over threshold; a resonance waits
for a bandwidth that passes; an unmistakable bandwidth may enter with a Gauss–Markov term or a resonance when alone
it would raise the held-out error (:data:`PAIR_FACTOR`); shaped quantisation's held-out error is judged where its
column differs from the Q line it replaces. Re-exported by :mod:`.candidates`."""

from __future__ import annotations

from ..effects import RESONANCE_Q
from ._proposal import Proposal, Round, search_grid
from .curvefit import Solution, base_name, held_theta, search

__all__ = ["PAIR_FACTOR", "choose"]


#: A bandwidth that raises the held-out error alone may enter with a Gauss–Markov term if its statistic is
#: at least this multiple of the threshold.
PAIR_FACTOR = 100.0


#: The white noises' own shapes at the shortest τ, taken before the rest (the lower χ² first): the sensor's roll-off
#: on N and a sigma-delta's shaping of Q — every other column is judged against the white noise they reshape.
_SHORT_TAU = ("bandwidth", "shaped_quantisation")


def _admissible(props: list, sol: Solution, tie: float = 0.0) -> list:
    """Proposals whose test passes, whose parameter is identified and amplitude positive, and that lower
    χ²/dof (a spectral line, held at its amplitude from the samples, needs its own test, material to the curve,
    and the held-out error's fall, as a removal in time: a term the curve fitted before it — a Gauss–Markov
    term that took the line's bump, its T_c biased — can make the true line raise χ²/dof, and the weights
    change with the model's noise mix). Spectral lines and the sensor's roll-off first, the one that explains
    more of the curve (the lower χ²) before the other: the roll-off is a property of the white noise every other
    column is judged against, and weak lines held before it can leave it no held-out gain (ADIS16405 run 3
    acc_x: four lines after the 0.54 Hz site line, then the roll-off 5.16 → 8.42 % held out, turned down; final
    χ²/dof 252), while a strong line's harmonics can pass for a roll-off (a 0.73 Hz square wave's: a boxcar of
    25 samples). Then by the statistic over its threshold (a line is also the most specific evidence: a
    sinusoid raises a bump on the curve that a Gauss–Markov term would otherwise take)."""
    ok = []
    for pr in props:
        why = _inadmissible(pr, sol)
        if why is None:
            ok.append(pr)
        elif pr.stat > pr.thr:  # a test that passed: say why it was not taken
            pr.record["rejected"] = why
    first = [pr for pr in ok if pr.line is not None or pr.effect in _SHORT_TAU]
    first.sort(key=lambda pr: pr.sol.chi2)
    rest = [pr for pr in ok if not (pr.line is not None or pr.effect in _SHORT_TAU)]
    rest.sort(key=lambda pr: -pr.stat / pr.thr)
    return _shaped_before_filter(first, tie) + rest


def _shaped_before_filter(first: list, tie: float) -> list:
    """``first`` with shaped quantisation before a bandwidth that fits the curve better by less than ``tie`` (χ² in
    effective points). Second-order shaped noise beside white rate noise is a moving-average process of two lags,
    and so is white noise through a boxcar of 2 to 3 samples beside white angle noise: both fit the curve, the
    boxcar with a number more (its span) and a white angle noise tuned to make the spectrum rise (the blind12
    sigma-delta: χ² 154.7 against 155.6, tie 17). The shaped kind is proposed only where the samples' spectrum
    rises toward f_s/2 faster than white angle noise allows (:func:`._shaped.spectrum_rises`), which a low-pass
    falling to f_s/2 never does; where the two are one process (white noise through 3 taps beside a Q that
    outgrows its fall) the curve's near-tie goes to the kind with a number fewer."""
    sq = next((pr for pr in first if pr.effect == "shaped_quantisation"), None)
    bw = next((pr for pr in first if pr.effect == "bandwidth"), None)
    if sq is None or bw is None or first.index(sq) < first.index(bw) or sq.sol.chi2 > bw.sol.chi2 + tie:
        return first
    rest = [pr for pr in first if pr is not sq]
    return rest[: rest.index(bw)] + [sq] + rest[rest.index(bw) :]


def _inadmissible(pr: Proposal, sol: Solution) -> str | None:
    """Why proposal ``pr`` cannot be accepted against the model ``sol`` (None: it can)."""
    if not pr.stat > pr.thr:
        return "test not passed"
    if pr.edge:
        return f"its parameter ({pr.p:.4g}) sits at the edge of its search range: not identified"
    if not pr.sol.theta[-1] > 0:
        return "amplitude 0"
    if pr.line is None and not pr.sol.chi2_dof < sol.chi2_dof:  # a held line has tests of its own
        return f"χ²/dof does not fall ({sol.chi2_dof:.4g} → {pr.sol.chi2_dof:.4g})"
    return None


def _first_heldout_winner(cands: list, rnd: Round):
    """The first proposal that lowers the held-out error: (proposal, held-out before, after), or None.

    A roll-off is judged beside the lines held so far and, where that fails, without them (:func:`_unheld_gain`)."""
    for pr in cands:
        ho_b = ho_a = None
        if pr.split is not None:
            ho_b = pr.split.error(rnd.start, rnd.effects)
            ho_a = pr.split.error(rnd.start, rnd.effects + [(pr.key, pr.p)])
            if (
                not ho_a < ho_b
                and not (pr.effect == "bandwidth" and _unheld_gain(pr, rnd, ho_b, ho_a))
                and not (pr.effect == "shaped_quantisation" and _shaped_gain(pr, rnd, ho_b, ho_a))
            ):
                pr.record["rejected"] = f"held-out error {ho_b:.3g} → {ho_a:.3g} %"
                continue
        return (pr, ho_b, ho_a)
    return None


def _unheld_gain(pr: Proposal, rnd: Round, ho_b: float, ho_a: float) -> bool:
    """Whether the roll-off ``pr`` lowers the held-out error of the model without the lines held so far. A held
    line's column is measured in the samples, not fitted, and a line whose phase wanders is a sinusoid's column
    only up to its coherence time: beside it, the roll-off's gain at the shortest τ can be lost in the long-τ
    scatter of the two parts (ADIS16405 run 3 acc_x: beside the 0.54 Hz site line 6.2 → 7.25 %, without it
    25.2 → 12.8 %). The roll-off's evidence should not hang on which came first; both comparisons go into its
    ``pair_note``."""
    assert pr.split is not None
    free = [(k, p) for k, p in rnd.effects if held_theta(k) is None]
    if len(free) == len(rnd.effects):
        return False
    ho_b2 = pr.split.error(rnd.start, free)
    ho_a2 = pr.split.error(rnd.start, free + [(pr.key, pr.p)])
    if not ho_a2 < ho_b2:
        return False
    pr.pair_note = (
        f"held out beside the lines held so far {ho_b:.3g} → {ho_a:.3g} %, without them {ho_b2:.3g} → {ho_a2:.3g} %"
    )
    return True


def _shaped_gain(pr: Proposal, rnd: Round, ho_b: float, ho_a: float) -> bool:
    """Whether shaped quantisation lowers the held-out error where its column differs from the Q line it replaces —
    τ below k·τ0, its first k − 1 averaging factors; beyond, the two models differ only through the refit of the
    other terms, and the held-out error over the whole curve is decided by the long-τ scatter of the two parts (the
    blind12 sigma-delta on seed 1304: 2.79 → 3.24 %, while at τ0 3.1 → 0.03 %: beyond 1 s both models miss the
    parts' flicker alike and the refit's N decided the sum). Its curve test has passed and the samples' spectrum
    shows the shaping (:func:`._shaped.spectrum_rises`); this is the held-out check of the τ it explains. Both
    comparisons go into its ``pair_note``."""
    if pr.split is None:
        return False
    tau_max = (pr.p - 1.0) / rnd.curve.fs
    lo_b = pr.split.error_below(rnd.start, rnd.effects, tau_max)
    lo_a = pr.split.error_below(rnd.start, rnd.effects + [(pr.key, pr.p)], tau_max)
    if not lo_a < lo_b:
        return False
    pr.pair_note = (
        f"held out over the whole curve {ho_b:.3g} → {ho_a:.3g} %, at τ ≤ {tau_max:.3g} s (where its column "
        f"differs from the Q line it replaces) {lo_b:.3g} → {lo_a:.3g} %"
    )
    return True


def _partners(rnd: Round, with_bw: list, candidates) -> list:
    """The terms a roll-off may enter beside (:func:`_paired_bandwidth`): the Gauss–Markov term and the resonance
    of each quality factor at their best parameters with the bandwidth in the model, where identified."""
    out = []
    if "gauss_markov" in candidates:
        p, s, edge = search(
            rnd.curve, rnd.start, with_bw, "gauss_markov", search_grid("gauss_markov", rnd.tmin, rnd.tmax)
        )
        out.append(("gauss_markov", p, s, edge))
    if "resonance" in candidates:
        for q in RESONANCE_Q:
            key = f"resonance:{q:g}"
            p, s, edge = search(rnd.curve, rnd.start, with_bw, key, search_grid("resonance", rnd.tmin, rnd.tmax))
            out.append((key, p, s, edge))
    return [(key, p) for key, p, s, edge in out if not edge and s.theta[-1] > 0]


def _paired_bandwidth(ok: list, rnd: Round, candidates):
    """An unmistakable roll-off (statistic ≥ :data:`PAIR_FACTOR` × threshold) that alone raised the held-out
    error, accepted when it lowers it together with a Gauss–Markov term or a resonance (the next step's): a
    bandwidth alone can raise the held-out error where a bump sits further up the curve (the five terms bend to
    the bump once the short τ are right) or where a resonance sits beside the roll-off (the ADIS16405
    accelerometers' 10 Hz hump: run 6 acc_x, the roll-off alone 8.95 → 9.72 %, with a resonance → 8.62 %).
    (proposal, held-out before, after alone), or None."""
    bw = next((pr for pr in ok if pr.effect == "bandwidth"), None)
    if bw is None or bw.split is None or not bw.stat >= PAIR_FACTOR * bw.thr:
        return None
    with_bw = rnd.effects + [(bw.key, bw.p)]
    partners = _partners(rnd, with_bw, candidates)
    if not partners:
        return None
    ho_b = bw.split.error(rnd.start, rnd.effects)
    ho_alone = bw.split.error(rnd.start, with_bw)
    ho_pair, (key, _p) = min((bw.split.error(rnd.start, with_bw + [pt]), pt) for pt in partners)
    if not ho_pair < ho_b:
        return None
    name = "Gauss–Markov term" if base_name(key) == "gauss_markov" else f"resonance (Q = {key.split(':', 1)[1]})"
    bw.pair_note = (
        f"accepted with the {name} of the next step: alone it moved the held-out error "
        f"{ho_b:.3g} → {ho_alone:.3g} %, with it → {ho_pair:.3g} %"
    )
    return (bw, ho_b, ho_alone)


def choose(props: list, rnd: Round, candidates):
    """The proposal a step accepts, with the held-out error before and after it, or None (the loop stops).

    A resonance near the shortest τ can stand in for the sensor's roll-off: while a bandwidth passes its test
    and is not in the model, the resonance waits until the bandwidth (alone or paired) was tried."""
    ok = _admissible(props, rnd.sol, rnd.curve.tau.size / rnd.curve.n_eff)
    deferred = []
    if any(pr.effect == "bandwidth" for pr in ok):
        deferred = [pr for pr in ok if pr.effect == "resonance"]
        ok = [pr for pr in ok if pr.effect != "resonance"]
    chosen = _first_heldout_winner(ok, rnd)
    if chosen is None:
        chosen = _paired_bandwidth(ok, rnd, candidates)
    if chosen is None and deferred:
        chosen = _first_heldout_winner(deferred, rnd)
    return chosen
