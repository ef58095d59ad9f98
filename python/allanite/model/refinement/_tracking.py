"""A line family's fundamental — or a lone line — with its phase tracked (:mod:`allanite.model.wander`), where the
tracker's nested test says it wanders and the tracked form predicts held-out samples better than the steady fit;
and the held-out test in time both forms are judged by (:func:`heldout_variance_ratio`)."""

from __future__ import annotations

import math

import numpy as np

from .. import periodic, wander
from .levels import alpha
from .scoring import HELDOUT_BLOCKS

__all__ = ["heldout_variance_ratio", "tracked"]


def tracked(ctx, fam: periodic.LineFamily, steady: np.ndarray, ratio_steady, out: tuple):
    """The family with its fundamental's phase tracked (:func:`allanite.model.wander.track_family`) where its nested
    test says the fundamental wanders and the tracked form predicts held-out samples better than the steady one:
    (component, refit, held-out ratio), the step's ``params``, ``intervals`` and ``evidence`` in ``out`` updated
    (the fundamental's mean and wander); else None (the test's numbers, where it ran, in ``evidence["wander"]``).
    ``ratio_steady`` is the steady form's held-out ratio, or a function giving it (computed only once the tracker
    takes the family: a lone line's steady ratio is needed nowhere else)."""
    params, intervals, evidence = out
    tf, test = wander.track_family(ctx.y, ctx.fs, fam.gens, fam.coefs, steady, alpha("periodic:wander", ctx.level))
    if test is None:
        return None
    ratio = heldout_variance_ratio(ctx.y, tf.refit) if tf is not None else math.nan
    if callable(ratio_steady):
        ratio_steady = ratio_steady() if tf is not None else math.nan
    evidence["wander"] = {"test": test, "heldout_variance_ratio": {"steady": ratio_steady, "tracked": ratio}}
    if tf is None or not ratio < ratio_steady:
        return None
    mean, rms, half = tf.mean_hz, tf.wander_rms_hz, tf.wander_half_span_hz
    # the mean of a track of ≈ 2·B·T independent values: its SD the wander's rms over √(2BT)
    sd = rms / math.sqrt(max(2.0 * tf.bandwidth_hz * ctx.y.size / ctx.fs, 1.0))
    rel = fam.rms_sd / fam.rms if fam.rms > 0 else 0.0
    params |= {"fundamentals": [mean], "lines": int(tf.orders.size), "rms": tf.rms}
    params |= {"wander_hz": rms, "wander_pct": 100.0 * rms / mean, "wander_half_span_hz": half}
    intervals["fundamentals"] = [(mean - sd, mean + sd)]
    intervals["rms"] = (max(0.0, tf.rms * (1.0 - rel)), tf.rms * (1.0 + rel))
    evidence["frequencies_hz"] = [float(k * mean) for k in tf.orders]
    evidence["coefficients"] = [[int(k)] for k in tf.orders]
    evidence["amplitudes"] = [float(v) for v in np.hypot(tf.a, tf.b)]
    evidence["wander"] |= {
        "bandwidth_hz": tf.bandwidth_hz,
        "reference_order": tf.reference,
        "note": (
            f"the fundamental wanders: mean {mean:.6g} Hz, rms {rms:.3g} Hz ({100 * rms / mean:.3g} %), "
            f"±{half:.3g} Hz over 1–99 % of the record; removed with its phase tracked (the {tf.reference}. "
            f"harmonic demodulated in ±{tf.bandwidth_hz:.3g} Hz), each harmonic at its order times that phase"
        ),
    }
    return tf.component(), tf.refit, ratio


def heldout_variance_ratio(y: np.ndarray, refit) -> float:
    """The held-out test in time of a component that predicts samples: each part of alternate blocks (even,
    odd) with the component refitted on the other part (``refit(samples, idx)`` → a function of indices)
    removed, its residual power over its power without it, both parts pooled — below 1 when the component
    predicts samples it was not fitted to. (The held-out Allan-curve error, the other removals' test, is
    dominated by what the curve effects found after the removals have not modelled yet — a low-pass — and
    turned down a 229×-the-floor sideband family on a consumer IMU's record.)"""
    per = y.size // HELDOUT_BLOCKS
    blocks = [np.arange(j * per, (j + 1) * per) for j in range(HELDOUT_BLOCKS)]
    num = den = 0.0
    for parity in (0, 1):
        held_in = np.concatenate([b for j, b in enumerate(blocks) if j % 2 == parity])
        held_out = np.concatenate([b for j, b in enumerate(blocks) if j % 2 != parity])
        comp = np.asarray(refit(y[held_in], held_in)(held_out), dtype=np.float64)
        z = y[held_out] - y[held_out].mean()
        r = z - (comp - comp.mean())
        num, den = num + float(r @ r), den + float(z @ z)
    return num / den if den > 0 else math.inf
