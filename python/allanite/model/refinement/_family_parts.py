"""A periodic removal's parts (:mod:`.removals`' ``"periodic"`` entry): a family's params, intervals and evidence
as found, its waveform folded on the period beside the lines of the families still to come, and the least-squares
sinusoid a lone line's wander is judged against."""

from __future__ import annotations

import numpy as np

from .. import linefit, periodic, template
from ._tracking import heldout_variance_ratio, tracked
from .calibrated import tested

__all__ = ["family_out", "folded_waveform", "hunting", "other_lines", "sinusoid_at"]


def sinusoid_at(y: np.ndarray, fs: float, f_hz: float) -> np.ndarray:
    """The least-squares sinusoid at ``f_hz`` in ``y``."""
    idx, nu, one = np.arange(y.size), np.array([f_hz / fs]), np.array([[1]])
    a, b = linefit.solve(y, idx, nu, one)
    return linefit.evaluate(idx, nu, one, a, b)


def family_out(fam: periodic.LineFamily, a: float, search: dict) -> tuple[dict, dict, dict]:
    """A periodic step's ``params``, ``intervals`` and ``evidence`` for the family ``fam`` as found (steady)."""
    ratios = fam.evidence["psd_ratio"]
    i = int(np.argmax(ratios))
    sd = fam.gens_sd
    params = {"fundamentals": [float(g) for g in fam.gens], "lines": int(fam.coefs.shape[0]), "rms": fam.rms}
    intervals = {
        "fundamentals": [(float(g - s), float(g + s)) for g, s in zip(fam.gens, sd)],
        "rms": (max(0.0, fam.rms - fam.rms_sd), fam.rms + fam.rms_sd),
    }
    evidence = {
        "domain": "psd",
        "test": tested("psd_ratio", float(ratios[i]), fam.evidence["threshold"], a),
        "frequencies_hz": [float(f) for f in fam.frequencies],
        "coefficients": fam.coefs.tolist(),
        "amplitudes": [float(v) for v in fam.amplitudes],
        "targeted": fam.evidence["targeted"],
        "bins_searched": search["bins"],
    }
    return params, intervals, evidence


def folded_waveform(ctx, fam: periodic.LineFamily, ratio_lines: float, rest=()):
    """A family of harmonics as its waveform folded on the period, with its held-out variance ratio, when that
    is below the lines' (``ratio_lines``); None otherwise, or for a family of sidebands (two generators).

    The fold is taken on the samples less the lines of the families still to come (``rest``, least squares on
    the same samples): a fold holds whatever repeats on its period, and where two fundamentals share the sampled
    lattice (1.7 and 13.7 Hz at 200 Hz both repeat every 2000 samples) the first family's fine template held the
    other's square wave too, which then lost its lines to it (``benches/refine_blind10.py``'s two families); the
    held-in samples of its held-out test are folded the same way."""
    if fam.gens.size != 1 or not fam.gens[0] > 0:
        return None
    others = other_lines(ctx.y, rest)
    tpl = template.fit_template(ctx.y if others is None else ctx.y - others, ctx.fs, float(fam.gens[0]))
    refit = tpl.refit
    if others is not None:

        def refit(samples: np.ndarray, idx: np.ndarray):
            return tpl.refit(samples - others[idx], idx)

    ratio = heldout_variance_ratio(ctx.y, refit)
    return (tpl, ratio, refit) if ratio < ratio_lines else None


def other_lines(y: np.ndarray, rest) -> np.ndarray | None:
    """The least-squares lines of the families ``rest`` in ``y`` (their frequencies as found), summed; None if none."""
    if not rest:
        return None
    idx = np.arange(y.size)
    out = np.zeros(y.size)
    for fam in rest:
        g = fam.gens / fam.fs
        a, b = linefit.solve(y, idx, g, fam.coefs)
        out += linefit.evaluate(idx, g, fam.coefs, a, b)
    return out


def hunting(ctx, search: dict, a: float):
    """A harmonic family whose fundamental hunts, which the search split among families and sinusoids
    (:func:`allanite.model.periodic.hunting_family`), removed with its fundamental's phase tracked where the tracker's
    nested test says it wanders (at its share of ``level``, as any family's) and the tracked form predicts held-out
    samples better than the same lattice at fixed frequencies: (component, refit, held-out ratio, params, intervals,
    evidence, family, the search's families and sinusoids it takes); else None (nothing considered: the parts are
    offered as before)."""
    got = periodic.hunting_family(ctx.y, ctx.fs, search)
    if got is None:
        return None
    fam, covered = got
    out = family_out(fam, a, search)
    done = tracked(ctx, fam, fam.component(), lambda: heldout_variance_ratio(ctx.y, fam.refit), out)
    if done is None:
        return None
    out[2]["hunting"] = {
        "clusters_hz": fam.evidence["hunting"],
        "note": "the search's peaks around each harmonic (one line smeared by the hunting) gathered on one lattice",
    }
    return (*done, *out, fam, covered)
