"""The wheel a user without Rust installs (issue 32 item 7), checked when one is given.

CI builds and repairs it once (``.ci/wheel build``: the README's ``# ci:wheel`` line) and names it in
``ALLANITE_WHEEL``; these tests check that it holds the whole package and nothing else, carries the abi3 and
manylinux tags of the stated policy, that the installed package this suite imports is byte for byte that wheel's
(so the suite ran on its code), and that it installs and imports in a virtual environment whose PATH has no
cargo. Without ``ALLANITE_WHEEL`` they skip: build a wheel with the README's ``# ci:wheel`` line and point
``ALLANITE_WHEEL`` at ``dist/allanite-…-manylinux_2_34_x86_64.whl``.
"""

from __future__ import annotations

import base64
import csv
import hashlib
import io
import os
import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE_SRC = ROOT / "python" / "allanite"
#: The manylinux policy the README's ``# ci:wheel`` line repairs to (docs/install.md says why).
POLICY = "manylinux_2_34_x86_64"
_NAME = re.compile(r"^allanite-(?P<version>[^-]+)-cp39-abi3-(?P<platform>[\w.]+)\.whl$")


@pytest.fixture(scope="module")
def wheel() -> Path:
    given = os.environ.get("ALLANITE_WHEEL", "").strip()
    if not given:
        pytest.skip("no wheel given: build one with the README's '# ci:wheel' line and set ALLANITE_WHEEL (CI does)")
    path = Path(given)
    assert path.is_file(), f"ALLANITE_WHEEL={given} is not a file"
    return path


def _record(wheel: Path) -> dict[str, str]:
    """The wheel's RECORD: path → sha256 (urlsafe base64, as in RECORD)."""
    with zipfile.ZipFile(wheel) as z:
        name = next(n for n in z.namelist() if n.endswith(".dist-info/RECORD"))
        rows = csv.reader(io.StringIO(z.read(name).decode()))
        return {row[0]: row[1].split("=", 1)[1] for row in rows if row and row[1]}


def _digest(data: bytes) -> str:
    return base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()


def test_the_wheel_is_abi3_and_of_the_stated_policy(wheel):
    m = _NAME.match(wheel.name)
    assert m, f"{wheel.name}: not an abi3 (cp39-abi3) allanite wheel"
    assert m.group("platform") == POLICY
    with zipfile.ZipFile(wheel) as z:
        meta = z.read(next(n for n in z.namelist() if n.endswith(".dist-info/WHEEL"))).decode()
    assert f"Tag: cp39-abi3-{POLICY}" in meta and "Root-Is-Purelib: false" in meta


def test_the_wheel_holds_the_whole_package(wheel):
    source = {
        "allanite/" + p.relative_to(PACKAGE_SRC).as_posix()
        for p in PACKAGE_SRC.rglob("*")
        if p.is_file() and "__pycache__" not in p.parts and not p.name.endswith((".so", ".pyd", ".pyc"))
    }
    with zipfile.ZipFile(wheel) as z:
        names = set(z.namelist())
        entry_points = z.read(next(n for n in names if n.endswith(".dist-info/entry_points.txt"))).decode()
    packaged = {n for n in names if n.startswith("allanite/") and not n.endswith("/")}
    assert packaged == source | {"allanite/_core.abi3.so"}, (
        f"missing: {sorted(source - packaged)}; unexpected: {sorted(packaged - source - {'allanite/_core.abi3.so'})}"
    )
    assert re.search(r"^allanite\s*=\s*allanite\.cli:main$", entry_points, re.MULTILINE), entry_points
    assert not any(n.startswith("allanite.libs/") for n in names), "auditwheel grafted libraries into the wheel"


def test_the_suite_runs_on_the_wheels_code(wheel):
    import allanite

    installed = Path(allanite.__file__).resolve().parent
    differ = []
    for path, digest in _record(wheel).items():
        if path.startswith("allanite/"):
            local = installed / path[len("allanite/") :]
            if not local.is_file() or _digest(local.read_bytes()) != digest:
                differ.append(path)
    assert differ == [], f"the imported allanite ({installed}) is not the wheel's: {differ}"


def test_the_wheel_installs_and_runs_without_rust(wheel, tmp_path):
    """Into a virtual environment (its dependencies from this one, so nothing is downloaded) whose PATH holds
    no cargo: the package imports from the venv, computes, and its command line answers."""
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--system-site-packages", "--without-pip", str(venv)], check=True)
    path = os.pathsep.join([str(venv / "bin"), "/usr/local/bin", "/usr/bin", "/bin"])
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "CARGO_HOME", "RUSTUP_HOME")}
    env.update(PATH=path, VIRTUAL_ENV=str(venv))
    assert shutil.which("cargo", path=path) is None and shutil.which("rustc", path=path) is None
    python = str(venv / "bin" / "python")
    # this environment's pip installs into the venv (``--python``), which saves the venv a pip of its own;
    # --ignore-installed: the venv sees this environment's allanite (the same version), which pip would otherwise
    # call "already satisfied" and leave the venv without its own copy
    pip = [sys.executable, "-m", "pip", "--python", python, "install", "-q", "--no-deps", "--no-index",
           "--ignore-installed", str(wheel)]
    subprocess.run(pip, check=True, env=env, cwd=tmp_path)
    code = (
        "import sys, numpy as np, allanite\n"
        "assert allanite.__file__.startswith(sys.prefix), allanite.__file__\n"
        "y = allanite.simulate(100_000, 100.0, N=2e-3, seed=1)\n"
        "r = allanite.avar(y, 100.0, taus=[1.0])\n"
        "print(f'{r.adev[0]:.2e}')\n"
    )
    out = subprocess.run([python, "-c", code], env=env, cwd=tmp_path, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert abs(float(out.stdout) / 2e-3 - 1) < 0.05  # white rate noise: ADEV(1 s) = N
    cli = subprocess.run(
        [str(venv / "bin" / "allanite"), "report", "--help"], env=env, cwd=tmp_path, capture_output=True, text=True
    )
    assert cli.returncode == 0 and "--window" in cli.stdout
