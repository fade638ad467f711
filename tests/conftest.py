import os
import re

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

import lfqt
import lfqt.preload

# the import's kernel loading ends with a release of the pool's idle memory:
# done before any test looks at the pool
lfqt.preload.wait()

settings.register_profile("ci", max_examples=60, deadline=None,
                          suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("dev", max_examples=200, deadline=None,
                          suppress_health_check=[HealthCheck.too_slow])
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))


def verified(build, points, **kwargs):
    """Build a mesh with ``build`` and verify it exactly; every mesh a test
    builds goes through here."""
    tri = build(points, **kwargs)
    report = lfqt.verify(points, tri)
    assert report.ok, report.problems
    return tri


def triangulate_verified(points, **kwargs):
    return verified(lfqt.triangulate, points, **kwargs)


def insert_verified(points, **kwargs):
    return verified(lfqt.insert, points, **kwargs)


def without_cell(tri, k):
    """A copy of ``tri`` with cell k removed and neighbours renumbered (a hole)."""
    import copy
    keep = np.ones(len(tri.simplices), bool)
    keep[k] = False
    remap = np.cumsum(keep) - 1
    nb = tri.neighbors[keep].copy()
    nb = np.where(nb == k, -1, np.where(nb >= 0, remap[np.maximum(nb, 0)], -1))
    out = copy.copy(tri)
    out.simplices, out.neighbors = tri.simplices[keep], nb
    return out


def triangle_set(simplices):
    """Triangles as a set of vertex triples independent of rotation."""
    out = set()
    for a, b, c in np.asarray(simplices):
        k = int(np.argmin((a, b, c)))
        rot = (a, b, c)[k:] + (a, b, c)[:k]
        out.add(tuple(int(v) for v in rot))
    return out


def smaps_entry(arr):
    """(resident kB, VmFlags) of the mapping that holds arr, from Linux's
    smaps; None where that is not available."""
    start = arr.__array_interface__["data"][0]
    try:
        text = open("/proc/self/smaps").read()
    except OSError:
        return None
    for m in re.finditer(r"^([0-9a-f]+)-([0-9a-f]+) .*?\nRss:\s+(\d+) kB.*?\nVmFlags:([^\n]*)",
                         text, re.M | re.S):
        lo, hi = int(m.group(1), 16), int(m.group(2), 16)
        if lo <= start < hi:
            return int(m.group(3)), m.group(4).split()
    return None


@pytest.fixture
def rng():
    return np.random.default_rng(12345)


@pytest.fixture(scope="session")
def smoke_results(tmp_path_factory):
    """The main job at smoke scale, run once per session: (results root of
    the smoke scale, everything it printed)."""
    import contextlib
    import io

    from experiments import all as all_experiments
    out = tmp_path_factory.mktemp("main_job")
    text = io.StringIO()
    with contextlib.redirect_stdout(text):
        assert all_experiments.main(["--scale", "smoke", "--out", str(out), "--quiet"]) == 0
    return out / "smoke", text.getvalue()


@pytest.hookimpl(trylast=True)  # after -k and -m have deselected
def pytest_collection_modifyitems(config, items):
    """Start test_bounds' child run now when it is selected, and move the
    test that waits for it to the end: the child then runs on the second
    core beside the suite instead of after it."""
    bounds = [item for item in items if item.name == "test_kernels_stay_inside_their_arrays"]
    for item in bounds:
        items.remove(item)
        items.append(item)
        item.module.start(config)
