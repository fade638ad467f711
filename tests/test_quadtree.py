"""lfqt.quadtree: the split table of the LFQT against its definition on
random sets of both widths, including negative coordinates, -0.0 and
duplicates."""
import numpy as np
import pytest
from hypothesis import given, strategies as st

import lfqt

coords = st.floats(-1e6, 1e6, allow_nan=False, allow_infinity=False, width=32)


def _check(points):
    tree = lfqt.quadtree(points)
    n = len(points)
    nodes = tree.nodes
    assert sorted(tree.order) == list(range(n))
    P = np.asarray(points, dtype=np.float64)[tree.order]
    m = len(nodes["bit"])
    distinct = len({(float(a) + 0.0, float(b) + 0.0) for a, b in points})
    assert m == distinct - 1  # a binary tree over the distinct points
    if m:
        assert nodes["depth"][-1] == 0 and nodes["parent"][-1] == -1
        assert (nodes["hi"][-1], nodes["lo"][-1]) == (n, 0)
    for k in range(m):
        lo, split, hi = nodes["lo"][k], nodes["split"][k], nodes["hi"][k]
        assert lo < split < hi
        cell = P[lo:hi]
        assert (cell[:, 0] >= nodes["x0"][k]).all() and (cell[:, 0] <= nodes["x1"][k]).all()
        assert (cell[:, 1] >= nodes["y0"][k]).all() and (cell[:, 1] <= nodes["y1"][k]).all()
        c = P[:, nodes["axis"][k]]
        cut = nodes["cut"][k]
        assert (c[lo:split] < cut).all() and (c[split:hi] >= cut).all()
        assert nodes["axis"][k] == (0 if nodes["bit"][k] % 2 else 1)
        assert nodes["level"][k] == nodes["bit"][k] + 1
        p = nodes["parent"][k]
        if p >= 0:  # a child's cell lies in its parent's and splits at a lower bit
            assert p > k and nodes["bit"][p] > nodes["bit"][k]
            assert nodes["depth"][k] == nodes["depth"][p] + 1
            assert nodes["x0"][p] <= nodes["x0"][k] and nodes["x1"][k] <= nodes["x1"][p]
            assert nodes["y0"][p] <= nodes["y0"][k] and nodes["y1"][k] <= nodes["y1"][p]
    return tree


@given(st.lists(st.tuples(coords, coords), min_size=1, max_size=60))
def test_split_table_float32(pts):
    _check(np.array(pts, dtype=np.float32))


@given(st.lists(st.tuples(st.floats(-1e300, 1e300), st.floats(-1e300, 1e300)), min_size=1,
                max_size=60))
def test_split_table_float64(pts):
    _check(np.array(pts, dtype=np.float64))


def test_quadrants_split_on_sign_bits_first():
    pts = np.array([[-1, -1], [1, -1], [-1, 1], [1, 1], [0.5, 0.25]], dtype=np.float32)
    tree = _check(pts)
    root = -1
    assert tree.nodes["field"][root] == "sign" and tree.nodes["level"][root] == 64
    assert tree.nodes["cut"][root] == 0.0 and tree.nodes["axis"][root] == 0


@pytest.mark.parametrize("dtype,fields", [(np.float32, (23, 31)), (np.float64, (52, 63))])
def test_bit_fields(dtype, fields):
    """Exponent splits separate powers of two; mantissa splits stay inside one."""
    pts = np.array([[0.75, 1.0], [1.5, 1.0], [1.25, 1.0]], dtype=dtype)
    tree = _check(pts)
    f = dict(zip(tree.nodes["cut"], tree.nodes["field"]))
    assert f[1.0] == "exponent" and f[1.5] == "mantissa"
