"""Parallel LFQT (fqDel section 3.4): bins and a split-list merge.

One thread cuts the upper levels of the quad-tree into *bins*; that is cheap
because a split is a binary search over sorted keys.  Each bin is subdivided
and merged by the jitted kernels with the GIL released, writing only its own
triangle slots and its own vertices.  A
merge of the upper part either starts as soon as both of its children are
done (``schedule="tasks"``, the default: the paper's split-list of Fig. 2,
with a small scheduler in Python threads standing in for its atomic
counters, numba has none, and tasks are coarse), or waits for all merges of
the level below (``schedule="levels"``, a barrier per level).  On our
2-core machines, 2 threads, medians of 11 interleaved calls, "tasks" took
81.5-82.6 ms at 1M uniform points against 82.5-83.3 for "levels", and
869 against 871 ms at 10M: a thread out of bins takes the merges whose
children are done instead of waiting at the barrier.  (A first "tasks",
which submitted every item to the pool and left the caller waiting,
measured 88-95 ms at 1M.)

The triangulation does not depend on the thread count: the tree, hence every
merge and every slot id, depends only on the keys.
"""
import threading
import time
from collections import deque

import numpy as np

from ..predicates.counters import new_counters
from .hybrid import insert_bin
from .layout import PART
from .subdivide import subdivide_top

# Bins per thread.  One bin per thread leaves threads idle when the data-
# dependent LFQT splits are unbalanced; many bins per thread push work into
# the upper, less parallel part (paper Fig. 5).  Four balances the two.
BINS_PER_THREAD = 4


def bin_size_for(n, threads):
    return max(1, -(-n // (BINS_PER_THREAD * threads)))


class _Tree:
    """The upper tree of nodes (lo, hi, split, bit, left, right), with each
    node's finished partition row."""

    def __init__(self, nodes):
        self.nodes = nodes
        m = len(nodes)
        self.parent = np.full(m, -1, dtype=np.int64)
        for k in range(m):
            if nodes[k, 2] >= 0:
                self.parent[nodes[k, 4]] = k
                self.parent[nodes[k, 5]] = k
        self.parts = np.empty((m, PART), dtype=np.int64)
        self.bins = [k for k in range(m) if nodes[k, 2] < 0]


def build(state, workers, schedule="tasks", bin_size=None, insert_order=None):
    """Triangulate the sorted points of ``state`` (lfqt.dc.state.State) on
    ``workers``.  Returns (root partition row, counts, stats).  ``bin_size``
    caps the keys per bin (default: BINS_PER_THREAD bins per thread); with
    ``insert_order`` each bin is triangulated by insertion in that order
    (lfqt.dc.hybrid) instead of by its own merges."""
    threads = workers.threads
    t0 = time.perf_counter()
    nodes = subdivide_top(state.khi, state.klo, state.wide, state.n,
                          bin_size or bin_size_for(state.n, threads))
    state.drop_keys()  # the bins subdivide from the gaps
    tree = _Tree(nodes)
    t_top = time.perf_counter() - t0
    lock = threading.Lock()
    thread_seconds = ({"order_lower": 0.0, "insert_lower": 0.0} if insert_order else
                      {"subdivide_lower": 0.0, "merge_lower": 0.0})
    thread_seconds["merge_top"] = 0.0
    counters = []

    def add_time(key, dt):
        with lock:
            thread_seconds[key] += dt

    def run_bin(k):
        lo, hi = int(nodes[k, 0]), int(nodes[k, 1])
        cnt = new_counters()
        a = time.perf_counter()
        if insert_order:  # the order's time apart from the insertion's
            t_order = insert_bin(state, lo, hi, insert_order, cnt, tree.parts[k:k + 1])
            add_time("order_lower", t_order)
            add_time("insert_lower", time.perf_counter() - a - t_order)
        else:
            share = state.merge_range(lo, hi, cnt, tree.parts[k:k + 1])
            wall = time.perf_counter() - a
            add_time("subdivide_lower", share * wall)
            add_time("merge_lower", (1.0 - share) * wall)
        counters.append(cnt)

    def run_merge(k):
        left, right = nodes[k, 4], nodes[k, 5]
        cnt = new_counters()
        op = np.array([nodes[k, 2]], dtype=np.int64)  # its code: gaps[split]
        a = time.perf_counter()
        state.merge(0, 1, cnt, tree.parts[[left, right]], 2, tree.parts[k:k + 1], ops=op)
        add_time("merge_top", time.perf_counter() - a)
        counters.append(cnt)

    t1 = time.perf_counter()
    if len(nodes) == 1:
        run_bin(0)
    elif workers.pool is None:  # one thread (the hybrid method): bins, then merges, in order
        _run_levels(tree, workers, run_bin, run_merge)
    elif schedule == "tasks":
        _run_tasks(tree, workers, run_bin, run_merge)
    elif schedule == "levels":
        _run_levels(tree, workers, run_bin, run_merge)
    else:
        raise ValueError(f"schedule must be 'tasks' or 'levels', got {schedule!r}")
    wall = time.perf_counter() - t1
    total = np.sum(counters, axis=0) if counters else new_counters()
    stats = {"subdivide_top": t_top, "parallel_wall": wall, "bins": len(tree.bins),
             "thread_seconds": thread_seconds}
    return tree.parts[len(nodes) - 1], total, stats


def _run_tasks(tree, workers, run_bin, run_merge):
    """Dependency-driven, on the caller and threads - 1 pool threads
    (Workers.each): each takes the next ready item, a merge whose two
    children are done before any bin (it is on the way to the root), else
    the largest bin left, and waits only when nothing is ready."""
    nodes = tree.nodes
    bins_left = sorted(tree.bins, key=lambda k: nodes[k, 1] - nodes[k, 0])  # largest last
    merges = deque()
    children_left = np.full(len(nodes), 2, dtype=np.int64)
    remaining = [len(nodes)]
    errors = []
    cond = threading.Condition()

    def take():
        with cond:
            while not errors and remaining[0] and not merges and not bins_left:
                cond.wait()
            if errors or not remaining[0]:
                return None, -1
            return (run_merge, merges.popleft()) if merges else (run_bin, bins_left.pop())

    def done(k):
        with cond:
            remaining[0] -= 1
            parent = tree.parent[k]
            if parent >= 0:
                children_left[parent] -= 1
                if children_left[parent] == 0:
                    merges.append(parent)
            cond.notify_all()

    def work(_):
        while True:
            fn, k = take()
            if fn is None:
                return
            try:
                fn(k)
            except BaseException as e:  # noqa: BLE001 - re-raised in the caller
                with cond:
                    errors.append(e)
                    cond.notify_all()
                return
            done(k)

    workers.each(work, range(workers.threads))
    if errors:
        raise errors[0]


def _run_levels(tree, workers, run_bin, run_merge):
    """Barrier per level: all bins, then the merges of height 1, 2, ...  On
    threads the bins go largest first, so that no large bin is left to run
    alone at the end (1M uniform points on 2 threads, merge 0.097-0.102 ->
    0.090-0.092 s); on one thread (no pool) in address order.  A level of
    one merge runs in the calling thread (Workers.each): a round trip
    through the pool cost 0.05-0.2 ms, as much as the merge, on each of the
    5-8 such levels of 1M uniform points in 16 bins."""
    nodes = tree.nodes
    height = np.zeros(len(nodes), dtype=np.int64)
    for k in range(len(nodes)):  # post-order: children before parents
        if nodes[k, 2] >= 0:
            height[k] = 1 + max(height[nodes[k, 4]], height[nodes[k, 5]])
    order = (tree.bins if workers.pool is None else
             sorted(tree.bins, key=lambda k: nodes[k, 0] - nodes[k, 1]))  # by -(hi - lo)
    workers.each(run_bin, order)
    for h in range(1, int(height.max()) + 1):
        workers.each(run_merge, np.flatnonzero(height == h))
