"""``allantools.ci``: confidence intervals, equivalent degrees of freedom and noise identification.

The EDFs are allanite's (:func:`allanite.edf_greenhall`, SP 1065's tables); the noise identification
is Riley & Greenhall's lag-1 autocorrelation method (W. J. Riley, C. A. Greenhall, *Power law noise
identification using the lag 1 autocorrelation*, Proc. 18th EFTF, 2004) as allantools applies it, and
the B1 / R(n) ratios of Barnes (1969) and Howe, Beard, Greenhall & Riley (2000). Written from those
sources and allantools' documented behaviour; no allantools code is used. Nothing is printed.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ParameterError
from ..estimators import confidence
from ..estimators._edf_deviations import edf_mtotvar, edf_totvar
from ._intervals import ONE_SIGMA_CI, confidence_interval, edf_simple
from .allantools import adev, mdev

__all__ = [
    "ONE_SIGMA_CI",
    "confidence_interval",
    "confidence_interval_noiseID",
    "rn",
    "rn_theory",
    "rn_boundary",
    "b1",
    "b1_theory",
    "b1_boundary",
    "b_to_mu",
    "lag1_acf",
    "autocorr_noise_id",
    "detrend",
    "edf_greenhall",
    "edf_totdev",
    "edf_mtotdev",
    "edf_simple",
]

#: (d, overlapping, modified) of Greenhall's EDF for each deviation confidence_interval_noiseID takes
_GREENHALL_CASES = {
    "adev": (2, False, False),
    "oadev": (2, True, False),
    "mdev": (2, True, True),
    "tdev": (2, True, True),
    "hdev": (3, False, False),
    "ohdev": (3, True, False),
}


def _integral(value, name: str) -> int:
    v = float(value)
    if not np.isfinite(v) or v != round(v):
        raise ParameterError(f"{name} must be an integer, got {value!r}")
    return int(round(v))


def edf_greenhall(alpha, d, m, N, overlapping=False, modified=False, verbose=False):
    """Greenhall & Riley's EDF of a d-th difference variance (:func:`allanite.edf_greenhall`), with
    allantools' defaults (classic, unmodified). ``verbose`` is accepted and ignored.

    Where allantools differs: it raises ``NotImplementedError`` for unmodified white PM with fewer
    than d + 1 summands per stride (here the paper's closed form), takes the short-record branch at
    exactly r = d + 1 (here the table, as for r > d + 1), and returns a negative EDF for records
    shorter than the filter (here a ParameterError naming N).

    Examples
    --------
    >>> from allanite.compat import edf_greenhall
    >>> round(float(edf_greenhall(0, 2, 100, 1001, overlapping=True)), 2)
    12.81
    """
    return confidence.edf_greenhall(
        _integral(alpha, "alpha"), _integral(d, "d"), _integral(m, "m"), _integral(N, "N"), overlapping, modified
    )


def edf_totdev(N, m, alpha):
    """EDF of TOTDEV, b·N/m − c (NIST SP 1065 Table 7) for α = 0, −1, −2; otherwise :func:`edf_simple`."""
    a = _integral(alpha, "alpha")
    if a not in (0, -1, -2):
        return edf_simple(N, m, a)
    return edf_totvar(a, _integral(m, "m"), _integral(N, "N"))


def edf_mtotdev(N, m, alpha):
    """EDF of MTOTDEV, b·N/m − c (NIST SP 1065 Table 8) for α = 2 … −2."""
    return edf_mtotvar(_integral(alpha, "alpha"), _integral(m, "m"), _integral(N, "N"))


def confidence_interval_noiseID(x, dev, af, dev_type="adev", data_type="phase", ci=ONE_SIGMA_CI):
    """Confidence interval (dev_min, dev_max) of ``dev`` = a ``dev_type`` deviation of ``x`` at averaging
    factor ``af``: the noise type from :func:`autocorr_noise_id`, Greenhall's EDF with N = len(x),
    then :func:`confidence_interval`. ``dev_type``: adev, oadev, mdev, tdev, hdev or ohdev (others:
    ``NotImplementedError``, as noise identification on fewer than 30 points)."""
    if dev_type not in _GREENHALL_CASES:
        raise NotImplementedError(f"dev_type {dev_type!r}: only {', '.join(_GREENHALL_CASES)} have a Greenhall EDF")
    d, overlapping, modified = _GREENHALL_CASES[dev_type]
    alpha = autocorr_noise_id(x, int(af), data_type=data_type, dmin=0, dmax=3 if d == 3 else 2)[0]
    edf = edf_greenhall(alpha, d, af, len(x), overlapping=overlapping, modified=modified)
    return confidence_interval(dev, edf, ci)


def lag1_acf(x, detrend_deg=1):
    """Lag-1 autocorrelation r1 = Σ(x_n − x̄)(x_{n+1} − x̄) / Σ(x_n − x̄)² (Riley & Greenhall 2004,
    eq. 2; no (N − 1)/N factor). ``detrend_deg`` is accepted and unused, as in allantools."""
    z = np.asarray(x, dtype=np.float64)
    z = z - z.mean()
    return float(np.dot(z[:-1], z[1:]) / np.dot(z, z))


def detrend(x, deg=1):
    """``x`` minus its least-squares polynomial of degree ``deg`` in the sample index."""
    z = np.asarray(x, dtype=np.float64)
    t = np.arange(z.size)
    return z - np.polyval(np.polyfit(t, z, deg), t)


def autocorr_noise_id(x, af, data_type="phase", dmin=0, dmax=2):
    """Power-law noise identification from the lag-1 autocorrelation (Riley & Greenhall 2004):
    (alpha_int, alpha, d, rho).

    Phase data are decimated by ``af`` and lose a quadratic; frequency data are averaged in groups of
    ``af`` and lose a line. Then the series is differenced (d times, ``dmin`` ≤ d ≤ ``dmax``) until
    ρ = r1/(1 + r1) < 0.25; p = −2(ρ + d), alpha = p (+ 2 for phase data), alpha_int = −round(2ρ) − 2d
    (+ 2). Fewer than 30 points after decimation: ``NotImplementedError``, as allantools.
    """
    z = np.asarray(x, dtype=np.float64)
    af = _integral(af, "af")
    if af < 1:
        raise ParameterError(f"af must be an averaging factor ≥ 1, got {af}")
    phase = data_type == "phase"
    if phase:
        z = detrend(z[::af], deg=2)
    elif data_type == "freq":
        k = z.size // af
        z = detrend(z[: k * af].reshape(k, af).mean(axis=1), deg=1)
    else:
        raise ParameterError(f'data_type must be "phase" or "freq", got {data_type!r}')
    if z.size < 30:
        raise NotImplementedError(f"noise identification needs at least 30 points after averaging, got {z.size}")
    d = 0
    while True:
        r1 = lag1_acf(z)
        rho = r1 / (1.0 + r1)
        if d >= dmin and (rho < 0.25 or d >= dmax):
            shift = 2 if phase else 0
            return int(-np.round(2 * rho) - 2 * d) + shift, -2.0 * (rho + d) + shift, d, rho
        z = np.diff(z)
        d += 1


def b1(x, af, rate):
    """Barnes' B1 ratio: the N-sample variance of the ``af``-averaged frequency (from phase ``x``, unscaled
    differences) over the Allan variance at τ = af·rate — allantools' arguments, which agree with
    τ = af/rate only at rate = 1."""
    avar = adev(x, taus=[af * rate], data_type="phase", rate=rate)[1][0] ** 2
    y = np.diff(np.asarray(x, dtype=np.float64))
    k = y.size // int(af)
    return float(np.var(y[: k * int(af)].reshape(k, int(af)).mean(axis=1), ddof=1) / avar)


def b1_theory(N, mu):
    """Expected B1 for N averages and the exponent μ of the Allan variance's τ^μ (Barnes 1969):
    N(1 − N^μ) / (2(N − 1)(1 − 2^μ)), with its limit N ln N / (2(N − 1) ln 2) at μ = 0."""
    N = float(N)
    if mu == 0:
        return N * math.log(N) / (2.0 * (N - 1.0) * math.log(2.0))
    return N * (1.0 - N**mu) / (2.0 * (N - 1.0) * (1.0 - 2.0**mu))


#: μ (AVAR ∝ τ^μ) of each phase-PSD exponent b (S_x ∝ f^b, α = b + 2)
_MU_OF_B = {0: -2, -1: -2, -2: -1, -3: 0, -4: 1, -5: 2, -6: 3}


def b_to_mu(b):
    """μ of the Allan variance (∝ τ^μ) for the phase-PSD exponent b (α = b + 2): WPM and FPM −2, WFM −1,
    FFM 0, RWFM 1, and 2, 3 for the two redder types."""
    if b not in _MU_OF_B:
        raise ParameterError(f"b must be one of {sorted(_MU_OF_B)}, got {b!r}")
    return _MU_OF_B[b]


def b1_boundary(b_hi, N):
    """B1 boundary between the noise types b_hi − 1 and b_hi: the geometric mean of their B1."""
    return math.sqrt(b1_theory(N, b_to_mu(b_hi - 1)) * b1_theory(N, b_to_mu(b_hi)))


def rn(x, af, rate):
    """R(n) = MVAR/AVAR of phase ``x`` at τ = af·rate (allantools' arguments, as :func:`b1`)."""
    a = adev(x, taus=[af * rate], data_type="phase", rate=rate)[1][0]
    m = mdev(x, taus=[af * rate], data_type="phase", rate=rate)[1][0]
    return float((m / a) ** 2)


def rn_theory(af, b):
    """Expected R(n) at averaging factor ``af`` for the phase-PSD exponent b (IEEE 1139; f_h = 1/(2τ0)):
    1/af for WPM (b = 0), [3 ln(256/27)/(8π²)] / [(1.038 + 3 ln(π·af))/(4π²)] for FPM, 1 otherwise."""
    if b == 0:
        return 1.0 / af
    if b == -1:
        avar = (1.038 + 3.0 * math.log(2.0 * math.pi * 0.5 * af)) / (4.0 * math.pi**2)
        mvar = 3.0 * math.log(256.0 / 27.0) / (8.0 * math.pi**2)
        return mvar / avar
    return 1.0


def rn_boundary(af, b_hi):
    """R(n) boundary between b_hi − 1 and b_hi: the geometric mean of their expected R(n)."""
    return math.sqrt(rn_theory(af, b_hi) * rn_theory(af, b_hi - 1))
