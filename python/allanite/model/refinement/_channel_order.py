"""The order in which a record's channels are regressed: the strongest first, not the order they were given in.

Each channel's regression is tested on the samples the ones taken before it left. Taken in the order of
``channels=``, a channel correlated with the coupling one is taken first wherever it comes first — it takes the
part of the coupling it shares, and what it leaves of the true channel's is too little to pass (blind suite 10's
three channels: temperature, supply voltage and a humidity the bias follows, the humidity partly anti-correlated
with the temperature — alone the humidity's likelihood ratio is 45 and the temperature's 36, both against ≈ 17; in
the given order the temperature was taken at −3.6× the humidity's coefficient and the humidity, on what it left,
read 2.6 against 18.4). So each round tests every channel not yet taken on the current samples and offers the one
whose statistic is furthest beyond its threshold (forward selection); once offered, the others are tested again on
the samples that removal left (where it was turned down, the samples are the same and their removals stand).

The decision whether *any* regression is taken is the same as in the given order: the first round tests every
channel on the samples as they are, each at its share of the level, and something is offered exactly when one of
them passes — the order changes which channel is taken first, not the rate at which a record without a coupling
takes one. One channel: one round, as before. Only what the last round turned down is recorded as considered.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any

__all__ = ["margin", "strongest_first"]


def margin(test: dict) -> float:
    """How far a removal's test (``evidence["test"]``, its statistic the first entry) is beyond its threshold, on
    a χ²-like scale: the ratio of a likelihood ratio to its threshold, of a t statistic's square to its
    threshold's square."""
    thr, value = float(test["threshold"]), float(next(iter(test.values())))  # the statistic first (``tested``)
    if thr <= 0:
        return float("inf")
    return (value / thr) ** 2 if "t" in test else value / thr


def strongest_first(ctx: Any, one: Callable[[Any, str, Any], Iterator[Any]]) -> Iterator[Any]:
    """The removals ``one(ctx, name, channel)`` yields for each channel of ``ctx.channels`` (at most one each),
    strongest first (module docstring). ``ctx.y`` is read after each yield: the caller's loop replaces it when it
    accepts the removal; what ``one`` records through ``ctx.consider`` is kept from each channel's last test only."""
    left = dict(ctx.channels)
    consider = ctx.consider
    found: dict = {}  # name → (removal or None, its considered entries), on the samples ``tested_on``
    tested_on = None
    while left:
        if tested_on is not ctx.y:
            found, tested_on = {}, ctx.y
        for name, ch in left.items():
            if name not in found:
                said: list = []
                ctx.consider = lambda effect, entry, said=said: said.append((effect, entry))
                try:
                    rems = list(one(ctx, name, ch))
                finally:
                    ctx.consider = consider
                found[name] = (rems[0] if rems else None, said)
        offered = {k: v[0] for k, v in found.items() if k in left and v[0] is not None}
        if not offered:
            break
        best = max(offered, key=lambda k: margin(offered[k].evidence["test"]))
        del left[best]
        yield offered[best]
    for name in left:
        for effect, entry in found.get(name, (None, []))[1]:
            consider(effect, entry)
