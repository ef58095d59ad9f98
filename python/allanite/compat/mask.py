"""``allantools.mask``: ITU-T TDEV and MTIE masks of primary reference (time) clocks, in seconds.

Each mask is a table of pieces a + b·τ, each up to a bound on τ (seconds), from

* G.811 (1997) Amd. 1 (2016), primary reference clock (PRC): TDEV Table 3, MTIE Table 2;
* G.8272/Y.1367 (2018), primary reference time clock classes A and B (PRTC-A, PRTC-B): MTIE Tables 1–2,
  TDEV Tables 3–4;
* G.8272.1/Y.1367.1 (2016) Amd. 1 (2017), enhanced PRTC (ePRTC): MTIE Table 1, TDEV Table 2.

Every function takes τ as a number or an array (allantools: a number) and returns the same shape. A
bound belongs to the piece below it for the ePRTC MTIE mask and to the piece above it elsewhere (as in
allantools; the masks are continuous there, but for ≤ 1e-3 relative steps). The ePRTC TDEV slope is
1 ns/30 000 s, continuous at both ends (allantools rounds it to 3.33333e-5 ns/s).
"""

from __future__ import annotations

import numpy as np

__all__ = ["prc_tdev", "prc_mtie", "eprtc_tdev", "eprtc_mtie", "prtcA_tdev", "prtcB_tdev", "prtcA_mtie", "prtcB_mtie"]

_INF = float("inf")
NS, US = 1e-9, 1e-6

#: (upper τ bound in s, a in s, b in s/s): the mask is a + b·τ up to the bound
MASKS = {
    "prc_tdev": [(100.0, 3 * NS, 0.0), (1000.0, 0.0, 0.03 * NS), (_INF, 30 * NS, 0.0)],
    "prc_mtie": [(1000.0, 0.025 * US, 0.275e-3 * US), (_INF, 0.29 * US, 1e-5 * US)],
    "eprtc_tdev": [(3e4, 1 * NS, 0.0), (3e5, 0.0, NS / 3e4), (_INF, 10 * NS, 0.0)],
    "eprtc_mtie": [
        (1.0, 4 * NS, 0.0),
        (100.0, 3.89 * NS, 0.11114 * NS),
        (4e5, 15 * NS, 0.0375e-3 * NS),
        (_INF, 30 * NS, 0.0),
    ],
    "prtcA_tdev": [(100.0, 3 * NS, 0.0), (1000.0, 0.0, 0.03 * NS), (_INF, 30 * NS, 0.0)],
    "prtcB_tdev": [(100.0, 1 * NS, 0.0), (500.0, 0.0, 0.01 * NS), (_INF, 5 * NS, 0.0)],
    "prtcA_mtie": [(273.0, 0.025 * US, 0.275e-3 * US), (_INF, 0.1 * US, 0.0)],
    "prtcB_mtie": [(54.5, 0.025 * US, 0.275e-3 * US), (_INF, 0.04 * US, 0.0)],
}


#: masks whose bounds belong to the piece below them
INCLUSIVE = {"eprtc_mtie"}


def _mask(name: str, tau):
    t = np.asarray(tau, dtype=np.float64)
    pieces = MASKS[name]
    below = np.less_equal if name in INCLUSIVE else np.less
    out = np.select([below(t, hi) for hi, _, _ in pieces], [a + b * t for _, a, b in pieces], np.nan)
    return float(out) if out.ndim == 0 else out


def prc_tdev(tau):
    """TDEV mask of a primary reference clock (G.811): 3 ns to 100 s, 0.03·τ ns to 1000 s, then 30 ns.

    Examples
    --------
    >>> from allanite.compat import mask
    >>> mask.prc_tdev(500)
    1.5e-08
    """
    return _mask("prc_tdev", tau)


def prc_mtie(tau):
    """MTIE mask of a primary reference clock (G.811): 0.275e-3·τ + 0.025 µs to 1000 s, then 1e-5·τ + 0.29 µs."""
    return _mask("prc_mtie", tau)


def eprtc_tdev(tau):
    """TDEV mask of an enhanced primary reference time clock (G.8272.1): 1 ns to 30 000 s, rising to
    10 ns at 300 000 s, then 10 ns."""
    return _mask("eprtc_tdev", tau)


def eprtc_mtie(tau):
    """MTIE mask of an ePRTC (G.8272.1): 4 ns to 1 s, 0.11114·τ + 3.89 ns to 100 s,
    0.0375e-3·τ + 15 ns to 400 000 s, then 30 ns."""
    return _mask("eprtc_mtie", tau)


def prtcA_tdev(tau):
    """TDEV mask of a class-A primary reference time clock (G.8272): 3 ns to 100 s, 0.03·τ ns to 1000 s,
    then 30 ns."""
    return _mask("prtcA_tdev", tau)


def prtcB_tdev(tau):
    """TDEV mask of a class-B PRTC (G.8272): 1 ns to 100 s, 0.01·τ ns to 500 s, then 5 ns."""
    return _mask("prtcB_tdev", tau)


def prtcA_mtie(tau):
    """MTIE mask of a class-A PRTC (G.8272): 0.275e-3·τ + 0.025 µs to 273 s, then 100 ns."""
    return _mask("prtcA_mtie", tau)


def prtcB_mtie(tau):
    """MTIE mask of a class-B PRTC (G.8272): 0.275e-3·τ + 0.025 µs to 54.5 s, then 40 ns."""
    return _mask("prtcB_mtie", tau)
