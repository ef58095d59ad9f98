"""Functions stay short: no body over 80 lines in the package or the benches, read from the source (AST).

The brief: "Functions stay short (≲ 80 lines) and modules small — split as you go." A function's
length here is its body without the docstring: from the first statement after the docstring to the
function's last line (comments and blank lines inside count; the signature and the docstring do not).
Nested functions and methods are measured on their own and also count inside their parent.
Every module under ``python/allanite`` is walked and nothing there is allowed over the limit; the
benchmark scripts under ``benches/`` are held to the same limit, with the one exception listed below.
Modules of the package stay at most 600 lines (every line counts: docstrings, comments, blank lines).
"""

from __future__ import annotations

import ast
import textwrap
from pathlib import Path

import pytest

import allanite

PACKAGE = Path(allanite.__file__).parent
BENCHES = Path(__file__).resolve().parents[1] / "benches"
LIMIT = 80
MODULE_LIMIT = 600
#: benchmark functions still over the limit, each with the reason it was not split
BENCH_ALLOWED = {
    # 95 lines; left whole on 2026-11-27 while the regression on slow channels (issue 29, item 1) is reworked
    # with this bench as its null check — split it (null records, power, summary, page) once that has landed
    "regression_null.py:main",
}


def _body_lines(node: ast.FunctionDef | ast.AsyncFunctionDef) -> int:
    """Lines of ``node``'s body without its docstring (0 for a body that is only a docstring)."""
    body = node.body
    first = body[0]
    if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant):
        if isinstance(first.value.value, str):
            body = body[1:]
    if not body:
        return 0
    end = node.end_lineno
    assert end is not None
    return end - body[0].lineno + 1


def _long_functions(source: str, limit: int = LIMIT) -> list[tuple[str, int, int]]:
    """(qualified name, first line, body lines) of each function in ``source`` longer than ``limit``."""
    found: list[tuple[str, int, int]] = []

    def walk(node: ast.AST, prefix: str) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = _body_lines(child)
                if n > limit:
                    found.append((prefix + child.name, child.lineno, n))
                walk(child, prefix + child.name + ".")
            elif isinstance(child, ast.ClassDef):
                walk(child, prefix + child.name + ".")
            else:
                walk(child, prefix)

    walk(ast.parse(source), "")
    return found


def test_the_measure_counts_the_body_without_the_docstring() -> None:
    # A docstring of 100 lines and a body of exactly 80 pass; one line more fails, and the
    # offender is named with its line and length (also as a method and as a nested function).
    doc = '    """' + "\n".join(["x"] * 100) + '"""\n'
    body80 = "".join(f"    a{i} = {i}\n" for i in range(80))
    ok = "def f():\n" + doc + body80
    assert _long_functions(ok) == []
    long = ok + "    return a0\n"
    assert _long_functions(long) == [("f", 1, 81)]
    method = "class C:\n" + textwrap.indent(long, "    ")
    assert _long_functions(method) == [("C.f", 2, 81)]
    nested = "def outer():\n" + textwrap.indent(long, "    ") + "    return f\n"
    assert _long_functions(nested) == [("outer", 1, 183), ("outer.f", 2, 81)]


def test_no_library_function_is_over_80_lines() -> None:
    modules = sorted(PACKAGE.rglob("*.py"))
    assert len(modules) > 50  # the walk reaches the whole package, not an empty folder
    offenders = [
        f"{path.relative_to(PACKAGE)}:{line} {name} ({n} lines)"
        for path in modules
        for name, line, n in _long_functions(path.read_text(encoding="utf-8"))
    ]
    assert offenders == [], "split these into well-named helpers:\n" + "\n".join(offenders)


def test_no_bench_function_is_over_80_lines_but_the_allowed() -> None:
    scripts = sorted(BENCHES.glob("*.py"))
    if not scripts:
        pytest.skip(f"no benchmark scripts beside the tests ({BENCHES}): an installed package's tests")
    found = {
        f"{path.name}:{name}": n
        for path in scripts
        for name, _line, n in _long_functions(path.read_text(encoding="utf-8"))
    }
    over = sorted(f"{k} ({n} lines)" for k, n in found.items() if k not in BENCH_ALLOWED)
    assert over == [], "split these into well-named helpers:\n" + "\n".join(over)
    # an allowance that is no longer needed is dropped, so the list says only what is true
    assert sorted(BENCH_ALLOWED - set(found)) == []


def test_no_library_module_is_over_600_lines() -> None:
    # The brief: modules small (≲ 600 lines). A module that grows past it is split by concern first.
    sizes = {path: len(path.read_text(encoding="utf-8").splitlines()) for path in PACKAGE.rglob("*.py")}
    assert len(sizes) > 50 and max(sizes.values()) > MODULE_LIMIT // 2  # the walk reads real modules
    over = sorted(f"{p.relative_to(PACKAGE)} ({n} lines)" for p, n in sizes.items() if n > MODULE_LIMIT)
    assert over == [], "split these modules by concern:\n" + "\n".join(over)
