"""A sinc^k (CIC) kind named at the bandwidth step is weighed on the whole chain against the kinds without it
(:func:`allanite.model.refinement._rolloff.sinc_chain_kept`): ADIS16405 run 6 acc_z's sinc³ at one step stood in
for its 10 Hz resonance and left its 0.46 Hz line, ending at χ²/dof 2.22 where the boxcar's chain ends at 1.09."""

from __future__ import annotations

import contextlib
import math

import numpy as np
import pytest
from scipy import signal

import allanite
from allanite.model.refinement import loop
from allanite.model.refinement._rolloff import sinc_chain_kept, sinc_choice, sinc_named, without_sincs
from allanite.model.refinement.result import Step

FS = 200.0


class _Sol:
    def __init__(self, chi2):
        self.chi2 = chi2


def test_sinc_chain_kept_unless_the_other_chain_ends_better():
    tie = 10.0
    # run 6 acc_z: the sinc³ chain ends at χ² 2.22·231, the boxcar's (a line and a resonance more) at 1.09·231
    assert not sinc_chain_kept(_Sol(2.22 * 231), _Sol(1.09 * 231), tie)
    # run 1 acc_z: the sinc³ chain ends better (2.36 against 2.52): it stays
    assert sinc_chain_kept(_Sol(2.36 * 231), _Sol(2.52 * 231), tie)
    # a tie (a CIC read at its output rate against a boxcar of two samples): the kind named at the step stays
    assert sinc_chain_kept(_Sol(190.3), _Sol(190.4 - 9.9), tie)
    assert not sinc_chain_kept(_Sol(190.3), _Sol(190.3 - 10.1), tie)


def test_without_sincs_drops_every_order_and_nests():
    def f(kind, p, chi2):
        return (f"bandwidth:{kind}", p, _Sol(chi2), False)

    found = [f("boxcar", 1.66, 156.0), f("sinc3", 1.0, 83.5), f("single_pole", 30.0, 170.0)]
    assert [x[0] for x in sinc_choice(found, 10.0)][-1] == "bandwidth:sinc3"
    with without_sincs():
        with without_sincs():
            pass
        assert [x[0] for x in sinc_choice(found, 10.0)] == ["bandwidth:boxcar", "bandwidth:single_pole"]
    assert sinc_named([("sinusoid:held:1:0", 0.5), ("bandwidth:sinc3|floor", 1.0)])
    assert not sinc_named([("bandwidth:boxcar", 1.2), ("resonance:16", 10.0)])


def _cic3(seed: int, n: int = 150_000) -> np.ndarray:
    """A sinc³ CIC 3200 → 200 Hz on white noise, plus rate random walk."""
    dec = 16
    rng = np.random.default_rng(seed)
    h = np.ones(dec) / dec
    h = np.convolve(np.convolve(h, h), h)
    w = rng.standard_normal(n * dec + h.size) * 4e-3 * math.sqrt(FS * dec)
    return signal.oaconvolve(w, h, mode="valid")[::dec][:n] + allanite.simulate(n, FS, K=2e-5, seed=rng)


@pytest.mark.parametrize("kept", [True, False])
def test_refine_carries_both_chains_where_a_sinc_is_named(monkeypatch, kept):
    # the rule forced either way: the chain kept is the whole chain (its steps, effects and fit), the other's
    # final χ²/dof in the bandwidth step's evidence
    monkeypatch.setattr(loop, "sinc_chain_kept", lambda with_sinc, without, tie: kept)
    r = allanite.refine(_cic3(7), FS, progress=False)
    bw = [st for st in r.steps if st.effect == "bandwidth"]
    assert len(bw) == 1 and r.found.count("bandwidth") == 1
    chains = bw[0].evidence["kind_chains"]
    assert set(chains) == {"with_sinc", "without_sinc"}
    assert chains["with_sinc"]["effects"] == ["bandwidth"] and "bandwidth" in chains["without_sinc"]["effects"]
    named = bw[0].params["filter"]
    assert named.startswith("sinc") == kept
    mine = chains["with_sinc" if kept else "without_sinc"]
    assert mine["chi2_dof"] == pytest.approx(r.fit.chi2_dof, rel=1e-9)
    assert [base for base in mine["effects"]] == [st.effect for st in r.steps if st.effect != "change_point"]
    if kept:  # a sinc³ CIC: its chain ends better than the kinds without it
        assert chains["with_sinc"]["chi2_dof"] < chains["without_sinc"]["chi2_dof"]


class _Fit:
    def __init__(self, chi2_dof):
        self.chi2_dof = chi2_dof


class _Curve:
    tau = np.ones(20)
    n_eff = 4.0


def _nested_run(monkeypatch, kept_inner: bool, kept_outer: bool):
    """A curve loop stubbed as one step per call, named by which options are withdrawn, under two options that
    every first chain takes (:data:`loop.ALTERNATIVES`' mechanism: sinc^k inside the resonance shape)."""
    inner_on, outer_on = [True], [True]

    def withdraw(flag):
        @contextlib.contextmanager
        def off():
            flag.append(False)
            try:
                yield
            finally:
                flag.pop()

        return off

    def loop_stub(self, *args):
        key = f"bandwidth:{'sinc3' if inner_on[-1] else 'boxcar'}" if outer_on[-1] else "resonance:4"
        self.steps.append(Step(effect=key.split(":")[0], params={}, intervals={}, evidence={}, before={}, after={}))
        self.lines.append(None)
        self.consider(key, {"param": 1.0})
        self.effects = self.effects + [(key, 1.0)]
        self.sol = _Fit(1.0 + len(self.considered) + 0.5 * inner_on[-1])

    alts = (
        loop.Alternative(
            lambda eff: any(k == "bandwidth:sinc3" for k, _p in eff),
            withdraw(inner_on),
            lambda a, b, tie: kept_inner,
            "kind_chains",
            "bandwidth",
            ("with_sinc", "without_sinc"),
        ),
        loop.Alternative(
            lambda eff: any(k.startswith("bandwidth") for k, _p in eff),
            withdraw(outer_on),
            lambda a, b, tie: kept_outer,
            "shape_chains",
            "bandwidth",
            ("with_bandpass", "lorentzian_only"),
        ),
    )
    monkeypatch.setattr(loop._Run, "curve_loop", loop_stub)
    run = object.__new__(loop._Run)
    run.curve, run.effects, run.steps, run.lines, run.sol, run.considered = _Curve(), [], [], [], _Fit(9.0), {}
    run.curve_chains(run.fork(), alts, ())
    return run


@pytest.mark.parametrize("kept_inner", [True, False])
@pytest.mark.parametrize("kept_outer", [True, False])
def test_every_chain_runs_from_the_fork_as_it_was(monkeypatch, kept_inner, kept_outer):
    # both options taken in the first chain: the inner one is decided (two chains), then the outer one runs again
    # from the same fork — it must start empty, not with the steps the inner rerun appended to the fork
    run = _nested_run(monkeypatch, kept_inner, kept_outer)
    want = ("bandwidth:sinc3" if kept_inner else "bandwidth:boxcar") if kept_outer else "resonance:4"
    assert [k for k, _p in run.effects] == [want]
    assert len(run.steps) == len(run.lines) == 1
    assert list(run.considered) == [want]
    if kept_outer:  # the kept bandwidth step carries both decisions, each between its own two chains
        ev = run.steps[0].evidence
        assert list(ev["kind_chains"]) == ["with_sinc", "without_sinc"]
        assert ev["kind_chains"]["with_sinc"]["effects"] == ["bandwidth"]
        assert ev["shape_chains"]["lorentzian_only"]["effects"] == ["resonance"]
