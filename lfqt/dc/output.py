"""Output of the divide and conquer, and the kernels around the pipeline:
the Morton-order gather of the input, the real triangles in input indices,
the hull loop and ``duplicate_of``.  Every kernel works on an index range,
so the pipeline can chunk it over threads.

The output is built in T's own memory, so that T and a full copy of the
result never coexist (peak memory, lfqt.dc._output):

1. ``mark_real``: one bit per real (used, non-ghost) slot, in 64-slot blocks,
   and each block's count; ``first[b]``, the real slots before block b, then
   gives a slot its output row with one popcount (``row``);
2. ``write_simplices``: the vertex rows, in input indices, to a new array;
3. ``pack_neighbors``: each chunk of blocks writes its neighbour rows at the
   start of its own part of T.  Row k of a chunk lands at 3k, below the
   twins of slot k or later that are still to be read (at 6k + 3 or more);
4. ``move_rows``: the chunks' rows slide down to their final place, in
   chunk order, each below what is still to move; T is then shrunk to them.
"""
import numpy as np
from numba import njit

from ..indexing import popcount, u
from .layout import slot, tri
from .subdivide import DUP


@njit(cache=True, nogil=True)
def gather_points(x, y, perm, scale, P, lo, hi):
    """P[i] = (x, y)[perm[i]] * scale for i in [lo, hi): coordinates in
    Morton order as float64 (an exact power-of-two scale); x and y of a point
    share a cache line."""
    for i in range(lo, hi):
        j = u(perm[u(i)])
        P[u(i), 0] = np.float64(x[j]) * scale
        P[u(i), 1] = np.float64(y[j]) * scale


BLOCK = 64  # slots per word of the bitmask of real slots


@njit(cache=True, nogil=True)
def mark_real(T, codes, bits, counts, blo, bhi):
    """bits[b]: bit j set when slot 64b + j is a real triangle, for the blocks
    [blo, bhi); counts[b]: how many are.  Slots 2(p-1) and 2(p-1)+1 belong to
    the merge at split position p and are used iff ``codes[p] != DUP``
    (lfqt.dc.subdivide; T is never filled: an unused slot holds garbage and
    is not looked at).
    Branch-free: the short-circuit form compiled to a loop five times
    slower."""
    nslots = T.shape[0] // 6
    for b in range(blo, bhi):
        word = np.uint64(0)
        for t in range(BLOCK * b, min(BLOCK * b + BLOCK, nslots)):
            p = (t >> 1) + 1
            real = ((codes[u(p)] != DUP) & (T[slot(t, 0)] >= 0) & (T[slot(t, 1)] >= 0)
                    & (T[slot(t, 2)] >= 0))
            word |= np.uint64(real) << np.uint64(t & (BLOCK - 1))
        bits[u(b)] = word
        counts[u(b)] = popcount(word)


@njit(cache=True, inline="always")
def is_real(bits, t):
    return (bits[u(t >> 6)] >> np.uint64(t & (BLOCK - 1))) & np.uint64(1)


@njit(cache=True, inline="always")
def row(bits, first, t):
    """Output row of the real slot t: the real slots before it."""
    below = bits[u(t >> 6)] & ((np.uint64(1) << np.uint64(t & (BLOCK - 1))) - np.uint64(1))
    return first[u(t >> 6)] + popcount(below)


@njit(cache=True, nogil=True)
def write_simplices(T, bits, first, perm, simplices, blo, bhi):
    """The vertex rows, in input indices, of the real slots of blocks
    [blo, bhi)."""
    k = first[u(blo)]
    for t in range(BLOCK * blo, min(BLOCK * bhi, T.shape[0] // 6)):
        if is_real(bits, t):
            for i in range(3):
                simplices[u(k), i] = perm[u(T[slot(t, i)])]
            k += 1


@njit(cache=True, nogil=True)
def pack_neighbors(T, bits, first, blo, bhi):
    """The neighbour rows of the real slots of blocks [blo, bhi), packed from
    T[6 * 64 * blo] on (see the module's step 3); neighbour i is opposite
    vertex i, -1 on the hull.  Returns how many entries were written."""
    base = 6 * BLOCK * blo
    k = 0
    for t in range(BLOCK * blo, min(BLOCK * bhi, T.shape[0] // 6)):
        if is_real(bits, t):
            for i in range(3):
                w = tri(T[slot(t, 3 + (i + 1) % 3)])  # edge opposite i starts at i + 1
                T[u(base + 3 * k + i)] = row(bits, first, w) if is_real(bits, w) else -1
            k += 1
    return 3 * k


@njit(cache=True, nogil=True)
def move_rows(T, src, dst, count):
    """T[dst:dst + count] = T[src:src + count] for dst <= src (forward)."""
    for j in range(count):
        T[u(dst + j)] = T[u(src + j)]


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
