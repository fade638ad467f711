"""lfqt.distributed: Tile & Merge, first on this process (the algorithm,
property-based), then on a real 2-worker dask LocalCluster (inputs, outputs,
the worker-loss retry).  Every mesh is checked twice: by lfqt.verify on the
gathered result and by the distributed lfqt.distributed.verify."""
import copy
import doctest
import inspect
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import example, given, strategies as st

import lfqt
from lfqt import distributed as D
from lfqt.distributed import check as dcheck, partition, sources

from conftest import triangle_set

dask_distributed = pytest.importorskip("dask.distributed")
import dask  # noqa: E402  (after dask.distributed: skipped with it)


def serial(points, tiles, chunk_rows=97):
    """Tile & Merge on this process, both checks applied."""
    chunks = sources.chunks(points, chunk_rows)
    tri = D.triangulate_on(chunks, D.Serial(), tiles=tiles, points=points)
    report = lfqt.verify(points, tri)
    assert report.ok, report.problems
    dist = D.verify_on(tri, chunks, D.Serial())
    assert dist.ok, dist.problems
    return tri


def _grid(nx, ny):
    return np.stack(np.meshgrid(np.arange(float(nx)), np.arange(float(ny))), -1).reshape(-1, 2)


def _cocircular(r=5525):
    """Every integer point on the circle of radius r (exactly cocircular)."""
    pts = [(x, s * y) for x in range(-r, r + 1) for s in (1, -1)
           for y in [int(round((r * r - x * x) ** 0.5))] if y * y == r * r - x * x]
    return np.unique(np.array(pts, dtype=np.float64), axis=0)


# --- the algorithm, on this process ---------------------------------------------------------

@pytest.mark.parametrize("n,tiles", [(500, 2), (3000, 5), (20000, 9)])
def test_random_sets_equal_the_single_machine_triangulation(rng, n, tiles):
    pts = rng.random((n, 2))
    tri = serial(pts, tiles)
    assert triangle_set(tri.simplices) == triangle_set(lfqt.triangulate(pts).simplices)
    assert tri.stats["rounds"] >= 2 and tri.stats["sent_per_round"][-1] == 0


@given(st.lists(st.tuples(st.integers(-6, 6), st.integers(-6, 6)), min_size=1, max_size=90),
       st.integers(1, 7))
# found by a fresh CI run: a cocircular face (2, 3, 6, 5) at the hull vertex 6 lost a triangle
# when the tile kept 6's raw neighbours only
@example(coords=[(0, 0), (-1, 0), (2, 0), (2, -1), (2, 5), (3, 1), (4, -2)], tiles=1)
def test_small_integer_sets_any_tiles(coords, tiles):
    # many cocircular and collinear subsets and duplicates
    serial(np.array(coords, dtype=np.float64), tiles, chunk_rows=13)


# magnitudes within the predicates' window (wider spans are a clear error, tested below)
_coordinate = st.floats(-1e3, 1e3).map(lambda v: 0.0 if abs(v) < 1e-100 else v)


@given(st.lists(st.tuples(_coordinate, _coordinate), min_size=3, max_size=150, unique=True),
       st.integers(2, 6))
def test_float_sets_equal_the_single_machine_triangulation(coords, tiles):
    pts = np.array(coords, dtype=np.float64)
    tri = serial(pts, tiles, chunk_rows=31)
    ref = lfqt.triangulate(pts)
    if not ref.degenerate and _general_position(pts, ref):
        assert triangle_set(tri.simplices) == triangle_set(ref.simplices)


def _general_position(pts, ref):
    """No edge of ref with its four points cocircular (then the DT is unique)."""
    from lfqt.distributed import geometry
    P = pts * 2.0 ** ref.stats["scale_exponent"]
    face = geometry.faces(P, ref.simplices.astype(np.int64), ref.neighbors.astype(np.int64))
    return len(np.unique(face)) == len(face)


def test_a_sealed_tile_keeps_every_vertex_of_a_face_at_its_frontier():
    """The cocircular face 2-3-6-5 (circle about (3.5, -0.5)) touches the
    frontier vertex 6 only in its raw triangles 3-5-2 and 6-5-3; its
    canonical fan from 2 joins 2 to 6, so the tile must keep 2 too."""
    from lfqt.distributed import geometry
    P = np.array([(0, 0), (-1, 0), (2, 0), (2, -1), (2, 5), (3, 1), (4, -2)], dtype=np.float64)
    ref = lfqt.triangulate(P)
    S, N = ref.simplices.astype(np.int64), ref.neighbors.astype(np.int64)
    face = geometry.faces(P, S, N)
    marked = np.zeros(len(P), dtype=bool)
    marked[6] = True
    raw = {int(v) for t in S if 6 in t for v in t}
    assert 2 not in raw  # 2 is no raw neighbour of 6 ...
    kept = set(np.flatnonzero(geometry.with_face_neighbours(S, marked, face)).tolist())
    assert kept == raw | {2}  # ... but shares its cocircular face
    alone = np.arange(len(S))  # every triangle its own face: the raw neighbours exactly
    assert set(np.flatnonzero(geometry.with_face_neighbours(S, marked, alone)).tolist()) == raw


@pytest.mark.parametrize("name,points,tiles", [
    ("grid", _grid(40, 30), 8),
    ("grid shuffled", np.random.default_rng(0).permutation(_grid(31, 17)), 5),
    ("cocircular", _cocircular(), 4),
    ("cocircular and centre", np.r_[_cocircular(), [[0.0, 0.0]]], 3),
    ("collinear", np.c_[np.arange(100.0), 2 * np.arange(100.0)], 4),
    ("two lines", np.r_[np.c_[np.arange(50.0), np.zeros(50)], np.c_[np.arange(50.0), np.ones(50)]],
     6),
    ("three points", np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]), 4),
    ("one point", np.array([[2.0, 3.0]]), 2),
])
def test_degenerate_sets_are_valid(name, points, tiles):
    serial(points, tiles, chunk_rows=41)


def test_duplicates_and_negative_zero(rng):
    pts = rng.random((400, 2))
    pts = np.r_[pts, pts[:60], pts[:7]]
    z = rng.integers(-3, 4, (300, 2)).astype(np.float64)
    z[z == 0] = -0.0
    for p in (pts, np.r_[z, np.abs(z)]):
        tri = serial(p, 4)
        assert (tri.duplicate_of != np.arange(len(p))).sum() == len(p) - len(np.unique(p + 0.0,
                                                                                        axis=0))


@pytest.mark.parametrize("scale", [1e-300, 1e-310, 1e300])
def test_extreme_magnitudes(rng, scale):
    pts = rng.random((2000, 2)) * scale
    tri = serial(pts, 4)
    assert triangle_set(tri.simplices) == triangle_set(lfqt.triangulate(pts).simplices)


def test_bad_input_is_a_clear_error():
    with pytest.raises(ValueError, match="NaN"):
        serial(np.array([[0.0, 0.0], [np.nan, 1.0], [1.0, 0.0]]), 2)
    with pytest.raises(ValueError, match="shape"):
        sources.chunks(np.zeros((5, 3)))
    with pytest.raises(FileNotFoundError):
        sources.chunks("/nonexistent/*.npy")
    with pytest.raises(ValueError, match="binades"):
        serial(np.array([[1e-300, 0.0], [1e300, 1.0], [0.0, 1.0]]), 2)


def test_kd_tiles_are_balanced_on_clustered_data(rng):
    pts = np.r_[rng.normal(0, 1e-3, (9000, 2)), rng.random((1000, 2))]
    nodes, cells = partition.kd_tree(pts, 8)
    counts = np.bincount(partition.assign(pts, nodes), minlength=8)
    assert counts.min() > 0.6 * counts.mean()
    inside = [(cells[t, 0] <= pts[:, 0]) & (pts[:, 0] < cells[t, 2]) & (cells[t, 1] <= pts[:, 1])
              & (pts[:, 1] < cells[t, 3]) for t in range(8)]
    assert (np.sum(inside, axis=0) == 1).all()  # the cells partition the plane
    near = partition.touching(cells)
    assert (near == near.T).all() and near.diagonal().all() and not near.all()


@pytest.mark.parametrize("n,chunk_rows,tiles", [(1200, 400, 3), (6000, 150, 30)])
def test_the_graph_grows_as_tiles_plus_chunks(rng, n, chunk_rows, tiles):
    """The partition is a shuffle through files: a task per chunk and per
    tile, not per pair (40 chunks x 30 tiles made 1,200 piece tasks); so is
    verify's lookup of coordinates, and its border pairing is a tree."""
    pts = rng.random((n, 2))
    chunks = sources.chunks(pts, chunk_rows)
    C = len(chunks)
    engine = D.Serial()
    tri = D.triangulate_on(chunks, engine, tiles=tiles, points=pts)
    assert lfqt.verify(pts, tri).ok
    assert tri.stats["chunks"] == C and tri.stats["tiles"] == tiles
    assert tri.stats["tasks"]["measure"] == C
    assert tri.stats["tasks"]["partition"] == partition.tasks(C, tiles) == C + 1 + 2 * tiles
    before = engine.submitted
    report = D.verify_on(tri, chunks, engine)
    assert report.ok, report.problems
    shares = tiles  # one share per tile's triangles; at 40 x 30, a product would be 1,200
    assert engine.submitted - before <= 6 * (C + shares) + 10


# --- the distributed check catches broken meshes ---------------------------------------------

def _broken(tri, simplices):
    out = copy.copy(tri)
    out.simplices, out.stats = simplices, {}
    return out


def test_verify_rejects_broken_meshes(rng):
    pts = rng.random((1500, 2))
    chunks = sources.chunks(pts, 200)
    tri = serial(pts, 3)
    S = tri.simplices

    def problems(simplices, chunk_list=chunks):
        report = D.verify_on(_broken(tri, simplices), chunk_list, D.Serial())
        assert not report.ok
        return " ".join(report.problems)

    assert "cycle" in problems(S[1:])                              # a hole
    assert "counter clockwise" in problems(np.r_[S[:1, ::-1], S[1:]])  # a flipped triangle
    assert "repeated" in problems(np.r_[S, S[:1]]) or "cycle" in problems(np.r_[S, S[:1]])
    assert "locally delaunay" in problems(_flip_one_edge(pts, tri))
    assert "a point" in problems(np.r_[S, [[0, 1, len(pts) + 5]]])
    extra = np.r_[pts, [[0.5, 0.5 + 1e-9]]]
    assert "distinct" in problems(S, sources.chunks(extra, 200))   # an unused point
    far = np.r_[pts, [[5.0, 5.0]]]
    assert "outside" in problems(S, sources.chunks(far, 200))      # a point beyond the hull


def _flip_one_edge(pts, tri):
    """The triangles with one interior edge flipped (a valid triangulation
    that is not Delaunay)."""
    S, N = tri.simplices.copy(), tri.neighbors
    for t in range(len(S)):
        for k in range(3):
            s = N[t, k]
            if s < 0:
                continue
            a, b, c = S[t, k], S[t, (k + 1) % 3], S[t, (k + 2) % 3]
            d = next(v for v in S[s] if v not in (b, c))

            def ccw(p, q, r):
                (ux, uy), (vx, vy) = pts[q] - pts[p], pts[r] - pts[p]
                return ux * vy - uy * vx > 1e-9

            if ccw(a, b, d) and ccw(a, d, c):  # the quad a b d c is convex
                S[t], S[s] = (a, b, d), (a, d, c)
                return S
    raise AssertionError("no flippable edge")


# --- the public functions: annotated, and their examples run ---------------------------------

def test_every_public_item_is_annotated_and_has_examples():
    for name in D.__all__:
        item = getattr(D, name)
        assert "Examples\n    --------" in item.__doc__, name
        functions = [m for _, m in inspect.getmembers(item, inspect.isfunction)
                     if not m.__name__.startswith("_")] if inspect.isclass(item) else [item]
        for f in functions:
            sig = inspect.signature(f)
            assert sig.return_annotation is not sig.empty, f.__qualname__
            assert all(p.annotation is not p.empty for p in sig.parameters.values()
                       if p.name != "self"), f.__qualname__


@pytest.mark.parametrize("name", ["triangulate_on", "verify_on", "assemble", "Serial"])
def test_the_examples_that_need_no_cluster_run(name):
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS)
    for test in doctest.DocTestFinder().find(getattr(D, name), name, globs={}):
        runner.run(test)
    assert runner.summarize(verbose=False) == (0, runner.tries) and runner.tries


# --- a plain script: lfqt.distributed's own LocalCluster, in a child process ----------------

SCRIPT_TOP = """\
import os
import sys

import numpy as np

import lfqt

with open("runs.txt", "a") as f:  # once: no worker imports the script again
    print(os.getpid(), file=f)
"""

SCRIPT_CALLS = """\
pts = np.random.default_rng(3).random((3000, 2))
main_file = sys.modules["__main__"].__file__
tri = lfqt.distributed.triangulate(pts, tiles=3, progress=False)
report = lfqt.distributed.verify(tri, pts, progress=False)
assert sys.modules["__main__"].__file__ == main_file  # given back
np.save("points.npy", pts)
np.save("simplices.npy", tri.simplices)
print("distributed verify:", report.ok)
"""


@pytest.mark.parametrize("guard", [False, True], ids=["top level", "under the guard"])
def test_a_script_with_or_without_the_main_guard(tmp_path, guard):
    """A script run as ``python script.py``, its calls at top level or
    under ``if __name__ == "__main__":``; before, the first failed with
    "RuntimeError: Nanny failed to start" and the second ran the script's
    top level again in every worker."""
    calls = ('if __name__ == "__main__":\n' + textwrap.indent(SCRIPT_CALLS, "    ")
             if guard else SCRIPT_CALLS)
    (tmp_path / "script.py").write_text(SCRIPT_TOP + "\n" + calls)
    env = dict(os.environ, PYTHONPATH=str(Path(lfqt.__file__).resolve().parents[1]))
    run = subprocess.run([sys.executable, "script.py"], cwd=tmp_path, env=env,
                         capture_output=True, text=True, timeout=900)
    assert run.returncode == 0, run.stderr[-3000:]
    assert "distributed verify: True" in run.stdout
    assert len((tmp_path / "runs.txt").read_text().split()) == 1
    pts, S = np.load(tmp_path / "points.npy"), np.load(tmp_path / "simplices.npy")
    assert lfqt.verify(pts, D.assemble(pts, S, np.arange(len(pts)), {})).ok
    assert triangle_set(S) == triangle_set(lfqt.triangulate(pts).simplices)


# --- on a real Dask cluster -------------------------------------------------------------------

@pytest.fixture(scope="module")
def client():
    cluster = dask_distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                            dashboard_address=None)
    with dask_distributed.Client(cluster) as c:
        yield c
    cluster.close()


@pytest.fixture(scope="module")
def cloud():
    return np.random.default_rng(7).random((150_000, 2))


@pytest.fixture(scope="module")
def reference(cloud):
    return triangle_set(lfqt.triangulate(cloud).simplices)


def _gathered_ok(points, tri, client, reference=None):
    assert lfqt.verify(points, tri).ok
    report = D.verify(tri, points, client=client, progress=False)
    assert report.ok, report.problems
    if reference is not None:
        assert triangle_set(tri.simplices) == reference


def test_dask_array_input(client, cloud, reference):
    tri = D.triangulate(cloud, client=client, tiles=6, progress=False)
    _gathered_ok(cloud, tri, client, reference)
    assert set(tri.stats["peak_rss"]) == set(client.scheduler_info()["workers"])


def test_dask_npy_and_parquet_chunks(client, cloud, reference, tmp_path):
    import pyarrow as pa
    import pyarrow.parquet as pq
    for i, part in enumerate(np.array_split(cloud, 5)):
        np.save(tmp_path / f"part-{i}.npy", part)
        pq.write_table(pa.table({"x": part[:, 0], "y": part[:, 1]}), tmp_path / f"part-{i}.parquet")
    for pattern in ("part-*.npy", "part-*.parquet"):
        tri = D.triangulate(str(tmp_path / pattern), client=client, tiles=4, progress=False)
        _gathered_ok(cloud, tri, client, reference)


def test_dask_collection_input_and_a_scheduler_address(client, cloud, reference):
    import dask.array as da
    tri = D.triangulate(da.from_array(cloud, chunks=(40_000, 2)), client=client.scheduler.address,
                        progress=False)
    assert triangle_set(tri.simplices) == reference


@pytest.mark.parametrize("fmt", ["npy", "parquet"])
def test_dask_out_writes_each_tile(client, cloud, reference, tmp_path, fmt):
    got = D.triangulate(cloud, client=client, tiles=4, out=tmp_path, format=fmt, progress=False)
    assert sorted(os.listdir(tmp_path)) == sorted(os.path.basename(p) for p in got)  # no leftovers
    assert got.n == len(cloud) and got.stats["tiles"] == 4
    shares = [dcheck.share_triangles(fmt, p) for p in got]
    assert triangle_set(np.concatenate(shares)) == reference
    report = D.verify(got, cloud, client=client, progress=False)
    assert report.ok, report.problems


def test_dask_grid_and_cocircular_are_valid(client):
    for pts in (_grid(300, 200), _cocircular()):
        _gathered_ok(pts, D.triangulate(pts, client=client, tiles=5, progress=False), client)


def test_in_memory_input_draws_no_large_graph_warning(client):
    """Every tile's triangles (24 bytes each) exceed the size at which Dask
    warns of a large graph: verify sends them in tasks of at most 8 MiB,
    and the tasks that read them (or the points) get futures."""
    from dask.utils import parse_bytes
    pts = np.random.default_rng(11).random((450_000, 2))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        tri = D.triangulate(pts, client=client, tiles=2, progress=False)
        _gathered_ok(pts, tri, client, triangle_set(lfqt.triangulate(pts).simplices))
    threshold = parse_bytes(dask.config.get("distributed.admin.large-graph-warning-threshold"))
    assert min(tri.stats["triangles_per_tile"]) * 24 > threshold
    assert not [str(w.message) for w in caught if "large graph" in str(w.message)]


def test_put_data_outlives_the_worker_holding_it(client):
    """Data sent by Engine.put is a task's result: when the worker holding
    it dies, it is computed again (scattered data would be gone)."""
    from lfqt.distributed.engine import Dask
    engine = Dask(client, progress=False)
    data = np.arange(3 << 20)  # 24 MiB: three tasks, joined on a worker
    future = engine.put(data)
    dask_distributed.wait(future)
    holder = client.who_has([future])[future.key][0]
    os.kill(client.run(os.getpid)[holder], signal.SIGKILL)  # the nanny restarts it
    assert np.array_equal(engine.gather([engine.submit(np.copy, future)])[0], data)
    assert holder not in client.scheduler_info()["workers"]


def test_dask_worker_loss_is_retried(client, cloud, reference):
    done = {}
    worker = threading.Thread(target=lambda: done.update(
        tri=D.triangulate(cloud, client=client, tiles=8, progress=False)))
    before = set(client.scheduler_info()["workers"])
    worker.start()
    deadline = time.time() + 120
    while not client.run_on_scheduler(_round_two_started) and time.time() < deadline:
        time.sleep(0.05)
    assert worker.is_alive(), "the run ended before a worker could be lost"
    pids = client.run(os.getpid)
    os.kill(pids[sorted(pids)[0]], signal.SIGKILL)  # the nanny restarts it
    worker.join(300)
    assert not worker.is_alive()
    assert triangle_set(done["tri"].simplices) == reference
    assert set(client.scheduler_info()["workers"]) != before


def _round_two_started(dask_scheduler):
    return any("round2" in str(k) for k in dask_scheduler.tasks)


def _started(prefix):
    def check(dask_scheduler):
        return any(str(k).startswith(prefix) for k in dask_scheduler.tasks)
    return check


def test_dask_worker_loss_during_verify_is_retried(client, cloud):
    """A worker killed while verify's shuffles run: the lost results are
    computed again from the files on disk, and the verdict and counts are
    those of the mesh."""
    tri = lfqt.triangulate(cloud)
    done = {}
    worker = threading.Thread(target=lambda: done.update(
        report=D.verify(tri, cloud, client=client, progress=False)))
    before = set(client.scheduler_info()["workers"])
    worker.start()
    deadline = time.time() + 120
    while not client.run_on_scheduler(_started("check")) and time.time() < deadline:
        time.sleep(0.05)
    assert worker.is_alive(), "verify ended before a worker could be lost"
    pids = client.run(os.getpid)
    os.kill(pids[sorted(pids)[-1]], signal.SIGKILL)  # the nanny restarts it
    worker.join(300)
    report = done["report"]
    assert report.ok, report.problems
    assert report.counts["triangles"] == len(tri.simplices)
    assert report.counts["distinct_points"] == report.counts["vertices"] == len(cloud)
    assert set(client.scheduler_info()["workers"]) != before


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full")
def test_dask_a_full_disk_is_a_clear_error_and_leaves_nothing(client, tmp_path):
    """A tile's file cannot be written (the kernel says ENOSPC: the name is
    a link to /dev/full): a DiskFullError naming the file, and the call
    removes what it wrote (tiles' files, the partition's scratch)."""
    pts = np.random.default_rng(5).random((20_000, 2))
    os.symlink("/dev/full", tmp_path / "tile-00001.npy")
    with pytest.raises(D.shuffle.DiskFullError, match="no space left to write .*tile-00001"):
        D.triangulate(pts, client=client, tiles=3, out=tmp_path, progress=False)
    assert os.listdir(tmp_path) == []


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full")
def test_a_full_scratch_disk_leaves_no_partial_file(tmp_path):
    from lfqt.distributed import shuffle
    target = tmp_path / "chunk-000000.npy"
    os.symlink("/dev/full", f"{target}.{os.getpid()}.part")
    with pytest.raises(shuffle.DiskFullError, match="no space left"):
        shuffle.write(target, [0, 2], np.arange(2), np.zeros((2, 2)))
    assert os.listdir(tmp_path) == []
