"""A new scipy user's first hour with ``lfqt.Delaunay``, in 2D and 3D: every
step compares values with scipy.spatial.Delaunay on the same points, or with
exact facts (generic random points have one Delaunay triangulation)."""
import functools
import pickle

import numpy as np
import pytest
import scipy.spatial as sp
from scipy.spatial import QhullError
from threadpoolctl import threadpool_limits

import lfqt

N = {2: 2000, 3: 800}
KEY = {2: "triangles", 3: "tetrahedra"}
dims = pytest.mark.parametrize("dim", [2, 3])


@pytest.fixture(scope="module", autouse=True)
def one_blas_thread():
    """scipy's transform calls LAPACK once per simplex: OpenBLAS threads on
    busy shared cores make it 30 s instead of 5 ms.  One thread here."""
    with threadpool_limits(limits=1, user_api="blas"):
        yield


@functools.lru_cache(maxsize=None)
def built(dim):
    """points, lfqt.Delaunay, scipy Delaunay: once per dimension."""
    p = np.random.default_rng(20240 + dim).random((N[dim], dim))
    return p, lfqt.Delaunay(p), sp.Delaunay(p)


def vsets(simplices):  # simplices as a set of vertex sets
    return {frozenset(map(int, s)) for s in simplices}


def match(d, s):
    """For each simplex of d, the index of the scipy simplex with its vertex set."""
    where = {frozenset(map(int, t)): k for k, t in enumerate(s.simplices)}
    return np.array([where[frozenset(map(int, t))] for t in d.simplices])


def weights(tri, t, x):
    """Barycentric weights of x in simplex t as {vertex: weight}, from transform."""
    T = tri.transform[t]
    c = T[:-1] @ (x - T[-1])
    return dict(zip(map(int, tri.simplices[t]), np.append(c, 1 - c.sum())))


def queries(dim, n=3000, seed=7):
    return np.random.default_rng(seed).uniform(-0.25, 1.25, (n, dim))


def hull_excess(p, q):
    """max over hull facets of the signed distance: > 0 outside the hull."""
    eq = sp.ConvexHull(p).equations
    return (q @ eq[:, :-1].T + eq[:, -1]).max(axis=1)


def contains(d, f, q, eps=1e-12):
    T = d.transform[f]
    c = np.einsum("kij,kj->ki", T[:, :-1], q - T[:, -1])
    bary = np.concatenate([c, 1 - c.sum(axis=1, keepdims=True)], axis=1)
    return (bary >= -eps).all(axis=1)


@dims
def test_build_and_verify(dim):
    p, d, s = built(dim)
    assert d.ndim == dim and d.npoints == len(p) and d.points.shape == p.shape
    reports = [lfqt.verify(p, d), lfqt.verify(p, s), lfqt.verify(p, d.simplices)]
    assert all(r.ok for r in reports), [r.problems for r in reports]
    assert [r.counts[KEY[dim]] for r in reports] == [d.nsimplex] * 3 == [s.nsimplex] * 3


@dims
def test_simplices_and_neighbors(dim):
    p, d, s = built(dim)
    assert d.simplices.shape == s.simplices.shape
    assert vsets(d.simplices) == vsets(s.simplices)
    m = match(d, s)  # neighbours, mapped to scipy's numbering, are scipy's
    mapped = np.where(d.neighbors >= 0, m[np.maximum(d.neighbors, 0)], -1)
    for t in range(d.nsimplex):
        ours = {(int(v), int(n)) for v, n in zip(d.simplices[t], mapped[t])}
        theirs = {(int(v), int(n)) for v, n in zip(s.simplices[m[t]], s.neighbors[m[t]])}
        assert ours == theirs
        for j in range(dim + 1):
            n = d.neighbors[t, j]
            if n >= 0:
                assert set(d.simplices[n]) & set(d.simplices[t]) == set(np.delete(d.simplices[t], j))
                assert t in d.neighbors[n]


@dims
def test_find_simplex(dim):
    p, d, s = built(dim)
    q = queries(dim)
    f = d.find_simplex(q)
    assert f.shape == (len(q),) and f.dtype == s.find_simplex(q).dtype
    ins = f >= 0
    assert contains(d, f[ins], q[ins]).all()
    ex = hull_excess(p, q)
    assert not (ex[~ins] < -1e-12).any()          # -1 only outside (or on) the hull
    clear = np.abs(ex) > 1e-9
    assert np.array_equal(f[clear] == -1, s.find_simplex(q[clear]) == -1)
    assert np.array_equal(f[clear] == -1, ex[clear] > 0)
    # tsearch-style: the shape of xi[..., :ndim] is kept
    grid = q[:60].reshape(3, 4, 5, dim)
    g = d.find_simplex(grid)
    assert g.shape == (3, 4, 5) and np.array_equal(g.ravel(), f[:60])
    # brute force: also contains, and -1 at the same queries (both exact)
    b = d.find_simplex(q, bruteforce=True)
    assert np.array_equal(b >= 0, ins) and contains(d, b[ins], q[ins]).all()
    assert d.find_simplex(np.full(dim, np.nan)) == -1


@dims
def test_find_simplex_tol(dim):
    p, d, s = built(dim)
    h = sp.ConvexHull(p)
    cen = p[h.simplices].mean(axis=1)             # the facet most inside the bounding box
    k = int(np.minimum(cen - p.min(axis=0), p.max(axis=0) - cen).min(axis=1).argmax())
    x = cen[k] + 1e-12 * h.equations[k, :-1]   # 1e-12 outside the facet k
    assert hull_excess(p, x[None])[0] > 0
    assert d.find_simplex(x) == -1
    t = int(d.find_simplex(x, tol=1e-9))
    assert t >= 0 and set(h.simplices[k]) <= set(d.simplices[t])
    assert min(weights(d, t, x).values()) >= -1e-9
    assert s.find_simplex(x, tol=1e-9) >= 0


@dims
def test_vertex_adjacency_and_hull(dim):
    p, d, s = built(dim)
    (ip, ix), (jp, jx) = d.vertex_neighbor_vertices, s.vertex_neighbor_vertices
    assert np.array_equal(ip, jp)
    for k in range(d.npoints):
        assert set(ix[ip[k]:ip[k + 1]]) == set(jx[jp[k]:jp[k + 1]])
    v2s = d.vertex_to_simplex
    assert v2s.shape == (d.npoints,)
    assert all(k in d.simplices[v2s[k]] for k in range(d.npoints))
    facets = lambda h: {tuple(sorted(map(int, f))) for f in h}
    assert d.convex_hull.shape == s.convex_hull.shape
    assert facets(d.convex_hull) == facets(s.convex_hull)
    assert len(d.coplanar) == len(s.coplanar) == 0


@dims
def test_geometry_matches_scipy(dim):
    p, d, s = built(dim)
    m = match(d, s)
    rng = np.random.default_rng(3)
    for t in range(d.nsimplex):  # weights at a random point of each simplex, vertex by vertex
        w = rng.dirichlet(np.ones(dim + 1))
        x = w @ p[d.simplices[t]]
        ours, theirs = weights(d, t, x), weights(s, m[t], x)
        exact = dict(zip(map(int, d.simplices[t]), w))
        for v in ours:
            assert abs(ours[v] - theirs[v]) <= 1e-12 * max(1.0, abs(theirs[v])), (t, v)
            assert abs(ours[v] - exact[v]) <= 1e-9
    assert d.paraboloid_scale == pytest.approx(s.paraboloid_scale, rel=1e-12)
    assert d.paraboloid_shift == pytest.approx(s.paraboloid_shift, rel=1e-12, abs=1e-300)
    q = queries(dim, 50)
    np.testing.assert_allclose(d.lift_points(q), s.lift_points(q), rtol=1e-12, atol=1e-300)
    eq, seq = d.equations, s.equations[m]
    assert eq.shape == seq.shape
    np.testing.assert_allclose(eq, seq, rtol=1e-12, atol=1e-12 * np.abs(seq).max())
    pd, spd = d.plane_distance(q), s.plane_distance(q)[:, m]
    np.testing.assert_allclose(pd, spd, rtol=1e-12, atol=1e-12 * np.abs(spd).max())


@dims
def test_incremental(dim):
    p, d, s = built(dim)
    half = N[dim] // 2
    inc = lfqt.Delaunay(p[:half], incremental=True)
    sinc = sp.Delaunay(p[:half], incremental=True)
    assert vsets(inc.simplices) == vsets(sinc.simplices)
    inc.add_points(p[half:])
    sinc.add_points(p[half:])
    assert inc.npoints == len(p) and np.array_equal(inc.points, p)
    assert vsets(inc.simplices) == vsets(d.simplices) == vsets(sinc.simplices)
    assert (inc.paraboloid_scale, inc.paraboloid_shift) == (1.0, 0.0) == \
        (sinc.paraboloid_scale, sinc.paraboloid_shift)
    for tri in (inc, sinc, d):  # closed, closed, never incremental
        tri.close()
        with pytest.raises(RuntimeError):
            tri.add_points(p[:3] + 2)


@dims
def test_pickle(dim):
    p, d, s = built(dim)
    e = pickle.loads(pickle.dumps(d))
    assert np.array_equal(e.simplices, d.simplices) and np.array_equal(e.neighbors, d.neighbors)
    assert np.array_equal(e.points, d.points)
    q = queries(dim, 500, seed=11)
    assert np.array_equal(e.find_simplex(q), d.find_simplex(q))
    np.testing.assert_array_equal(e.transform, d.transform)


def test_triplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    p, d, s = built(2)
    fig, ax = plt.subplots()
    try:
        lines = ax.triplot(p[:, 0], p[:, 1], d.simplices)
        assert len(lines) == 2                   # the edges, then the (no) markers
        ip, ix = d.vertex_neighbor_vertices
        nedges = len(ix) // 2
        X, Y = lines[0].get_xdata(), lines[0].get_ydata()
        assert len(X) == len(Y) == 3 * nedges    # each edge: 2 ends and a NaN
        X, Y = X.reshape(-1, 3), Y.reshape(-1, 3)
        assert np.isnan(X[:, 2]).all() and np.isnan(Y[:, 2]).all()
        at = {(x, y): k for k, (x, y) in enumerate(p)}
        drawn = {frozenset((at[X[e, 0], Y[e, 0]], at[X[e, 1], Y[e, 1]])) for e in range(nedges)}
        edges = {frozenset(e) for t in d.simplices for e in ((t[0], t[1]), (t[1], t[2]), (t[0], t[2]))}
        assert drawn == edges
        fig.canvas.draw()
    finally:
        plt.close(fig)


@dims
def test_degenerate_raises_qhull_error(dim):
    t = np.arange(20) / 16.0                      # dyadic: exactly collinear/coplanar
    if dim == 2:
        bad = np.c_[t, 2 * t + 1]
    else:
        bad = np.c_[t, t[::-1] ** 2, 3 * t - t[::-1] ** 2 + 5]   # z = 3x - y + 5, exactly
    for build in (sp.Delaunay, lfqt.Delaunay):
        with pytest.raises(QhullError) as err:
            build(bad)
    assert isinstance(err.value, lfqt.DegenerateInputError)
