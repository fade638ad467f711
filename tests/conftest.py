import os

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

import lfqt

settings.register_profile("ci", max_examples=60, deadline=None,
                          suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("dev", max_examples=200, deadline=None,
                          suppress_health_check=[HealthCheck.too_slow])
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))


def triangulate_verified(points, **kwargs):
    """Triangulate and exactly verify; every mesh a test builds goes through here."""
    tri = lfqt.triangulate(points, **kwargs)
    report = lfqt.verify(points, tri)
    assert report.ok, report.problems
    return tri


def triangle_set(simplices):
    """Triangles as a set of vertex triples independent of rotation."""
    out = set()
    for a, b, c in np.asarray(simplices):
        k = int(np.argmin((a, b, c)))
        rot = (a, b, c)[k:] + (a, b, c)[:k]
        out.add(tuple(int(v) for v in rot))
    return out


@pytest.fixture
def rng():
    return np.random.default_rng(12345)
