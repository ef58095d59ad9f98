"""``unexplained``'s ``"channel_shape"`` check: the final residual's dependence on a slow channel's *value* beyond
the terms kept for it (:func:`allanite.model._shape.shape_test`; docs/channels.md, "A coupling no term models") —
a staircase, a thermostat, a compensation table with steps that a straight line in the channel leaves uncorrelated
with it. Said, never removed; its own share of ``level`` (:data:`.levels.UNEXPLAINED_SHARES`), split over the
slow channels."""

from __future__ import annotations

from .. import channels
from .._shape import shape_test
from ._missing_context import MissingContext, chi2_dof
from .curvefit import base_name

__all__ = ["channel_shape_check", "kept_terms"]


def kept_terms(ctx: MissingContext, name: str) -> tuple:
    """The optional terms the final model kept for channel ``name`` (``"quadratic"``, ``"rate_coefficient"``), the
    null's columns beside the channel itself: what they explain is not a departure."""
    for k, p in ctx.effects:
        if base_name(k) == "regression" and p.get("channel") == name:
            return tuple(t for t in ("quadratic", "rate_coefficient") if t in p)
    return ()


def _where(named: list, unit: str | None, name: str) -> str:
    """Words for the departure: the channel's values where the rate steps (and its size), or its curvature."""
    u = unit or "rate unit"
    steps = sorted((c, v) for c, v in named if not isinstance(c, str))
    parts = []
    if steps:
        near = " and ".join(f"{c:.3g}" for c, _v in steps)
        parts.append(f"steps near {near} (largest ≈ {max(abs(v) for _c, v in steps):.3g} {u})")
    if any(isinstance(c, str) for c, _v in named):
        parts.append("curvature its kept terms do not model")
    return f"the rate depends on {name!r} beyond its kept terms: " + "; ".join(parts or ["its value"])


def channel_shape_check(ctx: MissingContext, a: float) -> list[dict]:
    """One entry per slow channel whose residual departs from its kept terms (:func:`shape_test` at ``a`` split
    over the slow channels): ``"cuts"`` [(value, step)] where, in the channel's unit and the rate's."""
    if ctx.y is None or not ctx.channels:
        return []
    slow = {name: ch for name, ch in ctx.channels.items() if channels.is_slow(ch)}
    out = []
    t_lo, t_hi = float(ctx.curve.tau[0]), float(ctx.curve.tau[-1])
    for name, ch in slow.items():
        r = shape_test(ctx.y, ch, ctx.fs, a / len(slow), kept=kept_terms(ctx, name))
        if not r["fired"]:
            continue
        lo = max(t_lo, min(t_hi, 0.1 * ctx.y.size / ctx.fs))  # a slow channel moves the longest τ
        out.append(
            {"domain": "channels", "tau": (lo, t_hi), "band_hz": None, "chi2_dof": chi2_dof(ctx, lo, t_hi)}
            | {"what": _where(r["named"], ctx.unit, name), "channel": name, "cuts": r["named"]}
            | {"statistic": r["statistic"], "threshold": r["threshold"], "alpha": r["alpha"], "nu": r["nu"]}
        )
    return out
