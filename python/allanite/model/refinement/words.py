"""What the final model still misses, in words — the one place that says ``Refinement.unexplained`` to a reader.

:meth:`allanite.Refinement.report`, the notebook display, ``summary.json`` (each entry's ``"text"``), the HTML
report page and the console all take their sentences from here, so they say the same thing: where in τ (and
frequency) the model still misses something, or that the final model passes every calibrated check — never the
latter when a check found something.
"""

from __future__ import annotations

import math

from .levels import UNEXPLAINED_SHARES

__all__ = [
    "MISFIT_CHI2_DOF",
    "checks_alpha",
    "declared_sentence",
    "describe_region",
    "heldout_clause",
    "misfit_sentences",
    "missing_sentences",
    "passes_sentence",
    "span_text",
]

#: The final curve χ²/dof from which the words beside "passes every calibrated check" also say the misfit: the
#: checks test for the signatures they know, at their share of the level — not the whole misfit's size.
MISFIT_CHI2_DOF = 2.0
#: A normalised residual |z| from which a τ is "far off" the model (about 2σ of its estimate).
FAR_Z = 2.0
#: Fewer non-overlapping clusters than this at a τ: "few clusters" (the estimate rests on few differences).
FEW_CLUSTERS = 20


def checks_alpha(level: float) -> float:
    """The false-alarm probability per record that the checks of what is still missing spend together."""
    return level * sum(UNEXPLAINED_SHARES.values())


def heldout_clause(pct: float | None) -> str:
    """The closing words of an entry judged against the final model's held-out error (none without one).

    Examples
    --------
    >>> heldout_clause(4.567), heldout_clause(None)
    ('; held-out error 4.6 %', '')
    """
    return "" if pct is None else f"; held-out error {pct:.2g} %"


def declared_sentence(declared: dict, taken: bool) -> str:
    """The filter the user declared (``Refinement.declared_filter``) and what the bandwidth step made of it — the
    report, the notebook display, the HTML page and the console say it alike."""
    did = (
        "the curve needed it: the bandwidth step's kind is the declared filter, its shape fixed (not searched)"
        if taken
        else "the curve did not need it: no bandwidth step was taken"
    )
    return f"Declared filter: {declared.get('words', declared.get('type', 'a filter'))}; {did}."


def describe_region(reg: dict) -> str:
    """One entry of ``Refinement.unexplained`` in words: "τ 0.2–3 s, ≈ 0.17–2.5 Hz: …, χ²/dof 4.1 there" (with
    its time region first where it has one, key ``"t"``, s: "t 0–5000 s, τ 0.01 s: …").

    Examples
    --------
    >>> describe_region({"tau": (0.2, 3.0), "band_hz": (0.17, 2.5), "chi2_dof": 4.12,
    ...                  "what": "the Allan curve departs from the model"})
    'τ 0.20–3.0 s, ≈ 0.17–2.5 Hz: the Allan curve departs from the model, χ²/dof 4.1 there'
    >>> describe_region({"tau": (0.01, 0.01), "t": (5000.0, 10000.0), "band_hz": None, "chi2_dof": None,
    ...                  "what": "the noise level changes along the record"})
    't 5000–10000 s, τ 0.010 s: the noise level changes along the record'
    """
    lo, hi = reg["tau"]
    text = f"τ {_span(lo, hi)} s"
    if reg.get("t") is not None:  # a time region along the record (s)
        text = f"t {_span(*reg['t'])} s, {text}"
    band = reg.get("band_hz")
    if band is not None:
        text += f", ≈ {_span(band[0], band[1])} Hz"
    if reg.get("what"):
        text += f": {reg['what']}"
    chi2 = reg.get("chi2_dof")
    if chi2 is not None and math.isfinite(chi2):
        text += f", χ²/dof {_num(chi2)} there"
    return text


def passes_sentence(level: float) -> str:
    """What is said when ``unexplained`` is empty: the final model passes the checks, at their level."""
    return (
        "The final model passes every calibrated check of what it may still miss (the Allan-curve score test "
        "and, with samples, lines in the PSD, an accepted line's amplitude along the record, a drift, steps of "
        "the mean, the noise level along the record, the channels, outliers, and clipped or repeated samples; "
        "without, the whole curve's two-sided GLS χ²) at a false-alarm probability "
        f"of {100 * checks_alpha(level):.3g} % per record together (their share of level {level:g})."
    )


def missing_sentences(unexplained: list, level: float) -> list[str]:
    """One sentence per entry of ``unexplained`` ("The model still misses something at τ …"), or the one
    sentence saying that the final model passes (:func:`passes_sentence`) when it is empty.

    Examples
    --------
    >>> missing_sentences([{"tau": (0.2, 3.0), "band_hz": None, "chi2_dof": 4.1, "what": ""}], 0.05)
    ['The model still misses something at τ 0.20–3.0 s, χ²/dof 4.1 there.']
    >>> missing_sentences([], 0.05)[0][:32]
    'The final model passes every cal'
    """
    if not unexplained:
        return [passes_sentence(level)]
    return [f"The model still misses something at {describe_region(r)}." for r in unexplained]


def misfit_sentences(chi2_dof: float, p_value: float | None, where: dict | None, stand_in: dict | None) -> list[str]:
    """What is said beside :func:`passes_sentence` when the final model's curve χ²/dof is ``MISFIT_CHI2_DOF`` or
    more: that number and what the checks test; ``where``: the τ of its largest normalised residuals (``"tau"``
    (lo, hi) s, ``"max_z"``, ``"clusters"`` the fewest non-overlapping clusters there); ``stand_in``: a resolved
    term that sets the model at its longest τ (``"term"``, ``"name"``, ``"value"`` in words, ``"tau_max"`` s,
    ``"record_s"``) — it may stand in for a slow periodic or a drift.

    Examples
    --------
    >>> said = misfit_sentences(3.54, 7.5e-12, {"tau": (0.16, 1.3), "max_z": 2.3, "clusters": 470.0}, None)
    >>> said[0][:44]
    'Yet its curve χ²/dof is 3.54 (p = 7.5e-12 un'
    >>> said[1]
    'Its largest normalised residuals are at τ 0.16–1.3 s (|z| up to 2.3).'
    """
    p = "" if p_value is None else f"p = {p_value:.2g} under χ²(dof), "
    out = [
        f"Yet its curve χ²/dof is {chi2_dof:.3g} ({p}a guide, not calibrated: the calibrated checks decide): they "
        "test the record for the signatures of the effects they know — a line, a drift, a step, a change of level, "
        "a bump in the Allan curve — each at its share of the level, not for the size of the whole misfit."
    ]
    if where is not None and where["max_z"] < FAR_Z:
        out.append(
            f"No single τ is far off (|z| ≤ {where['max_z']:.2g} on the dense curve): the misfit is in the curve's "
            "shape across τ, which the estimates' correlation across τ makes count."
        )
    elif where is not None:
        lo, hi = where["tau"]
        few = (
            f", where the record holds only {where['clusters']:.0f} non-overlapping clusters"
            if where["clusters"] < FEW_CLUSTERS
            else ""
        )
        z = f"|z| up to {where['max_z']:.2g}"
        out.append(f"Its largest normalised residuals are at τ {_span(lo, hi)} s ({z}){few}.")
    if stand_in is not None:
        out.append(
            f"{stand_in['term']} ({stand_in['name']}, {stand_in['value']}) is resolved and sets the model at its "
            f"longest τ ({_num(stand_in['tau_max'])} s of a {_num(stand_in['record_s'])} s record): it may stand in "
            "for a slow periodic or a drift whose period or time scale is near the record's length, which a record "
            "this short cannot tell from it — a longer record can."
        )
    return out


def span_text(lo: float, hi: float) -> str:
    """``lo–hi`` as the sentences write a range (one value if they are equal).

    Examples
    --------
    >>> span_text(0.0, 5000.0), span_text(4992.5, 10000.0)
    ('0–5000', '4992–10000')
    """
    return _span(lo, hi)


def _span(lo: float, hi: float) -> str:
    """``lo–hi`` with as many digits as it takes to tell them apart (one value if they are equal)."""
    if not hi > lo:
        return _num(lo)
    for extra in range(4):
        a, b = _num(lo, extra), _num(hi, extra)
        if a != b:
            return f"{a}–{b}"
    return f"{a}–{b}"


def _num(v: float, extra: int = 0) -> str:
    if v == 0 or not math.isfinite(v):
        return f"{v:g}"
    if abs(v) >= 1000:
        return f"{v:.0f}"
    digits = max(0, 1 - int(math.floor(math.log10(abs(v))))) + extra
    return f"{v:.{min(digits, 6)}f}"
