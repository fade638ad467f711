"""Parallel LFQT (fqDel section 3.4): bins and a split-list merge.

One thread cuts the upper levels of the quad-tree into *bins*; that is cheap
because a split is a binary search over sorted keys.  Each bin is subdivided
and merged by the jitted kernels with the GIL released, writing only its own
op range ``[2 lo, 2 hi)``, its own triangle slots and its own vertices.  A
merge of the upper part either starts as soon as both of its children are
done (``schedule="tasks"``, the paper's split-list of Fig. 2, with a small
scheduler in Python threads standing in for its atomic counters: numba has
none, and tasks are coarse), or waits for all merges of the level below
(``schedule="levels"``, a barrier per level).  On our 2-core machines,
at 4M uniform points and 2 threads, "levels" measured 1.21-1.43 s and
"tasks" 1.55-1.88 s over several series (medians of 7, fresh processes;
mostly in allocation and output, not in the merges), so "levels" is the
default; with many cores and deep upper trees "tasks" should win.

The triangulation does not depend on the thread count: the tree, hence every
merge and every slot id, depends only on the keys.
"""
import threading
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from . import dc
from .predicates import N_COUNTERS

MIN_CHUNK = 1 << 16  # below this a chunk costs more to schedule than to run


class Workers:
    """A thread pool for nogil kernels over index ranges.  With one thread
    everything runs inline; ``threads`` may exceed the core count."""

    def __init__(self, threads):
        self.threads = max(1, int(threads))
        self.pool = ThreadPoolExecutor(self.threads, thread_name_prefix="lfqt") \
            if self.threads > 1 else None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        if self.pool:
            self.pool.shutdown(wait=True)

    def chunks(self, n):
        k = max(1, min(self.threads, n // MIN_CHUNK))
        cuts = [n * i // k for i in range(k + 1)]
        return list(zip(cuts[:-1], cuts[1:]))

    def map(self, chunks, fn):
        """[fn(c, lo, hi) for each chunk c = (lo, hi)], in parallel."""
        if self.pool is None or len(chunks) == 1:
            return [fn(c, lo, hi) for c, (lo, hi) in enumerate(chunks)]
        return list(self.pool.map(lambda a: fn(a[0], *a[1]), enumerate(chunks)))


# Bins per thread.  One bin per thread leaves threads idle when the data-
# dependent LFQT splits are unbalanced; many bins per thread push work into
# the upper, less parallel part (paper Fig. 5).  Four balances the two.
BINS_PER_THREAD = 4


def bin_size_for(n, threads):
    return max(1, -(-n // (BINS_PER_THREAD * threads)))


class _Tree:
    """The upper tree of nodes (lo, hi, split, bit, left, right) with the
    state of each task."""

    def __init__(self, nodes):
        self.nodes = nodes
        m = len(nodes)
        self.parent = np.full(m, -1, dtype=np.int64)
        for k in range(m):
            if nodes[k, 2] >= 0:
                self.parent[nodes[k, 4]] = k
                self.parent[nodes[k, 5]] = k
        self.ext = np.empty((m, 4), dtype=np.int64)
        self.single = np.empty(m, dtype=np.bool_)
        self.bins = [k for k in range(m) if nodes[k, 2] < 0]


def build(khi, klo, wide, n, P, T, ghost_out, rep, ops, fmt, level_filter, workers,
          schedule="tasks"):
    """Triangulate sorted points on ``workers``.  Returns (root_ext (4,),
    root_single, counters, stats)."""
    threads = workers.threads
    t0 = time.perf_counter()
    nodes = dc.subdivide_top(khi, klo, wide, n, bin_size_for(n, threads))
    tree = _Tree(nodes)
    t_top = time.perf_counter() - t0
    lock = threading.Lock()
    thread_seconds = {"subdivide_lower": 0.0, "merge_lower": 0.0, "merge_top": 0.0}
    counters = []

    def add_time(key, dt):
        with lock:
            thread_seconds[key] += dt

    def run_bin(k):
        lo, hi = int(nodes[k, 0]), int(nodes[k, 1])
        cnt = np.zeros(N_COUNTERS, dtype=np.int64)
        a = time.perf_counter()
        end = dc.subdivide_lfqt(khi, klo, wide, lo, hi, ops, 2 * lo, rep)
        b = time.perf_counter()
        dc.run_ops(ops, 2 * lo, end, P, T, ghost_out, fmt, level_filter, cnt,
                   tree.ext, tree.single, 0, tree.ext[k:k + 1], tree.single[k:k + 1])
        add_time("subdivide_lower", b - a)
        add_time("merge_lower", time.perf_counter() - b)
        counters.append(cnt)

    def run_merge(k):
        left, right = nodes[k, 4], nodes[k, 5]
        cnt = np.zeros(N_COUNTERS, dtype=np.int64)
        in_ext = np.stack((tree.ext[left], tree.ext[right]))
        in_single = np.array([tree.single[left], tree.single[right]])
        op = np.array([(nodes[k, 2] << 8) | nodes[k, 3]], dtype=np.int64)
        a = time.perf_counter()
        dc.run_ops(op, 0, 1, P, T, ghost_out, fmt, level_filter, cnt, in_ext, in_single, 2,
                   tree.ext[k:k + 1], tree.single[k:k + 1])
        add_time("merge_top", time.perf_counter() - a)
        counters.append(cnt)

    t1 = time.perf_counter()
    if len(nodes) == 1:
        run_bin(0)
    elif schedule == "tasks":
        _run_tasks(tree, workers.pool, run_bin, run_merge)
    elif schedule == "levels":
        _run_levels(tree, workers.pool, run_bin, run_merge)
    else:
        raise ValueError(f"schedule must be 'tasks' or 'levels', got {schedule!r}")
    wall = time.perf_counter() - t1
    root = len(nodes) - 1
    total = np.sum(counters, axis=0) if counters else np.zeros(N_COUNTERS, dtype=np.int64)
    stats = {"subdivide_top": t_top, "parallel_wall": wall, "bins": len(tree.bins),
             "thread_seconds": thread_seconds}
    return tree.ext[root], bool(tree.single[root]), total, stats


def _run_tasks(tree, pool, run_bin, run_merge):
    """Dependency-driven: a merge is submitted when its second child ends."""
    pending = np.full(len(tree.nodes), 2, dtype=np.int64)
    lock = threading.Lock()
    done = threading.Event()
    errors = []
    root = len(tree.nodes) - 1

    def finished(k):
        if k == root:
            done.set()
            return
        parent = tree.parent[k]
        with lock:
            pending[parent] -= 1
            ready = pending[parent] == 0
        if ready:
            submit(run_merge, parent)

    def task(fn, k):
        if errors:
            return
        try:
            fn(k)
        except BaseException as e:  # noqa: BLE001 - re-raised in the caller
            errors.append(e)
            done.set()
            return
        finished(k)

    def submit(fn, k):
        pool.submit(task, fn, k)

    # In address order: neighbouring bins share pages and cache lines, and
    # largest-first measured slower here (it scatters the memory traffic).
    for k in tree.bins:
        submit(run_bin, k)
    done.wait()
    if errors:
        raise errors[0]


def _run_levels(tree, pool, run_bin, run_merge):
    """Barrier per level: all bins, then the merges of height 1, 2, ..."""
    nodes = tree.nodes
    height = np.zeros(len(nodes), dtype=np.int64)
    for k in range(len(nodes)):  # post-order: children before parents
        if nodes[k, 2] >= 0:
            height[k] = 1 + max(height[nodes[k, 4]], height[nodes[k, 5]])
    list(pool.map(run_bin, tree.bins))
    for h in range(1, int(height.max()) + 1):
        list(pool.map(run_merge, np.flatnonzero(height == h)))
