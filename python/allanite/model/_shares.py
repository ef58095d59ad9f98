"""Shares of the per-record false-alarm level that more than one module needs, without their heavy imports.

:mod:`allanite.model.channels` (scipy) spends :data:`TERM_SHARE` on a slow channel's optional terms, and
:mod:`allanite.model.refinement.levels` lists it in the record's budget; both take it from here, so that
reading the budget (as the report's summary does) loads no scipy.
"""

from __future__ import annotations

__all__ = ["TERM_SHARE", "FIRST_QUADRATIC", "WANDER_SHARE", "LINE_GAIN_SHARE"]

#: Share of the per-record level spent on each optional term's test of a channel regression (a test run only
#: once the coupling itself is accepted) — and on the level term's own (``"coefficient"``, the channel itself),
#: tested only where a d(ch)/dt term alone is kept beside it. Its share is the whole level (5 % at the default):
#: the other shares guard the claim of a term that is added; this one the claim of the coupling's leading term
#: that the record no longer supports once d(ch)/dt carries it. Dropped wrongly, a coupling is left in the
#: residual; kept wrongly, one coefficient with an interval about 0 is reported. At 2 % of the level (0.1 %) it
#: dropped blind8's true 1.3·10⁻⁴ °/s per °C (10.79 against 10.83, p 0.0010; docs/channels.md "The level term").
TERM_SHARE = {"quadratic": 0.02, "rate_coefficient": 0.02, "lag_s": 0.02, "coefficient": 1.0}
#: Fraction of the coupling's own α spent on the quadratic's test where the channel's test fails (a turnover
#: temperature: :func:`allanite.model.channels.regress_channel`); the channel and its quadrature get the rest. The
#: coupling is accepted by either, so the two together spend the coupling's α — not the coupling's and the
#: quadratic's :data:`TERM_SHARE` beside it (docs/channels.md, "A turnover temperature").
FIRST_QUADRATIC = 0.2
#: Share of the per-record level spent on whether an accepted line family's fundamental wanders (its phase tracked
#: instead of fixed: :func:`allanite.model.wander.track_family`) — a test run only once the family is accepted.
WANDER_SHARE = 0.02
#: Share of the per-record level spent on whether an accepted spectral line's amplitude follows a given channel (its
#: term then a·(1 + g·(channel − mean))·cos(2πf0t + φ): :mod:`allanite.model.refinement._line_gain`) — a test run
#: only once the line is accepted and only where channels are given, so on a clean record it spends nothing; the
#: same 0.02 as the other conditional options (a channel's optional terms, a family's wander), its false-alarm rate
#: on lines that do not follow a channel measured in benches/results/line_channel_null.md.
LINE_GAIN_SHARE = 0.02
