"""Output of the divide and conquer, and the kernels around the pipeline:
the Morton-order gather of the input, the real triangles in input indices,
the hull loop and ``duplicate_of``.  Every kernel works on an index range,
so the pipeline can chunk it over threads.

The output is written over T, so that the result costs no memory beyond
T's and T and a copy of the result never coexist (peak memory,
lfqt.dc._memory):

1. ``fill_holes``: once the merges are done every used slot holds a real
   triangle or a ghost of the one hull ring, and the slots of the
   duplicates' merges are unused, so the m real triangles fit in the first
   m slots: each one above moves into a ghost's or an unused slot below,
   found from the ring and the merges' codes, not from a pass over T.  A
   slot is then its output row, and a twin, shifted, its neighbour's, with
   no rank from a bitmap of the real slots and a popcount
   (docs/performance.md, "output without ranks");
2. ``rows_high``: the upper half of the slots, read from the last down,
   put their neighbour rows in place, ``T[3m + 3t]``, which lies on slots
   already read, and their vertex rows (input indices) in a buffer, in P's
   memory, which the merges no longer need;
3. ``rows_low``: the lower half, read from the first up, put their vertex
   rows in place, ``T[3t]``, over slots already read, their neighbour rows
   at ``T[3m + 3t]``, over slots that step 2 read, and two of the buffered
   upper vertex rows, whose place is slot t's own entries, there.  Then
   ``simplices`` is ``T[0:3m]`` and ``neighbors`` ``T[3m:6m]``::

        T after 1  [ real slots 0 ......... m/2 ......... m | ghosts ]
        after 2    [ lower slots  | upper, read | upper neighbour rows ]
        after 3    [ vertex rows, lower | upper | neighbour rows, all   ]
                   0                           3m                      6m

   Steps 2 and 3 each land their rows on slots read before, so on several
   threads they run in pieces that grow as they go (write_rows).
"""
import numpy as np
from numba import njit

from ..indexing import borrow, prefetch, u
from ..workers import MIN_CHUNK
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
def rows_high(T, perm, buf, m, lo, hi):
    """Step 2 for the real slots [lo, hi) of the upper half (lo >= m // 2),
    read from the last down: each neighbour row (neighbour i opposite
    vertex i, -1 on the hull) to its place T[3m + 3t], over slots already
    read, and each vertex row, in input indices, to buf[3(t - m // 2)].
    Slot t is read whole before its rows are written.  Returns 0, or -1
    for a ghost (never, but never as output)."""
    T, perm, buf = borrow(T), borrow(perm), borrow(buf)
    half = m // 2
    for t in range(hi - 1, lo - 1, -1):
        a, b, c = T[slot(t, 0)], T[slot(t, 1)], T[slot(t, 2)]
        if min(a, b, c) < 0:
            return -1
        _put(T, 3 * (m + t), T[slot(t, 4)] >> 2, T[slot(t, 5)] >> 2, T[slot(t, 3)] >> 2)
        _put(buf, 3 * (t - half), perm[u(a)], perm[u(b)], perm[u(c)])
    return 0


@njit(cache=True, nogil=True)
def rows_low(T, perm, buf, m, lo, hi):
    """Steps 3 and 4 for the real slots [lo, hi) of the lower half (hi <=
    m // 2), read from the first up: each vertex row to its place T[3t],
    over slots already read, each neighbour row to T[3m + 3t], over slots
    that rows_high read, and the upper vertex rows j = 2t - m // 2 and
    j + 1 of ``buf``, whose places 3(m // 2 + j) are slot t's own entries,
    there once it is read (while its lines are in the cache).  Returns 0,
    or -1 for a ghost."""
    T, perm, buf = borrow(T), borrow(perm), borrow(buf)
    half = m // 2
    for t in range(lo, hi):
        a, b, c = T[slot(t, 0)], T[slot(t, 1)], T[slot(t, 2)]
        if min(a, b, c) < 0:
            return -1
        _put(T, 3 * (m + t), T[slot(t, 4)] >> 2, T[slot(t, 5)] >> 2, T[slot(t, 3)] >> 2)
        for j in range(max(2 * t - half, 0), 2 * t - half + 2):
            _put(T, 3 * (half + j), buf[u(3 * j)], buf[u(3 * j + 1)], buf[u(3 * j + 2)])
        _put(T, 3 * t, perm[u(a)], perm[u(b)], perm[u(c)])
    return 0


@njit(cache=True, inline="always")
def _put(dst, at, x, y, z):
    """dst[at:at + 3] = x, y, z (the values read before: they may come from
    the slot the row lands on)."""
    dst[u(at)] = x
    dst[u(at + 1)] = y
    dst[u(at + 2)] = z


def write_rows(T, perm, buf, m, workers, first=None):
    """Steps 2 and 3 of the module's docstring: the m packed real slots of T
    become its vertex rows T[0:3m] and its neighbour rows T[3m:6m], with
    ``buf`` (at least 3(m - m // 2) entries of T's dtype) holding the upper
    half's vertex rows meanwhile.  On several threads each step runs in
    pieces whose rows land only on slots read before the piece (rows_high,
    rows_low; the first piece of each, ``first`` rows (default MIN_CHUNK),
    on one thread, in order).  Returns False for a ghost among the slots."""
    first = first or MIN_CHUNK
    half = m // 2
    steps = ((_pieces(half, m, workers.threads, True, first),
              lambda c, a, b: rows_high(T, perm, buf, m, a, b)),
             (_pieces(0, half, workers.threads, False, first),
              lambda c, a, b: rows_low(T, perm, buf, m, a, b)))
    for pieces, rows in steps:
        for k, (lo, hi) in enumerate(pieces):
            parts = [(lo, hi)] if k == 0 else [
                (lo + a, lo + b) for a, b in workers.chunks(hi - lo, min_chunk=MIN_CHUNK)]
            if min(workers.map(parts, rows)) < 0:
                return False
    if m % 2:  # the last upper vertex row, on slot m // 2, which rows_high read
        T[3 * m - 3:3 * m] = buf[3 * half:3 * half + 3]
    return True


def _pieces(lo, hi, threads, down, first):
    """The pieces of [lo, hi) for rows_high (``down``: from hi, each piece
    [a, b) with a >= 2b - m, where m = hi, its rows landing at 3m + 3t >= 6b)
    or rows_low (from lo, each [a, b) with b <= 2a, its rows landing below
    6a): one piece on one thread; else a first one of ``first`` rows, then
    pieces as long as all before them."""
    if hi <= lo:
        return []
    if threads == 1:
        return [(lo, hi)]
    out = []
    if down:
        b = max(lo, hi - first)
        out.append((b, hi))
        while b > lo:
            a = max(lo, 2 * b - hi)
            out.append((a, b))
            b = a
    else:
        a = min(hi, lo + first)
        out.append((lo, a))
        while a < hi:
            b = min(hi, 2 * a)
            out.append((a, b))
            a = b
    return out


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
