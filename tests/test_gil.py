"""The core releases the GIL while it computes, so other Python threads keep running."""

import threading

import numpy as np

import allanite


def test_other_threads_run_while_the_core_computes():
    y = np.random.default_rng(0).normal(size=3_000_000)
    done = threading.Event()
    result = {}

    def work():
        result["d"] = allanite.davar(y, 100.0, window=1_000_000, hop=10_000, taus="exp", workers=1)
        done.set()

    ticks = 0
    th = threading.Thread(target=work)
    th.start()
    while not done.is_set():
        ticks += 1  # pure-Python work: only possible if the computing thread let go of the GIL
    th.join()
    assert result["d"].avar.shape[1] == 201
    # Holding the GIL for the whole call would allow at most a handful of switches (none inside
    # the Rust call); a released GIL lets this loop spin hundreds of thousands of times.
    assert ticks > 10_000
