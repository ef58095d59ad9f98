"""Every module's docstring examples run and print what they claim (the same as
``pytest --doctest-modules --pyargs allanite``, kept here so the plain test command runs them)."""

import doctest
import importlib
import pkgutil

import pytest

import allanite

MODULES = sorted(m.name for m in pkgutil.walk_packages(allanite.__path__, "allanite.") if m.name != "allanite.__main__")


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name):
    module = importlib.import_module(name)
    failures, _ = doctest.testmod(module, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert failures == 0


def test_the_public_entry_points_have_examples():
    for name in (
        "avar",
        "davar",
        "tau_grid",
        "fit",
        "refine",
        "confidence_intervals",
        "identify_alpha",
        "information_bound",
        "simulate",
        "default_record",
    ):
        assert ">>>" in (getattr(allanite, name).__doc__ or ""), f"allanite.{name} has no example"
