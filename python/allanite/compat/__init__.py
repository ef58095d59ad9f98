"""An allantools-compatible front door: ``from allanite import compat as allantools``.

The names of allantools 2024.06 — its 41 top-level names (``__all__``) and the submodules scripts
import (:mod:`~allanite.compat.allantools`, :mod:`~allanite.compat.ci`, :mod:`~allanite.compat.dataset`,
:mod:`~allanite.compat.noise`, :mod:`~allanite.compat.noise_kasdin`, :mod:`~allanite.compat.plot`,
:mod:`~allanite.compat.realtime`, :mod:`~allanite.compat.mask`) — with allantools' signatures,
defaults and return shapes, computed by allanite's Rust core (the deviations, real-time deviations
and MTIE) or plain NumPy/SciPy (conversions, EDFs, noise generators). Nothing imports allantools.

``install_as_allantools()`` (opt-in, never on import) makes ``import allantools`` itself resolve here.

Differences from allantools are deliberate and listed in ``docs/compat.md``: interior NaN raise an
:class:`~allanite.errors.InputError` (``gradev`` excepted), a bad rate a :class:`RateError` (both a
ParameterError and the RuntimeError allantools raises), no usable τ a :class:`NoTauError` (both a
ParameterError and allantools' UserWarning); nothing is printed.
"""

from __future__ import annotations

# the submodules are attributes, as in allantools (allantools.realtime.oadev_realtime, …)
from . import allantools as allantools
from . import ci as ci
from . import dataset as dataset
from . import mask as mask
from . import noise as noise
from . import noise_kasdin as noise_kasdin
from . import plot as plot
from . import realtime as realtime
from ._alias import install_as_allantools
from ._input import NoTauError, RateError
from .allantools import (
    __version__,
    adev,
    calc_hdev_phase,
    calc_htotdev_freq,
    calc_mtotdev_phase,
    frequency2fractional,
    frequency2phase,
    gcodev,
    gradev,
    hdev,
    htotdev,
    mdev,
    mtie,
    mtie_phase_fast,
    mtotdev,
    oadev,
    ohdev,
    pdev,
    phase2frequency,
    phase2radians,
    psd2allan,
    tau_generator,
    tau_reduction,
    tdev,
    theo1,
    three_cornered_hat_phase,
    tierms,
    totdev,
    trim_data,
    ttotdev,
)
from .ci import (
    autocorr_noise_id,
    confidence_interval,
    confidence_interval_noiseID,
    edf_greenhall,
    edf_mtotdev,
    edf_simple,
    edf_totdev,
)
from .dataset import Dataset
from .noise_kasdin import Noise
from .plot import Plot
from .realtime import oadev_realtime as oadev_realtime
from .realtime import ohdev_realtime as ohdev_realtime
from .realtime import tdev_realtime as tdev_realtime

#: allantools 2024.06's ``__all__`` (its 41 names, in its order), then allanite's additions
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
    "frequency2phase",
    "phase2frequency",
    "phase2radians",
    "frequency2fractional",
    "three_cornered_hat_phase",
    "noise",
    "gradev",
    "gcodev",
    "trim_data",
    "edf_simple",
    "edf_greenhall",
    "edf_totdev",
    "edf_mtotdev",
    "confidence_interval",
    "confidence_interval_noiseID",
    "autocorr_noise_id",
    "Dataset",
    "Noise",
    "Plot",
    "psd2allan",
    "tau_generator",
    "tau_reduction",
    "install_as_allantools",
    "RateError",
    "NoTauError",
]

ALLANTOOLS_ALL = __all__[:41]

#: the deviations of (data, rate, data_type, taus) → (taus, devs, errs, ns) that allanite.compat had first
ESTIMATORS = [
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
