"""Public API: input validation, the phase pipeline, scipy-style wrapper."""
import math
import os
import time

import numpy as np
from numba import njit

from . import dc, insert as _insert, morton, orders, parallel, radix
from .mesh import Triangulation
from .predicates import CCW_A, COUNTER_NAMES, N_COUNTERS, orient2d

# Exactness window (see predicates): after an exact power-of-two rescale every
# nonzero |coordinate| must lie in [2**(MIN_ULP_EXP + 52), 2**MAX_EXP), so that
# no product of the predicates' degree (4 in 2D, 5 for in-sphere) overflows or
# leaves the normal range.
MAX_EXP = 248
MIN_ULP_EXP = -240
MAX_EXP_3D = 198
MIN_ULP_EXP_3D = -192
FORMATS = {  # coord_bits, exp_bits, mant_bits, smallest normal exponent
    np.dtype(np.float32): (32, 8, 23, -126),
    np.dtype(np.float64): (64, 11, 52, -1022),
}


class DegenerateInputError(ValueError):
    """Fewer than 3 distinct points, or all points collinear (scipy's Delaunay
    raises QhullError in that case)."""


def _as_exact_float(points, dims):
    """Validate an (n, d) array-like with d in ``dims``; return it as float32
    or float64 holding exactly the input values."""
    arr = np.asarray(points)
    if arr.dtype == object or arr.dtype.kind not in "fiu":
        raise TypeError(f"points must be real numbers, got dtype {arr.dtype}")
    if arr.ndim != 2 or arr.shape[1] not in dims:
        want = " or ".join(f"(n, {d})" for d in dims)
        raise ValueError(f"points must have shape {want}, got {arr.shape}")
    if arr.dtype.kind in "iu":
        big = (arr > 2 ** 53) | (arr < -2 ** 53)
        inexact = np.zeros(len(arr), dtype=bool)
        for r, c in zip(*np.nonzero(big)):
            inexact[r] |= int(float(arr[r, c])) != int(arr[r, c])
        if inexact.any():
            rows = np.flatnonzero(inexact)
            raise ValueError(f"{len(rows)} integer rows are not exactly representable in float64 "
                             f"(beyond 2**53); the first is row {rows[0]}")
        return arr.astype(np.float64)
    if arr.dtype == np.float16:
        return arr.astype(np.float32)
    if arr.dtype not in (np.float32, np.float64):
        wide = arr
        arr = arr.astype(np.float64)
        if not np.array_equal(arr, wide, equal_nan=True):
            raise ValueError(f"{wide.dtype} points are not exactly representable as float64")
    return arr


def _coordinates(points, workers=None):
    """Validate (n, 2) input; return (x, y, scale exponent).  x and y are
    float32 or float64 views of one array holding exactly the input values
    (no copies: a point's x and y then share a cache line in the Morton-order
    gather); the exponent is _exponent_for's, from the same scan."""
    arr = _as_exact_float(points, (2,))
    x, y = arr[:, 0], arr[:, 1]
    bad, first, big, small = _scan_all(x, y, workers)
    if bad:
        raise ValueError(f"points contain NaN or inf in {bad} rows; the first is row {first}")
    return x, y, _exponent_for(x.dtype, big, small)


def _scan_all(x, y, workers=None):
    """(rows with NaN/inf, first such row, max |v|, min nonzero |v|)."""
    workers = workers or parallel.Workers(1)
    parts = workers.map(workers.chunks(x.shape[0]), lambda c, lo, hi: _scan(x, y, lo, hi))
    firsts = [p[1] for p in parts if p[0]]
    return (sum(p[0] for p in parts), firsts[0] if firsts else -1,
            max((p[2] for p in parts), default=0.0), min((p[3] for p in parts), default=np.inf))


@njit(cache=True, nogil=True)
def _scan(x, y, lo, hi):
    """One pass over [lo, hi): (rows with NaN/inf, first such row, max |v|,
    min nonzero |v|)."""
    bad = 0
    first = -1
    big = 0.0
    small = np.inf
    for i in range(lo, hi):
        a = abs(x[i])
        b = abs(y[i])
        if not (a < np.inf and b < np.inf):
            bad += 1
            if first < 0:
                first = i
            continue
        big = max(big, a, b)
        if a > 0.0:
            small = min(small, a)
        if b > 0.0:
            small = min(small, b)
    return bad, first, big, small


def _exponent_for(dtype, big, small):
    """Power of two that brings coordinates with nonzero magnitudes in
    [small, big] into the exactness window, or ValueError when they span too
    many binades."""
    if dtype == np.float32:
        return 0  # float32's whole range already fits the window
    return _window_exponent(big, small, MAX_EXP, MIN_ULP_EXP)


def _window_exponent(big, small, max_exp, min_ulp_exp):
    """Power of two s with every nonzero magnitude in [small, big] mapped into
    [2**(min_ulp_exp + 52), 2**max_exp)."""
    if big == 0.0:
        return 0
    top = math.frexp(big)[1] - 1
    bottom = max(math.frexp(small)[1] - 1, -1022)
    lo = min_ulp_exp + 52 - bottom
    hi = max_exp - 1 - top
    if lo > hi:
        span = max_exp - 1 - min_ulp_exp - 52
        raise ValueError(
            f"coordinate magnitudes span 2**{bottom} to 2**{top}, more than {span} binades; "
            "exact predicates cannot represent every product without overflow or underflow. "
            "Translate or split the data so that the smallest nonzero magnitude is closer to "
            "the largest.")
    return min(max(0, lo), hi)


def _exact_coordinates(points):
    """float64 coordinates, rescaled by an exact power of two so that the
    predicates are exact on them."""
    x, y, s = _coordinates(points)
    return x.astype(np.float64) * 2.0 ** s, y.astype(np.float64) * 2.0 ** s


def _exact_points(points, dims):
    """Validated (n, d) float64 coordinates rescaled by an exact power of two
    into the exactness window of dimension d; returns (P, scale exponent)."""
    arr = _as_exact_float(points, dims)
    finite = np.isfinite(arr).all(axis=1)
    if not finite.all():
        bad = np.flatnonzero(~finite)
        raise ValueError(f"points contain NaN or inf in {len(bad)} rows; the first is row {bad[0]}")
    P = np.array(arr, dtype=np.float64, order="C")
    mags = np.abs(P[P != 0])
    window = (MAX_EXP, MIN_ULP_EXP) if P.shape[1] == 2 else (MAX_EXP_3D, MIN_ULP_EXP_3D)
    s = _window_exponent(float(mags.max(initial=0.0)), float(mags.min(initial=np.inf)), *window)
    P *= 2.0 ** s
    return P, s


def _exact_points3(points):
    return _exact_points(points, (3,))[0]


def _index_dtype(n):
    return np.int32 if n < 2 ** 31 - 2 else np.int64


def triangulate(points, *, threads=1, subdivision="lfqt", counters=False, filter="level",
                schedule="levels"):
    """Exact Delaunay triangulation of 2D points by LFQT divide and conquer.

    points: array-like (n, 2) of float32, float64 or integers (exact in
        float64).  float32 input gives 64-bit Morton keys, float64 input
        128-bit keys; coordinates are never rounded.
    threads: worker threads (None: all cores).  With more than one, the
        upper quad-tree levels are cut into bins triangulated in parallel and
        merged as soon as both children are done (fqDel 3.4).  The result
        does not depend on the thread count.  The alternating ablation always
        runs on one thread.
    subdivision: "lfqt" (split at the highest differing Morton bit) or
        "alternating" (Triangle's alternating median cuts, same merge and
        predicates) for ablation.
    counters: report predicate counts and undecided filter stages in stats.
    filter: stage-1 error bound, "level" (fqDel 2.4, LFQT only) or
        "constant" (Triangle's).
    schedule: "levels" (a barrier after each level of the upper tree) or
        "tasks" (each merge starts when both children are done, the paper's
        split-list).  "levels" measured faster on our 2-core machines (see
        lfqt.parallel), so it is the default.
    """
    if subdivision not in ("lfqt", "alternating"):
        raise ValueError(f"subdivision must be 'lfqt' or 'alternating', got {subdivision!r}")
    if filter not in ("level", "constant"):
        raise ValueError(f"filter must be 'level' or 'constant', got {filter!r}")
    if schedule not in ("tasks", "levels"):
        raise ValueError(f"schedule must be 'tasks' or 'levels', got {schedule!r}")
    if threads is not None and (not isinstance(threads, (int, np.integer)) or threads < 1):
        raise ValueError(f"threads must be a positive integer or None, got {threads!r}")
    if threads is None:
        threads = os.cpu_count() or 1
    threads = int(threads)

    with parallel.Workers(threads) as workers:
        return _triangulate(points, workers, subdivision, counters, filter, schedule)


def _triangulate(points, workers, subdivision, counters, filter, schedule):
    t0 = time.perf_counter()
    x, y, scale_exp = _coordinates(points, workers)
    n = x.shape[0]
    idx = np.zeros(1, dtype=_index_dtype(n))
    wide = x.dtype == np.float64
    coord_bits, exp_bits, mant_bits, emin = FORMATS[x.dtype]
    fmt = np.array([coord_bits, exp_bits, mant_bits, emin, scale_exp], dtype=np.int64)
    chunks = workers.chunks(n)
    t_validate = time.perf_counter()

    # Phase 1: Morton keys, radix sort, coordinates in Morton order.
    perm = np.arange(n, dtype=idx.dtype)
    if wide:
        khi = np.empty(n, dtype=np.uint64)
        klo_in = np.empty(n, dtype=np.uint64)
        workers.map(chunks, lambda c, lo, hi: morton.morton_keys64_into(x, y, khi, klo_in, lo, hi))
        khi, klo, perm = radix.sort_keys128(khi, klo_in, perm, workers)
        del klo_in
    else:
        keys = np.empty(n, dtype=np.uint64)
        workers.map(chunks, lambda c, lo, hi: morton.morton_keys32_into(x, y, keys, lo, hi))
        klo, perm = radix.sort_keys(keys, perm, workers)
        khi = klo[:0]
        del keys
    P = np.empty((n, 2), dtype=np.float64)
    workers.map(chunks, lambda c, lo, hi: dc.gather_points(x, y, perm, 2.0 ** scale_exp, P, lo, hi))
    del x, y  # P holds the coordinates from here on; peak memory matters at 10M+
    t_sort = time.perf_counter()

    ops = np.empty(max(2 * n, 1), dtype=np.int64)
    rep = np.empty(n, dtype=idx.dtype)
    nslots = max(2 * (n - 1), 0)
    T = np.empty(6 * nslots, dtype=idx.dtype)
    workers.map(workers.chunks(len(T)), lambda c, lo, hi: dc.fill(T, dc.UNUSED, lo, hi))
    ghost_out = np.empty(n, dtype=idx.dtype)
    cnt = np.zeros(N_COUNTERS, dtype=np.int64)
    out_ext = np.empty((dc._STACK, 4), dtype=np.int64)
    out_single = np.empty(dc._STACK, dtype=np.bool_)
    level_filter = filter == "level" and subdivision == "lfqt"
    parallel_run = subdivision == "lfqt" and workers.threads > 1 and n > 1
    t_alloc = time.perf_counter()

    # Phases 2 and 3: subdivide and merge, in bins when parallel.
    if parallel_run:
        root_ext, root_single, cnt, pstats = parallel.build(
            khi, klo, wide, n, P, T, ghost_out, rep, ops, fmt, level_filter, workers, schedule)
        out_ext[0], out_single[0], left = root_ext, root_single, 1
        t_subdivide = t_alloc + pstats["subdivide_top"]
        t_merge = time.perf_counter()
        phases = dict(subdivide_top=pstats["subdivide_top"], **pstats["thread_seconds"])
        bins = pstats["bins"]
    else:
        nops = dc.subdivide_lfqt(khi, klo, wide, 0, n, ops, 0, rep) if n else 0
        if subdivision == "alternating" and n:
            ids = np.flatnonzero(rep == np.arange(n)).astype(np.int64)
            nops = dc.subdivide_alternating(ids, P, ops)
            del ids
        t_subdivide = time.perf_counter()
        left = dc.run_ops(ops, 0, nops, P, T, ghost_out, fmt, level_filter, cnt,
                          out_ext, out_single, 0, out_ext, out_single) if n else 0
        t_merge = time.perf_counter()
        phases = dict(subdivide_top=0.0, subdivide_lower=t_subdivide - t_alloc,
                      merge_lower=t_merge - t_subdivide, merge_top=0.0)
        bins = 1
    del ops, khi, klo, P

    # Output: the real triangles, in input indices, compacted in parallel.
    slot_chunks = workers.chunks(nslots)
    newid = np.empty(nslots, dtype=idx.dtype)
    counts = workers.map(slot_chunks, lambda c, lo, hi: dc.number_real(T, newid, lo, hi))
    starts = np.concatenate(([0], np.cumsum(counts))).astype(np.int64)
    if len(slot_chunks) > 1:
        workers.map(slot_chunks, lambda c, lo, hi: dc.offset_ids(newid, lo, hi, starts[c]))
    simplices = np.empty((int(starts[-1]), 3), dtype=idx.dtype)
    neighbors = np.empty((int(starts[-1]), 3), dtype=idx.dtype)
    workers.map(slot_chunks, lambda c, lo, hi: dc.write_real(T, newid, perm, simplices, neighbors,
                                                             lo, hi))
    del newid
    duplicate_of = np.empty(n, dtype=idx.dtype)
    n_distinct = int(sum(workers.map(
        chunks, lambda c, lo, hi: dc.duplicates_into(rep, perm, duplicate_of, lo, hi))))
    degenerate, reason = False, ""
    if len(simplices):
        hull = dc.hull_loop(T, ghost_out[out_ext[0, dc.XMIN]], perm, idx)
    else:
        degenerate = True
        if left == 0:
            hull, reason = np.empty(0, dtype=idx.dtype), "no points"
        elif out_single[0]:
            hull, reason = perm[[out_ext[0, dc.XMIN]]], "fewer than 3 distinct points"
        else:
            hull = perm[[out_ext[0, dc.XMIN], out_ext[0, dc.XMAX]]]
            reason = "fewer than 3 distinct points" if n_distinct < 3 else "all points collinear"
    t_output = time.perf_counter()

    stats = {
        "seconds": {"validate": t_validate - t0, "sort": t_sort - t_validate,
                    "allocate": t_alloc - t_sort, "subdivide": t_subdivide - t_alloc,
                    "merge": t_merge - t_subdivide, "output": t_output - t_merge,
                    "total": t_output - t0},
        # paper Fig. 5: thread-seconds per phase, lower part (bins) and top
        "phases": dict(sort=t_sort - t_validate, **phases),
        "bins": bins,
        "n_distinct": n_distinct,
        "key_bits": 128 if wide else 64,
        "scale_exponent": scale_exp,
        "subdivision": subdivision,
        "filter": "level" if level_filter else "constant",
        "threads": workers.threads,
        "schedule": schedule if parallel_run else "serial",
    }
    if counters:
        stats["predicates"] = dict(zip(COUNTER_NAMES, map(int, cnt)))
    return Triangulation(points=points, simplices=simplices, neighbors=neighbors, hull=hull,
                         duplicate_of=duplicate_of, stats=stats, degenerate=degenerate,
                         reason=reason)


def insert(points, *, order="kdtree", hint=None, counters=True, seed=0):
    """Exact Delaunay triangulation of 2D or 3D points by incremental
    insertion (Bowyer–Watson) in a given order (Liu et al. 2013).

    points: (n, 2) or (n, 3) array-like; dimension from the shape.
    order: a name from lfqt.orders.ORDERS ("kdtree" by default, "kdtree-
        alternate", "hilbert", "brio", "random", "input") or an explicit
        (perm, hint) pair of int arrays.
    hint: for Kd orders, "parent" (default) or "sibling".
    counters: report orientation tests during location, conflicting cells
        and in-sphere tests (totals and per point), and cycles per phase.
    seed: for the randomized orders.

    Returns a Triangulation; in 3D ``simplices`` are right-handed
    tetrahedra and ``hull`` the outward (k, 3) hull facets.
    """
    t0 = time.perf_counter()
    P, s = _exact_points(points, (2, 3))
    n, d = P.shape
    t1 = time.perf_counter()
    if isinstance(order, tuple):
        perm, hints = (np.asarray(a, dtype=np.int64) for a in order)
        if sorted(perm.tolist()) != list(range(n)) or len(hints) != n:
            raise ValueError("an explicit order must be (perm, hint) with perm a permutation of "
                             "range(n) and one hint per point")
        order_name = "explicit"
    else:
        perm, hints = orders.order(P, order, hint=hint or "parent", seed=seed)
        order_name = order
    t2 = time.perf_counter()
    span = float(np.abs(P).max(initial=1.0)) or 1.0
    # Store the points in Hilbert order: vertex ids then follow space, so the
    # cells and coordinates a walk touches are close in memory whatever the
    # insertion order (the Kd order jumps across space at every level).
    store = _storage_order(P)
    rank = np.empty(n, dtype=np.int64)
    rank[store] = np.arange(n)
    hint_ids = np.where(hints >= 0, rank[np.maximum(hints, 0)], -1)
    C, N, alive, ncells, dup_rank, cnt, ok = _insert.insert_all(
        np.ascontiguousarray(P[store]), d, rank[perm], hint_ids, span)
    dup_of = store[dup_rank[rank]]
    t3 = time.perf_counter()
    idx = _index_dtype(n)
    degenerate, reason = False, ""
    if ok:
        simplices, neighbors = _insert.finite_cells(C, N, alive, store)
        facets = _insert.hull_facets(C, alive, store)
        hull = _chain_hull(facets) if d == 2 else facets.astype(idx)
    else:
        degenerate = True
        simplices = np.empty((0, d + 1), dtype=np.int32)
        neighbors = np.empty((0, d + 1), dtype=np.int32)
        distinct = np.unique(P, axis=0, return_index=True)[1] if n else np.empty(0, int)
        hull = np.array(sorted({int(distinct[0]), int(distinct[-1])}) if n else [], dtype=idx)
        reason = ("no points" if n == 0 else "fewer than %d affinely independent points (%s)"
                  % (d + 1, "all equal" if len(distinct) == 1 else
                     "collinear" if d == 2 else "collinear or coplanar"))
        dup_of = np.arange(n)
        if n:
            _, first, inv = np.unique(P, axis=0, return_index=True, return_inverse=True)
            dup_of = first[inv.ravel()]
    t4 = time.perf_counter()
    stats = {
        "seconds": {"validate": t1 - t0, "order": t2 - t1, "insert": t3 - t2,
                    "output": t4 - t3, "total": t4 - t0},
        "order": order_name, "dimension": d, "scale_exponent": s,
        "n_distinct": int(np.count_nonzero(dup_of == np.arange(n))),
    }
    if counters:
        totals = dict(zip(_insert.COUNTER_NAMES, map(int, cnt)))
        inserted = max(stats["n_distinct"], 1)
        stats["counts"] = totals
        stats["per_point"] = {"orientation_tests": totals["orientation_tests"] / inserted,
                              "conflicts": totals["conflicts"] / inserted,
                              "insphere_tests": totals["insphere_tests"] / inserted}
        stats["cycles"] = {"locate": totals["locate_cycles"], "cavity": totals["cavity_cycles"]}
        hz = _insert.cycles_per_second()
        stats["seconds"]["locate"] = totals["locate_cycles"] / hz
        stats["seconds"]["cavity"] = totals["cavity_cycles"] / hz
    return Triangulation(points=points, simplices=simplices, neighbors=neighbors, hull=hull,
                         duplicate_of=dup_of.astype(idx), stats=stats, degenerate=degenerate,
                         reason=reason)


def _storage_order(P):
    """A permutation of the rows of P along a Hilbert curve (2D or 3D)."""
    if len(P) == 0:
        return np.arange(0)
    # Cells of 2^-16 (2D) or 2^-10 (3D) of the bounding box are fine enough
    # for locality, and cheaper to index than the order's 31/21 bits.
    bits = 16 if P.shape[1] == 2 else 10
    return orders.sorted_by_key(orders.hilbert_keys(P, np.arange(len(P)), bits))


def _chain_hull(edges):
    """Counter-clockwise vertex loop from 2D hull facets (a, b) of infinite
    cells, whose counter-clockwise hull edge is b -> a."""
    nxt = {int(b): int(a) for a, b in edges}
    start = int(edges[0][1])
    loop = [start]
    while nxt[loop[-1]] != start:
        loop.append(nxt[loop[-1]])
    return np.array(loop, dtype=np.int32)


@njit(cache=True)
def _locate(xs, ys, simplices, neighbors, qx, qy, start):
    """Visibility walk with exact orientation; -1 outside the hull."""
    cnt = np.zeros(N_COUNTERS, dtype=np.int64)
    m = simplices.shape[0]
    out = np.empty(qx.shape[0], dtype=np.int64)
    t = start
    for k in range(qx.shape[0]):
        if t < 0:
            t = start
        px = qx[k]
        py = qy[k]
        found = -1
        for _ in range(4 * m + 4):
            moved = False
            for j in range(3):
                i = (j + k) % 3  # rotate the first edge tried so the walk cannot cycle
                a = simplices[t, (i + 1) % 3]
                b = simplices[t, (i + 2) % 3]
                if orient2d(xs[a], ys[a], xs[b], ys[b], px, py, CCW_A, cnt) < 0.0:
                    nb = neighbors[t, i]
                    if nb < 0:
                        t = -1
                    else:
                        t = nb
                    moved = True
                    break
            if not moved:
                found = t
                break
            if t < 0:
                break
        out[k] = found
        if found >= 0:
            t = found
    return out


class Delaunay:
    """Drop-in for the common use of ``scipy.spatial.Delaunay`` in 2D.

    Raises :class:`DegenerateInputError` where scipy raises QhullError
    (fewer than 3 distinct points or all collinear).  ``coplanar`` lists the
    duplicate rows that are not vertices, as (row, simplex, vertex) like
    scipy's.
    """

    def __init__(self, points, **kwargs):
        self._tri = triangulate(points, **kwargs)
        if self._tri.degenerate:
            raise DegenerateInputError(f"cannot triangulate: {self._tri.reason}")
        self.points = np.asarray(points, dtype=np.float64)
        self.simplices = self._tri.simplices
        self.neighbors = self._tri.neighbors
        self.ndim = 2
        self.npoints = len(self.points)
        self.nsimplex = len(self.simplices)
        self.stats = self._tri.stats
        self._scale = 2.0 ** self.stats["scale_exponent"]
        self._xs = self.points[:, 0] * self._scale
        self._ys = self.points[:, 1] * self._scale
        self._lo = self.points.min(axis=0)
        self._hi = self.points.max(axis=0)
        self._simplices64 = self.simplices.astype(np.int64)
        self._neighbors64 = self.neighbors.astype(np.int64)
        self._vnv = None

    @property
    def triangulation(self):
        return self._tri

    @property
    def convex_hull(self):
        h = self._tri.hull
        return np.stack((h, np.roll(h, -1)), axis=1)

    @property
    def coplanar(self):
        dup = self._tri.duplicate_of
        rows = np.flatnonzero(dup != np.arange(len(dup)))
        if len(rows) == 0:
            return np.empty((0, 3), dtype=np.int32)
        owner = np.empty(self.npoints, dtype=np.int64)
        owner[self.simplices.ravel()] = np.repeat(np.arange(self.nsimplex), 3)
        return np.stack((rows, owner[dup[rows]], dup[rows]), axis=1).astype(np.int32)

    def find_simplex(self, xi):
        q = np.asarray(xi, dtype=np.float64)
        shape = q.shape[:-1]
        q = q.reshape(-1, 2)
        if not np.isfinite(q).all():
            raise ValueError("query points must be finite")
        # Outside the bounding box needs no predicate (and could overflow one).
        inside = ((q[:, 0] >= self._lo[0]) & (q[:, 0] <= self._hi[0])
                  & (q[:, 1] >= self._lo[1]) & (q[:, 1] <= self._hi[1]))
        qx = np.ascontiguousarray(q[inside, 0]) * self._scale
        qy = np.ascontiguousarray(q[inside, 1]) * self._scale
        mags = np.abs(np.concatenate((qx, qy)))
        if np.any((mags > 0) & (mags < 2.0 ** (MIN_ULP_EXP + 52))):
            raise ValueError("query coordinates are too small relative to the triangulated "
                             "points for exact predicates")
        found = np.full(len(q), -1, dtype=np.int64)
        found[inside] = _locate(self._xs, self._ys, self._simplices64, self._neighbors64,
                                qx, qy, 0)
        return found.astype(np.int32).reshape(shape)

    @property
    def vertex_neighbor_vertices(self):
        if self._vnv is None:
            s = self.simplices.astype(np.int64)
            a = np.concatenate((s[:, 0], s[:, 1], s[:, 2], s[:, 1], s[:, 2], s[:, 0]))
            b = np.concatenate((s[:, 1], s[:, 2], s[:, 0], s[:, 0], s[:, 1], s[:, 2]))
            key = np.unique(a * self.npoints + b)
            src, dst = key // self.npoints, key % self.npoints
            indptr = np.zeros(self.npoints + 1, dtype=np.int32)
            np.cumsum(np.bincount(src, minlength=self.npoints), out=indptr[1:])
            self._vnv = (indptr, dst.astype(np.int32))
        return self._vnv
