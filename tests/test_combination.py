"""The window-function combination (issue 14, paper 002): the summed surface, the measured band cross
term, the coefficient series with and without the Gauss–Markov term, bad input."""

from __future__ import annotations

import numpy as np
import pytest

import allanite
from allanite.errors import ParameterError

FS = 100.0


def test_combined_surface_is_the_sum_of_the_band_davars():
    y = np.random.default_rng(0).normal(size=30_000)
    c = allanite.combine(y, FS, window=401, hop=200)
    s = allanite.wavelet_split(y, FS)
    low = allanite.davar(s.low, FS, window=401, hop=200, taus=c.combined.tau)
    high = allanite.davar(s.high, FS, window=401, hop=200, taus=c.combined.tau, taper="hann")
    np.testing.assert_array_equal(c.low.avar, low.avar)
    np.testing.assert_array_equal(c.high.avar, high.avar)
    np.testing.assert_array_equal(c.combined.avar, low.avar + high.avar)
    assert c.low.taper == "rect" and c.high.taper == "hann"
    # white noise: the db5 bands barely correlate (measured ≤ 0.5 % of the total at every τ)
    assert np.max(np.abs(c.cross)) < 0.02
    # the cross term is what separates the band sum from the DAVAR of the summed bands
    both = allanite.davar(s.low + s.high, FS, window=401, hop=200, taus=c.combined.tau).avar
    rect_sum = low.avar + allanite.davar(s.high, FS, window=401, hop=200, taus=c.combined.tau).avar
    np.testing.assert_allclose(np.median((both - rect_sum) / both, axis=1), c.cross, atol=1e-12)


def test_coefficient_series_recovers_white_noise_and_gauss_markov():
    y = allanite.simulate(40_000, FS, N=0.01, gauss_markov=[(0.05, 0.3)], seed=3)
    taus = np.unique(np.round(np.geomspace(1, 600, 20))) / FS
    c = allanite.combine(
        y, FS, window=2001, hop=500, taus=taus, split={"trend": "none"}, terms=("N",), gauss_markov=True
    )
    assert 0.15 < c.gauss_markov["tc"] < 0.6
    assert np.median(c.gauss_markov["sigma"]) == pytest.approx(0.05, rel=0.2)
    assert np.median(c.coefficients.values["N"]) == pytest.approx(0.01, rel=0.05)
    assert c.coefficients.t.size == c.combined.t.size == c.gauss_markov["sigma"].size


def test_a5_trend_removal_shrinks_slow_noise():
    """Removing A5 high-passes near fs/64: a rate random walk mostly disappears from the low band."""
    y = allanite.simulate(60_000, FS, N=0.01, K=0.01, seed=5)
    kw = dict(window=4001, hop=2000, terms=("N", "K"), taus=np.unique(np.round(np.geomspace(1, 1300, 16))) / FS)
    a5 = allanite.combine(y, FS, **kw)
    none = allanite.combine(y, FS, split={"trend": "none"}, **kw)
    k_a5, k_none = np.median(a5.coefficients.values["K"]), np.median(none.coefficients.values["K"])
    assert k_none == pytest.approx(0.01, rel=0.5)
    assert k_a5 < 0.5 * k_none


def test_bad_input():
    y = np.random.default_rng(1).normal(size=(5000, 2))
    with pytest.raises(ParameterError, match="one axis"):
        allanite.combine(y, FS, window=401, hop=100)
    with pytest.raises(ParameterError, match="split must be"):
        allanite.combine(y[:, 0], FS, window=401, split="db5")
    with pytest.raises(ParameterError, match="unknown taper"):
        allanite.combine(y[:, 0], FS, window=401, high_taper="kaiser")


def test_report_sections_taper_and_split():
    from allanite.cli import build_parser
    from allanite.report import build_report

    y = allanite.simulate(30_000, FS, N=0.01, B=0.002, seed=2)
    rep = build_report(y, FS, unit="deg/s", taper="hann", split="db5", window=3000, hop=1000)
    p = rep.summary()["paper002"]
    ax = p["axes"][0]
    assert p["taper"] == "hann" and p["split"] == "db5"
    # white rate noise N = 0.01 °/√s = 0.6 °/√h in both windows; the Hann series scatters more
    assert ax["taper"]["N"]["rect"]["median"] == pytest.approx(0.6, rel=0.05)
    assert ax["taper"]["N"]["hann"]["median"] == pytest.approx(0.6, rel=0.05)
    assert ax["combination"]["bands"]["high"]["levels"] == ["d2", "d1"]
    assert ax["combination"]["cross_max_rel"] < 0.05
    assert 'id="paper002"' in rep.html({}) and "Paper 002 sections" in rep.text()
    args = build_parser().parse_args(["report", "--taper", "hann", "--split", "db5"])
    assert args.taper == "hann" and args.split == "db5"
