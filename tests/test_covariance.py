"""The covariance of overlapping Allan variance estimates across τ (allanite._covariance), which the
noise-model fit uses: checked against the exact quadratic-form covariance on short records, and for
flicker (no exact kernel) against Monte Carlo."""

import numpy as np
import pytest

import allanite
from allanite.model._covariance import assemble, covariance_blocks

N_SAMPLES, FS = 300, 10.0
TAU0 = 1.0 / FS
M = np.array([1, 2, 3, 5, 8, 16, 40, 90])


def _estimator_matrices(n, m_values):
    """σ̂²(m) = yᵀ B_m y for rate samples y (the overlapping estimator written out as a quadratic form)."""
    phase = np.tril(np.ones((n + 1, n)), -1) * TAU0  # x_k = τ0 Σ_{j<k} y_j
    out = []
    for m in m_values:
        count = n + 1 - 2 * m
        d = np.zeros((count, n + 1))
        k = np.arange(count)
        d[k, k] += 1.0
        d[k, k + m] -= 2.0
        d[k, k + 2 * m] += 1.0
        u = d @ phase / (m * TAU0)
        out.append(u.T @ u / (2 * count))
    return out


def _exact(cov_y, mean=None):
    """Cov(yᵀB_i y, yᵀB_j y) = 2 tr(B_i C B_j C) + 4 μᵀB_i C B_j μ for Gaussian y ~ (μ, C)."""
    bs = _estimator_matrices(N_SAMPLES, M)
    out = np.empty((M.size, M.size))
    for i, bi in enumerate(bs):
        for j, bj in enumerate(bs):
            out[i, j] = 2.0 * np.trace(bi @ cov_y @ bj @ cov_y)
            if mean is not None:
                out[i, j] += 4.0 * mean @ bi @ cov_y @ bj @ mean
    return out


def _rel_err(a, b):
    return np.max(np.abs(a - b) / np.sqrt(np.outer(np.diag(b), np.diag(b))))


@pytest.fixture(scope="module")
def rate_covariances():
    n = N_SAMPLES
    walk = np.tril(np.ones((n, n)))
    diff = np.zeros((n, n + 1))
    diff[np.arange(n), np.arange(n)] = -1.0 / TAU0
    diff[np.arange(n), np.arange(n) + 1] = 1.0 / TAU0
    return {
        "Q": diff @ diff.T,  # white angle of variance 1, differenced
        "N": np.eye(n) / TAU0,  # white rate of variance 1/τ0
        "K": walk @ walk.T * TAU0,  # random walk with steps of variance τ0
    }


@pytest.mark.parametrize("term", ["Q", "N", "K"])
def test_each_term_matches_the_exact_quadratic_form(rate_covariances, term):
    s, t = covariance_blocks(M, N_SAMPLES, FS, (term,))
    got = assemble(s, t, np.array([1.0]), (term,))
    assert _rel_err(got, _exact(rate_covariances[term])) < 3e-4


def test_mixture_and_ramp(rate_covariances):
    c = rate_covariances
    terms = ("Q", "N", "K", "R")
    theta = np.array([0.5, 0.3, 2.0, 0.49])
    mean = 0.7 * np.arange(N_SAMPLES) * TAU0  # R = 0.7: a deterministic ramp
    want = _exact(0.5 * c["Q"] + 0.3 * c["N"] + 2.0 * c["K"], mean)
    s, t = covariance_blocks(M, N_SAMPLES, FS, terms)
    assert _rel_err(assemble(s, t, theta, terms), want) < 3e-4
    # the diagonal is the estimate's variance: 2σ⁴/ν with ν the equivalent degrees of freedom
    var = np.diag(assemble(s, t, theta, terms))
    assert np.all(var > 0)


def test_flicker_against_monte_carlo():
    n, reps = 2048, 600
    m = allanite.avar(np.zeros(n) + np.arange(n) % 3, 1.0).m
    est = np.array([allanite.avar(allanite.simulate(n, 1.0, B=1.0, seed=s), 1.0).avar for s in range(reps)])
    mc = np.cov(est.T)
    s, t = covariance_blocks(m, n, 1.0, ("B",))
    model = assemble(s, t, np.array([1.0]), ("B",))
    # the continuous-time kernel is right once m is a few samples (the sampled flicker's plateau is
    # 1.44× at m = 1) and before the simulated record's own roll-off at the longest τ
    mid = slice(3, m.size - 2)
    ratio = np.sqrt(np.diag(model) / np.diag(mc))[mid]
    assert np.all(np.abs(ratio - 1) < 0.12), ratio
    cm = mc / np.sqrt(np.outer(np.diag(mc), np.diag(mc)))
    ca = model / np.sqrt(np.outer(np.diag(model), np.diag(model)))
    assert np.all(np.abs(np.diag(cm, 1) - np.diag(ca, 1))[mid] < 0.1)


def test_blocks_are_cached_and_read_only():
    a = covariance_blocks(M, N_SAMPLES, FS, ("N",))
    b = covariance_blocks(list(M), N_SAMPLES, FS, ("N",))
    assert a[0] is b[0]
    with pytest.raises(ValueError):
        a[0][0, 0, 0, 0] = 1.0


def _flicker_cross_exact(d, mi, mj):
    """r_ij(d) of the flicker kernel in 50-digit decimal arithmetic (no cancellation)."""
    from decimal import Decimal, getcontext

    getcontext().prec = 50
    acc = Decimal(0)
    for a, la in enumerate((1, -2, 1)):
        for b, lb in enumerate((1, -2, 1)):
            h = Decimal(d + b * mj - a * mi)
            if h != 0:
                acc += la * lb * h * h * abs(h).ln()
    return float(acc / (2 * Decimal(str(np.pi)) * mi * mj))


@pytest.mark.parametrize("mi, mj", [(1, 1), (1, 4), (64, 1024)])
def test_flicker_tail_keeps_its_precision_far_out(mi, mj):
    from allanite.model._covariance import _cross

    d = np.array([0.0, 3.0, 40.0, 1e3, 1e5, -1e7, 1e8])
    got = _cross(d, mi, mj, 1.0)[2]
    want = np.array([_flicker_cross_exact(int(v), mi, mj) for v in d])
    np.testing.assert_allclose(got, want, rtol=1e-9)
    # the finite-support kernels are exactly zero beyond the shared samples (not rounding noise)
    far = _cross(np.array([1e8]), mi, mj, 1.0)
    assert far[0, 0] == far[1, 0] == far[3, 0] == 0.0


def test_flicker_variance_scales_as_one_over_n_up_to_1e8():
    # at m = 1 flicker's estimate variance is ∝ 1/M: n·Var must not drift with the record length (the
    # nine-term sum of h²·ln|h| used to cancel catastrophically: 10⁴× too large at n = 10⁸)
    from allanite.model._covariance import _blocks

    scaled = [n * _blocks(np.array([1, 2, 4]), n, 1.0, ("B",))[0][0, 0, 0, 0] for n in (10**4, 10**6, 10**8)]
    assert scaled[1] == pytest.approx(scaled[0], rel=1e-3) and scaled[2] == pytest.approx(scaled[0], rel=1e-3)


def test_a_suffix_of_remembered_blocks_is_sliced_bit_for_bit():
    from allanite.model import _covariance

    m = np.array([1, 2, 4, 8, 16, 32, 64, 128, 256, 512, 1024, 2048])
    terms = ("Q", "N", "B", "K", "R")
    full = covariance_blocks(m, 20_000, 100.0, terms)
    for k in (1, 3, 6):
        s, t = covariance_blocks(m[k:], 20_000, 100.0, terms)
        fresh_s, fresh_t = _covariance._blocks(m[k:], 20_000, 100.0, terms)
        assert np.array_equal(s.view(np.int64), fresh_s.view(np.int64))
        assert np.array_equal(t.view(np.int64), fresh_t.view(np.int64))
        assert not s.flags.writeable and s.shape[2:] == (m.size - k, m.size - k) and full[0].shape[2] == m.size
    # another record length is not a slice of this one
    other = covariance_blocks(m[2:], 20_001, 100.0, terms)
    assert not np.array_equal(other[0], covariance_blocks(m[2:], 20_000, 100.0, terms)[0])
