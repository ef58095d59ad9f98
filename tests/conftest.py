"""Shared fixtures for the allanite test suite.

Reference data (Stable32 tables, real clock records) live *beside* the repository, not in it (their
licences do not fit the package). They are found through one setting, ``ALLANITE_SHARED_DATA``,
defaulting to ``<repo>/../shared/data``; tests that need them skip with a clear reason when absent.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np
import pytest
from hypothesis import settings

from allanite.results import AllanResult

# The property tests run on fixed inputs wherever the test command runs (the same examples on every run,
# no example database written), so a red run is a change, never a draw. Exploring new inputs is a separate,
# explicit run: ALLANITE_EXPLORE=1 python -m pytest (or --hypothesis-profile=explore), which draws at random
# and keeps failures in .hypothesis/. The Rust property tests follow the same switch (rust/testutil/src/proptest_config.rs).
settings.register_profile("fixed", derandomize=True, database=None)
settings.register_profile("explore", derandomize=False)
settings.load_profile("explore" if os.environ.get("ALLANITE_EXPLORE", "").strip() not in ("", "0") else "fixed")

DEFAULT_SHARED_DATA = Path(__file__).resolve().parents[2] / "shared" / "data"


def _slow_wanted(config: pytest.Config) -> bool:
    """ALLANITE_SLOW=1 (any value but empty or 0), or a -m expression that names ``slow``."""
    if os.environ.get("ALLANITE_SLOW", "").strip() not in ("", "0"):
        return True
    return "slow" in (config.getoption("markexpr", "") or "")


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """The default run keeps CI's share small: tests marked ``slow`` — a heavier second record of a case a
    cheaper default test covers, or a larger sample of a statistic a smaller one checks — are skipped with a
    reason that says how to run them (docs/development.md lists what each set covers)."""
    if _slow_wanted(config):
        return
    skip = pytest.mark.skip(reason="slow: a heavier twin of a default test; run with ALLANITE_SLOW=1 or -m slow")
    for item in items:
        if item.get_closest_marker("slow") is not None:
            item.add_marker(skip)


def shared_data_dir() -> Path:
    """Where the shared reference data are expected (``ALLANITE_SHARED_DATA`` or the default)."""
    env = os.environ.get("ALLANITE_SHARED_DATA", "").strip()
    return Path(env) if env else DEFAULT_SHARED_DATA


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """The shared reference-data folder; skips the test when it is not there."""
    path = shared_data_dir()
    if not path.is_dir():
        pytest.skip(
            f"shared reference data not found at {path} (set ALLANITE_SHARED_DATA to the folder "
            f"holding stable32/, adis16405/, ...)"
        )
    return path


@pytest.fixture(scope="session")
def stable32_dir(shared_data: Path) -> Path:
    path = shared_data / "stable32"
    if not path.is_dir():
        pytest.skip(f"Stable32 reference tables not found at {path}")
    return path


def read_avar_curve(path: Path) -> dict:
    """The avar package's curve CSV → {channel: AllanResult}; fs and n from the first comment line.
    (Its estimator sums T − 2m terms over T − 2m + 1, ≤ 6e-6 from the textbook value: left as is.)"""
    lines = path.read_text().splitlines()
    meta = dict(re.findall(r"(\w+)=([^;]+)", lines[0]))
    fs, n = float(meta["freq_Hz"]), int(float(meta["n"]))
    chans: dict = {}
    for row in (ln.split(",") for ln in lines[1:] if ln and not ln.startswith("#")):
        if row[0] == "channel":
            continue
        chans.setdefault(row[0], []).append((float(row[1]), float(row[2])))
    out = {}
    for ch, v in chans.items():
        a = np.array(v)
        m = np.round(a[:, 0] * fs).astype(np.int64)
        out[ch] = AllanResult(tau=m / fs, avar=a[:, 1], n=n + 1 - 2 * m, m=m, estimator="oavar", fs=fs, n_samples=n)
    return out


@pytest.fixture(scope="session")
def load_avar_curve():
    """The reader of the ``avar`` package's Allan-curve CSVs (``../shared/data/avar-curves``), as a
    fixture so that test modules share it without importing one another."""
    return read_avar_curve


@pytest.fixture
def rng() -> np.random.Generator:
    """A fresh, fixed-seed generator per test (tests stay independent of their order)."""
    return np.random.default_rng(20240611)


@pytest.fixture(scope="session", autouse=True)
def _null_records_shared():
    """Refine's checks along time draw their null records from fixed seeds at lengths that do not depend on the
    record (``allanite.model._null_records``): within :func:`~allanite.model._null_records.sharing` — what a report
    opens around its axes' refinements — each record's flicker is drawn once and found again, bit for bit the same
    numbers (``test_refine_recent.py`` holds that), so every refine of the session shares them as a report's axes do:
    ≈ 13 % of a refine test's CPU (issue 29's CI share; ≤ 32 records of ≤ 4 MB kept per test process)."""
    from allanite.model._null_records import sharing

    with sharing():
        yield


@pytest.fixture(autouse=True)
def _blas_one_thread(request):
    """Every test runs OpenBLAS on one thread (:func:`allanite._blas.one_thread`, as refine does itself): the suite
    runs on as many processes as cores (``-n 2``), and the tests that call the linear algebra outside refine (the
    warm-up's GLS fits, the bound, the covariances) multiply matrices of 10²–10³ rows, where a second BLAS thread's
    spin-wait costs more than the product — on the shared 2-core machine test_warmup's ramp choice took 8–13 CPU s
    against 3.2–3.4 on one thread (issue 29's CI share). Tests of the thread count itself (``blas_threads``) keep
    the library's own count."""
    if request.node.get_closest_marker("blas_threads") is not None:
        yield
        return
    from allanite._blas import one_thread

    with one_thread():
        yield


@pytest.fixture(autouse=True)
def _clean_allanite_env(monkeypatch):
    """The library reads ALLANITE_NUM_THREADS / ALLANITE_MAX_MEMORY; a value left in the caller's
    environment must not change what the tests see."""
    monkeypatch.delenv("ALLANITE_NUM_THREADS", raising=False)
    monkeypatch.delenv("ALLANITE_MAX_MEMORY", raising=False)
