"""The public API, read with Griffe from the source (nothing is imported): what the site's API reference
shows, and what the docstring-coverage test checks (``tests/test_site.py``), so the two cannot disagree.

Public follows Griffe, as mkdocstrings renders it: a module none of whose dotted parts starts with ``_``;
in it, the names in its ``__all__`` or, without one, the names it defines that do not start with ``_``; in a
public class, the methods and properties it defines that do not start with ``_``. A public name re-exported
by a package (``allanite.fit``) is documented once, where it is defined when that module offers it, else on
the package's page.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import griffe

PACKAGE = "allanite"
SRC = Path(__file__).resolve().parents[2] / "python"


def load(src: Path = SRC) -> griffe.Module:
    """The package as Griffe sees it (numpydoc docstrings)."""
    extensions = griffe.load_extensions("griffe_sphinx")
    return griffe.load(
        PACKAGE, search_paths=[str(src)], docstring_parser="numpy", resolve_aliases=True, extensions=extensions
    )


def public_modules(pkg: griffe.Module) -> list[griffe.Module]:
    """The package and its public modules, depth first in name order."""
    out = [pkg]
    for name, member in sorted(pkg.members.items()):
        if not member.is_alias and member.is_module and not name.startswith("_") and name != "__main__":
            out += public_modules(member)
    return out


def _target(member: griffe.Object | griffe.Alias) -> griffe.Object | None:
    """The object itself, or what an alias points at (None when outside the package's reach)."""
    try:
        return member.final_target if member.is_alias else member
    except (griffe.AliasResolutionError, griffe.CyclicAliasError):
        return None


@dataclass
class Reference:
    """Where each public object is documented: the anchor (a dotted path) of its entry and that entry's page."""

    anchor_of: dict[str, str] = field(default_factory=dict)  # object's own path -> anchor of its entry
    page_of: dict[str, str] = field(default_factory=dict)  # anchor -> module whose page holds it
    extra: dict[str, list[str]] = field(default_factory=dict)  # package -> re-exports shown on its page
    names: dict[str, dict[str, str]] = field(default_factory=dict)  # package -> {re-exported name: anchor}

    def _add(self, path: str, anchor: str, page: str) -> None:
        self.anchor_of[path] = anchor
        self.page_of[anchor] = page


def reference(pkg: griffe.Module) -> Reference:
    """Decide the entry of every public object: a defined name on its module's page; a re-export links there
    or, when the defining module does not offer it (a private module), gets its entry on the package's page."""
    ref = Reference()
    modules = public_modules(pkg)
    for module in modules:
        for member in module.members.values():
            if not member.is_alias and not member.is_module and member.is_public and member.docstring:
                ref._add(member.path, member.path, module.path)
                if member.is_class:
                    for name, sub in member.members.items():
                        if not sub.is_alias and not name.startswith("_") and sub.docstring:
                            ref._add(sub.path, sub.path, module.path)
    for module in modules:
        for name, member in module.members.items():
            target = _target(member) if member.is_alias and member.is_public else None
            if target is None or target.is_module or not target.docstring:
                continue
            if target.path not in ref.anchor_of:
                ref._add(target.path, member.path, module.path)
                ref.extra.setdefault(module.path, []).append(name)
                if target.is_class:
                    for sub_name, sub in target.members.items():
                        if not sub.is_alias and not sub_name.startswith("_") and sub.docstring:
                            ref._add(sub.path, f"{member.path}.{sub_name}", module.path)
            ref.names.setdefault(module.path, {})[name] = ref.anchor_of[target.path]
    return ref


def public_objects(pkg: griffe.Module) -> list[griffe.Object]:
    """Every public module, module-level object and class method/property, each once (aliases resolved)."""
    seen: dict[str, griffe.Object] = {}
    for module in public_modules(pkg):
        seen[module.path] = module
        for member in module.members.values():
            obj = _target(member) if member.is_public else None
            if obj is None or obj.is_module or not obj.path.startswith(PACKAGE + "."):
                continue
            seen[obj.path] = obj
            if obj.is_class:
                for name, sub in obj.members.items():
                    if not sub.is_alias and not name.startswith("_") and (sub.is_function or "property" in sub.labels):
                        seen[sub.path] = sub
    return list(seen.values())


def undocumented(pkg: griffe.Module) -> list[str]:
    """Dotted paths of the public objects that have no docstring."""
    return sorted(o.path for o in public_objects(pkg) if not (o.docstring and o.docstring.value.strip()))


# --------------------------------------------------------------------------------------------------
# the generated pages


def _page_file(module: str) -> str:
    return "index.md" if module == PACKAGE else f"{module}.md"


def _entries(package: str, ref: Reference) -> list[str]:
    """The entries of re-exports whose defining module is private, on the package's page."""
    lines: list[str] = []
    for name in ref.extra.get(package, []):
        lines += [
            "",
            f"::: {package}.{name}",
            "    options:",
            "      heading_level: 3",
            "      show_root_full_path: true",
        ]
    return lines


def _summary(obj: griffe.Object | griffe.Alias) -> str:
    """The docstring's first sentence, for a table cell."""
    text = (obj.docstring.value if obj.docstring else "").strip().split("\n\n")[0]
    text = re.sub(r":\w+:`~?([^`]+)`", r"`\1`", " ".join(text.split()))
    return text.replace("|", "\\|")


def _table(package: griffe.Module, links: dict[str, str], ref: Reference) -> list[str]:
    rows = ["| name | what | documented in |", "|---|---|---|"]
    for name, anchor in links.items():
        page = ref.page_of[anchor]
        what = _summary(_target(package.members[name]) or package.members[name])
        rows.append(f"| [`{name}`][{anchor}] | {what} | [`{page}`]({_page_file(page)}) |")
    return rows


def index_page(pkg: griffe.Module, ref: Reference) -> str:
    """The reference's front page: the package's docstring, every top-level name, every module."""
    lines = [
        "# API reference",
        "",
        "Generated from the docstrings (numpydoc); `help()` shows the same text in Python.",
        "",
        f"::: {PACKAGE}",
        "    options:",
        "      members: false",
        "      show_root_heading: false",
        "",
        f"## `import {PACKAGE}`",
        "",
    ]
    lines += _table(pkg, ref.names.get(PACKAGE, {}), ref)
    lines += _entries(PACKAGE, ref)
    lines += ["", "## Modules", ""]
    lines += [f"- [`{m.path}`]({m.path}.md)" for m in public_modules(pkg)[1:]]
    return "\n".join(lines) + "\n"


def module_page(module: griffe.Module, ref: Reference) -> str:
    """A module's page: its docstring and members; a package's: its docstring, names and modules."""
    lines = [f"# `{module.path}`", "", f"::: {module.path}", "    options:", "      show_root_heading: false"]
    if not module.is_package:
        return "\n".join(lines) + "\n"
    lines += ["      members: false", ""]
    links = ref.names.get(module.path, {})
    if links:
        lines += _table(module, links, ref) + [""]
    lines += _entries(module.path, ref) + [""]
    subs = [m for m in public_modules(module)[1:] if m.parent is module]
    if subs:
        lines += ["## Modules", ""] + [f"- [`{m.path}`]({m.path}.md)" for m in subs]
    return "\n".join(lines) + "\n"


def pages(pkg: griffe.Module) -> dict[str, str]:
    """Every generated page: site path → Markdown."""
    ref = reference(pkg)
    out = {"api/index.md": index_page(pkg, ref)}
    for module in public_modules(pkg)[1:]:
        out[f"api/{module.path}.md"] = module_page(module, ref)
    return out
