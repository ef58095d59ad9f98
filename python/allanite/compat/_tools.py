"""allantools' helpers: conversions between phase, frequency and radians, NaN trimming, τ lists,
the three-cornered hat, and Allan deviation from a power spectral density. Plain NumPy/SciPy,
written from allantools' documented behaviour (no allantools code is used)."""

from __future__ import annotations

import numpy as np

from ..errors import InputError, ParameterError
from ._input import NoTauError, averaging_factors, check_data_type, check_rate, integrated


def frequency2phase(freqdata, rate):
    """Integrate fractional frequency to phase in seconds, as allantools: leading and trailing NaN
    are dropped, the mean removed, and the phase starts at 0 — N + 1 points for N frequency samples.

    Examples
    --------
    >>> from allanite.compat import frequency2phase
    >>> frequency2phase([1.0, 2.0, 3.0], 2.0).tolist()
    [0.0, -0.5, -0.5, 0.0]
    """
    return integrated(freqdata, check_rate(rate))


def phase2frequency(phase, rate):
    """Fractional frequency ``rate·diff(phase)`` (N − 1 samples for N phase points)."""
    return check_rate(rate) * np.diff(np.asarray(phase, dtype=np.float64))


def phase2radians(phasedata, v0):
    """Phase in seconds to radians of an oscillator at ``v0`` Hz: 2π·v0·x."""
    return 2.0 * np.pi * float(v0) * np.asarray(phasedata, dtype=np.float64)


def frequency2fractional(frequency, mean_frequency=-1):
    """Frequency in Hz to fractional frequency (f − f0)/f0, f0 = ``mean_frequency`` or, when it is −1
    (the default), the mean of the data. A list, as allantools returns it."""
    f = np.asarray(frequency, dtype=np.float64)
    mu = np.mean(f) if mean_frequency == -1 else float(mean_frequency)
    return ((f - mu) / mu).tolist()


def input_to_phase(data, rate, data_type):
    """Phase data as given, frequency data integrated (:func:`frequency2phase`)."""
    if check_data_type(data_type) == "phase":
        return data
    return frequency2phase(data, rate)


def trim_data(x):
    """``x`` without its leading and trailing NaN; NaN inside are kept.

    Examples
    --------
    >>> import numpy as np
    >>> from allanite.compat import trim_data
    >>> trim_data(np.array([np.nan, 1.0, np.nan, 2.0, np.nan])).tolist()
    [1.0, nan, 2.0]
    """
    ok = np.flatnonzero(~np.isnan(np.asarray(x, dtype=np.float64)))
    if ok.size == 0:
        return x[:0]
    return x[int(ok[0]) : int(ok[-1]) + 1]


def tau_generator(data, rate, taus=None, v=False, even=False, maximum_m=-1):
    """allantools' τ list: ``(data as an array, m, taus)`` with m = round(τ·rate) for ``taus`` (None,
    ``[]``, "octave", "decade", "log10", "all" or τ in seconds), 0 < m < len(data), m ≤ ``maximum_m``
    (−1: no limit), sorted, de-duplicated; ``even`` keeps even m only (Theo1). ``v`` is accepted and
    ignored (nothing is printed).

    Examples
    --------
    >>> from allanite.compat.allantools import tau_generator
    >>> _, m, taus = tau_generator(range(10), 2.0, taus="octave")
    >>> m.tolist(), taus.tolist()
    ([1.0, 2.0, 4.0, 8.0], [0.5, 1.0, 2.0, 4.0])
    """
    r = check_rate(rate)
    data = np.asarray(data)
    top = None if maximum_m == -1 else float(maximum_m)
    m = averaging_factors(taus, data.size, r, top=top, even=even)
    return data, m, m / r


def tau_reduction(ms, rate, n_per_decade):
    """Thin a dense list of m to at most ``n_per_decade`` per decade: an m is kept when the next one
    falls in another bin rint(n_per_decade·log10 m); the last m is dropped. Returns (m, m/rate).

    Examples
    --------
    >>> from allanite.compat.allantools import tau_reduction
    >>> tau_reduction(range(1, 43), 1.0, 2)[0].tolist()
    [1, 5, 17]
    """
    ms = np.asarray(ms).astype(np.int64)
    bins = np.rint(n_per_decade * np.log10(ms))
    ms = ms[:-1][bins[1:] != bins[:-1]]
    return ms, ms / float(rate)


def remove_small_ns(taus, devs, deverrs, ns):
    """Keep the τ with more than one term (ns > 1); ``deverrs`` may be one array or a list of two
    (lower, upper). Raises :class:`~allanite.compat.NoTauError` (a ``UserWarning``) when none is left."""
    keep = np.asarray(ns) > 1
    if isinstance(deverrs, list):
        if len(deverrs) != 2:
            raise ParameterError(f"deverrs must be one array or a list of two, got a list of {len(deverrs)}")
        errs = [np.asarray(deverrs[0])[keep], np.asarray(deverrs[1])[keep]]
    else:
        errs = np.asarray(deverrs)[keep]
    if not keep.any():
        raise NoTauError("remove_small_ns: no τ has more than one term")
    return np.asarray(taus)[keep], np.asarray(devs)[keep], errs, np.asarray(ns)[keep]


def three_cornered_hat_phase(phasedata_ab, phasedata_bc, phasedata_ca, rate, taus, function):
    """Three-cornered hat: clock A's deviation from the phase differences AB, BC, CA,
    σ²_A = (σ²_AB + σ²_CA − σ²_BC)/2 (clipped at 0), with ``function`` any deviation of this module.
    Returns (taus, dev_A, errs as a list (dev/√n), ns of AB). Riley, *The three-cornered hat*."""
    out = [function(p, data_type="phase", rate=rate, taus=taus) for p in (phasedata_ab, phasedata_bc, phasedata_ca)]
    (tau_ab, dev_ab, _, ns_ab), (_, dev_bc, _, _), (_, dev_ca, _, _) = out
    if not len(dev_ab) == len(dev_bc) == len(dev_ca):
        raise InputError(
            f"the three records give {len(dev_ab)}, {len(dev_bc)} and {len(dev_ca)} τ: they must have equal lengths"
        )
    var_a = np.maximum(0.5 * (dev_ab**2 + dev_ca**2 - dev_bc**2), 0.0)
    dev_a = np.sqrt(var_a)
    return tau_ab, dev_a, [d / np.sqrt(n) for d, n in zip(dev_a, ns_ab)], ns_ab


def _psd_taus(df: float, fmax: float, base) -> tuple[np.ndarray, float]:
    """allantools' τ list of psd2allan: τ0 = 1/f_max, n = f_max/(2·df); m = base^k (k < ⌊log_base n⌋)
    and n itself, rounded and de-duplicated, or every m < n when base ≤ 1."""
    tau0 = 1.0 / fmax
    n = fmax / (2.0 * df)
    if base > 1:
        k = np.arange(np.floor(np.log(n) / np.log(base)))
        m = np.unique(np.round(np.append(float(base) ** k, n)))
    else:
        m = np.arange(1, n)
    return m, tau0


def psd2allan(S_y, f=1.0, kind="adev", base=2):
    """Allan (``kind="adev"``) or modified Allan (``"mdev"``) deviation from a one-sided PSD of fractional
    frequency, NIST SP 1065 eqs. 65–66: σ²(τ) = 2∫ S_y(f)·|sin^{k+1}(πfτ)/(πfτ)^k|² df, k = 1 (ADEV) or
    2 (MDEV). ``S_y[0]`` is at f = 0; ``f`` is the frequency axis (an array) or its step (a number).

    The integral is taken over S_y's cubic-spline interpolant, refined 8× (the integrand oscillates
    with period 1/τ in f), by Simpson's rule. Returns (taus, deviations) on allantools' τ list: τ0 =
    1/f_max, m = base^k up to f_max/(2·df) and that value itself (base ≤ 1: every m).
    """
    from scipy.interpolate import CubicSpline

    if not isinstance(S_y, np.ndarray):
        raise ParameterError(f"S_y must be a numpy array, got {type(S_y).__name__}")
    if isinstance(f, np.ndarray):
        df = float(f[1] - f[0])
    elif np.isscalar(f):
        df = float(f)
    else:
        raise ParameterError(f"f must be a frequency array or a frequency step, got {type(f).__name__}")
    if str(kind)[:1].lower() not in ("a", "m"):
        raise ParameterError(f'kind must be "adev" or "mdev", got {kind!r}')
    k = 1 if str(kind)[0].lower() == "a" else 2
    s = np.asarray(S_y, dtype=np.float64)
    f0 = df * np.arange(s.size)
    m, tau0 = _psd_taus(df, f0[-1], base)
    fine = np.linspace(0.0, f0[-1], 8 * (s.size - 1) + 1)
    spec = CubicSpline(f0, s)(fine)
    taus = m * tau0
    # composite Simpson weights on the uniform fine grid (an odd number of points: 8(n − 1) + 1)
    w = np.full(fine.size, 2.0)
    w[1::2] = 4.0
    w[0] = w[-1] = 1.0
    sw = spec * w * ((fine[1] - fine[0]) / 3.0)
    var = np.empty(taus.size)
    for lo in range(0, taus.size, 64):  # 64 τ at a time: memory stays O(64·len(fine))
        arg = np.pi * fine[None, :] * taus[lo : lo + 64, None]
        sin = np.sin(arg)
        with np.errstate(invalid="ignore", divide="ignore"):
            h = sin * (sin / arg) ** k  # sin^(k+1)(πfτ)/(πfτ)^k with an integer power
        h[arg == 0.0] = 0.0
        var[lo : lo + 64] = 2.0 * ((h * h) @ sw)
    return taus, np.sqrt(var)
