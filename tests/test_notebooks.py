"""The example notebooks run top to bottom (issue 21): every notebook in ``examples/``, fresh kernel,
a time limit per cell, so a notebook can never rot. Their outputs are stripped in git (checked here too).

The notebooks use the project's shared data when ``ALLANITE_SHARED_DATA`` (or ``../shared/data``) has it and
simulate otherwise; the kernel inherits this process's environment, and runs with ``examples/`` as its
working directory, as a user opening the notebook would.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
#: Where the run with the shared data leaves each executed notebook; the documentation site renders these
#: (docs/_site/hooks.py), so its notebooks show their outputs without the site's build running them.
EXECUTED = EXAMPLES.parent / "build" / "notebooks" / "examples"
NOTEBOOKS = sorted(EXAMPLES.glob("*.ipynb"))
CELL_TIMEOUT = 120  # s, per cell; every notebook runs in well under a minute


def test_there_are_notebooks():
    assert [p.name for p in NOTEBOOKS] == [
        "01_quick_start.ipynb",
        "02_dynamic_view.ipynb",
        "03_long_tau_theo.ipynb",
        "04_from_allantools.ipynb",
    ]


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_outputs_are_stripped(path):
    nbformat = pytest.importorskip("nbformat", reason="nbformat is needed to read the notebooks (test extra)")
    book = nbformat.read(path, as_version=4)
    dirty = [i for i, c in enumerate(book.cells) if c.cell_type == "code" and (c.outputs or c.execution_count)]
    assert dirty == [], f"{path.name}: cells {dirty} carry outputs; strip them before committing"


def _run(path, monkeypatch, shared: str, keep: Path | None = None):
    """Run the notebook with ``ALLANITE_SHARED_DATA=shared``; returns the text of its outputs and, with
    ``keep``, writes the executed notebook there."""
    nbformat = pytest.importorskip("nbformat", reason="nbformat is needed to run the notebooks (test extra)")
    nbclient = pytest.importorskip("nbclient", reason="nbclient is needed to run the notebooks (test extra)")
    pytest.importorskip("ipykernel", reason="ipykernel is needed to run the notebooks (test extra)")
    monkeypatch.setenv("ALLANITE_SHARED_DATA", shared)
    monkeypatch.delenv("MPLBACKEND", raising=False)  # the kernel's inline backend, as in Jupyter
    book = nbformat.read(path, as_version=4)
    client = nbclient.NotebookClient(
        book, timeout=CELL_TIMEOUT, kernel_name="python3", resources={"metadata": {"path": str(EXAMPLES)}}
    )
    client.execute()
    errors = [o for c in book.cells if c.cell_type == "code" for o in c.outputs if o.output_type == "error"]
    assert errors == []
    # every result the notebook shows renders as HTML (the rich display), not only as text
    html = [o for c in book.cells if c.cell_type == "code" for o in c.outputs if "text/html" in o.get("data", {})]
    assert html, f"{path.name}: no rich result displayed"
    if keep is not None:
        keep.mkdir(parents=True, exist_ok=True)
        nbformat.write(book, keep / path.name)
    return "".join(o.get("text", "") for c in book.cells if c.cell_type == "code" for o in c.outputs)


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_notebook_runs(path, monkeypatch):
    # the shared data: the tests' default (../shared/data from the repository) made absolute for the kernel
    shared = os.environ.get("ALLANITE_SHARED_DATA", str(EXAMPLES.parent.parent / "shared" / "data"))
    text = _run(path, monkeypatch, str(Path(shared).resolve()), keep=EXECUTED)
    uses_shared = path.name != "02_dynamic_view.ipynb"  # 02 simulates on purpose (a known change)
    if uses_shared and Path(shared).is_dir():
        assert "real data" in text


@pytest.mark.parametrize("path", [p for p in NOTEBOOKS if p.name != "02_dynamic_view.ipynb"], ids=lambda p: p.stem)
def test_notebook_runs_without_the_shared_data(path, monkeypatch, tmp_path):
    """What a new user gets: no shared data, so the notebook simulates and says so."""
    text = _run(path, monkeypatch, str(tmp_path / "absent"))
    assert "SIMULATED" in text
