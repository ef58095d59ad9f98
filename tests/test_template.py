"""A periodic waveform by epoch folding (allanite.model.template): every harmonic at once, the folded ones too,
where least squares at the harmonics below f_s/2 leaves the folded ones in the record."""

from __future__ import annotations

import math

import numpy as np
from scipy import signal

from allanite.model import linefit
from allanite.model.template import fit_template, fold

FS = 400.0
N = 200_000
F0 = 2.3  # 400/2.3 = 173.9 samples a period: the sawtooth's harmonics above 200 Hz fold into the band


def _saw(amp=0.05):
    return amp * signal.sawtooth(2 * np.pi * F0 * np.arange(N) / FS + 1.1)


def test_folding_takes_the_folded_harmonics_that_least_squares_below_nyquist_misses():
    saw = _saw()
    y = saw + np.random.default_rng(3).normal(0.0, 0.002, N)
    tpl = fit_template(y, FS, F0)
    # 400/2.3 = 4000/23 samples a period: the samples sit at exactly 4000 phases, 4096 bins hold one each
    assert tpl.bins == 4096 and np.count_nonzero(tpl.counts) == 4000
    err_t = float(np.std(saw - tpl.component()))
    # least squares at every harmonic below f_s/2 (86 of them): the folded ones, Σ_{k>86} (2A/πk)²/2, stay
    coefs = np.arange(1, int(FS / 2 / F0) + 1)[:, None]
    a, b = linefit.solve(y, np.arange(N), np.array([F0 / FS]), coefs)
    err_ls = float(np.std(saw - linefit.evaluate(np.arange(N), np.array([F0 / FS]), coefs, a, b)))
    folded = 2 * 0.05 / math.pi * math.sqrt(sum(0.5 / k**2 for k in range(87, 200_000)))
    assert abs(err_ls / folded - 1) < 0.15  # what the lines leave is the folded harmonics
    # what the template leaves is the noise of 50 samples per phase: 0.002/√50
    assert abs(err_t / (0.002 / math.sqrt(50)) - 1) < 0.1 and err_t < 0.2 * err_ls
    assert abs(tpl.rms / (0.05 / math.sqrt(3)) - 1) < 0.002
    assert tpl.rms_sd < 0.001 * tpl.rms


def test_a_continuum_of_phases_takes_the_held_out_best_number_of_bins():
    f0 = 2.2961  # 4·10⁶/22961 samples a period: every sample at a phase of its own
    saw = 0.05 * signal.sawtooth(2 * np.pi * f0 * np.arange(N) / FS)
    y = saw + np.random.default_rng(5).normal(0.0, 0.01, N)
    tpl = fit_template(y, FS, f0)
    ho = tpl.heldout
    assert tpl.bins == min(ho, key=ho.get) and 32 <= tpl.bins <= 1024 and max(ho) == 4096
    assert abs(tpl.rms / (0.05 / math.sqrt(3)) - 1) < 0.01
    assert float(np.std(saw - tpl.component())) < 0.05 * 0.05


def test_a_whole_number_of_samples_a_period_fills_the_empty_bins():
    # a period of exactly 10 samples: 64 bins get samples in 10 of them; the rest interpolated, the samples exact
    n = 10_000
    wave = np.array([0.0, 1.0, 3.0, 2.0, -1.0, -4.0, -2.0, 0.5, 1.5, -1.0])
    y = np.tile(wave, n // 10)
    mean, count = fold(y, np.arange(n), 0.1, 64)
    assert np.count_nonzero(count) == 10 and np.all(np.isfinite(mean))
    tpl = fit_template(y, 10.0, 1.0, bins=64)
    assert np.max(np.abs(tpl.component() - (y - y.mean()))) < 1e-12


def test_the_refit_on_held_in_blocks_predicts_the_held_out_ones():
    saw = _saw()
    y = saw + np.random.default_rng(4).normal(0.0, 0.01, N)
    tpl = fit_template(y, FS, F0)
    held_in = np.concatenate([np.arange(j * 25_000, (j + 1) * 25_000) for j in range(0, 8, 2)])
    held_out = np.setdiff1d(np.arange(N), held_in)
    g = tpl.refit(y[held_in], held_in)
    resid = y[held_out] - g(held_out)
    assert abs(float(np.std(resid)) / 0.01 - 1) < 0.02  # the noise is what is left
