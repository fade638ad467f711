"""The peers of the field today (issue 53): each one's mesh judged exactly
on random points, each measured in a child process; the coordinate matching
that maps their vertices back to input rows; the exact judgement of a mesh.
A peer that cannot be installed skips with the reason (the setup and CI
install them all)."""
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import drivers
import lfqt
from drivers.exactness import describe, judge
from drivers.matching import rows_of

FIELD = ["delaunator", "cdt", "startinpy", "meshpy-triangle", "gmsh", "cgal-python",
         "cgal-python-points"]


def triangle_set(simplices):
    """The triangles as vertex sets: Delaunator and gmsh give some clockwise."""
    return {tuple(sorted(map(int, t))) for t in np.asarray(simplices)}


def require(name):
    ok, why = drivers.available(name)
    if not ok:
        pytest.skip(why)


def isolated(name, pts):
    m = drivers.measure_isolated(drivers.make(name), pts, repeats=1, keep_simplices=True,
                                 timeout=60)
    assert m.ok, m
    return m


@pytest.mark.parametrize("name", FIELD)
def test_field_peers_give_lfqts_triangulation_on_random_points(name, rng):
    require(name)
    pts = rng.random((1500, 2))
    m = isolated(name, pts)
    assert m.seconds[0] > 0 and m.version
    report = lfqt.verify(pts, m.simplices)
    if drivers.make(name).inexact:  # gmsh: what its flag says, and no more
        assert not report.ok
        ours = triangle_set(lfqt.triangulate(pts).simplices)
        theirs = triangle_set(m.simplices)
        assert len(theirs) < len(ours) and len(theirs - ours) < 0.05 * len(ours)
        return
    assert report.ok, report.summary
    assert triangle_set(m.simplices) == triangle_set(lfqt.triangulate(pts).simplices)


def test_every_field_peer_is_registered_in_its_own_family():
    families = {drivers.make(n).family for n in FIELD}
    assert len(families) == len(FIELD) - 1  # the two cgal-python names are one family
    assert set(FIELD) <= set(drivers.names(2))


def test_startinpy_keeps_points_closer_than_its_default_snap_tolerance(rng):
    require("startinpy")
    pts = rng.random((300, 2))
    pts[1] = pts[0] + 1e-7  # merged at startinpy's default tolerance of 1e-3
    m = isolated("startinpy", pts)
    assert lfqt.verify(pts, m.simplices).ok and np.isin(1, m.simplices)


def test_cdt_refuses_duplicates_with_an_error(rng):
    require("cdt")
    pts = rng.random((100, 2))
    pts[5] = pts[7]
    m = drivers.measure_isolated(drivers.make("cdt"), pts, repeats=1, timeout=60)
    assert not m.ok and m.reason == "error"


def test_delaunator_times_itself_inside_node(rng):
    require("delaunator")
    peer = drivers.make("delaunator")
    pts = rng.random((2000, 2))
    m = drivers.measure(peer, pts, repeats=2)
    assert len(m.seconds) == 2 and all(0 < s < 5 for s in m.seconds)
    assert peer.report["node"].startswith("v") and peer.report["triangles"] > 3000


def test_a_measurement_can_judge_its_mesh_exactly(rng):
    pts = rng.random((400, 2))
    m = drivers.measure_isolated(drivers.make("qhull-2d"), pts, repeats=1, check=True)
    assert m.ok and m.check["verdict"] == "exact" and describe(m.check) == "exact"


@given(st.integers(0, 2 ** 32 - 1), st.integers(1, 200))
def test_rows_of_finds_each_input_row_exactly(seed, n):
    rng = np.random.default_rng(seed)
    pts = np.round(rng.normal(size=(n, 2)), int(rng.integers(0, 4)))  # repeats and negatives
    perm = rng.permutation(n)
    rows = rows_of(pts, pts[perm])
    assert np.array_equal(pts[rows], pts[perm])
    first = {tuple(p): i for i, p in reversed(list(enumerate(pts.tolist())))}
    assert rows.tolist() == [first[tuple(p)] for p in pts[perm].tolist()]


def test_rows_of_takes_signed_zeros_as_one_and_marks_strangers():
    pts = np.array([[0.0, 1.0], [2.0, -0.0], [3.0, 3.0]])
    rows = rows_of(pts, np.array([[-0.0, 1.0], [2.0, 0.0], [3.0, 3.0 + 1e-15]]))
    assert rows.tolist() == [0, 1, -1]


def test_judge_counts_bad_edges_and_missing_triangles():
    # a square pushed off its circle: one diagonal is Delaunay, the other is not
    pts = np.array([[0.0, 0.0], [1.0, 0.0], [1.1, 1.0], [0.0, 1.0], [0.5, -3.0]])
    good = lfqt.triangulate(pts).simplices
    assert judge(pts, good)["verdict"] == "exact"
    dropped = judge(pts, good[1:])
    assert dropped["verdict"] == "wrong" and dropped["missing_triangles"] == 1
    a, b, c, d = 0, 1, 2, 3  # the Delaunay diagonal is 0-2 or 1-3: use the other
    diag = {tuple(sorted(e)) for t in good.tolist() for e in zip(t, t[1:] + t[:1])}
    flipped = [[a, b, d], [b, c, d]] if (0, 2) in diag else [[a, b, c], [a, c, d]]
    rest = [t for t in good.tolist() if 4 in t]
    bad = judge(pts, np.array(flipped + rest))
    assert bad["verdict"] == "wrong" and bad["non_delaunay_edges"] == 1
    assert describe(bad) == "wrong: 1 bad edges"


def test_a_peer_that_is_not_installed_says_how_to_install_it(monkeypatch, tmp_path):
    from drivers import cdt, delaunator
    monkeypatch.setattr(cdt.CdtPeer, "module", "pythoncdt_not_here")
    ok, why = drivers.available("cdt")
    assert not ok and "pip install pythoncdt" in why
    monkeypatch.setattr(delaunator, "MODULE", tmp_path / "missing" / "package.json")
    ok, why = drivers.available("delaunator")
    assert not ok and "npm install" in why
