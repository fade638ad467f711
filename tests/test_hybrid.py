"""lfqt.dc.hybrid: insertion in the LFQT's cells, merged above by the
divide and conquer.  Every mesh is verified exactly; in general position it
equals the divide and conquer's; the thread count never changes it."""
import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import lfqt
from conftest import triangle_set, triangulate_verified
from test_dc import fixtures

LEAVES = [3, 8, 64, 4096]


@pytest.mark.parametrize("name,points", sorted(fixtures().items()))
@pytest.mark.parametrize("leaf", LEAVES)
def test_hostile_fixtures_verify(name, points, leaf):
    for order in ("hilbert", "kdtree"):
        triangulate_verified(points, method="hybrid", leaf_size=leaf, leaf_order=order)


@pytest.mark.parametrize("leaf", [4, 32, 1024])
def test_equals_divide_and_conquer_in_general_position(leaf, rng):
    pts = rng.random((20_000, 2))
    hyb = triangulate_verified(pts, method="hybrid", leaf_size=leaf)
    assert triangle_set(hyb.simplices) == triangle_set(triangulate_verified(pts).simplices)
    assert hyb.stats["method"] == "hybrid" and hyb.stats["bins"] > 1 or leaf >= 20_000
    two = triangulate_verified(pts, method="hybrid", leaf_size=leaf, threads=2)
    assert np.array_equal(two.simplices, hyb.simplices)  # identical, not just equal as sets


coord = st.integers(-8, 8)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(coord, coord), min_size=1, max_size=120), st.sampled_from(LEAVES))
def test_tie_heavy_integer_sets_verify(pts, leaf):
    """Grids with duplicates and collinear bins (which fall back to the
    divide and conquer's merges)."""
    triangulate_verified(np.array(pts, dtype=np.float64), method="hybrid", leaf_size=leaf)


def test_bad_arguments_are_refused():
    pts = np.random.default_rng(0).random((10, 2))
    with pytest.raises(ValueError, match="method"):
        lfqt.triangulate(pts, method="sweep")
    with pytest.raises(ValueError, match="leaf_size"):
        lfqt.triangulate(pts, method="hybrid", leaf_size=0)
    with pytest.raises(ValueError, match="leaf_order"):
        lfqt.triangulate(pts, method="hybrid", leaf_order="brio")
    with pytest.raises(ValueError, match="subdivision"):
        lfqt.triangulate(pts, method="hybrid", subdivision="alternating")
