"""The three distribution functions the analysis path needs — χ² quantile, χ² survival, normal quantile —
computed by the same :mod:`scipy.special` kernels :mod:`scipy.stats` calls (``chi2._ppf``, ``chi2._sf``,
``norm._ppf``), with its edge cases (ν ≤ 0 → NaN). Importing :mod:`scipy.stats` costs about half a second,
most of ``import allanite``; these give identical numbers without it,
and load :mod:`scipy.special`'s kernels at their first call (:func:`special`)."""

from __future__ import annotations

import numpy as np

__all__ = ["chi2_ppf", "chi2_sf", "norm_ppf", "special"]

#: The three kernels this module calls, all in ``scipy.special._ufuncs``.
KERNELS = ("gammaincinv", "chdtrc", "ndtri")

_LOADED: list = []  # the module the kernels are taken from, once loaded


def special():
    """The module holding :data:`KERNELS`: :mod:`scipy.special` where it is imported already or other Python
    threads run, else its compiled ``_ufuncs`` extension loaded alone (:func:`_ufuncs_alone`).

    ``import scipy.special`` costs 0.35–0.6 s of CPU here, two thirds of it SciPy's array-API namespace, which
    clones NumPy's and so imports ``numpy.f2py`` (and with it ``charset_normalizer``) and ``numpy.testing``;
    the three kernels' extension alone loads in about 10 ms. The ufuncs are the same compiled functions that
    ``scipy.special`` exports, so the numbers are the same bits (``tests/test_lazy_imports.py``)."""
    if not _LOADED:
        _LOADED.append(_kernels_module())
    return _LOADED[0]


def _kernels_module():
    import threading

    if threading.active_count() == 1:
        try:
            return _ufuncs_alone()
        except Exception:  # scipy.special imported already, or another SciPy layout: the package as usual
            pass
    from scipy import special as package

    return package


def _ufuncs_alone():
    """``scipy.special._ufuncs`` loaded from its file without running ``scipy/special/__init__.py``.

    The one place allanite writes ``sys.modules`` besides :mod:`allanite.compat`'s opt-in alias
    (``tests/test_layering.py``). The extension imports its compiled siblings (``_ufuncs_cxx``,
    ``_special_ufuncs``, …) as submodules of ``scipy.special``, so a bare package module stands in for it while
    it loads (only this thread runs Python: :func:`_kernels_module`); where ``scipy.special`` is imported
    already, ImportError (its ufuncs are taken from it). Afterwards every ``scipy.special`` entry is taken out of
    ``sys.modules`` again — a later ``import scipy.special`` (``refine``, a user's code) runs the package's
    ``__init__`` and loads its submodules as if this had not happened, with all its attributes; this module
    keeps its own instance."""
    import importlib.machinery
    import importlib.util
    import os
    import sys
    import types

    import scipy

    if "scipy.special" in sys.modules:
        raise ImportError("scipy.special is imported already: its ufuncs are taken from it")
    base = os.path.join(scipy.__path__[0], "special")
    paths = [os.path.join(base, "_ufuncs" + s) for s in importlib.machinery.EXTENSION_SUFFIXES]
    path = next(p for p in paths if os.path.exists(p))  # StopIteration: another layout, the package is used
    stub = types.ModuleType("scipy.special")
    stub.__path__ = [base]
    before = set(sys.modules)
    sys.modules["scipy.special"] = stub
    try:
        spec = importlib.util.spec_from_file_location("scipy.special._ufuncs", path)
        if spec is None or spec.loader is None:
            raise ImportError(f"no loader for {path}")
        module = importlib.util.module_from_spec(spec)
        sys.modules["scipy.special._ufuncs"] = module
        spec.loader.exec_module(module)
        for name in KERNELS:
            getattr(module, name)
    finally:
        for name in [m for m in sys.modules if m not in before and m.startswith("scipy.special")]:
            del sys.modules[name]
    return module


def _out(v):
    return float(v) if np.ndim(v) == 0 else v


def chi2_ppf(p, nu):
    """``scipy.stats.chi2.ppf(p, nu)``: 2·P⁻¹(ν/2, p); NaN for ν ≤ 0 or p outside [0, 1]. The kernel sees valid
    arguments only (as scipy.stats's argument check does), so a user's ``scipy.special.seterr`` cannot turn
    an invalid one into an exception."""
    p, nu = np.broadcast_arrays(np.asarray(p, dtype=np.float64), np.asarray(nu, dtype=np.float64))
    ok = (nu > 0) & (p >= 0) & (p <= 1)
    with np.errstate(invalid="ignore"):
        # loaded at the first interval, not at import allanite
        q = 2.0 * special().gammaincinv(np.where(ok, nu, 2.0) / 2.0, np.where(ok, p, 0.5))
    return _out(np.where(ok, q, np.nan))


def chi2_sf(x, nu):
    """``scipy.stats.chi2.sf(x, nu)``: Q(ν/2, x/2), 1 for x ≤ 0; NaN for ν ≤ 0 or x NaN (the kernel sees ν > 0
    only)."""
    x, nu = np.broadcast_arrays(np.asarray(x, dtype=np.float64), np.asarray(nu, dtype=np.float64))
    ok = nu > 0
    with np.errstate(invalid="ignore"):
        q = special().chdtrc(np.where(ok, nu, 1.0), np.maximum(x, 0.0))
    return _out(np.where(ok, np.where(x <= 0, 1.0, q), np.nan))


def norm_ppf(p):
    """``scipy.stats.norm.ppf(p)``: the inverse of the standard normal CDF; NaN for p outside [0, 1] (the
    kernel sees p in [0, 1] only)."""
    p = np.asarray(p, dtype=np.float64)
    ok = (p >= 0) & (p <= 1)
    return _out(np.where(ok, special().ndtri(np.where(ok, p, 0.5)), np.nan))
