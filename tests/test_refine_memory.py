"""One default refine's Python-side memory on a long clean record: no check may make record-size copies by the
handful again (benches/results/refine_cost.md, "The final checks chunked")."""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest

import allanite


@pytest.mark.slow  # an 8e6-sample refine; chunked nulls: the tests below
def test_refine_traced_peak_stays_a_few_records():
    # 8·10⁶ samples (64 MB): the traced peak (NumPy's arrays; the compiled core's working arrays are not traced)
    # was 14.7× a 4·10⁶ record at 478e6dd — the lattice step's ≈ 5 copies, whole-record Welch passes, the held-out
    # parts twice with their indices — and 5.6× with them chunked or made when asked. The "steps" check (r6steps)
    # added a cost that did not grow with the record: its null's 2²² half-block means simulated at once (≈ 240 MB
    # at their peak), 5.8× of 8·10⁶. Drawn a chunk at a time (r7mem) the peak is 4.57× (by stage: the outliers
    # check's transient, 2.5× the record, over ≈ 1.3× held through the final checks): the bound fails on one
    # record-size copy more.
    y = np.asarray(allanite.simulate(8_000_000, 100.0, seed=3, N=0.01, B=0.002, K=1e-4))
    tracemalloc.start(1)
    try:
        r = allanite.refine(y, 100.0, progress=False)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert r.steps == []  # a clean record: the checks ran to the end and found nothing
    assert peak < 5 * y.nbytes, f"traced peak {peak / y.nbytes:.2f}× the record"


def test_the_steps_null_is_drawn_a_chunk_at_a_time():
    # its 2²² half-block means at the cap were simulated at once — 32 MB for the means alone, ≈ 125–225 MB
    # traced with the flicker's transforms and the increments (r7mem) — now 2¹⁸ at a time: its traced peak is
    # below that one array of means
    from allanite.model.refinement import _mean_steps as mss

    th = [9e-6, 9e-8, 1e-10]  # white, flicker and random walk: the flicker's transforms are the largest
    mss.null_ratios(1_000_000, 100.0, ("N", "B", "K"), th, 1e-5, seed=1)  # the filter's cached transform
    tracemalloc.start(1)
    try:
        null = mss.null_ratios(1_000_000, 100.0, ("N", "B", "K"), th, 1e-5, seed=2)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert null["n_boot"] == mss.MAX_BOOT and null["draws"].size == mss.MAX_BOOT
    assert peak < 2**22 * 8, f"traced peak {peak / 2**20:.0f} MB"


def test_null_chunks_are_the_whole_up_to_one_chunk_and_seeded_per_chunk_beyond():
    from allanite.model import tracing

    args = (48, 1000, 100.0, ("N", "B", "K"), [1e-6, 1e-8, 1e-12])
    whole = tracing.simulated_block_means(*args, 5000, 11)  # 2.4·10⁵ samples: one chunk
    (one,) = tracing.simulated_block_mean_chunks(*args, 5000, 11)
    assert np.array_equal(one, whole)
    n_boot = 3 * (tracing.SIM_CHUNK // 48) + 17  # three full chunks and 17 records of a fourth
    parts = list(tracing.simulated_block_mean_chunks(*args, n_boot, 11))
    assert [p.shape[1] for p in parts] == [tracing.SIM_CHUNK // 48] * 3 + [17]
    again = list(tracing.simulated_block_mean_chunks(*args, n_boot, 11))
    assert all(np.array_equal(p, q) for p, q in zip(parts, again))  # reproducible from the seed
    assert not np.allclose(parts[0][:, :17], parts[3])  # each chunk its own stream
    # drawn one ahead on a second thread: each chunk is its own generator's record, as drawn alone
    from allanite.model._null_records import block_rate_record

    sd = dict(zip(("N", "B", "K", "R"), (1e-3, 1e-4, 1e-6, 0.0)))
    alone = block_rate_record(48 * (tracing.SIM_CHUNK // 48), 0.1, **sd, seed=np.random.default_rng([11, 2]))
    assert np.array_equal(parts[2], alone.reshape(-1, 48).T)


def test_the_chunked_nulls_statistic_per_record_is_the_whole_arrays():
    # the null's statistic is per record (column): made a chunk of records at a time it is the same to the bit
    from allanite.model.refinement import _mean_step as ms
    from allanite.model.refinement import _mean_steps as mss

    g = np.cumsum(np.random.default_rng(1).normal(size=(256, 3000)), axis=0)
    z, _ = mss.increment_z(g, mss.STEP_BLOCKS)
    parts = np.concatenate([mss.increment_z(g[:, i : i + 700], mss.STEP_BLOCKS)[0] for i in range(0, 3000, 700)], 1)
    assert np.array_equal(z, parts)
    b = g[:48]
    assert np.array_equal(
        ms.split_statistic(b)[0],
        np.concatenate([ms.split_statistic(b[:, :1000])[0], ms.split_statistic(b[:, 1000:])[0]]),
    )


def test_the_chunked_steps_null_matches_the_one_long_records():
    # records cut from long records of 2¹⁸ block-rate samples rather than one of 2²²: the same null. Each
    # length's median z over 8 seeds each way (2000 records a null) agrees within 3 standard errors of the
    # difference; the one-record form is simulated_block_means, still the drift check's.
    from allanite.model import tracing
    from allanite.model.refinement import _mean_steps as mss

    th = [9e-6, 9e-8, 1e-10]
    blocks = mss._blocks(1_000_000)
    nb, per = 2 * blocks[-1], 1_000_000 // (2 * blocks[-1])
    chunked, whole = [], []
    for seed in range(8):
        chunked.append(mss.null_ratios(1_000_000, 100.0, ("N", "B", "K"), th, 1e-3, seed=seed)["q"])
        sims = tracing.simulated_block_means(nb, per, 100.0, ("N", "B", "K"), th, 2000, seed)
        whole.append(np.median(mss.increment_z(sims, blocks)[0], axis=1))
    a, b = np.array(chunked), np.array(whole)
    se = np.sqrt(a.var(axis=0, ddof=1) / 8 + b.var(axis=0, ddof=1) / 8)
    assert np.all(np.abs(a.mean(axis=0) - b.mean(axis=0)) < 3 * se), (a.mean(axis=0), b.mean(axis=0), se)
    assert np.all(se < 0.01 * a.mean(axis=0))  # and the comparison is sharp: the medians within 1 %


def test_a_channel_regression_holds_one_column_at_a_time():
    # a slow temperature's Whittle regression (refine's removal and its channels check): its three columns
    # (the channel, its square, its derivative) were built at once beside their transforms — 13.0× the rate
    # record traced at 10⁶ samples; made and transformed one at a time, 10.0×; the bins' numbers and bands let
    # go before the transforms and each difference tapered in place, 9.0× (r7mem)
    from allanite.model.channels import regress_channel

    n = 1_000_000
    y = np.asarray(allanite.simulate(n, 100.0, seed=3, N=0.01, B=0.002, K=1e-4))
    temp = 25.0 + np.cumsum(np.random.default_rng(4).normal(0.0, 0.5 / 6000, n))
    tracemalloc.start(1)
    try:
        r = regress_channel(y, temp, 100.0, name="temp")
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert not r.accepted  # independent of the rate
    assert peak < 9.5 * y.nbytes, f"traced peak {peak / y.nbytes:.2f}× the record"
