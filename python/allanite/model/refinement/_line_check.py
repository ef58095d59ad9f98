"""The ``"line"`` check of :mod:`.missing`: is each line the final model accepted the same along the record?
(:func:`._line_constancy.line_constancy` on the final samples, Bonferroni over every line tested.)

Two kinds of line are tested: each ``"sinusoid"`` the model holds, and the strongest testable line of each
``"periodic"`` family removed in time (:attr:`.missing.MissingContext.families`; a sinusoid within half a
block's resolution of that line — the part of it the removal left, taken as a sinusoid — is that line, tested
once: said as the family's line where that is material, else as the sinusoid). The test compares complex
amplitudes, so a change of phase counts as surely as one of amplitude: a family is removed as one set of lines
(or one waveform) along the whole record, and one switched on halfway is removed at about half its amplitude,
each of its lines left in the final samples with that half on both sides and its phase flipped between them
(2.3 Hz harmonics 0.3/k, k = 1…4, on unit white noise, 100 Hz × 10⁵: p ≈ 10⁻⁴²) — equal amplitudes, which a
rule on the final samples' amplitudes never said.

A change is said only where it is material, by the level check's rule: the side further from the record's
line, in Allan deviation at the τ where the line's Allan variance peaks (≈ 0.371/f0), must depart by more than
the final model's held-out RMS ADEV error (``heldout_pct``). Each side's line is its blocks' mean power
(|c|² less the noise variance, whatever the phase: a wandering phase at one power is no change of the Allan
variance), for a family's line as it is in the record — the final samples' phasors plus the removed
component's own, on the final curve plus the removed line's power: the switched-on family is ≈ 0 before the
switch and its whole amplitude after. A family's line whose phase alone turns at one power is tested but not
said (the part the removal missed is then a line of the final samples at its power, the ``"psd"`` check's or
a sinusoid's).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ._line_channel import follows_channel
from ._line_constancy import MAX_BLOCKS, MIN_PERIODS, block_phasors, line_constancy
from .curvefit import base_name
from .words import heldout_clause, span_text

__all__ = ["line_check", "tested_lines"]


def _split(ph: np.ndarray, lengths: np.ndarray) -> int:
    """The block index k (1 … B − 1) that best splits the phasors into two constant runs (length-weighted)."""
    best, k_best = -1.0, 1
    for k in range(1, ph.size):
        w1, w2 = lengths[:k].sum(), lengths[k:].sum()
        m1, m2 = np.sum(ph[:k] * lengths[:k]) / w1, np.sum(ph[k:] * lengths[k:]) / w2
        gain = float(w1 * w2 / (w1 + w2) * abs(m1 - m2) ** 2)
        if gain > best:
            best, k_best = gain, k
    return k_best


def _peak(ctx: Any, f0: float) -> tuple[float, float, float]:
    """The τ nearest 0.371/f0 (where a line's Allan variance peaks), the curve's AVAR there and the factor g of
    a sinusoid of amplitude A, whose Allan variance is A²·g = A²·sin⁴(πfτ)/(πfτ)²."""
    tau_arr = np.asarray(ctx.curve.tau, dtype=float)
    i = int(np.argmin(np.abs(np.log(tau_arr * f0 / 0.371))))
    tau, av = float(tau_arr[i]), float(ctx.curve.avar[i])
    x = math.pi * f0 * tau
    return tau, max(av, 1e-300), math.sin(x) ** 4 / x**2


def _departure_pct(
    ctx: Any, f0: float, amps: tuple[float, float], shares: tuple[float, float], extra: float = 0.0
) -> tuple:
    """How far the side further from the record's line departs from it, in % of the curve's Allan deviation
    at the τ nearest 0.371/f0 (the curve plus ``extra``·g: a line's power the removals took from it)."""
    tau, av, g = _peak(ctx, f0)
    av += extra * g
    mean_sq = shares[0] * amps[0] ** 2 + shares[1] * amps[1] ** 2
    dep = max(abs(math.sqrt(max(1 + (a**2 - mean_sq) * g / av, 0.0)) - 1) for a in amps)
    return 100 * dep, tau


def tested_lines(ctx: Any) -> list[tuple[float, int | None, bool]]:
    """The lines the check tests, as (frequency Hz, the index of its family in ``ctx.families`` or None, whether
    the model holds a sinusoid there): each family's strongest line the test takes (≥ 4 blocks of MIN_PERIODS
    periods, below fs/2), then each sinusoid not within half the finest block resolution (MAX_BLOCKS·fs/(2n))
    of one of those — the part of a family's line its removal left, taken as a sinusoid, is that line, tested
    once."""
    n = 0 if ctx.y is None else int(ctx.y.size)
    f_min, tol = 4 * MIN_PERIODS * ctx.fs / max(n, 1), 0.5 * MAX_BLOCKS * ctx.fs / max(n, 1)
    fams: list[tuple[float, int]] = []
    for j, (_gens, freqs, amps, _comp) in enumerate(ctx.families):
        ok = [(a, f) for f, a in zip(freqs, amps) if f_min <= f < ctx.fs / 2]
        if ok:
            fams.append((float(max(ok)[1]), j))
    sins = [float(p) for k, p in ctx.effects if base_name(k) == "sinusoid"]
    near = [[f for f in sins if abs(f - g) <= tol] for g, _j in fams]
    out: list[tuple[float, int | None, bool]] = [(f, None, True) for f in sins if not any(f in m for m in near)]
    return out + [(g, j, bool(m)) for (g, j), m in zip(fams, near)]


def line_check(ctx: Any, a: float) -> list[dict]:
    """One entry per tested line (:func:`tested_lines`) whose complex amplitude changes along the final samples
    (each tested at ``a`` over the number of lines tested) where the change is material (module docstring):
    ``"t"`` the later side of the best split of the block phasors (s), ``"band_hz"`` (f0 ± one block's
    resolution), ``"amplitudes"`` (each side's |A|, rate unit: for a sinusoid the root of its blocks' mean |c|²
    less their noise variance, so that a wandering phase is not read as a smaller amplitude; for a family's line
    the |mean phasor| of the line in the record — left plus removed — less its noise variance),
    ``"departure_pct"`` as in the module docstring; a family's line also ``"family"`` (its fundamentals, Hz),
    ``"change"`` (|Δ|, the sides' mean phasors of the line in the record) and ``"phase_change_deg"`` (the
    turn of its phase between the sides). Nothing
    without an accepted line."""
    if ctx.y is None:
        return []
    tested = tested_lines(ctx)
    out: list[dict] = []
    for f0, fam, held in tested:
        # a line whose term follows a channel is tested less the part its gain models: ``ctx.y`` is without it
        r = line_constancy(ctx.y, ctx.fs, f0, a / len(tested), phasors=True)
        if r is None or not r["rejected"]:
            continue
        edges = np.asarray(r["edges_s"])
        ph, lengths = np.asarray(r["phasors"]), np.diff(edges)
        k = _split(ph, lengths)
        sides = ((float(edges[0]), float(edges[k])), (float(edges[k]), float(edges[-1])))
        w = (float(lengths[:k].sum() / lengths.sum()), float(lengths[k:].sum() / lengths.sum()))
        reg = None if fam is None else _family_entry(ctx, r, k, sides, w, ctx.families[fam])
        if reg is None and held:  # what the family's removal left, held as a sinusoid: its amplitude changes
            reg = _amplitude_entry(ctx, r, k, sides, w)
        if reg is None:
            continue
        reg = _tied(ctx, r, reg, a / len(tested), None if fam is None else ctx.families[fam][3])
        half = 1.0 / float(lengths.mean())
        out.append(
            reg
            | {"domain": "line", "tau": (reg["tau_peak"], reg["tau_peak"]), "t": sides[1]}
            | {"band_hz": (f0 - half, f0 + half), "chi2_dof": None, "heldout_pct": ctx.heldout_pct, "f0": f0}
            | {"statistic": r["statistic"], "threshold": r["threshold"], "alpha": r["alpha"]}
        )
        del out[-1]["tau_peak"]
    return out


def _tied(ctx: Any, r: dict, reg: dict, a: float, removed) -> dict:
    """The entry with the channel its line's amplitude follows, where one does (:mod:`._line_channel`, at ``a``):
    the line's block phasors as it is in the record — the final samples' plus, for a family's line, the removed
    component's own (``removed``)."""
    chans = getattr(ctx, "channels", None)
    if not chans:
        return reg
    ph = np.asarray(r["phasors"])
    if removed is not None:
        ph = ph + block_phasors(np.asarray(removed, dtype=float), ctx.fs, float(r["f0"]), int(r["blocks"]))
    tie = follows_channel(ph, r["phasor_unit"], r["noise_level"], r["noise_dof"], r["edges_s"], ctx.fs, chans, a)
    if tie is None:
        return reg
    what = reg["what"][:-1] if reg["what"].endswith(")") else reg["what"]
    name = repr(tie["channel"])
    words = f"; it follows {name}: {100 * tie['g']:+.2g} % of its amplitude per unit of {name} about {tie['mean']:.4g})"
    return reg | {"what": what + words, "follows": tie}


def _tail(ctx: Any, dep: float, tau: float) -> str:
    held = heldout_clause(ctx.heldout_pct)
    size = f"{dep:.2g}" if dep < 100 else f"{dep:.0f}"
    return f"{size} % of the Allan deviation at τ {tau:.3g} s{held})"


def _material(ctx: Any, dep: float) -> bool:
    return ctx.heldout_pct is None or dep > ctx.heldout_pct


def _amplitude_entry(ctx: Any, r: dict, k: int, sides: tuple, w: tuple) -> dict | None:
    """A sinusoid's entry: each side's |A| (its blocks' mean |c|² less their noise variance, whatever the phase)
    and their departure from the record's mean power; None where it is not material."""
    ph = np.asarray(r["phasors"])
    power = np.abs(ph) ** 2 - np.asarray(r["phasor_var"])  # unbiased |A|² per block, whatever its phase
    amps = (math.sqrt(max(float(np.mean(power[:k])), 0.0)), math.sqrt(max(float(np.mean(power[k:])), 0.0)))
    f0 = float(r["f0"])
    dep, tau = _departure_pct(ctx, f0, amps, w)
    if not _material(ctx, dep):
        return None
    unit = f" {ctx.unit}" if ctx.unit else ""
    what = (
        f"the {f0:.2f} Hz line's amplitude changes along the record: {amps[0]:.3g}{unit} in t "
        f"{span_text(*sides[0])} s, {amps[1]:.3g}{unit} in t {span_text(*sides[1])} s (" + _tail(ctx, dep, tau)
    )
    return {"what": what, "amplitudes": amps, "departure_pct": dep, "tau_peak": tau}


def _family_entry(ctx: Any, r: dict, k: int, sides: tuple, w: tuple, family: tuple) -> dict | None:
    """A removed family's line, as it is in the record: the final samples' block phasors plus the removed
    component's own. Each side's |A| from its blocks' mean power less their noise variance (whatever the
    phase), judged as a sinusoid's against the record's mean power on the record's curve (the final one plus
    the removed line's A²·g); for the entry, the change of the sides' mean phasors (|Δ|² less its noise
    variance) and the turn of the line's phase between them. None where the change is not material."""
    gens, _freqs, _amps, comp = family
    ph, var = np.asarray(r["phasors"]), np.asarray(r["phasor_var"])
    f0 = float(r["f0"])
    removed = block_phasors(np.asarray(comp, dtype=float), ctx.fs, f0, int(r["blocks"]))
    own = ph + removed
    lengths = np.diff(np.asarray(r["edges_s"]))
    rec, v, power = [], [], []
    for sl in (slice(0, k), slice(k, None)):
        ln = lengths[sl]
        rec.append(complex(np.sum(own[sl] * ln) / ln.sum()))
        v.append(float(np.sum(var[sl] * ln**2) / ln.sum() ** 2))
        power.append(max(float(np.mean(np.abs(own[sl]) ** 2 - var[sl])), 0.0))
    change = math.sqrt(max(abs(rec[1] - rec[0]) ** 2 - v[0] - v[1], 0.0))
    amps = (math.sqrt(power[0]), math.sqrt(power[1]))
    turn = math.degrees(abs(np.angle(rec[1] * rec[0].conjugate())))
    dep, tau = _departure_pct(ctx, f0, amps, w, extra=float(np.mean(np.abs(removed) ** 2)))
    if not _material(ctx, dep):
        return None
    unit = f" {ctx.unit}" if ctx.unit else ""
    name = " × ".join(f"{g:.2f}" for g in gens)
    phase = f"its phase turned {turn:.0f}°; " if min(abs(rec[0]) ** 2, abs(rec[1]) ** 2) > 9 * max(v) else ""
    what = (
        f"the {name} Hz family's lines change along the record: its {f0:.2f} Hz line {amps[0]:.3g}{unit} in t "
        f"{span_text(*sides[0])} s, {amps[1]:.3g}{unit} in t {span_text(*sides[1])} s ({phase}" + _tail(ctx, dep, tau)
    )
    return {"what": what, "amplitudes": amps, "departure_pct": dep, "tau_peak": tau} | {
        "family": [float(g) for g in gens],
        "change": change,
        "phase_change_deg": turn,
    }
