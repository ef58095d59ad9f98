"""The front page and the documentation site (issue 32 item 8).

The README is a front page whose examples run and print what it shows; the site (``mkdocs.yml``,
``docs/_site/``) builds with warnings as errors — a broken link, a missing page, an unresolved reference fails
it — and its API reference has an entry, with a docstring, for every public name.
"""

from __future__ import annotations

import doctest
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
SITE_TOOLS = ROOT / "docs" / "_site"

_PYCON = re.compile(r"^```pycon\n(.*?)^```", re.DOTALL | re.MULTILINE)


def _api():
    """docs/_site/api.py: what the reference holds (needs griffe, from the docs extra)."""
    pytest.importorskip("griffe", reason="griffe reads the public API: pip install '.[docs]' (in the test extra)")
    pytest.importorskip("griffe_sphinx", reason="griffe-sphinx reads '#:' comments: pip install '.[docs]'")
    sys.path.insert(0, str(SITE_TOOLS))
    try:
        import api
    finally:
        sys.path.remove(str(SITE_TOOLS))
    return api


# --------------------------------------------------------------------------------------------------
# the front page


def test_readme_is_a_front_page_with_the_ci_commands():
    lines = README.read_text(encoding="utf-8").splitlines()
    assert len(lines) <= 150, f"README.md has {len(lines)} lines; the reference belongs in docs/"
    for marker in ("# ci:main", "# ci:test", "# ci:wheel"):
        assert sum(line.endswith(marker) for line in lines) == 1, marker


def test_readme_examples_print_what_the_readme_shows():
    text = README.read_text(encoding="utf-8")
    blocks = _PYCON.findall(text)
    assert len(blocks) == 4, "the README shows four examples"
    test = doctest.DocTestParser().get_doctest("\n".join(blocks), {}, "README.md", str(README), 0)
    assert len(test.examples) >= 12
    runner = doctest.DocTestRunner(optionflags=doctest.NORMALIZE_WHITESPACE)
    runner.run(test)
    assert runner.failures == 0


# --------------------------------------------------------------------------------------------------
# docstring coverage


@pytest.fixture(scope="module")
def package():
    """(docs/_site/api.py, the package as Griffe reads it), loaded once for the module."""
    api = _api()
    return api, api.load()


def test_every_public_name_has_a_docstring(package):
    api, pkg = package
    objects = api.public_objects(pkg)
    assert len(objects) > 300  # modules, functions, classes, methods, properties, constants
    missing = api.undocumented(pkg)
    assert missing == [], "public names without a docstring (the API reference would leave them out):\n" + "\n".join(
        missing
    )


def test_every_public_name_has_an_entry_in_the_reference(package):
    api, pkg = package
    ref = api.reference(pkg)
    for obj in api.public_objects(pkg):
        if not obj.is_module:
            assert obj.path in ref.anchor_of, obj.path
    # a re-export whose home module is private is documented on the package's page
    assert ref.anchor_of["allanite.estimators._registry.get"] == "allanite.estimators.get"
    assert ref.anchor_of["allanite.analysis.avar"] == "allanite.analysis.avar"


def test_the_coverage_check_finds_what_is_missing(tmp_path):
    api = _api()
    pkg_dir = tmp_path / "allanite"
    (pkg_dir / "_private").mkdir(parents=True)
    (pkg_dir / "__init__.py").write_text('"""Doc."""\nfrom .mod import shown, hidden\n__all__ = ["shown", "hidden"]\n')
    (pkg_dir / "_private" / "__init__.py").write_text("def secret():\n    pass\n")
    (pkg_dir / "mod.py").write_text(
        '"""Doc."""\n\n#: A documented constant.\nLIMIT = 3\nBARE = 4\n\n\ndef shown():\n    """Doc."""\n\n\n'
        'def hidden():\n    pass\n\n\nclass Thing:\n    """Doc."""\n\n    def method(self):\n        pass\n\n'
        "    @property\n    def size(self):\n        return 1\n\n    def _private(self):\n        pass\n"
    )
    missing = api.undocumented(api.load(tmp_path))
    assert missing == [
        "allanite.mod.BARE",
        "allanite.mod.Thing.method",
        "allanite.mod.Thing.size",
        "allanite.mod.hidden",
    ]


# --------------------------------------------------------------------------------------------------
# the site


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    """The site built as CI builds it: ``mkdocs build --strict`` (mkdocs.yml), into a temporary folder."""
    pytest.importorskip("mkdocs", reason="the site needs the docs extra: pip install '.[docs]' (in the test extra)")
    _api()
    out = tmp_path_factory.mktemp("site")
    env = dict(os.environ, NO_MKDOCS_2_WARNING="1")
    proc = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(out)],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    warnings = [line for line in proc.stderr.splitlines() if "WARNING" in line or "ERROR" in line]
    assert proc.returncode == 0 and not warnings, proc.stderr[-5000:]
    return out


def test_the_site_holds_every_page(site):
    assert (site / "index.html").is_file()  # README.md
    for page in ROOT.glob("docs/*.md"):
        assert (site / "docs" / page.with_suffix(".html").name).is_file(), page.name
    for page in ROOT.glob("benches/results/*.md"):
        assert (site / "benches" / "results" / page.with_suffix(".html").name).is_file(), page.name
    for book in ROOT.glob("examples/*.ipynb"):
        assert (site / "examples" / book.with_suffix(".html").name).is_file(), book.name
    assert (site / "benches" / "index.html").is_file()  # benches/README.md


def test_the_reference_documents_every_public_name(site, package):
    api, pkg = package
    ref = api.reference(pkg)
    pages = {}
    for anchor, module in ref.page_of.items():
        name = "index.html" if module == api.PACKAGE else f"{module}.html"
        if name not in pages:
            pages[name] = (site / "api" / name).read_text(encoding="utf-8")
        assert f'id="{anchor}"' in pages[name], f"{anchor} has no entry in api/{name}"


def test_docstring_citations_link_to_the_formula_sheet(site):
    sheet = ROOT.joinpath("docs/FORMULAS.md")
    link = re.compile(rf'href="\.\./docs/{sheet.stem}\.html#([\w-]+)"')
    targets = set()
    for page in (site / "api").glob("*.html"):
        html = page.read_text(encoding="utf-8")
        targets |= set(link.findall(html))
        # roles became links or code, not raw Sphinx markup
        assert ":func:`" not in html and ":class:`" not in html, page.name
    assert len(targets) >= 5, "the docs/FORMULAS.md citations in the docstrings did not become links"
    html = (site / "docs" / f"{sheet.stem}.html").read_text(encoding="utf-8")
    for anchor in targets:
        assert f'id="{anchor}"' in html, anchor


def test_refines_entry_lists_every_effect_under_candidates(site):
    """refine's docstring lists the effects registry at import time; the reference reads the source, so its
    extension fills the same list in (``docs/_site/griffe_roles.fill_effects``) — once a literal ``{effects}``
    line, whose lower indentation also turned the whole parameter list into a code block."""
    import allanite

    html = (site / "api" / "allanite.model.refinement.loop.html").read_text(encoding="utf-8")
    assert "{effects}" not in html
    for name in allanite.model.EFFECTS:
        assert f"&#39;{name}&#39;" in html or f"'{name}'" in html, name
    # the parameters after the list are parsed as parameters (a table row each), not shown as text
    for param in ("x_or_result", "candidates", "unit", "level", "progress"):
        assert re.search(rf"<code>{param}</code>", html), param


def test_fill_effects_puts_the_registry_at_the_placeholders_indentation():
    sys.path.insert(0, str(SITE_TOOLS))
    try:
        from griffe_roles import fill_effects
    finally:
        sys.path.remove(str(SITE_TOOLS))
    import allanite

    filled = fill_effects(
        "Parameters\n----------\ncandidates : tuple\n    Effects:\n\n    {effects}\nunit : str\n    Unit."
    )
    items = [ln for ln in filled.splitlines() if ln.lstrip().startswith("- ``'")]
    assert len(items) == len(allanite.model.EFFECTS) and all(ln.startswith("    - ") for ln in items)
    assert filled.splitlines()[-2:] == ["unit : str", "    Unit."]
    assert fill_effects("no placeholder") == "no placeholder"


def test_the_site_links_are_relative(site):
    for page in (site / "index.html", site / "docs" / "guide.html", site / "api" / "allanite.analysis.html"):
        html = page.read_text(encoding="utf-8")
        assert not re.search(r'(?:href|src)="/(?!/)', html), f"{page.name} has a site-absolute link"
