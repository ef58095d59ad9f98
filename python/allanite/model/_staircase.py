"""A channel as loggers write it — quantised in value, held in time — read back as the quantity it samples
(:mod:`allanite.model.channels`' regressors).

Real IMU temperature channels are quantised (0.5, 0.125, 1/16, 1/340 °C steps), read at 1 Hz or less and held
between readings on a 100 Hz–2 kHz rate log. Regressed as written, the staircase is the true temperature plus a
measurement error that is neither white nor small where it matters:

- *held*: a zero-order hold delays the reading by half its period and adds images of it above the reading rate
  (its d/dt is a spike train at the reading rate);
- *quantised*, the channel moving slowly against its quantum: the error is a sawtooth at the rate the channel
  crosses its steps — power at 10⁻³–10⁻¹ Hz, right among the coupling's bands — which a white floor from the
  channel's top octave (:func:`allanite.model._regressors.channel_signal`) does not see. A lag smooths that
  sawtooth away, so the lag's test took it for a lag (a 0.5 °C staircase of a slow sine at 10 Hz: a lag of 16 s
  kept at 2Δℓ 57 against 15.5, truth none).

:func:`channel_form` reads the form from the channel alone — only where its typical step between readings is a
small share of its range (:data:`FINE_STEP`; a switch or a multi-position profile turned on a fixed grid of
samples steps by what it measures, and stays as it is): the quantum (every step a whole multiple of the
smallest), the hold (every change of value on a grid of ``hold`` samples, at least :data:`MIN_CHANGES` of them),
and whether the channel moves slowly against its quantum (at most :data:`MAX_REVERSALS` of its crossings between
steps turn back — a run of transitions between the same two steps, a channel chattering across their boundary
while it passes, counted as one crossing: a staircase, not a noisy channel dithering across steps).
:func:`reconstructed` reads it back: the
readings at their own instants (each hold's first sample), and for a slow staircase the instants where the
channel crossed between two steps — midway between the last reading at one step and the first at the next (the
mean of those instants over a crossing's chatter),
at the value midway between the steps (the rounding's threshold; a floor or ceiling quantiser's offset is a
constant, which the regression's mean absorbs) — with each turning-point step (and the first and last) at its
own value at the middle of its run; linear in between. A noisy channel's quantisation is dithered (nearly white)
and stays as it is; so does a channel neither quantised nor held (the same numbers as before).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = [
    "ChannelForm",
    "channel_form",
    "reconstructed",
    "reading_index",
    "reading_rate",
    "MIN_CHANGES",
    "MAX_REVERSALS",
]

#: A hold is read only from at least this many changes of value (a gcd of fewer could be chance: 2⁻¹⁵).
MIN_CHANGES = 16
#: A quantised channel is a slow staircase when at most this share of its crossings between steps turn back.
MAX_REVERSALS = 0.25
#: A channel is read back only when its typical step between readings is at most this share of its range: a
#: sampled quantity, not a switch or a multi-position profile whose steps are real (a ±1 g profile turned on a
#: fixed grid of samples looks held; a heater switched on once, a one-step staircase).
FINE_STEP = 1.0 / 8.0
#: Transitions between the same two steps are one crossing (chatter) while each follows the last within this
#: share of the median time between crossings of different boundaries.
CHATTER_SHARE = 0.5
#: Steps are whole multiples of the quantum to this fraction of it.
LATTICE_TOL = 1e-3


@dataclass(frozen=True)
class ChannelForm:
    """How a channel was written: ``quantum`` (channel unit; None: not quantised), ``hold`` (samples per reading,
    1: read every sample), ``phase`` (index of a reading), ``staircase`` (quantised and slow against its quantum:
    its steps' crossings are reconstructed), ``reversals`` (share of its crossings between steps that turn back)."""

    quantum: float | None = None
    hold: int = 1
    phase: int = 0
    staircase: bool = False
    reversals: float | None = None

    @property
    def plain(self) -> bool:
        """Nothing to read back: the channel is used as it is."""
        return self.hold == 1 and not self.staircase

    def words(self, fs: float) -> str:
        """In words: "quantised at 0.5 (a slow staircase), held for 1 s" or "as logged"."""
        out = []
        if self.quantum is not None:
            kind = "a slow staircase: its crossings read back" if self.staircase else "dithered by its noise"
            out.append(f"quantised at {self.quantum:.4g} ({kind})")
        if self.hold > 1:
            out.append(f"held for {self.hold / fs:.4g} s ({self.hold} samples; read at their first)")
        return ", ".join(out) or "as logged (neither quantised nor held)"

    def evidence(self, fs: float) -> dict:
        return {
            "quantum": self.quantum,
            "hold_s": self.hold / fs if self.hold > 1 else None,
            "staircase": self.staircase,
            "reversals": self.reversals,
            "words": self.words(fs),
        }


def _quantum(steps: np.ndarray) -> float | None:
    """The lattice's step: the smallest |step| when every step is a whole multiple of it, else None."""
    a = np.abs(steps)
    if a.size == 0:
        return None
    q = float(a.min())
    r = a / q
    return q if float(np.max(np.abs(r - np.rint(r)))) <= LATTICE_TOL else None


def _hold(x: np.ndarray) -> tuple[int, int]:
    """(samples per reading, index of one reading): the gcd of the distances between changes of value."""
    c = np.flatnonzero(np.diff(x) != 0) + 1
    if c.size < MIN_CHANGES:
        return 1, 0
    h = int(np.gcd.reduce(c - c[0]))
    return (h, int(c[0] % h)) if h >= 2 else (1, 0)


def reading_index(n: int, hold: int, phase: int) -> np.ndarray:
    """The instants (sample indices) of the readings: each hold's first sample; a partial hold at the start is read
    at index 0."""
    idx = np.arange(phase, n, hold)
    return idx if phase == 0 else np.concatenate([[0], idx])


@dataclass(frozen=True)
class _Crossings:
    """A staircase's transitions grouped: consecutive transitions between the same two steps are one crossing of
    their boundary (a channel chattering across it: its noise, a few hundredths of the quantum, flips the step back
    and forth while it passes); ``time`` the mean instant of a group's transitions, ``value`` the boundary (midway
    between the two steps), ``sign`` +1 rising, −1 falling, 0 a touch (back on the step it left: a turning point at
    the boundary); ``level_before``/``level_after`` the steps either side, ``gap_start``/``gap_end`` the instants of
    its first and last transitions."""

    time: np.ndarray
    value: np.ndarray
    sign: np.ndarray
    level_before: np.ndarray
    level_after: np.ndarray
    gap_start: np.ndarray
    gap_end: np.ndarray

    def turning_share(self) -> float:
        """Share of the crossings that turn: touches, and crossings the other way from the one before."""
        n = self.sign.size
        if n < 2:
            return 0.0
        crossing = self.sign[self.sign != 0]
        turns = int(np.sum(self.sign == 0)) + int(np.sum(crossing[1:] != crossing[:-1]))
        return turns / n


def _crossings(t: np.ndarray, v: np.ndarray) -> _Crossings:
    change = np.flatnonzero(np.diff(v) != 0)  # transition j: between readings change[j] and change[j] + 1
    a, b = v[change], v[change + 1]
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    tt = 0.5 * (t[change] + t[change + 1])
    new = np.ones(change.size, dtype=bool)
    new[1:] = (lo[1:] != lo[:-1]) | (hi[1:] != hi[:-1])
    # chatter is brief against the time between crossings of different boundaries: a longer stay on the other
    # side (a turning point's dwell on the top step) is two crossings, not one
    gap = np.diff(tt)
    spacing = float(np.median(gap[new[1:]])) if new[1:].any() else math.inf
    new[1:] |= gap > CHATTER_SHARE * spacing
    first = np.flatnonzero(new)
    last = np.append(first[1:], change.size) - 1
    before, after = a[first], b[last]
    return _Crossings(
        np.add.reduceat(tt, first) / (last - first + 1) if first.size else tt,
        0.5 * (lo[first] + hi[first]),
        np.sign(after - before),
        before,
        after,
        tt[first],
        tt[last],
    )


def channel_form(x: np.ndarray) -> ChannelForm:
    """The channel's form, read from its samples alone (module docstring)."""
    x = np.asarray(x, dtype=np.float64)
    hold, phase = _hold(x)
    v = x[reading_index(x.size, hold, phase)]
    d = np.diff(v)
    steps = d[d != 0]
    if steps.size == 0 or np.median(np.abs(steps)) > FINE_STEP * float(np.ptp(v)):
        return ChannelForm()  # its steps are what it measures (a switch, a multi-position profile): as it is
    q = _quantum(steps)
    if q is None:
        return ChannelForm(None, hold, phase)
    rev = _crossings(reading_index(x.size, hold, phase).astype(np.float64), v).turning_share()
    return ChannelForm(q, hold, phase, rev <= MAX_REVERSALS, rev)


def _staircase_knots(t: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Knots (instants, values) of a slow staircase read at instants ``t``: each crossing of a boundary between two
    steps (:class:`_Crossings`: its transitions' mean instant, the boundary's value), and each step the channel
    turns on (rises into and falls out of, or the reverse), the first and the last, at its own value in the
    middle of its stretch (module docstring)."""
    c = _crossings(t, v)
    if c.time.size == 0:
        return np.array([t[0], t[-1]], dtype=np.float64), np.array([v[0], v[-1]])
    turn = (c.sign[:-1] * c.sign[1:] < 0) & (c.level_after[:-1] == c.level_before[1:])
    mid_t = np.concatenate([[0.5 * (t[0] + c.gap_start[0])], 0.5 * (c.gap_end[:-1] + c.gap_start[1:])[turn]])
    mid_v = np.concatenate([[v[0]], c.level_after[:-1][turn]])
    mid_t = np.append(mid_t, 0.5 * (c.gap_end[-1] + t[-1]))
    mid_v = np.append(mid_v, v[-1])
    times = np.concatenate([c.time, mid_t])
    values = np.concatenate([c.value, mid_v])
    order = np.argsort(times, kind="stable")
    return times[order], values[order]


def reconstructed(x: np.ndarray, form: ChannelForm) -> np.ndarray:
    """The channel read back from its form (module docstring): ``x`` itself when :attr:`ChannelForm.plain`, else
    the readings (or a slow staircase's crossings) joined linearly, one value per sample; read-only."""
    x = np.asarray(x, dtype=np.float64)
    if form.plain:
        return x
    t = reading_index(x.size, form.hold, form.phase)
    v = x[t]
    kt, kv = _staircase_knots(t.astype(np.float64), v) if form.staircase else (t.astype(np.float64), v)
    out = np.interp(np.arange(x.size, dtype=np.float64), kt, kv)
    out.flags.writeable = False
    return out


def reading_rate(fs: float, form: ChannelForm) -> float:
    """The rate of the channel's own readings (Hz)."""
    return fs / form.hold if form.hold > 1 else fs
