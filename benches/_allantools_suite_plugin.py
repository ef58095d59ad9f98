"""pytest plugin for running allantools' own test suite in a subprocess (tests/test_compat_suite.py,
benches/compat_suite.py; started by _allantools_sdist.run_suite).

With ``ALLANITE_SUITE_TARGET=compat`` (the default) a meta-path blocker makes the real allantools
unimportable — asserted before anything else — and ``allanite.compat.install_as_allantools()`` makes
``allantools`` and its submodules resolve to allanite.compat. With ``=allantools`` the real package runs
(for the reference counts). Either way np.random is seeded per test (from its node id; the noise tests
are statistical) and once before collection, and every test's outcome and duration go to the JSON file
``ALLANITE_SUITE_REPORT``, with whether any module from the real allantools was ever loaded.
"""

from __future__ import annotations

import importlib.abc
import json
import os
import sys
import zlib

import numpy as np
import pytest

TARGET = os.environ.get("ALLANITE_SUITE_TARGET", "compat")
OUTCOMES: dict[str, dict] = {}


class RealAllantoolsBlocker(importlib.abc.MetaPathFinder):
    """Refuses to find ``allantools`` and ``allantools.*`` anywhere on the path."""

    def find_spec(self, fullname, path=None, target=None):
        if fullname == "allantools" or fullname.startswith("allantools."):
            raise ImportError(f"{fullname}: the real allantools is blocked in this run")
        return None


def _real_allantools_modules() -> list[str]:
    """Modules named allantools* whose file is not allanite's."""
    out = []
    for name, mod in list(sys.modules.items()):
        if name == "allantools" or name.startswith("allantools."):
            f = getattr(mod, "__file__", "") or ""
            if "allanite" not in f.replace("\\", "/").split("/"):
                out.append(name)
    return out


def pytest_configure(config):
    if TARGET == "compat":
        sys.meta_path.insert(0, RealAllantoolsBlocker())
        try:
            import allantools  # noqa: F401
        except ImportError:
            pass
        else:
            raise pytest.UsageError("the real allantools is still importable: the blocker failed")
        from allanite.compat import install_as_allantools

        install_as_allantools()
    np.random.seed(0)


@pytest.hookimpl(tryfirst=True)
def pytest_runtest_setup(item):
    np.random.seed(zlib.crc32(item.nodeid.encode()))


def _record(nodeid: str, outcome: str, duration: float, message: str = "") -> None:
    rec = OUTCOMES.setdefault(nodeid, {"outcome": "passed", "duration": 0.0, "message": ""})
    rec["duration"] += duration
    rank = ["passed", "skipped", "xfailed", "xpassed", "failed", "error"]
    if rank.index(outcome) >= rank.index(rec["outcome"]):
        rec["outcome"] = outcome
        if message:
            rec["message"] = message[-2000:]


def pytest_runtest_logreport(report):
    xfail = hasattr(report, "wasxfail")
    if report.failed:
        outcome = "failed" if report.when == "call" else "error"
    elif report.skipped:
        outcome = "xfailed" if xfail else "skipped"
    elif report.when == "call" and xfail:
        outcome = "xpassed"
    else:
        outcome = "passed"
    _record(report.nodeid, outcome, report.duration, str(report.longrepr) if report.failed else "")


def pytest_collectreport(report):
    if report.failed:
        _record(report.nodeid, "error", 0.0, str(report.longrepr))


def pytest_sessionfinish(session):
    path = os.environ.get("ALLANITE_SUITE_REPORT")
    if not path:
        return
    at = sys.modules.get("allantools")
    with open(path, "w", encoding="utf-8") as f:
        json.dump(
            {
                "target": TARGET,
                "allantools_module": getattr(at, "__name__", None),
                "real_allantools_loaded": _real_allantools_modules(),
                "blocked": any(isinstance(f, RealAllantoolsBlocker) for f in sys.meta_path),
                "outcomes": OUTCOMES,
            },
            f,
            indent=1,
        )
