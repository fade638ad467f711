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

Two lone vertices (an edge), a lone vertex with such an edge (a triangle),
and four points (two such edges, or a lone vertex and such a triangle) are
built directly, without the steps above (``run_ops``' base cases).

Predicates are staged (lfqt.predicates) with the stage-1 bound of the merge's
quad-tree level, and counted in ``counts`` (lfqt.predicates.counters).
"""
import numpy as np
from numba import njit

from ..indexing import borrow, u
from ..predicates.counters import INCIRCLE, ORIENT, tally_undecided
from ..predicates.levels import binade, level_bounds
from ..predicates.planar import (CCW_A, ICC_A, incircle_decide, incircle_staged, orient2d_decide,
                                 orient2d_staged, static_bounds)
from .layout import (GHOST, PART, SMALL, STACK, XMAX, XMIN, YMAX, YMIN, before, link,
                     link_edges, nxt, origin, prv, set_triangle, slot, tri, twin)
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
def _edge_of_two(T, ghost_out, A, l, r):
    """The base case of two lone vertices l, r: the ghosts A = (l, r, GHOST)
    and B = (r, l, GHOST), twins along all three edges."""
    B = A + 1
    _splice(T, A, B, l, r)
    _splice_side(T, A, B, -1, 0)
    _splice_side(T, A, B, -1, 1)
    ghost_out[u(l)] = B
    ghost_out[u(r)] = A


@njit(cache=True, inline="always")
def _ghost(T, ghost_out, G, a, b, R, i):
    """G becomes the ghost (b, a, GHOST) of the hull edge a -> b, which is
    edge i of the real triangle R."""
    set_triangle(T, G, b, a, GHOST)
    link_edges(T, G, 0, R, i)
    ghost_out[u(a)] = G


@njit(cache=True, inline="always")
def _join(T, G, H):
    """Close the ghost ring at the hull vertex between G's edge and the next
    one, H's: G = (h, g, GHOST) and H = (k, h, GHOST) meet at h."""
    link_edges(T, H, 1, G, 2)


@njit(cache=True, inline="always")
def _wrap3(T, ghost_out, x0, x1, x2, R0, i0, R1, i1, R2, i2, G0, G1, G2):
    """A hull of three vertices x0, x1, x2 (counter-clockwise) wrapped in
    the ghosts G0, G1, G2 of its edges x0 -> x1 (edge i0 of the real
    triangle R0), x1 -> x2 (i1 of R1) and x2 -> x0 (i2 of R2)."""
    _ghost(T, ghost_out, G0, x0, x1, R0, i0)
    _ghost(T, ghost_out, G1, x1, x2, R1, i1)
    _ghost(T, ghost_out, G2, x2, x0, R2, i2)
    _join(T, G2, G0)
    _join(T, G0, G1)
    _join(T, G1, G2)


@njit(cache=True, inline="always")
def _triangle_of_three(T, ghost_out, p, q, v, R, G0, G1, G2):
    """The base case of three points: the triangle R = (p, q, v), counter-
    clockwise, wrapped in its three ghosts, G0 across p -> q, G1 across
    q -> v, G2 across v -> p, each ghost the twin of its neighbours::

                 v
           G2   / \\   G1
               p---q
                G0
    """
    set_triangle(T, R, p, q, v)
    _wrap3(T, ghost_out, p, q, v, R, 0, R, 1, R, 2, G0, G1, G2)


@njit(cache=True, inline="always")
def _fan(T, ghost_out, x0, x1, x2, c, R0, R1, R2, G0, G1, G2):
    """Four points, c inside the triangle (x0, x1, x2) (counter-clockwise):
    the three triangles around c, wrapped in the ghosts G0, G1, G2 of the
    hull edges x0 -> x1, x1 -> x2, x2 -> x0::

                  x2
                 / | \\
                /  |  \\        R0 = (x0, x1, c)
           R2  /   c   \\  R1   R1 = (x1, x2, c)
              /  /   \\  \\     R2 = (x2, x0, c)
             x0 --------- x1
                   R0
    """
    set_triangle(T, R0, x0, x1, c)
    set_triangle(T, R1, x1, x2, c)
    set_triangle(T, R2, x2, x0, c)
    link_edges(T, R0, 1, R1, 2)
    link_edges(T, R1, 1, R2, 2)
    link_edges(T, R2, 1, R0, 2)
    _wrap3(T, ghost_out, x0, x1, x2, R0, 0, R1, 0, R2, 0, G0, G1, G2)


@njit(cache=True, inline="always")
def _quad(T, ghost_out, h0, h1, h2, h3, R0, R1, G0, G1, G2, G3):
    """Four points in convex position, h0 ... h3 counter-clockwise: the
    triangles R0 = (h0, h1, h2) and R1 = (h2, h3, h0) on the diagonal
    h0-h2, wrapped in the ghosts G0 ... G3 of the hull edges h0 -> h1 ...
    h3 -> h0::

            h3 ------ h2
             |  R1  / |
             |    /   |
             |  /  R0 |
            h0 ------ h1
    """
    set_triangle(T, R0, h0, h1, h2)
    set_triangle(T, R1, h2, h3, h0)
    link_edges(T, R0, 2, R1, 2)
    _ghost(T, ghost_out, G0, h0, h1, R0, 0)
    _ghost(T, ghost_out, G1, h1, h2, R0, 1)
    _ghost(T, ghost_out, G2, h2, h3, R1, 0)
    _ghost(T, ghost_out, G3, h3, h0, R1, 1)
    _join(T, G3, G0)
    _join(T, G0, G1)
    _join(T, G1, G2)
    _join(T, G2, G3)


@njit(cache=True)
def _four(T, P, counts, ghost_out, x, y, z, v, s0, s1, s2, s3, s4, s5):
    """The base case of four points: the triangle (x, y, z), counter-
    clockwise, and a fourth point v, triangulated in the six slots s0 ... s5
    their partitions held.  Returns (done, orient calls, in-circle calls);
    nothing is written when a triple is collinear (done False: the general
    merge takes over).

    Whether v lies right of each edge of (x, y, z) tells the case: of none,
    v is inside (a fan around v); of one, the four are in convex position
    and an in-circle test picks the diagonal; of two, their common vertex is
    inside the triangle of the other three and v (a fan around it).

    Called, not inlined, with one call of each builder: the first call's
    compile takes 21.5 s against 18.6 s without this base case, and took
    47 s with it inlined into every merge, two calls of each builder in
    each of its two call sites.  Base cases of four points are a tenth of
    the merges."""
    o1, st = _orient(P, x, y, v, CCW_A, np.inf)
    tally_undecided(counts, ORIENT, st)
    o2, st = _orient(P, y, z, v, CCW_A, np.inf)
    tally_undecided(counts, ORIENT, st)
    o3, st = _orient(P, z, x, v, CCW_A, np.inf)
    tally_undecided(counts, ORIENT, st)
    if o1 == 0.0 or o2 == 0.0 or o3 == 0.0:
        return False, 3, 0
    n1, n2, n3 = o1 < 0.0, o2 < 0.0, o3 < 0.0
    seen = n1 + n2 + n3
    if seen == 3:
        return False, 3, 0  # v right of all three edges: not for exact orientations
    if seen == 1:  # rotate the edge that v sees to x -> y
        if n2:
            x, y, z = y, z, x
        elif n3:
            x, y, z = z, x, y
        ic, st = incircle_staged(P[u(x), 0], P[u(x), 1], P[u(y), 0], P[u(y), 1], P[u(z), 0],
                                 P[u(z), 1], P[u(v), 0], P[u(v), 1], ICC_A, np.inf)
        tally_undecided(counts, INCIRCLE, st)
        # v in the circle through x, y, z: the diagonal v-z, else x-y
        h0, h1, h2, h3 = (v, y, z, x) if ic > 0.0 else (y, z, x, v)
        _quad(T, ghost_out, h0, h1, h2, h3, s0, s1, s2, s3, s4, s5)
        return True, 3, 1
    if seen == 2:  # rotate the vertex between the two edges v sees to y: the centre
        if n2 and n3:
            x, y, z = y, z, x
        elif n3 and n1:
            x, y, z = z, x, y
        x, y, z, v = x, v, z, y
    _fan(T, ghost_out, x, y, z, v, s0, s1, s2, s3, s4, s5)  # v, the centre
    return True, 3, 0


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
def _union_extremes(P, parts, lt, rt, x_split, small):
    """The extremes of the union of partitions lt and rt, into row lt, with
    its SMALL: along the split axis each side holds one by construction,
    across it the larger, picked by a select (layout.before)."""
    if x_split:
        parts[lt, XMAX] = parts[rt, XMAX]
        keep_max, keep_min, axis = YMAX, YMIN, 1
    else:
        parts[lt, YMAX] = parts[rt, YMAX]
        keep_max, keep_min, axis = XMAX, XMIN, 0
    a, b = parts[lt, keep_max], parts[rt, keep_max]
    parts[lt, keep_max] = b if before(P, a, b, axis) else a
    a, b = parts[lt, keep_min], parts[rt, keep_min]
    parts[lt, keep_min] = b if before(P, b, a, axis) else a
    parts[lt, SMALL] = small


@njit(cache=True, inline="always")
def _ahead(T, P, g, s):
    """The vertex the tangent walk of side s would move to from ghost g
    (g >= 0), with its coordinates, and the ghost it would then be at."""
    c = T[slot(g, 1 - s)]
    return c, P[u(c), 0], P[u(c), 1], tri(T[slot(g, 4 + s)])


@njit(cache=True, inline="always")
def _walk(T, P, counts, l, lx, ly, r, rx, ry, g, c, cx, cy, h, s, ccwb, ccws):
    """One step of side s's end of the base l -> r (coordinates lx ... ry)
    toward the lower common tangent, g being the ghost at that end (< 0: a
    lone vertex, no test) and (c, cx, cy, h) = _ahead(g): (moved, the end
    and its coordinates, g, c, cx, cy, h after the step, whether it made an
    orient test; an undecided stage 1 goes to ``counts``).  The next step's
    vertex is loaded before this step's test decides."""
    end, ex, ey = (l, lx, ly) if s == 0 else (r, rx, ry)
    if g < 0:
        return False, end, ex, ey, g, c, cx, cy, h, False
    nc, ncx, ncy, nh = _ahead(T, P, h, s)
    o, st = orient2d_staged(lx, ly, rx, ry, cx, cy, ccwb, ccws)
    tally_undecided(counts, ORIENT, st)
    if o < 0.0:
        return True, c, cx, cy, h, nc, ncx, ncy, nh, True
    return False, end, ex, ey, g, c, cx, cy, h, True


@njit(cache=True, inline="always")
def _beyond(T, P, g):
    """The vertex across ghost g's hull edge, in the real triangle there,
    and its coordinates (GHOST and zeros where that is a ghost too)."""
    x = T[origin(prv(T[slot(g, 3)]))]
    if x == GHOST:
        return x, 0.0, 0.0
    return x, P[u(x), 0], P[u(x), 1]


@njit(cache=True, inline="always")
def _side(T, P, A, B, s):
    """Side s's state next to the ghost A: (its ghost g, the candidate c
    and its coordinates, the vertex x beyond and its coordinates); g == B
    when the side's hull is used up (then nothing else is meaningful)."""
    g = tri(T[slot(A, 5 - s)])
    if g == B:
        return g, -1, 0.0, 0.0, GHOST, 0.0, 0.0
    c = T[slot(g, s)]
    x, xx, xy = _beyond(T, P, g)
    return g, c, P[u(c), 0], P[u(c), 1], x, xx, xy


@njit(cache=True, inline="always")
def _candidate(T, P, counts, B, s, g, c, cx, cy, x, xx, xy, lx, ly, rx, ry, bx, by, blift, ccwb,
               ccws, iccb, iccs):
    """Side s's candidate above the base l -> r (coordinates lx ... ry),
    from the side's state (_side): (valid, the state after it, the
    candidate's difference to l, its lift and its cross product with the
    base's, orient calls, in-circle calls; the calls stage 1 left undecided
    go to ``counts``).  Edges to the candidate whose next neighbour lies in
    the circle through l, r and it are deleted on the way.

    Every predicate subtracts l, so that what a test computes serves the
    next (lfqt.predicates.planar's *_decide take the products as computed):
    with b = r - l (bx, by; its lift blift), u = c - l and v = x - l::

        orient(l, r, c)       = orient(r, c, l)        = b x u
        incircle(l, r, c, x)  = -incircle(r, c, x, l)
                              = -(|b|^2 (u x v) + |u|^2 (v x b) + |v|^2 (b x u))

    b x u is the orient test's, |u|^2 and v's terms become u's when x
    becomes the candidate, and run_ops' choice between the sides reuses
    both sides' u, |u|^2 and b x u: a third of an in-circle test's
    arithmetic, and two thirds of the choice's (1M uniform, 3 interleaved
    series of 11 calls: the same predicate counts, merge 121.0-123.3 ->
    115.7-117.3 ms)."""
    ok = False
    n_o = n_i = 0
    ux = uy = lift = k = 0.0
    if g != B:  # else the side's hull is used up
        ux = cx - lx
        uy = cy - ly
        k = bx * uy - by * ux
        o, st = orient2d_decide(k, bx, by, ux, uy, rx, ry, cx, cy, lx, ly, ccwb, ccws)
        n_o = 1
        tally_undecided(counts, ORIENT, st)
        ok = o > 0.0
        lift = ux * ux + uy * uy
        while ok and x != GHOST:  # delete edges to c while the next one is in its circle
            vx = xx - lx
            vy = xy - ly
            vlift = vx * vx + vy * vy
            bv = bx * vy - by * vx
            det = blift * (ux * vy - vx * uy) + lift * -bv + vlift * k
            ic, st = incircle_decide(det, bx, by, ux, uy, vx, vy, blift, lift, vlift, rx, ry, cx,
                                     cy, xx, xy, lx, ly, iccb, iccs)
            n_i += 1
            tally_undecided(counts, INCIRCLE, st)
            if ic >= 0.0:  # incircle(l, r, c, x) <= 0: x is not inside
                break
            tt = _flip_ghost(T, g, T[slot(g, 3)], x)
            if s == 0:
                g = tt
            # x was strictly inside the circle through l, r and c, beyond the
            # deleted edge from the base: strictly above the base, valid
            # without an orient test (as in Triangle's merge).
            c, cx, cy = x, xx, xy
            ux, uy, lift, k = vx, vy, vlift, bv
            x, xx, xy = _beyond(T, P, g)
    return ok, g, c, cx, cy, x, xx, xy, ux, uy, lift, k, n_o, n_i


@njit(cache=True, inline="always")
def _base_case(T, P, counts, ghost_out, parts, lt, rt, l, r, A):
    """Build the merge of partitions lt and rt directly if it is a base case
    (A, A + 1: the merge's slots; l, r: the base's ends): (built, the
    result's SMALL, orient calls, in-circle calls).

    Two lone vertices make an edge, a lone vertex and such an edge a
    triangle (one orient test where the merge makes four; 1M uniform: 158
    -> 151 ms): 54% of all merges on uniform points.  Four points, two edges
    or a lone vertex and a triangle (another tenth), come from three or four
    orient tests and at most one in-circle test (_four).  Where three of the
    points are collinear the general merge takes over."""
    small_l, small_r = parts[lt, SMALL], parts[rt, SMALL]
    pair = small_l * small_r  # 1: 1+1, 2: 1+2, 3: 1+3, 4: 2+2, 0 or above: none
    if pair == 1:
        _edge_of_two(T, ghost_out, A, l, r)
        return True, 2, 0, 0
    side, v = (rt, l) if small_l == 1 else (lt, r)  # pairs 2 and 3: a lone vertex v beside side
    if pair == 2:
        a, b = parts[side, XMIN], parts[side, XMAX]
        o, st = _orient(P, a, b, v, CCW_A, np.inf)
        tally_undecided(counts, ORIENT, st)
        if o == 0.0:
            return False, 0, 1, 0
        p, q = (a, b) if o > 0.0 else (b, a)
        _triangle_of_three(T, ghost_out, p, q, v, A, A + 1, ghost_out[u(a)], ghost_out[u(b)])
        return True, 3, 1, 0
    if pair != 3 and pair != 4:
        return False, 0, 0, 0
    tested = 0
    if pair == 4:  # two edges: the triangle of three of their points, and the fourth
        x, y = parts[lt, XMIN], parts[lt, XMAX]
        z, v = parts[rt, XMIN], parts[rt, XMAX]
        s0, s1, s2, s3 = ghost_out[u(x)], ghost_out[u(y)], ghost_out[u(z)], ghost_out[u(v)]
        o, st = _orient(P, x, y, z, CCW_A, np.inf)
        tally_undecided(counts, ORIENT, st)
        if o == 0.0:
            return False, 0, 1, 0
        if o < 0.0:
            x, y = y, x
        tested = 1
    else:  # the triangle's vertices, counter-clockwise along its ghosts
        x = parts[side, XMIN]
        s1 = ghost_out[u(x)]
        y = T[slot(s1, 0)]
        s2 = ghost_out[u(y)]
        z = T[slot(s2, 0)]
        s3 = ghost_out[u(z)]
        s0 = tri(T[slot(s1, 3)])  # the real triangle, across the ghost's edge
    built, oc, ic = _four(T, P, counts, ghost_out, x, y, z, v, s0, s1, s2, s3, A, A + 1)
    return built, 0, tested + oc, ic


@njit(cache=True, inline="always")
def _copy_row(dst, i, src, j):
    """dst[i] = src[j] for partition rows, entry by entry: a row assignment
    compiles numba's shape-mismatch error path, 1.6 s of the first call's
    25.6 s (a cold cache)."""
    for k in range(PART):
        dst[i, k] = src[j, k]


@njit(cache=True, nogil=True)
def run_ops(ops, op_lo, op_hi, mesh, codes, counts, parts_in, n_in, parts_out):
    """Execute ops[op_lo:op_hi] (lfqt.dc.subdivide; a merge at split position
    p has its code in ``codes[p]``) on a stack of partitions
    that starts with the ``n_in`` rows of ``parts_in`` (a merge of the upper
    tree pushes its two finished children).  The partitions left on the
    stack (one for a whole subtree) are written to ``parts_out`` and their
    number returned.  Predicate counts are added to ``counts``.

    Each side (0: left, next to l; 1: right, next to r) runs ``_walk``
    (the tangent) and ``_candidate`` (the bubble) with a literal side, so
    that both get code specialised for them (a loop over the side, which
    LLVM does not unroll, cost 10-28% of the merge).  An inlined helper
    that loops would pay two atomic reference counts per array per call
    (half the run time), so it gets borrowed views of the arrays
    (lfqt.indexing.borrow), which cost none; so does ``_base_case``, which
    does not loop but runs for every merge (its reference counts on
    ghost_out and the partition stack: 1M uniform, merge +8 ms).
    """
    P, T, ghost_out, fmt, level_filter = mesh
    P, T, counts, ghost_out = borrow(P), borrow(T), borrow(counts), borrow(ghost_out)
    stack = np.empty((STACK, PART), dtype=np.int64)
    parts = borrow(stack)  # the views are for the inlined helpers (see above)
    # (stack is used once more at the end: numba frees an array after its
    # last use, and a borrowed view does not keep it alive)
    # Call counts and each side's state live in scalars, not in small arrays:
    # the stores to T may alias any array, which would cost reloads.  The
    # calls stage 1 leaves undecided are rare and counted in ``counts`` on a
    # branch: as four more scalars they cost registers in every step
    # (docs/performance.md, "merge counters").
    o_calls = i_calls = 0
    top = -1
    for i in range(n_in):
        top += 1
        _copy_row(parts, top, parts_in, i)
    for k in range(op_lo, op_hi):
        op = ops[u(k)]
        if op < 0:  # push the single vertex -op - 1
            top += 1
            for j in range(SMALL):
                parts[u(top), j] = -op - 1
            parts[u(top), SMALL] = 1
            continue
        # unsigned rows: numba checks a signed index for wraparound at every
        # access (1M uniform: merge 117.5-117.7 -> 114.3-114.7 ms)
        lt, rt, code = u(top - 1), u(top), np.int64(codes[u(op)])
        x_split = code == ALT_X if code >= ALT_X else (code & 1) == 1
        l = parts[lt, XMAX if x_split else YMAX]  # the base l -> r
        r = parts[rt, XMIN if x_split else YMIN]
        A = 2 * (op - 1)  # the merge's two triangle slots, A and A + 1
        built, small, oc, ic = _base_case(T, P, counts, ghost_out, parts, lt, rt, l, r, A)
        o_calls += oc
        i_calls += ic
        if built:
            _union_extremes(P, parts, lt, rt, x_split, small)
            top -= 1
            continue
        single_l, single_r = parts[lt, SMALL] == 1, parts[rt, SMALL] == 1
        ccwb, iccb = _bounds(P, code, parts[lt, XMIN], fmt, level_filter)
        wx, wy = _box(P, parts, lt, rt)
        ccws, iccs = static_bounds(wx, wy, ccwb, iccb)
        gl = -1 if single_l else tri(T[slot(ghost_out[u(l)], 4)])  # the ghost at each end
        gr = -1 if single_r else ghost_out[u(r)]
        # The base's and the candidates' coordinates stay in registers: the
        # predicates on the critical path then load only the point they
        # test, and each walk step loads the next one's point before its own
        # test decides (1M uniform, merge minima 131.4-132.6 -> 127.3-130.4
        # ms, same counts).
        lx, ly = P[u(l), 0], P[u(l), 1]
        rx, ry = P[u(r), 0], P[u(r), 1]
        cl, clx, cly, hl = _ahead(T, P, gl, 0) if gl >= 0 else (-1, 0.0, 0.0, -1)
        cr, crx, cry, hr = _ahead(T, P, gr, 1) if gr >= 0 else (-1, 0.0, 0.0, -1)
        while True:  # lower common tangent: l walks clockwise, r counter-clockwise
            moved, l, lx, ly, gl, cl, clx, cly, hl, tested = _walk(
                T, P, counts, l, lx, ly, r, rx, ry, gl, cl, clx, cly, hl, 0, ccwb, ccws)
            o_calls += tested
            if moved:
                continue
            moved, r, rx, ry, gr, cr, crx, cry, hr, tested = _walk(
                T, P, counts, l, lx, ly, r, rx, ry, gr, cr, crx, cry, hr, 1, ccwb, ccws)
            o_calls += tested
            if not moved:
                break
        B = A + 1
        _splice(T, A, B, l, r)
        _splice_side(T, A, B, gl, 0)
        _splice_side(T, A, B, gr, 1)
        l_bottom = l
        # Each side's state (_side) is carried from step to step, and only
        # the side that advanced loads it again: a cross edge writes the
        # vertices of A and the new A and link entries, never the other
        # side's ghost, candidate or the vertex beyond, so that side's chain
        # of dependent loads leaves the critical path (docs/performance.md,
        # "merge's idle side").  The advancing side's next
        # state cannot be loaded ahead: the cross edge may become the real
        # triangle beyond its next ghost.
        gl, cl, clx, cly, xl, xlx, xly = _side(T, P, A, B, 0)
        gr, cr, crx, cry, xr, xrx, xry = _side(T, P, A, B, 1)
        while True:  # the rising bubble
            bx, by = rx - lx, ry - ly  # the base's difference and lift (_candidate)
            blift = bx * bx + by * by
            vl, gl, cl, clx, cly, xl, xlx, xly, ulx, uly, liftl, kl, oc, ic = _candidate(
                T, P, counts, B, 0, gl, cl, clx, cly, xl, xlx, xly, lx, ly, rx, ry, bx, by,
                blift, ccwb, ccws, iccb, iccs)
            o_calls += oc
            i_calls += ic
            vr, gr, cr, crx, cry, xr, xrx, xry, urx, ury, liftr, kr, oc, ic = _candidate(
                T, P, counts, B, 1, gr, cr, crx, cry, xr, xrx, xry, lx, ly, rx, ry, bx, by,
                blift, ccwb, ccws, iccb, iccs)
            o_calls += oc
            i_calls += ic
            if not vl and not vr:
                break
            right = vr
            if vl and vr:  # incircle(cl, l, r, cr) = incircle(cl, r, cr, l), from _candidate's
                det = liftl * kr + blift * (urx * uly - ulx * ury) + liftr * -kl
                ic, st = incircle_decide(det, ulx, uly, bx, by, urx, ury, liftl, blift, liftr,
                                         clx, cly, rx, ry, crx, cry, lx, ly, iccb, iccs)
                i_calls += 1
                tally_undecided(counts, INCIRCLE, st)
                right = ic > 0.0
            g, c = (gr, cr) if right else (gl, cl)
            _cross_edge(T, A, g, l, r, c, 1 if right else 0)
            A = g
            if right:
                r, rx, ry = cr, crx, cry
                gr, cr, crx, cry, xr, xrx, xry = _side(T, P, A, B, 1)
            else:
                l, lx, ly = cl, clx, cly
                gl, cl, clx, cly, xl, xlx, xly = _side(T, P, A, B, 0)
            set_triangle(T, A, l, r, GHOST)
        ghost_out[u(l_bottom)] = B
        ghost_out[u(r)] = A
        _union_extremes(P, parts, lt, rt, x_split, 0)
        top -= 1
    counts[ORIENT] += o_calls
    counts[INCIRCLE] += i_calls
    for i in range(top + 1):
        _copy_row(parts_out, i, stack, i)
    return top + 1
