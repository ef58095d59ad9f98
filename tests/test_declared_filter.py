"""A user-declared filter (``refine(..., filter=...)``, :mod:`allanite.model._declared`): its exact Allan variance
against long simulated filtered noise, its checks, and refine taking it as the bandwidth effect's one kind."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import signal

import allanite
from allanite.errors import ParameterError
from allanite.model._declared import declared_filter
from allanite.model.effects import filtered_white_avar


def _simulated_ratio(b, a, rate: float, dec: int, n_out: int, seed: int, m: np.ndarray):
    """(measured OAVAR / exact, relative SD of the measure) for white noise through (b, a) at ``rate``, decimated."""
    fs = rate / dec
    rng = np.random.default_rng(seed)
    x = rng.standard_normal(n_out * dec + 4096)
    y = signal.lfilter(b, a, x)[4096::dec][:n_out]  # the IIR's start-up left out
    decl = declared_filter({"b": b, "a": a, "rate": rate}, fs)
    res = allanite.avar(y, fs, taus=m / fs)
    exact = filtered_white_avar(res.tau, decl.kind, decl.cutoff, fs) / fs  # per unit N²·fs
    # the output's power at DC per unit input variance: the exact curve is per unit of it (unit two-sided sum)
    h = signal.lfilter(b, a, np.r_[1.0, np.zeros(20_000)])
    full = signal.fftconvolve(h, h[::-1])
    r = full[full.size // 2 :][::dec]
    dc = r[0] + 2 * r[1:].sum()
    span = max(1, decl.r.size)
    sd = np.sqrt(
        4.0 * (res.m + span) / (3.0 * n_out)
    )  # the overlapping estimate's spread, widened by the filter's span
    return res.avar / (exact * dc), sd


@pytest.mark.parametrize(
    "design",
    [
        (
            "remez FIR, 2 kHz → 500 Hz",
            lambda: (signal.remez(63, [0, 150, 230, 1000], [1, 0], fs=2000.0), [1.0]),
            2000.0,
            4,
        ),
        ("elliptic IIR at 100 Hz", lambda: signal.ellip(4, 1.0, 40.0, 20.0, fs=100.0), 100.0, 1),
        ("Chebyshev IIR, 1 kHz → 250 Hz", lambda: signal.cheby1(3, 0.5, 90.0, fs=1000.0), 1000.0, 4),
    ],
    ids=lambda d: d[0],
)
def test_exact_avar_matches_simulated_filtered_noise(design):
    _name, make, rate, dec = design
    b, a = make()
    m = np.array([1, 2, 3, 5, 8, 16, 64, 256])
    ratio, sd = _simulated_ratio(np.asarray(b), np.asarray(a), rate, dec, 400_000, 29, m)
    assert np.all(np.abs(ratio - 1.0) < 4.0 * sd), (ratio, sd)
    # and the check resolves a filter's shape: the Butterworths of orders 2–6 at the same −3 dB frequency (the
    # bandwidth family's nearest kinds) each depart from the exact curve by more than 3 of its SDs somewhere
    fs = rate / dec
    decl = declared_filter({"b": b, "a": a, "rate": rate}, fs)
    own = filtered_white_avar(m / fs, decl.kind, decl.cutoff, fs)
    for order in (2, 3, 4, 5, 6):
        other = filtered_white_avar(m / fs, f"butterworth{order}", min(decl.cutoff, 0.49 * fs), fs)
        assert np.max(np.abs(other / own - 1.0) / sd) > 3.0, order


def test_declared_butterworth_is_the_butterworth_kind():
    b, a = signal.butter(4, 100.0, fs=1000.0)
    decl = declared_filter((b, a), 1000.0)
    tau = np.geomspace(1e-3, 10.0, 40)
    own = filtered_white_avar(tau, decl.kind, decl.cutoff, 1000.0)
    closed = filtered_white_avar(tau, "butterworth4", 100.0, 1000.0)
    np.testing.assert_allclose(own, closed, rtol=1e-10)
    assert decl.cutoff == pytest.approx(100.0, rel=1e-6)
    assert decl.describe() == {"type": "IIR", "rate_hz": 1000.0, "decimation": 1, "order": 4, "cutoff_hz": decl.cutoff}


def test_fir_decimated_autocorrelation_is_taps_read_every_d():
    taps = signal.firwin(31, 0.2)
    decl = declared_filter({"taps": taps, "decimation": 3}, 100.0)
    assert decl.rate == 300.0 and decl.decimation == 3
    full = np.correlate(taps, taps, mode="full")[taps.size - 1 :][::3]
    np.testing.assert_allclose(decl.r, full / (full[0] + 2 * full[1:].sum()), rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize(
    ("spec", "words"),
    [
        ([], "empty"),
        ([0.5, float("nan")], "finite"),
        (np.ones((3, 2)), "1-D"),
        (([1.0], [1.0, -1.5]), "unstable"),
        (([1.0], [0.0, 1.0]), r"a\[0\]"),
        ({"taps": [1.0, 1.0], "rate": 250.0}, "decimation times the output rate"),
        ({"taps": [1.0, 1.0], "decimation": 0}, "whole number"),
        ({"taps": [1.0, -1.0]}, "not a low-pass"),
        ({"taps": [1.0], "gain": 2}, "allowed keys"),
        ([0.0, 0.0], "all zero"),
    ],
)
def test_bad_filters_are_named(spec, words):
    with pytest.raises(ParameterError, match=words):
        declared_filter(spec, 100.0)


def test_refine_checks_the_filter_before_any_work():
    with pytest.raises(ParameterError, match="unstable"):
        allanite.refine(np.zeros(10), 100.0, filter=([1.0], [1.0, -2.0]), progress=False)


def test_refine_takes_the_declared_filter_as_the_bandwidth():
    fs = 200.0
    b, a = signal.ellip(4, 1.0, 40.0, 30.0, fs=fs)  # 1 dB of passband ripple: no kind of the family's shape
    rng = np.random.default_rng(5)
    y = signal.lfilter(b, a, 0.02 * rng.standard_normal(40_000))
    r = allanite.refine(y, fs, filter=(b, a), candidates=("bandwidth",), progress=False)
    assert r.found == ["bandwidth"]
    st = r.steps[0]
    decl = declared_filter((b, a), fs)
    assert st.params["filter"] == "declared" and st.params["cutoff"] == decl.cutoff
    assert "cutoff" not in st.intervals  # known, not fitted
    # N: the white level the declared filter's output has at DC (|H(0)|² = 1 − ripple for an even-order elliptic)
    n_true = 0.02 / math.sqrt(fs) * abs(np.polyval(b[::-1], 1.0) / np.polyval(a[::-1], 1.0))
    assert st.evidence["N"] == pytest.approx(n_true, rel=0.05)
    assert r.declared_filter["type"] == "IIR" and r.declared_filter["order"] == 4
    assert "Declared filter: an IIR of order 4 at 200 Hz" in r.report()
    assert "declared filter" in r._repr_html_()
    assert r.unexplained == []


def test_cli_reads_the_filter_file(tmp_path):
    from allanite import cli

    path = tmp_path / "iir.txt"
    path.write_text("# b, then a\n0.2, 0.4, 0.2\n1.0 -0.3 0.1\n")
    args = cli.build_parser().parse_args(["report", "x.npy", "--fs", "100", "--refine-filter", str(path)])
    assert cli._refine_filter(args) == {"b": [0.2, 0.4, 0.2], "a": [1.0, -0.3, 0.1]}
    assert cli._refine_option(args) is True  # the declared filter implies the refinement
    path.write_text("1 2\n3 4\n5 6\n")
    with pytest.raises(ParameterError, match="3 rows"):
        cli._refine_filter(args)
    args = cli.build_parser().parse_args(["report", "x.npy", "--fs", "100", "--refine-filter-rate", "400"])
    with pytest.raises(ParameterError, match="give the filter too"):
        cli._refine_filter(args)


def test_the_page_says_the_declared_filter():
    from types import SimpleNamespace

    from allanite.report import _sections

    said = {"type": "FIR", "words": "a 95-tap FIR at 8000 Hz, decimated by 8 (−3 dB at 321.6 Hz)"}
    ref = SimpleNamespace(filled=None, counter=None, declared_filter=said, found=["bandwidth"])
    assert _sections._axis_notes(ref, "gyro_z") == [
        "Model refinement of gyro_z: Declared filter: a 95-tap FIR at 8000 Hz, decimated by 8 (−3 dB at 321.6 Hz); "
        "the curve needed it: the bandwidth step's kind is the declared filter, its shape fixed (not searched)."
    ]


@pytest.mark.slow  # ≈ 9 s under load; the default tests above cover the sentence and refine's step
def test_the_report_page_and_summary_carry_the_declared_filter():
    from allanite.report import build_report

    fs = 200.0
    b, a = signal.ellip(4, 1.0, 40.0, 30.0, fs=fs)
    y = signal.lfilter(b, a, 0.02 * np.random.default_rng(5).standard_normal(40_000))
    rep = build_report(y, fs, unit="deg/s", refine=("bandwidth",), refine_filter=(b, a), progress=False)
    assert "Declared filter: an IIR of order 4 at 200 Hz" in rep.html({})
    (axis,) = rep.summary()["refinement"]["axes"]
    assert axis["declared_filter"]["type"] == "IIR" and axis["declared_filter"]["order"] == 4
