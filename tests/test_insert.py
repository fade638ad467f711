"""Incremental insertion in 2D and 3D: every mesh is verified exactly."""
import copy
import itertools
import json
import pathlib
import subprocess
import sys

import numpy as np
import pytest
import scipy.spatial
from hypothesis import HealthCheck, given, settings, strategies as st

import lfqt
from lfqt.incremental import tetra
from lfqt.incremental.kernel import finite_cells, insert_all
from lfqt import orders, predicates as P
from lfqt.predicates.counters import CONFLICTS
from lfqt._input import exact_points3
from conftest import insert_verified, without_cell


def cells(simplices):
    return {tuple(sorted(map(int, s))) for s in np.asarray(simplices)}


def cospherical_integer_points(r2):
    """All integer points on the sphere x^2 + y^2 + z^2 = r2."""
    r = int(np.sqrt(r2)) + 1
    return np.array([p for p in itertools.product(range(-r, r + 1), repeat=3)
                     if sum(v * v for v in p) == r2], dtype=float)


@pytest.mark.parametrize("d", [2, 3])
@pytest.mark.parametrize("order", orders.ORDERS)
def test_agrees_with_scipy_in_general_position(order, d, rng):
    pts = rng.random((1500, d))
    tri = insert_verified(pts, order=order)
    assert cells(tri.simplices) == cells(scipy.spatial.Delaunay(pts).simplices)


@pytest.mark.parametrize("name,pts", [
    ("grid", np.stack(np.meshgrid(*[np.arange(7)] * 3), -1).reshape(-1, 3).astype(float)),
    ("cospherical", cospherical_integer_points(50)),
    ("cospherical+centre", np.r_[cospherical_integer_points(81), [[0.0, 0.0, 0.0]]]),
    ("coplanar start", np.r_[np.c_[np.random.default_rng(1).random((60, 2)), np.zeros(60)],
                              np.random.default_rng(2).random((60, 3))]),
    ("collinear start", np.r_[np.c_[np.arange(30.0), np.zeros(30), np.zeros(30)],
                               np.random.default_rng(3).random((50, 3)) * 30]),
    ("faces and edges", np.array([p for p in itertools.product([0, 0.5, 1], repeat=3)])),
    ("duplicates", np.r_[np.random.default_rng(4).random((200, 3)),
                         np.random.default_rng(4).random((200, 3))[:50]]),
])
@pytest.mark.parametrize("order", ["kdtree", "random", "input"])
def test_degenerate_3d_sets(name, pts, order):
    tri = insert_verified(pts, order=order)
    assert not tri.degenerate
    if name == "duplicates":
        assert tri.n_distinct == 200 and tri.stats["counts"]["duplicates"] == 50


def rounded_sphere(n, seed):
    """n points on the sphere of radius 0.45 about the origin, rounded to
    doubles: cospherical up to rounding, the 3D analogue of gDel2D's circle."""
    v = np.random.default_rng(seed).normal(size=(n, 3))
    return 0.45 * v / np.linalg.norm(v, axis=1)[:, None]


@pytest.mark.parametrize("order", ["kdtree", "brio"])
def test_rounded_sphere_is_exact_without_the_expansions(order):
    # Nearly every in-sphere test fails the float filter here; the double-
    # double stage with its tail terms (lfqt.predicates.spatial) decides them:
    # without it this input ran 50x slower than the cube.
    tri = insert_verified(rounded_sphere(1500, 7), order=order)
    counts = tri.stats["counts"]
    assert counts["incircle_stage1_undecided"] > counts["incircle_tests"] // 2
    assert counts["incircle_stage2_undecided"] == 0


def test_degenerate_2d_sets():
    g = np.stack(np.meshgrid(np.arange(20), np.arange(20)), -1).reshape(-1, 2).astype(float)
    insert_verified(g, order="kdtree")
    ang = np.arange(12) * np.pi / 6
    circle = np.c_[np.round(np.cos(ang) * 5), np.round(np.sin(ang) * 5)]
    insert_verified(np.unique(np.r_[circle, [[0.0, 0.0]]], axis=0), order="input")


@pytest.mark.parametrize("pts,d", [
    (np.c_[np.random.default_rng(0).random((30, 2)), np.zeros(30)], 3),
    (np.c_[np.arange(10.0), np.arange(10.0), np.arange(10.0)], 3),
    (np.c_[np.arange(10.0), 2 * np.arange(10.0)], 2),
    (np.ones((5, 3)), 3),
])
def test_lower_dimensional_sets_are_flagged(pts, d):
    tri = lfqt.insert(pts)
    assert tri.degenerate and len(tri.simplices) == 0 and tri.simplices.shape[1] == d + 1
    assert "affinely independent" in tri.reason


def test_same_triangulation_for_every_order(rng):
    pts = rng.random((2000, 3))
    base = cells(insert_verified(pts, order="kdtree").simplices)
    for order in orders.ORDERS[1:]:
        assert cells(lfqt.insert(pts, order=order).simplices) == base
    assert cells(lfqt.insert(pts, hint="sibling").simplices) == base


def test_explicit_order_and_bad_order():
    pts = np.random.default_rng(0).random((50, 3))
    perm = np.arange(50)[::-1]
    tri = insert_verified(pts, order=(perm, np.full(50, -1)))
    assert tri.stats["order"] == "explicit"
    with pytest.raises(ValueError, match="permutation"):
        lfqt.insert(pts, order=(np.zeros(50, int), np.full(50, -1)))
    for bad_hint in (50, -2):  # an index into the points, or -1
        with pytest.raises(ValueError, match="a point index or -1"):
            lfqt.insert(pts, order=(perm, np.full(50, bad_hint)))
    hinted = insert_verified(pts, order=(perm, np.r_[-1, perm[:-1]]))
    assert cells(hinted.simplices) == cells(tri.simplices)


def test_more_points_than_int32_cell_ids_allow_is_a_clear_error(monkeypatch):
    import lfqt.incremental as incremental
    assert 8 * incremental.MAX_POINTS < 2 ** 31
    monkeypatch.setattr(incremental, "MAX_POINTS", 10)
    with pytest.raises(ValueError, match="at most 10 points"):
        lfqt.insert(np.random.default_rng(0).random((11, 3)))
    assert len(lfqt.insert(np.random.default_rng(0).random((10, 3))).simplices)
    # 3D: 4 t + i must be an int32 for every tetrahedron a set may need
    assert 7 * incremental.MAX_POINTS_3D <= tetra.MAX_CELLS and 4 * tetra.MAX_CELLS < 2 ** 31
    monkeypatch.setattr(incremental, "MAX_POINTS_3D", 5)
    with pytest.raises(ValueError, match="at most 5 3D points"):
        lfqt.insert(np.random.default_rng(0).random((6, 3)))
    assert len(lfqt.insert(np.random.default_rng(0).random((6, 2))).simplices)


def test_more_cells_than_int32_ids_allow_is_a_clear_error():
    pts = np.r_[cospherical_integer_points(121), [[0.0, 0.0, 0.0]]]
    P3 = exact_points3(pts)
    perm, hint = np.arange(len(pts)), np.full(len(pts), -1)
    full = tetra.insert_all(P3, perm, hint, 16.0, 8)[3]  # records used, growing from 8
    assert tetra.insert_all(P3, perm, hint, 16.0, 8, full)[3] == full  # exactly enough
    with pytest.raises(ValueError, match="int32"):
        tetra.insert_all(P3, perm, hint, 16.0, 8, full - 1)


@pytest.mark.parametrize("d", [2, 3])
@pytest.mark.parametrize("n", [300, 60_000])  # records on numpy's memory, then on a mapping
def test_output_written_over_the_records_is_the_output_beside_them(d, n):
    rng = np.random.default_rng(d)
    P = rng.random((n, d))
    perm, hint = np.arange(n), np.full(n, -1)
    run = insert_all(P, perm, hint, 1.0) if d == 2 else tetra.insert_all(P, perm, hint, 1.0)
    assert run.records is not None and run.ok
    ids = rng.permutation(n)
    shift = 2 if d == 3 else 0  # 3D neighbours are facet refs, 4 t + i
    beside = finite_cells(run.C, run.N, run.mark, ids, shift=shift)
    over = finite_cells(run.C, run.N, run.mark, ids, run.records, shift=shift)
    assert np.shares_memory(over[0], run.records)
    for a, b in zip(beside, over):
        assert np.array_equal(a, b)
    # and it is the Delaunay triangulation (unique for random points): Qhull's
    assert cells(np.argsort(ids)[over[0]]) == cells(scipy.spatial.Delaunay(P).simplices)


def test_growth_paths_give_the_same_mesh():
    pts = np.r_[cospherical_integer_points(121), [[0.0, 0.0, 0.0]]]  # centre: a huge cavity
    P3 = exact_points3(pts)
    perm = np.arange(len(pts))
    hint = np.full(len(pts), -1)
    small = tetra.insert_all(P3, perm, hint, 16.0, 8)  # tiny storage, grows many times
    big = tetra.insert_all(P3, perm, hint, 16.0, 0)
    assert small.records is None and big.records is not None  # grown past them, or not
    ids = np.arange(len(pts))
    s_small, _, _ = finite_cells(small[0], small[1], small[2], ids, shift=2)
    s_big, _, _ = finite_cells(big[0], big[1], big[2], ids, shift=2)
    assert cells(s_small) == cells(s_big)
    assert big[5][CONFLICTS] > 256  # the centre's cavity outgrew the initial scratch
    insert_verified(pts, order="input")


@pytest.mark.parametrize("d", [2, 3])
def test_an_insertion_compiles_only_its_own_dimensions_kernel(d):
    # the drivers typed afresh in a child process, whatever the numba cache
    # holds: the other dimension's range kernel must not be loaded or
    # compiled (it took 11-13 s of a first call with a cold cache)
    code = f"""
import numba, numpy as np, lfqt
from lfqt.incremental import kernel, tetra
kernel._insert_all = numba.njit(kernel._insert_all.py_func)
tetra._run_alone = numba.njit(tetra._run_alone.py_func)
P = np.random.default_rng(0).random((50, {d}))
assert lfqt.verify(P, lfqt.insert(P)).ok
print(len(kernel._insert_range.signatures), len(tetra._insert_lane.signatures))
"""
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.split() == (["1", "0"] if d == 2 else ["0", "1"])


def test_kdtree_counts_match_paper_two(rng):
    pts = rng.random((30000, 3))
    tri = insert_verified(pts, order="kdtree", phase_times=True)
    per = tri.stats["per_point"]
    assert 9 < per["orientation_tests"] < 15  # paper 2, Table 8: about 11.7
    assert 12 < per["conflicts"] < 25  # paper 2 counts 17 inside CGAL
    sec = tri.stats["seconds"]
    assert sec["order"] > 0 and sec["locate"] > 0 and sec["cavity"] > 0
    assert sec["locate"] + sec["cavity"] <= sec["insert"] * 1.05
    # without phase times: the same counts, and no cycles reported as zero
    plain = lfqt.insert(pts, order="kdtree")
    assert "locate" not in plain.stats["seconds"] and "cycles" not in plain.stats
    timed = {k: v for k, v in tri.stats["counts"].items() if not k.endswith("_cycles")}
    assert plain.stats["counts"] == timed and tri.stats["counts"]["cavity_cycles"] > 0


def _insphere(pts, cell, p):
    a, b, c, d = (tuple(map(float, pts[v])) for v in cell)
    o, _ = P.orient3d_staged(a, b, c, d, P.O3D_A)
    s, _ = P.insphere_staged(a, b, c, d, tuple(map(float, p)), P.ISP_A)
    return s * np.sign(o)


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2 ** 32 - 1), st.integers(10, 120))
def test_inserting_a_point_removes_exactly_the_cells_whose_sphere_contains_it(seed, n):
    pts = np.random.default_rng(seed).random((n, 3))
    head = np.arange(n - 1)
    before = lfqt.insert(pts[:-1], order=(head, np.full(n - 1, -1)))
    after = lfqt.insert(pts, order=(np.arange(n), np.full(n, -1)))
    removed = cells(before.simplices) - cells(after.simplices)
    expect = {c for c in cells(before.simplices) if _insphere(pts, c, pts[-1]) > 0}
    assert removed == expect


@settings(max_examples=40, deadline=None)
@given(st.lists(st.tuples(*[st.integers(-3, 3).map(float)] * 3), min_size=5, max_size=60),
       st.sampled_from(["kdtree", "brio", "input"]))
def test_random_integer_sets_are_delaunay(points, order):
    pts = np.array(points)
    tri = lfqt.insert(pts, order=order)
    assert lfqt.verify(pts, tri).ok
    assert tri.n_distinct == len({tuple(p) for p in points})


def test_verify_3d_rejects_broken_meshes(rng):
    pts = rng.random((400, 3))
    tri = insert_verified(pts)
    flipped = copy.copy(tri)
    s = tri.simplices.copy()
    s[7, [0, 1]] = s[7, [1, 0]]
    flipped.simplices = s
    rep = lfqt.verify(pts, flipped)
    assert not rep.ok and not rep.checks["orientation"]
    holed = without_cell(tri, np.flatnonzero((tri.neighbors >= 0).all(axis=1))[0])
    holed.hull = None
    rep = lfqt.verify(pts, holed)
    assert not rep.ok and not rep.checks["convex_boundary"]


@pytest.mark.parametrize("d", [2, 3])
@pytest.mark.parametrize("scale", [1.0, 2.0 ** -1050])
@pytest.mark.parametrize("order", ["kdtree", "input"])  # the Kd layout, and the coarse Hilbert one
def test_insert_leaves_its_input_untouched(d, scale, order, rng):
    """insert reads the caller's array in place when it needs no rescale
    (lfqt._input.exact_points(copy=False)): it must never write it, nor
    refuse a read-only one (numpy and numba raise on a write to it)."""
    pts = rng.random((3000, d)) * scale
    before = pts.copy()
    pts.setflags(write=False)
    tri = insert_verified(pts, order=order)
    assert np.array_equal(pts, before) and tri.points is pts
    assert tri.n_distinct == 3000
    assert np.array_equal(tri.duplicate_of, np.arange(3000))


# Parallel 3D insertion (tetra's lanes).  The lanes start after SEQUENTIAL
# points; the tests lower it so that small sets run in rounds, and a child
# process runs the sets that could crash a kernel.
PARALLEL_CASES = """
import json, sys
sys.path.insert(0, "tests")
import numpy as np
import lfqt
from lfqt.incremental import tetra
from test_insert import hard_3d_sets
tetra.SEQUENTIAL = 64
if len(sys.argv) > 1:  # a lane's records run out: its other points are deferred
    tetra.LANE_RECORDS, tetra.LANE_SLACK = 2, 8
out = {}
for name, pts in hard_3d_sets():
    got = {}
    for threads in (1, 2, 7):
        a = lfqt.insert(pts, threads=threads)
        b = lfqt.insert(pts, threads=threads)
        assert lfqt.verify(pts, a).ok, (name, threads, lfqt.verify(pts, a).reason)
        assert np.array_equal(a.simplices, b.simplices), (name, threads)  # run to run
        got[threads] = sorted(map(tuple, np.sort(a.simplices, axis=1).tolist()))
    out[name] = got[1] == got[2] == got[7]
print(json.dumps(out))
"""


def hard_3d_sets():
    """(name, points) of the 3D sets the parallel tests run: random, a
    grid, cospherical integers, duplicates, -0.0, huge, tiny and subnormal
    magnitudes."""
    rng = np.random.default_rng(5)
    grid = np.stack(np.meshgrid(*[np.arange(12.0)] * 3), -1).reshape(-1, 3)
    uniform = rng.random((3000, 3))
    dups = np.r_[uniform[:1500], uniform[:700]]
    signed = np.r_[grid[:500] - 5.0, [[-0.0, 0.0, -0.0]]]
    return [("uniform", uniform), ("grid", grid),
            ("cospherical", cospherical_integer_points(121)),
            ("duplicates", dups), ("signed zero", signed),
            ("huge", uniform * 1e300), ("tiny", uniform * 1e-300),
            ("subnormal", grid[:800] * 5e-324)]


@pytest.mark.parametrize("starved", [False, True])
def test_parallel_3d_is_exact_deterministic_and_the_same_where_unique(starved):
    args = [sys.executable, "-c", PARALLEL_CASES] + (["starved"] if starved else [])
    proc = subprocess.run(args, capture_output=True, text=True, timeout=900,
                          cwd=pathlib.Path(__file__).resolve().parents[1])
    assert proc.returncode == 0, proc.stderr[-3000:]
    same = json.loads(proc.stdout.strip().splitlines()[-1])
    assert set(same) == {name for name, _ in hard_3d_sets()}
    # unique Delaunay tetrahedralizations: the same tetrahedra on every count
    for name in ("uniform", "duplicates", "huge", "tiny"):
        assert same[name], name


def test_parallel_3d_runs_in_rounds_and_matches_one_thread(rng, monkeypatch):
    monkeypatch.setattr(tetra, "SEQUENTIAL", 256)
    passes = []
    real = tetra._parallel_pass

    def spy(*args):
        out = real(*args)
        passes.append((len(args[2]), len(out[2]), args[6][1]))  # todo, left, the slabs' axis
        return out

    monkeypatch.setattr(tetra, "_parallel_pass", spy)
    pts = rng.random((20000, 3))
    one = lfqt.insert(pts, threads=1)
    assert not passes  # one thread: no lanes
    two = insert_verified(pts, threads=2)
    assert len(passes) >= 2 * 5  # rounds of 256, 512, ... each in two passes
    assert all(left < todo or todo == 0 for todo, left, _ in passes)  # every pass inserts
    # each round's passes cross two sides; the last round's leftovers, the third
    rounds = passes[:-1] if len(passes) % 2 else passes
    assert all({a for _, _, a in rounds[k:k + 2]} == {rounds[0][2], rounds[1][2]}
               for k in range(0, len(rounds), 2))
    assert len(passes) % 2 == 1 and passes[-1][2] not in {rounds[0][2], rounds[1][2]}
    assert cells(one.simplices) == cells(two.simplices)
    assert lfqt.Delaunay(pts, threads=2).simplices.shape == one.simplices.shape


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(st.tuples(*[st.integers(-3, 3).map(float)] * 3), min_size=5, max_size=120))
def test_parallel_3d_random_integer_sets_are_delaunay(points):
    points = np.array(points)
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(tetra, "SEQUENTIAL", 8)
        tri = lfqt.insert(points, threads=3)
    report = lfqt.verify(points, tri)
    assert report.ok or tri.degenerate, report.reason


def test_threads_must_be_a_positive_integer():
    pts = np.random.default_rng(0).random((50, 3))
    for bad in (0, -1, 1.5, True, "2"):
        with pytest.raises(ValueError, match="threads"):
            lfqt.insert(pts, threads=bad)
    assert lfqt.insert(pts, threads=None).simplices.shape[1] == 4
