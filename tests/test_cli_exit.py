"""The command line's exit and what it imports. ``main()`` of the process's own arguments freezes the garbage
collector's objects before the interpreter exits (so that its exit does not walk them all again); ``main(argv)``
— a caller that goes on — leaves the collector alone. The files of a report run the command's way are complete.
Without a terminal to draw a bar on, tqdm is not imported."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

from allanite import cli


@pytest.fixture
def frozen(monkeypatch):
    calls = []
    monkeypatch.setattr(cli.gc, "freeze", lambda: calls.append(True))
    return calls


def test_main_of_the_process_arguments_freezes_before_exit(monkeypatch, frozen, capsys):
    monkeypatch.setattr(sys, "argv", ["allanite"])
    assert cli.main() == 2  # no command: the help, status 2
    assert frozen == [True]
    assert "commands:" in capsys.readouterr().out


def test_main_of_the_process_arguments_freezes_after_an_error_too(monkeypatch, frozen, capsys):
    monkeypatch.setattr(sys, "argv", ["allanite", "report", "/no/such/log.csv", "--fs", "100"])
    assert cli.main() == 2
    assert frozen == [True]
    assert "no such file" in capsys.readouterr().err


def test_main_with_arguments_leaves_the_collector_alone(frozen):
    assert cli.main([]) == 2
    assert frozen == []


def test_report_files_complete_after_the_command_exits(tmp_path):
    rng = np.random.default_rng(3)
    log = tmp_path / "gyro.csv"
    np.savetxt(log, rng.normal(size=(4000, 2)) * 0.01, delimiter=",", header="gx,gy", comments="")
    out = tmp_path / "out"
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p))
    proc = subprocess.run(
        [sys.executable, "-m", "allanite", "report", str(log), "--fs", "100", "--no-fit", "-q", "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=300,
        env=env,
    )
    assert proc.returncode == 0, proc.stderr
    summary = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    html = (out / "report.html").read_text(encoding="utf-8")
    assert html.rstrip().endswith("</html>")
    for name in summary["files"]["figures"]:
        data = (out / name).read_bytes()
        assert data.startswith(b"\x89PNG") and data.endswith(b"IEND\xaeB`\x82")


def test_no_progress_bar_no_tqdm_import(tmp_path):
    """A report whose stderr is no terminal draws no bar: tqdm (whose import reads the installed packages'
    metadata) is not imported."""
    log = tmp_path / "gyro.csv"
    np.savetxt(log, np.random.default_rng(4).normal(size=(3000, 1)) * 0.01, header="g", comments="")
    code = (
        "import sys; from allanite import cli; "
        f"rc = cli.main(['report', {str(log)!r}, '--fs', '50', '--no-fit', '--out', {str(tmp_path / 'o')!r}]); "
        "print('TQDM', 'tqdm' in sys.modules, rc)"
    )
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p))
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300, env=env)
    assert "TQDM False 0" in proc.stdout, proc.stdout + proc.stderr
    assert "static Allan deviation" in proc.stdout  # the steps are printed as lines instead (stdout no terminal)


def test_import_allanite_leaves_the_optional_modules_for_their_first_use():
    code = (
        "import sys, allanite; "
        "lazy = ('combination', 'wavelet', 'simulation', 'datasets', 'kalibr', 'model.refinement'); "
        "print(sorted(m for m in lazy if 'allanite.' + m in sys.modules)); "
        "from allanite.combination import combine; from allanite.wavelet import Split; "
        "print(allanite.combine is combine, allanite.Split is Split, 'to_kalibr' in dir(allanite))"
    )
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p))
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300, env=env)
    assert proc.stdout.split("\n")[:2] == ["[]", "True True True"], proc.stdout + proc.stderr


def test_the_report_loads_the_quantile_kernels_alone_even_with_a_progress_bar(tmp_path):
    """With a bar on a terminal (tqdm starts a monitor thread), the command still loads the intervals' χ²
    kernels without the whole scipy.special package: it loads them before the bar exists."""
    log = tmp_path / "gyro.csv"
    np.savetxt(log, np.random.default_rng(5).normal(size=(4000, 1)) * 0.01, header="g", comments="")
    code = (
        "import sys, threading; from allanite import cli, _dist; "
        "cli._isatty = lambda stream: True; "
        f"rc = cli.main(['report', {str(log)!r}, '--fs', '50', '--out', {str(tmp_path / 'o')!r}]); "
        "print('KERNELS', _dist.special().__name__, 'scipy.special' in sys.modules, 'tqdm' in sys.modules, rc)"
    )
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p))
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300, env=env)
    assert "KERNELS scipy.special._ufuncs False True 0" in proc.stdout, proc.stdout + proc.stderr[-3000:]
