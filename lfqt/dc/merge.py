"""Phase 3 of the divide and conquer: the Guibas–Stolfi merge (fqDel 3.3).

With every partition wrapped in ghost triangles (lfqt.dc.layout), a merge of
a left (or lower) partition with a right (or upper) one is:

1. the lower common tangent ``l-r``, walked from the extremes that face
   each other;
2. a splice of the two ghost rings along it: two new ghosts, ``A = (l, r,
   GHOST)`` above the tangent and ``B = (r, l, GHOST)`` below;
3. the rising bubble: on each side the candidate above the base ``l-r``;
   an edge to a candidate that fails the in-circle test is deleted by
   flipping it with its ghost; the better candidate gives the next cross
   edge, which ``A`` becomes, and the base moves up.

Predicates are staged (lfqt.predicates) with the stage-1 bound of the merge's
quad-tree level, and counted in ``counts`` (lfqt.predicates.counters).
"""
import numpy as np
from numba import njit

from ..indexing import u
from ..predicates.counters import INCIRCLE, ORIENT, tally
from ..predicates.levels import binade, level_bounds
from ..predicates.planar import CCW_A, ICC_A, incircle_staged, orient2d_staged, static_bounds
from .layout import (GHOST, PART, SINGLE, STACK, XMAX, XMIN, YMAX, YMIN, less, link, link_edges,
                     nxt, origin, prv, set_triangle, slot, tri, twin)
from .subdivide import ALT_X


@njit(cache=True, inline="always")
def _orient(P, a, b, c, bound, static):
    """Exact orientation of points a, b, c (> 0: counter-clockwise), and the
    stage that decided it."""
    return orient2d_staged(P[u(a), 0], P[u(a), 1], P[u(b), 0], P[u(b), 1], P[u(c), 0],
                           P[u(c), 1], bound, static)


@njit(cache=True, inline="always")
def _splice(T, A, B, l, r):
    """The new ghosts A = (l, r, GHOST) above the tangent l-r and B = (r, l,
    GHOST) below it, twins across it; ``_splice_side`` joins them to each
    side's ghost ring::

            ... gl'      A      gr' ...        gl, gr: ghosts at l and r
                   \\  l ---> r  /
                   /  l <--- r  \\
            ... gl       B      gr  ...
    """
    set_triangle(T, A, l, r, GHOST)
    set_triangle(T, B, r, l, GHOST)
    link_edges(T, A, 0, B, 0)


@njit(cache=True, inline="always")
def _splice_side(T, A, B, g, s):
    """Join A and B to the ghost ring of side s (0: left, at l; 1: right, at
    r) through its ghost g at the tangent's end; g < 0 for a single vertex,
    where A and B close on each other."""
    # A's edge at that end is 2 - s, B's is 1 + s
    if g < 0:
        link_edges(T, A, 2 - s, B, 1 + s)
    else:
        link(T, A, 2 - s, T[slot(g, 5 - s)])
        link_edges(T, B, 1 + s, g, 2 - s)


@njit(cache=True, inline="always")
def _flip_ghost(T, g, e, x):
    """Delete a hull edge by flipping it with its ghost.  g = (p, q, GHOST)
    is the ghost of hull edge q -> p, e the half-edge q -> p of the real
    triangle (q, p, x) across it.  Afterwards g = (p, x, GHOST) and the old
    triangle is the ghost (x, q, GHOST), which is returned::

              x                      x
             / \\                    /|\\
            /   \\                  / | \\
           q --e-> p     =>       q  |  p      (edge q-p is gone; the hull
             g (ghost)             tt | g       now runs q -> x -> p)
    """
    tt = tri(e)
    t_px = T[twin(nxt(e))]  # twin of p -> x
    t_xq = T[twin(prv(e))]  # twin of x -> q
    g1 = T[slot(g, 4)]
    g2 = T[slot(g, 5)]
    set_triangle(T, tt, x, T[slot(g, 1)], GHOST)
    set_triangle(T, g, T[slot(g, 0)], x, GHOST)
    link(T, tt, 0, t_xq)
    link(T, tt, 1, g1)
    link_edges(T, tt, 2, g, 1)
    link(T, g, 0, t_px)
    link(T, g, 2, g2)
    return tt


@njit(cache=True, inline="always")
def _cross_edge(T, A, g, l, r, c, s):
    """Add the cross edge from the base l -> r to the candidate c of side s
    (g: c's ghost, next to A): A becomes the real triangle (l, r, c) and g
    the new A, the ghost of the new base, (l, c) or (c, r), whose vertices
    the caller sets::

          c -- ... (g)              c               s = 1: c on the right,
          ^                        / \\              new base l -> c
          |  A = (l, r, GHOST) => /   \\  g = (l, c, GHOST)
        l ----> r               l ----> r   (A = (l, r, c))
    """
    g0 = T[slot(g, 3)]
    a = T[slot(A, 4 + s)]
    set_triangle(T, A, l, r, c)
    link_edges(T, A, 1 + s, g, 0)
    link(T, A, 2 - s, g0)
    link(T, g, 1 + s, a)


@njit(cache=True, inline="always")
def _bounds(P, code, probe, fmt, level_filter):
    """Stage-1 bounds (orient, in-circle) of a merge: the level's, probed at
    one point of the node, or Triangle's constants."""
    if code >= ALT_X or not level_filter:
        return CCW_A, ICC_A
    ex = binade(P[u(probe), 0], fmt[4], fmt[3])
    ey = binade(P[u(probe), 1], fmt[4], fmt[3])
    return level_bounds(code, fmt[0], fmt[1], fmt[2], ex, ey)


@njit(cache=True, inline="always")
def _box(P, parts, lt, rt):
    """Width and height of the box around partitions lt and rt, from their
    extremes: every point of their merge lies in it (lfqt.predicates.planar.
    static_bounds)."""
    x0 = min(P[u(parts[lt, XMIN]), 0], P[u(parts[rt, XMIN]), 0])
    x1 = max(P[u(parts[lt, XMAX]), 0], P[u(parts[rt, XMAX]), 0])
    y0 = min(P[u(parts[lt, YMIN]), 1], P[u(parts[rt, YMIN]), 1])
    y1 = max(P[u(parts[lt, YMAX]), 1], P[u(parts[rt, YMAX]), 1])
    return x1 - x0, y1 - y0


@njit(cache=True, inline="always")
def _union_extremes(P, parts, lt, rt, x_split):
    """The extremes of the union of partitions lt and rt, into row lt: along
    the split axis each side holds one by construction, across it the larger."""
    if x_split:
        parts[lt, XMAX] = parts[rt, XMAX]
        keep_max, keep_min, axis = YMAX, YMIN, 1
    else:
        parts[lt, YMAX] = parts[rt, YMAX]
        keep_max, keep_min, axis = XMAX, XMIN, 0
    a = parts[lt, keep_max]
    b = parts[rt, keep_max]
    if less(P[u(a), 0], P[u(a), 1], P[u(b), 0], P[u(b), 1], axis):
        parts[lt, keep_max] = b
    a = parts[lt, keep_min]
    b = parts[rt, keep_min]
    if less(P[u(b), 0], P[u(b), 1], P[u(a), 0], P[u(a), 1], axis):
        parts[lt, keep_min] = b
    parts[lt, SINGLE] = 0


@njit(cache=True, nogil=True)
def run_ops(ops, op_lo, op_hi, mesh, codes, counts, parts_in, n_in, parts_out):
    """Execute ops[op_lo:op_hi] (lfqt.dc.subdivide; a merge at split position
    p has its code in ``codes[p]``) on a stack of partitions
    that starts with the ``n_in`` rows of ``parts_in`` (a merge of the upper
    tree pushes its two finished children).  The partitions left on the
    stack (one for a whole subtree) are written to ``parts_out`` and their
    number returned.  Predicate counts are added to ``counts``.

    The merge is written out in this loop rather than in a helper: an inlined
    helper that loops and takes the arrays keeps numba's atomic reference
    counts of them alive, a third of the run time.  Side s (0: left, next to
    l; 1: right, next to r) indexes the two-element ``end``, ``ghost``,
    ``cand`` and ``valid``, so that both sides run the same lines.
    """
    P, T, ghost_out, fmt, level_filter = mesh
    parts = np.empty((STACK, PART), dtype=np.int64)
    end = np.empty(2, dtype=np.int64)    # the base l -> r
    ghost = np.empty(2, dtype=np.int64)  # the ghost at each end, then next to A
    cand = np.empty(2, dtype=np.int64)   # each side's candidate above the base
    valid = np.empty(2, dtype=np.bool_)
    cand_x = np.empty(2)                 # and its coordinates
    cand_y = np.empty(2)
    top = -1
    for i in range(n_in):
        top += 1
        parts[top] = parts_in[i]
    for k in range(op_lo, op_hi):
        op = ops[k]
        if op < 0:  # push the single vertex -op - 1
            top += 1
            for j in range(SINGLE):
                parts[top, j] = -op - 1
            parts[top, SINGLE] = 1
            continue
        lt, rt, code = top - 1, top, np.int64(codes[u(op)])
        x_split = code == ALT_X if code >= ALT_X else (code & 1) == 1
        end[0] = parts[lt, XMAX if x_split else YMAX]
        end[1] = parts[rt, XMIN if x_split else YMIN]
        single_l, single_r = parts[lt, SINGLE] == 1, parts[rt, SINGLE] == 1
        ccwb = iccb = ccws = iccs = 0.0
        if not (single_l and single_r):  # two lone vertices: no predicate
            ccwb, iccb = _bounds(P, code, parts[lt, XMIN], fmt, level_filter)
            wx, wy = _box(P, parts, lt, rt)
            ccws, iccs = static_bounds(wx, wy, ccwb, iccb)
        ghost[0] = -1 if single_l else tri(T[slot(ghost_out[u(end[0])], 4)])
        ghost[1] = -1 if single_r else ghost_out[u(end[1])]
        moved = True
        while moved:  # lower common tangent: l walks clockwise, r counter-clockwise
            moved = False
            for s in range(2):
                if ghost[s] < 0:
                    continue
                c = T[slot(ghost[s], 1 - s)]
                o, st = _orient(P, end[0], end[1], c, ccwb, ccws)
                tally(counts, ORIENT, st)
                if o < 0.0:
                    end[s] = c
                    ghost[s] = tri(T[slot(ghost[s], 4 + s)])
                    moved = True
                    break
        A = 2 * (op - 1)
        B = A + 1
        _splice(T, A, B, end[0], end[1])
        for s in range(2):
            _splice_side(T, A, B, ghost[s], s)
        l_bottom = end[0]
        # The base's and the candidates' coordinates stay in registers: the
        # predicates on the bubble's critical path then load only the point
        # they test.
        lx, ly = P[u(end[0]), 0], P[u(end[0]), 1]
        rx, ry = P[u(end[1]), 0], P[u(end[1]), 1]
        while True:  # the rising bubble
            for s in range(2):
                g = tri(T[slot(A, 5 - s)])
                ok = False
                if g != B:  # else the side's hull is used up
                    c = T[slot(g, s)]
                    cx, cy = P[u(c), 0], P[u(c), 1]
                    o, st = orient2d_staged(lx, ly, rx, ry, cx, cy, ccwb, ccws)
                    tally(counts, ORIENT, st)
                    ok = o > 0.0
                    while ok:  # delete edges to c while the next one is in its circle
                        e = T[slot(g, 3)]
                        x = T[origin(prv(e))]
                        if x == GHOST:
                            break
                        xx, xy = P[u(x), 0], P[u(x), 1]
                        ic, st = incircle_staged(lx, ly, rx, ry, cx, cy, xx, xy, iccb, iccs)
                        tally(counts, INCIRCLE, st)
                        if ic <= 0.0:
                            break
                        tt = _flip_ghost(T, g, e, x)
                        if s == 0:
                            g = tt
                        # x was strictly inside the circle through l, r and
                        # c, beyond the deleted edge from the base: strictly
                        # above the base, valid without an orient test (as in
                        # Triangle's merge).
                        c, cx, cy = x, xx, xy
                    cand[s] = c
                    cand_x[s] = cx
                    cand_y[s] = cy
                valid[s] = ok
                ghost[s] = g
            if not valid[0] and not valid[1]:
                break
            s = 0 if valid[0] else 1
            if valid[0] and valid[1]:
                ic, st = incircle_staged(cand_x[0], cand_y[0], lx, ly, rx, ry, cand_x[1],
                                         cand_y[1], iccb, iccs)
                tally(counts, INCIRCLE, st)
                s = 1 if ic > 0.0 else 0
            _cross_edge(T, A, ghost[s], end[0], end[1], cand[s], s)
            A = ghost[s]
            end[s] = cand[s]
            if s == 0:
                lx, ly = cand_x[0], cand_y[0]
            else:
                rx, ry = cand_x[1], cand_y[1]
            set_triangle(T, A, end[0], end[1], GHOST)
        ghost_out[u(l_bottom)] = B
        ghost_out[u(end[1])] = A
        _union_extremes(P, parts, lt, rt, x_split)
        top -= 1
    for i in range(top + 1):
        parts_out[i] = parts[i]
    return top + 1
