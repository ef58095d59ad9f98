"""Noise identification of a long rate record in chunks: :func:`~allanite.estimators.confidence.identify_alpha`
on more than :data:`LONG_SAMPLES` rate samples without a copy of the record.

:func:`identify_alpha` on rate data works on ``rate = x − mean(x)``, the block averages of ``rate`` at each
m (lag-1 ACF of them and their differences, or Barnes' B1 ratio where few remain) and, for R(n) = MVAR/AVAR
where B1 says white-or-flicker phase, the phase ``[0, cumsum(rate)]`` and its second differences at lag m and
their running sums. On a record of 10⁸ samples each of those is 800 MB, and several are alive at once.

:class:`LongRate` forms the same quantities a chunk at a time from the caller's samples: the block averages
and the phase bit for bit as the whole-array code forms them (the same elements, a sequential cumulative
sum continued across chunks); the sums and means over the record (AVAR, MVAR) are added chunk by chunk,
the lag-1 autocorrelation's sums are formed in the Rust core in one pass per m without holding the block
averages (``rust/core/src/block_acf.rs``; every m of a call at once, in parallel), and the block averages
at a multiple of the last m are averages of its averages (one pass over the record for a whole octave
grid), so they differ from the whole-array code's by rounding only (a few units in
the last place — α is rounded to an integer from them). The phase is held (8 bytes a sample) only where an
R(n) is needed, and then once for every m.
"""

from __future__ import annotations

import numpy as np

from .. import _core
from .._validate import resolve_workers

__all__ = ["LONG_SAMPLES", "CHUNK", "LongRate"]

#: Rate records longer than this are identified in chunks (shorter ones by the whole-array code).
LONG_SAMPLES = 1 << 22
#: Elements per chunk.
CHUNK = 1 << 20


class LongRate:
    """The rate samples ``arr`` (1-D float64) less their mean ``mu``, read a chunk at a time."""

    def __init__(self, arr: np.ndarray, mu: float, chunk: int | None = None):
        self.arr, self.mu, self.chunk = arr, mu, int(CHUNK if chunk is None else chunk)
        self.n = int(arr.size)
        self._phase: np.ndarray | None = None
        self._coarse: tuple[int, np.ndarray] | None = None  # (m, block averages at m): see all_means
        self._sums: dict[tuple[int, int], np.ndarray] = {}  # (m, dmax): the core's sums, see lag1_acfs

    def means(self, m: int, k0: int, k1: int) -> np.ndarray:
        """Averages of the blocks k0 … k1 − 1 of m samples: the rows of ``rate[:k·m].reshape(k, m).mean(1)``."""
        if m == 1:  # a block of one: its average is the sample (x/1 is x)
            return self.arr[k0:k1] - self.mu
        rows = (self.arr[k0 * m : k1 * m] - self.mu).reshape(k1 - k0, m)
        return rows.mean(axis=1)

    def all_means(self, m: int) -> np.ndarray:
        """Every block average at m (k = n // m of them). From the record the first time; after that, where
        m is a multiple of the last m asked for, as averages of its averages (one pass over the record for a
        whole octave grid instead of one per τ; the same averages to rounding)."""
        k = self.n // m
        if self._coarse is not None and m % self._coarse[0] == 0 and m > self._coarse[0]:
            j = m // self._coarse[0]
            z = self._coarse[1][: k * j].reshape(k, j).mean(axis=1)
        else:
            per = max(1, self.chunk // m)
            z = np.concatenate([self.means(m, a, min(k, a + per)) for a in range(0, k, per)] or [np.empty(0)])
        if z.size <= self.chunk:  # held: at most a chunk
            self._coarse = (m, z)
        return z

    def prefetch(self, ms, dmax: int = 2) -> None:
        """Form the sums :meth:`lag1_acfs` needs at every m of ``ms`` in one core call (the factors in
        parallel on the core's threads, ``ALLANITE_NUM_THREADS``); :meth:`lag1_acfs` then reads them."""
        todo = sorted({int(m) for m in ms} - {m for m, d in self._sums if d == dmax})
        if not todo:
            return
        sums = _core.block_lag1_sums(self.arr, self.mu, todo, dmax, resolve_workers(None))
        for m, row in zip(todo, sums):
            self._sums[(m, dmax)] = row

    def lag1_acfs(self, m: int, dmax: int = 2) -> list[tuple[float, int]]:
        """[(lag-1 autocorrelation with Stable32's (L − 1)/L factor, L) of the d-th difference of the block
        averages at m, for d = 0 … dmax] — :func:`allanite.estimators.confidence._lag1_acf` in one pass
        over the record in the core (``rust/core/src/block_acf.rs``): each difference's sum, sum of squares,
        lag-1 products and end values, without holding the block averages (the record's length at m = 1).
        Sum of squares about the mean = Σw² − Lμ², which loses nothing here: the block averages of a
        record less its mean, and their differences, average to ≈ 0."""
        self.prefetch([m], dmax)
        stats = self._sums[(int(m), dmax)]
        k = self.n // m
        out = []
        for d in range(dmax + 1):
            length = k - d
            if length < 1:
                out.append((0.0, max(length, 0)))
                continue
            s1, s2, c, first, last = (float(v) for v in stats[d])
            mu = s1 / length
            den = s2 - length * mu * mu
            num = c - mu * (2.0 * s1 - first - last) + (length - 1) * mu * mu
            out.append((0.0 if den <= 0.0 else num / den * (length - 1) / length, length))
        return out

    def acf_alpha(self, m: int, dmax: int = 2) -> float:
        """Riley & Greenhall's fractional estimate p (frequency data) at m, as ``_acf_alpha``."""
        acfs = self.lag1_acfs(m, dmax)
        d = 0
        while True:
            r1, length = acfs[d]
            delta = r1 / (1.0 + r1) if r1 > -1.0 else -1e9
            if delta < 0.25 or d >= dmax or length < 4:
                return -2.0 * (delta + d)
            d += 1

    def phase(self) -> np.ndarray:
        """``[0, cumsum(rate)]``, the same floats as NumPy's whole-array cumsum (held once made)."""
        if self._phase is None:
            p = np.empty(self.n + 1)
            p[0] = 0.0
            carry = 0.0
            for a in range(0, self.n, self.chunk):
                b = min(self.n, a + self.chunk)
                seg = np.cumsum(np.concatenate(([carry], self.arr[a:b] - self.mu)))
                p[a + 1 : b + 1] = seg[1:]
                carry = seg[-1]
            self._phase = p
        return self._phase

    def rn(self, m: int) -> float | None:
        """R(n) = MVAR/AVAR at m from the phase, as ``_b1_rn_alpha`` forms it; None where the AVAR is 0."""
        x = self.phase()
        n = x.size
        length = n - 2 * m  # second differences dd[i] = x[i + 2m] − 2 x[i + m] + x[i]

        def dd(a: int, b: int) -> np.ndarray:
            return x[2 * m + a : 2 * m + b] - 2.0 * x[m + a : m + b] + x[a:b]

        oav = sum(
            float(np.dot(v, v)) for v in (dd(a, min(length, a + self.chunk)) for a in range(0, length, self.chunk))
        )
        if oav == 0.0:
            return None
        oav /= length
        # c = [0, cumsum(dd)]; the MVAR terms are (c[j + m] − c[j]) / m for j = 0 … length − m
        count = length + 1 - m
        lo, hi = _running(dd, 0, length, self.chunk), _running(dd, m, length, self.chunk)
        mv = 0.0
        for a in range(0, count, self.chunk):
            b = min(count, a + self.chunk)
            v = (next(hi)[: b - a] - next(lo)[: b - a]) / m
            mv += float(np.einsum("i,i->", v, v))
        return (mv / count) / oav


def _running(dd, start: int, length: int, chunk: int):
    """Consecutive chunks of ``c[start:]``, c = [0, cumsum(dd[0:length])], each ``chunk`` long (the last
    shorter): the sequential sum continued from chunk to chunk, the same floats as NumPy's cumsum."""
    carry = 0.0
    pos = 0  # c[pos] = carry
    while pos < start:  # run up to c[start]
        b = min(start, pos + chunk)
        carry = float(np.cumsum(np.concatenate(([carry], dd(pos, b))))[-1])
        pos = b
    while pos <= length:
        b = min(length, pos + chunk - 1)
        seg = np.cumsum(np.concatenate(([carry], dd(pos, b))))  # c[pos] … c[b]
        yield seg
        carry, pos = float(seg[-1]), b + 1
        if b == length:
            return
        # the next chunk starts at c[b + 1] = c[b] + dd[b]
        carry = float(carry + dd(b, b + 1)[0])
