"""The numpydoc Examples of the public API run as doctests.

Every public function and class of ``ti_spinorbit.__all__`` (and the two public modules,
``catalog`` and ``analytic``) has an Examples section in its docstring, and every example in
those docstrings (methods of the classes included) runs and prints what it shows, with
``doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE``. The examples are tiny on purpose: objects
built and inspected, and runs of a few members over a few orbits, so the file runs in well
under a minute once Taichi has compiled its kernels (the first run of each kernel variant
compiles it, about a second each on 2 cores, or loads it from the offline cache). Examples
that write files write them into a temporary folder (the working directory of each test).
"""

import doctest
import inspect

import numpy as np
import pytest

import ti_spinorbit as tso

#: Names of ti_spinorbit.__all__ that are neither a function, a class nor a module (numbers):
#: their meaning is in the docs of what uses them.
NOT_DOCUMENTABLE = {"__version__", "G"}
NAMES = [name for name in tso.__all__ if name not in NOT_DOCUMENTABLE]
OPTIONS = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE


def _doctests(name):
    """The doctests of one public name: its docstring, and for a class or a module, those of
    the methods and functions it defines."""
    obj = getattr(tso, name)
    finder = doctest.DocTestFinder(exclude_empty=True)
    module = obj if inspect.ismodule(obj) else inspect.getmodule(obj)
    return finder.find(obj, f"ti_spinorbit.{name}", module=module,
                       globs={"np": np, "tso": tso})


@pytest.mark.parametrize("name", NAMES)
def test_every_public_name_has_examples(name):
    doc = inspect.getdoc(getattr(tso, name)) or ""
    assert "\nExamples\n--------\n" in doc, f"ti_spinorbit.{name}: add a numpydoc Examples section"
    assert any(t.examples for t in _doctests(name)), f"ti_spinorbit.{name}: no >>> example"


@pytest.fixture
def in_tmp(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    return tmp_path


@pytest.mark.parametrize("name", NAMES)
def test_the_examples_run(name, in_tmp):
    runner = doctest.DocTestRunner(optionflags=OPTIONS)
    out = []
    for test in _doctests(name):
        runner.run(test, out=out.append)
    result = runner.summarize(verbose=False)
    assert result.failed == 0, "".join(out)[-6000:]
