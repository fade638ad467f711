"""Dwyer-style divide and conquer on the LFQT (fqDel 3.2, 3.3).

Data layout (Triangle's, in one flat int array ``T``): triangle ``t`` owns
the half-edges ``3t + i`` (i = 0, 1, 2) running from its vertex ``T[6t + i]``
to vertex ``T[6t + (i+1)%3]``; ``T[6t + 3 + i]`` is the twin half-edge.
Vertices and neighbours of a triangle share a cache line, which halves the
misses of the pointer chasing in a merge.  Vertex ids are positions in Morton order.  The convex
hull is wrapped in *ghost* triangles ``(a, b, GHOST)`` (hull edge ``b -> a``),
always stored with the ghost vertex in slot 2, so every partition is a closed
surface and a Guibas–Stolfi merge is nothing but:

* a splice of the two ghost rings along the lower common tangent (two new
  ghosts ``A`` above it and ``B`` below it), and
* flips: deleting a non-Delaunay edge of either side flips it with its ghost,
  and adding a cross edge flips ``A`` with the neighbouring ghost.

The merge at split position ``p`` owns triangle slots ``2(p-1)`` and
``2(p-1)+1``, so slot ids depend only on the input, never on scheduling.

Phase 2 (subdivide) writes the quad-tree as a post-order list of ``ops``:
``-(v+1)`` pushes the single vertex ``v``; ``(p << 8) | code`` merges the two
partitions on top of the stack.  ``code < 128`` is the Morton bit of an LFQT
split (odd: x-split); ``ALT_X``/``ALT_Y`` are Triangle-style alternating cuts.
"""

import numpy as np
from numba import njit
from numba.cpython.unsafe.numbers import leading_zeros

from .indexing import div3, u
from .predicates import (C_INCIRCLE, C_INCIRCLE_S1, C_INCIRCLE_S2, C_ORIENT, C_ORIENT_S1,
                         C_ORIENT_S2, CCW_A, ICC_A, binade, incircle_staged, level_bounds,
                         orient2d_staged)

GHOST = -1
UNUSED = -2
ALT_X = 128
ALT_Y = 129
XMAX, XMIN, YMAX, YMIN = 0, 1, 2, 3
_STACK = 160
_ONE = np.uint64(1)
_ZERO = np.uint64(0)


# --------------------------------------------------------------------------
# Phase 2: subdivision


@njit(cache=True, inline="always")
def _bsr(x):
    """Index of the highest set bit of a non-zero uint64 (one lzcnt)."""
    return 63 - leading_zeros(x)


@njit(cache=True, inline="always")
def _diff_bit(hi_a, lo_a, hi_b, lo_b):
    """Highest bit in which two 128-bit keys differ, or -1 when equal.  Keys
    are passed as scalars: array arguments on a hot path cost numba atomic
    reference counting."""
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
def subdivide_lfqt(khi, klo, wide, lo, hi, ops, nops, rep):
    """Algorithm 1 of fqDel as one sweep: append the post-order ops of the
    quad-tree over sorted keys [lo, hi) to ``ops`` starting at ``nops``.
    Runs of equal keys become one vertex; ``rep[i]`` is set to the sorted
    position that represents position i.  Returns the new op count.

    A node splits at the gap where its first and last keys first differ,
    and that gap's highest differing bit is the largest of all gaps in the
    node, so the quad-tree is the Cartesian tree of the adjacent keys'
    differing bits.  Its post-order falls out of a stack of open splits, in
    O(n) and without Algorithm 1's binary search per node; the ops are the
    same as the recursive form's.
    """
    if hi <= lo:
        return nops
    s_split = np.empty(_STACK, dtype=np.int64)
    s_bit = np.empty(_STACK, dtype=np.int64)
    top = -1  # open splits, bits strictly decreasing upwards
    run = lo
    rep[u(lo)] = lo
    ops[u(nops)] = -(lo + 1)
    nops += 1
    for i in range(lo + 1, hi):
        if wide:
            bit = _diff_bit(khi[u(i - 1)], klo[u(i - 1)], khi[u(i)], klo[u(i)])
        else:
            bit = _diff_bit(_ZERO, klo[u(i - 1)], _ZERO, klo[u(i)])
        if bit < 0:
            rep[u(i)] = run
            continue
        while top >= 0 and s_bit[top] < bit:
            ops[u(nops)] = (s_split[top] << 8) | s_bit[top]
            nops += 1
            top -= 1
        top += 1
        s_split[top] = i
        s_bit[top] = bit
        run = i
        rep[u(i)] = i
        ops[u(nops)] = -(i + 1)
        nops += 1
    while top >= 0:
        ops[u(nops)] = (s_split[top] << 8) | s_bit[top]
        nops += 1
        top -= 1
    return nops


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
    s_lo = np.empty(_STACK, dtype=np.int64)
    s_hi = np.empty(_STACK, dtype=np.int64)
    s_split = np.empty(_STACK, dtype=np.int64)
    s_bit = np.empty(_STACK, dtype=np.int64)
    s_state = np.empty(_STACK, dtype=np.int64)
    s_left = np.empty(_STACK, dtype=np.int64)
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


@njit(cache=True, inline="always")
def _less(ax, ay, bx, by, axis):
    """Total order of distinct points: (x, y) for axis 0, (y, -x) for axis 1."""
    if axis == 0:
        return ax < bx or (ax == bx and ay < by)
    return ay < by or (ay == by and ax > bx)


@njit(cache=True)
def _select(ids, lo, hi, k, P, axis):
    """Partition ids[lo:hi] so that ids[k] is in sorted position (nth_element)."""
    while hi - lo > 1:
        mid = (lo + hi) >> 1
        # median of three as pivot
        a, b, c = ids[lo], ids[mid], ids[hi - 1]
        if _less(P[b, 0], P[b, 1], P[a, 0], P[a, 1], axis):
            a, b = b, a
        if _less(P[c, 0], P[c, 1], P[b, 0], P[b, 1], axis):
            b, c = c, b
            if _less(P[b, 0], P[b, 1], P[a, 0], P[a, 1], axis):
                a, b = b, a
        px = P[b, 0]
        py = P[b, 1]
        i = lo
        j = hi - 1
        while i <= j:
            while _less(P[ids[i], 0], P[ids[i], 1], px, py, axis):
                i += 1
            while _less(px, py, P[ids[j], 0], P[ids[j], 1], axis):
                j -= 1
            if i <= j:
                t = ids[i]
                ids[i] = ids[j]
                ids[j] = t
                i += 1
                j -= 1
        if k <= j:
            hi = j + 1
        elif k >= i:
            lo = i
        else:
            return


@njit(cache=True)
def subdivide_alternating(ids, P, ops):
    """Triangle's alternating median cuts over distinct vertices ``ids``:
    fill ``ops`` in post-order and return their count."""
    n = ids.shape[0]
    _select(ids, 0, n, n >> 1, P, 0)
    s_lo = np.empty(_STACK, dtype=np.int64)
    s_hi = np.empty(_STACK, dtype=np.int64)
    s_axis = np.empty(_STACK, dtype=np.int64)
    s_state = np.empty(_STACK, dtype=np.int64)
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
            ops[nops] = (mid << 8) | (ALT_X + s_axis[top])
            nops += 1
            top -= 1
    return nops


# --------------------------------------------------------------------------
# Phase 3: merge


@njit(cache=True, inline="always")
def _slot(t, i):
    """Index in T of entry i of triangle t (0-2 vertices, 3-5 twins),
    unsigned (see lfqt.indexing)."""
    return np.uint64(6 * t + i)


@njit(cache=True, inline="always")
def _next(e):
    return e - 2 if np.uint64(e) % np.uint64(3) == np.uint64(2) else e + 1


@njit(cache=True, inline="always")
def _prev(e):
    return e + 2 if np.uint64(e) % np.uint64(3) == np.uint64(0) else e - 1


@njit(cache=True, inline="always")
def _vidx(e):
    """Index in T of the origin vertex of half-edge e (3t + i -> 6t + i).
    The merge indexes T through scalar helpers: helpers taking the array
    itself cost numba an atomic reference-count update per call."""
    u = np.uint64(e)
    return u + np.uint64(3) * (u // np.uint64(3))


@njit(cache=True, inline="always")
def _hidx(e):
    """Index in T of the twin of half-edge e."""
    u = np.uint64(e)
    return u + np.uint64(3) * (u // np.uint64(3)) + np.uint64(3)


@njit(cache=True, nogil=True)
def run_ops(ops, op_lo, op_hi, P, T, ghost_out, fmt, level_filter, counters,
            in_ext, in_single, n_in, out_ext, out_single):
    """Execute ops[op_lo:op_hi] on a partition stack that starts with the
    n_in partitions in_ext/in_single (a top merge pushes its two finished
    children); the partitions left on the stack (one for a whole subtree)
    are written to out_ext/out_single and their number returned.

    A merge joins the partitions ext[top-1] (left/lower) and ext[top]
    (right/upper) into ext[top-1].  ``fmt`` = (coord_bits, exp_bits,
    mant_bits, emin, scale_exp) of the input format, for the level-dependent
    bounds.  The merge is written inline in this loop on purpose: passing the
    arrays to a helper per merge or per predicate costs numba an atomic
    reference-count update each time, a third of the run time.
    """
    ext = np.empty((_STACK, 4), dtype=np.int64)
    single = np.empty(_STACK, dtype=np.bool_)
    n_orient = 0  # calls
    s_orient = 0  # sum of deciding stages (0, 1, 2)
    s2_orient = 0  # calls decided by the exact stage
    n_incircle = 0
    s_incircle = 0
    s2_incircle = 0
    top = -1
    for i in range(n_in):
        top += 1
        for j in range(4):
            ext[top, j] = in_ext[i, j]
        single[top] = in_single[i]
    for k in range(op_lo, op_hi):
        op = ops[k]
        if op < 0:
            v = -op - 1
            top += 1
            ext[top, 0] = v
            ext[top, 1] = v
            ext[top, 2] = v
            ext[top, 3] = v
            single[top] = True
        else:
            slot = op >> 8
            code = op & 255
            lt = top - 1
            rt = top
            if code >= ALT_X:
                x_split = code == ALT_X
                ccwb = CCW_A
                iccb = ICC_A
            else:
                x_split = (code & 1) == 1
                if level_filter:
                    probe = ext[lt, XMIN]
                    ex = binade(P[u(probe), 0], fmt[4], fmt[3])
                    ey = binade(P[u(probe), 1], fmt[4], fmt[3])
                    ccwb, iccb = level_bounds(code, fmt[0], fmt[1], fmt[2], ex, ey)
                else:
                    ccwb = CCW_A
                    iccb = ICC_A
            if x_split:
                l = ext[lt, XMAX]
                r = ext[rt, XMIN]
            else:
                l = ext[lt, YMAX]
                r = ext[rt, YMIN]
            l_single = single[lt]
            r_single = single[rt]

            # Lower common tangent.  gl = (l, cw(l), GHOST), gr = (ccw(r), r, GHOST).
            gl = -1
            gr = -1
            if not l_single:
                gl = div3(T[_slot(ghost_out[u(l)], 4)])
            if not r_single:
                gr = ghost_out[u(r)]
            while True:
                if not l_single:
                    lp = T[_slot(gl, 1)]
                    o, st = orient2d_staged(P[u(l), 0], P[u(l), 1], P[u(r), 0], P[u(r), 1], P[u(lp), 0], P[u(lp), 1], ccwb)
                    n_orient += 1
                    s_orient += st
                    s2_orient += st >> 1
                    if o < 0.0:
                        gl = div3(T[_slot(gl, 4)])
                        l = lp
                        continue
                if not r_single:
                    rp = T[_slot(gr, 0)]
                    o, st = orient2d_staged(P[u(l), 0], P[u(l), 1], P[u(r), 0], P[u(r), 1], P[u(rp), 0], P[u(rp), 1], ccwb)
                    n_orient += 1
                    s_orient += st
                    s2_orient += st >> 1
                    if o < 0.0:
                        gr = div3(T[_slot(gr, 5)])
                        r = rp
                        continue
                break

            # Splice the ghost rings: A = (l, r, G) above the tangent, B below.
            A = 2 * (slot - 1)
            B = A + 1
            T[_slot(A, 0)] = l
            T[_slot(A, 1)] = r
            T[_slot(A, 2)] = GHOST
            T[_slot(B, 0)] = r
            T[_slot(B, 1)] = l
            T[_slot(B, 2)] = GHOST
            T[_hidx(3 * A)] = 3 * B
            T[_hidx(3 * B)] = 3 * A
            if l_single:
                T[_hidx(3 * A + 2)] = 3 * B + 1
                T[_hidx(3 * B + 1)] = 3 * A + 2
            else:
                l_out = T[_slot(gl, 5)]
                T[_hidx(3 * A + 2)] = l_out
                T[_hidx(l_out)] = 3 * A + 2
                T[_hidx(3 * B + 1)] = 3 * gl + 2
                T[_hidx(3 * gl + 2)] = 3 * B + 1
            if r_single:
                T[_hidx(3 * A + 1)] = 3 * B + 2
                T[_hidx(3 * B + 2)] = 3 * A + 1
            else:
                r_in = T[_slot(gr, 4)]
                T[_hidx(3 * A + 1)] = r_in
                T[_hidx(r_in)] = 3 * A + 1
                T[_hidx(3 * B + 2)] = 3 * gr + 1
                T[_hidx(3 * gr + 1)] = 3 * B + 2
            l_bottom = l

            # Rising bubble.
            while True:
                xl = P[u(l), 0]
                yl = P[u(l), 1]
                xr = P[u(r), 0]
                yr = P[u(r), 1]
                GL = div3(T[_slot(A, 5)])
                lvalid = False
                if GL != B:
                    lc = T[_slot(GL, 0)]
                    o, st = orient2d_staged(xl, yl, xr, yr, P[u(lc), 0], P[u(lc), 1], ccwb)
                    n_orient += 1
                    s_orient += st
                    s2_orient += st >> 1
                    lvalid = o > 0.0
                    while lvalid:
                        e = T[_slot(GL, 3)]
                        x = T[_vidx(_prev(e))]
                        if x == GHOST:
                            break
                        ic, st = incircle_staged(xl, yl, xr, yr, P[u(lc), 0], P[u(lc), 1], P[u(x), 0], P[u(x), 1], iccb)
                        n_incircle += 1
                        s_incircle += st
                        s2_incircle += st >> 1
                        if ic <= 0.0:
                            break
                        # (l, lc, x) is not Delaunay: flip l-lc with its ghost.
                        tt = div3(e)
                        t_lc_x = T[_hidx(_next(e))]
                        t_x_l = T[_hidx(_prev(e))]
                        g1 = T[_slot(GL, 4)]
                        g2 = T[_slot(GL, 5)]
                        T[_slot(tt, 0)] = x
                        T[_slot(tt, 1)] = l
                        T[_slot(tt, 2)] = GHOST
                        T[_slot(GL, 0)] = lc
                        T[_slot(GL, 1)] = x
                        T[_slot(GL, 2)] = GHOST
                        T[_hidx(3 * tt)] = t_x_l
                        T[_hidx(t_x_l)] = 3 * tt
                        T[_hidx(3 * tt + 1)] = g1
                        T[_hidx(g1)] = 3 * tt + 1
                        T[_hidx(3 * tt + 2)] = 3 * GL + 1
                        T[_hidx(3 * GL + 1)] = 3 * tt + 2
                        T[_hidx(3 * GL)] = t_lc_x
                        T[_hidx(t_lc_x)] = 3 * GL
                        T[_hidx(3 * GL + 2)] = g2
                        T[_hidx(g2)] = 3 * GL + 2
                        GL = tt
                        lc = x
                        # x was strictly inside the circle through l, r and
                        # the old lc, on the far side of l-lc from r: it is
                        # strictly above the base, valid without an orient
                        # test (as in Triangle's merge).
                GR = div3(T[_slot(A, 4)])
                rvalid = False
                if GR != B:
                    rc = T[_slot(GR, 1)]
                    o, st = orient2d_staged(xl, yl, xr, yr, P[u(rc), 0], P[u(rc), 1], ccwb)
                    n_orient += 1
                    s_orient += st
                    s2_orient += st >> 1
                    rvalid = o > 0.0
                    while rvalid:
                        e = T[_slot(GR, 3)]
                        x = T[_vidx(_prev(e))]
                        if x == GHOST:
                            break
                        ic, st = incircle_staged(xl, yl, xr, yr, P[u(rc), 0], P[u(rc), 1], P[u(x), 0], P[u(x), 1], iccb)
                        n_incircle += 1
                        s_incircle += st
                        s2_incircle += st >> 1
                        if ic <= 0.0:
                            break
                        tt = div3(e)
                        t_r_x = T[_hidx(_next(e))]
                        t_x_rc = T[_hidx(_prev(e))]
                        g1 = T[_slot(GR, 4)]
                        g2 = T[_slot(GR, 5)]
                        T[_slot(GR, 0)] = r
                        T[_slot(GR, 1)] = x
                        T[_slot(GR, 2)] = GHOST
                        T[_slot(tt, 0)] = x
                        T[_slot(tt, 1)] = rc
                        T[_slot(tt, 2)] = GHOST
                        T[_hidx(3 * GR)] = t_r_x
                        T[_hidx(t_r_x)] = 3 * GR
                        T[_hidx(3 * GR + 1)] = 3 * tt + 2
                        T[_hidx(3 * tt + 2)] = 3 * GR + 1
                        T[_hidx(3 * GR + 2)] = g2
                        T[_hidx(g2)] = 3 * GR + 2
                        T[_hidx(3 * tt)] = t_x_rc
                        T[_hidx(t_x_rc)] = 3 * tt
                        T[_hidx(3 * tt + 1)] = g1
                        T[_hidx(g1)] = 3 * tt + 1
                        rc = x  # valid, as on the left
                if not lvalid and not rvalid:
                    break
                choose_right = not lvalid
                if lvalid and rvalid:
                    ic, st = incircle_staged(P[u(lc), 0], P[u(lc), 1], xl, yl, xr, yr, P[u(rc), 0], P[u(rc), 1], iccb)
                    n_incircle += 1
                    s_incircle += st
                    s2_incircle += st >> 1
                    choose_right = ic > 0.0
                if choose_right:
                    # cross edge l-rc: A and GR become (l, r, rc) and the new A
                    a0 = T[_slot(A, 3)]
                    a2 = T[_slot(A, 5)]
                    g0 = T[_slot(GR, 3)]
                    g1 = T[_slot(GR, 4)]
                    T[_slot(A, 0)] = l
                    T[_slot(A, 1)] = r
                    T[_slot(A, 2)] = rc
                    T[_slot(GR, 0)] = l
                    T[_slot(GR, 1)] = rc
                    T[_slot(GR, 2)] = GHOST
                    T[_hidx(3 * A)] = a0
                    T[_hidx(a0)] = 3 * A
                    T[_hidx(3 * A + 1)] = g0
                    T[_hidx(g0)] = 3 * A + 1
                    T[_hidx(3 * A + 2)] = 3 * GR
                    T[_hidx(3 * GR)] = 3 * A + 2
                    T[_hidx(3 * GR + 1)] = g1
                    T[_hidx(g1)] = 3 * GR + 1
                    T[_hidx(3 * GR + 2)] = a2
                    T[_hidx(a2)] = 3 * GR + 2
                    A = GR
                    r = rc
                else:
                    # cross edge lc-r: A and GL become (l, r, lc) and the new A
                    a0 = T[_slot(A, 3)]
                    a1 = T[_slot(A, 4)]
                    g0 = T[_slot(GL, 3)]
                    g2 = T[_slot(GL, 5)]
                    T[_slot(A, 0)] = l
                    T[_slot(A, 1)] = r
                    T[_slot(A, 2)] = lc
                    T[_slot(GL, 0)] = lc
                    T[_slot(GL, 1)] = r
                    T[_slot(GL, 2)] = GHOST
                    T[_hidx(3 * A)] = a0
                    T[_hidx(a0)] = 3 * A
                    T[_hidx(3 * A + 1)] = 3 * GL
                    T[_hidx(3 * GL)] = 3 * A + 1
                    T[_hidx(3 * A + 2)] = g0
                    T[_hidx(g0)] = 3 * A + 2
                    T[_hidx(3 * GL + 1)] = a1
                    T[_hidx(a1)] = 3 * GL + 1
                    T[_hidx(3 * GL + 2)] = g2
                    T[_hidx(g2)] = 3 * GL + 2
                    A = GL
                    l = lc
            ghost_out[u(l_bottom)] = B
            ghost_out[u(r)] = A

            # Extremes of the union: one side's by construction, else the larger.
            if x_split:
                ext[lt, XMAX] = ext[rt, XMAX]
                keep_max, keep_min, order = YMAX, YMIN, 1
            else:
                ext[lt, YMAX] = ext[rt, YMAX]
                keep_max, keep_min, order = XMAX, XMIN, 0
            a = ext[lt, keep_max]
            b = ext[rt, keep_max]
            if _less(P[u(a), 0], P[u(a), 1], P[u(b), 0], P[u(b), 1], order):
                ext[lt, keep_max] = b
            a = ext[lt, keep_min]
            b = ext[rt, keep_min]
            if _less(P[u(b), 0], P[u(b), 1], P[u(a), 0], P[u(a), 1], order):
                ext[lt, keep_min] = b
            single[lt] = False
            top -= 1
    counters[C_ORIENT] += n_orient
    counters[C_ORIENT_S1] += s_orient - s2_orient
    counters[C_ORIENT_S2] += s2_orient
    counters[C_INCIRCLE] += n_incircle
    counters[C_INCIRCLE_S1] += s_incircle - s2_incircle
    counters[C_INCIRCLE_S2] += s2_incircle
    for i in range(top + 1):
        for j in range(4):
            out_ext[i, j] = ext[i, j]
        out_single[i] = single[i]
    return top + 1


# --------------------------------------------------------------------------
# Output


@njit(cache=True, nogil=True)
def number_real(T, newid, lo, hi):
    """Ids 0, 1, ... for the real (non-ghost, used) triangles of slots
    [lo, hi), -1 for the others; returns how many are real.  Branch-free:
    the short-circuit form compiled to a loop five times slower."""
    m = 0
    for t in range(lo, hi):
        real = (T[_slot(t, 0)] >= 0) & (T[_slot(t, 1)] >= 0) & (T[_slot(t, 2)] >= 0)
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
            simplices[u(k), i] = perm[u(T[_slot(t, i)])]
            # edge opposite vertex i starts at vertex i+1
            neighbors[u(k), i] = newid[div3(T[_slot(t, 3 + (i + 1) % 3)])]


@njit(cache=True)
def hull_loop(T, start_ghost, perm, index_sample):
    """Counter-clockwise hull vertices (input indices) by walking the ghost
    ring from ``start_ghost``."""
    count = 0
    g = start_ghost
    while True:
        count += 1
        g = T[6 * g + 5] // 3
        if g == start_ghost:
            break
    out = np.empty(count, dtype=index_sample.dtype)
    g = start_ghost
    for i in range(count):
        out[i] = perm[T[6 * g + 1]]
        g = T[6 * g + 5] // 3
    return out


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
def duplicates_into(rep, perm, out, lo, hi):
    """duplicate_of in input indices from representatives in sorted order;
    returns how many positions of [lo, hi) represent themselves."""
    distinct = 0
    for i in range(lo, hi):
        r = rep[u(i)]
        out[u(perm[u(i)])] = perm[u(r)]
        distinct += r == i
    return distinct


@njit(cache=True, nogil=True)
def fill(arr, value, lo, hi):
    for i in range(lo, hi):
        arr[u(i)] = value
