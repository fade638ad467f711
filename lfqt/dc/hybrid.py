"""Paper 1's open question (sections 4.3 and 5): incremental insertion in the
lower levels of the LFQT, divide and conquer above them.

A bin (a quad-tree cell of at most ``leaf_size`` keys, lfqt.dc.bins) is
triangulated by lfqt's Bowyer–Watson inserter in Hilbert or Kd-tree order
of its own points, and its cells are written into the bin's own triangle
slots in the layout the merge reads (lfqt.dc.layout): finite cells become
triangles, infinite cells ghosts.  A bin of m distinct points owns the 2(m-1)
slots of its m-1 merges, and its triangulation has exactly 2(m-1) cells,
ghosts included (Euler), so the slots are filled exactly.  The merges above
the bins run unchanged.  A bin whose points are collinear (no cells) is
merged by the divide and conquer instead.

The inserter's infinite cell (.., INF, ..) is oriented so that a point
beyond its hull edge in place of INF makes it positive; rotated to put INF
in slot 2 it is the merge's ghost (a, b, GHOST), hull edge b -> a::

        a <------- b      hull edge b -> a (counter-clockwise around the hull)
         \\  real  /
          \\      /        ghost (a, b, GHOST) lies beyond it
"""
import time

import numpy as np
from numba import njit

from .. import orders
from ..incremental import kernel as insertion
from ..indexing import u
from ..predicates.counters import N_PREDICATE
from .layout import (GHOST, SMALL, XMAX, XMIN, YMAX, YMIN, before, edge, slot,
                     tail)
from .subdivide import run_starts

ORDERS = ("hilbert", "kdtree")


@njit(cache=True, nogil=True)
def fill_bin(C, N, mark, ids, slots, P, T, ghost_out, part):
    """Write the live cells of a 2D insertion (C, N, mark; vertex k of the
    insertion is point ids[k]) into triangle ``slots`` of T, set ghost_out of
    the hull vertices and the partition row ``part``.  Returns False when
    the cell count does not match the slots (never for a valid bin)."""
    m = C.shape[0]
    tslot = np.full(m, -1, dtype=np.int64)
    rot = np.zeros(m, dtype=np.int64)  # T index i is C index (i + rot) % 3
    k = 0
    for c in range(m):
        if mark[c] == insertion.DEAD:
            continue
        if k == slots.shape[0]:
            return False
        tslot[c] = slots[k]
        k += 1
        for i in range(3):
            if C[c, i] < 0:
                rot[c] = (i + 1) % 3
    if k != slots.shape[0]:
        return False
    for c in range(m):
        t = tslot[c]
        if t < 0:
            continue
        for i in range(3):
            v = C[c, (i + rot[c]) % 3]
            T[slot(t, i)] = GHOST if v < 0 else ids[v]
        if T[slot(t, 2)] == GHOST:  # ghost (a, b, GHOST): hull edge b -> a leaves b
            ghost_out[u(tail(T, t))] = t
    for c in range(m):
        t = tslot[c]
        if t < 0:
            continue
        for i in range(3):
            a = T[slot(t, i)]
            b = T[slot(t, (i + 1) % 3)]
            t2 = tslot[N[c, (i + 2 + rot[c]) % 3]]
            for j in range(3):
                if T[slot(t2, j)] == b and T[slot(t2, (j + 1) % 3)] == a:
                    T[slot(t, 3 + i)] = edge(t2, j)
    v0 = ids[0]
    for j in range(SMALL):
        part[j] = v0
    part[SMALL] = 0
    for k in range(1, ids.shape[0]):
        v = ids[k]
        if before(P, part[XMAX], v, 0):
            part[XMAX] = v
        if before(P, v, part[XMIN], 0):
            part[XMIN] = v
        if before(P, part[YMAX], v, 1):
            part[YMAX] = v
        if before(P, v, part[YMIN], 1):
            part[YMIN] = v
    return True


def insert_bin(state, lo, hi, order, counts, part):
    """Triangulate the bin of sorted keys [lo, hi) of ``state`` by insertion
    in ``order`` into its slots, writing its partition row into ``part``
    (shape (1, PART)).  Falls back to the divide and conquer's own merges
    for a bin of fewer than 3 distinct points or collinear ones.  Returns
    the seconds spent building the order."""
    ops = state.bin_ops(lo, hi)
    ids = run_starts(state.gaps, lo, hi)
    t_order = 0.0
    if len(ids) >= 3:
        P = np.take(state.mesh.P, ids, axis=0)
        t0 = time.perf_counter()
        perm, hints = orders.order(P, order)
        t_order = time.perf_counter() - t0
        C, N, mark, _, _, cnt, ok, _ = insertion.insert_all(P, perm, hints,
                                                             insertion.coordinate_span(P))
        if ok:
            p = ops[ops >= 0]
            slots = np.sort(np.concatenate((2 * (p - 1), 2 * (p - 1) + 1)))
            if fill_bin(C, N, mark, ids.astype(np.int64), slots, state.mesh.P, state.mesh.T,
                        state.mesh.ghost_out, part[0]):
                counts += cnt[:N_PREDICATE]
                return t_order
            live = int((mark != insertion.DEAD).sum())
            raise RuntimeError(f"bin [{lo}, {hi}): {live} cells for {len(slots)} "
                               "slots")
    state.merge(0, len(ops), counts, part, 0, part, ops=ops)
    return t_order
