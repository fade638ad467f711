"""lfqt.derived through lfqt.Delaunay: scipy's values where scipy defines
them, simplex by simplex (the two meshes are the same set of simplices on
generic points, in another order)."""
import numpy as np
import pytest
import scipy.spatial

import lfqt

REL = 1e-12


def _pair(points, **kwargs):
    ours = lfqt.Delaunay(points, **kwargs)
    assert lfqt.verify(points, ours.triangulation).ok
    theirs = scipy.spatial.Delaunay(points, **kwargs)
    key = {frozenset(s): k for k, s in enumerate(theirs.simplices.tolist())}
    match = np.array([key.get(frozenset(s), -1) for s in ours.simplices.tolist()])
    # Qhull's floating-point mesh may differ from the exact one (offset data, no Qbb in
    # incremental mode): values are compared on the simplices both have
    assert (match >= 0).mean() > 0.5
    return ours, theirs, match


def _cases(dim, rng, incremental):
    yield rng.random((300, dim))
    yield rng.random((150, dim)) * 1e-7 - 3e-8                 # small, across zero
    if not incremental:
        # UTM-like offsets.  Not in incremental mode: there scipy drops Qbb, the lift
        # |x|^2 ~ 1e11 is not rescaled, and Qhull's planes of these near-vertical facets
        # differ from a direct evaluation by 1e-5 (they are its merged facets' planes)
        yield rng.standard_normal((200, dim)) * 1e3 + 5e5


@pytest.mark.parametrize("incremental", [False, True])
@pytest.mark.parametrize("dim", [2, 3])
def test_lift_equations_and_plane_distance_agree_with_scipy(dim, incremental, rng):
    for pts in _cases(dim, rng, incremental):
        ours, theirs, match = _pair(pts, incremental=incremental)
        assert ours.paraboloid_scale == pytest.approx(theirs.paraboloid_scale, rel=REL)
        assert ours.paraboloid_shift == pytest.approx(theirs.paraboloid_shift, rel=REL, abs=0)
        q = rng.random((20, dim)) * np.ptp(pts, axis=0) + pts.min(axis=0)
        lifted, want = ours.lift_points(q), theirs.lift_points(q)
        assert np.allclose(lifted, want, rtol=REL, atol=0)
        both = match >= 0
        eq, weq = ours.equations[both], theirs.equations[match[both]]
        # unit normals: components agree to REL of the norm (1); offsets to REL of their size
        scale = np.abs(weq[:, -1]).max() + 1.0
        assert np.abs(eq[:, :-1] - weq[:, :-1]).max() <= REL * 10
        assert np.abs(eq[:, -1] - weq[:, -1]).max() <= REL * 10 * scale
        dist, wdist = ours.plane_distance(q)[:, both], theirs.plane_distance(q)[:, match[both]]
        assert np.abs(dist - wdist).max() <= REL * 10 * (np.abs(wdist).max() + scale)


@pytest.mark.parametrize("dim", [2, 3])
def test_transform_and_vertex_neighbours_agree_with_scipy(dim, rng):
    pts = rng.random((400, dim))
    ours, theirs, match = _pair(pts)
    assert (match >= 0).all()
    x = rng.random(dim)  # its barycentric coordinates, vertex by vertex, in both meshes
    weights = []
    for d, rows in ((ours, np.arange(ours.nsimplex)), (theirs, match)):
        T = d.transform[rows]
        c = np.einsum("ijk,ik->ij", T[:, :-1, :], x - T[:, -1, :])
        c = np.c_[c, 1 - c.sum(axis=1)]
        by_vertex = np.argsort(d.simplices[rows], axis=1)
        weights.append(np.take_along_axis(c, by_vertex, axis=1))
    assert np.allclose(weights[0], weights[1], rtol=1e-9, atol=1e-9)
    indptr, indices = ours.vertex_neighbor_vertices
    wptr, wind = theirs.vertex_neighbor_vertices
    assert indptr.dtype == wptr.dtype and indices.dtype == wind.dtype
    assert np.array_equal(indptr, wptr)
    for v in range(len(pts)):
        mine = indices[indptr[v]:indptr[v + 1]]
        assert np.all(np.diff(mine) > 0)  # sorted, each once
        assert set(mine.tolist()) == set(wind[wptr[v]:wptr[v + 1]].tolist())


@pytest.mark.parametrize("dim", [2, 3])
def test_transform_is_nan_exactly_for_simplices_too_flat_to_invert(dim):
    """A point a hair inside the unit simplex's far facet makes a sliver:
    its transform is NaN, as scipy's condition limit says, and no other."""
    pts = np.r_[np.eye(dim), np.zeros((1, dim)), [np.full(dim, 1.0 / dim) * (1 - 1e-13)]]
    d = lfqt.Delaunay(pts)
    T = d.transform
    flat = np.isnan(T[:, :-1, :]).any(axis=(1, 2))
    for t, s in enumerate(d.simplices):
        X = pts[s]
        M = (X[:-1] - X[-1]).T
        cond = np.linalg.cond(M, 1)
        assert flat[t] == (cond >= 1.0 / (1000 * np.finfo(float).eps))
    assert flat.any() and not flat.all()
    good = ~flat
    r = T[good, -1, :]
    assert np.array_equal(r, pts[d.simplices[good, -1]])


@pytest.mark.parametrize("dim", [2, 3])
def test_derived_attributes_are_identical_on_every_thread_count(dim, rng):
    pts = rng.random((3000, dim))
    one, two = lfqt.Delaunay(pts, threads=1), lfqt.Delaunay(pts, threads=3)
    assert np.array_equal(one.simplices, two.simplices)
    for name in ("transform", "equations"):
        assert np.array_equal(getattr(one, name), getattr(two, name), equal_nan=True)
    for a, b in zip(one.vertex_neighbor_vertices, two.vertex_neighbor_vertices):
        assert np.array_equal(a, b)
