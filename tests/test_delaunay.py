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
@pytest.mark.parametrize("dtype, threads", [(np.float64, 1), (np.float32, 1), (np.float64, 2)])
def test_rejects_nan_and_inf_naming_count_and_first_row(bad, dtype, threads):
    pts = np.random.default_rng(0).random((200001, 2)).astype(dtype)  # chunks on 2 threads
    pts[3, 1] = bad
    pts[150007, 0] = bad
    with pytest.raises(ValueError, match="2 rows; the first is row 3"):
        lfqt.triangulate(pts, threads=threads)
    with pytest.raises(ValueError, match="NaN or inf"):
        lfqt.quadtree(pts[:10])


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


# -- the scipy.spatial.Delaunay interface, 2D and 3D --------------------------

def _built(points, **kwargs):
    """lfqt.Delaunay of points, its mesh verified exactly."""
    d = lfqt.Delaunay(points, **kwargs)
    report = lfqt.verify(points, d.triangulation)
    assert report.ok, report.problems[:3]
    return d


def _simplex_set(simplices):
    """Simplices as vertex sets (scipy does not fix the 3D orientation)."""
    return {frozenset(s) for s in np.asarray(simplices).tolist()}


def _facet_neighbours(simplices, neighbors):
    """{(simplex as frozenset, facet as frozenset): neighbour as frozenset or None}."""
    out = {}
    for s, nb in zip(simplices.tolist(), neighbors.tolist()):
        for i, t in enumerate(nb):
            facet = frozenset(s[:i] + s[i + 1:])
            out[(frozenset(s), facet)] = frozenset(simplices[t].tolist()) if t >= 0 else None
    return out


@pytest.mark.parametrize("dim", [2, 3])
def test_every_attribute_agrees_with_scipy_on_random_sets(dim, rng):
    pts = rng.random((400, dim))
    ours, theirs = _built(pts), scipy.spatial.Delaunay(pts)
    assert (ours.ndim, ours.npoints, ours.nsimplex) == (theirs.ndim, theirs.npoints,
                                                        theirs.nsimplex)
    assert _simplex_set(ours.simplices) == _simplex_set(theirs.simplices)
    assert _facet_neighbours(ours.simplices, ours.neighbors) == \
        _facet_neighbours(theirs.simplices, theirs.neighbors)
    for name in ("simplices", "neighbors", "convex_hull", "coplanar", "vertex_to_simplex",
                 "good"):
        assert getattr(ours, name).dtype == getattr(theirs, name).dtype, name
    assert {frozenset(f) for f in ours.convex_hull.tolist()} == \
        {frozenset(f) for f in theirs.convex_hull.tolist()}
    assert np.array_equal(ours.min_bound, theirs.min_bound)
    assert np.array_equal(ours.max_bound, theirs.max_bound)
    assert ours.furthest_site is False and ours.good.shape == (ours.nsimplex,)
    assert ours.equations.shape == theirs.equations.shape
    assert ours.transform.shape == theirs.transform.shape
    # matching simplices: barycentric coordinates per vertex, and the side
    # of each hyperplane (inside or outside the circumsphere), agree
    index = {frozenset(s): k for k, s in enumerate(theirs.simplices.tolist())}
    q = rng.random((50, dim))
    dist_ours, dist_theirs = ours.plane_distance(q), theirs.plane_distance(q)
    assert dist_ours.shape == (50, ours.nsimplex)
    for k, s in enumerate(ours.simplices.tolist()):
        j = index[frozenset(s)]
        clear = np.abs(dist_theirs[:, j]) > 1e-9
        assert np.array_equal(np.sign(dist_ours[clear, k]), np.sign(dist_theirs[clear, j]))
        for tr, simplex, t in ((ours.transform, s, k), (theirs.transform, theirs.simplices[j], j)):
            c = tr[t, :dim] @ (q[0] - tr[t, dim])
            bary = dict(zip(np.asarray(simplex).tolist(), np.r_[c, 1 - c.sum()]))
            if tr is ours.transform:
                mine = bary
        assert all(abs(mine[v] - bary[v]) < 1e-8 for v in mine)
    v2s = ours.vertex_to_simplex
    assert all(v in ours.simplices[v2s[v]] for v in range(len(pts)))
    lifted = ours.lift_points(q)
    assert lifted.shape == (50, dim + 1)
    assert np.allclose(lifted[:, -1], (q ** 2).sum(1) * ours.paraboloid_scale
                       + ours.paraboloid_shift)
    assert np.allclose(ours.plane_distance(ours.points[ours.simplices[:, 0]])
                       [np.arange(ours.nsimplex), np.arange(ours.nsimplex)], 0, atol=1e-12)


def _contains_exact(pts, simplex, q):
    """Exactly: does the positively oriented simplex contain q (2D or 3D)?"""
    from lfqt.location import _orient
    from fractions import Fraction as F
    verts = [[F(float(c)) for c in pts[v]] for v in simplex]
    qf = [F(float(c)) for c in q]
    return all(_orient(verts[:i] + [qf] + verts[i + 1:]) >= 0 for i in range(len(verts)))


def test_find_simplex_in_3d_is_exact_and_agrees_with_scipy(rng):
    pts = rng.random((500, 3))
    ours, theirs = _built(pts), scipy.spatial.Delaunay(pts)
    q = np.r_[rng.random((300, 3)) * 1.2 - 0.1, pts[:30]]
    found = ours.find_simplex(q)
    assert found.dtype == theirs.find_simplex(q).dtype
    for t, x in zip(found, q):
        if t >= 0:
            assert _contains_exact(pts, ours.simplices[t], x)
    clear = np.abs(theirs.plane_distance(q)).min(axis=1) > 1e-9
    assert np.array_equal((found < 0)[clear], (theirs.find_simplex(q) < 0)[clear])
    assert np.array_equal(ours.find_simplex(q, bruteforce=True) >= 0, found >= 0)
    assert ours.find_simplex(q.reshape(-1, 3, 3)).shape == (len(q) // 3, 3)
    assert ours.find_simplex([np.nan, 0.5, 0.5]) == -1


def test_find_simplex_in_3d_for_queries_the_rescale_cannot_hold(rng):
    pts = np.r_[rng.uniform(-1e80, 1e80, (100, 3)), [[0.0, 0.0, 0.0]]]
    d = _built(pts)
    q = 1e-300 * rng.standard_normal((5, 3))
    found = d.find_simplex(q)
    assert all(t >= 0 and _contains_exact(pts, d.simplices[t], x) for t, x in zip(found, q))


@pytest.mark.parametrize("dim", [2, 3])
def test_tolerance_only_widens_toward_scipy(dim, rng):
    pts = np.r_[np.eye(dim), np.zeros((1, dim))]  # the unit simplex
    d = _built(pts)
    outside = np.full(dim, 1.0 / dim) + 1e-13  # just beyond the far facet
    assert d.find_simplex(outside) == -1
    assert d.find_simplex(outside, tol=1e-10) == 0
    assert d.find_simplex(np.full(dim, 2.0), tol=1e-10) == -1
    assert d.find_simplex(np.full(dim, 0.1), tol=1e-10) == 0


@pytest.mark.parametrize("dim", [2, 3])
def test_simplex_and_grid_as_scipys_tests_do_in_2d_and_3d(dim):
    pts = np.r_[np.eye(dim), np.ones((1, dim))]
    d = _built(pts)
    assert np.array_equal(np.sort(d.simplices, axis=1), [list(range(dim + 1))])
    assert np.array_equal(d.neighbors, -np.ones((1, dim + 1), dtype=int))
    x = np.linspace(0, 1, {2: 70, 3: 11}[dim])
    grid = np.stack(np.meshgrid(*[x] * dim, indexing="ij"), -1).reshape(-1, dim)
    for g in (grid, np.r_[grid, grid]):
        d = _built(g)
        centroids = g[d.simplices].mean(axis=1)
        assert (d.find_simplex(centroids) >= 0).all()
        c = np.einsum("ijk,ik->ij", d.transform[:, :dim], centroids - d.transform[:, dim])
        assert np.allclose(c, 1.0 / (dim + 1), rtol=0.1)


@pytest.mark.parametrize("dim", [2, 3])
def test_incremental_mode_rebuilds_exactly_and_closes(dim, rng):
    chunks = [rng.random((dim + 2, dim)), rng.random((30, dim)), np.eye(dim), rng.random((5, dim))]
    d = lfqt.Delaunay(chunks[0], incremental=True)
    assert (d.paraboloid_scale, d.paraboloid_shift) == (1.0, 0.0)
    for c in chunks[1:]:
        d.add_points(c)
    union = np.concatenate(chunks)
    assert lfqt.verify(union, d.triangulation).ok
    assert d.npoints == len(union) and np.array_equal(d.points, union)
    assert _simplex_set(d.simplices) == _simplex_set(scipy.spatial.Delaunay(union).simplices)
    restarted = lfqt.Delaunay(chunks[0], incremental=True)
    restarted.add_points(np.concatenate(chunks[1:]), restart=True)
    assert _simplex_set(restarted.simplices) == _simplex_set(d.simplices)
    with pytest.raises(ValueError, match="invalid size"):
        d.add_points(rng.random((3, dim + 1)))
    d.close()
    with pytest.raises(RuntimeError, match="closed"):
        d.add_points(chunks[1])
    with pytest.raises(RuntimeError, match="not enabled"):
        lfqt.Delaunay(chunks[1]).add_points(chunks[2])


def test_options_and_errors_follow_scipy(rng):
    pts = rng.random((20, 2))
    with pytest.warns(UserWarning, match="'QJ Pp'"):
        lfqt.Delaunay(pts, qhull_options="QJ Pp")
    with pytest.raises(NotImplementedError, match="furthest"):
        lfqt.Delaunay(pts, furthest_site=True)
    with pytest.raises(ValueError, match="dimensions"):
        lfqt.Delaunay(rng.random((4, 10, 3)))
    with pytest.raises(ValueError, match="2 or 3 dimensions"):
        lfqt.Delaunay(rng.random((10, 4)))
    with pytest.raises(ValueError, match="masked"):
        lfqt.Delaunay(np.ma.masked_all((4, 2)))
    with pytest.raises(scipy.spatial.QhullError):  # code written for scipy catches it
        lfqt.Delaunay(np.zeros((4, 3)))
    with pytest.raises(lfqt.DegenerateInputError, match="coplanar"):
        lfqt.Delaunay(np.c_[rng.random((10, 2)), np.zeros(10)])
    d = lfqt.Delaunay(pts)
    with pytest.raises(IndexError):
        d.find_simplex(d)
    with pytest.raises(ValueError, match="dimensionality"):
        d.plane_distance(np.zeros(3))


def test_duplicates_are_coplanar_and_map_to_their_twins_simplex(rng):
    base = rng.random((10, 3))
    d = _built(np.r_[base, base])
    assert len(d.coplanar) == 10 and len(np.unique(d.simplices)) == 10
    for row, simplex, twin in d.coplanar:
        assert twin == row - 10 and twin in d.simplices[simplex]
        assert d.vertex_to_simplex[row] == simplex
    assert (d.vertex_to_simplex >= 0).all()
