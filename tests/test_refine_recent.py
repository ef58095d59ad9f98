"""Results remembered by their arrays' content within a refine (issue 29, refine's cost): each found again only
for equal samples and the same key, and equal to a fresh computation — the memory itself
(:class:`allanite.model._recent.Recent`), a line family's phasors and refits, the outlier test's quantisation step and local
noise scales and flags per cut, the bandwidth check's Welch spectrum. (A whole refine with every memory off:
``test_refine_cost.py``.)"""

from __future__ import annotations

import numpy as np
import pytest

from allanite.model import _chunked, linefit, outliers, periodic, tracing
from allanite.model._recent import Recent, remembering


@pytest.fixture(autouse=True)
def _remembering():
    with remembering():  # as within a refine call
        yield


def test_remembered_phasors_equal_fresh_ones(monkeypatch):
    def fresh(nu, idx):  # the same block × offset products, one index at a time
        b = linefit._BLOCK
        return np.array(
            [np.exp(2j * np.pi * ((n // b * b * nu) % 1.0)) * np.exp(2j * np.pi * ((n % b * nu) % 1.0)) for n in idx]
        )

    idx = np.arange(3, 40_000, 2)
    first = linefit._phasor(0.0123, idx)
    again = linefit._phasor(0.0123, idx.copy())  # equal indices in another array: remembered
    assert again is first and not again.flags.writeable
    np.testing.assert_allclose(again, fresh(0.0123, idx), rtol=0, atol=1e-14)
    other = linefit._phasor(0.0123, idx + 1)  # other indices, other spacing: computed
    np.testing.assert_allclose(other, fresh(0.0123, idx + 1), rtol=0, atol=1e-14)
    np.testing.assert_allclose(linefit._phasor(0.0124, idx), fresh(0.0124, idx), rtol=0, atol=1e-14)
    for k in range(6):
        linefit._phasor(0.001 * (k + 1), idx)
    assert len(linefit._PHASORS._items) == linefit._PHASORS.keep
    monkeypatch.setattr(linefit._PHASORS, "max_size", 100)  # a long record's phasors are not kept
    linefit._phasor(0.5, idx)
    assert linefit._PHASORS.get(idx, (0.5,)) is None


def test_recent_finds_equal_arrays_only():
    memo = Recent(2, 1000)
    a = np.arange(10.0)
    memo.put(a, ("k",), "first")
    assert memo.get(a.copy(), ("k",)) == "first"
    assert memo.get(a, ("other",)) is None
    assert memo.get(a.astype(np.float32), ("k",)) is None  # another dtype
    assert memo.get(a.reshape(2, 5), ("k",)) is None  # another shape
    b = a.copy()
    b[3] = 0.5
    assert memo.get(b, ("k",)) is None  # another element
    a[0] = 7.0  # the memory keeps a copy: changing the array afterwards does not change what it finds
    assert memo.get(np.arange(10.0), ("k",)) == "first" and memo.get(a, ("k",)) is None
    memo.put(b, (), 1)
    memo.put(a, (), 2)
    assert memo.get(np.arange(10.0), ("k",)) is None and len(memo._items) == 2  # the oldest out
    memo.put(np.zeros(1001), (), 3)  # too long to keep
    assert memo.get(np.zeros(1001)) is None


def test_remembered_outlier_scales_equal_fresh_ones():
    rng = np.random.default_rng(4)
    y = np.round(rng.standard_normal(50_000) / 0.05) * 0.05
    y[::997] += 3.0
    step, loc = outliers.lattice_step(np.diff(y)), outliers._local(y, 0.05)
    assert step == outliers._lattice_step(np.diff(y)) and step > 0
    fresh = outliers._local_sigmas(y, 0.05)
    for k in ("sigma_e", "sigma_d"):
        np.testing.assert_array_equal(loc[k], fresh[k])
        assert not loc[k].flags.writeable
    assert outliers._local(y.copy(), 0.05) is loc  # the same samples: remembered
    assert outliers._local(y, 0.1) is not loc  # another step: computed


def test_nothing_remembered_outside_a_refine_call():
    memo = Recent(2, 1000)
    memo.put(np.arange(3.0), (), "kept")
    assert memo.get(np.arange(3.0)) == "kept"
    with remembering():  # a nested call leaves the outer one's memory alone
        pass
    assert memo.get(np.arange(3.0)) == "kept"


def test_memories_forget_when_the_call_returns():
    # (outside the autouse fixture's context: a plain function would see nothing remembered)
    import allanite.model._recent as recent

    memo = Recent(2, 1000)
    depth = len(recent._OPEN)
    for _ in range(depth):  # leave this test's own context for a moment
        recent._OPEN.pop()
    try:
        memo.put(np.arange(3.0), (), "kept")
        assert memo.get(np.arange(3.0)) is None and memo._items == []
        with remembering():
            memo.put(np.arange(3.0), (), "kept")
            assert memo.get(np.arange(3.0)) == "kept"
        assert memo._items == [] and memo.get(np.arange(3.0)) is None
    finally:
        recent._OPEN.extend([True] * depth)


def test_phasors_of_a_long_record_are_exact_to_rounding():
    # the block × offset products against e^{i2π frac(νn)} with frac(νn) taken exactly (ν as its binary fraction):
    # within the rounding of ν·B·⌊n/B⌋ (≈ 2e4 here, half an ulp 1.8e-12, × 2π); the former table was off by 1e-9
    import math
    from fractions import Fraction

    nu = 0.0101286
    idx = np.arange(2_000_000)
    got = linefit._phasor(nu, idx)
    for n in (0, 1, 1023, 1024, 777_777, 1_999_999):
        ph = float((Fraction(nu) * n) % 1)
        assert abs(got[n] - complex(math.cos(2 * math.pi * ph), math.sin(2 * math.pi * ph))) < 2e-11
    sparse = np.array([5, 4096, 1_234_567])
    np.testing.assert_array_equal(linefit._phasor(nu, sparse), got[sparse])


def test_remembered_rolloff_spectrum_equals_a_fresh_one():
    from scipy import signal

    y = np.random.default_rng(8).standard_normal(60_000).cumsum() * 1e-3 + 0.2
    r1, r2 = np.array([1.0, 0.5]), np.array([1.0, 0.25, 0.05])
    first = tracing.rolloff_psd(y, 50.0, r1)
    f, p = _chunked.welch_mean(y, 50.0, 4096, float(y.mean()))  # the spectrum computed afresh (chunked)
    hi, lo = (f >= 20.0) & (f <= 24.0), (f >= 1.0) & (f <= 5.0)
    assert first["measured"] == float(p[hi].mean() / p[lo].mean())
    f0, p0 = signal.welch(y - y.mean(), fs=50.0, nperseg=4096)  # scipy's, as it was computed before
    assert np.array_equal(f, f0) and np.allclose(p, p0, rtol=1e-12, atol=0)
    got = tracing._WELCH.get(y, (50.0, 4096))
    assert got is not None and not got[1].flags.writeable
    again = tracing.rolloff_psd(y.copy(), 50.0, r2)  # equal samples, another filter: the spectrum found again
    assert again["measured"] == first["measured"] and again["predicted"] != first["predicted"]
    assert tracing._WELCH.get(y, (50.0, 4096)) is got
    z = y.copy()
    z[100] += 1.0  # other samples: computed
    f2, p2 = _chunked.welch_mean(z, 50.0, 4096, float(z.mean()))
    assert tracing.rolloff_psd(z, 50.0, r1)["measured"] == float(p2[hi].mean() / p2[lo].mean())


def test_remembered_outlier_flags_equal_fresh_ones(monkeypatch):
    rng = np.random.default_rng(12)
    y = rng.standard_normal(40_000)
    y[rng.choice(y.size, 40, replace=False)] += rng.choice([-1, 1], 40) * rng.uniform(6, 12, 40)
    first = outliers.outlier_test(y, 100.0, 0.01)
    assert first["accepted"] and np.count_nonzero(first["flags"]) >= 30
    first["flags"][:] = False  # the caller's copy: the memory keeps its own
    per_cut = outliers._FLAGGED.get(y)
    assert per_cut is not None and first["cut"] in per_cut
    again = outliers.outlier_test(y.copy(), 100.0, 0.001)  # another level, the same samples: found again
    flags_at, lam_at = outliers.flag_at(y, again["cut"])
    monkeypatch.setattr(Recent, "get", lambda self, arr, key=(): None)  # everything afresh
    fresh = outliers.outlier_test(y, 100.0, 0.001)
    assert again["cut"] == fresh["cut"] and again["expected_gaussian_flags"] == fresh["expected_gaussian_flags"]
    np.testing.assert_array_equal(again["flags"], fresh["flags"])
    np.testing.assert_array_equal(flags_at, fresh["flags"])
    assert lam_at == fresh["expected_gaussian_flags"] and again["cuts"] == fresh["cuts"]


def test_remembered_family_refits_equal_fresh_ones(monkeypatch):
    n, fs = 80_000, 100.0
    t = np.arange(n)
    y = np.random.default_rng(5).standard_normal(n) + 0.8 * np.sin(2 * np.pi * 0.0731 * t + 0.3)
    y += 0.3 * np.cos(2 * np.pi * 2 * 0.0731 * t)
    fam = periodic.LineFamily(
        fs=fs,
        gens=np.array([7.31]),
        gens_cov=np.eye(1),
        coefs=np.array([[1], [2]]),
        a=np.zeros(2),
        b=np.zeros(2),
        noise=np.ones(2),
        found=np.ones(2, dtype=bool),
        n=n,
    )
    half = np.concatenate([np.arange(j * 10_000, (j + 1) * 10_000) for j in range(0, 8, 2)])
    other = np.setdiff1d(t, half)
    first = fam.refit(y[half], half)(other)
    a, b = linefit.solve(y[half], half, fam.gens / fs, fam.coefs)  # afresh
    np.testing.assert_array_equal(first, linefit.evaluate(other, fam.gens / fs, fam.coefs, a, b))
    calls = []
    monkeypatch.setattr(linefit, "solve", lambda *args: calls.append(1) or (a, b))
    np.testing.assert_array_equal(fam.refit(y[half].copy(), half.copy())(other), first)  # found again
    assert calls == []
    fam.refit(y[half], half + 1)  # other indices: solved
    fam.refit(y[half] + 1e-9, half)  # other samples: solved
    assert len(calls) == 2


def test_memories_keep_one_copy_of_the_same_samples():
    # the outlier test's scales and flags, a family's phasors at each frequency, the held-out curves and the line
    # refits are asked for on the same samples: one read-only copy between the memories, found by content
    first, second = Recent(2, 1000), Recent(2, 1000)
    a = np.linspace(0.0, 1.0, 500)
    first.put(a, ("x",), 1)
    first.put(a.copy(), ("y",), 2)
    second.put(a.copy(), (), 3)
    kept = [item[1] for item in first._items + second._items]
    assert kept[0] is kept[1] is kept[2] and kept[0] is not a
    assert not kept[0].flags.writeable and np.array_equal(kept[0], a)
    a[7] = -1.0  # the caller's array changed afterwards: the kept copy did not
    assert first.get(np.linspace(0.0, 1.0, 500), ("y",)) == 2 and first.get(a, ("y",)) is None
    b = np.linspace(0.0, 1.0, 500)
    b[250] += 1e-9  # between the fingerprint's samples: equal fingerprints, another content
    second.put(b, ("b",), 4)
    assert second._items[-1][1] is not kept[0] and np.array_equal(second._items[-1][1], b)
    assert second.get(b, ("b",)) == 4 and second.get(np.linspace(0.0, 1.0, 500)) == 3
    strided = np.arange(40.0)[::2]  # a view: kept as its elements
    first.put(strided, (), 5)
    assert first.get(np.arange(0.0, 40.0, 2.0)) == 5 and first._items[-1][1].flags.c_contiguous
    assert second._items[0][1] is kept[0]  # still kept by the second memory after the first let it go


def test_remembered_noise_fits_and_bartlett_factors_equal_fresh_ones(monkeypatch):
    """The Whittle noise fit and the coupling bootstrap's Bartlett factors, found again by their inputs' bytes within
    a refine (a cold-started joint fit refits the record's own power; unexplained's channel check bootstraps the
    candidate step's null again): equal to the bit to a fresh computation, read-only."""
    import allanite
    from allanite.model import _coupling
    from allanite.model import _whittle as wh
    from allanite.model._recent import Small

    monkeypatch.setattr(_coupling, "BOOT_DRAWS", 20)  # a small bootstrap: the memory, not the calibration, is tested
    rng = np.random.default_rng(5)
    n = 6000
    temp = np.cumsum(rng.standard_normal(n)) * 0.01
    y = allanite.simulate(n, 10.0, N=1e-3, B=2e-4, K=1e-5, seed=rng)
    bands = wh.spectra(y, [temp - temp.mean()], 10.0)
    power, m = bands.q[bands.par] / bands.m[bands.par], bands.m[bands.par]
    first = wh.fit_noise(power, m, bands.basis)
    again = wh.fit_noise(power.copy(), m.copy(), bands.basis.copy())  # equal inputs in other arrays
    assert again is first and not first[0].flags.writeable and not first[1].flags.writeable
    fresh = wh._fit_noise(power, m, bands.basis, None)
    assert [a.tobytes() for a in first] == [a.tobytes() for a in fresh]
    warm = wh.fit_noise(power, m, bands.basis, first[0])  # another start: another fit
    assert warm is not first
    null = wh.joint_fit(bands, wh.Design([], []))
    inside = _coupling.bootstrap_scale(bands, null)
    assert _coupling.bootstrap_scale(bands, null) is inside
    assert _coupling._bootstrap_scale(bands, null, 0) == inside
    assert _coupling.bootstrap_scale(bands, null, seed=1) != inside  # another seed: other draws
    small = Small(2)
    for k in range(3):
        small.put(Small.key(np.arange(3.0) + k, k), k)
    assert small.get(Small.key(np.arange(3.0), 0)) is None  # the oldest out
    assert small.get(Small.key(np.arange(3.0) + 2, 2)) == 2
    assert small.get(Small.key(np.arange(3, dtype=np.int64) + 2, 2)) is None  # another dtype: another key


@pytest.mark.parametrize(
    "terms", [(1.0, 0.3, 0.02, 0.0), (0.0, 0.5, 0.0, 1e-4), (2.0, 0.0, 0.1, 0.0), (0.7, 0.2, 0.05, 3e-5)]
)
def test_null_records_equal_simulate_and_share_their_flicker(terms, _flicker_unshared):
    """The checks' null records (``model/_null_records.py``): allanite.simulate's numbers — to ~1e-15 of the record's
    largest value, as its flicker is the same convolution over another FFT length (the next fast one ≥ 2n − 1, not
    2n: ``_unit_flicker``), and to the bit where it has no flicker — for an int seed and a generator, the flicker
    found again for the same length and generator state (the generator left where
    the draws leave it), kept from one call to the next only within ``sharing``."""
    import allanite
    from allanite.model import _null_records as nr
    from allanite.model import _recent

    n, fs = 16383, 0.37  # 2n = 2·3·43·127 (the checks' 262 128 = 16·16383): another FFT length than simulate's
    kw = dict(zip("NBKR", terms))
    for seed in (7919, [7919, 3]):
        ref = allanite.simulate(n, fs, **kw, seed=np.random.default_rng(seed))
        for _ in range(2):  # drawn, then found again
            with nr.sharing():
                rng = np.random.default_rng(seed)
                got = nr.block_rate_record(n, fs, **kw, seed=rng)
                assert len(nr._FLICKER._items) == (1 if terms[1] else 0)
            if terms[1]:
                assert np.max(np.abs(got - ref)) <= 1e-12 * np.max(np.abs(ref))
            else:
                assert got.tobytes() == ref.tobytes()
            after = np.random.default_rng(seed)
            allanite.simulate(n, fs, **kw, seed=after)
            assert rng.bit_generator.state == after.bit_generator.state  # the next draws are simulate's
    nr.block_rate_record(n, fs, **kw, seed=5)
    assert nr._FLICKER._items == {}  # one call draws no record twice: outside ``sharing`` nothing is kept
    depth = len(_recent._OPEN)
    for _ in range(depth):  # leave the fixture's call: a plain call's memory is emptied when it returns
        _recent._OPEN.pop()
    nr._FLICKER._items.clear()  # (what this test drew within the fixture's call)
    try:
        with nr.sharing():
            with _recent.remembering():
                nr.block_rate_record(n, fs, **kw, seed=1)
            kept = len(nr._FLICKER._items)
            assert kept == (1 if terms[1] else 0)  # between two calls of a report
            with _recent.remembering():
                got, ref = nr.block_rate_record(n, fs, **kw, seed=1), allanite.simulate(n, fs, **kw, seed=1)
                assert np.max(np.abs(got - ref)) <= 1e-12 * np.max(np.abs(ref))
            assert len(nr._FLICKER._items) == kept
        assert nr._FLICKER._items == {}  # the report's scope left: forgotten
        with _recent.remembering():
            nr.block_rate_record(n, fs, **kw, seed=2)
        assert nr._FLICKER._items == {}  # a call outside any sharing: forgotten when it returns
    finally:
        for _ in range(depth):
            _recent._OPEN.append(True)
    with pytest.raises(ValueError, match="finite"):
        nr.block_rate_record(n, fs, N=float("nan"), B=0.0, K=0.0, R=0.0, seed=0)


@pytest.fixture
def _flicker_unshared():
    """The null records' flicker memory as a plain refine call finds it — held by no sharing and empty — for the
    test of what it keeps: the suite's session-long sharing (conftest's ``_null_records_shared``) set aside and
    given back after."""
    from allanite.model import _null_records as nr

    held, items = nr._FLICKER._held, dict(nr._FLICKER._items)
    nr._FLICKER._held = 0
    nr._FLICKER._items.clear()
    try:
        yield
    finally:
        nr._FLICKER._items.clear()
        nr._FLICKER._items.update(items)
        nr._FLICKER._held = held


def _curve_run():
    """A refinement under way on a short simulated record (its curve and held-out split built, no step taken)."""
    import allanite
    from allanite.model.refinement import loop
    from allanite.model.refinement._inputs import inputs

    x = allanite.simulate(40_000, 100.0, N=2e-3, K=2e-5, gauss_markov=[(4e-3, 2.0)], seed=5)
    y, result, _ch, _f = inputs(x, 100.0, "rate", 300, None, None, "error")
    run = loop._Run(y, result, ("Q", "N", "B", "K", "R"), None, 0.05, None, None)
    return run, tracing.thin_indices(run.curve.tau)


def test_remembered_step_test_equals_a_fresh_one():
    # loop._Run.step_test: the curve test and its bootstrap threshold, remembered under the model, the candidates
    # and the seed (a chain run again without an option asks from the same states)
    from allanite.model.refinement.calibrated import N_BOOT, curve_test
    from allanite.model.refinement.candidates import families
    from allanite.model.refinement.curvefit import solve
    from allanite.model.refinement.levels import alpha

    run, thin = _curve_run()
    cands = ("gauss_markov", "bandwidth", "resonance", "sinusoid")

    def fresh(n_step):
        test = curve_test(run.curve, thin, run.sol, run.start, run.effects, True)
        fam = families(run.curve.subset(thin), cands, True)
        return test, test.threshold(fam, alpha("curve", run.level), N_BOOT, seed=n_step)

    test, thr = run.step_test(0, cands, thin, True)
    assert run.step_test(0, cands, thin, True) == (test, thr)  # found again: the same objects
    f_test, f_thr = fresh(0)
    assert thr == f_thr and np.isfinite(thr)
    np.testing.assert_array_equal(test.model, f_test.model)
    assert run.step_test(1, cands, thin, True)[1] == fresh(1)[1]  # another seed: another draw
    run.effects = [("gauss_markov", 2.0)]  # another model: computed for it, not the one before
    run.sol = solve(run.curve, run.start, run.effects)
    got = run.step_test(0, cands, thin, True)
    assert got[0] is not test and got[1] == fresh(0)[1] != thr
