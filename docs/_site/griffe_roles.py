"""A Griffe extension for the site's API reference: the docstrings are numpydoc with Sphinx roles
(``:func:`avar```), which mkdocstrings shows verbatim. Each role becomes a link to the object's entry when the
reference renders it (a public, documented object), else inline code; each ``docs/FORMULAS.md §N`` becomes
a link to that section of the formula sheet. The docstrings themselves are unchanged (``help()`` shows them
as written; ``tests/test_docs.py`` checks the citations).
"""

from __future__ import annotations

import re
import sys
from pathlib import Path
from typing import Any

import griffe
from markdown.extensions.toc import slugify

sys.path.insert(0, str(Path(__file__).resolve().parent))
import api  # noqa: E402  (docs/_site/api.py, beside this file)

SHEET = Path(__file__).resolve().parents[1] / "FORMULAS.md"
_ROLE = re.compile(r":(?:func|class|mod|meth|attr|data|obj|exc):`(~?)([^`<]+?)(?:\s*<([^>]+)>)?`")
_CITE = re.compile(r"``?docs/FORMULAS\.md``?(\s*)§(\d+(?:\.\d+)*)|docs/FORMULAS\.md(\s*)§(\d+(?:\.\d+)*)")
_HEADING = re.compile(r"^#{2,4}\s+((\d+(?:\.\d+)*)\.?\s.*)$", re.MULTILINE)


def sheet_anchors(text: str) -> dict[str, str]:
    """Section number → the heading's anchor in the site (Python-Markdown's toc slug)."""
    return {m.group(2): slugify(m.group(1).strip(), "-") for m in _HEADING.finditer(text)}


def fill_effects(text: str) -> str:
    """A docstring's ``{effects}`` line (``refine``'s ``candidates``) as the effects registry's list, indented as
    that line: the list ``help(refine)`` shows, filled at import time (``model/refinement/loop.py``), which a
    static read of the source does not see. Reads the registry from the installed package."""
    line = next((ln for ln in text.splitlines() if ln.strip() == "{effects}"), None)
    if line is None:
        return text
    from allanite.model.effects import describe  # the registry: what refine tries, at run time

    return text.replace(line, describe(line[: len(line) - len(line.lstrip())]))


class SphinxRoles(griffe.Extension):
    """Rewrite roles and formula-sheet citations in every docstring, once the package is loaded."""

    def __init__(self) -> None:
        self.anchors = sheet_anchors(SHEET.read_text(encoding="utf-8"))

    def on_package(self, *, pkg: griffe.Module, loader: griffe.GriffeLoader, **kwargs: Any) -> None:
        if pkg.path == api.PACKAGE:
            self.ref = api.reference(pkg)
            self._walk(pkg, loader)

    def _walk(self, obj: griffe.Object, loader: griffe.GriffeLoader) -> None:
        if obj.docstring is not None:
            obj.docstring.value = self.rewrite(fill_effects(obj.docstring.value), obj, loader)
        for member in obj.members.values():
            if not member.is_alias:
                self._walk(member, loader)

    def rewrite(self, text: str, obj: griffe.Object, loader: griffe.GriffeLoader) -> str:
        """The docstring with its roles and citations as links (or inline code where nothing renders)."""

        def role(m: re.Match) -> str:
            shown = m.group(2).strip()
            target = (m.group(3) or shown).strip().rstrip("()")
            label = shown.rsplit(".", 1)[-1] if m.group(1) else shown
            anchor = self._resolve(target, obj, loader)
            return f"[`{label}`][{anchor}]" if anchor else f"`{label}`"

        def cite(m: re.Match) -> str:
            number = m.group(2) or m.group(4)
            anchor = self.anchors.get(number)
            return f"[docs/FORMULAS.md §{number}][{anchor}]" if anchor else m.group(0)

        return _CITE.sub(cite, _ROLE.sub(role, text))

    def _resolve(self, target: str, obj: griffe.Object, loader: griffe.GriffeLoader) -> str | None:
        """The anchor of the entry documenting what a role names, if the reference has one."""
        module = obj.module
        scopes = [obj, obj.parent, module, module.package] if obj.parent is not None else [obj, module]
        candidates = [target] + [f"{s.path}.{target}" for s in scopes if s is not None]
        for path in candidates:
            try:
                found = loader.modules_collection.get_member(path)
                final = found.final_target if found.is_alias else found
            except (KeyError, ValueError, AttributeError, griffe.AliasResolutionError, griffe.CyclicAliasError):
                continue
            if final.is_module:
                return final.path if not any(p.startswith("_") for p in final.path.split(".")) else None
            return self.ref.anchor_of.get(final.path)
        return None
