"""``import allanite`` leaves the heavy SciPy modules for their first use, and the quantiles it computes
without scipy.stats are scipy.stats' own numbers."""

import math
import subprocess
import sys

import numpy as np
import pytest
from scipy import stats

import allanite
from allanite._dist import chi2_ppf, chi2_sf, norm_ppf


def test_import_allanite_loads_no_scipy_stats_signal_optimize_or_matplotlib():
    code = (
        "import sys, allanite; "
        "print(sorted(m for m in ('scipy.stats', 'scipy.signal', 'scipy.optimize', 'matplotlib') if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_import_allanite_loads_no_jinja2_or_pywavelets():
    """The HTML templates (jinja2, ~0.1 s) load where a page or a notebook display is made, PyWavelets
    (~0.08 s) where paper 004's improved GM(1,1) uses a wavelet."""
    code = "import sys, allanite; print(sorted(m for m in ('jinja2', 'pywt') if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_the_command_line_and_the_report_load_no_scipy_stats_signal_optimize_or_matplotlib():
    """What ``allanite report`` imports before it computes: the refinement's loop (scipy.signal, stats,
    optimize) only with ``--refine``, matplotlib only when the figures are drawn."""
    code = (
        "import sys, allanite.cli, allanite.report; "
        "print(sorted(m for m in ('scipy.stats', 'scipy.signal', 'scipy.optimize', 'matplotlib') if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_refine_names_load_on_first_use():
    from allanite.model.refinement import Refinement, Step, refine

    assert allanite.refine is refine and allanite.Refinement is Refinement
    assert allanite.model.Step is Step
    from allanite.model import refinement

    assert refinement.LEVEL == refinement.levels.LEVEL and refinement.CANDIDATES == refinement.loop.CANDIDATES
    with pytest.raises(AttributeError, match="has no attribute 'no_such_name'"):
        refinement.no_such_name  # noqa: B018
    with pytest.raises(AttributeError, match="has no attribute 'no_such_name'"):
        allanite.no_such_name  # noqa: B018
    with pytest.raises(AttributeError, match="has no attribute 'no_such_name'"):
        allanite.model.no_such_name  # noqa: B018


def test_quantiles_are_scipy_stats_numbers_bit_for_bit():
    rng = np.random.default_rng(30)
    nu = np.concatenate([rng.random(3000) * 1e4 + 0.01, rng.integers(1, 300, 3000).astype(float), [0.0, -1.0, np.nan]])
    p = np.concatenate([rng.random(6000), [0.0, 1.0, 0.5]])
    x = np.concatenate([rng.random(6000) * 300, [0.0, -1.0, 3.0]])
    for q in (0.1585, 0.8415, 0.025, 0.975):
        np.testing.assert_array_equal(chi2_ppf(q, nu), stats.chi2.ppf(q, nu))
    np.testing.assert_array_equal(chi2_ppf(p, nu), stats.chi2.ppf(p, nu))
    np.testing.assert_array_equal(chi2_sf(x, nu), stats.chi2.sf(x, nu))
    np.testing.assert_array_equal(norm_ppf(p), stats.norm.ppf(p))
    assert isinstance(chi2_sf(5.0, 3), float) and chi2_sf(5.0, 3) == stats.chi2.sf(5.0, 3)
    assert np.isnan(chi2_ppf(0.5, 0.0)) and np.isnan(chi2_sf(1.0, 0.0))  # no χ² with ν ≤ 0


_KERNELS_FIRST = r"""
import json, sys
import numpy as np
from allanite import _dist
rng = np.random.default_rng(30)
nu = np.concatenate([rng.random(2000) * 1e4 + 0.01, rng.integers(1, 300, 2000).astype(float), [1e6, 0.0, -1.0]])
p = np.concatenate([rng.random(4000), [0.5, 0.0, 1.0]])
x = np.concatenate([rng.random(4000) * 300, [1e6, 0.0, -1.0]])
ours = [_dist.chi2_ppf(0.975, nu), _dist.chi2_ppf(p, nu), _dist.chi2_sf(x, nu), _dist.norm_ppf(p)]
alone = "scipy.special" not in sys.modules  # the kernels' extension was loaded without the package
kernels = _dist.special().__name__
import scipy.special, scipy.stats  # the package, imported afterwards as usual
theirs = [scipy.stats.chi2.ppf(0.975, nu), scipy.stats.chi2.ppf(p, nu), scipy.stats.chi2.sf(x, nu), scipy.stats.norm.ppf(p)]
same = all(np.array_equal(a, b, equal_nan=True) for a, b in zip(ours, theirs))
print(json.dumps({"alone": alone, "kernels": kernels, "same": same, "names": sorted(dir(scipy.special)),
                  "gammaln": float(scipy.special.gammaln(3.3))}))
"""


def test_the_kernels_load_without_scipy_special_and_leave_it_whole():
    """``allanite._dist`` loads scipy.special's compiled ufuncs alone where the package is not imported yet
    (``import scipy.special`` costs ~0.4 s of CPU): the same numbers as scipy.stats, bit for bit, and a later
    ``import scipy.special`` has every name it has in a process that never took that path."""
    import json

    got = json.loads(subprocess.run([sys.executable, "-c", _KERNELS_FIRST], capture_output=True, text=True,
                                    check=True).stdout)  # fmt: skip
    clean = subprocess.run(
        [
            sys.executable,
            "-c",
            "import json, scipy.special, scipy.stats; print(json.dumps(sorted(dir(scipy.special))))",
        ],
        capture_output=True,
        text=True,
        check=True,
    )
    assert got["alone"] and got["kernels"] == "scipy.special._ufuncs"
    assert got["same"]
    assert got["names"] == json.loads(clean.stdout)
    assert got["gammaln"] == pytest.approx(math.lgamma(3.3), rel=1e-14)  # the package works as usual


def test_with_scipy_special_imported_the_kernels_come_from_it():
    import scipy.special

    from allanite import _dist

    assert _dist._kernels_module() is scipy.special


def test_invalid_arguments_are_nan_as_in_scipy_stats_whatever_scipy_special_seterr_says():
    """scipy.stats checks a distribution's arguments before it calls the kernel, so a user's
    ``scipy.special.seterr(all="raise")`` (process-wide, and it applies to the kernels allanite loads alone too:
    they are the same compiled ufuncs) never turns ν ≤ 0 or p outside [0, 1] into an exception there; a NaN
    χ² is a NaN p-value, not 1 (a failed fit does not pass)."""
    import scipy.special

    nu = np.array([-1.0, 0.0, 3.0, np.nan])
    with scipy.special.errstate(all="raise"):
        for p in (0.5, 1.5, -0.5):
            np.testing.assert_array_equal(chi2_ppf(p, nu), stats.chi2.ppf(p, nu))
        np.testing.assert_array_equal(chi2_sf(1.0, nu), stats.chi2.sf(1.0, nu))
        np.testing.assert_array_equal(norm_ppf([2.0, -1.0, 0.3]), stats.norm.ppf([2.0, -1.0, 0.3]))
    assert np.isnan(chi2_sf(np.nan, 3.0)) and np.isnan(stats.chi2.sf(np.nan, 3.0))
    assert chi2_sf(-np.inf, 3.0) == stats.chi2.sf(-np.inf, 3.0) == 1.0
