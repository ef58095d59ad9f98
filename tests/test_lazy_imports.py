"""``import allanite`` leaves the heavy SciPy modules for their first use, and the quantiles it computes
without scipy.stats are scipy.stats' own numbers."""

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
