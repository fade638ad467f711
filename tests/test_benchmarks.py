"""The asv benchmarks (benchmarks/benchmarks.py) run: every method of every
class once, at small sizes (track values finite and not negative), so that
a renamed API or argument breaks a test rather than a long ``asv run``.
TimeCompile is left out: it compiles the library in a fresh interpreter
with a cold cache (measured by bench_dc)."""
import itertools
import math

import pytest

from benchmarks import benchmarks as B

SMALL = 3000  # stands in for every size parameter


def _small(value):
    return SMALL if isinstance(value, int) and value >= 1000 else value


def _classes():
    return [c for name, c in vars(B).items()
            if isinstance(c, type) and c.__module__ == B.__name__ and name != "TimeCompile"]


def _cases(cls):
    params = getattr(cls, "params", [])
    if params and not isinstance(params[0], list):
        params = [params]
    combos = itertools.product(*params) if params else [()]
    seen = []
    for combo in combos:
        small = tuple(_small(v) for v in combo)
        if small not in seen:
            seen.append(small)
    return seen


@pytest.mark.parametrize("cls", _classes(), ids=lambda c: c.__name__)
def test_every_benchmark_method_runs(cls):
    methods = [m for m in dir(cls) if m.split("_")[0] in ("time", "peakmem", "track")]
    assert methods, cls
    ran = 0
    for args in _cases(cls):
        bench = cls()
        try:
            if hasattr(bench, "setup"):
                bench.setup(*args)
        except NotImplementedError:  # asv's way to skip a combination
            continue
        for name in methods:
            value = getattr(bench, name)(*args)
            if name.startswith("track_"):
                assert isinstance(value, (int, float)) and math.isfinite(value) and value >= 0, \
                    (name, args, value)
            ran += 1
    assert ran > 0
