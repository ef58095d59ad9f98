"""allanite.compat.realtime: streaming OADEV, OHDEV and TDEV/MDEV on the core, equal to the batch
estimators after every point, for fixed and automatic averaging factors, and to allantools' classes
where those are exact."""

from __future__ import annotations

import numpy as np
import pytest

from allanite import _core, compat
from allanite.errors import InputError, ParameterError

CLASSES = {
    "oadev": compat.realtime.oadev_realtime,
    "ohdev": compat.realtime.ohdev_realtime,
    "tdev": compat.realtime.tdev_realtime,
}
#: points a factor needs before its first term: 2m + 1 (OADEV), 3m + 1 (OHDEV), 3m (TDEV)
FIRST = {"oadev": lambda m: 2 * m + 1, "ohdev": lambda m: 3 * m + 1, "tdev": lambda m: 3 * m}


@pytest.fixture
def phase():
    rng = np.random.default_rng(7)
    # a clock's phase: random-walk FM on a frequency offset, seconds
    return 1e-6 * np.cumsum(3.0 + np.cumsum(rng.standard_normal(400)) * 0.01 + rng.standard_normal(400))


def _batch(name: str, x: np.ndarray, afs, tau0: float) -> dict:
    """{af: batch deviation} for the factors the batch estimator keeps (ns > 1)."""
    taus, devs, _, _ = getattr(compat, name)(x, rate=1.0 / tau0, taus=np.asarray(afs, dtype=float) * tau0)
    return dict(zip(np.round(taus / tau0).astype(int).tolist(), devs))


@pytest.mark.parametrize("name", CLASSES)
def test_every_prefix_equals_the_batch_estimator(name, phase):
    afs, tau0 = [1, 2, 5, 13], 0.25
    rt = CLASSES[name](afs=afs, tau0=tau0)
    for p, x in enumerate(phase, start=1):
        rt.add_phase(x)
        if p % 37 and p != phase.size:
            continue
        want = _batch(name, phase[:p], afs, tau0) if p > 3 else {}
        for af, got in zip(afs, rt.dev):
            if af in want:
                assert got == pytest.approx(want[af], rel=1e-11), (name, p, af)
            elif p < FIRST[name](af):
                assert got == 0.0
    assert rt.taus().tolist() == [tau0 * a for a in afs]
    assert rt.x == phase.tolist()
    if name == "tdev":
        _, md, _, _ = compat.mdev(phase, rate=1.0 / tau0, taus=np.array(afs) * tau0)
        np.testing.assert_allclose(rt.mdev(), md, rtol=1e-11)


@pytest.mark.parametrize("name", CLASSES)
def test_automatic_factors_are_exact_from_their_start(name, phase):
    rt = CLASSES[name](tau0=2.0, auto_afs=True)
    rt.add_phases(phase[:150])
    for x in phase[150:]:
        rt.add_phase(x)
    # allantools' schedule: 1, 2, 3, 6, 10, 18, 32, 56, 100, 178 …, each once the stream holds 2m + 1 points
    assert rt.afs.tolist() == [1, 2, 3, 6, 10, 18, 32, 56, 100, 178]
    want = _batch(name, phase, rt.afs, 2.0)
    for af, got in zip(rt.afs, rt.devs()):
        if af in want:
            assert got == pytest.approx(want[af], rel=1e-11), (name, af)
    assert len(want) >= 7


@pytest.mark.parametrize("name", CLASSES)
def test_frequency_points_and_batches(name, phase):
    y = np.diff(phase) * 1e6  # frequency points: the phase steps by each (tau0 = 1)
    rt = CLASSES[name](afs=[1, 3, 8])
    for f in y:
        rt.add_frequency(f)
    want = getattr(compat, name)(y, data_type="freq", taus=[1, 3, 8])[1]
    np.testing.assert_allclose(rt.dev, want, rtol=1e-10)  # deviations ignore the offset batch removes
    one, many = CLASSES[name](afs=[2, 7]), CLASSES[name](afs=[2, 7])
    for x in phase:
        one.add_phase(x)
    many.add_phases(phase[:100])
    many.add_phases(phase[100:])
    np.testing.assert_array_equal(one.dev, many.dev)


@pytest.mark.parametrize("name", CLASSES)
def test_equal_to_allantools_with_fixed_factors(name, phase):
    allantools = pytest.importorskip("allantools")
    theirs = getattr(allantools.realtime, f"{name}_realtime")(afs=[1, 4, 9], tau0=0.5)
    ours = CLASSES[name](afs=[1, 4, 9], tau0=0.5)
    for x in phase:
        theirs.add_phase(x)
        ours.add_phase(x)
    np.testing.assert_allclose(ours.dev, theirs.dev, rtol=1e-10)
    np.testing.assert_allclose(ours.taus(), theirs.taus())
    if name == "tdev":
        np.testing.assert_allclose(ours.mdev(), theirs.mdev(), rtol=1e-10)


def test_bad_input_is_named(phase):
    rt = compat.realtime.oadev_realtime(afs=[1])
    rt.add_phases(phase[:5])
    with pytest.raises(InputError, match=r"non-finite value \(NaN\) at sample 7"):
        rt.add_phases(np.array([1.0, 2.0, np.nan, 3.0]))
    assert len(rt.x) == 7  # the points before it are kept
    with pytest.raises(InputError, match=r"\(inf\) at sample 7"):
        rt.add_phase(np.inf)
    with pytest.raises(ParameterError, match="af must be an integer ≥ 1"):
        compat.realtime.tdev_realtime(afs=[2, 0])
    with pytest.raises(ParameterError, match="tau0 must be a positive finite number, got 0"):
        compat.realtime.ohdev_realtime(tau0=0)
    with pytest.raises(ParameterError, match='unknown streaming variance "avar"; allowed'):
        _core.StreamingVariance("avar", [1], [])
