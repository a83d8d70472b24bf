"""The Examples sections of the core's docstrings run as doctests.

The modules are imported by their package names (``texsynth.metrics``, ...), whatever the
checkout's folder is called: pytest's ``--doctest-modules`` would name them after the folder,
which holds the extension's own ``__init__.py``.
"""

import doctest
import importlib
import pkgutil

import pytest

import texsynth

MODULES = sorted(m.name for m in pkgutil.walk_packages(texsynth.__path__, "texsynth."))


def test_the_core_has_examples_to_run():
    examples = sum(len(doctest.DocTestFinder().find(importlib.import_module(name)))
                   for name in MODULES)
    assert examples > 0


@pytest.mark.parametrize("name", MODULES)
def test_examples(name):
    result = doctest.testmod(importlib.import_module(name), optionflags=doctest.ELLIPSIS)
    assert result.failed == 0, f"{result.failed} of {result.attempted} examples failed in {name}"
