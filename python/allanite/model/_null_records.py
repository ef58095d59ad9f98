"""Records of the five-term model for the simulated nulls of refine's checks along time (the drift, mean and steps
checks: :func:`allanite.model.tracing.simulated_block_mean_chunks`), :func:`allanite.simulate`'s numbers with
the flicker's part remembered.

Those nulls are records of 2¹⁸–5·10⁵ samples at the block rate, drawn from fixed seeds: their length and seeds do
not depend on the record's length, and every axis of a log draws the same ones (the coefficients differ, the unit
draws do not). Three quarters of such a record's cost is its flicker — Kasdin & Walter's filter, two FFTs over
twice its length — which is a function of the generator's state and the length alone: here its linear convolution
over the next fast FFT length at or above 2n − 1 (:func:`_unit_flicker`; the records' 2·262 128 = 2⁵·3·43·127 points
took 2.5× the FFT time of 2¹⁹), the filter's transform at that length kept for the process. :func:`block_rate_record`
is :func:`allanite.simulate`'s arithmetic for constant white-rate, flicker, random-walk and ramp coefficients,
term for term in the same order, with the flicker taken from a memory (by the length and the generator's state
before it, with the state after it) within :func:`sharing`, from one refine call to the next: a report's
refinements of a log's axes share them, so its second and later axes draw no flicker (≈ 50 MB kept meanwhile,
2 MB a record; no other memory is kept between the calls, and a call outside it keeps none). The same draws as
:func:`allanite.simulate`'s record, equal to it to ~1e-15 of its largest value (the same convolution, rounded in
another FFT length; ``tests/test_refine_recent.py``).
"""

from __future__ import annotations

import functools
import math

import numpy as np
import scipy.fft

from ..simulation import power_law_coefficients, simulate
from ._recent import Small, holding

__all__ = ["block_rate_record", "sharing"]

#: The flicker of each null record drawn within a refine (or a report's refinements): its unit samples (read-only)
#: and the generator's state after them, by the length and the state before.
_FLICKER = Small(32)


def _state_key(rng: np.random.Generator) -> tuple:
    """The generator's whole state as a hashable tuple (its bit generator's name, counters and buffered bits)."""

    def frozen(v):
        return tuple(sorted((k, frozen(x)) for k, x in v.items())) if isinstance(v, dict) else v

    return frozen(rng.bit_generator.state)


def _flicker(n: int, rng: np.random.Generator) -> np.ndarray:
    """``kasdin_walter(n, 1.0, rng)``, found again for the same length and generator state (the generator then
    set to the state the draws leave it in) within :func:`sharing` — one refine call draws no record twice, so
    outside it nothing is kept (≈ 50 MB a call would hold for nothing)."""
    if not _FLICKER._held:
        return _unit_flicker(n, rng)
    key = (n, _state_key(rng))
    hit = _FLICKER.get(key)
    if hit is not None:
        rng.bit_generator.state = hit[1]
        return hit[0]
    out = _unit_flicker(n, rng)
    out.setflags(write=False)
    return _FLICKER.put(key, (out, rng.bit_generator.state))[0]


def _unit_flicker(n: int, rng: np.random.Generator) -> np.ndarray:
    """``allanite.kasdin_walter(n, 1.0, rng)`` — the same n unit draws through the same filter — as a linear
    convolution over the next fast FFT length ≥ 2n − 1 (no wrap-around reaches the first n outputs) instead of
    exactly 2n points: equal to it up to rounding (~1e-15 of its largest value)."""
    w = rng.normal(size=n)
    size = scipy.fft.next_fast_len(2 * n - 1, real=True)
    spec = scipy.fft.rfft(w, size)
    spec *= _flicker_response(n, size)  # in place, and the inverse over it: the same products, two copies fewer
    return scipy.fft.irfft(spec, size, overwrite_x=True)[:n]


@functools.lru_cache(maxsize=4)
def _flicker_response(n: int, size: int) -> np.ndarray:
    """The length-``size`` transform of Kasdin & Walter's first n flicker (α = 1) coefficients
    (:func:`allanite.simulation.power_law_coefficients`; read-only; the null records' few lengths are kept for the
    process: ≤ 4 × 8 MB)."""
    out = scipy.fft.rfft(power_law_coefficients(n, 1.0), size)
    out.flags.writeable = False
    return out


def block_rate_record(n: int, fs: float, N: float, B: float, K: float, R: float, seed) -> np.ndarray:
    """``allanite.simulate(n, fs, N=N, B=B, K=K, R=R, seed=seed)`` for constant coefficients ≥ 0 (a float each): the
    same terms in the same order from the same draws, the flicker's unit samples remembered (:func:`_flicker`)."""
    if not all(math.isfinite(v) and v >= 0 for v in (N, B, K, R)):
        return simulate(n, fs, N=N, B=B, K=K, R=R, seed=seed)  # its error, naming the coefficient
    tau0 = 1.0 / float(fs)
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    y = np.zeros(n)
    if N != 0:
        y += rng.normal(size=n) * (N / np.sqrt(tau0))
    if B != 0:
        y += _flicker(n, rng) * B
    if K != 0:
        y += np.cumsum(rng.normal(size=n) * (K * np.sqrt(tau0)))
    if R != 0:
        y += R * (np.arange(n) * tau0)  # the sample times only where a ramp needs them
    return y


def sharing():
    """A context in which the null records' flicker is kept from one refine call to the next (a report's axes)."""
    return holding(_FLICKER)
