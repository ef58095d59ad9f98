"""A sinc^k (CIC) kind named at the bandwidth step is weighed on the whole chain against the kinds without it
(:func:`allanite.model.refinement._rolloff.sinc_chain_kept`): ADIS16405 run 6 acc_z's sinc³ at one step stood in
for its 10 Hz resonance and left its 0.46 Hz line, ending at χ²/dof 2.22 where the boxcar's chain ends at 1.09."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import signal

import allanite
from allanite.model.refinement import loop
from allanite.model.refinement._rolloff import sinc_chain_kept, sinc_choice, sinc_named, without_sincs

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
