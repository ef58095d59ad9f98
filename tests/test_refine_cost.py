"""refine's speed-ups give the numbers of the plain computations they replace (issue 29, refine's cost).

Each shortcut is checked against the plain path, bit for bit: the fits of a grid run together against one fit at a
time (the IRLS of the pre-batching code, written out here; with spectral lines held at their power too) and their
designs stacked against one per model, the NNLS
without scipy's wrapper against ``scipy.optimize.nnls``, the covariance blocks with the lag kernels of many pairs at
once (and their nodes built for all pairs at once) against one pair at a time, Greenhall's EDF sums in one call
against shift by shift, the replacement's running median at the flagged samples against the filter's, the drift
bootstrap's one-product statistics against a QR per grid point (within
1e-9), Brent's bounded search as a coroutine against scipy's, a step's searches run in lockstep against one search
after another (scipy's bounded search, one fit per call), the line spectra remembered within a refine and the EDF
remembered per averaging factors against fresh ones, the line families' phase gridding, DTFT and waveforms against
their plain forms, and a whole default ``refine`` with every memory and the lockstep against one that recomputes
everything one search at a time (a record with a Gauss–Markov term and a temperature coupling: the curve's memories
and the channel's transforms in one pair of refines). The fits here run the Python loop (``_irls.irls_python``; the Rust core's
loop, which agrees with it to rounding, is checked in ``tests/test_refine_irls.py``), but for the whole default
``refine``, which runs the core's loop both ways. No timings here: ``benches/bench_refine_cost.py``.
"""

from __future__ import annotations

import contextlib
import importlib
import math

import numpy as np
import pytest
from scipy.optimize import minimize_scalar
from scipy.optimize import nnls as scipy_nnls

import allanite
from allanite.model import _covariance, _nnls, linefit, lines, tracing
from allanite.model._recent import Recent, Small
from allanite.model.refinement import _brent, _irls, curvefit
from allanite.model.refinement import candidates as cands
from allanite.model.refinement.candidates import bandwidth_grids

START = ("Q", "N", "B", "K", "R")
COMPILED = _irls.COMPILED


@pytest.fixture(autouse=True)
def python_irls(monkeypatch):
    """The fits of this module in the Python loop, whose arithmetic the plain paths below write out."""
    monkeypatch.setattr(_irls, "COMPILED", None)


@pytest.fixture(scope="module")
def curve():
    y = allanite.simulate(200_000, 100.0, N=2e-3, B=3e-4, K=2e-5, gauss_markov=[(4e-3, 3.0)], seed=3)
    res = allanite.avar(y, 100.0, taus=allanite.tau_grid(y.size, 100.0, "exp", points=200, m_max=y.size // 9))
    keep = res.avar > 0
    return curvefit.Curve(res.tau[keep], res.m[keep].astype(float), res.avar[keep], 100.0, y.size + 1, "oavar")


def _plain_solve(curve, terms, effects, max_iter=40):
    """The IRLS as it was before the batch (one design, scipy's NNLS on unit-norm columns)."""
    a, alphas = curvefit.design(curve, terms, effects)
    nu_cols = np.column_stack(
        [
            np.where(
                al == -2,
                curve.edf(-2),
                np.where(al == -1, curve.edf(-1), np.where(al == 2, curve.edf(2), curve.edf(0))),
            )
            for al in alphas
        ]
    )
    y = curve.avar
    model, theta = y.copy(), np.zeros(a.shape[1])
    nu = nu_cols[:, 1] if len(terms) > 1 else nu_cols[:, 0]
    floor = 1e-12 * np.max(y)
    for it in range(max_iter):
        sw = np.sqrt(nu / (2.0 * np.maximum(model, floor) ** 2))
        aw = a * sw[:, None]
        scale = np.linalg.norm(aw, axis=0)
        scale[scale == 0] = 1.0
        new = scipy_nnls(aw / scale, y * sw, maxiter=50 * a.shape[1])[0] / scale
        parts = a * new
        new_model = np.maximum(parts.sum(axis=1), floor)
        done = bool(np.all(np.abs(new - theta) <= 1e-6 * np.abs(theta)))
        model = new_model if it == 0 else np.sqrt(model * new_model)
        theta = new
        if new.any():
            tot, den = parts.sum(axis=1), np.sum(parts**2 / nu_cols, axis=1)
            nu = np.where(den > 0, tot**2 / np.maximum(den, 1e-300), nu)
        if done:
            break
    model = np.maximum(a @ theta, floor)
    z = (y - model) * np.sqrt(nu / (2.0 * model**2))
    return theta, nu, float(np.sum(z**2))


@pytest.mark.parametrize("effects", [[], [("sinusoid", 7.0)], [("gauss_markov", 3.0), ("bandwidth:single_pole", 20.0)]])
@pytest.mark.parametrize("max_iter", [6, 40])
def test_grid_fits_together_equal_one_at_a_time(curve, effects, max_iter):
    for key, grid in [("resonance:16", np.geomspace(5.0, 40.0, 9)), ("gauss_markov", np.geomspace(0.5, 200.0, 7))]:
        together = curvefit.chi2s(curve, START, effects, key, grid, max_iter=max_iter)
        plain = [_plain_solve(curve, START, effects + [(key, float(p))], max_iter)[2] for p in grid]
        np.testing.assert_array_equal(together, plain)
    kind, grid = next(iter(bandwidth_grids(curve).items()))
    together = curvefit.chi2s(curve, START, effects, f"bandwidth:{kind}", grid[:6], max_iter=max_iter)
    plain = [_plain_solve(curve, START, effects + [(f"bandwidth:{kind}", float(p))], max_iter)[2] for p in grid[:6]]
    np.testing.assert_array_equal(together, plain)


def test_solve_equals_the_plain_irls(curve):
    effects = [("gauss_markov", 3.0)]
    theta, nu, chi2 = _plain_solve(curve, START, effects)
    sol = curvefit.solve(curve, START, effects)
    np.testing.assert_array_equal(sol.theta, theta)
    np.testing.assert_array_equal(sol.nu, nu)
    assert sol.chi2 == chi2
    # a second solve on the same curve reads its columns from the curve's memory: the same numbers
    again = curvefit.solve(curve, START, effects)
    np.testing.assert_array_equal(again.theta, sol.theta)
    np.testing.assert_array_equal(again.cov, sol.cov)


def test_nnls_equals_scipy_and_keeps_its_errors():
    rng = np.random.default_rng(5)
    for _ in range(20):
        a = np.abs(rng.standard_normal((60, 5))) * np.geomspace(1e-6, 1e3, 5)
        b = rng.standard_normal(60) + 2.0
        scale = np.linalg.norm(a, axis=0)
        ref = scipy_nnls(a / scale, b, maxiter=250)[0] / scale
        np.testing.assert_array_equal(_nnls.nnls(a, b), ref)
    a[3, 2] = np.nan
    with pytest.raises(ValueError, match="infs or NaNs"):
        _nnls.nnls(a, b)


def _plain_cross(d, mi, mj, tau0):
    """The lag kernels of one pair of averaging factors, as before the pairs were evaluated together."""
    lam = (1.0, -2.0, 1.0)
    offsets = [(lam[a] * lam[b], float(b * mj - a * mi)) for a in range(3) for b in range(3)]
    acc = np.zeros((4, d.size))
    far = np.abs(d) >= 4.0 * (2 * mi + 2 * mj)
    near = ~far
    for w, o in offsets:
        acc[:, near] += w * _covariance._kernels(d[near] + o, tau0)
    outside = (d > 2 * mi) | (d < -2 * mj)
    acc[0, outside] = acc[1, outside] = acc[3, outside] = 0.0
    if far.any():
        ad, sgn, total = np.abs(d[far]), np.sign(d[far]), np.zeros(int(far.sum()))
        for k in range(4, 17):
            s_k = sum(w * o**k for w, o in offsets)
            if s_k == 0.0:
                continue
            g_k = 2.0 * (-1.0) ** (k - 1) * math.factorial(k - 3) / ad ** (k - 2) * sgn**k
            total += g_k * (s_k / math.factorial(k))
        acc[2, far] = total * (tau0 * tau0 / (2.0 * math.pi))
    return acc / (mi * mj * tau0 * tau0)


def _plain_nodes(mi, mj, big_m_i, big_m_j, long_tail):
    """The quadrature nodes built piece by piece, as before."""
    lo, hi = -(big_m_i - 1), big_m_j - 1
    s_lo, s_hi = max(lo, -2 * mj), min(hi, 2 * mi)
    bps = {s_lo, s_hi, 0, big_m_j - big_m_i} | {a * mi - b * mj for a in range(3) for b in range(3)}
    a_lo, a_hi = s_lo, s_hi
    if long_tail:
        bps |= {lo, hi} | {2 * mi * 2**k for k in range(64) if 2 * mi * 2**k < hi}
        bps |= {-2 * mj * 2**k for k in range(64) if 2 * mj * 2**k < -lo}
        a_lo, a_hi = lo, hi
    pts = np.array(sorted(b for b in bps if a_lo <= b <= a_hi), dtype=np.float64)
    nodes, weights = [pts], [np.ones(pts.size)]
    for a, b in zip(pts[:-1], pts[1:]):
        n_in = int(b - a) - 1
        if 0 < n_in <= _covariance._EXACT_RUN:
            nodes.append(np.arange(a + 1, b))
            weights.append(np.ones(n_in))
        elif n_in > 0:
            half = 0.5 * ((b - 0.5) - (a + 0.5))
            nodes.append(0.5 * ((b - 0.5) + (a + 0.5)) + half * _covariance._GL_X)
            weights.append(half * _covariance._GL_W)
    d, w = np.concatenate(nodes), np.concatenate(weights)
    return d, w * np.clip(np.minimum(big_m_i, big_m_j - d) - np.maximum(0.0, -d), 0.0, None)


@pytest.mark.parametrize("n", [5_000, 100_000_000])
@pytest.mark.parametrize("terms", [START, ("N", "K")])
def test_covariance_blocks_equal_pair_by_pair(n, terms):
    m = np.unique(np.geomspace(1, n // 9, 9).astype(np.int64))
    s_blk, t_blk = _covariance._blocks(m, n, 100.0, terms)
    stoch = [t for t in terms if t in _covariance.KERNEL_TERMS]
    sel = [_covariance.KERNEL_TERMS.index(t) for t in stoch]
    big_m, tau = n + 1 - 2 * m, m * 0.01
    for i in range(m.size):
        for j in range(i, m.size):
            d, wc = _plain_nodes(int(m[i]), int(m[j]), int(big_m[i]), int(big_m[j]), "B" in stoch)
            d_new, wc_new, size = _covariance._nodes([m[i]], [m[j]], [big_m[i]], [big_m[j]], "B" in stoch)
            assert size.tolist() == [d.size]
            np.testing.assert_array_equal(d_new, d)
            np.testing.assert_array_equal(wc_new, wc)
            r = _plain_cross(d, int(m[i]), int(m[j]), 0.01)[sel]
            norm = 1.0 / (float(big_m[i]) * float(big_m[j]))
            rw = r * wc
            # the same formulas, but NumPy's SIMD transcendental functions and summation order depend on the
            # array's shape and NumPy's version, and the flicker term's cross-covariance cancels at 10^8 samples:
            # equal to 1e-12 of the block's largest entry (the scale the GLS sees), not to the bit
            s_ref, t_ref = 0.5 * norm * (rw @ r.T), norm * tau[i] * tau[j] * rw.sum(axis=1)
            np.testing.assert_allclose(s_blk[:, :, i, j], s_ref, rtol=0, atol=1e-12 * np.abs(s_ref).max())
            np.testing.assert_allclose(t_blk[:, i, j], t_ref, rtol=0, atol=1e-12 * np.abs(t_ref).max())
    # every pair's nodes at once: each pair's own, one after another
    ii, jj = np.triu_indices(m.size)
    d_all, wc_all, sizes = _covariance._nodes(m[ii], m[jj], big_m[ii], big_m[jj], "B" in stoch)
    plain = [_plain_nodes(int(m[i]), int(m[j]), int(big_m[i]), int(big_m[j]), "B" in stoch) for i, j in zip(ii, jj)]
    assert sizes.tolist() == [d.size for d, _wc in plain]
    np.testing.assert_array_equal(d_all, np.concatenate([d for d, _wc in plain]))
    np.testing.assert_array_equal(wc_all, np.concatenate([wc for _d, wc in plain]))


def test_drift_bootstrap_statistics_equal_a_qr_per_grid_point():
    rng = np.random.default_rng(2)
    nb = 300
    b = np.cumsum(rng.standard_normal((nb, 200)), axis=0) * 0.02 + rng.standard_normal((nb, 200))
    tb = (np.arange(nb) * 1000 + 499.5) / 100.0
    length = nb * 1000 / 100.0
    base = np.column_stack([np.ones(nb), tb])
    q0 = np.linalg.qr(base)[0]
    rss0 = np.sum((b - q0 @ (q0.T @ b)) ** 2, axis=0)
    best = np.full(b.shape[1], np.inf)
    for lt in np.linspace(math.log(length / 200), math.log(length / 2), 24):
        q = np.linalg.qr(np.column_stack([base, np.exp(-tb / math.exp(lt))]))[0]
        best = np.minimum(best, np.sum((b - q @ (q.T @ b)) ** 2, axis=0))
    np.testing.assert_allclose(tracing._grid_stats(b, tb, length), nb * np.log(rss0 / best), rtol=1e-9, atol=1e-9)


def _one_at_a_time(curve, terms, effects, specs):
    """The searches one after another, each on its own, with scipy's bounded search (the code before the lockstep)."""
    out = []
    for key, grid, cont in specs:
        chis = curvefit.chi2s(curve, terms, effects, key, grid, max_iter=6)
        k = int(np.argmin(chis))
        lo, hi = math.log(grid[max(0, k - 1)]), math.log(grid[min(grid.size - 1, k + 1)])
        p = float(grid[k])
        if cont and hi > lo:
            res = minimize_scalar(
                lambda lp, key=key: float(curvefit.chi2s(curve, terms, effects, key, [math.exp(lp)])[0]),
                bounds=(lo, hi),
                method="bounded",
                options={"xatol": 1e-3},
            )
            p = math.exp(res.x)
        out.append(curvefit._searched(curve, terms, effects, key, grid, cont, p, k))
    return out


def test_refine_with_remembered_columns_equals_recomputing(monkeypatch):
    monkeypatch.setattr(_irls, "COMPILED", COMPILED)  # the default path: the core's loop where it is built
    # a Gauss–Markov term and a temperature coupling (2.5 cycles): the curve's searches and the channel's remembered
    # transforms in one pair of refines (test_refine_cost_memos.py's refine with a channel alone: the slow set)
    n, fs = 50_000, 50.0  # 1000 s: both effects found, and as much remembered as at 100 000 (r12ci)
    t = np.arange(n) / fs
    temp = 10.0 + 5.0 * np.sin(2 * np.pi * t / (n / fs / 2.5)) + 0.01 * np.random.default_rng(2).standard_normal(n)
    y = allanite.simulate(n, fs, N=2e-3, K=2e-5, gauss_markov=[(5e-3, 4.0)], seed=8) + 2e-3 * temp
    hits, recent_get = [], Recent.get

    def counted(self, arr, key=()):
        value = recent_get(self, arr, key)
        hits.append(value is not None)
        return value

    monkeypatch.setattr(Recent, "get", counted)
    cached = allanite.refine(y, fs, channels={"temp": temp}, progress=False)
    assert sum(hits) > 10  # the channel's and the held-out curves' memories were used (28 times at the last count)
    monkeypatch.setattr(curvefit.Curve, "cached", lambda self, key: None)  # every column, EDF and subset afresh
    loop = importlib.import_module("allanite.model.refinement.loop")
    monkeypatch.setattr(loop, "prefetch", lambda rnd, c: None)
    monkeypatch.setattr(loop, "remembering_spectra", contextlib.nullcontext)  # every line spectrum afresh
    monkeypatch.setattr(curvefit, "searches", _one_at_a_time)  # each search alone, when proposed
    monkeypatch.setattr(Recent, "get", lambda self, arr, key=(): None)  # held-out curves, phasors, … afresh
    monkeypatch.setattr(Small, "get", lambda self, key: None)  # noise fits, Bartlett factors afresh
    plain = allanite.refine(y, fs, channels={"temp": temp}, progress=False)
    assert cached.found == plain.found == ["gauss_markov", "regression"]
    for a, b in zip(cached.steps, plain.steps):
        assert a.params == b.params and a.intervals == b.intervals
        assert a.before == b.before and a.after == b.after
    assert cached.fit.chi2 == plain.fit.chi2
    assert cached.unexplained == plain.unexplained


def test_brent_coroutine_visits_scipys_points():
    rng = np.random.default_rng(4)
    for i in range(300):
        c = rng.uniform(-3.0, 3.0, 4)
        lo, hi = sorted(rng.uniform(-2.0, 2.0, 2))

        def f(x, c=c, step=i % 3 == 0):  # smooth, and with steps (parabolas rejected, golden sections)
            return float(c[0] * np.sin(c[1] * x) + c[2] * (x - c[3]) ** 2 + (np.floor(5 * x) if step else 0.0))

        seen: list = []
        ours: list = []
        ref = minimize_scalar(
            lambda x, seen=seen: seen.append(x) or f(x), bounds=(lo, hi), method="bounded", options={"xatol": 1e-3}
        )
        got = _brent.minimize(lambda x, ours=ours: ours.append(x) or f(x), lo, hi, xatol=1e-3)
        assert got == ref.x and ours == seen and len(seen) == ref.nfev


def _plain_search(curve, terms, effects, key, grid, continuous=True):
    """One search as before the lockstep: the grid screened, scipy's bounded search one fit per call."""
    chis = [_plain_solve(curve, terms, effects + [(key, float(p))], 6)[2] for p in grid]
    k = int(np.argmin(chis))
    lo, hi = math.log(grid[max(0, k - 1)]), math.log(grid[min(grid.size - 1, k + 1)])
    p = float(grid[k])
    if continuous and hi > lo:
        res = minimize_scalar(
            lambda lp: _plain_solve(curve, terms, effects + [(key, math.exp(lp))])[2],
            bounds=(lo, hi),
            method="bounded",
            options={"xatol": 1e-3},
        )
        p = math.exp(res.x)
    theta, _nu, chi2 = _plain_solve(curve, terms, effects + [(key, p)])
    if p != float(grid[k]):
        theta_k, _nu_k, chi2_k = _plain_solve(curve, terms, effects + [(key, float(grid[k]))])
        if chi2 > chi2_k:
            p, theta, chi2 = float(grid[k]), theta_k, chi2_k
    return p, theta, chi2, (k == 0 and continuous) or k == grid.size - 1


@pytest.mark.parametrize("effects", [[], [("bandwidth:single_pole", 20.0)]])
def test_searches_in_lockstep_equal_one_after_another(curve, effects):
    rnd = cands.Round(curve, START, effects, curvefit.solve(curve, START, effects))
    specs = [
        s for name in ("gauss_markov", "bandwidth", "resonance") for s in cands.CURVE_CANDIDATES[name].searches(rnd)
    ]
    assert len(specs) >= 5
    fresh = curvefit.Curve(curve.tau, curve.m, curve.avar, curve.fs, curve.n_points, curve.estimator)
    together = curvefit.searches(fresh, START, effects, specs)
    for (key, grid, cont), (p, sol, edge) in zip(specs, together):
        p_ref, theta_ref, chi2_ref, edge_ref = _plain_search(curve, START, effects, key, grid, cont)
        assert (p, edge) == (p_ref, edge_ref), key
        np.testing.assert_array_equal(sol.theta, theta_ref)
        assert sol.chi2 == chi2_ref
    # a proposal's search afterwards is read from the curve's memory: the same numbers, its own Solution
    again = curvefit.search(fresh, START, effects, *specs[0])
    assert again[0] == together[0][0] and again[1] is not together[0][1]
    np.testing.assert_array_equal(again[1].theta, together[0][1].theta)


def _plain_fold(z, u, m_bins, seg, n_seg):
    """The gridding + FFT of :func:`allanite.model.linefit._fold` as it was (offsets added per part, the
    kernel's transform computed per call)."""
    x = u * m_bins
    j = x.astype(np.int64)
    w = x - j
    j1 = np.where(j + 1 >= m_bins, 0, j + 1)
    off = 0 if seg is None else seg * m_bins
    size = m_bins * n_seg
    parts = []
    for part in (z.real, z.imag) if np.iscomplexobj(z) else (z,):
        hi = part * w
        parts.append(np.bincount(j + off, part - hi, minlength=size) + np.bincount(j1 + off, hi, minlength=size))
    g = parts[0] + 1j * parts[1] if len(parts) == 2 else parts[0]
    out = np.fft.fft(g.reshape(n_seg, m_bins), axis=1)
    k = np.arange(m_bins)
    ks = np.where(k > m_bins // 2, k - m_bins, k)
    return out / np.sinc(ks / m_bins) ** 2


@pytest.mark.parametrize("n_seg", [1, 32])
@pytest.mark.parametrize("kind", [np.float64, np.complex128])
def test_fold_equals_the_plain_gridding(n_seg, kind):
    rng = np.random.default_rng(6)
    n = 50_000
    z = rng.standard_normal(n) + (1j * rng.standard_normal(n) if kind is np.complex128 else 0.0)
    u = np.mod(np.arange(n) * 0.1234567, 1.0)
    u[:3] = [0.0, np.nextafter(1.0, 0.0), 0.5]  # the last phase bin wraps to the first
    seg = None if n_seg == 1 else np.minimum(np.arange(n) * n_seg // n, n_seg - 1)
    for m_bins in (4096, 2**14):
        np.testing.assert_array_equal(linefit._fold(z, u, m_bins, seg, n_seg), _plain_fold(z, u, m_bins, seg, n_seg))


def _same_search(a, b):
    assert a["bins"] == b["bins"] and a["p_value"] == b["p_value"] and a["lines"] == b["lines"]
    for pa, pb in zip(a["passes"], b["passes"], strict=True):
        assert pa.keys() == pb.keys()
        for key in pa:
            if isinstance(pa[key], np.ndarray):
                np.testing.assert_array_equal(pa[key], pb[key])


def test_remembered_line_spectra_equal_fresh_ones():
    t = np.arange(200_000) / 100.0
    y = allanite.simulate(t.size, 100.0, N=2e-3, K=2e-5, seed=9) + 0.02 * np.sin(2 * np.pi * 1.3 * t)
    other = y + 0.02 * np.sin(2 * np.pi * 7.1 * t)
    fresh = [lines.find_lines(v, 100.0, a) for v, a in ((y, 0.01), (y, 0.2), (other, 0.01))]
    with lines.remembering_spectra():
        # the same samples at two levels (the masks of the first search must not leak into the second), a copy
        # of them, other samples: each the fresh search's numbers
        got = [lines.find_lines(v, 100.0, a) for v, a in ((y, 0.01), (y, 0.2), (other, 0.01))]
        again = lines.find_lines(y.copy(), 100.0, 0.01)
        assert len(lines._SPECTRA[-1]) == 2  # two records' spectra computed, not four
    assert lines._SPECTRA == []  # forgotten on leaving
    for g, f in zip(got, fresh):
        _same_search(g, f)
    _same_search(again, fresh[0])
    assert len(fresh[0]["lines"]) >= 1 and len(fresh[2]["lines"]) >= 2


def test_remembered_edf_equals_computed(curve):
    from allanite.model import fitting

    twin = curvefit.Curve(curve.tau, curve.m.copy(), curve.avar * 1.1, curve.fs, curve.n_points, curve.estimator)
    half = curvefit.Curve(curve.tau, curve.m, curve.avar, curve.fs, curve.n_points // 2, curve.estimator)
    for alpha in (-2, -1, 0, 2):
        plain = fitting.edf_per_tau(np.full(curve.m.size, alpha), curve.m, curve.n_points, curve.estimator)
        np.testing.assert_array_equal(curve.edf(alpha), plain)
        assert twin.edf(alpha) is curve.edf(alpha)  # the same factors and length: read from memory
        plain_half = fitting.edf_per_tau(np.full(curve.m.size, alpha), curve.m, curve.n_points // 2, curve.estimator)
        np.testing.assert_array_equal(half.edf(alpha), plain_half)
        assert not np.array_equal(plain_half, plain)


def test_stacked_designs_equal_one_per_model(curve):
    prefix = [("gauss_markov", 3.0)]
    grids = [("resonance:4", [6.0, 9.0]), ("bandwidth:boxcar", [1.5, 3.0])]
    models = [prefix + [(key, p)] for key, grid in grids for p in grid]
    models += [prefix + [("gauss_markov", 40.0)], prefix + [("resonance:4", 12.0)]]  # groups interleaved
    a, nu = curvefit._stacked(curve, START, models)
    for g, eff in enumerate(models):
        d, alphas = curvefit.design(curve, START, eff)
        np.testing.assert_array_equal(a[g], d)
        np.testing.assert_array_equal(nu[g], curvefit.edf_columns(curve, alphas))
    assert not np.array_equal(a[2][:, 1], a[0][:, 1])  # a bandwidth's design has N zeroed, a resonance's not


def _plain_evaluate(idx, gens, coefs, a, b):
    """:func:`allanite.model.linefit.evaluate` as it was: every waveform interpolated as a complex array."""
    gens, coefs = linefit._oriented(np.atleast_1d(np.asarray(gens, float)), np.atleast_2d(np.asarray(coefs)))
    out = np.zeros(idx.size)
    u = np.mod(idx * gens[0], 1.0)
    nu2 = float(gens[1]) if gens.size > 1 else 0.0
    for s, rows, ph in linefit._groups(coefs, nu2, idx):  # ph: |s|'s phasor, conjugated for a negative s
        k = coefs[rows, 0]
        m_bins = linefit._grid(int(np.max(np.abs(k))))
        spec = np.zeros(m_bins, dtype=np.complex128)
        np.add.at(spec, np.mod(k, m_bins), (a[rows] - 1j * b[rows]) / np.sinc(k / m_bins) ** 2)
        wave = np.fft.ifft(spec) * m_bins
        wave = np.append(wave, wave[0])
        x = u * m_bins
        j = x.astype(np.int64)
        f = x - j
        val = wave[j] * (1.0 - f) + wave[j + 1] * f
        if ph is not None:
            val = val * (np.conj(ph) if s < 0 else ph)
        out += val.real
    return out


def test_evaluate_equals_the_complex_interpolation(monkeypatch):
    monkeypatch.setattr(linefit, "_WAVE", None)  # NumPy's path (the core's: tests/test_refine_irls.py)
    rng = np.random.default_rng(7)
    idx = np.arange(100_000)
    for gens, coefs in [
        (np.array([0.0123]), np.arange(1, 40)[:, None]),  # harmonics: the real path
        (np.array([0.031, 0.0047]), np.array([[k, s] for k in (1, 2, 3) for s in (-2, -1, 0, 1, 2)])),  # sidebands
    ]:
        a, b = rng.standard_normal(coefs.shape[0]), rng.standard_normal(coefs.shape[0])
        got = linefit.evaluate(idx, gens, coefs, a, b)
        np.testing.assert_array_equal(got, _plain_evaluate(idx, gens, coefs, a, b))
        assert np.std(got) > 1.0


def _plain_dtft(y, idx, gens, coefs, n_seg=1):
    """:func:`allanite.model.linefit.dtft` as it was: the heterodyned samples complex, each group gridded anew."""
    gens, coefs = linefit._oriented(np.atleast_1d(np.asarray(gens, float)), np.atleast_2d(np.asarray(coefs)))
    out = np.zeros((n_seg, coefs.shape[0]), dtype=np.complex128)
    seg = None if n_seg == 1 else np.minimum(np.arange(idx.size) * n_seg // max(1, idx.size), n_seg - 1)
    u = np.mod(idx * gens[0], 1.0)
    nu2 = float(gens[1]) if gens.size > 1 else 0.0
    for s, rows, ph in linefit._groups(coefs, nu2, idx):  # ph: |s|'s phasor, the conjugate of −|s|'s
        k = coefs[rows, 0]
        m_bins = linefit._grid(int(np.max(np.abs(k))))
        z = y if ph is None else y * (ph if s < 0 else np.conj(ph))
        out[:, rows] = _plain_fold(z, u, m_bins, seg, n_seg)[:, np.mod(k, m_bins)]
    return out if n_seg > 1 else out[0]


@pytest.mark.parametrize("n_seg", [1, 32])
def test_dtft_equals_the_plain_heterodyne(n_seg):
    rng = np.random.default_rng(8)
    y = rng.standard_normal(60_000)
    idx = np.arange(y.size)
    for gens, coefs in [
        (np.array([0.0123]), np.arange(1, 40)[:, None]),
        (np.array([0.031, 0.0047]), np.array([[k, s] for k in (1, 2, 30) for s in (-2, -1, 0, 1, 2)])),
    ]:
        np.testing.assert_array_equal(linefit.dtft(y, idx, gens, coefs, n_seg), _plain_dtft(y, idx, gens, coefs, n_seg))


def test_no_models_fit_to_nothing(curve):
    # a step whose searches are all on fixed grids has no bounded search to start: fitting an empty list of
    # models gives an empty answer (it had raised IndexError from the stacked designs: test_fuzz's short record)
    assert curvefit.chi2s_of(curve, START, []).shape == (0,)
    grid = np.geomspace(0.5, 50, 8)
    got = curvefit.searches(curve, START, [], [("gauss_markov", grid, False)])
    want = int(np.argmin(curvefit.chi2s(curve, START, [], "gauss_markov", grid, 6)))
    assert len(got) == 1 and float(got[0][0]) == float(grid[want]), got


def _plain_held(a, nu_cols, y, nu, max_iter, floor, held):
    """The IRLS of one design with ``held`` columns, as it was before the batch (one design at a time)."""
    fixed = np.zeros(a.shape[1])
    for i, (th, _var) in held.items():
        fixed[i] = th
    free = np.ones(a.shape[1], dtype=bool)
    free[list(held)] = False
    y_free = y - a @ fixed
    theta, model = fixed.copy(), y.copy()
    for it in range(max_iter):
        sw = np.sqrt(nu / (2.0 * np.maximum(model, floor) ** 2))
        aw = a[:, free] * sw[:, None]
        scale = np.linalg.norm(aw, axis=0)
        scale[scale == 0] = 1.0
        new = fixed.copy()
        new[free] = scipy_nnls(aw / scale, y_free * sw, maxiter=50 * int(free.sum()))[0] / scale
        parts = a * new
        tot = parts.sum(axis=1)
        done = bool(np.all(np.abs(new - theta) <= 1e-6 * np.abs(theta)))
        model = np.maximum(tot, floor) if it == 0 else np.sqrt(model * np.maximum(tot, floor))
        theta = new
        if new.any():
            den = np.sum(parts**2 / nu_cols, axis=1)
            nu = np.where(den > 0, tot**2 / np.maximum(den, 1e-300), nu)
        if done:
            break
    return theta, nu


@pytest.mark.parametrize("max_iter", [6, 40])
def test_held_fits_together_equal_one_at_a_time(curve, max_iter):
    # a line measured in the time domain held at its power (one or two of them) while a grid is searched: the
    # designs reweighted together give each design's own numbers, bit for bit
    line = float(np.median(curve.avar)) * 0.3
    for held in (
        [(curvefit.held_key("sinusoid", line, 0.01 * line**2), 7.0)],
        [(curvefit.held_key("sinusoid", line, 1e-4), 7.0), (curvefit.held_key("sinusoid", 0.1 * line, 1e-6), 0.9)],
    ):
        grid = np.geomspace(0.5, 200.0, 9)
        models = [held + [("gauss_markov", float(p))] for p in grid]
        a, nu_cols = curvefit._stacked(curve, START, models)
        hold = curvefit._held(START, models[0])
        nu0, floor = nu_cols[0][:, 1], 1e-12 * np.max(curve.avar)
        theta, nu = _irls.irls(a, nu_cols, curve.avar, nu0, max_iter, floor, held=hold)
        for g in range(len(models)):
            want = _plain_held(a[g], nu_cols[g], curve.avar, nu0, max_iter, floor, hold)
            np.testing.assert_array_equal(theta[g], want[0])
            np.testing.assert_array_equal(nu[g], want[1])
        # the held columns stay at their power, the grid's fits differ from one another
        assert all(theta[:, i].tolist() == [v[0]] * len(models) for i, v in hold.items())
        assert np.unique(theta[:, -1]).size > 3
        chi2 = curvefit.chi2s(curve, START, held, "gauss_markov", grid, max_iter=max_iter)
        np.testing.assert_array_equal(chi2, [_irls.chi2_at(curve.avar, a[g], theta[g], nu[g], floor) for g in range(9)])


def _plain_sz(t, F, alpha, d):
    """Greenhall & Riley's sz (eqs. 7–9) as it was: one sw per shift, each shift's sx on its own."""
    from allanite.estimators.edf import _sw

    def sx(t):
        if math.isinf(F):
            return _sw(t, alpha + 2)
        return F * F * (2.0 * _sw(t, alpha) - _sw(t - 1.0 / F, alpha) - _sw(t + 1.0 / F, alpha))

    t = np.asarray(t, dtype=np.float64)
    out = np.zeros_like(t)
    for k in range(-d, d + 1):
        out = out + (-1) ** k * math.comb(2 * d, d + k) * sx(t + k)
    return out


def test_greenhall_sums_in_one_call_equal_shift_by_shift(monkeypatch):
    # the EDF every fit of refine asks for (first time per α, m, N): sw of every shift and every lag at once
    from allanite.estimators import edf

    def plain_basic_sum(J, M, S, F, alpha, d):
        j = np.arange(1, int(J), dtype=np.float64)
        total = float(_plain_sz(0.0, F, alpha, d)) ** 2
        total += (1.0 - J / M) * float(_plain_sz(J / S, F, alpha, d)) ** 2
        return total + 2.0 * float(np.sum((1.0 - j / M) * _plain_sz(j / S, F, alpha, d) ** 2))

    cases = [
        (a, d, m, n, ov, mod)
        for d in (1, 2, 3)
        for a in range(2, -5, -1)
        if a + 2 * d > 1
        for m in (1, 2, 7, 33, 34, 500)
        for n in (2001, 1_000_001)
        for ov, mod in ((True, False), (False, False), (True, True))
    ]
    new = [edf._edf_greenhall_one.__wrapped__(*c) for c in cases]
    for args in [(0.0, 1, 0, 2), (np.arange(5) / 3.0, 7, -1, 2), (np.arange(9) / 2.0, math.inf, -2, 3)]:
        np.testing.assert_array_equal(edf._sz(*args), _plain_sz(*args))
    monkeypatch.setattr(edf, "_sz", _plain_sz)
    monkeypatch.setattr(edf, "_basic_sum", plain_basic_sum)
    plain = [edf._edf_greenhall_one.__wrapped__(*c) for c in cases]
    # one np.sum over every shift against a sum per shift: the same terms, NumPy's summation order aside
    np.testing.assert_allclose(new, plain, rtol=1e-12, atol=0)
    assert len(set(new)) > len(cases) // 2


@pytest.mark.parametrize("n", [10, 64, 65, 1_000, 200_000])
def test_running_median_at_flags_equals_the_filter(n):
    from scipy.ndimage import median_filter

    from allanite.model import outliers

    rng = np.random.default_rng(n)
    y = np.round(rng.standard_normal(n).cumsum(), 1)  # ties too
    full = median_filter(y, size=outliers.LEVEL_SPAN, mode="nearest")
    for k in (1, 2, max(1, n // 50), n // 3):
        idx = np.sort(rng.choice(n, size=k, replace=False))
        idx[0] = 0  # the record's ends, where the window runs past them
        idx[-1] = n - 1 if k > 1 else idx[-1]
        idx = np.unique(idx)
        np.testing.assert_array_equal(outliers._running_median_at(y, idx, outliers.LEVEL_SPAN), full[idx])
