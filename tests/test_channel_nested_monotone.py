"""A nested likelihood ratio of the channel regression is never below zero (`allanite.model._whittle.joint_fit`
returns the best coefficients-and-noise pair it visited; `nested_fit` starts from the smaller model where the cold
alternation ends below it). On main a 1 kHz × 10⁶ record with a 300 s lag read −59.5 for its d(ch)/dt term: the
noise refit lowered the likelihood after the first GLS step (docs/channels.md, "Quantised and held channels")."""

from __future__ import annotations

import numpy as np

import allanite
from allanite.model import _whittle as wh
from allanite.model._regressors import regressor_design, regressor_iter
from allanite.model.channels import lagged


def _bands(y, x, fs):
    n_use = wh.usable_length(y.size)
    y, x = y[:n_use], x[:n_use]
    mean = float(x.mean())
    return wh.spectra(y, regressor_iter(x, mean, float(np.mean((x - mean) ** 2)), fs, None), fs)


def test_the_rate_terms_likelihood_ratio_on_a_long_lagged_record_is_not_negative():
    fs, n = 1000.0, 1_000_000
    rng = np.random.default_rng(1)
    temp = 25.0 + 5.0 * np.sin(2 * np.pi * np.arange(n) / fs / 500.0)
    bands = _bands(0.02 * rng.standard_normal(n) + 0.004 * lagged(temp, 300.0, fs), temp, fs)
    small = wh.joint_fit(bands, regressor_design([], bands.m.size))
    big = wh.nested_fit(bands, regressor_design(["rate_coefficient"], bands.m.size), small)
    # main: −59.5 (the alternation ended below the channel-alone fit); the lag's d(ch)/dt part is real: +58.4
    assert 2.0 * (big["loglik"] - small["loglik"]) > 50.0
    # the pair returned is a point of the model: its likelihood is the one of its coefficients and noise
    resid = wh.residual_power(bands, regressor_design(["rate_coefficient"], bands.m.size), big["c"])
    assert np.isclose(wh.loglik(bands, resid, big["s"]), big["loglik"], rtol=1e-12)


def test_nested_fits_never_fall_below_the_smaller_model_on_null_records():
    # warm-ups, cycles and walks the rate does not follow; 2Δℓ of each nested step ≥ 0 (a likelihood ratio)
    for seed in range(6):
        rng = np.random.default_rng(seed)
        fs, n = (1.0, 20.0)[seed % 2], 8000
        t = np.arange(n) / fs
        temp = (25.0 - 10.0 * np.exp(-t / t[-1] * 5.0), 25.0 + 5.0 * np.sin(2 * np.pi * t / t[-1] * 2))[seed % 2]
        y = allanite.simulate(n, fs, N=1e-3, B=3e-4, K=2e-5, seed=rng)
        bands = _bands(y, temp + 0.01 * rng.standard_normal(n), fs)
        null = wh.joint_fit(bands, wh.Design([], []))
        chain = [null]
        for keys in ([], ["quadratic"], ["quadratic", "rate_coefficient"]):
            chain.append(wh.nested_fit(bands, regressor_design(keys, bands.m.size), chain[-1]))
        steps = np.diff([f["loglik"] for f in chain])
        assert np.all(steps >= 0.0), (seed, steps)
