import numpy as np
import pytest
import scipy.spatial

import lfqt
from conftest import triangle_set, triangulate_verified


def test_accepts_lists_and_integer_arrays():
    tri = triangulate_verified([[0, 0], [4, 0], [0, 3], [5, 5]])
    assert len(tri.simplices) == 2
    triangulate_verified(np.array([[0, 0], [2 ** 53, 0], [0, 1]], dtype=np.int64))
    triangulate_verified(np.array([[0, 0], [2 ** 60, 0], [0, 1]], dtype=np.int64))  # exact


@pytest.mark.parametrize("layout", ["fortran", "every_other_row", "wider_array", "float32_strided"])
def test_non_contiguous_input_gives_the_contiguous_result(layout, rng):
    pts = rng.random((3000, 2))
    view = {"fortran": lambda: np.asfortranarray(pts),
            "every_other_row": lambda: pts[::2],
            "wider_array": lambda: np.c_[pts, pts[:, :1]][:, :2],
            "float32_strided": lambda: pts.astype(np.float32)[::3]}[layout]()
    assert not view.flags["C_CONTIGUOUS"]
    tri = triangulate_verified(view)
    assert triangle_set(tri.simplices) == triangle_set(
        triangulate_verified(np.ascontiguousarray(view)).simplices)


def test_rejects_integers_that_are_not_exact_in_float64():
    with pytest.raises(ValueError, match="not exactly representable.*first is row 1"):
        lfqt.triangulate(np.array([[0, 0], [2 ** 53 + 1, 0], [0, 1]], dtype=np.int64))


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_rejects_nan_and_inf_naming_count_and_first_row(bad):
    pts = np.random.default_rng(0).random((10, 2))
    pts[3, 1] = bad
    pts[7, 0] = bad
    with pytest.raises(ValueError, match="2 rows; the first is row 3"):
        lfqt.triangulate(pts)


@pytest.mark.parametrize("shape", [(5,), (5, 3), (2, 2, 2)])
def test_rejects_wrong_shape(shape):
    with pytest.raises(ValueError, match="shape"):
        lfqt.triangulate(np.zeros(shape))


def test_rejects_non_numeric():
    with pytest.raises(TypeError):
        lfqt.triangulate(np.array([["a", "b"]]))


def test_rejects_magnitudes_too_far_apart():
    with pytest.raises(ValueError, match="binades"):
        lfqt.triangulate(np.array([[1e300, 0.0], [0.0, 1e-300], [1.0, 1.0]]))


def test_rejects_bad_options():
    pts = np.random.default_rng(0).random((10, 2))
    with pytest.raises(ValueError):
        lfqt.triangulate(pts, subdivision="quick")
    with pytest.raises(ValueError):
        lfqt.triangulate(pts, filter="none")
    with pytest.raises(ValueError):
        lfqt.triangulate(pts, threads=0)


def test_float16_is_widened_exactly():
    pts = np.random.default_rng(0).random((100, 2)).astype(np.float16)
    tri = triangulate_verified(pts)
    assert tri.stats["key_bits"] == 64


def test_delaunay_wrapper_matches_scipy(rng):
    pts = rng.random((2000, 2))
    ours, theirs = lfqt.Delaunay(pts), scipy.spatial.Delaunay(pts)
    assert triangle_set(ours.simplices) == triangle_set(theirs.simplices)
    q = np.r_[rng.random((500, 2)) * 1.2 - 0.1, pts[:20]]
    f_ours, f_theirs = ours.find_simplex(q), theirs.find_simplex(q)
    assert np.array_equal(f_ours < 0, f_theirs < 0)
    for k in np.flatnonzero(f_ours >= 0)[:300]:
        tri = pts[ours.simplices[f_ours[k]]]
        bary = np.linalg.solve(np.c_[tri[1] - tri[0], tri[2] - tri[0]], q[k] - tri[0])
        assert bary.min() >= -1e-12 and bary.sum() <= 1 + 1e-12
    ip, ix = ours.vertex_neighbor_vertices
    jp, jx = theirs.vertex_neighbor_vertices
    for v in range(0, 2000, 97):
        assert set(ix[ip[v]:ip[v + 1]]) == set(jx[jp[v]:jp[v + 1]])
    assert {frozenset(e) for e in ours.convex_hull.tolist()} == \
        {frozenset(e) for e in theirs.convex_hull.tolist()}
    assert ours.find_simplex(q.reshape(-1, 1, 2)).shape == (len(q), 1)


def test_delaunay_raises_like_scipy_on_degenerate_input():
    with pytest.raises(lfqt.DegenerateInputError, match="collinear"):
        lfqt.Delaunay(np.c_[np.arange(5.0), np.arange(5.0)])
    with pytest.raises(ValueError, match="distinct"):
        lfqt.Delaunay([[0.0, 0.0], [0.0, 0.0], [1.0, 1.0]])


def test_delaunay_reports_duplicates_as_coplanar():
    pts = np.array([[0.0, 0], [1, 0], [0, 1], [1, 1], [1, 0]])
    d = lfqt.Delaunay(pts)
    assert d.coplanar.shape == (1, 3)
    row, simplex, vertex = d.coplanar[0]
    assert row == 4 and vertex == 1 and 1 in d.simplices[simplex]


def test_find_simplex_on_scaled_input():
    pts = np.random.default_rng(2).random((300, 2)) * 1e-300
    d = lfqt.Delaunay(pts)
    assert np.all(d.find_simplex(pts) >= 0)
    assert d.find_simplex([[1.0, 1.0]])[0] == -1


def _contains(pts, simplex, q):
    """Exactly: does the counter-clockwise triangle ``simplex`` contain q?"""
    from fractions import Fraction as F
    a, b, c = (pts[v] for v in simplex)

    def orient(p, r, s):
        return (F(p[0]) - F(s[0])) * (F(r[1]) - F(s[1])) - (F(p[1]) - F(s[1])) * (F(r[0]) - F(s[0]))
    return orient(a, b, q) >= 0 and orient(b, c, q) >= 0 and orient(c, a, q) >= 0


def test_find_simplex_is_exact_for_queries_the_rescale_cannot_hold(rng):
    """Queries 1e-300 from the origin among points of magnitude 1e100 underflow
    in the rescaled frame; (1e-60, 0.5) on unit data lies below its window."""
    big = np.r_[rng.uniform(-1e100, 1e100, (200, 2)), [[0.0, 0.0]]]
    ang = np.linspace(0, 2 * np.pi, 8, endpoint=False)
    tiny = 1e-300 * np.c_[np.cos(ang), np.sin(ang)]
    unit = np.r_[rng.random((200, 2)), [[0.0, 0.0], [1, 0], [0, 1], [1, 1]]]
    for pts, qs in ((big, tiny), (unit, np.array([[1e-60, 0.5], [0.5, 1e-300], [1e-320, 1e-320]]))):
        d = lfqt.Delaunay(pts)
        found = d.find_simplex(qs)
        assert all(t >= 0 and _contains(pts, d.simplices[t], q) for t, q in zip(found, qs))


def test_find_simplex_follows_scipy_on_nan_and_bad_shapes(rng):
    d = lfqt.Delaunay(rng.random((50, 2)))
    assert d.find_simplex([[np.nan, 0.5], [0.5, np.nan]]).tolist() == [-1, -1]
    with pytest.raises(IndexError):
        d.find_simplex(1)
    with pytest.raises(ValueError, match="dimensionality"):
        d.find_simplex([[0.1, 0.2, 0.3]])
    q = rng.random((20, 2))
    assert np.array_equal(d.find_simplex(q, bruteforce=True, tol=1e-12), d.find_simplex(q))
