"""verify must accept correct meshes from anyone and reject every kind of
broken one."""
import copy

import numpy as np
import pytest
import scipy.spatial

import lfqt
from conftest import triangulate_verified, without_cell


@pytest.fixture
def good(rng):
    pts = rng.random((300, 2))
    return pts, triangulate_verified(pts)


def broken(tri, **changes):
    out = copy.copy(tri)
    for k, v in changes.items():
        setattr(out, k, v)
    return out


def test_accepts_scipy_triangulation(rng):
    pts = rng.random((500, 2))
    d = scipy.spatial.Delaunay(pts)
    # scipy's hull edges are unordered and undirected: chain them, then orient
    adj = {}
    for a, b in d.convex_hull:
        adj.setdefault(a, []).append(b)
        adj.setdefault(b, []).append(a)
    loop = [d.convex_hull[0, 0], d.convex_hull[0, 1]]
    while True:
        a, b = adj[loop[-1]]
        nxt = a if a != loop[-2] else b
        if nxt == loop[0]:
            break
        loop.append(nxt)
    ring = np.array(loop)
    area = np.sum(pts[ring, 0] * np.roll(pts[ring, 1], -1) - np.roll(pts[ring, 0], -1) * pts[ring, 1])
    if area < 0:
        ring = ring[::-1]

    class Mesh:
        simplices = d.simplices
        neighbors = d.neighbors
        hull = ring
    assert lfqt.verify(pts, Mesh()).ok


def test_rejects_clockwise_triangle(good):
    pts, tri = good
    s = tri.simplices.copy()
    s[5] = s[5, ::-1]
    rep = lfqt.verify(pts, broken(tri, simplices=s))
    assert not rep.ok and not rep.checks["orientation"]


def test_rejects_missing_triangle(good):
    pts, tri = good
    rep = lfqt.verify(pts, without_cell(tri, np.flatnonzero((tri.neighbors >= 0).all(axis=1))[0]))
    assert not rep.ok and not rep.checks["convex_boundary"]


def test_rejects_flipped_edge(good):
    pts, tri = good
    s, nb = tri.simplices.copy(), tri.neighbors.copy()
    t = np.flatnonzero((nb >= 0).all(axis=1))[0]
    i = 0
    u = nb[t, i]
    a, b, c = s[t, 0], s[t, 1], s[t, 2]  # edge b-c opposite a
    j = [k for k in range(3) if nb[u, k] == t][0]
    d = s[u, j]
    # flip edge b-c to a-d; stays a valid triangulation only if convex, so check orientation too
    s[t] = [a, b, d]
    s[u] = [d, c, a]
    rep = lfqt.verify(pts, broken(tri, simplices=s))
    assert not rep.ok


def test_rejects_non_delaunay_but_valid_triangulation():
    # Square split along the wrong diagonal of a non-cocircular quad.
    pts = np.array([[0.0, 0.0], [2.0, 0.0], [2.1, 1.0], [0.0, 1.0]])
    tri = lfqt.triangulate(pts)
    s = tri.simplices
    assert lfqt.verify(pts, tri).ok
    # the other diagonal
    diag = set(s[0]) & set(s[1])
    other = [v for v in range(4) if v not in diag]
    p, q = sorted(diag)
    t1 = [other[0], p, other[1]]
    t2 = [other[1], q, other[0]]
    fix = []
    for t in (t1, t2):
        a, b, c = pts[t]
        area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
        fix.append(t if area > 0 else t[::-1])
    s2 = np.array(fix)
    nb = np.full((2, 3), -1)
    for k, t in enumerate(s2):
        for i in range(3):
            if set(t) - {t[i]} == set(other):
                nb[k, i] = 1 - k
    rep = lfqt.verify(pts, broken(tri, simplices=s2, neighbors=nb))
    assert not rep.ok and rep.checks["orientation"] and not rep.checks["delaunay"]


def test_rejects_unused_point(good):
    pts, tri = good
    extra = np.r_[pts, [[0.5, 0.5 + 1e-9]]]
    rep = lfqt.verify(extra, broken(tri, duplicate_of=np.arange(len(extra))))
    assert not rep.ok and not rep.checks["all_points_used"]


def test_rejects_wrong_hull(good):
    pts, tri = good
    rep = lfqt.verify(pts, broken(tri, hull=tri.hull[::-1]))
    assert not rep.ok and not rep.checks["hull"]


def test_rejects_bogus_duplicate_map(good):
    pts, tri = good
    dup = tri.duplicate_of.copy()
    dup[3] = 4
    rep = lfqt.verify(pts, broken(tri, duplicate_of=dup))
    assert not rep.ok and not rep.checks["duplicates"]


def test_rejects_unflagged_empty_mesh():
    pts = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    tri = lfqt.triangulate(pts)
    empty = broken(tri, simplices=np.empty((0, 3), int), neighbors=np.empty((0, 3), int),
                   degenerate=True, hull=tri.hull[:2])
    rep = lfqt.verify(pts, empty)
    assert not rep.ok and not rep.checks["collinear"]


def test_report_raises_with_reasons(good):
    pts, tri = good
    s = tri.simplices.copy()
    s[0] = s[0, ::-1]
    with pytest.raises(AssertionError, match="counter-clockwise"):
        lfqt.verify(pts, broken(tri, simplices=s)).raise_if_invalid()


@pytest.mark.parametrize("break_it", ["short_neighbors", "long_neighbors", "hull_out_of_range",
                                      "simplices_wrong_width", "neighbors_out_of_range",
                                      "float_simplices", "duplicate_of_short", "no_simplices"])
def test_malformed_arrays_are_reported_never_raised(break_it, rng):
    pts = rng.random((300, 2))
    tri = copy.copy(lfqt.triangulate(pts))
    if break_it == "short_neighbors":
        tri.neighbors = tri.neighbors[:-5]  # a truncated view must not pass as ok
    elif break_it == "long_neighbors":
        tri.neighbors = np.r_[tri.neighbors, tri.neighbors[:3]]
    elif break_it == "hull_out_of_range":
        tri.hull = np.r_[tri.hull, 10 ** 6]
    elif break_it == "simplices_wrong_width":
        tri.simplices = tri.simplices[:, :2]
    elif break_it == "neighbors_out_of_range":
        tri.neighbors = tri.neighbors.copy()
        tri.neighbors[0, 0] = len(tri.simplices) + 7
    elif break_it == "float_simplices":
        tri.simplices = tri.simplices + 0.5
    elif break_it == "duplicate_of_short":
        tri.duplicate_of = tri.duplicate_of[:10]
    else:
        tri.simplices = None
    report = lfqt.verify(pts, tri)
    assert not report.ok and report.problems and not report.checks["indices"]


def test_mesh_from_simplices_lets_verify_check_bare_simplices(rng):
    from lfqt.verification import mesh_from_simplices
    for d in (2, 3):
        pts = rng.random((500, d))
        s = lfqt.insert(pts).simplices
        assert lfqt.verify(pts, mesh_from_simplices(s, len(pts))).ok
        assert not lfqt.verify(pts, mesh_from_simplices(s[1:], len(pts))).ok
