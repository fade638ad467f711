"""Output of the divide and conquer, and the kernels around the pipeline:
the Morton-order gather of the input, numbering and writing the
real triangles in input indices, the hull loop and ``duplicate_of``.  Every
kernel works on an index range, so the pipeline can chunk it over threads.
"""
import numpy as np
from numba import njit

from ..indexing import u
from .layout import slot, tri


@njit(cache=True, nogil=True)
def gather_points(x, y, perm, scale, P, lo, hi):
    """P[i] = (x, y)[perm[i]] * scale for i in [lo, hi): coordinates in
    Morton order as float64 (an exact power-of-two scale); x and y of a point
    share a cache line."""
    for i in range(lo, hi):
        j = u(perm[u(i)])
        P[u(i), 0] = np.float64(x[j]) * scale
        P[u(i), 1] = np.float64(y[j]) * scale


@njit(cache=True, nogil=True)
def number_real(T, split, newid, lo, hi):
    """Ids 0, 1, ... for the real (non-ghost, used) triangles of slots
    [lo, hi), -1 for the others; returns how many are real.  Slots 2(p-1)
    and 2(p-1)+1 belong to the merge at split position p, and are used iff
    ``split[p] == p`` (T is never filled: an unused slot holds garbage and
    is not looked at).  Branch-free: the short-circuit form compiled to a
    loop five times slower."""
    m = 0
    for t in range(lo, hi):
        p = (t >> 1) + 1
        real = ((split[u(p)] == p) & (T[slot(t, 0)] >= 0) & (T[slot(t, 1)] >= 0)
                & (T[slot(t, 2)] >= 0))
        newid[u(t)] = m if real else -1
        m += real
    return m


@njit(cache=True, nogil=True)
def offset_ids(newid, lo, hi, offset):
    """Add a chunk's output offset to its numbered triangles."""
    for t in range(lo, hi):
        k = newid[u(t)]
        if k >= 0:
            newid[u(t)] = k + offset


@njit(cache=True, nogil=True)
def write_real(T, newid, perm, simplices, neighbors, lo, hi):
    """Rows of the real triangles of slots [lo, hi) in input indices;
    neighbour i is opposite vertex i, -1 on the hull."""
    for t in range(lo, hi):
        k = newid[u(t)]
        if k < 0:
            continue
        for i in range(3):
            simplices[u(k), i] = perm[u(T[slot(t, i)])]
            # edge opposite vertex i starts at vertex i+1
            neighbors[u(k), i] = newid[tri(T[slot(t, 3 + (i + 1) % 3)])]


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
def duplicates_into(rep, perm, out, lo, hi):
    """duplicate_of in input indices from representatives in sorted order;
    returns how many positions of [lo, hi) represent themselves."""
    distinct = 0
    for i in range(lo, hi):
        r = rep[u(i)]
        out[u(perm[u(i)])] = perm[u(r)]
        distinct += r == i
    return distinct
