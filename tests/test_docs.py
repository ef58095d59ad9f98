"""The documentation's cross-references: every ``docs/FORMULAS.md §N`` citation names a section that
exists, every mention of the formula sheet names the repository's own ``docs/FORMULAS.md``, and every
relative link in README.md, benches/README.md and docs/*.md points to a file that exists.

Each checker is also run on a small made-up tree, so that a checker that silently finds nothing would fail.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SHEET = ROOT / "docs" / "FORMULAS.md"

#: Where citations are looked for: the package, its Rust core, tests, bench scripts and the docs.
CITING = ("python/**/*.py", "python/**/*.pyi", "rust/**/*.rs", "tests/*.py", "benches/*.py", "docs/*.md", "*.md")
#: Markdown files whose relative links must resolve.
LINKING = ("README.md", "benches/README.md", "docs/*.md")

_HEADING = re.compile(r"^#{2,4}\s+(\d+(?:\.\d+)*)\.?\s", re.MULTILINE)
_NUM = r"\d+(?:\.\d+)*"
_SEP = r"(?:,\s*|\s+and\s+|\s*[–-]\s*)"
#: A mention of the sheet, with what precedes it (to tell docs/FORMULAS.md from another sheet).
_MENTION = re.compile(r"(?P<prefix>[\w./-]*)FORMULAS\b(?P<ext>\.md)?")
#: The section list right after a mention: optional closing backticks and spaces, then §N[, §M …].
_SECTIONS = re.compile(rf"^`{{0,2}}\s*(?:'s\s+)?(§{_NUM}(?:{_SEP}§?{_NUM})*)")
#: §N inside the sheet itself (not the external "SP 1065 §5.2.16").
_INNER = re.compile(rf"(?<!1065 )§({_NUM})")
_LINK = re.compile(r"!?\[[^\]]*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
_REFLINK = re.compile(r"^\s*\[[^\]]+\]:\s*<?(\S+?)>?(?:\s|$)", re.MULTILINE)


def sheet_sections(text: str) -> set[str]:
    """Section numbers of the sheet's headings ("2", "2.1", …)."""
    return set(_HEADING.findall(text))


def citation_problems(root: Path, sections: set[str], patterns=CITING, skip=()) -> list[str]:
    """Every mention of FORMULAS(.md) under ``root``: it must name docs/FORMULAS.md (a docs/*.md file may
    write FORMULAS.md), and each §N after it must be a section of the sheet."""
    problems = []
    seen: set[Path] = set()
    for pattern in patterns:
        for path in sorted(root.glob(pattern)):
            if path in seen or path.resolve() in skip or "results" in path.relative_to(root).parts:
                continue
            seen.add(path)
            text = path.read_text(encoding="utf-8")
            in_docs = path.parent.resolve() == (root / "docs").resolve()
            for m in _MENTION.finditer(text):
                line = text.count("\n", 0, m.start()) + 1
                where = f"{path.relative_to(root)}:{line}"
                prefix = m.group("prefix")
                if path.resolve() == (root / "docs" / "FORMULAS.md").resolve():
                    continue
                if not m.group("ext") or not (prefix.endswith("docs/") or (in_docs and prefix == "")):
                    problems.append(f"{where}: {prefix}FORMULAS{m.group('ext') or ''} — cite docs/FORMULAS.md")
                    continue
                if prefix not in ("docs/", ""):
                    problems.append(f"{where}: {prefix}FORMULAS.md is not the repository's docs/FORMULAS.md")
                    continue
                cited = _SECTIONS.match(text[m.end() : m.end() + 80])
                if cited:
                    for number in re.findall(_NUM, cited.group(1)):
                        if number not in sections:
                            problems.append(f"{where}: docs/FORMULAS.md §{number} does not exist")
    return problems


def link_problems(root: Path, patterns=LINKING) -> list[str]:
    """Relative Markdown links (inline and reference-style) whose target file does not exist."""
    problems = []
    for pattern in patterns:
        for path in sorted(root.glob(pattern)):
            text = path.read_text(encoding="utf-8")
            for m in list(_LINK.finditer(text)) + list(_REFLINK.finditer(text)):
                target = m.group(1)
                if re.match(r"^[a-z][a-z0-9+.-]*:", target, re.IGNORECASE) or target.startswith("#"):
                    continue  # a URL (http:, mailto:, …) or an anchor in the same page
                file_part = target.split("#", 1)[0].split("?", 1)[0]
                if file_part and not (path.parent / file_part).exists():
                    line = text.count("\n", 0, m.start()) + 1
                    problems.append(f"{path.relative_to(root)}:{line}: link to missing {target}")
    return problems


# --------------------------------------------------------------------------------------------------
# the repository


def test_the_sheet_exists_with_unique_numbered_sections():
    assert SHEET.is_file(), f"{SHEET} is missing"
    text = SHEET.read_text(encoding="utf-8")
    numbers = _HEADING.findall(text)
    assert len(numbers) == len(set(numbers)), f"duplicate section numbers: {numbers}"
    top = [int(n) for n in numbers if "." not in n]
    assert top == list(range(1, len(top) + 1)), f"top-level sections not numbered 1, 2, …: {top}"
    # every subsection belongs to a section that exists
    for n in numbers:
        if "." in n:
            assert n.rsplit(".", 1)[0] in numbers, n


def test_the_sheets_own_section_references_exist():
    text = SHEET.read_text(encoding="utf-8")
    sections = sheet_sections(text)
    missing = sorted({n for n in _INNER.findall(text) if n not in sections})
    assert not missing, f"docs/FORMULAS.md refers to missing sections: {missing}"


def test_every_citation_names_an_existing_section():
    sections = sheet_sections(SHEET.read_text(encoding="utf-8"))
    problems = citation_problems(ROOT, sections, skip={Path(__file__).resolve()})
    assert not problems, "\n".join(problems)


def test_the_package_cites_the_sheet():
    """The sheet is cited from the code (not only from the tests): the check above has work to do."""
    sections = sheet_sections(SHEET.read_text(encoding="utf-8"))
    cited = 0
    for path in (ROOT / "python").rglob("*.py"):
        for m in _MENTION.finditer(path.read_text(encoding="utf-8")):
            text = path.read_text(encoding="utf-8")
            if _SECTIONS.match(text[m.end() : m.end() + 80]):
                cited += 1
    assert cited >= 5 and len(sections) >= 10


def test_relative_links_resolve():
    problems = link_problems(ROOT)
    assert not problems, "\n".join(problems)


# --------------------------------------------------------------------------------------------------
# the checkers themselves, on a made-up tree


@pytest.fixture
def fake_tree(tmp_path: Path) -> Path:
    (tmp_path / "docs").mkdir()
    (tmp_path / "python").mkdir()
    (tmp_path / "docs" / "FORMULAS.md").write_text(
        "# Sheet\n\n## 1. One\n\n### 1.1 Sub\n\n## 2. Two\n", encoding="utf-8"
    )
    (tmp_path / "docs" / "other.md").write_text(
        "See [the sheet](FORMULAS.md) and [gone](missing.md), ![fig](fig.png), [web](https://x.org/a.md), "
        "[anchor](#top), FORMULAS.md §2.\n\n[ref]: ../README.md\n",
        encoding="utf-8",
    )
    (tmp_path / "README.md").write_text("[docs](docs/FORMULAS.md#two) [nope](docs/nope.md)\n", encoding="utf-8")
    (tmp_path / "python" / "mod.py").write_text(
        '"""Good: ``docs/FORMULAS.md`` §1.1 and docs/FORMULAS.md §1, §2; '
        'bad: docs/FORMULAS.md §3, docs/FORMULAS.md §1.2, ../shared/FORMULAS.md §1, FORMULAS §2."""\n',
        encoding="utf-8",
    )
    return tmp_path


def test_citation_checker_flags_what_it_should(fake_tree):
    sections = sheet_sections((fake_tree / "docs" / "FORMULAS.md").read_text(encoding="utf-8"))
    assert sections == {"1", "1.1", "2"}
    problems = citation_problems(fake_tree, sections)
    joined = "\n".join(problems)
    assert "§3 does not exist" in joined and "§1.2 does not exist" in joined
    assert "../shared/FORMULAS.md" in joined and "FORMULAS — cite docs/FORMULAS.md" in joined
    assert len(problems) == 4, joined  # §1.1, §1, §2 and docs/other.md's "FORMULAS.md §2" are fine


def test_link_checker_flags_what_it_should(fake_tree):
    problems = link_problems(fake_tree)
    assert sorted(p.split("link to missing ")[1] for p in problems) == ["docs/nope.md", "fig.png", "missing.md"]
