"""The Examples sections of the public docstrings run, as a user would
paste them: each example imports what it uses (empty globals)."""
import doctest
import importlib

import pytest

# Modules whose docstrings have Examples; each must run at least one.
# lfqt.distributed's start a Dask cluster: tests/test_distributed.py runs
# the ones that need none.
MODULES_WITH_EXAMPLES = ["lfqt.dc", "lfqt.dc.quadtree", "lfqt.incremental", "lfqt.orders",
                         "lfqt.triangulation", "lfqt.verification", "lfqt.delaunay",
                         "lfqt.workspace", "lfqt.interpolate", "lfqt.natural"]
OPTIONS = doctest.NORMALIZE_WHITESPACE


@pytest.mark.parametrize("name", MODULES_WITH_EXAMPLES)
def test_examples_run(name):
    module = importlib.import_module(name)
    failed, attempted = doctest.testmod(module, globs={}, optionflags=OPTIONS, report=False)
    assert attempted > 0, f"{name} has no examples: take it off MODULES_WITH_EXAMPLES"
    assert failed == 0, f"{failed} of {attempted} examples of {name} failed (output above)"
