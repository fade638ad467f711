"""Incremental Delaunay insertion in 2D and 3D (Liu et al. 2013): the
validated public wrapper ``insert`` over the kernels of lfqt.incremental.kernel."""
from __future__ import annotations

import os
import time
from collections import namedtuple

import numpy as np
import numpy.typing as npt

from .. import calls, orders
from .._input import exact_points, index_dtype
from ..clock import cycles_per_second
from ..predicates.counters import DUPLICATES, NAMES, N_INSERT, ORIENT_S1, ORIENT_S2, per_point
from ..triangulation import Triangulation
from ..workers import Workers
from . import kernel, tetra

# the walk counts its orientation tests, not their stages
_COUNTED = [NAMES[k] for k in range(N_INSERT) if k not in (ORIENT_S1, ORIENT_S2)]
# the kernel's phase cycles (insert(phase_times=True)), by phase
_CYCLES = {"locate": "locate_cycles", "cavity": "cavity_cycles"}
# Cell ids are int32 and the storage starts at kernel.CELLS_PER_POINT cells
# per point (kernel.insert_all): more points would overflow the ids.
MAX_POINTS = (2 ** 31 - 1) // kernel.CELLS_PER_POINT
# 3D records name facets, 4 t + i in an int32: 2^29 - 1 tetrahedra, and a
# random set makes 6.7 a point
MAX_POINTS_3D = tetra.MAX_CELLS // 7


@calls.entry
def insert(points: npt.ArrayLike, *,
           order: orders.OrderName | tuple[npt.ArrayLike, npt.ArrayLike] = "kdtree",
           hint: orders.Hint | None = None, counters: bool = True, phase_times: bool = False,
           seed: int = 0, threads: int | None = 1) -> Triangulation:
    """Exact Delaunay triangulation of 2D or 3D points by incremental
    insertion (Bowyer–Watson) in a given order (Liu et al. 2013).

    Parameters
    ----------
    points : array_like, shape (n, 2) or (n, 3)
        Dimension from the shape; validated and rescaled like ``triangulate``.
    order : str or (perm, hint)
        A name from ``lfqt.orders.ORDERS`` ("kdtree" by default,
        "kdtree-alternate", "hilbert", "hilbert-grid", "brio", "random",
        "input") or an explicit pair of int arrays.
    hint : {"parent", "sibling"}, optional
        For the Kd orders: start each walk at the parent (default) or the
        left sibling.
    counters : bool
        Report ``stats["counts"]`` (orientation tests while locating,
        in-sphere tests, conflicting cells) and ``stats["per_point"]``; the
        kernel counts anyway, so this is free.
    phase_times : bool
        Also time the walks and the cavities with the cycle counter:
        ``stats["cycles"]`` and ``stats["seconds"]["locate"]`` and
        ``["cavity"]``.  Off by default: three reads of the counter per
        point cost about 4% of a 2D insertion (1M points, on a VM).
    seed : int
        For the randomized orders.
    threads : int
        3D: insert on this many threads (None: one per core).  After the
        first points, the order goes in rounds, each point by the thread
        that owns its slab of space; a point whose cavity crosses into
        another slab is retried in slabs across the next longest side, or
        inserted alone at the end.  The tetrahedra are the same on every thread count where
        the Delaunay tetrahedralization is unique, and the same run to run
        for a given count otherwise; the counts are those of that
        insertion, not the order's alone.  2D: ignored (``triangulate`` is
        the parallel 2D path).

    Returns
    -------
    Triangulation
        ``simplices`` (m, 3) counter-clockwise triangles in 2D, (m, 4)
        right-handed tetrahedra in 3D; ``hull`` the counter-clockwise loop
        in 2D, the outward (k, 3) hull facets in 3D.  Points of lower
        dimension: no simplices and ``degenerate=True``.

    Raises
    ------
    ValueError
        For points not of shape (n, 2) or (n, 3), NaN or inf, magnitudes
        beyond the kernels' window (lfqt._input), an unknown order or hint,
        an explicit order that is not a permutation with one hint per
        point, more than MAX_POINTS points, or more than MAX_POINTS_3D in 3D.
    TypeError
        For points that are not real numbers.

    Examples
    --------
    >>> import numpy as np
    >>> import lfqt
    >>> p = np.random.default_rng(0).random((100, 3))
    >>> tri = lfqt.insert(p, order="kdtree")
    >>> tri.simplices.shape[1], tri.hull.shape[1]
    (4, 3)
    >>> bool(lfqt.verify(p, tri).ok)
    True
    >>> sorted(tri.stats["per_point"])  # in-sphere tests counted as incircle_tests
    ['conflicts', 'incircle_tests', 'orientation_tests']
    >>> rows = lambda t: sorted(sorted(r) for r in t.simplices.tolist())
    >>> rows(lfqt.insert(p[:, :2], order="hilbert")) == rows(lfqt.triangulate(p[:, :2]))
    True
    """
    t0 = time.perf_counter()
    threads = _threads(threads)
    P, s, largest = exact_points(points, (2, 3), copy=False)  # P is only read
    n, d = P.shape
    if n > MAX_POINTS:
        raise ValueError(f"insert takes at most {MAX_POINTS} points (its cell ids are int32), "
                         f"got {n}; lfqt.triangulate has no such limit in 2D")
    if d == 3 and n > MAX_POINTS_3D:
        raise ValueError(f"insert takes at most {MAX_POINTS_3D} 3D points (its facet refs are "
                         f"int32), got {n}")
    t1 = time.perf_counter()
    perm, hints, order_name, store, stored = _order(P, order, hint, seed, threads)
    t2 = time.perf_counter()
    span = kernel.coordinate_span(P, largest)
    # Store the points along space (orders.layout): vertex ids then follow
    # space, so the cells and coordinates a walk touches are close in memory
    # whatever the insertion order (the Kd order jumps across space at every
    # level).
    kernel.relabel(perm, hints, store)  # perm and hints are ours (_order)
    if d == 3:
        insertion = tetra.insert_all(stored, perm, hints, span, timing=phase_times,
                                     threads=threads)
    else:
        insertion = kernel.insert_all(stored, perm, hints, span, timing=phase_times)
    C, N, mark, ncells, dup_rank, cnt, ok, records = insertion
    duplicates = int(cnt[DUPLICATES])  # points found equal to one inserted before
    dup_of = kernel.duplicate_of(store, dup_rank) if duplicates else None
    t3 = time.perf_counter()
    degenerate, reason = False, ""
    if ok:
        workers = Workers(threads) if d == 3 and threads > 1 else None
        simplices, neighbors, facets = kernel.finite_cells(C, N, mark, store, records,
                                                           shift=2 if d == 3 else 0,
                                                           workers=workers)
        del C, N, mark, records  # the simplices now stand where the cells were
        hull = _chain_hull(facets) if d == 2 else facets.astype(index_dtype(n))
        if duplicates:
            simplices, hull, dup_of = _first_of_duplicates(simplices, hull, dup_of)
        else:
            dup_of = np.arange(n, dtype=index_dtype(n))
        n_distinct = n - duplicates
    else:
        simplices, neighbors, hull, dup_of, n_distinct, reason = _degenerate(P)
        degenerate = True
    t4 = time.perf_counter()
    stats = {
        "seconds": {"validate": t1 - t0, "order": t2 - t1, "insert": t3 - t2,
                    "output": t4 - t3, "total": t4 - t0},
        "order": order_name, "dimension": d, "scale_exponent": s,
        "n_distinct": n_distinct,
    }
    if counters:
        counts = {name: int(cnt[NAMES.index(name)]) for name in _COUNTED
                  if phase_times or name not in _CYCLES.values()}
        stats["counts"] = counts
        stats["per_point"] = per_point(counts, stats["n_distinct"])
    if phase_times:
        stats["cycles"] = {phase: int(cnt[NAMES.index(name)]) for phase, name in _CYCLES.items()}
        hz = cycles_per_second()
        for phase, cycles in stats["cycles"].items():
            stats["seconds"][phase] = cycles / hz
    return Triangulation(points=points, simplices=simplices, neighbors=neighbors, hull=hull,
                         duplicate_of=dup_of.astype(index_dtype(n), copy=False), stats=stats,
                         degenerate=degenerate, reason=reason)


# The insertion order (perm, hints, its name) and the points' layout in
# memory (store, stored: lfqt.orders.layout).
Order = namedtuple("Order", "perm hints name store stored")
# The output of points that span fewer than d dimensions.
Degenerate = namedtuple("Degenerate", "simplices neighbors hull dup_of n_distinct reason")


def _threads(threads):
    """The thread count ``threads`` asks for (None: the cores)."""
    if threads is None:
        return os.cpu_count() or 1
    if isinstance(threads, bool) or not isinstance(threads, (int, np.integer)) or threads < 1:
        raise ValueError(f"threads must be a positive integer or None, got {threads!r}")
    return int(threads)


def _order(P, order, hint, seed, threads):
    """The Order of the insertion order and the points' layout in memory
    (lfqt.orders.layout)."""
    n = len(P)
    if isinstance(order, tuple):
        perm, hints = (np.array(a, dtype=np.int64) for a in order)  # copies: relabelled in place
        if (sorted(perm.tolist()) != list(range(n)) or len(hints) != n
                or np.any((hints < -1) | (hints >= n))):
            raise ValueError("an explicit order must be (perm, hint) with perm a permutation of "
                             "range(n) and one hint per point, a point index or -1")
        return Order(perm, hints, "explicit", *orders.layout(P, "input")[2:])
    perm, hints, store, stored = orders.layout(P, order, hint=hint or "parent", seed=seed,
                                               threads=threads if P.shape[1] == 3 else 1)
    # "hilbert" is its own layout: store is perm itself where layout keeps it
    # int64 (2**31 points or more), a copy in int32 below
    if np.shares_memory(perm, store):
        perm = perm.copy()
    return Order(perm, hints, order, store, stored)


def _first_of_duplicates(simplices, hull, dup_of):
    """Make the smallest input index of each set of equal points its
    vertex, as the divide and conquer does (the inserter keeps whichever it
    met first)."""
    first = np.arange(len(dup_of))
    np.minimum.at(first, dup_of, np.arange(len(dup_of)))
    dtype = simplices.dtype
    return (first[simplices].astype(dtype), first[hull].astype(hull.dtype),
            first[dup_of].astype(dup_of.dtype))


def _degenerate(P):
    """The Degenerate output for points that span fewer than d dimensions:
    no cells, the extreme points as hull, duplicates by exact equality, the
    number of distinct points, and the reason."""
    n, d = P.shape
    idx = index_dtype(n)
    dup_of, first = np.arange(n), np.empty(0, dtype=int)
    if n:  # first: the first index of each distinct point, in lexicographic order
        _, first, inv = np.unique(P, axis=0, return_index=True, return_inverse=True)
        dup_of = first[inv.ravel()]
    hull = np.array(sorted({int(first[0]), int(first[-1])}) if n else [], dtype=idx)
    reason = ("no points" if n == 0 else "fewer than %d affinely independent points (%s)"
              % (d + 1, "all equal" if len(first) == 1 else
                 "collinear" if d == 2 else "collinear or coplanar"))
    empty = np.empty((0, d + 1), dtype=np.int32)
    return Degenerate(empty, empty.copy(), hull, dup_of, len(first), reason)


def _chain_hull(edges):
    """Counter-clockwise vertex loop from 2D hull facets (a, b) of infinite
    cells, whose counter-clockwise hull edge is b -> a."""
    nxt = {int(b): int(a) for a, b in edges}
    start = int(edges[0][1])
    loop = [start]
    while nxt[loop[-1]] != start:
        loop.append(nxt[loop[-1]])
    return np.array(loop, dtype=np.int32)
