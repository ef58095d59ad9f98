"""MkDocs hooks that make the site out of the repository's own files.

Pages keep their repository paths (README.md is the home page, docs/X.md stays docs/X.md, the notebooks stay
in examples/, the benches' results in benches/results/), so every relative link that works when reading the
repository works in the site and ``mkdocs build --strict`` fails on one that does not. The API reference is
one generated page per public module (``docs/_site/api.py`` decides what is public). Pages no nav entry
names — a new docs/*.md, a new results page — are added to their section by these hooks, so the site
never silently leaves a page out.

A notebook is rendered from its executed copy when ``tests/test_notebooks.py`` left one
(``build/notebooks/examples/``, at least as new as the notebook), else as stored (code without outputs);
the build never runs a notebook.
"""

from __future__ import annotations

import sys
from pathlib import Path

from mkdocs.plugins import event_priority
from mkdocs.structure.files import File, Files

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(Path(__file__).resolve().parent))

import api  # noqa: E402  (docs/_site/api.py, beside this file)

#: What the site holds, as repository globs, and the nav section that lists a page none names.
SOURCES = {
    "README.md": None,
    "LICENSE": None,
    "docs/*.md": "Topics",
    "docs/*.png": None,
    "examples/*.ipynb": "Getting started",
    "benches/README.md": "Benchmarks",
    "benches/results/*.md": "Benchmarks",
    "benches/results/*.png": None,
}
EXECUTED = ROOT / "build" / "notebooks"
API_SECTION = "API reference"


def _sources() -> dict[str, str | None]:
    """Repository path → nav section, for every file the site holds."""
    out: dict[str, str | None] = {}
    for pattern, section in SOURCES.items():
        for path in sorted(ROOT.glob(pattern)):
            out[path.relative_to(ROOT).as_posix()] = section
    return out


def _named(nav: list) -> set[str]:
    """Every page path a nav (nested lists and {title: page|list}) names."""
    found: set[str] = set()
    for entry in nav:
        value = next(iter(entry.values())) if isinstance(entry, dict) else entry
        if isinstance(value, list):
            found |= _named(value)
        else:
            found.add(value)
    return found


def _section(nav: list, title: str) -> list:
    """The list of a top-level nav section (created at the end if absent)."""
    for entry in nav:
        if isinstance(entry, dict) and title in entry:
            if not isinstance(entry[title], list):
                entry[title] = [entry[title]]
            return entry[title]
    nav.append({title: []})
    return nav[-1][title]


def _api_pages() -> dict[str, str]:
    """Generated API pages: site path → Markdown (computed once per build)."""
    global _PAGES
    if _PAGES is None:
        _PAGES = api.pages(api.load())
    return _PAGES


_PAGES: dict[str, str] | None = None


def on_config(config):
    nav = config.nav
    named = _named(nav)
    for path, section in _sources().items():
        if section and path.endswith(".md") and path not in named:
            _section(nav, section).append(path)
    api_list = _section(nav, API_SECTION)
    api_list[:] = [p for p in _api_pages() if p not in named or p == "api/index.md"]
    return config


@event_priority(100)  # before mkdocs-jupyter turns the notebooks into pages
def on_files(files: Files, config) -> Files:
    kept = [f for f in files if not f.src_dir or Path(f.src_dir).resolve() != Path(config.docs_dir).resolve()]
    out = Files(kept)
    for path in _sources():
        executed, source = EXECUTED / path, ROOT / path
        fresh = path.endswith(".ipynb") and executed.is_file() and executed.stat().st_mtime >= source.stat().st_mtime
        out.append(File(path, str(EXECUTED if fresh else ROOT), config.site_dir, config.use_directory_urls))
    for path, text in _api_pages().items():
        out.append(File.generated(config, path, content=text))
    return out
