"""Parallel LFQT: the result does not depend on the thread count or the
schedule, errors in workers surface, and stats carry the Fig. 5 phases."""
import subprocess
import sys
import textwrap
import threading
import time
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import generators
import lfqt
from conftest import triangle_set, triangulate_verified
from lfqt.dc import bins, merge
from lfqt.workers import Workers

THREADS = [2, 3, 4, 7]


def same_mesh(a, b):
    return triangle_set(a.simplices) == triangle_set(b.simplices) and \
        np.array_equal(a.duplicate_of, b.duplicate_of) and np.array_equal(a.hull, b.hull)


@pytest.mark.parametrize("name", ["uniform", "grid", "cluster", "circle", "spiral"])
@pytest.mark.parametrize("schedule", ["tasks", "levels"])
def test_same_triangulation_for_every_thread_count(name, schedule):
    pts = generators.make(name, 40000, seed=5)
    serial = triangulate_verified(pts, threads=1)
    for threads in THREADS:
        par = triangulate_verified(pts, threads=threads, schedule=schedule)
        assert same_mesh(serial, par), (name, threads)
        assert par.stats["threads"] == threads and par.stats["bins"] > 1


@settings(max_examples=50, deadline=None)
@given(st.integers(0, 2 ** 32 - 1), st.integers(2, 3000), st.sampled_from(THREADS),
       st.booleans())
def test_random_small_sets_match_serial(seed, n, threads, with_duplicates):
    rng = np.random.default_rng(seed)
    pts = rng.random((n, 2))
    if with_duplicates:
        pts = np.r_[pts, pts[: n // 3]]
    serial = lfqt.triangulate(pts, threads=1)
    par = triangulate_verified(pts, threads=threads)
    assert same_mesh(serial, par)


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2 ** 32 - 1), st.integers(2, 3000), st.sampled_from(THREADS),
       st.booleans())
def test_output_pieces_over_every_thread_match_serial(seed, n, threads, with_duplicates):
    """With output pieces and chunks of 64 rows at the least, small sets
    split their output over every thread: the rows written over T's slots
    in pieces that grow as they go (lfqt.dc.output.write_rows)."""
    rng = np.random.default_rng(seed)
    pts = rng.random((n, 2))
    if with_duplicates:
        pts = np.r_[pts, pts[: n // 3]]
    serial = lfqt.triangulate(pts, threads=1)
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(lfqt.dc.output, "MIN_CHUNK", 64)
        par = triangulate_verified(pts, threads=threads)
    assert np.array_equal(serial.simplices, par.simplices)
    assert np.array_equal(serial.neighbors, par.neighbors)
    assert same_mesh(serial, par)


def test_parallel_sort_sized_sets_of_few_distinct_points():
    # Above 2 * 65536 points the keys are sorted in parallel (lfqt.radix):
    # a set of one point repeated, or of a few repeated many times, leaves
    # ranges of equal keys larger than a thread's share.  In a child process,
    # so that a hang fails the test rather than the run.
    code = textwrap.dedent("""
        import numpy as np, lfqt
        n = 150_000
        same = np.full((n, 2), 0.3)
        tri = lfqt.triangulate(same, threads=2)
        assert tri.degenerate and tri.n_distinct == 1
        g = np.stack(np.meshgrid(np.arange(30.0), np.arange(30.0)), -1).reshape(-1, 2)
        few = g[np.random.default_rng(0).integers(0, len(g), n)]
        a, b = lfqt.triangulate(few, threads=1), lfqt.triangulate(few, threads=2)
        assert lfqt.verify(few, b).ok and b.n_distinct == 900
        assert np.array_equal(a.simplices, b.simplices)
        assert np.array_equal(a.duplicate_of, b.duplicate_of)
        print("ok")
    """)
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0 and proc.stdout.strip() == "ok", proc.stderr[-2000:]


def test_more_threads_than_points_and_cores():
    pts = np.random.default_rng(1).random((5, 2))
    assert same_mesh(lfqt.triangulate(pts), triangulate_verified(pts, threads=16))
    assert triangulate_verified(np.ones((4, 2)), threads=8).degenerate


def test_default_uses_all_cores():
    tri = lfqt.triangulate(np.random.default_rng(0).random((200000, 2)), threads=None)
    import os
    assert tri.stats["threads"] == os.cpu_count()


def test_fig5_phases_are_reported():
    tri = lfqt.triangulate(np.random.default_rng(0).random((300000, 2)), threads=4, counters=True)
    ph = tri.stats["phases"]
    assert set(ph) == {"sort", "subdivide_top", "subdivide_lower", "merge_lower", "merge_top"}
    assert ph["merge_lower"] > 0 and ph["merge_top"] > 0 and tri.stats["bins"] >= 16
    serial = lfqt.triangulate(np.random.default_rng(0).random((300000, 2)), counters=True)
    # same merges, so the same predicate calls in total
    assert tri.stats["counts"]["orientation_tests"] == serial.stats["counts"]["orientation_tests"]


def test_every_count_is_the_same_on_any_thread_count():
    # A grid's cocircular quads leave stage 1 undecided: the bins and the top
    # merges each count those in their own array, the sum must be the serial one.
    g = np.stack(np.meshgrid(np.arange(150.0), np.arange(140.0)), -1).reshape(-1, 2)
    serial = triangulate_verified(g, counters=True).stats["counts"]
    assert serial["incircle_stage1_undecided"] > 0
    for threads in (2, 5):
        assert triangulate_verified(g, threads=threads, counters=True).stats["counts"] == serial


def test_worker_errors_surface_without_hanging(monkeypatch):
    calls = {"n": 0}
    real = merge.run_ops

    def flaky(*args):
        calls["n"] += 1
        if calls["n"] == 3:
            raise MemoryError("injected")
        return real(*args)

    monkeypatch.setattr(merge, "run_ops", flaky)
    pts = np.random.default_rng(0).random((100000, 2))
    for schedule in ("tasks", "levels"):
        calls["n"] = 0
        with pytest.raises(MemoryError, match="injected"):
            lfqt.triangulate(pts, threads=3, schedule=schedule)


def test_workers_chunking_covers_the_range():
    with Workers(3) as w:
        for n in (0, 1, 5, 10 ** 6 + 7):
            chunks = w.chunks(n)
            assert chunks[0][0] == 0 and chunks[-1][1] == n
            assert all(a[1] == b[0] for a, b in zip(chunks, chunks[1:]))
        out = w.map(w.chunks(10 ** 6), lambda c, lo, hi: (c, hi - lo))
        assert [c for c, _ in out] == list(range(len(out))) and sum(s for _, s in out) == 10 ** 6


def test_workers_each_runs_every_item_once_on_the_caller_and_the_pool():
    def slow(k):
        time.sleep(0.002)  # long enough for the pool threads to wake up and take items
        return k, threading.current_thread().name
    with Workers(3) as w:
        out = w.each(slow, range(40))
    assert [k for k, _ in out] == list(range(40))
    names = {name for _, name in out}
    assert threading.main_thread().name in names and any(n.startswith("lfqt") for n in names)
    with Workers(1) as w:
        assert w.each(slow, [5])[0][1] == threading.main_thread().name


def test_workers_share_a_pool_and_do_not_wait_for_a_helper_still_queued():
    a, b = Workers(2), Workers(2)
    assert a.pool is b.pool and Workers(3).pool is not a.pool
    release = threading.Event()
    blocker = a.pool.submit(release.wait, 10)  # the pool's one thread is busy elsewhere
    try:
        assert b.each(lambda k: k * k, range(5)) == [0, 1, 4, 9, 16]  # all on the caller
        assert not blocker.done()  # each() did not wait for its queued helper
    finally:
        release.set()
    assert blocker.result() is True


def test_a_forked_child_has_pool_threads_of_its_own():
    code = textwrap.dedent("""
        import multiprocessing, threading, time
        from lfqt.workers import Workers

        def names():
            def slow(k):
                time.sleep(0.002)
                return threading.current_thread().name
            return sorted(set(Workers(2).each(slow, range(40))))

        if __name__ == "__main__":
            parent = names()  # the parent's pool has its thread
            with multiprocessing.get_context("fork").Pool(1) as p:
                child = p.apply(names)
            assert any(n.startswith("lfqt") for n in parent), parent
            assert any(n.startswith("lfqt") for n in child), child
            print("ok")
    """)
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 0 and proc.stdout.strip() == "ok", proc.stderr[-2000:]


def test_workers_each_raises_only_after_the_items_in_flight_end():
    started, done = [], []
    both = threading.Event()

    def work(k):
        if k == 0:  # fails once the two other items run on the other two threads
            both.wait(10)
            raise ValueError("item 0")
        started.append(k)
        if len(started) == 2:
            both.set()
        if threading.current_thread() is not threading.main_thread():
            time.sleep(0.2)  # the pool's items outlast the caller's
        done.append(k)
    with Workers(3) as w:
        with pytest.raises(ValueError, match="item 0"):
            w.each(work, range(3))
        assert sorted(done) == [1, 2]


def test_levels_run_the_bins_largest_first_on_threads_then_each_height():
    # bins 0 [0, 10), 1 [10, 40), 3 [40, 60); merges 2 = 0 + 1, 4 = 2 + 3
    nodes = np.array([[0, 10, -1, -1, -1, -1], [10, 40, -1, -1, -1, -1], [0, 40, 10, 5, 0, 1],
                      [40, 60, -1, -1, -1, -1], [0, 60, 40, 6, 2, 3]])
    # threads that run their items in the order given, and one thread
    in_turn = SimpleNamespace(pool=object(), each=lambda fn, items: [fn(k) for k in items])
    for workers, first in ((in_turn, [1, 3, 0]), (Workers(1), [0, 1, 3])):
        calls = []
        bins._run_levels(bins._Tree(nodes), workers, lambda k: calls.append(("bin", k)),
                         lambda k: calls.append(("merge", k)))
        assert calls == [("bin", k) for k in first] + [("merge", 2), ("merge", 4)]


def test_tasks_take_a_ready_merge_before_the_largest_bin_left():
    # bins 0 [0, 30), 1 [30, 50), 3 [50, 60); merges 2 = 0 + 1, 4 = 2 + 3
    nodes = np.array([[0, 30, -1, -1, -1, -1], [30, 50, -1, -1, -1, -1], [0, 50, 30, 5, 0, 1],
                      [50, 60, -1, -1, -1, -1], [0, 60, 50, 6, 2, 3]])
    calls = []
    one_at_a_time = SimpleNamespace(threads=2, each=lambda fn, items: [fn(k) for k in items])
    bins._run_tasks(bins._Tree(nodes), one_at_a_time, lambda k: calls.append(("bin", k)),
                    lambda k: calls.append(("merge", k)))
    assert calls == [("bin", 0), ("bin", 1), ("merge", 2), ("bin", 3), ("merge", 4)]


def test_tasks_run_every_item_once_on_threads_and_children_first():
    nodes = np.array([[0, 30, -1, -1, -1, -1], [30, 50, -1, -1, -1, -1], [0, 50, 30, 5, 0, 1],
                      [50, 60, -1, -1, -1, -1], [0, 60, 50, 6, 2, 3]])
    ended, lock = [], threading.Lock()

    def run(k):
        time.sleep(0.01 * (nodes[k, 1] - nodes[k, 0]) / 30)
        with lock:
            assert all(c in ended for c in nodes[k, 4:] if nodes[k, 2] >= 0)
            ended.append(int(k))
    with Workers(3) as w:
        bins._run_tasks(bins._Tree(nodes), w, run, run)
    assert sorted(ended) == [0, 1, 2, 3, 4] and ended[-1] == 4


def test_bad_schedule():
    with pytest.raises(ValueError, match="schedule"):
        lfqt.triangulate(np.random.default_rng(0).random((30, 2)), threads=1, schedule="x")
