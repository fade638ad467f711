"""lfqt.location through lfqt.Delaunay.find_simplex: every answer contains its
query by exact rational arithmetic, whatever the path (walk, brute force,
threads, queries below the frame's floor), and scipy's tolerance is answered
near the hull without a scan."""
from fractions import Fraction as F

import numpy as np
import pytest
import scipy.spatial
from hypothesis import given, settings, strategies as st

import lfqt
from lfqt import location
from lfqt.location import _orient


def _built(points, **kwargs):
    d = lfqt.Delaunay(points, **kwargs)
    report = lfqt.verify(points, d.triangulation)
    assert report.ok, report.problems[:3]
    return d


def _contains(pts, simplex, q):
    verts = [[F(float(c)) for c in pts[v]] for v in simplex]
    qf = [F(float(c)) for c in q]
    return all(_orient(verts[:i] + [qf] + verts[i + 1:]) >= 0 for i in range(len(verts)))


def _inside_hull(pts, d, q):
    """Exactly: does q lie in the hull (closed), i.e. beyond none of the
    hull facets (the facets without a neighbour)?"""
    qf = [F(float(c)) for c in q]
    for s, nb in zip(d.simplices, d.neighbors):
        for i in np.flatnonzero(nb < 0):
            verts = [[F(float(c)) for c in pts[v]] for v in s]
            if _orient(verts[:i] + [qf] + verts[i + 1:]) < 0:
                return False
    return True


def _check(pts, d, qs, found):
    for t, q in zip(found, qs):
        if t >= 0:
            assert _contains(pts, d.simplices[t], q), (t, q)
        else:
            assert not _inside_hull(pts, d, q), q


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("threads", [1, 2, 3])
def test_walk_brute_force_and_threads_answer_exactly(dim, threads, rng):
    pts = np.r_[rng.random((300, dim)), np.eye(dim)]
    d = _built(pts, threads=threads)
    qs = np.r_[rng.random((400, dim)) * 1.2 - 0.1, pts[::7], (pts[:40] + pts[1:41]) / 2]
    walk = d.find_simplex(qs)
    brute = d.find_simplex(qs, bruteforce=True)
    _check(pts, d, qs, walk)
    _check(pts, d, qs, brute)
    assert np.array_equal(walk < 0, brute < 0)


def test_many_queries_on_two_threads_match_one_thread(rng):
    """Large query sets are split over the threads (chunks of 4096 sorted
    queries); a query strictly inside a simplex has one answer."""
    pts = rng.random((5000, 2))
    q = rng.random((20000, 2))
    one, two = _built(pts, threads=1), _built(pts, threads=2)
    assert np.array_equal(one.simplices, two.simplices)
    assert np.array_equal(one.find_simplex(q), two.find_simplex(q))


@st.composite
def _tiny_cases(draw):
    """A small mesh with edges along and near the axes, and queries whose
    components lie far below the frame's floor: on an edge, or a hair off
    it, so that the in-frame part and the tiny part compete."""
    dim = draw(st.sampled_from([2, 3]))
    k = draw(st.integers(8, 30))
    seed = draw(st.integers(0, 2 ** 32 - 1))
    rng = np.random.default_rng(seed)
    pts = rng.integers(-4, 5, (k, dim)).astype(float)
    slant = 2.0 ** -draw(st.integers(150, 200))  # an edge at slope 2**-e, near the floor
    pts = np.r_[pts, np.eye(dim), -np.eye(dim), [np.r_[1.0, np.full(dim - 1, slant)]],
                np.zeros((1, dim))]
    exps = draw(st.lists(st.integers(-1074, -150), min_size=dim, max_size=dim))
    signs = draw(st.lists(st.sampled_from([-1.0, 0.0, 1.0]), min_size=dim, max_size=dim))
    q = np.array([s * 2.0 ** e for s, e in zip(signs, exps)])
    base = draw(st.sampled_from(["origin", "edge", "slant"]))
    if base == "edge":
        q[0] += 0.5
    elif base == "slant":
        q[0] += 0.5
        q[1:] += 0.5 * slant * draw(st.sampled_from([0.5, 1.0, 2.0]))
    return pts, q


@given(_tiny_cases())
@settings(max_examples=60, deadline=None)
def test_queries_below_the_floor_are_located_exactly(case):
    pts, q = case
    d = _built(pts)
    t = d.find_simplex(q[None, :])[0]
    _check(pts, d, [q], [t])


def test_tiny_queries_stay_in_the_kernels_and_big_frames_fall_back(monkeypatch, rng):
    """No rational arithmetic on the common tiny query; a frame scaled down
    too far for the shift (data near 1e300) still answers exactly, in
    rationals."""
    calls = []
    real = location.locate_rational
    monkeypatch.setattr("lfqt.delaunay.locate_rational",
                        lambda *a: calls.append(1) or real(*a))
    unit = np.r_[rng.random((200, 2)), [[0.0, 0.0], [1, 0], [0, 1], [1, 1]]]
    qs = np.array([[1e-60, 0.5], [0.5, 1e-300], [1e-320, 1e-320], [0.25, -1e-310]])
    d = _built(unit)
    _check(unit, d, qs, d.find_simplex(qs))
    assert not calls
    huge = np.r_[rng.uniform(-1e300, 1e300, (100, 2)), [[0.0, 0.0]]]
    d = _built(huge)
    assert not location.tiny_frame_ok(d._exponent, 2)
    qs = 1e-300 * rng.standard_normal((3, 2))
    _check(huge, d, qs, d.find_simplex(qs))
    assert len(calls) == 3


@pytest.mark.parametrize("dim", [2, 3])
def test_tolerance_near_the_hull_matches_a_full_scan(dim, rng):
    """Just outside the hull, the search near the facets the query sees
    finds a simplex within tol wherever a scan of every simplex does, and
    the one it returns is within tol; far outside, -1."""
    pts = rng.random((400, dim))
    d = _built(pts)
    hull = scipy.spatial.ConvexHull(pts)
    normals = hull.equations[:, :-1]  # outward
    # points on hull facets pushed out along the facet normal
    centers = pts[hull.simplices].mean(axis=1)[:60]
    qs = centers + 1e-11 * normals[:60]
    tol = 1e-6
    found = d.find_simplex(qs, tol=tol)
    tr = d.transform
    for t, q in zip(found, qs):
        c = np.einsum("ijk,ik->ij", tr[:, :-1, :], q - tr[:, -1, :])
        c = np.c_[c, 1 - c.sum(axis=1)]
        some = ((c >= -tol).all(axis=1)).any()
        assert (t >= 0) == some
        if t >= 0:
            assert (c[t] >= -tol).all()
    far = centers[:5] + 1.0 * normals[:5]
    assert (d.find_simplex(far, tol=tol) == -1).all()


def test_tolerance_never_scans_every_simplex(rng):
    """The tolerant search evaluates at most SEEN simplices per query; on a
    mesh of many more it still finds a simplex within tol exactly where a
    scan of every simplex finds one (a sliver on the hull may have none)."""
    pts = rng.random((20000, 2))
    d = _built(pts)
    assert d.nsimplex > 4 * location.SEEN
    hull = scipy.spatial.ConvexHull(pts)
    q = pts[hull.simplices].mean(axis=1) + 1e-12 * hull.equations[:, :-1]
    found = d.find_simplex(q, tol=1e-6)
    tr = d.transform
    for t, x in zip(found, q):
        c = np.einsum("ijk,ik->ij", tr[:, :-1, :], x - tr[:, -1, :])
        within = (np.c_[c, 1 - c.sum(axis=1)] >= -1e-6).all(axis=1)
        assert (t >= 0) == within.any()
        assert t < 0 or within[t]
    assert (found >= 0).sum() > len(q) // 2
    assert (d.find_simplex(q) == -1).all()


@pytest.mark.parametrize("dim", [2, 3])
def test_sparse_queries_jump_then_walk_and_answer_exactly(dim, rng):
    """Few queries on a large mesh start from the nearest of about m**(1/3)
    spread simplices (jump and walk) instead of the previous answer."""
    pts = rng.random((6000, dim))
    d = _built(pts)
    q = np.r_[rng.random((30, dim)), [np.full(dim, 2.0)]]
    assert location.jump_sample(len(q), len(pts), d.nsimplex) > 0
    assert location.jump_sample(len(pts) // location.JUMP_SPARSITY + 1, len(pts), d.nsimplex) == 0
    found = d.find_simplex(q)
    assert found[-1] == -1
    for t, x in zip(found[:-1], q[:-1]):
        assert t >= 0 and _contains(pts, d.simplices[t], x)


@pytest.mark.parametrize("dim", [2, 3])
def test_tolerance_never_answers_a_simplex_too_flat_for_its_transform(dim):
    """A sliver on the hull has a NaN transform: a query just outside it
    gets a simplex whose coordinates are within tol, never the sliver."""
    pts = np.r_[np.eye(dim), np.zeros((1, dim)), [np.full(dim, 1.0 / dim) * (1 - 1e-13)]]
    d = _built(pts)
    flat = np.isnan(d.transform[:, :-1, :]).any(axis=(1, 2))
    assert flat.any()
    q = np.full(dim, 1.0 / dim) + 1e-12
    t = d.find_simplex(q, tol=1e-6)
    assert t == -1 or not flat[t]
    if t >= 0:
        T = d.transform[t]
        c = T[:-1] @ (q - T[-1])
        assert (np.r_[c, 1 - c.sum()] >= -1e-6).all()


@pytest.mark.parametrize("dim", [2, 3])
def test_walk_frame_is_the_mesh_renumbered(dim, rng):
    """The walk's mesh holds the same simplices, row for row and slot for
    slot, in points numbered in the order the rows first name them, scaled
    into the location's frame; lfqt.Delaunay walks on it with its own
    neighbours."""
    pts = np.r_[rng.random((500, dim)), rng.random((20, dim))]
    pts[-20:] = pts[:20]  # duplicates: rows no simplex names
    tri = lfqt.triangulate(pts) if dim == 2 else lfqt.insert(pts)
    P, S = location.walk_frame(pts, tri.simplices, 4.0)
    assert len(P) == tri.n_distinct
    assert np.array_equal(P[S], 4.0 * pts[tri.simplices])
    first = np.unique(S.ravel(), return_index=True)[1]
    assert np.all(np.diff(first) > 0)  # numbered in the order of first appearance
    d = _built(pts)
    P2, S2, N2 = d._mesh
    assert np.array_equal(P2[S2], d.points[d.simplices] * 2.0 ** d.stats["scale_exponent"])
    assert N2 is d.neighbors


@pytest.mark.parametrize("dim", [2, 3])
def test_coherent_queries_on_a_grid_mesh_answer_exactly(dim):
    """Cocircular (cospherical) grid points, walked in the renumbered frame:
    queries on vertices, on edges and in cells, in row order (coherent,
    walked as given) and shuffled (sorted first), each answer contains its
    query and the two orders agree on every query inside a cell."""
    side = 7 if dim == 2 else 4
    axes = [np.arange(side, dtype=float)] * dim
    pts = np.stack([g.ravel() for g in np.meshgrid(*axes, indexing="ij")], axis=1)
    d = _built(pts)
    fine = [np.linspace(-0.5, side - 0.5, 3 * side)] * dim
    qs = np.stack([g.ravel() for g in np.meshgrid(*fine, indexing="ij")], axis=1)
    assert location.coherent(qs)
    in_order = d.find_simplex(qs)
    _check(pts, d, qs, in_order)
    shuffle = np.random.default_rng(1).permutation(len(qs))
    shuffled = np.empty_like(in_order)
    shuffled[shuffle] = d.find_simplex(qs[shuffle])
    _check(pts, d, qs, shuffled)
    assert np.array_equal(in_order < 0, shuffled < 0)


@pytest.mark.parametrize("dim", [2, 3])
def test_the_walks_static_bound_covers_the_queries_box_as_well_as_the_meshes(dim, rng):
    """walk_static's bound certifies a step only if every corner and query
    of it lies in its box: queries beyond the mesh's box widen it."""
    from lfqt.predicates.planar import ICC_A, CCW_A, static_bounds
    from lfqt.predicates.spatial import ISP_A, O3D_A, static_bounds3
    box = np.array([np.zeros(dim), np.ones(dim)])
    inside, far = rng.random((50, dim)), np.r_[rng.random((49, dim)), [np.full(dim, -7.0)]]
    widths = [8.0] * dim

    def expected(w):
        bounds = static_bounds(*w, CCW_A, ICC_A) if dim == 2 else static_bounds3(*w, O3D_A, ISP_A)
        return bounds[0]

    assert location.walk_static(box, inside) == expected([1.0] * dim)
    assert location.walk_static(box, far) == expected(widths) > expected([1.0] * dim)
    assert location.walk_static(box * 1e300, far * 1e300) == np.inf  # overflows: off


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2 ** 31), st.sampled_from([2, 3]),
       st.sampled_from([2.0 ** -600, 1.0, 2.0 ** 600]))
def test_queries_on_vertices_and_edges_of_a_scaled_mesh_are_found_exactly(seed, dim, scale):
    """Queries on the mesh's vertices and edge midpoints make orientations
    of zero, which no static bound certifies: each answer still holds its
    query.  Powers of two scale the integer points, so that the midpoints
    are exact."""
    rng = np.random.default_rng(seed)
    pts = np.round(rng.random((200, dim)) * 64) * scale
    d = _built(pts)
    s = d.simplices[rng.integers(0, d.nsimplex, 40)]
    q = np.r_[pts[s[:, 0]], (pts[s[:, 0]] + pts[s[:, 1]]) / 2]
    for t, x in zip(d.find_simplex(q), q):
        assert t >= 0 and _contains(pts, d.simplices[t], x)
