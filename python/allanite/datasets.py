"""The bundled default record: a deterministic simulated three-axis gyro log.

It is generated, not shipped, so the package stays small and the record is the same on every
machine (NumPy's PCG64 stream for a fixed seed). One hour at 100 Hz, 360 000 samples per axis, in
°/s, with these IEEE-952 terms (per axis, scaled 1, 1.3, 0.8 for x, y, z):

- angle random walk N = 0.15 °/√h (white rate noise),
- rate random walk K = 10 °/h^1.5 (integrated white noise),
- a first-order Gauss–Markov bias, σ = 5 °/h, correlation time 60 s (the bias-instability region),
- quantization of the rate to 1e-4 °/s steps (Q ≈ 2.9e-7 °),
- a stretch from 20 to 30 minutes where the angle random walk is 4× larger — what the dynamic
  Allan variance is for.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .simulation import ar1

__all__ = ["default_record", "DEFAULT_FS", "DEFAULT_SEED"]

#: Sampling rate of the bundled record, Hz.
DEFAULT_FS = 100.0
#: Seed of the bundled record's generator (the record is the same on every machine).
DEFAULT_SEED = 20261122
DEFAULT_DURATION_S = 3600.0
DEFAULT_TERMS: dict[str, Any] = {
    "N_deg_per_sqrt_h": 0.15,
    "K_deg_per_h15": 10.0,
    "gauss_markov_sigma_deg_per_h": 5.0,
    "gauss_markov_tc_s": 60.0,
    "quantization_step_deg_per_s": 1e-4,
    "loud_stretch_s": (1200.0, 1800.0),
    "loud_factor": 4.0,
    "axis_scale": (1.0, 1.3, 0.8),
}


def default_record(seed: int = DEFAULT_SEED):
    """The default record: ``(x, fs, description)``, x of shape (360000, 3) in °/s.

    Examples
    --------
    >>> import allanite
    >>> x, fs, info = allanite.default_record()
    >>> x.shape, fs
    ((360000, 3), 100.0)
    """
    fs = DEFAULT_FS
    n = int(DEFAULT_DURATION_S * fs)
    tau0 = 1.0 / fs
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    terms = DEFAULT_TERMS
    n_arw = terms["N_deg_per_sqrt_h"] / 60.0  # °/√s
    k_rrw = terms["K_deg_per_h15"] / 216000.0  # °/s^1.5
    gm_sigma = terms["gauss_markov_sigma_deg_per_h"] / 3600.0  # °/s
    tc = terms["gauss_markov_tc_s"]
    phi = np.exp(-tau0 / tc)
    lo, hi = terms["loud_stretch_s"]
    arw_scale = np.where((t >= lo) & (t < hi), terms["loud_factor"], 1.0)
    cols = []
    for scale in terms["axis_scale"]:
        white = rng.normal(size=n) * (n_arw / np.sqrt(tau0)) * arw_scale
        walk = np.cumsum(rng.normal(size=n)) * (k_rrw * np.sqrt(tau0))
        drive = rng.normal(size=n) * (gm_sigma * np.sqrt(1.0 - phi * phi))
        gm = ar1(drive, phi, rng.normal() * gm_sigma)
        rate = scale * (white + walk + gm)
        step = terms["quantization_step_deg_per_s"]
        cols.append(np.round(rate / step) * step)
    x = np.column_stack(cols)
    description = {
        "what": "simulated 3-axis gyro, °/s, deterministic",
        "fs_hz": fs,
        "seed": seed,
        "samples_per_axis": n,
        "unit": "deg/s",
        **{k: v for k, v in terms.items()},
    }
    return x, fs, description
