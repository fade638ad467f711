"""Dwyer-style divide and conquer on the LFQT (fqDel): the validated public
wrapper ``triangulate`` and its phases, over the kernels of this package.

    sort        Morton keys of the float bits, radix sort (lfqt.morton, lfqt.radix)
    subdivide   Algorithm 1 as one sweep (lfqt.dc.subdivide)
    merge       Guibas–Stolfi on ghost-wrapped triangles (lfqt.dc.merge)
    parallel    bins and the upper tree's merges (lfqt.dc.bins)
    output      real triangles in input indices (lfqt.dc.output)
"""
from __future__ import annotations

import os
import time
from typing import Any, Literal, NamedTuple, get_args

import numpy as np
import numpy.typing as npt

from .. import calls, morton, radix, workspace
from .._input import FORMATS, exact_floats2d, exponent_for, index_dtype, magnitudes
from ..indexing import iota
from ..predicates.counters import as_dict, new_counters, per_point
from ..triangulation import Triangulation
from ..workers import Workers
from . import bins, hybrid, output, subdivide
from .layout import PART, SMALL, XMAX, XMIN, Mesh, t_dtype
from .state import State

Subdivision = Literal["lfqt", "alternating"]
Filter = Literal["level", "constant"]
Schedule = Literal["tasks", "levels"]
Method = Literal["dc", "hybrid"]
LeafOrder = Literal["hilbert", "kdtree"]  # hybrid.ORDERS
SUBDIVISIONS: tuple[Subdivision, ...] = get_args(Subdivision)
FILTERS: tuple[Filter, ...] = get_args(Filter)
SCHEDULES: tuple[Schedule, ...] = get_args(Schedule)
METHODS: tuple[Method, ...] = get_args(Method)
LEAF_SIZE = 1024  # keys per bin of the hybrid method (see experiments.hybrid)


@calls.entry
def triangulate(points: npt.ArrayLike, *, threads: int | np.integer[Any] | None = 1,
                subdivision: Subdivision = "lfqt", counters: bool = True,
                filter: Filter = "level", schedule: Schedule = "tasks", method: Method = "dc",
                leaf_size: int | np.integer[Any] | None = None,
                leaf_order: LeafOrder = "hilbert") -> Triangulation:
    """Exact Delaunay triangulation of 2D points by LFQT divide and conquer.

    Parameters
    ----------
    points : array_like, shape (n, 2)
        float32, float64 or integers (exact in float64).  float32 input gives
        64-bit Morton keys, float64 input 128-bit keys; coordinates are never
        rounded.
    threads : int or None
        Worker threads (None: all cores).  With more than one, the upper
        quad-tree levels are cut into bins triangulated in parallel, then
        merged upwards (fqDel 3.4).  The result does not depend on the thread
        count.  The alternating ablation always runs on one thread.
    subdivision : {"lfqt", "alternating"}
        Split at the highest differing Morton bit, or Triangle's alternating
        median cuts with the same merge and predicates (ablation).
    counters : bool
        Report ``stats["counts"]``: predicate calls and the calls each filter
        stage left undecided (paper 1, Table 1), and ``stats["per_point"]``.
        The kernels count anyway, so this is free.
    filter : {"level", "constant"}
        Stage-1 error bound: level-dependent (fqDel 2.4, LFQT only) or
        Triangle's constant.
    schedule : {"tasks", "levels"}
        Each upper merge runs as soon as both of its children are done (the
        paper's split-list; default, measured faster on our 2-core machines,
        see lfqt.dc.bins), or level by level with a barrier after each.
    method : {"dc", "hybrid"}
        Divide and conquer all the way down, or (paper 1's open question,
        lfqt.dc.hybrid) incremental insertion in the LFQT cells of at most
        ``leaf_size`` keys (default LEAF_SIZE) in ``leaf_order``
        ("hilbert" or "kdtree"), merged by the divide and conquer above.
        Both give the exact Delaunay triangulation.
    leaf_size : int, optional
        Keys per cell of ``method="hybrid"`` (default LEAF_SIZE).
    leaf_order : {"hilbert", "kdtree"}
        The insertion order in the cells of ``method="hybrid"``.

    Returns
    -------
    Triangulation
        ``simplices`` (m, 3) counter-clockwise, ``neighbors``, the
        counter-clockwise ``hull`` loop, ``duplicate_of``, and ``stats``:
        seconds per phase, thread-seconds per phase of paper 1's Figure 5
        (``stats["phases"]``), and with ``counters``, the predicate counts.
        Fewer than 3 distinct points, or all collinear: no simplices, the
        extreme points in ``hull``, and ``degenerate=True``.

    Raises
    ------
    ValueError
        For an option out of its set, points not of shape (n, 2), NaN or
        inf, or magnitudes spanning more than 435 binades (lfqt._input).
    TypeError
        For points that are not real numbers.

    Examples
    --------
    >>> import numpy as np
    >>> import lfqt
    >>> p = np.random.default_rng(0).random((100, 2))
    >>> tri = lfqt.triangulate(p)
    >>> tri.simplices.shape[1]
    3
    >>> len(tri.simplices) == 2 * len(p) - 2 - len(tri.hull)  # Euler, on distinct points
    True
    >>> bool(lfqt.verify(p, tri).ok)
    True
    >>> same = lfqt.triangulate(p, threads=2, schedule="levels")
    >>> np.array_equal(same.simplices, tri.simplices)
    True
    >>> sorted(tri.stats["per_point"])
    ['incircle_tests', 'orientation_tests']
    """
    for name, value, allowed in (("subdivision", subdivision, SUBDIVISIONS),
                                 ("filter", filter, FILTERS), ("schedule", schedule, SCHEDULES),
                                 ("method", method, METHODS), ("leaf_order", leaf_order,
                                                               hybrid.ORDERS)):
        if value not in allowed:
            raise ValueError(f"{name} must be one of {', '.join(map(repr, allowed))}, "
                             f"got {value!r}")
    if threads is not None and (not isinstance(threads, (int, np.integer)) or threads < 1):
        raise ValueError(f"threads must be a positive integer or None, got {threads!r}")
    if method == "hybrid" and subdivision != "lfqt":
        raise ValueError("method='hybrid' inserts in the LFQT's cells: subdivision must be 'lfqt'")
    if leaf_size is not None and (not isinstance(leaf_size, (int, np.integer)) or leaf_size < 1):
        raise ValueError(f"leaf_size must be a positive integer, got {leaf_size!r}")
    threads = int(threads if threads is not None else os.cpu_count() or 1)
    hybrid_leaf = (leaf_size or LEAF_SIZE, leaf_order) if method == "hybrid" else None
    with Workers(threads) as workers:
        return _triangulate(points, workers, subdivision, counters, filter, schedule, hybrid_leaf)


def _memory(n, idx, workers):
    """The call's two large mappings (lfqt.workspace), each home in turn to
    arrays whose lives do not overlap, so that the phases of a call write
    the same pages one after the other instead of a fresh set each, and
    its peak memory is that of the merges' end: T, P, perm, ghost_out and
    the gaps (about 73 bytes a point, docs/performance.md, "peak memory")::

        slots   [ khi | key_buf | slo ]               phase 1: the sort's keys
                [ T: 6 entries a triangle slot .... ]  phases 2-3, the keys dropped
                [ simplices (m, 3) | neighbors (m, 3) ] the output, over T
        points  [ perm_buf ]                            phase 1: the sort's scratch
                [ P: (n, 2) float64 ]                   phases 1-3
                [ buf ]                                 the output's upper vertex rows

    The keys are sized for 128-bit keys, the larger.  A result keeps
    ``slots`` alone, and ``points`` goes back to the pool at the call's
    end.  Both are written whole, so a fresh mapping is populated at once,
    on ``workers`` (workspace.empty).  Returns (slots, points), uint8
    arrays."""
    slots = workspace.empty(max(workspace.view_bytes(_t_spec(n)),
                                workspace.view_bytes(*_sort_specs(n, True))), np.uint8,
                            populate=workers)
    t_bytes = np.dtype(_t_spec(n)[1]).itemsize
    points = workspace.empty(max(workspace.view_bytes(_point_spec(n)),
                                 3 * n * t_bytes, n * np.dtype(idx).itemsize), np.uint8,
                             populate=workers)
    return slots, points


def _sort_specs(n, wide):
    """The sort's keys (workspace.views): the keys (their high words for
    128-bit keys), radix.sort_keys' scratch for them, and for 128-bit keys
    the sorted low words."""
    return [(n, np.uint64)] * (3 if wide else 2)


def _t_spec(n):
    """T's entries (6 per triangle slot, 2 slots per merge) and dtype."""
    return 6 * max(2 * (n - 1), 0), t_dtype(n)


def _point_spec(n):
    """P's entries and dtype."""
    return 2 * n, np.float64


class Sorted(NamedTuple):
    """Phase 1's output: the sorted keys (khi empty for 64-bit keys), the
    uint8 gaps between adjacent ones, whether a key repeats, the
    permutation, and the points in key order scaled by 2**scale_exp."""
    khi: np.ndarray
    klo: np.ndarray
    gaps: np.ndarray
    copies: bool
    perm: np.ndarray
    P: np.ndarray
    scale_exp: int


class Output(NamedTuple):
    """The result's arrays (_output), and the reason the set is degenerate
    ("" when it is not)."""
    simplices: np.ndarray
    neighbors: np.ndarray
    hull: np.ndarray
    duplicate_of: np.ndarray
    n_distinct: int
    reason: str


def _sorted_points(pts, workers, idx_dtype, slots, points):
    """Phase 1: Morton keys of the C-contiguous (n, 2) points ``pts``, radix
    sort, the gaps between adjacent keys, and the points gathered in Morton
    order as float64 scaled by 2**scale_exp (exact; the exponent from the
    scan of the keys' pass, lfqt._input), in the mappings ``slots`` and
    ``points`` (_memory).  Returns a Sorted.  ValueError for NaN or inf."""
    n = pts.shape[0]
    khi, klo, perm, scan = sorted_keys(pts, workers, idx_dtype, (slots, points))
    scale_exp = exponent_for(pts.dtype, *magnitudes(pts, scan, workers))
    P = workspace.views(points, _point_spec(n))[0].reshape(n, 2)
    gaps, copies = key_gaps(khi, klo, pts.dtype == np.float64, workers, lambda lo, hi: (
        output.gather_points(pts, perm, 2.0 ** scale_exp, P, lo, hi)))
    return Sorted(khi, klo, gaps, copies, perm, P, scale_exp)


def key_gaps(khi, klo, wide, workers, also=None):
    """The uint8 gaps of sorted keys (lfqt.dc.subdivide.gap_bits) and
    whether a key repeats.  ``also(lo, hi)``, if given, runs on each chunk
    in the same parallel step (one hand-off to the pool for the two)."""
    n = klo.shape[0]
    gaps = workspace.empty(n, np.uint8)

    def chunk(c, lo, hi):
        if also is not None:
            also(lo, hi)
        return subdivide.gap_bits(khi, klo, wide, gaps, lo, hi)
    return gaps, any(workers.map(workers.chunks(n), chunk))


def sorted_keys(pts, workers, idx_dtype, scratch=None):
    """Morton keys of the C-contiguous (n, 2) float32 or float64 points and
    their radix sort: (khi, klo, perm, scan), khi empty for 64-bit keys
    (float32 input), scan the chunks' scans of the coordinates that the
    keys' pass makes (lfqt.morton, lfqt._input.magnitudes).  ``scratch``:
    the mappings of _memory, the keys in the first (default: new arrays)."""
    n = pts.shape[0]
    wide = pts.dtype == np.float64
    specs = _sort_specs(n, wide)
    slots, points = scratch or (workspace.empty(workspace.view_bytes(*specs), np.uint8),
                                workspace.empty(n * np.dtype(idx_dtype).itemsize, np.uint8))
    perm_buf = workspace.views(points, (n, idx_dtype))[0]
    chunks = workers.chunks(n)
    perm = workspace.empty(n, idx_dtype)
    if wide:  # the low words from the points' bits, in runs of equal high words only
        khi, key_buf, slo = workspace.views(slots, *specs)
        bits = pts.view(np.uint64)
        scan = workers.map(chunks, lambda c, lo, hi: morton.morton_high64_into(bits, khi, perm,
                                                                               lo, hi))
        return (*radix.sort_keys128(khi, bits, perm, workers, (key_buf, perm_buf), slo), scan)
    keys, key_buf = workspace.views(slots, *specs)
    bits = pts.view(np.uint32)
    scan = workers.map(chunks, lambda c, lo, hi: morton.morton_keys32_into(bits, keys, perm, lo,
                                                                           hi))
    klo, perm = radix.sort_keys(keys, perm, workers, scratch=(key_buf, perm_buf))
    return klo[:0], klo, perm, scan


def _state(s, dtype, level_filter, slots):
    """The arrays of the subdivision and merge (lfqt.dc.state.State) around
    the sorted keys and points ``s`` (a Sorted), T in the call's mapping
    ``slots`` (_memory).
    T is not filled: every slot a merge owns is written by it, and the
    output tells the others by their split position (output.fill_holes).
    The keys in T's memory are read no more once the merges start
    (State.drop_keys)."""
    n = s.P.shape[0]
    idx = s.perm.dtype
    T = workspace.views(slots, _t_spec(n))[0]
    coord_bits, exp_bits, mant_bits, emin = FORMATS[dtype]
    fmt = np.array([coord_bits, exp_bits, mant_bits, emin, s.scale_exp], dtype=np.int64)
    mesh = Mesh(s.P, T, workspace.empty(n, idx), fmt, level_filter)
    return State(s.khi, s.klo, dtype == np.float64, mesh, None, s.gaps, s.gaps, s.copies)


def _serial(state, subdivision, counts):
    """Phases 2 and 3 on one thread: (root partition row, phase seconds)."""
    n = state.n
    state.drop_keys()  # the gaps stand for the keys, in T's memory, from here on
    t0 = time.perf_counter()
    root = np.zeros((1, PART), dtype=np.int64)
    share = 0.0  # of the time, the subdivision's
    if subdivision == "alternating" and n:
        state.codes = np.full(n, subdivide.DUP, dtype=np.uint8)
        state.ops = np.empty(2 * n, dtype=np.int64)
        nops = subdivide.subdivide_alternating(subdivide.run_starts(state.gaps, 0, n),
                                               state.mesh.P, state.ops, state.codes)
        share = time.perf_counter() - t0
        state.merge(0, nops, counts, root, 0, root)
        share /= max(time.perf_counter() - t0, 1e-12)
    elif n:
        share = state.merge_range(0, n, counts, root)
    wall = time.perf_counter() - t0
    return root[0], dict(subdivide_top=0.0, subdivide_lower=share * wall,
                         merge_lower=(1.0 - share) * wall, merge_top=0.0)


def _triangulate(points, workers, subdivision, counters, filter, schedule, hybrid_leaf=None):
    t0 = time.perf_counter()
    pts = exact_floats2d(points)  # NaN and inf: in the keys' pass (_sorted_points)
    n = pts.shape[0]
    t_validate = time.perf_counter()
    idx = index_dtype(n)
    slots, points_mem = _memory(n, idx, workers)
    ordered = _sorted_points(pts, workers, idx, slots, points_mem)
    dtype = pts.dtype
    del pts  # P holds the coordinates from here on; peak memory matters at 10M+
    t_sort = time.perf_counter()
    level_filter = filter == "level" and subdivision == "lfqt"
    state = _state(ordered, dtype, level_filter, slots)
    perm, scale_exp = ordered.perm, ordered.scale_exp
    del slots, ordered  # T's array holds it from here on
    counts = new_counters()
    parallel_run = subdivision == "lfqt" and (workers.threads > 1 or hybrid_leaf) and n > 1
    t_alloc = time.perf_counter()
    if parallel_run:
        leaf, order = hybrid_leaf or (None, None)
        root, counts, pstats = bins.build(state, workers, schedule, leaf, order)
        phases = dict(subdivide_top=pstats["subdivide_top"], **pstats["thread_seconds"])
        n_bins = pstats["bins"]
    else:
        root, phases = _serial(state, subdivision, counts)
        n_bins = 1
    t_merge = time.perf_counter()
    wide = state.wide
    out = _output(state, perm, root, workers, points_mem)
    del state
    t_output = time.perf_counter()
    # wall clock: in parallel only the top subdivision is apart from the merges
    subdivide_wall = phases["subdivide_top"] + (0.0 if parallel_run else phases["subdivide_lower"])
    stats = {  # validate: dtypes and shapes (NaN, inf and magnitudes: in the sort's keys pass)
        "seconds": {"validate": t_validate - t0, "sort": t_sort - t_validate,
                    "allocate": t_alloc - t_sort, "subdivide": subdivide_wall,
                    "merge": t_merge - t_alloc - subdivide_wall, "output": t_output - t_merge,
                    "total": t_output - t0},
        # paper Fig. 5: thread-seconds per phase, lower part (bins) and top
        "phases": dict(sort=t_sort - t_validate, **phases),
        "bins": n_bins,
        "n_distinct": out.n_distinct,
        "key_bits": 128 if wide else 64,
        "scale_exponent": scale_exp,
        "subdivision": subdivision,
        "filter": "level" if level_filter else "constant",
        "threads": workers.threads,
        "schedule": schedule if parallel_run else "serial",
        "method": "hybrid" if hybrid_leaf else "dc",
    }
    if hybrid_leaf:
        stats["leaf_size"], stats["leaf_order"] = hybrid_leaf
    if counters:
        stats["counts"] = as_dict(counts)
        stats["per_point"] = per_point(stats["counts"], out.n_distinct)
    return Triangulation(points=points, simplices=out.simplices, neighbors=out.neighbors,
                         hull=out.hull, duplicate_of=out.duplicate_of, stats=stats,
                         degenerate=bool(out.reason), reason=out.reason)


def _output(state, perm, root, workers, points_mem):
    """The real triangles in input indices, the hull loop and duplicate_of,
    as an Output.  Takes the mesh out of ``state`` and turns T into
    ``simplices`` and ``neighbors`` in its own memory (lfqt.dc.output),
    with P's (``points_mem``, _memory) for the rows in between, and
    ``duplicate_of`` in ghost_out's, so that no array of the mesh and of
    the result coexist."""
    T, ghost_out, gaps, codes, copies = (state.mesh.T, state.mesh.ghost_out, state.gaps,
                                         state.codes, state.copies)
    state.mesh = state.khi = state.klo = state.ops = state.gaps = state.codes = None  # P
    n = len(perm)
    idx = perm.dtype
    start = int(ghost_out[root[XMIN]]) if len(T) else -1  # a ghost of the hull ring
    duplicate_of = ghost_out  # written over it: the ghosts are read no more
    del ghost_out
    if copies:
        n_distinct = _first_copies(gaps, perm, workers, duplicate_of)
    else:  # duplicate_of is the identity
        n_distinct = n
        workers.map(workers.chunks(n), lambda c, lo, hi: iota(duplicate_of, lo, hi))
    m = 0
    ring = len(T) > 0 and root[SMALL] != 1  # else a lone distinct point, without ghosts
    if ring:
        hull = output.hull_loop(T, start, perm, perm[:1])
        m = 2 * (n_distinct - 1) - len(hull)  # the merges' slots, less the ghosts
    reason = ""
    if m == 0:
        if n == 0:
            hull, reason = np.empty(0, dtype=idx), "no points"
        elif not ring:
            hull, reason = perm[[root[XMIN]]], "fewer than 3 distinct points"
        else:
            hull = perm[[root[XMIN], root[XMAX]]]
            reason = "fewer than 3 distinct points" if n_distinct < 3 else "all points collinear"
    elif m < 0 or not output.fill_holes(T, codes, start, m, copies):
        raise RuntimeError("lfqt internal error: the real triangles do not fill the slots; "
                           "please report the input")
    del gaps, codes
    buf = workspace.views(points_mem, (3 * (m - m // 2), T.dtype))[0]
    if not output.write_rows(T, perm, buf, m, workers):
        raise RuntimeError("lfqt internal error: a ghost triangle off the hull ring; please "
                           "report the input")
    rows = workspace.keep_range(T, 0, 6 * m)
    if T.dtype != idx:  # more than 2**28 points: T's entries are wider than the indices
        rows = rows.astype(idx)
    return Output(rows[:3 * m].reshape(m, 3), rows[3 * m:].reshape(m, 3), hull, duplicate_of,
                  n_distinct, reason)


def _first_copies(gaps, perm, workers, out):
    """duplicate_of into ``out`` when some key repeats: each point's first
    copy (output.duplicates_into), by ranges over ``workers``; returns the
    number of distinct points.  When none repeats, _output writes the
    identity instead (a sequential write, not a scatter to the input order:
    docs/performance.md, "identity duplicate_of")."""
    return int(sum(workers.map(workers.chunks(len(perm)), lambda c, lo, hi: (
        output.duplicates_into(gaps, perm, out, lo, hi)))))
