"""One default refine's Python-side memory on a long clean record: no check may make record-size copies by the
handful again (benches/results/refine_cost.md, "The final checks chunked")."""

from __future__ import annotations

import tracemalloc

import numpy as np

import allanite


def test_refine_traced_peak_stays_a_few_records():
    # 8·10⁶ samples (64 MB): the traced peak (NumPy's arrays; the compiled core's working arrays are not traced)
    # was 14.7× a 4·10⁶ record at 478e6dd — the lattice step's ≈ 5 copies, whole-record Welch passes, the held-out
    # parts twice with their indices — and 5.6× with them chunked or made when asked. Since the "steps" check
    # (r6steps) the peak holds a cost that does not grow with the record: its null's 2²² half-block means are
    # simulated at the block rate whatever the record's length (≈ 240 MB at their peak, inside the simulation),
    # 7–11× a 4·10⁶ record from run to run but 5.8× of 8·10⁶ (peak 4·10⁶ → 8·10⁶: +0.35 of the added samples'
    # bytes). At 8·10⁶ the bound still fails on a handful of record-size copies, which is what it is for.
    y = np.asarray(allanite.simulate(8_000_000, 100.0, seed=3, N=0.01, B=0.002, K=1e-4))
    tracemalloc.start(1)
    try:
        r = allanite.refine(y, 100.0, progress=False)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert r.steps == []  # a clean record: the checks ran to the end and found nothing
    assert peak < 8 * y.nbytes, f"traced peak {peak / y.nbytes:.1f}× the record"
