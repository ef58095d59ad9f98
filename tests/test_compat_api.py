"""allanite.compat's allantools 2024.06 names beyond the 13 first deviations: the namespace, the new
deviations (pdev, gcodev, gradev, the calc_* functions), the helpers, ``ci``, ``mask``, Dataset and
Plot — each against allantools itself where allantools is right, against the definition where it is
not (docs/compat.md lists those differences)."""

from __future__ import annotations

import contextlib
import io

import numpy as np
import pytest

from allanite import compat
from allanite.errors import AllaniteError, InputError, ParameterError

allantools = pytest.importorskip("allantools")


def _at(fn, *args, **kw):
    with contextlib.redirect_stdout(io.StringIO()):  # allantools prints on some inputs
        return fn(*args, **kw)


def _close(got, want, rtol=1e-10):
    for g, w in zip(got, want):
        np.testing.assert_allclose(np.asarray(g, dtype=float), np.asarray(w, dtype=float), rtol=rtol, atol=0)


@pytest.fixture
def walk():
    rng = np.random.default_rng(31)
    return np.cumsum(rng.standard_normal(2000)) + 0.3 * rng.standard_normal(2000)


def test_the_namespace_is_allantools():
    assert compat.ALLANTOOLS_ALL == allantools.__all__
    assert all(hasattr(compat, n) for n in compat.__all__)
    for sub in ("allantools", "ci", "dataset", "noise", "noise_kasdin", "plot", "realtime", "mask"):
        theirs = getattr(allantools, sub)
        ours = getattr(compat, sub)
        public = [n for n in dir(theirs) if not n.startswith("_") and callable(getattr(theirs, n))]
        public = [n for n in public if getattr(getattr(theirs, n), "__module__", "") == theirs.__name__]
        # internals of allantools' EDF code and its infinite Voss–McCartney iterator are not offered
        skip = {"greenhall_BasicSum", "greenhall_sz", "greenhall_sx", "greenhall_sw", "greenhall_table1"}
        skip |= {"greenhall_table2", "greenhall_table3", "edf_greenhall_simple", "iterpink", "mtie_rolling_window"}
        skip |= {"calc_adev_phase", "calc_pdev_phase", "calc_gcodev_phase", "calc_gradev_phase"}
        missing = [n for n in public if not hasattr(ours, n) and n not in skip]
        assert missing == [], (sub, missing)
    assert compat.__version__.startswith("2024.06+allanite.")


def test_errors_are_also_allantools_classes():
    with pytest.raises(RuntimeError, match="rate must be a positive finite sampling rate in Hz, got 0.0"):
        compat.adev(np.arange(10.0), rate=0.0)
    with pytest.raises(compat.RateError):
        compat.tau_generator(np.arange(10.0), -1.0)
    with pytest.raises(UserWarning, match="no τ of the requested ones"):
        compat.oadev(np.arange(10.0), taus=[50.0])
    assert issubclass(compat.RateError, ParameterError) and issubclass(compat.NoTauError, ParameterError)


@pytest.mark.parametrize("data_type", ["phase", "freq"])
@pytest.mark.parametrize("taus", ["octave", "all", [1, 3, 7.5, 40]])
def test_pdev_gcodev_equal_allantools(walk, data_type, taus):
    x = walk[:300] if data_type == "phase" else np.diff(walk[:301]) * 1e-3
    y = x + np.random.default_rng(2).standard_normal(x.size) * 0.5 * np.std(x)
    _close(compat.pdev(x, rate=2.0, data_type=data_type, taus=taus), _at(allantools.pdev, x, 2.0, data_type, taus))
    got = compat.gcodev(x, y, rate=2.0, data_type=data_type, taus=taus)
    _close(got, _at(allantools.gcodev, x, y, 2.0, data_type, taus))


def test_gcodev_of_a_record_with_itself_is_its_oadev(walk):
    got = compat.gcodev(walk, walk, taus="all")
    want = compat.oadev(walk, taus="all")
    _close(got, want, rtol=1e-12)
    with pytest.raises(InputError, match="same length, got 2000 and 1999"):
        compat.gcodev(walk, walk[1:])


def test_pdev_matches_sigmatheta_on_nbs14():
    """NIST SP 1065's 1000-point NBS14 frequency record; SigmaTheta's PDEV at τ = 1, 2, 4 (quoted by
    allantools' test suite) — PVAR over M = N − 2m terms."""
    n = [1234567890]
    for _ in range(999):
        n.append((16807 * n[-1]) % 2147483647)
    y = np.array(n) / 2147483647.0
    taus, devs, _, ns = compat.pdev(y, data_type="freq", taus=[1, 2, 4])
    np.testing.assert_allclose(devs, [0.29223187810675200, 0.21445233564252639, 0.15618112158618463], rtol=1e-12)
    np.testing.assert_array_equal(ns, [999, 997, 993])


def test_gradev_skips_terms_touching_gaps_and_has_real_intervals(walk):
    x = walk.copy()
    x[[10, 500, 501, 1500]] = np.nan
    taus, devs, (lo, hi), ns = compat.gradev(x, rate=2.0, taus="all", ci=0.9, noisetype="wf")
    t_at, d_at, _, n_at = _at(allantools.gradev, x, rate=2.0, taus="all")
    _close((taus, devs, ns), (t_at, d_at, n_at), rtol=1e-12)
    # the gap-free terms, by hand, at m = 3
    m = 3
    v = x[2 * m :] - 2 * x[m:-m] + x[: -2 * m]
    v = v[~np.isnan(v)]
    assert ns[m - 1] == v.size and devs[m - 1] == pytest.approx(np.sqrt(np.mean(v**2) / 2) * 2.0 / m, rel=1e-12)
    # errors: distances to the χ² bounds with SP 1065's EDF for WFM and N = present points
    edf = compat.edf_simple(x.size - 4, m, 0)
    b_lo, b_hi = compat.confidence_interval(devs[m - 1], edf, 0.9)
    assert lo[m - 1] == pytest.approx(devs[m - 1] - b_lo) and hi[m - 1] == pytest.approx(b_hi - devs[m - 1])
    # NaN where the N − 4 present points are too few for SP 1065's formula (N < 2m + 1)
    ok = 2 * taus * 2.0 + 1 <= x.size - 4
    assert np.all(lo[ok] > 0) and np.all(hi[ok] > lo[ok]) and np.isnan(lo[~ok]).all() and (~ok).sum() == 2
    # without gaps it is the overlapping ADEV
    _close(compat.gradev(walk, taus="octave")[:2], compat.oadev(walk, taus="octave")[:2], rtol=1e-12)
    y = walk.copy()
    y[7] = np.inf
    with pytest.raises(InputError, match=r"data\[7\] = inf"):
        compat.gradev(y)


@pytest.mark.parametrize("m", [1, 2, 5, 17])
def test_calc_functions_equal_allantools(walk, m):
    for stride in (m, 1, 3):
        _close(compat.calc_hdev_phase(walk, 2.0, m, stride), allantools.calc_hdev_phase(walk, 2.0, m, stride))
    x = walk[:300]
    _close(compat.calc_mtotdev_phase(x, 2.0, m), allantools.calc_mtotdev_phase(x, 2.0, m))
    _close(compat.calc_htotdev_freq(np.diff(x), m), allantools.calc_htotdev_freq(np.diff(x), m))
    with pytest.raises(ParameterError, match="m = 101 needs 3m ≤ N = 300"):
        compat.calc_mtotdev_phase(x, 2.0, 101)


def test_mtie_phase_fast_is_exact_mtie(walk):
    got = compat.mtie_phase_fast(walk, rate=4.0, taus="all")
    _close(got, _at(allantools.mtie, walk, rate=4.0, taus="all"), rtol=1e-13)
    m = 37
    direct = max(np.ptp(walk[i : i + m + 1]) for i in range(walk.size - m))
    assert got[1][m - 1] == direct


def test_conversions_equal_allantools(walk):
    f = 1e7 + walk[:50]
    assert compat.frequency2fractional(f, mean_frequency=1e7) == allantools.frequency2fractional(f, 1e7)
    assert compat.frequency2fractional(list(f)) == allantools.frequency2fractional(list(f))
    y = np.array([np.nan, 1.0, 2.0, np.nan, 5.0, 3.0, np.nan])
    _close([compat.frequency2phase(y, 4.0)], [allantools.frequency2phase(y, 4.0)], rtol=1e-15)
    np.testing.assert_array_equal(compat.phase2frequency(walk, 3.0), allantools.phase2frequency(walk, 3.0))
    _close([compat.phase2radians(walk, 5e6)], [allantools.phase2radians(walk, 5e6)], rtol=1e-15)
    np.testing.assert_array_equal(compat.trim_data(y), allantools.trim_data(y))
    assert compat.trim_data([np.nan, 1.0, 2.0]) == [1.0, 2.0]
    np.testing.assert_array_equal(compat.allantools.input_to_phase(walk, 1.0, "phase"), walk)
    with pytest.raises(ParameterError, match='data_type must be "phase" or "freq", got \'fr\''):
        compat.allantools.input_to_phase(walk, 1.0, "fr")


@pytest.mark.parametrize("taus", [None, [], "all", "octave", "decade", "log10", [0.4, 1, 1, 3.5, 2.5, 1e9], 2.0])
@pytest.mark.parametrize("kw", [{}, {"even": True}, {"maximum_m": 20}])
def test_tau_generator_equals_allantools(taus, kw):
    data = np.arange(128.0)
    got = compat.tau_generator(data, 2.0, taus=taus, **kw)
    want = _at(allantools.tau_generator, data, 2.0, taus=taus, **kw)
    for g, w in zip(got, want):
        np.testing.assert_array_equal(g, w)


def test_tau_reduction_and_remove_small_ns():
    ms = np.arange(1, 500)
    for n in (1, 2, 5, 10, 40):
        got = compat.allantools.tau_reduction(ms, 2.0, n)
        want = allantools.allantools.tau_reduction(ms, 2.0, n)
        np.testing.assert_array_equal(got[0], want[0])
        np.testing.assert_array_equal(got[1], want[1])
    taus, devs, lo, hi = (np.arange(1.0, 7.0) * k for k in (1, 2, 3, 4))
    ns = np.array([9.0, 5.0, 2.0, 1.0, 0.0, 3.0])
    got = compat.allantools.remove_small_ns(taus, devs, [lo, hi], ns)
    want = allantools.allantools.remove_small_ns(taus, devs, [lo, hi], ns)
    for g, w in zip((got[0], got[1], *got[2], got[3]), (want[0], want[1], *want[2], want[3])):
        np.testing.assert_array_equal(g, w)
    with pytest.raises(compat.NoTauError, match="no τ has more than one term"):
        compat.allantools.remove_small_ns(taus, devs, lo, np.ones(6))
    with pytest.raises(ParameterError, match="a list of 3"):
        compat.allantools.remove_small_ns(taus, devs, [lo, hi, lo], ns)


def test_three_cornered_hat_equals_allantools(walk):
    rng = np.random.default_rng(4)
    ab, bc = walk[:1000], walk[1000:] + rng.standard_normal(1000)
    ca = -(ab + bc) + 0.1 * rng.standard_normal(1000)
    got = compat.three_cornered_hat_phase(ab, bc, ca, 1.0, "octave", compat.oadev)
    want = allantools.three_cornered_hat_phase(ab, bc, ca, 1.0, "octave", allantools.oadev)
    _close((got[0], got[1], got[2], got[3]), want)
    assert isinstance(got[2], list)


def test_psd2allan_is_sp1065s_integral():
    """White FM of PSD h0: ADEV² = h0/(2τ), MDEV² = h0/(4τ) (SP 1065 Table 9); τ list as allantools'."""
    f = np.arange(2001.0)
    s = np.full(f.size, 1e-22)
    for kind, k in (("adev", 2.0), ("mdev", 4.0)):
        for base in (2, 10, 0):
            taus, dev = compat.psd2allan(s, f, kind=kind, base=base)
            t_at, d_at = allantools.psd2allan(s, f, kind=kind, base=base)
            np.testing.assert_array_equal(taus, t_at)
            _close([dev], [d_at], rtol=1e-9)
            far = taus > 20 * taus[0]  # away from the PSD's upper edge (its f_h = 1/τ0)
            np.testing.assert_allclose(
                dev[far], np.sqrt(1e-22 / (k * taus[far])), rtol=0.08 if kind == "adev" else 4e-3
            )
    # a power law (flicker FM): against the same integral refined 64× this is within 2e-4 (allantools' 4×
    # refinement: 3e-3 at the longest τ, where the integrand's period 1/τ is two steps of the PSD)
    from scipy.integrate import simpson
    from scipy.interpolate import CubicSpline

    s = np.concatenate(([0.0], 1e-22 / f[1:]))
    fine = np.linspace(0.0, f[-1], 64 * (f.size - 1) + 1)
    spec = CubicSpline(f, s)(fine)
    for kind, k in (("adev", 1), ("mdev", 2)):
        taus, got = compat.psd2allan(s, 1.0, kind=kind)
        arg = np.pi * fine[None, :] * taus[:, None]
        h = np.sin(arg) ** (k + 1) / np.where(arg == 0, 1.0, arg) ** k
        ref = np.sqrt(2.0 * simpson(spec * h**2, x=fine, axis=1))
        _close([got], [ref], rtol=2e-4)
        _close([got], [allantools.psd2allan(s, 1.0, kind=kind)[1]], rtol=3e-3)
    with pytest.raises(ParameterError, match='kind must be "adev" or "mdev"'):
        compat.psd2allan(s, 1.0, kind="hdev")
    with pytest.raises(ParameterError, match="S_y must be a numpy array, got list"):
        compat.psd2allan([1.0, 2.0])


# --------------------------------------------------------------------------------------------
# ci


def test_confidence_interval_equals_allantools():
    for ci in (compat.ci.ONE_SIGMA_CI, 0.9, 0.1, 0.5):
        _close(compat.confidence_interval(2.5, 7.3, ci), allantools.confidence_interval(2.5, 7.3, ci), rtol=1e-13)
    lo, hi = compat.confidence_interval(2.5, np.array([3.0, 30.0]))  # arrays too (allantools: numbers only)
    _close((lo[1], hi[1]), allantools.confidence_interval(2.5, 30.0), rtol=1e-13)
    with pytest.raises(ParameterError, match=r"ci must be a probability in \(0, 1\), got 1.0"):
        compat.confidence_interval(1.0, 5.0, 1.0)


def test_edf_greenhall_equals_allantools_where_allantools_has_a_value():
    compared = 0
    for a in (2, 1, 0, -1, -2, -3, -4):
        for d in (1, 2, 3):
            if a + 2 * d <= 1:
                continue
            for m in (1, 2, 7, 64, 300):
                for n in (1001, 5000, 100000):
                    for ov in (False, True):
                        for mo in (False, True):
                            try:
                                want = _at(allantools.edf_greenhall, a, d, m, n, ov, mo)
                            except Exception:  # allantools: NotImplementedError, table lookups out of range
                                continue
                            if want <= 0 or m * (d + 1) * (1 if ov else 1) > n / 3:
                                continue  # allantools' negative EDFs of too-short records; r near d + 1
                            got = compat.edf_greenhall(a, d, m, n, ov, mo)
                            assert got == pytest.approx(want, rel=1e-10), (a, d, m, n, ov, mo)
                            compared += 1
    assert compared > 300
    # floats from Stable32 tables are fine when integral; the paper's closed form where allantools has none
    assert compat.edf_greenhall(0.0, 2, 10.0, 1001) == compat.edf_greenhall(0, 2, 10, 1001)
    assert compat.edf_greenhall(2, 2, 400, 1001, overlapping=True) > 0
    with pytest.raises(ParameterError, match="m must be an integer, got 2.5"):
        compat.edf_greenhall(0, 2, 2.5, 1001)
    with pytest.raises(ParameterError, match="too short"):
        compat.edf_greenhall(0, 2, 300, 500)


def test_total_and_simple_edfs():
    for n, m in ((1000, 10), (5000, 3)):
        for a in (0, -1, -2, 2):
            assert compat.edf_totdev(n, m, a) == pytest.approx(_at(allantools.edf_totdev, n, m, a), rel=1e-13)
        for a in (2, 1, 0, -1, -2):
            assert compat.edf_mtotdev(n, float(m), a) == pytest.approx(_at(allantools.edf_mtotdev, n, m, a), rel=1e-13)
        for a in (2, 1, 0, -2, None, 7):
            assert compat.edf_simple(n, m, a) == pytest.approx(_at(allantools.edf_simple, n, m, a), rel=1e-13)
    # SP 1065 Table 5, flicker FM at m = 1: 2(N − 2)²/(2.3N − 4.9) (allantools drops the square)
    assert compat.edf_simple(1000, 1, -1) == pytest.approx(2 * 998**2 / (2.3 * 1000 - 4.9), rel=1e-13)
    with pytest.raises(ParameterError, match="alpha = 3 is not covered"):
        compat.edf_mtotdev(1000, 10, 3)


@pytest.mark.parametrize("data_type", ["phase", "freq"])
@pytest.mark.parametrize("af", [1, 3, 10])
def test_noise_identification_equals_allantools(data_type, af):
    rng = np.random.default_rng(af)
    w = rng.standard_normal(3000)
    for series in (w, np.cumsum(w), np.cumsum(np.cumsum(w)), np.diff(w)):
        got = compat.autocorr_noise_id(series, af, data_type=data_type)
        want = _at(allantools.autocorr_noise_id, series, af, data_type=data_type)
        assert got[0] == want[0] and got[2] == want[2]
        _close(got[1::2], want[1::2], rtol=1e-9)
    with pytest.raises(NotImplementedError, match="at least 30 points"):
        compat.autocorr_noise_id(w[:100], 4)
    with pytest.raises(ParameterError, match="data_type must be"):
        compat.autocorr_noise_id(w, 1, data_type="rate")
    for dev_type in ("adev", "oadev", "mdev", "tdev", "hdev", "ohdev"):
        got = compat.confidence_interval_noiseID(np.cumsum(w), 1.3, af, dev_type=dev_type, data_type="phase")
        want = _at(allantools.confidence_interval_noiseID, np.cumsum(w), 1.3, af, dev_type=dev_type)
        _close(got, want)
    with pytest.raises(NotImplementedError, match="totdev"):
        compat.confidence_interval_noiseID(w, 1.0, 1, dev_type="totdev")


def test_b1_rn_and_their_theory_equal_allantools(walk):
    assert compat.ci.b1(walk, 4, 1.0) == pytest.approx(allantools.ci.b1(walk, 4, 1.0), rel=1e-12)
    assert compat.ci.rn(walk, 4, 1.0) == pytest.approx(allantools.ci.rn(walk, 4, 1.0), rel=1e-12)
    for n in (10, 100, 1000):
        for mu in (-2, -1, 0, 1, 2, 3):
            assert compat.ci.b1_theory(n, mu) == pytest.approx(allantools.ci.b1_theory(n, mu), rel=1e-12)
    for b in (0, -1, -2, -3, -4):
        assert compat.ci.b_to_mu(b) == allantools.ci.b_to_mu(b)
        assert compat.ci.rn_theory(8, b) == pytest.approx(allantools.ci.rn_theory(8, b), rel=1e-14)
        assert compat.ci.rn_boundary(8, b) == pytest.approx(allantools.ci.rn_boundary(8, b), rel=1e-14)
        assert compat.ci.b1_boundary(b, 100) == pytest.approx(allantools.ci.b1_boundary(b, 100), rel=1e-14)
    assert compat.ci.lag1_acf(walk) == pytest.approx(allantools.ci.lag1_acf(walk), rel=1e-12)
    _close([compat.ci.detrend(walk, 2)], [allantools.ci.detrend(walk, 2)], rtol=1e-9)
    with pytest.raises(ParameterError, match="b must be one of"):
        compat.ci.b_to_mu(1)


# --------------------------------------------------------------------------------------------
# mask, Dataset, Plot


@pytest.mark.parametrize("name", compat.mask.__all__)
def test_masks_equal_allantools(name):
    taus = [0.1, 0.5, 1, 5, 50, 54.5, 99, 100, 250, 273, 500, 999, 1000, 5000, 3e4, 1e5, 3e5, 4e5, 5e5, 1e6]
    got = getattr(compat.mask, name)(np.array(taus))
    want = [getattr(allantools.mask, name)(t) for t in taus]
    # the ePRTC TDEV slope is 1 ns/30 000 s here, 3.33333e-5 ns/s in allantools
    np.testing.assert_allclose(got, want, rtol=1.1e-5 if name == "eprtc_tdev" else 1e-14)
    assert isinstance(getattr(compat.mask, name)(10.0), float)


def test_dataset_computes_and_writes_as_allantools(tmp_path, walk):
    ours, theirs = compat.Dataset(walk, rate=2.0), allantools.Dataset(walk, rate=2.0)
    for fn in ("adev", "mdev", "theo1", "tierms"):
        got, want = ours.compute(fn), _at(theirs.compute, fn)
        assert list(got) == list(want) == ["taus", "stat", "stat_err", "stat_n"]
        _close(got.values(), want.values())
        assert ours.out["stat_id"] == fn
        ours.write_results(tmp_path / "a.txt", digits=6, header_params={"clock": "H-maser"})
        theirs.write_results(str(tmp_path / "b.txt"), digits=6, header_params={"clock": "H-maser"})
        a, b = ((tmp_path / n).read_text().splitlines() for n in ("a.txt", "b.txt"))
        assert a[1:] == b[1:] and a[0].startswith("# Generated by Allantools 2024.06+allanite.")
    with pytest.raises(AttributeError, match="'nosuch' is not defined"):
        ours.compute("nosuch")
    with pytest.raises(RuntimeError, match="one of the 'dev' functions"):
        ours.compute("trim_data")
    ours.set_input(walk, rate=4.0, data_type="freq", taus=[1.0])
    assert ours.inp == {"data": walk, "rate": 4.0, "data_type": "freq", "taus": [1.0]}


def test_plot_draws_the_dataset(tmp_path, walk):
    ds = compat.Dataset(walk)
    ds.compute("oadev")
    p = compat.Plot(no_display=True)
    p.plot(ds, errorbars=True, grid=True)
    assert p.ax.get_xscale() == "log" and p.ax.get_ylabel() == "oadev"
    p.plot(ds, color="r")
    np.testing.assert_array_equal(p.ax.lines[-1].get_ydata(), ds.out["stat"])
    p.save(tmp_path / "f.png")
    assert (tmp_path / "f.png").stat().st_size > 0
    p.plt.close(p.fig)


def test_the_alias_is_opt_in_and_resolves_every_submodule(tmp_path):
    import subprocess
    import sys
    from subprocess import PIPE

    code = """
import sys, allanite, allanite.compat
assert "allantools" not in sys.modules, "imported on import"
from allanite.compat import install_as_allantools
assert install_as_allantools() is allanite.compat and install_as_allantools() is allanite.compat
import allantools
from allantools.allantools import remove_small_ns
from allantools.ci import edf_greenhall
from allantools.realtime import oadev_realtime
from allantools import noise, mask, Dataset
import allantools.noise_kasdin, allantools.plot, allantools.dataset
assert allantools is allanite.compat and allantools.ci is allanite.compat.ci
assert oadev_realtime is allanite.compat.realtime.oadev_realtime
print("ok")
"""
    late = "import allantools\nfrom allanite.compat import install_as_allantools\ninstall_as_allantools()"
    # both interpreters at once (each spends seconds importing)
    procs = [subprocess.Popen([sys.executable, "-c", c], stdout=PIPE, stderr=PIPE, text=True) for c in (code, late)]
    (out, err), (_, late_err) = (p.communicate(timeout=120) for p in procs)
    assert out.strip() == "ok", err
    assert "AllaniteError: allantools is already imported (from " in late_err
    assert issubclass(AllaniteError, ValueError)
