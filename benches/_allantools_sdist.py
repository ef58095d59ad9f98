"""allantools 2024.6's source distribution — its test suite and data sets — fetched from the package
registry into a cache outside the clone, checked against a pinned sha256, and unpacked on demand.

Nothing of it is stored in this repository (allantools is LGPL): ``tests/test_compat_suite.py`` runs
its tests against allanite.compat (CI), ``benches/compat_suite.py`` runs the complete suite under both,
``benches/compat_bench.py --datasets`` times both on its data sets. The cache is ``ALLANITE_CACHE`` or
``~/.cache/allanite``. A bench helper like ``_common`` (the tests load it by its path).
"""

from __future__ import annotations

import hashlib
import os
import subprocess
import sys
import tarfile
from pathlib import Path

VERSION = "2024.6"
SDIST = f"allantools-{VERSION}.tar.gz"
#: sha256 of allantools-2024.6.tar.gz as served by PyPI (computed once from the download)
SHA256 = "c4380c74de834ac869aefc899038e784ef1dd396370be89d6836abffbe484289"


#: the suite's size as allantools 2024.6 collects it (all of it runs there; docs/compat.md)
COLLECTED = 358

#: slow cases CI leaves to ``benches/compat_suite.py`` (they pass there, docs/compat.md): each reads the
#: 556 990-point Cs 5071A record from its gzip text once per row of its Stable32 table, ~10 s of the
#: test's own file parsing per test, whatever computes the deviations
DESELECTED = [
    f"tests/Cs5071A/test_CS5071A_decade.py::TestCS::test_{name}_ci"
    for name in ("adev", "oadev", "mdev", "hdev", "ohdev", "totdev")
]
#: and two of test_adev_average's three noise levels qd (each case averages 30 draws of 2^16 points;
#: qd only scales the series, so the cases at qd = 6e-9 check the same thing): 42 cases, ~15 s of CI
DESELECTED += [
    f"tests/test_noise_kasdin.py::test_adev_average[{qd}-{tau}-{b}]"
    for qd in ("3e-15", "5e-10")
    for tau in (1, 2, 3, 4, 5, 20, 30)
    for b in (0, -1, -2)
]

#: {node id: reason} of tests that pass on allantools 2024.6 but not on allanite.compat (docs/compat.md)
EXCEPTIONS: dict[str, str] = {}

#: skipped by allantools' suite itself (``@pytest.mark.skip``)
SKIPPED = ["tests/ocxo/test_ocxo.py::TestOCXO::test_totdev_ci"]


class FetchError(RuntimeError):
    """The sdist could not be downloaded or does not match its pinned hash."""


def cache_dir() -> Path:
    env = os.environ.get("ALLANITE_CACHE", "").strip()
    return Path(env).expanduser() if env else Path.home() / ".cache" / "allanite"


def _sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def sdist() -> Path:
    """The verified sdist, downloaded with ``pip download`` when the cache lacks it."""
    cache = cache_dir()
    path = cache / SDIST
    if not path.is_file():
        cache.mkdir(parents=True, exist_ok=True)
        cmd = [sys.executable, "-m", "pip", "download", "--no-deps", "--no-binary", ":all:"]
        cmd += ["--disable-pip-version-check", "-d", str(cache), f"allantools=={VERSION}"]
        run = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
        if run.returncode != 0 or not path.is_file():
            tail = (run.stderr or run.stdout).strip().splitlines()[-3:]
            raise FetchError(f"`{' '.join(cmd)}` failed (exit {run.returncode}): {' | '.join(tail)}")
    got = _sha256(path)
    if got != SHA256:
        raise FetchError(f"{path} has sha256 {got}, expected {SHA256} (delete it to download again)")
    return path


def unpacked(dest: Path) -> Path:
    """The sdist's ``tests/`` and ``pytest.ini`` unpacked under ``dest``: the folder holding them."""
    root = dest / f"allantools-{VERSION}"
    if not (root / "tests").is_dir():
        with tarfile.open(sdist()) as tar:
            members = [
                m for m in tar.getmembers() if m.isfile() and m.name.split("/", 2)[1:2] in (["tests"], ["pytest.ini"])
            ]
            for m in members:
                if m.name.startswith("/") or ".." in Path(m.name).parts:
                    raise FetchError(f"unsafe path in {SDIST}: {m.name}")
            safe = {"filter": "data"} if hasattr(tarfile, "data_filter") else {}
            tar.extractall(dest, members=members, **safe)
    return root


def run_suite(root: Path, target: str, report: Path, args: tuple[str, ...] = (), timeout: float = 1800) -> dict:
    """Runs the unpacked suite under ``root`` in a subprocess with benches/_allantools_suite_plugin.py,
    against ``target`` ("compat" or "allantools"); returns the plugin's report (outcomes per test)
    with the wall time and the tail of pytest's output."""
    import json
    import time

    here = Path(__file__).resolve().parent
    env = dict(os.environ, ALLANITE_SUITE_TARGET=target, ALLANITE_SUITE_REPORT=str(report), MPLBACKEND="Agg")
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(here), env.get("PYTHONPATH", "")) if p)
    env.pop("PYTEST_ADDOPTS", None)
    cmd = [sys.executable, "-m", "pytest", "tests", "-q", "-p", "_allantools_suite_plugin", "-p", "no:cacheprovider"]
    cmd += ["-o", "addopts=", "-W", "ignore", *args]
    start = time.perf_counter()
    run = subprocess.run(cmd, cwd=root, env=env, capture_output=True, text=True, timeout=timeout)
    seconds = time.perf_counter() - start
    if not report.is_file():
        raise FetchError(f"the suite wrote no report (exit {run.returncode}): {run.stdout[-2000:]}{run.stderr[-2000:]}")
    out = json.loads(report.read_text(encoding="utf-8"))
    out.update(seconds=seconds, returncode=run.returncode, tail=(run.stdout + run.stderr)[-3000:])
    return out


def per_file(report: dict) -> dict[str, dict[str, int]]:
    """Outcome counts per test file: {file: {outcome: count}}."""
    counts: dict[str, dict[str, int]] = {}
    for nodeid, rec in report["outcomes"].items():
        f = counts.setdefault(nodeid.split("::")[0], {})
        f[rec["outcome"]] = f.get(rec["outcome"], 0) + 1
    return counts
