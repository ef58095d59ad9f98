"""Lone lines the time-domain tests are retried without: lines slow enough to move the drift test's block means
(:meth:`._in_time.TimeRemovals.drift_beside_slow_lines`), lines strong in the first differences the outlier test reads
(:meth:`._in_time.TimeRemovals.outliers_beside_lines`); their least-squares component in time."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .. import periodic, slowline
from ..tracing import DRIFT_BLOCKS

__all__ = [
    "slow_lines",
    "lines_component",
    "lines_in_differences",
    "lines_less",
    "slow_line_removal",
    "explained_by_channel",
]


def slow_lines(search: dict | None, length_s: float, declined: list) -> list[float]:
    """The frequencies (Hz) of the search's lone lines — and of the families a removal turned down — whose period
    spans more than two of the drift test's :data:`~allanite.model.tracing.DRIFT_BLOCKS` block means of a record
    ``length_s`` long (faster ones average out within a block)."""
    if search is None:
        return []
    f_max = DRIFT_BLOCKS / (2.0 * length_s)
    return [d["f0"] for d in periodic.sinusoid_lines(search, families=declined) if d["f0"] < f_max]


def lines_component(y: np.ndarray, fs: float, freqs: list[float]) -> np.ndarray:
    """The sinusoids at ``freqs`` (Hz) fitted to ``y`` by least squares together, with a constant and a ramp
    beside them (a warm-up's or a random walk's slope must not leak into a slow line's phase), as samples."""
    t = np.arange(y.size) / fs
    t_mid = t - t.mean()
    cols = [np.ones_like(t), t_mid / max(float(np.ptp(t_mid)), 1e-300)]
    for f in freqs:
        cols += [np.sin(2 * np.pi * f * t), np.cos(2 * np.pi * f * t)]
    x = np.column_stack(cols)
    coef, *_ = np.linalg.lstsq(x, np.asarray(y, dtype=np.float64), rcond=None)
    return x[:, 2:] @ coef[2:]


#: The lone lines the outlier test is retried without, at most (the strongest first).
FAST_LINES_MAX = 4
#: A line is strong in the first differences when its swing there, 2A·|sin(πf/fs)|, is at least this share of the
#: differences' robust σ (their median absolute value over 0.6745, the line in it).
FAST_LINE_SHARE = 0.25


def lines_in_differences(search: dict | None, y: np.ndarray, fs: float, declined: list) -> list[float]:
    """The frequencies (Hz) of the search's lone lines (and of the families a removal turned down) strong in the
    record's first differences — where the outlier test measures the noise's scale and the spikes' distance —
    strongest first, at most :data:`FAST_LINES_MAX`."""
    if search is None:
        return []
    d = np.diff(np.asarray(y, dtype=np.float64))
    sigma_d = float(np.median(np.abs(d - np.median(d)))) / 0.6745
    out = []
    for line in periodic.sinusoid_lines(search, families=declined):
        swing = 2.0 * line["amplitude"] * abs(np.sin(np.pi * line["f0"] / fs))
        if swing >= FAST_LINE_SHARE * sigma_d:
            out.append(float(line["f0"]))
    return out[:FAST_LINES_MAX]


def lines_less(y: np.ndarray, fs: float, freqs: list[float], chunk: int = 1 << 20) -> np.ndarray:
    """``y`` less the sinusoids at ``freqs`` fitted by least squares together with a constant and a ramp (as
    :func:`lines_component`), the normal equations summed over chunks of ``chunk`` samples: memory of the record
    and a chunk's columns, not the record's size times the columns."""
    y = np.asarray(y, dtype=np.float64)
    n, k = y.size, 2 + 2 * len(freqs)
    t_mean, t_ptp = (n - 1) / (2.0 * fs), max((n - 1) / fs, 1e-300)

    def cols(a: int, b: int) -> np.ndarray:
        t = np.arange(a, b) / fs
        out = [np.ones(b - a), (t - t_mean) / t_ptp]
        for f in freqs:
            out += [np.sin(2 * np.pi * f * t), np.cos(2 * np.pi * f * t)]
        return np.column_stack(out)

    gram, rhs = np.zeros((k, k)), np.zeros(k)
    for a in range(0, n, chunk):
        x = cols(a, min(n, a + chunk))
        gram += x.T @ x
        rhs += x.T @ y[a : a + chunk]
    coef = np.linalg.lstsq(gram, rhs, rcond=None)[0]
    out = y.copy()
    for a in range(0, n, chunk):
        out[a : a + chunk] -= cols(a, min(n, a + chunk))[:, 2:] @ coef[2:]
    return out


def slow_line_removal(y: np.ndarray, fs: float, line: dict) -> tuple[np.ndarray, Callable, dict, dict, dict]:
    """A line of few cycles (a :func:`allanite.model.periodic.sinusoid_lines` entry with ``"slow"``: found by its
    test in time, :func:`allanite.model.slowline.slow_line_test`) as a removal in time: its component (the test's
    generalised least-squares sinusoid, beside a constant, a ramp and settling drifts), its refit on held-in samples
    (least squares at f0 with a constant and a ramp), and the step's params, intervals and evidence. Such a line is
    removed from the samples rather than held on the Allan curve: its signature peaks near τ = 0.37/f0, beyond
    the τ the curve's held-out halves reach (a daily line in 4.6 days: the held-out error 3.33 → 3.46 % held,
    ``benches/refine_blind10.py``'s tiltmeter), while its phase, a few cycles, predicts the held-out blocks."""
    f0, amp, phase = float(line["f0"]), float(line["amplitude"]), float(line["phase"])
    component = amp * np.sin(2 * np.pi * f0 * np.arange(y.size) / fs + phase)
    length = y.size / fs

    def refit(samples: np.ndarray, idx: np.ndarray) -> Callable:
        t = np.asarray(idx, dtype=np.float64) / fs
        x = np.column_stack([np.ones_like(t), t / length, np.sin(2 * np.pi * f0 * t), np.cos(2 * np.pi * f0 * t)])
        coef = np.linalg.lstsq(x, np.asarray(samples, dtype=np.float64), rcond=None)[0]

        def at(i: np.ndarray) -> np.ndarray:
            ti = np.asarray(i, dtype=np.float64) / fs
            return coef[2] * np.sin(2 * np.pi * f0 * ti) + coef[3] * np.cos(2 * np.pi * f0 * ti)

        return at

    slow = line["slow"]
    params = {"amplitude": amp, "f0": f0, "phase": phase}
    intervals = {"amplitude": tuple(line["amplitude_interval"]), "f0": tuple(line["f0_interval"])}
    evidence = {
        "domain": "time",
        "test": {"chi2": slow["statistic"], "threshold": slow["threshold"], "alpha": slow["alpha"]},
        "slow_line": slow,
        "note": (
            f"{slow['cycles']:.1f} cycles in the record; {100 * slow['separable']:.0f} % of the line's whitened signal "
            "lies outside what a constant, a ramp and settling drifts can take — the rest of it could be a drift"
        ),
    }
    return component, refit, params, intervals, evidence


def explained_by_channel(y: np.ndarray, fs: float, line: dict, regressions) -> dict | None:
    """The channel that explains a line of few cycles, or None: a regression on it (of ``regressions``, each
    accepted by its own test on the samples as they are) after whose removal the line's test no longer finds it —
    a thermal chamber's cycles of a gyro's temperature are its coupling, not a line (``tests/sensors.py``'s
    temperature over 25 h, three cycles: without the regression a sinusoid took them and nothing was left to say
    of the channel). Through whatever terms the regression removes, a lag its test did not resolve too: unlike a
    warm-up (``removals._channel_explaining``), a line is no shape a lag makes of a channel that does not carry it —
    the lag only turns its phase."""
    slow = line["slow"]
    for rem in regressions:
        again = slowline.slow_line_test(y - rem.component, fs, slow["alpha"], f_max=slow["band_hz"][1])
        if again is None or not again["accepted"]:
            left = None if again is None else float(again["statistic"])
            return {"explained_by": rem.params["channel"], "statistic_without_channel": left}
    return None
