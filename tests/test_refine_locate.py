"""Locating a change of noise level to the sample (``changes.locate``) on quantized and continuous records."""

import math
import warnings

import numpy as np
import pytest

from allanite.model.refinement.changes import locate


def _reference(y, m, fs, floor=0.0):
    """Plain loop: the two-segment exponential likelihood of the squared m-sample differences, split by split."""
    k = len(y) // m
    b = [sum(y[i * m : (i + 1) * m]) / m for i in range(k)]
    d = [(b[i + 1] - b[i]) ** 2 + 1e-300 for i in range(k - 1)]
    n, best, best_j = len(d), -math.inf, None
    for j in range(2, n - 1):
        mu1 = max(sum(d[:j]) / j, floor)
        mu2 = max(sum(d[j:]) / (n - j), floor)
        ll = -0.5 * (j * math.log(mu1) + (n - j) * math.log(mu2))
        if ll > best:
            best, best_j = ll, j
    return (best_j + 1) * m / fs


def _quantized(rng, n, q, change_at):
    sigma = np.where(np.arange(n) < change_at, 1.0, 2.0)
    return np.round(sigma * rng.standard_normal(n) / q) * q


@pytest.mark.parametrize("m", [1, 3])
def test_locate_matches_a_plain_loop_on_continuous_samples(m):
    rng = np.random.default_rng(5)
    y = rng.standard_normal(1200) * np.where(np.arange(1200) < 700, 1.0, 1.8)
    t, (lo, hi) = locate(y, m, 10.0)
    assert t == pytest.approx(_reference(list(y), m, 10.0), abs=1e-12)
    assert lo <= t <= hi
    assert abs(t - 70.0) < 5.0


def test_locate_quantized_span_ending_in_equal_samples_finds_the_change():
    # a 1.5-LSB noise whose level doubles at sample 1200, its last samples equal: before, the tail's mean square
    # was 0 (log 0: a RuntimeWarning and an infinite likelihood), which put the split at the span's end
    rng = np.random.default_rng(11)
    y = _quantized(rng, 2400, 0.05 / 1.5, 1200)
    y[-4:] = y[-4]
    y[:3] = y[0]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        t, (lo, hi) = locate(y, 1, 100.0)
    q2 = float(np.min(np.diff(y)[np.diff(y) != 0] ** 2))
    assert t == pytest.approx(_reference(list(y), 1, 100.0, floor=q2 / 6), abs=1e-12)
    assert abs(t - 12.0) < 1.0, t
    assert lo <= 12.0 <= hi
    assert hi < 23.0


def test_locate_constant_span_has_no_warning_and_spans_everything():
    y = np.full(500, 0.25)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        t, (lo, hi) = locate(y, 1, 1.0)
    assert lo <= t <= hi
    assert hi - lo > 400
