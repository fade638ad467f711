"""The 3D peers of issue 52 (gmsh's HXT and default paths, TetGen through
meshpy, lfqt's 3D peers and their threads), each measured in a child
process and its mesh judged exactly; the exact judgement of a 3D mesh.  A
peer that cannot be installed skips with the reason (the setup and CI
install them all)."""
import sys

import numpy as np
import pytest

import drivers
import generators
import lfqt
from drivers.exactness import describe, judge

NEW_3D = ["gmsh-hxt", "gmsh-default", "tetgen", "lfqt-delaunay"]


def tet_set(simplices):
    return {tuple(sorted(map(int, s))) for s in np.asarray(simplices)}


def require(name):
    ok, why = drivers.available(name)
    if not ok:
        pytest.skip(why)


def isolated(name, pts, **kwargs):
    m = drivers.measure_isolated(drivers.make(name, **kwargs), pts, repeats=1, warmup=False,
                                 keep_simplices=True, check=True, timeout=60)
    assert m.ok, m
    return m


def test_the_3d_peers_are_registered_in_their_families():
    assert set(NEW_3D) | {"qhull-3d", "cgal-dt3-parallel"} <= set(drivers.names(3))
    assert {drivers.make(n).family for n in NEW_3D} == {"gmsh_tetrahedralize", "meshpy_tet",
                                                        "ours"}
    assert drivers.make("gmsh-hxt", threads=2).threads == 2
    assert drivers.make("cgal-dt3-parallel", threads=2).threads == 2
    for name in ("gmsh-default", "tetgen", "qhull-3d"):
        with pytest.raises(ValueError, match="one thread"):
            drivers.make(name, threads=2)


@pytest.mark.parametrize("name, threads", [("gmsh-hxt", 1), ("gmsh-hxt", 2), ("tetgen", 1),
                                           ("lfqt-delaunay", 1)])
def test_exact_3d_peers_give_lfqts_tetrahedralisation(name, threads, rng):
    require(name)
    pts = rng.random((1500, 3))
    m = isolated(name, pts, threads=threads)
    assert m.seconds[0] > 0 and m.check["verdict"] == "exact", m.check
    assert tet_set(m.simplices) == tet_set(lfqt.insert(pts).simplices)


def test_gmsh_default_is_flagged_and_judged_wrong_where_the_issue_says(rng):
    require("gmsh-default")
    assert drivers.make("gmsh-default").inexact and not drivers.make("gmsh-hxt").inexact
    # issue 52: flat tetrahedra on a grid (here 10^3, in lexicographic order) ...
    grid = isolated("gmsh-default", generators.make("grid-3d-sorted", 1000))
    assert grid.check["verdict"] == "wrong" and grid.check["flat"] > 0
    assert describe(grid.check).startswith(f"wrong: {grid.check['flat']:,} flat tetrahedra")
    # ... and tetrahedra missing along the hull on uniform random points
    m = isolated("gmsh-default", rng.random((3000, 3)))
    assert m.check["verdict"] == "wrong" and m.check["reflex_hull_edges"] > 0
    assert m.check["lfqt_tetrahedra"] > m.check["tetrahedra"]


def test_a_known_hang_is_the_peers_own_and_only_on_its_sets():
    assert drivers.known_failure("gmsh-hxt", "huge-3d", 8000).startswith("known hang")
    assert drivers.known_failure("gmsh-hxt", "huge-3d", 500) is None
    assert drivers.known_failure("gmsh-hxt", "grid-3d", 8000) is None
    assert drivers.known_failure("gmsh-default", "huge-3d", 8000) is None
    assert drivers.known_failure("tetgen", "huge-3d", 8000) is None


def test_hxt_returns_no_tetrahedra_on_subnormal_points():
    require("gmsh-hxt")
    m = isolated("gmsh-hxt", generators.make("subnormal-3d", 200))
    assert m.check["verdict"] == "wrong" and m.check["tetrahedra"] == 0
    assert describe(m.check) == "wrong: no tetrahedra"


def test_a_3d_peer_that_is_not_installed_says_how_to_install_it(monkeypatch):
    monkeypatch.setitem(sys.modules, "gmsh", None)  # import gmsh raises ImportError
    monkeypatch.setitem(sys.modules, "meshpy.tet", None)
    for name, package in (("gmsh-hxt", "gmsh"), ("gmsh-default", "gmsh"), ("tetgen", "meshpy")):
        ok, why = drivers.available(name)
        assert not ok and f"pip install {package}" in why
        m = drivers.measure_isolated(drivers.make(name), np.random.default_rng(0).random((50, 3)),
                                     repeats=1, timeout=30)
        assert not m.ok and "is not installed" in m.detail


def test_our_3d_peers_pass_their_threads_on(monkeypatch, rng):
    real_insert, real_delaunay = lfqt.insert, lfqt.Delaunay
    seen = []

    def insert(points, **kwargs):
        seen.append(("insert", kwargs.get("threads")))
        return real_insert(points, **kwargs)

    def delaunay(points, **kwargs):
        seen.append(("Delaunay", kwargs.get("threads")))
        return real_delaunay(points, **kwargs)
    monkeypatch.setattr(lfqt, "insert", insert)
    monkeypatch.setattr(lfqt, "Delaunay", delaunay)
    pts = rng.random((500, 3))
    for name in ("lfqt-insert-kdtree", "lfqt-delaunay"):
        peer = drivers.make(name, threads=2)
        assert "threads" in peer.options
        m = drivers.measure(peer, pts, repeats=1, keep_simplices=True)
        assert lfqt.verify(pts, m.simplices).ok
    assert seen == [("insert", 2)] * 3 + [("Delaunay", 2)] * 3  # prepare's warm-up, warm-up, run


def bipyramid():
    """A triangle in z = 0 and an apex either side, far from cospherical:
    two tetrahedra sharing the triangle, or three around the apexes' edge,
    tile the hull; exactly one of the two is Delaunay."""
    a = [[1.0, 0.0, 0.0], [-0.5, 0.8, 0.0], [-0.5, -0.8, 0.0]]
    return np.array(a + [[0.1, 0.05, 2.0], [0.0, -0.1, -0.3]])


def test_judge_in_3d_finds_a_flipped_mesh_and_accepts_either_orientation():
    pts = bipyramid()
    good = lfqt.insert(pts).simplices
    assert judge(pts, good)["verdict"] == "exact"
    assert judge(pts, good[:, [1, 0, 2, 3]])["verdict"] == "exact"  # reversed: still Delaunay
    two = [[0, 1, 2, 3], [0, 2, 1, 4]]
    three = [[0, 1, 3, 4], [1, 2, 3, 4], [2, 0, 3, 4]]
    flipped = np.array(three if len(good) == 2 else two)  # the other tiling: a 2-3 flip
    bad = judge(pts, flipped)
    assert bad["verdict"] == "wrong" and bad["non_delaunay_faces"] >= 1
    assert bad["flat"] == 0 and bad["lfqt_tetrahedra"] == len(good)
    assert describe(bad) == f"wrong: {bad['non_delaunay_faces']:,} non-Delaunay faces"
    dropped = judge(pts, good[1:])
    assert dropped["verdict"] == "wrong" and "convex_boundary" in dropped["problems"]


def test_judge_in_3d_counts_flat_tetrahedra():
    pts = np.r_[bipyramid(), [[0.0, 0.0, 0.0]]]  # a point inside the triangle
    flat = [[0, 1, 2, 5]]
    check = judge(pts, np.r_[lfqt.insert(pts).simplices, flat])
    assert check["verdict"] == "wrong" and check["flat"] == 1


def test_lfqt_delaunay_takes_a_set_whose_first_rows_are_coplanar():
    pts = generators.make("grid-3d-sorted", 1000)  # its first 100 rows lie in one plane
    m = isolated("lfqt-delaunay", pts)
    assert m.check["verdict"] == "exact"
