"""Record-length computations of :func:`allanite.refine`'s checks done a chunk of samples at a time.

At 10⁷–10⁸ samples a check that makes a few record-length temporaries (|x|, its nonzero values, their quotients,
a sort; a Welch pass's segments, their detrended and windowed copies and their transforms) needs several times the
record on top of it: one default refine of a 10⁷-sample record peaked at 14.5× the record, most of it such
transients. Here each is a pass over :data:`CHUNK`-sample pieces (or over one Welch segment at a time) with the same
arithmetic per sample, so the numbers are those of the whole-array forms (the quantisation step exactly; a Welch
PSD to the last bits of its segments' sum) and the memory beyond the inputs is a chunk's, or one segment's.
"""

from __future__ import annotations

import numpy as np

__all__ = ["CHUNK", "chunks", "lattice_step", "welch_detrended", "window_overlap"]

#: Samples per chunk (8 MB of float64).
CHUNK = 1 << 20


def chunks(n: int, size: int = CHUNK):
    """Slices covering 0 … n in pieces of ``size``."""
    for a in range(0, n, size):
        yield slice(a, min(n, a + size))


#: Nonzero |x| at or below this share of the largest are rounding residues, not a lattice (:func:`lattice_step`).
TINY = 1e-6


def lattice_step(x: np.ndarray) -> float:
    """The quantisation step of ``x`` (:func:`allanite.model.outliers.lattice_step`'s rule): the smallest nonzero
    |x| that recurs (its value over max|x|, rounded to 12 digits, three times or more), if at least 99 % of the
    nonzero |x| are whole multiples of it (to 1e-6), else 0 (|x| ≤ :data:`TINY`·max|x|, float rounding, count as
    zero). One sorted copy of the rounded quotients (the record's
    size) is the only record-length array; everything else is chunked (a record of one chunk has its nonzero |x|
    taken once for the four passes). The same result as the whole-array form
    (the same quotients, the same first value with three equal in the sorted order that ``np.unique`` counts)."""
    n = x.size
    one = None
    if n <= CHUNK:  # one chunk: its nonzero |x| once, for the four passes (the same values; a chunk's memory)
        a = np.abs(x)
        one = [a[a > 0]]
        del a

    def passes():
        return one if one is not None else _nonzero_abs(x)

    n_nz, scale = 0, 0.0
    for nz in passes():
        if nz.size:
            n_nz += nz.size
            scale = max(scale, float(nz.max()))
    if n_nz == 0:
        return 0.0
    # below 1e-6 of the largest |x| a value is the float rounding of samples with a large offset (a rate
    # differenced from an angle of 10⁴ °: residues of 10⁻⁹ on a lattice of 10⁻²), not a step: counted as zero
    floor = TINY * scale
    # one chunk: its |x| above the floor taken once for the three passes that read them (the same values)
    kept = None if one is None else [nz[nz > floor] for nz in one]

    def above():
        return kept if kept is not None else (nz[nz > floor] for nz in _nonzero_abs(x))

    n_nz = sum(v.size for v in kept) if kept is not None else sum(int(np.count_nonzero(nz > floor)) for nz in passes())
    r = np.empty(n_nz)
    pos = 0
    for nz in above():
        r[pos : pos + nz.size] = np.round(nz / scale, 12)
        pos += nz.size
    r.sort()
    first = _first_recurring(r)
    del r
    if first is None:
        return 0.0
    step = np.inf
    for nz in passes():
        near = nz[np.abs(nz / scale - first) <= 1e-12]
        if near.size:
            step = min(step, float(near.min()))
    on = 0
    for nz in above():
        q = nz / step
        on += int(np.count_nonzero(np.abs(q - np.rint(q)) <= 1e-6 * np.maximum(1.0, q)))  # rint: round's numbers
    return step if on / n_nz >= 0.99 else 0.0


def _nonzero_abs(x: np.ndarray):
    """The nonzero |x| of each chunk, in order (a fresh pass over ``x``)."""
    for s in chunks(x.size):
        a = np.abs(x[s])
        yield a[a > 0]


def _first_recurring(r: np.ndarray) -> float | None:
    """The smallest positive value of the sorted ``r`` that occurs three times or more (r[i] = r[i + 2]), or None."""
    i = int(np.searchsorted(r, 0.0, side="right"))
    while i + 2 < r.size:
        j = min(r.size - 2, i + CHUNK)
        hit = np.flatnonzero(r[i:j] == r[i + 2 : j + 2])
        if hit.size:
            return float(r[i + hit[0]])
        i = j
    return None


def welch_detrended(
    x: np.ndarray, win: np.ndarray, nper: int, mean: float = 0.0, rows: int = 16, each=None
) -> np.ndarray:
    """Σ over the 50 %-overlapping segments of ``x − mean`` of |rfft(window × segment less its least-squares
    line)|², ``rows`` segments at a time while a group stays within :data:`CHUNK` samples — the whole-group form,
    bit for bit —, else one segment at a time, the line's slope summed over chunks (a segment of half a 10⁸-sample
    record is 400 MB: the group of three such and its copies were several GB). Per segment then: its detrended
    copy, its transform and the power so far (≈ 2.5 segments). The groups' sums are added in segment order, as the
    whole-group sum adds its rows; ``mean`` is subtracted from each segment as it is taken (no copy of ``x``).
    ``each``, when given, is called with every group's (segments × bins) powers, in segment order."""
    step = nper // 2
    k = (x.size - nper) // step + 1
    c = (nper - 1) / 2.0
    if rows * nper <= CHUNK:
        p = np.zeros(nper // 2 + 1)
        t = np.arange(nper) - c
        tt = float(t @ t)
        for a in range(0, k, rows):  # a few segments at a time: bounded memory for long records
            idx = (np.arange(a, min(k, a + rows)) * step)[:, None] + np.arange(nper)[None, :]
            seg = x[idx] - mean
            seg = seg - seg.mean(axis=1, keepdims=True) - np.outer(seg @ t / tt, t)
            pw = np.abs(np.fft.rfft(seg * win, axis=1)) ** 2
            if each is not None:
                each(pw)
            p += np.sum(pw, axis=0)
        return p
    tt = _sum_squares_centred(nper)
    total: np.ndarray | None = None  # the first group's sum is the total so far (no zeros beside it)
    for a in range(0, k, rows):
        acc = _segment_power(x[a * step : a * step + nper], win, mean, tt)
        if each is not None:
            each(acc[None, :])
        for i in range(a + 1, min(k, a + rows)):
            one = _segment_power(x[i * step : i * step + nper], win, mean, tt)
            if each is not None:
                each(one[None, :])
            acc += one
        total = acc if total is None else total + acc
    assert total is not None
    return total


def _segment_power(seg: np.ndarray, win: np.ndarray, mean: float, tt: float) -> np.ndarray:
    """|rfft(window × (seg − mean) less its least-squares line)|² of one long segment: one detrended copy, its
    transform, then its power (the line's slope and the line itself a chunk at a time)."""
    nper = seg.size
    c = (nper - 1) / 2.0
    w = seg - mean
    trend = sum(float(w[s] @ (np.arange(s.start, s.stop, dtype=np.float64) - c)) for s in chunks(nper)) / tt
    w -= w.mean()
    for s in chunks(nper):
        w[s] -= trend * (np.arange(s.start, s.stop, dtype=np.float64) - c)
        w[s] *= win[s]
    spec = np.fft.rfft(w)
    del w
    power = np.abs(spec)
    del spec
    power **= 2
    return power


def _sum_squares_centred(nper: int) -> float:
    """Σ (t − (nper − 1)/2)² over t = 0 … nper − 1, summed over chunks."""
    c = (nper - 1) / 2.0
    total = 0.0
    for s in chunks(nper):
        t = np.arange(s.start, s.stop, dtype=np.float64) - c
        total += float(t @ t)
    return total


def window_overlap(win: np.ndarray, nper: int, lags: int) -> tuple[float, list[float], np.ndarray]:
    """For the window ``win`` normalised to Σh² = 1: (Σ win², the overlap correlations Σ h_t h_{t+m·nper/2} for
    m = 1, |Σ_t h_t² e^{−i2πjt/nper}|² for j = 1 … ``lags`` — the bins' correlation of white noise's periodogram)
    summed over chunks, the e^{−i2πjt/nper} as powers of e^{−i2πt/nper} (the whole-array form's values within
    1e-12; its h, h² and their transform were three more window-length arrays)."""
    ww = 0.0
    acc = np.zeros(lags, dtype=np.complex128)
    for s in chunks(nper, CHUNK // 16):
        w2 = win[s] * win[s]
        ww += float(np.sum(w2))
        e = np.exp(-2j * np.pi * np.arange(s.start, s.stop, dtype=np.float64) / nper)
        ej = e.copy()
        for j in range(lags):
            acc[j] += ej @ w2
            ej *= e
    half = nper // 2
    rho = sum(float(win[s] @ win[s.start + half : s.stop + half]) for s in chunks(nper - half))
    return ww, [rho / ww], np.abs(acc / ww) ** 2


def welch_mean(x: np.ndarray, fs: float, nper: int, mean: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """``scipy.signal.welch(x − mean, fs, nperseg=nper)`` (Hann window, half-overlapping segments, each less its
    mean, density scaling, their mean) a group of segments at a time within :data:`CHUNK` samples: the grouped
    segments' copies, windowed copies and transforms of the whole call were ≈ 6 record-size arrays. Within 1e-12
    of scipy's (its per-segment scaling before the mean reassociated)."""
    from scipy import signal

    win = signal.get_window("hann", nper)
    step = nper // 2
    k = (x.size - nper) // step + 1
    rows = max(1, CHUNK // nper)
    acc = np.zeros(nper // 2 + 1)
    for a in range(0, k, rows):
        idx = (np.arange(a, min(k, a + rows)) * step)[:, None] + np.arange(nper)[None, :]
        seg = x[idx] - mean
        seg -= seg.mean(axis=1, keepdims=True)
        seg *= win
        spec = np.fft.rfft(seg, axis=1)
        acc += np.sum((np.conjugate(spec) * spec).real, axis=0)
    acc *= 1.0 / (fs * float(win @ win))
    acc[1 : (nper + 1) // 2] *= 2.0  # one-sided: every bin but DC and, for an even nper, Nyquist
    return np.fft.rfftfreq(nper, 1.0 / fs), acc / k
