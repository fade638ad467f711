"""The LFQT and alternating triangulators on fixtures and random sets; every
mesh is verified exactly (conftest.triangulate_verified)."""
import subprocess
import sys
import textwrap

import numpy as np
import pytest
import scipy.spatial
from hypothesis import given, strategies as st

import lfqt
from lfqt.dc.layout import STACK
from lfqt.predicates.planar import orient2d_exact
from conftest import triangle_set, triangulate_verified

SUBDIVISIONS = ["lfqt", "alternating"]
DTYPES = [np.float64, np.float32]


def grid(k):
    g = np.stack(np.meshgrid(np.arange(k), np.arange(k)), -1).reshape(-1, 2)
    return g.astype(np.float64)


def fixtures():
    rng = np.random.default_rng(7)
    ang = np.linspace(0, 2 * np.pi, 257, endpoint=False)
    rot = np.array([[0.6, -0.8], [0.8, 0.6]])  # exact Pythagorean rotation
    k = np.arange(17)
    return {
        "grid_2^5": grid(32),
        "grid_2^4_offset": grid(16) + 2.0 ** 20,
        "rotated_grid": grid(20) @ rot.T,
        "circle": np.c_[np.cos(ang), np.sin(ang)],
        "circle_with_centre": np.r_[np.c_[np.cos(ang), np.sin(ang)], [[0.0, 0.0]]],
        "regular_polygon": np.c_[np.cos(2 * np.pi * k / 17), np.sin(2 * np.pi * k / 17)],
        "square_corners_repeated": np.tile([[0.0, 0.0], [1, 0], [1, 1], [0, 1]], (5, 1)),
        "negative_zero": np.array([[0.0, 0.0], [-0.0, 1.0], [1.0, -0.0], [-0.0, -0.0], [0.5, 0.5]]),
        "all_quadrants": rng.standard_normal((2000, 2)),
        "tiny_cluster": 0.5 + 1e-12 * rng.random((500, 2)),
        "below_float32": np.r_[rng.random((200, 2)), rng.random((200, 2)) + 2.0 ** -40],
        "scaled_1e-300": 1e-300 * rng.random((500, 2)),
        "scaled_1e-9": 1e-9 * rng.random((500, 2)),
        "scaled_1e9": 1e9 * rng.random((500, 2)),
        "scaled_1e300": 1e300 * rng.random((500, 2)),
        "subnormal": 1e-310 * rng.random((500, 2)),
        "small_integers": rng.integers(0, 6, (300, 2)).astype(np.float64),
        "line_plus_one": np.r_[np.c_[np.arange(50.0), np.zeros(50)], [[10.0, 1.0]]],
        "two_columns": np.r_[np.c_[np.zeros(30), np.arange(30.0)], np.c_[np.ones(30), np.arange(30.0)]],
    }


@pytest.mark.parametrize("subdivision", SUBDIVISIONS)
@pytest.mark.parametrize("name", sorted(fixtures()))
def test_fixtures_are_delaunay(name, subdivision):
    pts = fixtures()[name]
    tri = triangulate_verified(pts, subdivision=subdivision)
    assert not tri.degenerate
    if name not in ("scaled_1e-300", "subnormal") and np.abs(pts).max() < 3e38 \
            and np.abs(pts[pts != 0]).min(initial=1) > 1e-38:
        triangulate_verified(pts.astype(np.float32), subdivision=subdivision)


@pytest.mark.parametrize("subdivision", SUBDIVISIONS)
@pytest.mark.parametrize("dtype", DTYPES)
@pytest.mark.parametrize("pts,reason", [
    (np.c_[np.arange(10.0), 2 * np.arange(10.0)], "all points collinear"),
    (np.c_[np.zeros(9), np.arange(9.0)], "all points collinear"),
    (np.ones((6, 2)), "fewer than 3 distinct points"),
    (np.array([[0.0, 0.0], [1.0, 1.0], [0.0, 0.0]]), "fewer than 3 distinct points"),
    (np.zeros((1, 2)), "fewer than 3 distinct points"),
])
def test_degenerate_sets_are_flagged(pts, reason, subdivision, dtype):
    p = pts.astype(dtype)
    tri = triangulate_verified(p, subdivision=subdivision)
    assert tri.degenerate and tri.reason == reason and len(tri.simplices) == 0
    order = np.lexsort((p[:, 1], p[:, 0]))
    assert set(tri.hull) == {tri.duplicate_of[order[0]], tri.duplicate_of[order[-1]]}


@pytest.mark.parametrize("subdivision", SUBDIVISIONS)
def test_three_points_are_the_merges_base_case(subdivision, rng):
    """Any three points meet in the base case of a lone vertex and an edge:
    one orientation test makes the triangle; a collinear triple goes on to
    the general merge, which tests more."""
    triples = list(rng.integers(-3, 4, (300, 3, 2)).astype(np.float64))
    triples += [np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]]),
                np.array([[5.0, 0.0], [5.0, -1.0], [5.0, 3.0]])]
    seen = set()
    for pts in triples:
        if len(np.unique(pts, axis=0)) < 3:
            continue
        tri = triangulate_verified(pts, subdivision=subdivision, counters=True)
        tests = tri.stats["counts"]["orientation_tests"]
        seen.add(tri.degenerate)
        if tri.degenerate:
            assert tri.reason == "all points collinear" and tests > 1
        else:
            assert tests == 1 and len(tri.simplices) == 1
    assert seen == {True, False}


@pytest.mark.parametrize("subdivision", SUBDIVISIONS)
def test_four_points_are_the_merges_base_case(subdivision, rng):
    """Four points meet as two edges or as a lone vertex and a triangle, both
    base cases: four orient tests in all and at most one in-circle test,
    where the general merges make more.  Sets with a collinear triple go on
    to the general merge (tested more), cocircular ones (squares, inscribed
    quads) to the base case's in-circle tie."""
    quads = list(rng.integers(-4, 5, (400, 4, 2)).astype(np.float64))
    quads += [np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]),
              np.array([[0.0, 0.0], [4.0, 0.0], [0.0, 4.0], [1.0, 1.0]])]
    shapes = set()
    for pts in quads:
        if len(np.unique(pts, axis=0)) < 4:
            continue
        tri = triangulate_verified(pts, subdivision=subdivision, counters=True)
        counts = tri.stats["counts"]
        collinear = any(orient2d_exact(*pts[list(c)].ravel()) == 0.0
                        for c in ((0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)))
        if collinear:
            assert counts["orientation_tests"] > 4 or tri.degenerate
            continue
        assert counts["orientation_tests"] == 4 and counts["incircle_tests"] <= 1
        shapes.add(len(tri.simplices))
    assert shapes == {2, 3}  # convex quads, and a point inside a triangle


def test_many_calls_in_one_process_stay_sound():
    """Hundreds of small sets of every kind (duplicates, grids, cocircular
    rings, huge and tiny magnitudes), one after the other in one child
    process, each verified.  A kernel that writes to memory it no longer
    owns corrupts the allocator and crashes a later call (a merge stack
    freed while a borrowed view of it was still in use did, at the 24th)."""
    code = textwrap.dedent("""
        import numpy as np
        import lfqt
        from lfqt.verification import verify
        rng = np.random.default_rng(5)
        for t in range(400):
            n, kind = int(rng.integers(4, 120)), t % 5
            if kind == 0:
                p = rng.integers(-3, 4, (n, 2)).astype(float)
            elif kind == 1:
                p = rng.random((n, 2)) * 10.0 ** float(rng.integers(-300, 300))
            elif kind == 2:
                p = np.round(rng.random((n, 2)) * 8) / 8
            elif kind == 3:
                a = rng.integers(0, 8, n) * np.pi / 4
                p = np.c_[np.cos(a), np.sin(a)] * rng.integers(1, 3, (n, 1))
            else:
                p = rng.standard_normal((n, 2))
                p[::3] = p[1]
            for subdivision in ("lfqt", "alternating"):
                report = verify(p, lfqt.triangulate(p, subdivision=subdivision))
                assert report.ok, (t, subdivision, report)
        print("sound")
    """)
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=600)
    assert proc.returncode == 0 and proc.stdout.strip() == "sound", proc.stderr[-2000:]


def test_peak_memory_of_a_call_is_that_of_the_merges_arrays():
    """In a child process, 1M uniform points, on 1 and 2 threads: the
    resident memory a call adds at its peak (VmHWM, reset before the call)
    stays within the arrays alive at the end of the merges, T, P, perm,
    ghost_out (then duplicate_of), the gaps and a piece of ops per thread,
    plus 1 MiB: no list of all ops, and no result array beside T
    (lfqt.dc._memory).  Before the ops were swept
    in pieces and the output written over T, a call added 81 bytes a
    point, here 8 more than this bound."""
    code = textwrap.dedent("""
        import gc, sys
        import numpy as np
        import lfqt
        from lfqt import dc, preload, workspace
        from lfqt.dc.state import OPS_PIECE

        def status(key):
            with open("/proc/self/status") as f:
                return next(int(l.split()[1]) * 1024 for l in f if l.startswith(key + ":"))

        n = 1_000_000
        pts = np.random.default_rng(3).random((n, 2))
        preload.wait()
        lfqt.triangulate(pts[:1000], threads=2)  # the pool's threads started
        for threads in (1, 2):
            gc.collect()
            workspace.release()
            try:
                with open("/proc/self/clear_refs", "w") as f:
                    f.write("5")  # VmHWM back to VmRSS
            except OSError:
                print("skip"); sys.exit(0)
            before = status("VmRSS")
            tri = lfqt.triangulate(pts, threads=threads)
            peak = status("VmHWM") - before
            arrays = (workspace.view_bytes(dc._t_spec(n)) + workspace.view_bytes(dc._point_spec(n))
                      + n * tri.hull.itemsize + tri.duplicate_of.nbytes + n
                      + threads * OPS_PIECE * 8)
            print(threads, peak, arrays)
            assert peak <= arrays + (1 << 20), (threads, peak / n, arrays / n)
            assert lfqt.verify(pts, tri).ok
            del tri
        print("fits")
    """)
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=600)
    if proc.stdout.strip() == "skip":
        pytest.skip("no /proc/self/clear_refs to reset the peak")
    assert proc.returncode == 0 and proc.stdout.strip().endswith("fits"), \
        proc.stdout + proc.stderr[-2000:]


def test_empty_input():
    tri = lfqt.triangulate(np.empty((0, 2)))
    assert tri.degenerate and len(tri.hull) == 0 and len(tri.simplices) == 0


def test_duplicates_are_reported_and_inserted_once(rng):
    base = rng.random((400, 2))
    pts = np.r_[base, base[::3], base[:10]]
    tri = triangulate_verified(pts)
    assert tri.n_distinct == 400
    dup = tri.duplicate_of
    assert np.all(dup[:400] == np.arange(400))
    assert np.array_equal(dup[400:400 + len(base[::3])], np.arange(0, 400, 3))
    assert np.all(np.bincount(tri.simplices.ravel(), minlength=len(pts))[400:] == 0)


@pytest.mark.parametrize("copies", [0, 1])
def test_duplicate_of_is_the_identity_but_for_the_copies(copies, rng):
    pts = rng.random((2000, 2))
    pts = np.r_[pts, pts[1234:1234 + copies]]
    tri = triangulate_verified(pts, threads=2)
    want = np.arange(len(pts))
    want[2000:] = 1234
    assert np.array_equal(tri.duplicate_of, want) and tri.n_distinct == 2000


@given(st.integers(0, 2 ** 32 - 1), st.integers(3, 600), st.integers(0, 40),
       st.sampled_from([1, 2, 3]))
def test_hull_heavy_sets_with_copies_are_delaunay(seed, n, copies, threads):
    """Points on a parabola's arc, all on the hull, some repeated: most of
    the ghosts' and the copies' slots lie among the first m, the holes the
    output packs the real triangles into (lfqt.dc.output.fill_holes)."""
    rng = np.random.default_rng(seed)
    x = rng.random(n)
    pts = np.c_[x, x * x]
    pts = np.r_[pts, pts[rng.integers(0, n, copies)]]
    tri = triangulate_verified(pts, threads=threads)
    assert tri.n_distinct == len(np.unique(pts, axis=0))


@pytest.mark.parametrize("subdivision", SUBDIVISIONS)
def test_agrees_with_scipy_in_general_position(subdivision, rng):
    pts = rng.random((3000, 2))
    ours = triangulate_verified(pts, subdivision=subdivision)
    theirs = scipy.spatial.Delaunay(pts)
    assert triangle_set(ours.simplices) == triangle_set(theirs.simplices)


def test_output_conventions(rng):
    pts = rng.random((500, 2))
    tri = triangulate_verified(pts)
    assert tri.simplices.dtype == np.int32 and tri.neighbors.dtype == np.int32
    assert tri.simplices.shape == tri.neighbors.shape == (len(tri.simplices), 3)
    # neighbour i is opposite vertex i: it shares the other two vertices
    for t in range(0, len(tri.simplices), 37):
        for i in range(3):
            u = tri.neighbors[t, i]
            if u >= 0:
                shared = set(tri.simplices[t]) - {tri.simplices[t, i]}
                assert shared <= set(tri.simplices[u])
    assert tri.points is pts


@pytest.mark.parametrize("subdivision", SUBDIVISIONS)
def test_order_of_input_does_not_change_the_triangulation(subdivision, rng):
    pts = rng.random((1000, 2))
    perm = rng.permutation(1000)
    a = triangulate_verified(pts, subdivision=subdivision)
    b = triangulate_verified(pts[perm], subdivision=subdivision)
    assert triangle_set(a.simplices) == triangle_set(perm[b.simplices])


def test_filters_agree_and_level_filter_leaves_fewer_undecided():
    pts = np.random.default_rng(3).random((20000, 2))
    lev = triangulate_verified(pts, counters=True, filter="level")
    con = triangulate_verified(pts, counters=True, filter="constant")
    assert triangle_set(lev.simplices) == triangle_set(con.simplices)
    pl, pc = lev.stats["counts"], con.stats["counts"]
    assert pl["orientation_tests"] == pc["orientation_tests"] and pl["incircle_tests"] == pc["incircle_tests"]
    assert pl["incircle_stage1_undecided"] <= pc["incircle_stage1_undecided"]


def test_grid_cocircularity_goes_to_stage_two():
    tri = triangulate_verified(grid(64), counters=True)
    p = tri.stats["counts"]
    assert p["incircle_stage1_undecided"] > 0
    assert p["incircle_stage2_undecided"] == 0  # integer differences are exact: stage B decides


def test_stats_report_phases():
    tri = lfqt.triangulate(np.random.default_rng(0).random((1000, 2)), counters=True)
    assert set(tri.stats["seconds"]) >= {"sort", "subdivide", "merge", "total"}
    assert tri.stats["key_bits"] == 128 and tri.stats["n_distinct"] == 1000
    f32 = np.array([[0, 0], [1, 0], [0, 1]], dtype=np.float32)
    assert lfqt.triangulate(f32).stats["key_bits"] == 64


coordinate = st.one_of(st.integers(-4, 4).map(float), st.floats(-1, 1, width=32).map(float))


@given(st.lists(st.tuples(coordinate, coordinate), min_size=1, max_size=60),
       st.sampled_from(SUBDIVISIONS), st.sampled_from(DTYPES))
def test_random_degenerate_sets_are_delaunay(points, subdivision, dtype):
    pts = np.array(points, dtype=dtype)
    tri = triangulate_verified(pts, subdivision=subdivision)
    distinct = {tuple(p) for p in pts.tolist()}
    assert tri.n_distinct == len(distinct)


@given(st.integers(0, 2 ** 32 - 1), st.integers(3, 400))
def test_random_uniform_sets_match_between_subdivisions(seed, n):
    pts = np.random.default_rng(seed).random((n, 2))
    a = triangulate_verified(pts, subdivision="lfqt")
    b = triangulate_verified(pts, subdivision="alternating")
    assert triangle_set(a.simplices) == triangle_set(b.simplices)


def algorithm1_ops(keys, lo, hi):
    """fqDel's Algorithm 1 as written (recursive, binary search for the
    split), on Python ints: post-order ops and each split's bit."""
    ops, bits = [], {}

    def node(a, b):
        diff = keys[a] ^ keys[b - 1]
        if diff == 0:
            ops.append(-(a + 1))
            return
        bit = diff.bit_length() - 1
        split = next(i for i in range(a, b) if keys[i] >> bit & 1)
        node(a, split)
        node(split, b)
        ops.append(split)
        bits[split] = bit

    node(lo, hi)
    return ops, bits


@given(st.lists(st.integers(0, 2 ** 128 - 1) | st.integers(0, 40), min_size=1, max_size=80),
       st.data())
def test_subdivision_sweep_equals_algorithm_1(values, data):
    from lfqt.dc import subdivide
    keys = sorted(values)
    n = len(keys)
    lo = data.draw(st.integers(0, n - 1))
    hi = data.draw(st.integers(lo + 1, n))
    khi = np.array([k >> 64 for k in keys], dtype=np.uint64)
    klo = np.array([k & (2 ** 64 - 1) for k in keys], dtype=np.uint64)
    gaps = np.zeros(n, dtype=np.uint8)
    copies = subdivide.gap_bits(khi, klo, True, gaps, 0, n)
    assert [gaps[i] == subdivide.DUP for i in range(1, n)] == \
        [keys[i] == keys[i - 1] for i in range(1, n)]
    assert copies == (len(set(keys)) < n)
    part = np.zeros(n, dtype=np.uint8)  # a range's copies: past position 0 only
    assert subdivide.gap_bits(khi, klo, True, part, lo, hi) == \
        any(keys[i] == keys[i - 1] for i in range(max(lo, 1), hi))
    assert subdivide.run_starts(gaps, lo, hi).tolist() == \
        [i for i in range(lo, hi) if i == lo or keys[i] != keys[i - 1]]
    ops = np.zeros(2 * n + 3, dtype=np.int64)
    end = subdivide.subdivide_lfqt(gaps, lo, hi, ops, 3)
    expect_ops, expect_bits = algorithm1_ops(keys, lo, hi)
    assert ops[3:end].tolist() == expect_ops
    # the same sweep in pieces, as the merges run it (lfqt.dc.state.State.merge_range)
    piece = np.empty(data.draw(st.integers(STACK + 2, STACK + 12)), dtype=np.int64)
    stack = np.empty((2, STACK + 1), dtype=np.int64)
    swept, i, top = [], lo, -1
    while True:
        count, i, top = subdivide.subdivide_next(gaps, i, hi, piece, stack, top)
        if count == 0:
            break
        swept += piece[:count].tolist()
    assert swept == expect_ops
    assert {p: int(gaps[p]) for p in expect_bits} == expect_bits  # a split's code is its gap
    if all(k < 2 ** 64 for k in keys):  # 64-bit keys (float32 input)
        gaps64 = np.zeros(n, dtype=np.uint8)
        subdivide.gap_bits(khi[:0], klo, False, gaps64, 0, n)
        assert gaps64[1:].tolist() == gaps[1:].tolist()
