"""An allantools-compatible front door: ``from allanite import compat as allantools``.

Each function has allantools' call shape and return value,
``f(data, rate=1.0, data_type="phase", taus=None) -> (taus, devs, errs, ns)``, and copies its
conventions (written from allantools' documented behaviour; no allantools code is used), so that an
existing script switches by one import and gets the same numbers, computed by allanite's Rust core:

* **τ selection** — ``taus`` is ``None``/``"octave"`` (2^k, k ≤ ⌊log2 N⌋), ``"decade"`` (1, 2, 4 × 10^k,
  k ≤ ⌊log10 N⌋), ``"log10"`` (``int(10·log10 N)`` points from 1 to N, log-spaced), ``"all"`` (1 … N) or τ
  in seconds; each τ becomes m = round(τ·rate) (NumPy's round-half-to-even), kept if 0 < m < N (and
  within the estimator's range: m ≤ N/3 for MTOTDEV/TTOTDEV/HTOTDEV), sorted and de-duplicated; τ whose
  term count ``ns`` is ≤ 1 are dropped. N is the number of phase points (HTOTDEV: of frequency points).
* **phase / frequency** — frequency data lose leading and trailing NaN and their mean before
  integration to phase ``[0, cumsum(y − ȳ)/rate]``; phase data are used as given.
* **Theo1** — only even m, and τ is *labelled* m/rate, while the value is Theo1 at its own τ = 0.75·m/rate
  (allanite's :func:`allanite.avar` with ``estimator="theo1"`` labels it 0.75·m/rate and keeps m ≥ 10).
* **errs** — the value / √ns (TOTDEV: / √(N − 2); Theo1: / √(N − m); TIE rms: 0), not a confidence
  interval (allanite's results have ``confidence_intervals`` from the EDF).
* **ns** — float arrays: the number of terms averaged (Theo1: (N − m)·m/2 squared differences; MTIE and TIE
  rms: N − m windows; TOTDEV: N − 2).
* **no bias correction** — TOTDEV, MTOTDEV, TTOTDEV, HTOTDEV are the definitions' values, as allantools
  gives them (Stable32 divides by bias factors; see ``docs/compat.md``).

Differences from allantools, all deliberate: an interior NaN raises :class:`~allanite.errors.InputError`
naming its position (allantools returns NaN; use :func:`allanite.avar` with ``gaps="skip"``), an unknown
``data_type`` or ``taus`` a :class:`~allanite.errors.ParameterError`, and a record with no usable τ a
ParameterError (allantools raises ``UserWarning``). ``docs/compat.md`` lists each difference between these
conventions and the native API.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from . import _core
from .errors import InputError, ParameterError

__all__ = [
    "adev",
    "oadev",
    "mdev",
    "tdev",
    "hdev",
    "ohdev",
    "totdev",
    "mtotdev",
    "ttotdev",
    "htotdev",
    "theo1",
    "mtie",
    "tierms",
]

Arrays = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]


class _Record:
    """One input as phase points (N of them) and rate samples (N − 1), per allantools' conversion."""

    def __init__(self, data, rate, data_type: str) -> None:
        rate = float(rate)
        if not np.isfinite(rate) or rate <= 0:
            raise ParameterError(f"rate must be a positive finite sampling rate in Hz, got {rate!r}")
        if data_type not in ("phase", "freq"):
            raise ParameterError(f'data_type must be "phase" or "freq", got {data_type!r}')
        a = np.asarray(data, dtype=np.float64).ravel()
        self.rate = rate
        self.data_type = data_type
        if data_type == "freq":
            finite = np.flatnonzero(~np.isnan(a))
            a = a[finite[0] : finite[-1] + 1] if finite.size else a[:0]
        bad = np.flatnonzero(~np.isfinite(a))
        if bad.size:
            raise InputError(
                f"data[{int(bad[0])}] = {float(a[bad[0]])!r}: allanite.compat takes finite samples only "
                '(for records with missing samples use allanite.avar(..., gaps="skip"))'
            )
        if a.size < 2:
            raise InputError(f"data has {a.size} usable sample(s): at least 2 are needed")
        if data_type == "freq":
            self.freq = a
            self.y = a - a.mean()
            self.phase = np.concatenate(([0.0], np.cumsum(self.y) * (1.0 / rate)))
        else:
            self.phase = a
            self.y = np.diff(a) * rate
            self.freq = self.y
        self.n = self.phase.size


def _grid(taus, length: int, rate: float) -> np.ndarray:
    """τ (seconds) before rounding to m, for ``taus`` on a record of ``length`` points."""
    if taus is None or (isinstance(taus, list) and not taus):
        taus = "octave"
    if isinstance(taus, str):
        if taus == "all":
            return np.linspace(1.0, length, length) / rate
        if taus == "octave":
            top = int(np.floor(np.log2(length)))
            return np.logspace(0, top, top + 1, base=2.0) / rate
        if taus == "log10":
            top = np.log10(length)
            return np.logspace(0, top, int(10 * top), base=10.0) / rate
        if taus == "decade":
            return np.array([f * 10.0**k / rate for k in range(int(np.floor(np.log10(length))) + 1) for f in (1, 2, 4)])
        raise ParameterError(f'taus must be None, "all", "octave", "decade", "log10" or τ in seconds, got {taus!r}')
    out = np.asarray(taus, dtype=np.float64).ravel()
    if not np.all(np.isfinite(out)):
        raise ParameterError(f"taus must be finite, got {out[~np.isfinite(out)][0]!r}")
    return out


def _ms(taus, length: int, rate: float, *, top: float | None = None, even: bool = False) -> np.ndarray:
    """allantools' m selection: round, 0 < m < length (≤ top), unique and sorted; even m only for Theo1."""
    m = np.round(_grid(taus, length, rate) * rate)
    keep = (m > 0) & (m < length)
    if top is not None:
        keep &= m <= top
    m = np.unique(m[keep])
    if even:
        m = m[m % 2 == 0]
    return m.astype(np.int64)


def _finish(name: str, ms: np.ndarray, ns: np.ndarray, rate: float, value_fn: Callable[[list[int]], np.ndarray]):
    """Drop τ with ns ≤ 1 (allantools' rule), compute the deviations of the rest."""
    keep = ns > 1
    ms, ns = ms[keep], ns[keep]
    if ms.size == 0:
        raise ParameterError(f"{name}: no τ of the requested ones has more than one term for this record")
    devs = value_fn([int(m) for m in ms])
    return ms / rate, devs, ns.astype(np.float64)


def _rate_dev(rec: _Record, ms: list[int], estimator: str) -> np.ndarray:
    cols = [np.ascontiguousarray(rec.y)]
    if estimator in ("oavar", "avar"):
        v = _core.davar(cols, rec.y.size, 1, ms, estimator, "fast", 0)[0, :, 0]
    else:
        v = _core.deviation_static(cols, ms, estimator, 0)[0]
    return np.sqrt(v)


def _nonneg(a: np.ndarray) -> np.ndarray:
    return np.maximum(a, 0)


def adev(data, rate=1.0, data_type="phase", taus=None) -> Arrays:
    """Allan deviation (classic, non-overlapping), as ``allantools.adev``: (taus, devs, errs, ns)."""
    rec = _Record(data, rate, data_type)
    ms = _ms(taus, rec.n, rec.rate)
    ns = _nonneg(-(-(rec.n - 2 * ms) // ms))  # clusters starting at 0, m, 2m, … with a full second difference
    t, d, n = _finish("adev", ms, ns, rec.rate, lambda m: _rate_dev(rec, m, "avar"))
    return t, d, d / np.sqrt(n), n


def oadev(data, rate=1.0, data_type="phase", taus=None) -> Arrays:
    """Overlapping Allan deviation, as ``allantools.oadev``: (taus, devs, errs, ns)."""
    rec = _Record(data, rate, data_type)
    ms = _ms(taus, rec.n, rec.rate)
    t, d, n = _finish("oadev", ms, _nonneg(rec.n - 2 * ms), rec.rate, lambda m: _rate_dev(rec, m, "oavar"))
    return t, d, d / np.sqrt(n), n


def mdev(data, rate=1.0, data_type="phase", taus=None) -> Arrays:
    """Modified Allan deviation, as ``allantools.mdev``: (taus, devs, errs, ns)."""
    rec = _Record(data, rate, data_type)
    ms = _ms(taus, rec.n, rec.rate)
    t, d, n = _finish("mdev", ms, _nonneg(rec.n - 3 * ms) + 1, rec.rate, lambda m: _rate_dev(rec, m, "mvar"))
    return t, d, d / np.sqrt(n), n


def tdev(data, rate=1.0, data_type="phase", taus=None) -> Arrays:
    """Time deviation τ·MDEV/√3, as ``allantools.tdev``: (taus, devs, errs, ns)."""
    t, md, _, n = mdev(data, rate, data_type, taus)
    td = t * md / np.sqrt(3.0)
    return t, td, td / np.sqrt(n), n


def hdev(data, rate=1.0, data_type="phase", taus=None) -> Arrays:
    """Hadamard deviation (non-overlapping), as ``allantools.hdev``: (taus, devs, errs, ns)."""
    rec = _Record(data, rate, data_type)
    ms = _ms(taus, rec.n, rec.rate)
    ns = _nonneg(-(-(rec.n - 3 * ms) // ms))
    t, d, n = _finish("hdev", ms, ns, rec.rate, lambda m: _rate_dev(rec, m, "hvar"))
    return t, d, d / np.sqrt(n), n


def ohdev(data, rate=1.0, data_type="phase", taus=None) -> Arrays:
    """Overlapping Hadamard deviation, as ``allantools.ohdev``: (taus, devs, errs, ns)."""
    rec = _Record(data, rate, data_type)
    ms = _ms(taus, rec.n, rec.rate)
    t, d, n = _finish("ohdev", ms, _nonneg(rec.n - 3 * ms), rec.rate, lambda m: _rate_dev(rec, m, "ohvar"))
    return t, d, d / np.sqrt(n), n


def totdev(data, rate=1.0, data_type="phase", taus=None) -> Arrays:
    """Total deviation (no bias correction), as ``allantools.totdev``: (taus, devs, errs, ns)."""
    rec = _Record(data, rate, data_type)
    ms = _ms(taus, rec.n, rec.rate)
    ns = np.full(ms.shape, rec.n - 2)
    t, d, n = _finish("totdev", ms, ns, rec.rate, lambda m: _rate_dev(rec, m, "totvar"))
    return t, d, d / np.sqrt(n), n


def mtotdev(data, rate=1.0, data_type="phase", taus=None) -> Arrays:
    """Modified total deviation (no bias correction), as ``allantools.mtotdev``: (taus, devs, errs, ns)."""
    rec = _Record(data, rate, data_type)
    ms = _ms(taus, rec.n, rec.rate, top=rec.n / 3.0)
    t, d, n = _finish("mtotdev", ms, _nonneg(rec.n - 3 * ms + 1), rec.rate, lambda m: _rate_dev(rec, m, "mtotvar"))
    return t, d, d / np.sqrt(n), n


def ttotdev(data, rate=1.0, data_type="phase", taus=None) -> Arrays:
    """Time total deviation τ·MTOTDEV/√3, as ``allantools.ttotdev``: (taus, devs, errs, ns)."""
    t, md, _, n = mtotdev(data, rate, data_type, taus)
    td = t * md / np.sqrt(3.0)
    return t, td, td / np.sqrt(n), n


def htotdev(data, rate=1.0, data_type="phase", taus=None) -> Arrays:
    """Hadamard total deviation (no bias correction; m = 1 is OHDEV), as ``allantools.htotdev``."""
    rec = _Record(data, rate, data_type)
    # allantools selects τ on the frequency points here, not on the phase points
    length = rec.freq.size
    ms = _ms(taus, length, rec.rate, top=length / 3.0)
    ns = np.where(ms == 1, _nonneg(rec.n - 3 * ms), _nonneg(length - 3 * ms + 1))
    t, d, n = _finish("htotdev", ms, ns, rec.rate, lambda m: _rate_dev(rec, m, "htotvar"))
    return t, d, d / np.sqrt(n), n


def theo1(data, rate=1.0, data_type="phase", taus=None) -> Arrays:
    """Theo1 deviation, as ``allantools.theo1``: even m only, τ labelled m/rate (the value is Theo1 at
    0.75·m/rate); errs = dev/√(N − m), ns = (N − m)·m/2."""
    rec = _Record(data, rate, data_type)
    ms = _ms(taus, rec.n, rec.rate, even=True)
    ns = (rec.n - ms) * ms // 2

    def values(m: list[int]) -> np.ndarray:
        return np.sqrt(_core.theo1_static([np.ascontiguousarray(rec.y)], m, 0)[0])

    t, d, n = _finish("theo1", ms, ns, rec.rate, values)
    return t, d, d / np.sqrt(rec.n - t * rec.rate), n


def mtie(data, rate=1.0, data_type="phase", taus=None) -> Arrays:
    """Maximum time interval error (windows of m + 1 phase points), as ``allantools.mtie``."""
    rec = _Record(data, rate, data_type)
    ms = _ms(taus, rec.n, rec.rate)
    t, d, n = _finish(
        "mtie", ms, rec.n - ms, rec.rate, lambda m: _core.mtie_phase([np.ascontiguousarray(rec.phase)], m, 0)[0]
    )
    return t, d, d / np.sqrt(n), n


def tierms(data, rate=1.0, data_type="phase", taus=None) -> Arrays:
    """Time interval error rms, as ``allantools.tierms`` (its errs are 0)."""
    rec = _Record(data, rate, data_type)
    ms = _ms(taus, rec.n, rec.rate)
    t, d, n = _finish(
        "tierms", ms, rec.n - ms, rec.rate, lambda m: _core.tierms_phase([np.ascontiguousarray(rec.phase)], m, 0)[0]
    )
    return t, d, np.zeros_like(d), n
