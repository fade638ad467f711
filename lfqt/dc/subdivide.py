"""Phase 2 of the divide and conquer: the subdivision (fqDel 3.2, Algorithm 1).

The quad-tree over sorted keys is a property of adjacent keys: ``gaps[i]``
(``gap_bits``) is the highest bit in which keys i-1 and i differ, the level
of the split between them, or ``DUP`` when they are equal.  One byte per
point carries all that the later phases need of the keys, so the keys are
freed once it and the parallel top levels are computed.

The subdivision writes the quad-tree as a post-order list of ``ops``:
``-(v+1)`` pushes the single vertex ``v``; ``p >= 1`` merges the two
partitions on top of the stack, splitting at sorted position ``p``, with
the split's code in ``codes[p]``.  For the LFQT ``codes`` is ``gaps``
(``code < 128`` is the Morton bit, odd: x-split); the alternating ablation
(paper section 4.3) writes its own, ``ALT_X``/``ALT_Y`` for Triangle-style
cuts, at the positions 1 ... distinct - 1 it numbers its merges with.
A position p >= 1 owns the triangle slots of a merge iff ``codes[p] != DUP``.
"""
import numpy as np
from numba import njit
from numba.cpython.unsafe.numbers import leading_zeros

from ..indexing import random_index, range_seed, u
from .layout import STACK, before, less

ALT_X = 128
ALT_Y = 129
DUP = 255  # gaps[i]: key i equals key i - 1 (position 0 always starts a run)
_ONE = np.uint64(1)
_ZERO = np.uint64(0)


@njit(cache=True, inline="always")
def _bsr(x):
    """Index of the highest set bit of a non-zero uint64 (one lzcnt)."""
    return 63 - leading_zeros(x)


@njit(cache=True, inline="always")
def _diff_bit(hi_a, lo_a, hi_b, lo_b):
    """Highest bit in which two 128-bit keys differ, or -1 when equal.  Keys
    are passed as scalars: array arguments on a hot path cost numba atomic
    reference counting.  The low words are looked at only when the high
    words are equal: sorted low words exist only inside runs of equal high
    words (lfqt.radix.sort_keys128), and so does every caller's ``_has_bit``
    below bit 64."""
    d = hi_a ^ hi_b
    if d != 0:
        return 64 + _bsr(d)
    d = lo_a ^ lo_b
    if d != 0:
        return _bsr(d)
    return -1


@njit(cache=True, inline="always")
def _has_bit(hi, lo, bit):
    if bit >= 64:
        return (hi >> np.uint64(bit - 64)) & _ONE
    return (lo >> np.uint64(bit)) & _ONE


@njit(cache=True, nogil=True)
def gap_bits(khi, klo, wide, gaps, lo, hi):
    """gaps[i] for i in [lo, hi): the highest bit in which sorted keys i - 1
    and i differ, or DUP when they are equal (and for i = 0).  Returns
    whether a key in [lo, hi) repeats the one before it."""
    copies = False
    for i in range(lo, hi):
        if i == 0:
            gaps[0] = DUP
            continue
        if wide:
            bit = _diff_bit(khi[u(i - 1)], klo[u(i - 1)], khi[u(i)], klo[u(i)])
        else:
            bit = _diff_bit(_ZERO, klo[u(i - 1)], _ZERO, klo[u(i)])
        copies |= bit < 0
        gaps[u(i)] = DUP if bit < 0 else bit
    return copies


def run_starts(gaps, lo, hi):
    """The positions in [lo, hi) that start a run of equal keys, the first
    one always: the distinct vertices of the range."""
    starts = gaps[lo:hi] != DUP
    if hi > lo:
        starts[0] = True
    return lo + np.flatnonzero(starts)


@njit(cache=True, nogil=True)
def subdivide_lfqt(gaps, lo, hi, ops, nops):
    """Algorithm 1 of fqDel as one sweep: append the post-order ops of the
    quad-tree over sorted positions [lo, hi) to ``ops`` starting at ``nops``;
    returns the new op count.  Runs of equal keys are one vertex, their
    first position.

    A node splits at the gap where its first and last keys first differ,
    and that gap's highest differing bit is the largest of all gaps in the
    node, so the quad-tree is the Cartesian tree of the gaps.  Its
    post-order falls out of a stack of open splits, in O(n) and without
    Algorithm 1's binary search per node; the ops are the same as the
    recursive form's.
    """
    if hi <= lo:
        return nops
    s_split = np.empty(STACK + 1, dtype=np.int64)
    s_bit = np.empty(STACK + 1, dtype=np.int64)
    # A sentinel that no bit exceeds spares the pops a bound check, and
    # unsigned indices (lfqt.indexing.u) numba's wraparound of negative ones
    # (docs/performance.md, "subdivide's stack").
    s_bit[0] = DUP
    top = 0  # open splits from 1 up, bits strictly decreasing upwards
    ops[u(nops)] = -(lo + 1)
    nops += 1
    for i in range(lo + 1, hi):
        bit = np.int64(gaps[u(i)])
        if bit == DUP:
            continue
        while s_bit[u(top)] < bit:
            ops[u(nops)] = s_split[u(top)]
            nops += 1
            top -= 1
        top += 1
        s_split[u(top)] = i
        s_bit[u(top)] = bit
        ops[u(nops)] = -(i + 1)
        nops += 1
    while top > 0:
        ops[u(nops)] = s_split[top]
        nops += 1
        top -= 1
    return nops


@njit(cache=True, nogil=True)
def subdivide_next(gaps, i, hi, ops, stack, top):
    """subdivide_lfqt's sweep in pieces, for merges that run each piece of
    ops as it comes (lfqt.dc.state.State.merge_range) instead of holding
    all 2n of them: the ops of positions from ``i`` on, up to ``hi``, written
    from ops[0] while a position's pops and pushes still fit.  ``stack``
    (2, STACK + 1) holds the open splits (row 0) and their bits (row 1),
    ``top`` their count; a sweep starts at its first position with
    ``top = -1``.  Returns (ops written, the next position, top): no ops
    once the sweep is done."""
    room = ops.shape[0] - STACK - 2  # a position's pops and two pushes fit past it
    nops = 0
    if top < 0:  # the first position: its vertex, over the sentinel
        stack[1, 0] = DUP
        top = 0
        ops[0] = -(i + 1)
        nops = 1
        i += 1
    while i < hi and nops <= room:
        bit = np.int64(gaps[u(i)])
        if bit != DUP:
            while stack[1, u(top)] < bit:
                ops[u(nops)] = stack[0, u(top)]
                nops += 1
                top -= 1
            top += 1
            stack[0, u(top)] = i
            stack[1, u(top)] = bit
            ops[u(nops)] = -(i + 1)
            nops += 1
        i += 1
    if i >= hi and nops <= room:  # the splits left open close the range
        while top > 0:
            ops[u(nops)] = stack[0, u(top)]
            nops += 1
            top -= 1
    return nops, i, top


@njit(cache=True)
def subdivide_top(khi, klo, wide, n, bin_size):
    """The upper levels of the quad-tree, split until a node holds at most
    ``bin_size`` keys (or only equal keys): returns the post-order nodes as
    (lo, hi, split, bit, left, right) rows; split = -1 marks a bin."""
    # Inner nodes hold more than bin_size keys and are disjoint per depth
    # (at most 128 levels), which bounds the node count.
    cap = 2 * 130 * (n // max(bin_size, 1) + 1) + 8
    nodes = np.empty((cap, 6), dtype=np.int64)
    count = 0
    s_lo = np.empty(STACK, dtype=np.int64)
    s_hi = np.empty(STACK, dtype=np.int64)
    s_split = np.empty(STACK, dtype=np.int64)
    s_bit = np.empty(STACK, dtype=np.int64)
    s_state = np.empty(STACK, dtype=np.int64)
    s_left = np.empty(STACK, dtype=np.int64)
    top = 0
    s_lo[0] = 0
    s_hi[0] = n
    s_state[0] = 0
    last = -1
    while top >= 0:
        a = s_lo[top]
        b = s_hi[top]
        st = s_state[top]
        if st == 0:
            if wide:
                bit = _diff_bit(khi[u(a)], klo[u(a)], khi[u(b - 1)], klo[u(b - 1)])
            else:
                bit = _diff_bit(_ZERO, klo[u(a)], _ZERO, klo[u(b - 1)])
            if b - a <= bin_size or bit < 0:
                nodes[count, 0] = a
                nodes[count, 1] = b
                nodes[count, 2] = -1
                nodes[count, 3] = -1
                nodes[count, 4] = -1
                nodes[count, 5] = -1
                last = count
                count += 1
                top -= 1
                continue
            left = a
            right = b - 1
            while right - left > 1:
                mid = (left + right) >> 1
                if _has_bit(khi[u(mid)] if wide else _ZERO, klo[u(mid)], bit):
                    right = mid
                else:
                    left = mid
            s_split[top] = right
            s_bit[top] = bit
            s_state[top] = 1
            top += 1
            s_lo[top] = a
            s_hi[top] = right
            s_state[top] = 0
        elif st == 1:
            s_left[top] = last
            s_state[top] = 2
            top += 1
            s_lo[top] = s_split[top - 1]
            s_hi[top] = b
            s_state[top] = 0
        else:
            nodes[count, 0] = a
            nodes[count, 1] = b
            nodes[count, 2] = s_split[top]
            nodes[count, 3] = s_bit[top]
            nodes[count, 4] = s_left[top]
            nodes[count, 5] = last
            last = count
            count += 1
            top -= 1
    return nodes[:count].copy()


@njit(cache=True)
def _select(ids, lo, hi, k, P, axis):
    """Partition ids[lo:hi] so that ids[k] is in sorted position (nth_element).

    The pivot is the median of the first, middle and last elements, which
    suits points in Morton order, unless the last round kept more than 3/4
    of the range: then it is a pseudo-random element (Triangle's
    vertexmedian always picks one at random).  Without that guard the
    alternating subdivision of 1M Circle points, which defeats the median
    of three, took 2.1 s against 0.012 s at 100k."""
    state = range_seed(lo, hi)
    unbalanced = False
    while hi - lo > 1:
        if unbalanced:
            state, r = random_index(state, lo, hi)
            b = ids[r]
        else:
            mid = (lo + hi) >> 1
            a, b, c = ids[lo], ids[mid], ids[hi - 1]
            if before(P, b, a, axis):
                a, b = b, a
            if before(P, c, b, axis):
                b, c = c, b
                if before(P, b, a, axis):
                    a, b = b, a
        px = P[b, 0]
        py = P[b, 1]
        i = lo
        j = hi - 1
        while i <= j:
            while less(P[ids[i], 0], P[ids[i], 1], px, py, axis):
                i += 1
            while less(px, py, P[ids[j], 0], P[ids[j], 1], axis):
                j -= 1
            if i <= j:
                t = ids[i]
                ids[i] = ids[j]
                ids[j] = t
                i += 1
                j -= 1
        span = hi - lo
        if k <= j:
            hi = j + 1
        elif k >= i:
            lo = i
        else:
            return
        unbalanced = 4 * (hi - lo) > 3 * span


@njit(cache=True)
def subdivide_alternating(ids, P, ops, codes):
    """Triangle's alternating median cuts over distinct vertices ``ids``:
    fill ``ops`` in post-order and return their count.  A merge is numbered
    by its cut's index into ``ids`` (1 ... len(ids) - 1), with its axis in
    ``codes``."""
    n = ids.shape[0]
    _select(ids, 0, n, n >> 1, P, 0)
    s_lo = np.empty(STACK, dtype=np.int64)
    s_hi = np.empty(STACK, dtype=np.int64)
    s_axis = np.empty(STACK, dtype=np.int64)
    s_state = np.empty(STACK, dtype=np.int64)
    top = 0
    s_lo[0] = 0
    s_hi[0] = n
    s_axis[0] = 0
    s_state[0] = 0
    nops = 0
    while top >= 0:
        a = s_lo[top]
        b = s_hi[top]
        st = s_state[top]
        if b - a == 1:
            ops[nops] = -(ids[a] + 1)
            nops += 1
            top -= 1
            continue
        mid = a + ((b - a) >> 1)
        child_axis = 1 - s_axis[top]
        if st == 0:
            # Each half is re-cut along the other axis before it is divided.
            _select(ids, a, mid, a + ((mid - a) >> 1), P, child_axis)
            _select(ids, mid, b, mid + ((b - mid) >> 1), P, child_axis)
            s_state[top] = 1
            top += 1
            s_lo[top], s_hi[top], s_axis[top], s_state[top] = a, mid, child_axis, 0
        elif st == 1:
            s_state[top] = 2
            top += 1
            s_lo[top], s_hi[top], s_axis[top], s_state[top] = mid, b, child_axis, 0
        else:
            ops[nops] = mid
            codes[mid] = ALT_X + s_axis[top]
            nops += 1
            top -= 1
    return nops
