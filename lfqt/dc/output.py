"""Output of the divide and conquer, and the kernels around the pipeline:
the Morton-order gather of the input, the real triangles in input indices,
the hull loop and ``duplicate_of``.  Every kernel works on an index range,
so the pipeline can chunk it over threads.

The output is built in T's own memory, so that T and a full copy of the
result never coexist (peak memory, lfqt.dc._output):

1. ``fill_holes``: once the merges are done every used slot holds a real
   triangle or a ghost of the one hull ring, and the slots of the
   duplicates' merges are unused, so the m real triangles fit in the first
   m slots: each one above moves into a ghost's or an unused slot below,
   found from the ring and the merges' codes, not from a pass over T.  A
   slot is then its output row, and a twin, shifted, its neighbour's, with
   no rank from a bitmap of the real slots and a popcount
   (docs/performance.md, "output without ranks");
2. ``write_rows``: in one pass over T, the vertex rows, in input indices,
   to a new array, and each chunk's neighbour rows packed at the start of
   its own part of T.  Row k of a chunk lands at 3k to 3k + 2,
   below the slots after k, which are still to be read (at 6k + 6 on).
   With several chunks, the first is read downward and its rows packed to
   end where the second chunk's begin (``write_rows_down``), so that the
   two meet in place;
3. ``move_rows``: the later chunks' rows slide down behind them, in chunk
   order, each below what is still to move; the result keeps T's range of
   rows, and the pages around it go back to the system (lfqt.workspace).
   Meeting in place saves a move (docs/performance.md, "output rows").
"""
import numpy as np
from numba import njit

from ..indexing import borrow, prefetch, u
from .layout import GHOST, edge, inner, ring_ghost, slot, tail, twin
from .subdivide import DUP


# Morton order scatters the input indices: gather_points asks for the point
# AHEAD positions on before it reads it; memory's latency needs enough reads
# in flight, and more than 64 gained nothing (docs/performance.md, "gather
# ahead").
AHEAD = 64


@njit(cache=True, nogil=True)
def gather_points(pts, perm, scale, P, lo, hi):
    """P[i] = pts[perm[i]] * scale for i in [lo, hi): the (n, 2) points in
    Morton order as float64 (an exact power-of-two scale)."""
    for i in range(lo, hi):
        prefetch(pts, np.int64(perm[u(min(i + AHEAD, hi - 1))]))
        j = u(perm[u(i)])
        P[u(i), 0] = np.float64(pts[j, 0]) * scale
        P[u(i), 1] = np.float64(pts[j, 1]) * scale


@njit(cache=True)
def fill_holes(T, codes, start, m, copies):
    """Pack the m real triangles into the slots [0, m), in place, once the
    hull ring through ghost ``start`` has been read (hull_loop).  The holes
    below m are the ring's ghosts and the slots of the duplicates' merges
    (``codes[p] == DUP`` for split position p: slots 2(p-1) and 2(p-1)+1,
    never written); each real triangle from m on moves into one, and the
    twins of its edges follow it::

                 holes below m                 real triangles from m on
        T  [ R  G  R  D  R  R  G  R | R  G  R  R  D ]    R real, G ghost,
                ^     ^        ^    m  |     |  |          D unused (a copy's)
                |     |        +-------+     |  |
                |     +----------------------+  |
                +-------------------------------+

    First each real triangle's twin across the hull becomes -1, so that a
    twin is then its neighbour's slot (times 4, plus the edge) or -1.  The
    work is linear in the hull, plus a scan of the codes when a key
    repeats; never a pass over T.  Returns False when the holes and the
    real triangles from m on do not pair up (never for a mesh of the
    merges)."""
    nslots = T.shape[0] // 6
    holes = np.empty(nslots - m, dtype=np.int64)
    k = 0
    g = start
    while True:  # seal the hull; the ghosts below m are holes
        T[twin(inner(T, g))] = -1
        if g < m:
            if k == holes.shape[0]:
                return False
            holes[k] = g
            k += 1
        g = ring_ghost(T, g, 1)
        if g == start:
            break
    if copies:
        for t in range(m):
            if _unused(codes, t):
                if k == holes.shape[0]:
                    return False
                holes[k] = t
                k += 1
    j = 0
    for t in range(m, nslots):
        if not _unused(codes, t) and T[slot(t, 2)] != GHOST:  # a real triangle
            if j == k:
                return False
            _move(T, t, holes[j])
            j += 1
    return j == k


@njit(cache=True, inline="always")
def _unused(codes, t):
    """Whether slot t is never written: it belongs to the merge at split
    position t // 2 + 1 (lfqt.dc.layout), and that position repeats a key."""
    return codes[u((t >> 1) + 1)] == DUP


@njit(cache=True, inline="always")
def _move(T, t, d):
    """Real triangle t moves to slot d; its neighbours' twins follow."""
    for i in range(3):
        T[slot(d, i)] = T[slot(t, i)]
        e = T[slot(t, 3 + i)]
        T[slot(d, 3 + i)] = e
        if e >= 0:
            T[twin(e)] = edge(d, i)


@njit(cache=True, nogil=True)
def write_rows(T, perm, simplices, lo, hi, at):
    """The rows of the real slots [lo, hi) (packed: fill_holes): vertex rows,
    in input indices, to ``simplices``; neighbour rows (neighbour i opposite
    vertex i, -1 on the hull) packed into T from T[at] on, at <= 6 * lo.
    Slot t is read whole before its rows are written, and its neighbour row
    lands below the slots still to be read (the module's step 2).  Returns
    how many entries of T were written, or -1 for a ghost."""
    T, perm, simplices = borrow(T), borrow(perm), borrow(simplices)
    for t in range(lo, hi):
        if not _write_row(T, perm, simplices, t, at + 3 * (t - lo)):
            return -1
    return 3 * (hi - lo)


@njit(cache=True, nogil=True)
def write_rows_down(T, perm, simplices, lo, hi, end):
    """write_rows for the first of several chunks, its slots read from the
    last down and its neighbour rows packed to end at T[end], where the
    next chunk's begin (its first slot's, 6 * hi): the two meet without a
    move.  Row t lands at end - 3(hi - t), above every slot still to be
    read::

        T  [ slots of this chunk, read downward     | next chunk's slots ... )
                         [ its rows, written downward ][ next chunk's rows ... )
                      end - 3(hi - lo)               end

    Returns how many entries of T were written, or -1 as write_rows."""
    T, perm, simplices = borrow(T), borrow(perm), borrow(simplices)
    for t in range(hi - 1, lo - 1, -1):
        if not _write_row(T, perm, simplices, t, end - 3 * (hi - t)):
            return -1
    return 3 * (hi - lo)


@njit(cache=True, inline="always")
def _write_row(T, perm, simplices, t, at):
    """Real slot t's vertex row (input indices) to simplices[t] and its
    neighbour row to T[at:at + 3], after reading the slot whole; False for
    a ghost (never, but never as output)."""
    a, b, c = T[slot(t, 0)], T[slot(t, 1)], T[slot(t, 2)]
    if min(a, b, c) < 0:
        return False
    e_bc, e_ca, e_ab = T[slot(t, 4)], T[slot(t, 5)], T[slot(t, 3)]  # opposite a, b, c
    simplices[u(t), 0] = perm[u(a)]
    simplices[u(t), 1] = perm[u(b)]
    simplices[u(t), 2] = perm[u(c)]
    T[u(at)] = e_bc >> 2  # the neighbour's slot, and -1 stays -1
    T[u(at + 1)] = e_ca >> 2
    T[u(at + 2)] = e_ab >> 2
    return True


@njit(cache=True, nogil=True)
def move_rows(T, src, dst, count):
    """T[dst:dst + count] = T[src:src + count], forward: for dst < src, or
    ranges apart (a part of move_rows_parallel's pieces)."""
    for j in range(count):
        T[u(dst + j)] = T[u(src + j)]


def move_rows_parallel(T, src, dst, count, workers):
    """move_rows on ``workers``: in pieces of at most ``src - dst`` entries,
    one after the other, each split over the threads.  A piece's
    destination lies below its own source and over pieces already moved,
    so its parts never overwrite what another thread still reads::

        T  [ dst ...... | piece 0 src | piece 1 src | ... )
             piece 0 dst  piece 1 dst
    """
    gap = src - dst
    start = 0
    while gap > 0 and start < count:
        piece = min(gap, count - start)
        parts = [(start + a, start + b) for a, b in workers.chunks(piece)]
        workers.map(parts, lambda c, lo, hi: move_rows(T, src + lo, dst + lo, hi - lo))
        start += piece


@njit(cache=True)
def hull_loop(T, start_ghost, perm, index_sample):
    """Counter-clockwise hull vertices (input indices) by walking the ghost
    ring from ``start_ghost``."""
    count = 0
    g = start_ghost
    while True:
        count += 1
        g = ring_ghost(T, g, 1)
        if g == start_ghost:
            break
    out = np.empty(count, dtype=index_sample.dtype)
    g = start_ghost
    for i in range(count):
        out[i] = perm[tail(T, g)]
        g = ring_ghost(T, g, 1)
    return out


@njit(cache=True, nogil=True)
def duplicates_into(gaps, perm, out, lo, hi):
    """duplicate_of in input indices: each position of [lo, hi) points to the
    first of its run of equal keys (lfqt.dc.subdivide.gap_bits); returns how
    many positions start a run."""
    r = lo
    while r > 0 and gaps[u(r)] == DUP:  # the run that lo is in
        r -= 1
    distinct = 0
    for i in range(lo, hi):
        if i == 0 or gaps[u(i)] != DUP:
            r = i
            distinct += 1
        out[u(perm[u(i)])] = perm[u(r)]
    return distinct
