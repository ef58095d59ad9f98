"""allanite.compat (the allantools-compatible front door) against allantools itself: every function, both
data types, every ``taus`` form, on random records — the four returned arrays (taus, devs, errs, ns) equal to
1e-10 relative (in practice ≤ 4e-14; the numbers differ only by floating-point rounding)."""

from __future__ import annotations

import contextlib
import io

import numpy as np
import pytest

from allanite import compat
from allanite.errors import InputError, ParameterError

allantools = pytest.importorskip("allantools")

#: allantools' pure-Python O(N²)…O(N³) loops (MTOTDEV, TTOTDEV, HTOTDEV, Theo1, PDEV) get short records
SLOW = {"mtotdev", "ttotdev", "htotdev", "theo1", "pdev"}
#: every (data, rate, data_type, taus) → (taus, devs, errs, ns) deviation of allantools
DEVIATIONS = [*compat.ESTIMATORS, "pdev", "mtie_phase_fast"]
TAUS = [None, "all", "octave", "decade", "log10", "array"]


def _record(seed: int, name: str, data_type: str):
    rng = np.random.default_rng(seed)
    n = (40 if name in SLOW else 500) + 7 * seed
    # white + random-walk frequency on an offset, in fractional-frequency units
    y = 1e-9 * (rng.standard_normal(n) + 0.1 * np.cumsum(rng.standard_normal(n)) + 30.0)
    return y if data_type == "freq" else np.concatenate(([0.0], np.cumsum(y))) * 0.01


def _taus(form, n: int, rate: float):
    if form != "array":
        return form
    # off-grid τ (rounded half to even), duplicates, too large, unsorted
    return np.array([7.3, 0.5, 1.0, 1.25, 2.5 / rate, 1.0, n / (4 * rate), n / (3 * rate), n / rate, 1e9]) / rate


def _allantools(name, *args, **kw):
    with contextlib.redirect_stdout(io.StringIO()):  # allantools prints on some inputs
        return getattr(allantools, name)(*args, **kw)


@pytest.mark.parametrize("seed", [0, 1])
@pytest.mark.parametrize("form", TAUS, ids=str)
@pytest.mark.parametrize("data_type", ["phase", "freq"])
@pytest.mark.parametrize("name", DEVIATIONS)
def test_equals_allantools(name, data_type, form, seed):
    data = _record(seed, name, data_type)
    rate = 4.0 if seed else 1.0
    taus = _taus(form, data.size, rate)
    # allantools' own mtie_phase_fast is unfinished (its test expects it to fail): compat's is mtie
    want = _allantools("mtie" if name == "mtie_phase_fast" else name, data, rate=rate, data_type=data_type, taus=taus)
    got = getattr(compat, name)(data, rate=rate, data_type=data_type, taus=taus)
    for what, w, g in zip(("taus", "devs", "errs", "ns"), want, got):
        w = np.asarray(w, dtype=np.float64)
        assert g.shape == w.shape, (what, w, g)
        np.testing.assert_allclose(g, w, rtol=1e-10, atol=0, err_msg=f"{name} {what}")
    assert got[3].dtype == np.float64  # allantools' ns are floats


def test_frequency_data_are_trimmed_and_centred():
    y = np.array([np.nan, 3.0, 1.0, 4.0, 1.0, 5.0, 9.0, 2.0, 6.0, np.nan])
    t, d, _, _ = compat.mtie(y, data_type="freq", taus=[1.0, 2.0])
    want = _allantools("mtie", y, data_type="freq", taus=[1.0, 2.0])
    np.testing.assert_allclose(d, want[1], rtol=1e-13)
    assert d[0] == pytest.approx(9.0 - np.nanmean(y))


def test_theo1_labels_tau_as_m_over_rate(rng):
    x = np.cumsum(rng.standard_normal(200))
    t, d, e, n = compat.theo1(x, rate=10.0, taus=[0.2, 0.3, 1.0])
    np.testing.assert_array_equal(t, [0.2, 1.0])  # odd m = 3 dropped, τ = m/rate (not 0.75·m/rate)
    np.testing.assert_array_equal(n, [(200 - 2) * 2 / 2, (200 - 10) * 10 / 2])  # (N − m)·m/2
    want = _allantools("theo1", x, rate=10.0, taus=[0.2, 0.3, 1.0])
    np.testing.assert_allclose(d, want[1], rtol=1e-12)
    np.testing.assert_allclose(e, d / np.sqrt([198, 190]), rtol=1e-15)


def test_bad_input_is_named(rng):
    x = rng.standard_normal(50)
    x[17] = np.nan
    with pytest.raises(InputError, match=r"data\[17\] = nan"):
        compat.oadev(x)
    with pytest.raises(ParameterError, match='data_type must be "phase" or "freq"'):
        compat.adev(np.ones(10), data_type="frequency")
    with pytest.raises(ParameterError, match="taus must be None"):
        compat.mdev(np.arange(10.0), taus="octaves")
    with pytest.raises(ParameterError, match="rate must be a positive"):
        compat.hdev(np.arange(10.0), rate=0)
    with pytest.raises(ParameterError, match="no τ of the requested ones"):
        compat.ohdev(np.arange(10.0), taus=[100.0])
