"""A regression step of the model refinement (effect ``"regression"``: the rate regressed on another channel of the
log) as the report shows it: its units per unit of the channel, the noise terms fitted before and after the removal,
the optional terms' tests (a lag, a d(channel)/dt term, a quadratic) and the notes on a lag not resolved and on the
held-out error — as JSON (``summary.json``), console lines and the page's table rows."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .fmt import g, json_number

#: The optional terms of a regression, in the order the page lists them.
OPTIONAL_TERMS = ("quadratic", "rate_coefficient", "lag_s")

#: The header of the page's table of regression steps (:func:`regression_row`).
REGRESSION_COLUMNS = (
    "axis",
    "regressed on channel",
    "coefficient (final)",
    "method",
    "optional terms (each its nested test)",
    "noise terms before → after the removal",
    "notes",
)


def _tree(v: Any) -> Any:
    """Evidence made JSON-able: dicts and sequences element by element, numbers by :func:`json_number`."""
    if isinstance(v, dict):
        return {str(k): _tree(x) for k, x in v.items()}
    if isinstance(v, (list, tuple, np.ndarray)):
        return [_tree(x) for x in v]
    if v is None or isinstance(v, (str, bool, np.bool_)):
        return bool(v) if isinstance(v, np.bool_) else v
    return json_number(v)


def _terms(side: dict, ieee: dict | None) -> dict:
    """One side (before or after) of ``terms_before_after``: term → value, interval and unit (IEEE-952 units where
    the fit had a unit, else base form with unit None)."""
    out = {}
    for t, vals in side.items():
        if ieee is not None and t in ieee:
            v, lo, hi, unit = ieee[t]
        else:
            (v, lo, hi), unit = vals[:3], None
        out[t] = {"value": json_number(v), "interval": [json_number(lo), json_number(hi)], "unit": unit}
    return out


def regression_dict(evidence: dict) -> dict | None:
    """The regression's evidence for ``summary.json`` (None for a step without it): ``method``, ``slow_share``,
    ``optional_terms`` (each term's nested test: kept, statistic, threshold, p_value, alpha, dof; a lag also its
    profile), ``terms_before_after`` (N, B, K, … fitted before and after the removal), ``lag`` (a lag not resolved,
    in words, or None), ``heldout_note`` (why the held-out error rose, or None) and ``channel_form`` (how the
    channel was written and read back — "quantised at 0.5 (…), held for 1 s (…)" — or None: as logged)."""
    tba = evidence.get("terms_before_after")
    if "terms" not in evidence and tba is None:
        return None
    ieee = (tba or {}).get("ieee") or {}
    return {
        "method": evidence.get("method"),
        "slow_share": json_number(evidence.get("slow_share")),
        "optional_terms": _tree({k: v for k, v in (evidence.get("terms") or {}).items() if isinstance(v, dict)}),
        "terms_before_after": None
        if tba is None
        else {side: _terms(tba[side], ieee.get(side)) for side in ("before", "after") if side in tba},
        "lag": evidence.get("lag"),
        "heldout_note": evidence.get("heldout_note"),
        "channel_form": (evidence.get("channel_form") or {}).get("words"),
    }


def _optional_words(terms: dict) -> str:
    """The optional terms' tests in words: "quadratic not kept (statistic 3.19 < threshold 19.9); …"."""
    parts = []
    for name in [t for t in OPTIONAL_TERMS if t in terms] + [t for t in terms if t not in OPTIONAL_TERMS]:
        t = terms[name]
        kept = bool(t.get("kept"))
        stat, thr = t.get("statistic"), t.get("threshold")
        # the sign is the test's own: a lag and a d(ch)/dt term are chosen between, so a term may be kept below its
        # threshold (standing in for the other, which passed) or not kept above it (docs/channels.md)
        sign = "≥" if kept else "<"
        if isinstance(stat, (int, float)) and isinstance(thr, (int, float)):
            sign = "≥" if stat >= thr else "<"
        why = f"; {t['why']}" if isinstance(t.get("why"), str) and name in ("lag_s", "rate_coefficient") else ""
        if kept and name == "quadratic" and isinstance(t.get("t_ref"), (int, float)):  # channels.centring
            why = f"; the coefficient is the slope at the channel's mean {g(t['t_ref'], 4)}"
        parts.append(
            f"{name} {'kept' if kept else 'not kept'} (statistic {g(stat, 3)} {sign} threshold {g(thr, 3)}{why})"
        )
    return "; ".join(parts)


def _moves_words(tba: dict) -> str:
    """The noise terms before → after the removal: "N 0.589 → 0.588 °/√h; K 0 → 20 °/h^1.5"."""
    before, after = tba.get("before", {}), tba.get("after", {})
    parts = []
    for t in before:
        if t not in after:
            continue
        b, a = before[t], after[t]
        unit = a["unit"] or b["unit"] or "(base form)"
        parts.append(f"{t} {_num(b['value'])} → {_num(a['value'])} {unit}")
    return "; ".join(parts)


def _num(v) -> str:
    return "—" if v is None or (isinstance(v, float) and math.isnan(v)) else g(v, 3)


def regression_lines(reg: dict | None) -> list[str]:
    """The regression's evidence as sentences (the console prints them under the step, the page in its table)."""
    if not reg:
        return []
    lines = []
    if reg.get("terms_before_after"):
        lines.append(f"noise terms before → after the removal: {_moves_words(reg['terms_before_after'])}")
    if reg.get("optional_terms"):
        lines.append(f"optional terms: {_optional_words(reg['optional_terms'])}")
    if reg.get("channel_form"):
        lines.append(f"channel: {reg['channel_form']}")
    if reg.get("lag"):
        lines.append(f"lag: {reg['lag']}")
    if reg.get("heldout_note"):
        lines.append(f"held-out: {reg['heldout_note']}")
    return lines


def regression_row(axis: str, st: dict) -> list | None:
    """The page's row of a regression step: axis, channel, coefficient, method, optional terms, noise terms
    before → after, notes (None for another step)."""
    reg = st.get("regression")
    if not reg:
        return None
    coef = st["final_params"].get("coefficient", st["params"].get("coefficient"))
    unit = st["units"].get("coefficient", "")
    tba = reg.get("terms_before_after")
    form = f"channel {reg['channel_form']}" if reg.get("channel_form") else None
    notes = [x for x in (form, reg.get("lag"), reg.get("heldout_note")) if x]
    return [
        axis,
        str(st["params"].get("channel", "—")),
        f"{_num(coef)} {unit}",
        reg.get("method") or "—",
        _optional_words(reg.get("optional_terms") or {}) or "—",
        _moves_words(tba) if tba else "—",
        "; ".join(notes) or "—",
    ]


def channels_not_kept(r) -> list[dict]:
    """The channels a refinement tried a regression on and kept none of (``Refinement.considered``), each the
    proposal nearest its threshold: ``channel``, ``statistic`` (the likelihood ratio), ``threshold``, ``why`` (a
    test passed but the proposal was refused: the held-out error, another effect taken …; else None) and ``text``
    — a temperature the report handed on and no step used is said, not left to the reader to infer."""
    kept = {st.params.get("channel") for st in r.steps if st.effect == "regression"}
    best: dict = {}
    for rec in r.considered.get("regression", ()):
        ch = rec.get("channel")
        lr, thr = rec.get("likelihood_ratio"), rec.get("threshold")
        if ch is None or ch in kept or lr is None or not thr:
            continue
        if ch not in best or lr / thr > best[ch]["statistic"] / best[ch]["threshold"]:
            best[ch] = {"channel": str(ch), "statistic": float(lr), "threshold": float(thr), "why": rec.get("rejected")}
    out = []
    for d in best.values():
        because = (
            f"its test passed ({g(d['statistic'], 3)} > {g(d['threshold'], 3)}) but {d['why']}"
            if d["why"]
            else f"likelihood ratio {g(d['statistic'], 3)} under its threshold {g(d['threshold'], 3)}"
        )
        out.append(dict(d, text=f"A regression on {d['channel']} was tried and not kept: {because}."))
    return out
