"""Output of the divide and conquer, and the kernels around the pipeline:
the Morton-order gather of the input, the real triangles in input indices,
the hull loop and ``duplicate_of``.  Every kernel works on an index range,
so the pipeline can chunk it over threads.

The output is built in T's own memory, so that T and a full copy of the
result never coexist (peak memory, lfqt.dc._output):

1. ``mark_used`` and ``clear_ghosts``: one bit per real triangle's slot, in
   64-slot blocks, and each block's count.  Once the merges are done every
   used slot holds a real triangle or a ghost of the one hull ring, so the
   bits come from the merges' codes and a walk of the ring, not from a pass
   over T.  ``first[b]``, the real slots before block b, then gives a slot
   its output row with one popcount (lfqt.indexing.rank);
2. ``write_rows``: in one pass over T, the vertex rows, in input indices,
   to a new array, and each chunk of blocks' neighbour rows packed at the
   start of its own part of T.  Row k of a chunk lands at 3k to 3k + 2,
   below the slots after k, which are still to be read (at 6k + 6 on).
   With several chunks, the first is read downward and its rows packed to
   end where the second chunk's begin (``write_rows_down``), so that the
   two meet in place;
3. ``move_rows``: the later chunks' rows slide down behind them, in chunk
   order, each below what is still to move; the result keeps T's range of
   rows, and the pages around it go back to the system (lfqt.workspace).
   At 10M points on 2 threads the move cost 9.4 ms that meeting in place
   saves.
"""
import numpy as np
from numba import njit

from ..indexing import bit, borrow, popcount, prefetch, rank, u
from .layout import slot, tri
from .subdivide import DUP


# Morton order scatters the input indices: gather_points asks for the point
# AHEAD positions on before it reads it (1M: 9-17 -> 6-11 ms on a VM).  A
# random permutation, one thread: 1M 3.8 ms from 32 to 256; 10M 152 ms at
# 32, 128-131 ms from 64 to 256 (memory's latency needs more in flight).
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


BLOCK = 64  # slots per word of the bitmask of real slots (lfqt.indexing.bit)


@njit(cache=True, nogil=True)
def mark_used(codes, bits, counts, blo, bhi):
    """bits[b]: bit j set when slot 64b + j is used, for the blocks [blo,
    bhi); counts[b]: how many are.  Slots 2(p-1) and 2(p-1)+1 belong to the
    merge at split position p and are used iff ``codes[p] != DUP``
    (lfqt.dc.subdivide; T is never filled: an unused slot holds garbage and
    is not looked at).  Branch-free."""
    nslots = 2 * (codes.shape[0] - 1)
    for b in range(blo, bhi):
        word = np.uint64(0)
        for t in range(BLOCK * b, min(BLOCK * b + BLOCK, nslots)):
            used = codes[u((t >> 1) + 1)] != DUP
            word |= np.uint64(used) << np.uint64(t & (BLOCK - 1))
        bits[u(b)] = word
        counts[u(b)] = popcount(word)


@njit(cache=True)
def clear_ghosts(T, start, bits, counts):
    """Unmark the ghosts of the hull ring through ghost ``start``: after the
    last merge every used slot is a real triangle or one of them."""
    g = start
    while True:
        bits[u(g >> 6)] &= ~(np.uint64(1) << np.uint64(g & (BLOCK - 1)))
        counts[u(g >> 6)] -= 1
        g = tri(T[slot(g, 5)])
        if g == start:
            break


@njit(cache=True, nogil=True)
def write_rows(T, bits, first, perm, simplices, blo, bhi):
    """The rows of the real slots of blocks [blo, bhi): vertex rows, in input
    indices, to ``simplices``; neighbour rows (neighbour i opposite vertex i,
    -1 on the hull) packed into T from T[6 * 64 * blo] on.  Slot t is read
    whole before its rows are written, and its neighbour row lands below
    the slots still to be read (the module's step 2).  Returns how many
    entries of T were written, or -1 for a marked slot that is a ghost."""
    T, bits, first, perm, simplices = _borrowed(T, bits, first, perm, simplices)
    base = 6 * BLOCK * blo
    k = 0
    for t in range(BLOCK * blo, min(BLOCK * bhi, T.shape[0] // 6)):
        if bit(bits, t):  # a real slot
            if not _write_row(T, bits, first, perm, simplices, t, first[u(blo)] + k,
                              base + 3 * k):
                return -1
            k += 1
    return 3 * k


@njit(cache=True, nogil=True)
def write_rows_down(T, bits, first, perm, simplices, blo, bhi, end):
    """write_rows for the first of several chunks, its slots read from the
    last down and its neighbour rows packed to end at T[end], where the
    next chunk's begin (its first entry, 6 * 64 * bhi): the two meet
    without a move.  Row k of the chunk's m lands at end - 3(m - k), above
    every slot still to be read, for the m - k real slots from its own on
    are at most as many as the slots from its own to bhi::

        T  [ slots of this chunk, read downward     | next chunk's slots ... )
                         [ its rows, written downward ][ next chunk's rows ... )
                      end - 3m                       end

    Returns how many entries of T were written, or -1 as write_rows."""
    T, bits, first, perm, simplices = _borrowed(T, bits, first, perm, simplices)
    m = first[u(bhi)] - first[u(blo)]
    base = end - 3 * m
    k = m
    for t in range(min(BLOCK * bhi, T.shape[0] // 6) - 1, BLOCK * blo - 1, -1):
        if bit(bits, t):  # a real slot
            k -= 1
            if not _write_row(T, bits, first, perm, simplices, t, first[u(blo)] + k,
                              base + 3 * k):
                return -1
    return 3 * m


@njit(cache=True, inline="always")
def _borrowed(T, bits, first, perm, simplices):
    """Views for _write_row, a helper inlined into a loop, that hold no
    reference (lfqt.indexing.borrow): with the arrays themselves, each call
    paid two atomic reference counts per array (1M points, one thread: the
    whole call 166 -> 284 ms)."""
    return borrow(T), borrow(bits), borrow(first), borrow(perm), borrow(simplices)


@njit(cache=True, inline="always")
def _write_row(T, bits, first, perm, simplices, t, row, at):
    """Real slot t's vertex row (input indices) to simplices[row] and its
    neighbour row to T[at:at + 3], after reading the slot whole; False for
    a ghost off the hull ring (never, but never as output)."""
    a, b, c = T[slot(t, 0)], T[slot(t, 1)], T[slot(t, 2)]
    if min(a, b, c) < 0:
        return False
    e_bc, e_ca, e_ab = T[slot(t, 4)], T[slot(t, 5)], T[slot(t, 3)]  # opposite a, b, c
    simplices[u(row), 0] = perm[u(a)]
    simplices[u(row), 1] = perm[u(b)]
    simplices[u(row), 2] = perm[u(c)]
    T[u(at)] = _neighbor(bits, first, e_bc)
    T[u(at + 1)] = _neighbor(bits, first, e_ca)
    T[u(at + 2)] = _neighbor(bits, first, e_ab)
    return True


@njit(cache=True, inline="always")
def _neighbor(bits, first, e):
    """Output row of the triangle across half-edge twin e, -1 for a ghost."""
    w = tri(e)
    return rank(bits, first, w) if bit(bits, w) else -1


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
        g = tri(T[slot(g, 5)])
        if g == start_ghost:
            break
    out = np.empty(count, dtype=index_sample.dtype)
    g = start_ghost
    for i in range(count):
        out[i] = perm[T[slot(g, 1)]]
        g = tri(T[slot(g, 5)])
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
