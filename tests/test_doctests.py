"""The ``>>>`` examples of pyoa's docstrings, run as tests.

One mechanism for every module with examples: :func:`doctest.testmod` on the
module (its docstring and those of everything defined in it). Examples are
deterministic (fixed seeds, ``backend="numpy"`` where the default backend
would make the run depend on the OpenCL device) and use per-example
directives (``# doctest: +ELLIPSIS``) where they need any.

A module listed here must keep at least ``MIN_EXAMPLES`` examples, so that
examples lost by a docstring edit (or a module shadowed by a function of the
same name: ``pyoa.samplers`` is also a function) do not pass unnoticed.
"""

from __future__ import annotations

import doctest
import importlib
import io

import pytest

#: module -> the fewest examples it must have
MIN_EXAMPLES = {
    "pyoa.samplers": 5,
    "pyoa.catalogue": 2,
    "pyoa.hashes": 1,
    "pyoa.analysis": 7,
    "pyoa.analysis.pointsets": 4,
    "pyoa.analysis.integrands": 4,
    "pyoa.analysis.rates": 2,
    "pyoa.analysis.spectra": 3,
    "pyoa.analysis.statistics": 12,
    "pyoa.analysis._display": 2,
    "pyoa.qmc": 20,
}


def run_doctests(module_name: str) -> tuple[doctest.TestResults, str]:
    """Run one module's examples; return the results and the failure report."""
    # importlib, not attribute access: pyoa.samplers is shadowed by pyoa's function samplers()
    module = importlib.import_module(module_name)
    out = io.StringIO()
    runner = doctest.DocTestRunner(verbose=False)
    for test in doctest.DocTestFinder().find(module, module_name):
        runner.run(test, out=out.write)
    return doctest.TestResults(runner.failures, runner.tries), out.getvalue()


@pytest.mark.parametrize("module_name", sorted(MIN_EXAMPLES))
def test_docstring_examples(module_name):
    res, report = run_doctests(module_name)
    assert res.failed == 0, f"{res.failed} of {res.attempted} examples of {module_name} failed:\n{report}"
    assert res.attempted >= MIN_EXAMPLES[module_name], (
        f"{module_name} has {res.attempted} docstring examples, expected at least {MIN_EXAMPLES[module_name]}"
    )
