"""``allantools.noise_kasdin``: the Noise class — power-law phase noise and its predicted deviations.

The series is N. J. Kasdin and T. Walter's discrete power-law noise (*Discrete simulation of power
law noise*, Proc. IEEE FCS 1992): white samples of variance Q_d filtered by h_0 = 1,
h_k = h_{k−1}(k − 1 − b/2)/k (:func:`allanite.simulation.power_law_filter` with α = −b), whose phase
PSD is S_x(f) = 2Q_d·τ0·(2π f τ0)^b at f ≪ 1/τ0 (their eq. 39), i.e. S_x = g_b f^b with
g_b = 2Q_d(2π)^b τ0^(b+1), and S_y = (2πf)² S_x = h_a f^a, a = b + 2, h_a = 2Q_d(2π)^a τ0^(a−1).

The predicted deviations are the asymptotic (τ ≫ τ0) power-law forms, each the integral of S_y
against the estimator's transfer function (NIST SP 1065 §A; E. S. Ferre-Pikal et al., IEEE 1139;
F. Vernotte et al., IEEE TUFFC 63(4) 2016 for PVAR), with f_h = 1/(2τ0) and γ Euler's constant:

=====  ======================  ======================================  ==========================
b      AVAR / h_a              MVAR / h_a                              PVAR / h_a
=====  ======================  ======================================  ==========================
 0     3f_h/(4π²)·τ⁻²          3/(8π²)·τ⁻³                             3/(2π²)·τ⁻³
−1     (3γ − ln2 + 3ln(2πf_hτ))  3ln(256/27)/(8π²)·τ⁻²                  3(ln16 − 1)/(2π²)·τ⁻²
       /(4π²)·τ⁻²
−2     1/(2τ)                  1/(4τ)                                  3/(5τ)
−3     2 ln2                   (27/8)ln3 − 4 ln2                       2(7 − ln16)/5
−4     (2π²/3)·τ               (11π²/20)·τ                             (26π²/35)·τ
=====  ======================  ======================================  ==========================

Two constants differ from allantools', which uses (27/20)·ln2 (5.6e-4 larger) for MVAR at b = −3 and
(3 ln16 − 1)/(2π²) (38 % larger) for PVAR at b = −1; the values here are the transfer-function
integrals (``tests/test_compat_noise.py`` integrates them).
"""

from __future__ import annotations

import math

import numpy as np

from .._validate import check_count
from ..errors import ParameterError
from ..simulation import power_law_filter

__all__ = ["Noise"]

_GAMMA = 0.57721566490153286061  # Euler's constant

#: τ exponent c of AVAR and MVAR (∝ τ^c) for each phase exponent b
_C_AVAR = {0: -2.0, -1: -2.0, -2: -1.0, -3: 0.0, -4: 1.0}
_C_MVAR = {0: -3.0, -1: -2.0, -2: -1.0, -3: 0.0, -4: 1.0}


class Noise:
    """Discrete power-law noise of phase exponent ``b`` (0 WPM, −1 FPM, −2 WFM, −3 FFM, −4 RWFM), ``nr``
    points, discrete variance ``qd``, as ``allantools.Noise``. :meth:`generateNoise` fills
    ``time_series`` from NumPy's global random state.

    Examples
    --------
    >>> import numpy as np
    >>> from allanite.compat import Noise, adev
    >>> np.random.seed(3)
    >>> n = Noise(nr=2**16, qd=1e-20, b=-2)
    >>> n.generateNoise()
    >>> measured = adev(n.time_series, taus=[10.0])[1][0]
    >>> round(float(measured / n.adev(tau0=1.0, tau=10.0)), 1)
    1.0
    """

    def __init__(self, nr=2, qd=1, b=0):
        self.nr = nr
        self.qd = qd
        self.b = b
        self.time_series = np.array([])

    def set_input(self, nr=2, qd=1, b=0):
        """Sets the length, discrete variance and noise type."""
        self.nr = nr
        self.qd = qd
        self.b = b

    def generateNoise(self):
        """Draws ``nr`` white samples of variance ``qd`` and filters them (Kasdin & Walter); the result
        is ``time_series``. Any ``nr`` ≥ 1 works (allantools asks for a power of two)."""
        n = check_count(self.nr, "nr", 1)
        if float(self.qd) < 0:
            raise ParameterError(f"qd must be a variance ≥ 0, got {self.qd!r}")
        w = np.random.normal(0.0, math.sqrt(float(self.qd)), n)
        self.time_series = power_law_filter(w, -float(self.b)) if n > 1 else w

    def phase_psd_from_qd(self, tau0=1.0):
        """g_b of S_x(f) = g_b·f^b: 2·qd·(2π)^b·τ0^(b+1) (Kasdin & Walter eq. 39)."""
        return self.qd * 2.0 * (2.0 * np.pi) ** self.b * tau0 ** (self.b + 1.0)

    def frequency_psd_from_qd(self, tau0=1.0):
        """h_a of S_y(f) = h_a·f^a, a = b + 2: 2·qd·(2π)^a·τ0^(a−1)."""
        a = self.b + 2.0
        return self.qd * 2.0 * (2.0 * np.pi) ** a * tau0 ** (a - 1.0)

    def _b(self) -> int:
        if self.b not in _C_AVAR:
            raise ParameterError(f"b must be 0, -1, -2, -3 or -4 for a predicted deviation, got {self.b!r}")
        return int(self.b)

    def c_avar(self):
        """τ exponent c of AVAR ∝ τ^c for this noise type."""
        return _C_AVAR[self._b()]

    def c_mvar(self):
        """τ exponent c of MVAR ∝ τ^c for this noise type."""
        return _C_MVAR[self._b()]

    def adev_from_qd(self, tau0=1.0, tau=1.0):
        """√(K·h_a), with AVAR = K·h_a·τ^c (table in the module docstring)."""
        fh = 0.5 / tau0
        k = {
            0: 3.0 * fh / (4.0 * np.pi**2),
            -1: (3.0 * _GAMMA - math.log(2.0) + 3.0 * np.log(2.0 * np.pi * fh * tau)) / (4.0 * np.pi**2),
            -2: 0.5,
            -3: 2.0 * math.log(2.0),
            -4: 2.0 * np.pi**2 / 3.0,
        }[self._b()]
        return np.sqrt(k * self.frequency_psd_from_qd(tau0))

    def mdev_from_qd(self, tau0=1.0, tau=1.0):
        """√(K·h_a), with MVAR = K·h_a·τ^c (τ ≫ τ0; ``tau`` unused)."""
        k = {
            0: 3.0 / (8.0 * np.pi**2),
            -1: 3.0 * math.log(256.0 / 27.0) / (8.0 * np.pi**2),
            -2: 0.25,
            -3: 27.0 / 8.0 * math.log(3.0) - 4.0 * math.log(2.0),
            -4: 11.0 * np.pi**2 / 20.0,
        }[self._b()]
        return np.sqrt(k * self.frequency_psd_from_qd(tau0))

    def pdev_from_qd(self, tau0=1.0, tau=1.0):
        """√(K·h_a), with PVAR = K·h_a·τ^c (c as for MVAR; ``tau`` unused)."""
        k = {
            0: 3.0 / (2.0 * np.pi**2),
            -1: 3.0 * (math.log(16.0) - 1.0) / (2.0 * np.pi**2),
            -2: 0.6,
            -3: 2.0 * (7.0 - math.log(16.0)) / 5.0,
            -4: 26.0 * np.pi**2 / 35.0,
        }[self._b()]
        return np.sqrt(k * self.frequency_psd_from_qd(tau0))

    def adev(self, tau0, tau):
        """Predicted ADEV at ``tau`` for samples every ``tau0``."""
        return np.sqrt(self.adev_from_qd(tau0=tau0, tau=tau) ** 2 * tau ** self.c_avar())

    def mdev(self, tau0, tau):
        """Predicted MDEV at ``tau`` for samples every ``tau0``."""
        return np.sqrt(self.mdev_from_qd(tau0=tau0, tau=tau) ** 2 * tau ** self.c_mvar())
