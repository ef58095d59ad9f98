"""The deviations of ``allantools.allantools``, computed by allanite's Rust core.

Each has allantools' call shape and return value,
``f(data, rate=1.0, data_type="phase", taus=None) -> (taus, devs, errs, ns)``, and copies its
conventions (written from allantools' documented behaviour; no allantools code is used):

* **τ selection** — ``taus`` is ``None``/``[]``/``"octave"`` (2^k, k ≤ ⌊log2 N⌋), ``"decade"`` (1, 2, 4 ×
  10^k, k ≤ ⌊log10 N⌋), ``"log10"`` (``int(10·log10 N)`` points from 1 to N, log-spaced), ``"all"`` (1 … N)
  or τ in seconds; each τ becomes m = round(τ·rate) (NumPy's round-half-to-even), kept if 0 < m < N
  (and m ≤ N/3 for MTOTDEV/TTOTDEV/HTOTDEV), sorted and de-duplicated; τ whose term count ``ns`` is
  ≤ 1 are dropped. N is the number of phase points (HTOTDEV: of frequency points).
* **phase / frequency** — frequency data lose leading and trailing NaN and their mean before
  integration to phase ``[0, cumsum(y − ȳ)/rate]``; phase data are used as given.
* **Theo1** — only even m, and τ is *labelled* m/rate, while the value is Theo1 at its own τ = 0.75·m/rate.
* **errs** — the value / √ns (TOTDEV: / √(N − 2); Theo1: / √(N − m); TIE rms: 0), not a confidence
  interval (gradev: a confidence interval, see there).
* **ns** — float arrays: the number of terms averaged.
* **no bias correction** — TOTDEV, MTOTDEV, TTOTDEV, HTOTDEV are the definitions' values.

Differences from allantools, all deliberate (``docs/compat.md`` lists them): an interior NaN raises
:class:`~allanite.errors.InputError` naming its position (except in :func:`gradev`, made for gaps), an
unknown ``data_type`` or ``taus`` a :class:`~allanite.errors.ParameterError`, a bad rate a
:class:`~allanite.compat.RateError` (also a ``RuntimeError``), and a record with no usable τ a
:class:`~allanite.compat.NoTauError` (also a ``UserWarning``). Nothing is printed.
"""

from __future__ import annotations

import numpy as np

from .. import _core
from .._validate import check_count
from ..errors import InputError, ParameterError
from ._input import Arrays, NoTauError, Record, averaging_factors, check_rate, finish, refuse_nonfinite, with_errs
from ._intervals import check_ci, confidence_interval, edf_simple
from ._tools import (
    frequency2fractional,
    frequency2phase,
    input_to_phase,
    phase2frequency,
    phase2radians,
    psd2allan,
    remove_small_ns,
    tau_generator,
    tau_reduction,
    three_cornered_hat_phase,
    trim_data,
)

#: The allantools release whose API this module follows, then allanite's own version.
__version__ = "2024.06+allanite." + _core.__version__

__all__ = [
    "__version__",
    "adev",
    "oadev",
    "mdev",
    "pdev",
    "hdev",
    "ohdev",
    "calc_hdev_phase",
    "tdev",
    "totdev",
    "mtotdev",
    "calc_mtotdev_phase",
    "ttotdev",
    "htotdev",
    "calc_htotdev_freq",
    "theo1",
    "mtie",
    "mtie_phase_fast",
    "tierms",
    "gradev",
    "gcodev",
    "frequency2phase",
    "phase2frequency",
    "phase2radians",
    "frequency2fractional",
    "three_cornered_hat_phase",
    "trim_data",
    "psd2allan",
    "tau_generator",
    "tau_reduction",
    "remove_small_ns",
    "input_to_phase",
]


def _rate_var(y: np.ndarray, ms: list[int], estimator: str) -> np.ndarray:
    """The core's variance of rate samples ``y`` (τ0 = 1, the samples' units) at each m."""
    cols = [np.ascontiguousarray(y, dtype=np.float64)]
    if estimator in ("oavar", "avar"):
        return _core.davar(cols, y.size, 1, ms, estimator, "fast", 0)[0, :, 0]
    return _core.deviation_static(cols, ms, estimator, 0)[0]


def _rate_dev(rec: Record, ms: list[int], estimator: str) -> np.ndarray:
    return np.sqrt(_rate_var(rec.y, ms, estimator))


def _nonneg(a: np.ndarray) -> np.ndarray:
    return np.maximum(a, 0)


def adev(data, rate=1.0, data_type="phase", taus=None) -> Arrays:
    """Allan deviation (classic, non-overlapping), as ``allantools.adev``: (taus, devs, errs, ns).

    Examples
    --------
    The 10-point NBS14 phase record (NIST SP 1065 Table 31: ADEV 91.22945 at τ = 1):

    >>> from allanite.compat import adev
    >>> x = [0, 103.11111, 123.22222, 157.33333, 166.44444, 48.55555, -96.33333, -2.22222, 111.88889, 0]
    >>> taus, devs, errs, ns = adev(x, taus=[1, 2])
    >>> devs.round(4).tolist(), ns.tolist()
    ([91.2294, 115.8082], [8.0, 3.0])
    """
    rec = Record(data, rate, data_type)
    ms = averaging_factors(taus, rec.n, rec.rate)
    ns = _nonneg(-(-(rec.n - 2 * ms) // ms))  # clusters starting at 0, m, 2m, … with a full second difference
    return with_errs(*finish("adev", ms, ns, rec.rate, lambda m: _rate_dev(rec, m, "avar")))


def oadev(data, rate=1.0, data_type="phase", taus=None) -> Arrays:
    """Overlapping Allan deviation, as ``allantools.oadev``: (taus, devs, errs, ns)."""
    rec = Record(data, rate, data_type)
    ms = averaging_factors(taus, rec.n, rec.rate)
    return with_errs(*finish("oadev", ms, _nonneg(rec.n - 2 * ms), rec.rate, lambda m: _rate_dev(rec, m, "oavar")))


def mdev(data, rate=1.0, data_type="phase", taus=None) -> Arrays:
    """Modified Allan deviation, as ``allantools.mdev``: (taus, devs, errs, ns)."""
    rec = Record(data, rate, data_type)
    ms = averaging_factors(taus, rec.n, rec.rate)
    return with_errs(*finish("mdev", ms, _nonneg(rec.n - 3 * ms) + 1, rec.rate, lambda m: _rate_dev(rec, m, "mvar")))


def tdev(data, rate=1.0, data_type="phase", taus=None) -> Arrays:
    """Time deviation τ·MDEV/√3 (seconds), as ``allantools.tdev``: (taus, devs, errs, ns)."""
    t, md, _, n = mdev(data, rate, data_type, taus)
    return with_errs(t, t * md / np.sqrt(3.0), n)


def pdev(data, rate=1.0, data_type="phase", taus=None) -> Arrays:
    """Parabolic deviation (Vernotte et al. 2016), as ``allantools.pdev``: (taus, devs, errs, ns).

    σ²_P(τ) = 72/(M m⁴ τ²)·Σ_{i<M} [Σ_{k<m} ((m − 1)/2 − k)(x_{i+k} − x_{i+k+m})]², M = N − 2m terms
    (SigmaTheta's count); at m = 1 PDEV is the (overlapping) ADEV, with N − 2 terms.
    """
    rec = Record(data, rate, data_type)
    ms = averaging_factors(taus, rec.n, rec.rate)
    ns = _nonneg(rec.n - 2 * ms)

    def values(m: list[int]) -> np.ndarray:
        out = np.empty(len(m))
        one = np.array(m) == 1
        if one.any():
            out[one] = _rate_dev(rec, [1], "oavar")[0]
        if (~one).any():
            big = np.array(m)[~one]
            sums, counts = _core.pvar_phase(np.ascontiguousarray(rec.phase), big.tolist(), 0)
            out[~one] = np.sqrt(72.0 * sums / (counts * big.astype(np.float64) ** 6)) * rec.rate
        return out

    return with_errs(*finish("pdev", ms, ns, rec.rate, values))


def hdev(data, rate=1.0, data_type="phase", taus=None) -> Arrays:
    """Hadamard deviation (non-overlapping), as ``allantools.hdev``: (taus, devs, errs, ns)."""
    rec = Record(data, rate, data_type)
    ms = averaging_factors(taus, rec.n, rec.rate)
    ns = _nonneg(-(-(rec.n - 3 * ms) // ms))
    return with_errs(*finish("hdev", ms, ns, rec.rate, lambda m: _rate_dev(rec, m, "hvar")))


def ohdev(data, rate=1.0, data_type="phase", taus=None) -> Arrays:
    """Overlapping Hadamard deviation, as ``allantools.ohdev``: (taus, devs, errs, ns)."""
    rec = Record(data, rate, data_type)
    ms = averaging_factors(taus, rec.n, rec.rate)
    return with_errs(*finish("ohdev", ms, _nonneg(rec.n - 3 * ms), rec.rate, lambda m: _rate_dev(rec, m, "ohvar")))


def calc_hdev_phase(phase, rate, mj, stride):
    """One Hadamard deviation of phase data at m = ``mj`` with terms every ``stride`` points
    (``stride = mj``: HDEV, 1: OHDEV): (dev, dev/√n, n), n the number of third differences."""
    x = np.asarray(phase, dtype=np.float64).ravel()
    refuse_nonfinite(x)
    m, s = check_count(mj, "mj", 1), check_count(stride, "stride", 1)
    v = x[3 * m :: s] - 3.0 * x[2 * m : x.size - m : s] + 3.0 * x[m : x.size - 2 * m : s] - x[: x.size - 3 * m : s]
    n = max(v.size, 1)
    h = np.sqrt(np.dot(v, v) / 6.0 / n) * check_rate(rate) / m
    return h, h / np.sqrt(n), n


def totdev(data, rate=1.0, data_type="phase", taus=None) -> Arrays:
    """Total deviation (no bias correction), as ``allantools.totdev``: (taus, devs, errs, ns)."""
    rec = Record(data, rate, data_type)
    ms = averaging_factors(taus, rec.n, rec.rate)
    ns = np.full(ms.shape, rec.n - 2)
    return with_errs(*finish("totdev", ms, ns, rec.rate, lambda m: _rate_dev(rec, m, "totvar")))


def mtotdev(data, rate=1.0, data_type="phase", taus=None) -> Arrays:
    """Modified total deviation (no bias correction), as ``allantools.mtotdev``: (taus, devs, errs, ns)."""
    rec = Record(data, rate, data_type)
    ms = averaging_factors(taus, rec.n, rec.rate, top=rec.n / 3.0)
    ns = _nonneg(rec.n - 3 * ms + 1)
    return with_errs(*finish("mtotdev", ms, ns, rec.rate, lambda m: _rate_dev(rec, m, "mtotvar")))


def calc_mtotdev_phase(phase, rate, m):
    """One modified total deviation of phase data at m (3m ≤ N): (dev, dev/√n, n), n = N − 3m + 1."""
    rec = Record(phase, rate, "phase")
    m = check_count(m, "m", 1)
    if 3 * m > rec.n:
        raise ParameterError(f"m = {m} needs 3m ≤ N = {rec.n} phase points")
    dev = float(_rate_dev(rec, [m], "mtotvar")[0])
    n = rec.n - 3 * m + 1
    return dev, dev / np.sqrt(n), n


def ttotdev(data, rate=1.0, data_type="phase", taus=None) -> Arrays:
    """Time total deviation τ·MTOTDEV/√3 (seconds), as ``allantools.ttotdev``: (taus, devs, errs, ns)."""
    t, md, _, n = mtotdev(data, rate, data_type, taus)
    return with_errs(t, t * md / np.sqrt(3.0), n)


def htotdev(data, rate=1.0, data_type="phase", taus=None) -> Arrays:
    """Hadamard total deviation (no bias correction; m = 1 is OHDEV), as ``allantools.htotdev``."""
    rec = Record(data, rate, data_type)
    # allantools selects τ on the frequency points here, not on the phase points
    length = rec.freq.size
    ms = averaging_factors(taus, length, rec.rate, top=length / 3.0)
    ns = np.where(ms == 1, _nonneg(rec.n - 3 * ms), _nonneg(length - 3 * ms + 1))
    return with_errs(*finish("htotdev", ms, ns, rec.rate, lambda m: _rate_dev(rec, m, "htotvar")))


def calc_htotdev_freq(freq, m):
    """One Hadamard total deviation of frequency data at m (3m ≤ N): (dev, dev/√n, n), n = N − 3m + 1.

    At m = 1 this is the definition itself, which :func:`htotdev` replaces by OHDEV: a 3-point
    subsequence (a, b, c), detrended and reflected, is u b u u b u u b u with u = (a + c)/2, whose six
    second differences square to 12(u − b)² = 3Δ²: HTOTVAR(1) = mean(Δ²)/12 = OHVAR(1)/2, Δ the second
    difference of the frequency."""
    y = np.asarray(freq, dtype=np.float64).ravel()
    refuse_nonfinite(y)
    m = check_count(m, "m", 1)
    if 3 * m > y.size:
        raise ParameterError(f"m = {m} needs 3m ≤ N = {y.size} frequency points")
    if m == 1:
        d2 = y[2:] - 2.0 * y[1:-1] + y[:-2]
        dev = float(np.sqrt(np.dot(d2, d2) / d2.size / 12.0))
    else:
        dev = float(np.sqrt(_rate_var(y, [m], "htotvar")[0]))
    n = y.size - 3 * m + 1
    return dev, dev / np.sqrt(n), n


def theo1(data, rate=1.0, data_type="phase", taus=None) -> Arrays:
    """Theo1 deviation, as ``allantools.theo1``: even m only, τ labelled m/rate (the value is Theo1 at
    0.75·m/rate); errs = dev/√(N − m), ns = (N − m)·m/2."""
    rec = Record(data, rate, data_type)
    ms = averaging_factors(taus, rec.n, rec.rate, even=True)
    ns = (rec.n - ms) * ms // 2

    def values(m: list[int]) -> np.ndarray:
        return np.sqrt(_core.theo1_static([np.ascontiguousarray(rec.y)], m, 0)[0])

    t, d, n = finish("theo1", ms, ns, rec.rate, values)
    return t, d, d / np.sqrt(rec.n - t * rec.rate), n


def mtie(data, rate=1.0, data_type="phase", taus=None) -> Arrays:
    """Maximum time interval error (windows of m + 1 phase points), as ``allantools.mtie``."""
    rec = Record(data, rate, data_type)
    ms = averaging_factors(taus, rec.n, rec.rate)

    def values(m: list[int]) -> np.ndarray:
        return _core.mtie_phase([np.ascontiguousarray(rec.phase)], m, 0)[0]

    return with_errs(*finish("mtie", ms, rec.n - ms, rec.rate, values))


def mtie_phase_fast(phase, rate=1.0, data_type="phase", taus=None) -> Arrays:
    """MTIE by a fast algorithm — here the exact MTIE of :func:`mtie` (Van Herk / Gil-Werman running
    extremes, O(N) per τ), on the τ asked for. allantools' version is unfinished (its own test expects
    it to fail): it ignores ``taus`` and labels windows of 2^(k+1) points τ = 2^k."""
    return mtie(phase, rate, data_type, taus)


def tierms(data, rate=1.0, data_type="phase", taus=None) -> Arrays:
    """Time interval error rms, as ``allantools.tierms`` (its errs are 0)."""
    rec = Record(data, rate, data_type)
    ms = averaging_factors(taus, rec.n, rec.rate)

    def values(m: list[int]) -> np.ndarray:
        return _core.tierms_phase([np.ascontiguousarray(rec.phase)], m, 0)[0]

    t, d, n = finish("tierms", ms, rec.n - ms, rec.rate, values)
    return t, d, np.zeros_like(d), n


def gcodev(data_1, data_2, rate=1.0, data_type="phase", taus=None) -> Arrays:
    """Groslambert codeviation (Allan covariance of two synchronous measurements), as
    ``allantools.gcodev``: (taus, devs, errs, ns), dev = √(|Σ Δ²x1·Δ²x2| / (2n))·rate/m over the
    n = N − 2m overlapping second differences (the covariance's sign is dropped, as allantools does).
    Vernotte, Lenczner, Bourgeois & Rubiola 2016; Lantz et al. 2019."""
    r1, r2 = Record(data_1, rate, data_type), Record(data_2, rate, data_type)
    if r1.n != r2.n:
        raise InputError(f"data_1 and data_2 must have the same length, got {r1.n} and {r2.n} phase points")
    ms = averaging_factors(taus, r1.n, r1.rate)

    def values(m: list[int]) -> np.ndarray:
        p1, p2 = np.ascontiguousarray(r1.phase), np.ascontiguousarray(r2.phase)
        sums, counts = _core.allan_covariance_phase(p1, p2, m, 0)
        return np.sqrt(np.abs(sums) / (2.0 * counts)) * r1.rate / np.array(m, dtype=np.float64)

    return with_errs(*finish("gcodev", ms, _nonneg(r1.n - 2 * ms), r1.rate, values))


#: gradev's noise types and their α (S_y ∝ f^α), as its docstring lists them
_GRADEV_NOISE = {"wp": 2, "fp": 1, "wf": 0, "ff": -1, "rf": -2}


def gradev(data, rate=1.0, data_type="phase", taus=None, ci=0.9, noisetype="wp"):
    """Gap-resistant overlapping Allan deviation, as ``allantools.gradev``: missing phase points are
    NaN, and each second difference with a missing point is left out (Sesia et al. 2016).

    Returns (taus, devs, [err_lo, err_hi], ns): ns the second differences used; the errors are the
    distances from dev to the bounds of the ``ci`` (e.g. 0.9: 5 %…95 %) χ² interval with SP 1065's
    simple EDF (:func:`~allanite.compat.edf_simple`) for ``noisetype`` 'wp', 'fp', 'wf', 'ff' or 'rf'
    (anything else: N − 1 degrees of freedom), N the phase points present. allantools' own errors come
    out NaN (its interval call swaps two arguments). Frequency data are integrated as everywhere
    (leading/trailing NaN trimmed), so a NaN inside them leaves the phase after it unknown — pass phase.
    """
    rec = Record(data, rate, data_type, finite=False)
    if np.any(np.isinf(rec.phase)):
        refuse_nonfinite(rec.phase[~np.isnan(rec.phase)])
    ms = averaging_factors(taus, rec.n, rec.rate)
    ms = ms[2 * ms < rec.n]  # longer m have no second difference (allantools: ns = 0, dropped)
    sums, counts = np.zeros(ms.size), np.zeros(ms.size, dtype=np.int64)
    if ms.size:
        sums, counts = _core.oavar_phase_gaps(np.ascontiguousarray(rec.phase), ms.astype(np.int64).tolist(), 0)
    keep = counts > 1
    if not keep.any():
        raise NoTauError("gradev: no τ of the requested ones has more than one complete term for this record")
    ms, sums, counts = ms[keep], sums[keep], counts[keep].astype(np.float64)
    devs = np.sqrt(sums / (2.0 * counts)) * rec.rate / ms
    n_present = int(np.count_nonzero(~np.isnan(rec.phase)))
    lo, hi = _gradev_bounds(devs, ms, n_present, noisetype, ci)
    return ms / rec.rate, devs, [devs - lo, hi - devs], counts


def _gradev_bounds(devs: np.ndarray, ms: np.ndarray, n_present: int, noisetype, ci) -> tuple[np.ndarray, np.ndarray]:
    """gradev's χ² bounds at every τ; NaN where SP 1065's formula has no EDF (N < 2m + 1 points)."""
    check_ci(ci)
    alpha = _GRADEV_NOISE.get(noisetype)
    edf = np.full(ms.size, np.nan)
    ok = n_present >= 2 * ms + 1
    if ok.any():
        edf[ok] = edf_simple(n_present, ms[ok], alpha)
    ok &= edf > 0
    lo, hi = np.full(ms.size, np.nan), np.full(ms.size, np.nan)
    if ok.any():
        lo[ok], hi[ok] = confidence_interval(devs[ok], edf[ok], ci)
    return lo, hi
