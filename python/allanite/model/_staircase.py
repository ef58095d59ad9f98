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
and whether the channel moves slowly against its quantum (at most :data:`MAX_REVERSALS` of its steps undo the one
before: a staircase, not a noisy channel dithering across steps). :func:`reconstructed` reads it back: the
readings at their own instants (each hold's first sample), and for a slow staircase the instants where the
channel crossed between two steps — midway between the last reading at one step and the first at the next,
at the value midway between the steps (the rounding's threshold; a floor or ceiling quantiser's offset is a
constant, which the regression's mean absorbs) — with each turning-point step (and the first and last) at its
own value at the middle of its run; linear in between. A noisy channel's quantisation is dithered (nearly white)
and stays as it is; so does a channel neither quantised nor held (the same numbers as before).
"""

from __future__ import annotations

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
#: A quantised channel is a slow staircase when at most this share of its steps reverse the one before.
MAX_REVERSALS = 0.25
#: A channel is read back only when its typical step between readings is at most this share of its range: a
#: sampled quantity, not a switch or a multi-position profile whose steps are real (a ±1 g profile turned on a
#: fixed grid of samples looks held; a heater switched on once, a one-step staircase).
FINE_STEP = 1.0 / 8.0
#: Steps are whole multiples of the quantum to this fraction of it.
LATTICE_TOL = 1e-3


@dataclass(frozen=True)
class ChannelForm:
    """How a channel was written: ``quantum`` (channel unit; None: not quantised), ``hold`` (samples per reading,
    1: read every sample), ``phase`` (index of a reading), ``staircase`` (quantised and slow against its quantum:
    its steps' crossings are reconstructed), ``reversals`` (share of steps that undo the one before)."""

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


def _reversal_share(v: np.ndarray) -> float:
    d = np.diff(v)
    s = np.sign(d[d != 0])
    return float(np.mean(s[1:] != s[:-1])) if s.size > 1 else 0.0


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
    rev = _reversal_share(v)
    return ChannelForm(q, hold, phase, rev <= MAX_REVERSALS, rev)


def _staircase_knots(t: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Knots (instants, values) of a slow staircase read at instants ``t``: each crossing between two steps, and
    each turning-point step (and the first and last) at the middle of its run (module docstring)."""
    change = np.flatnonzero(np.diff(v) != 0)  # the last reading of each run but the last
    if change.size == 0:
        return np.array([t[0], t[-1]], dtype=np.float64), np.array([v[0], v[-1]])
    first = np.concatenate([[0], change + 1])  # runs' first and last readings
    last = np.concatenate([change, [v.size - 1]])
    cross_t = 0.5 * (t[change] + t[change + 1])
    cross_v = 0.5 * (v[change] + v[change + 1])
    up = np.sign(np.diff(v[first]))  # the direction into each run after the first
    turn = np.concatenate([[True], up[1:] != up[:-1], [True]])  # first, turning points, last
    mid_t = 0.5 * (t[first[turn]] + t[last[turn]])
    times = np.concatenate([cross_t, mid_t])
    values = np.concatenate([cross_v, v[first[turn]]])
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
