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

The state the merge carries from step to step is a few small named tuples
(``Vertex``, ``Walk``, ``Side``, ``Base``, ``Rel``, ``Bounds``): numba passes
a tuple by value, so that once the helpers are inlined every field is a
register, as separate scalars were, while the names say what each is.
"""
from collections import namedtuple

import numpy as np
from numba import njit

from ..indexing import borrow, u
from ..predicates.counters import INCIRCLE, ORIENT, tally_undecided
from ..predicates.levels import binade, level_bounds
from ..predicates.planar import (CCW_A, ICC_A, incircle_decide, incircle_staged, orient2d_decide,
                                 orient2d_staged, static_bounds)
from .layout import (GHOST, PART, SMALL, STACK, XMAX, XMIN, YMAX, YMIN, before, head, inner,
                     link, link_edges, nxt, origin, prv, ring_edge, ring_ghost, set_triangle,
                     tail, tri, twin)
from .subdivide import ALT_X

# A vertex and its coordinates, loaded once and kept in registers.
Vertex = namedtuple("Vertex", "id x y")
# One end of the base during the tangent walk: the ghost g at that end (< 0:
# a lone vertex), and the vertex ``ahead`` (a Vertex) that the walk would move
# the end to, with the ghost h it would then be at.
Walk = namedtuple("Walk", "g ahead h")
# One side of the rising bubble: its ghost g next to A (B when the side's hull
# is used up), its candidate c and the vertex x beyond g's hull edge (Vertexes;
# x.id is GHOST where that is a ghost too).
Side = namedtuple("Side", "g c x")
# The base l -> r (Vertexes), its difference (bx, by) = r - l and its lift.
Base = namedtuple("Base", "l r bx by lift")
# A candidate c relative to the base: u = c - l, its lift |u|^2 and the cross
# product k = b x u (lfqt.dc.merge._candidate).
Rel = namedtuple("Rel", "ux uy lift k")
# A merge's stage-1 bounds: dynamic and static (lfqt.predicates.planar), of
# orient and of in-circle.
Bounds = namedtuple("Bounds", "ccw ccw_static icc icc_static")


@njit(cache=True, inline="always")
def _orient(P, a, b, c, bound, static):
    """Exact orientation of points a, b, c (> 0: counter-clockwise), and the
    stage that decided it."""
    return orient2d_staged(P[u(a), 0], P[u(a), 1], P[u(b), 0], P[u(b), 1], P[u(c), 0],
                           P[u(c), 1], bound, static)


@njit(cache=True, inline="always")
def _vertex(P, v):
    """Vertex v with its coordinates."""
    return Vertex(np.int64(v), P[u(v), 0], P[u(v), 1])


@njit(cache=True, inline="always")
def _nowhere():
    """The Vertex of no vertex: GHOST, zeros for coordinates."""
    return Vertex(np.int64(GHOST), 0.0, 0.0)


@njit(cache=True, inline="always")
def splits_x(code):
    """Whether the merge of code ``code`` (lfqt.dc.subdivide) joins a left
    and a right partition (else a lower and an upper one): the LFQT's codes
    are levels, odd on an x split; the alternating ablation writes ALT_X or
    ALT_Y."""
    return code == ALT_X if code >= ALT_X else (code & 1) == 1


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
        link(T, A, 2 - s, ring_edge(T, g, 1 - s))
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
def _wrap3(T, ghost_out, x, inside, G):
    """A hull of three vertices x = (x0, x1, x2) (counter-clockwise) wrapped
    in the ghosts G = (G0, G1, G2) of its edges x0 -> x1, x1 -> x2 and
    x2 -> x0; ``inside`` holds the (real triangle, edge) of each of these
    edges."""
    _ghost(T, ghost_out, G[0], x[0], x[1], inside[0][0], inside[0][1])
    _ghost(T, ghost_out, G[1], x[1], x[2], inside[1][0], inside[1][1])
    _ghost(T, ghost_out, G[2], x[2], x[0], inside[2][0], inside[2][1])
    _join(T, G[2], G[0])
    _join(T, G[0], G[1])
    _join(T, G[1], G[2])


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
    _wrap3(T, ghost_out, (p, q, v), ((R, 0), (R, 1), (R, 2)), (G0, G1, G2))


@njit(cache=True, inline="always")
def _fan(T, ghost_out, x0, x1, x2, c, R, G):
    """Four points, c inside the triangle (x0, x1, x2) (counter-clockwise):
    the three triangles R = (R0, R1, R2) around c, wrapped in the ghosts
    G = (G0, G1, G2) of the hull edges x0 -> x1, x1 -> x2, x2 -> x0::

                  x2
                 / | \\
                /  |  \\        R0 = (x0, x1, c)
           R2  /   c   \\  R1   R1 = (x1, x2, c)
              /  /   \\  \\     R2 = (x2, x0, c)
             x0 --------- x1
                   R0
    """
    R0, R1, R2 = R
    set_triangle(T, R0, x0, x1, c)
    set_triangle(T, R1, x1, x2, c)
    set_triangle(T, R2, x2, x0, c)
    link_edges(T, R0, 1, R1, 2)
    link_edges(T, R1, 1, R2, 2)
    link_edges(T, R2, 1, R0, 2)
    _wrap3(T, ghost_out, (x0, x1, x2), ((R0, 0), (R1, 0), (R2, 0)), G)


@njit(cache=True, inline="always")
def _quad(T, ghost_out, h0, h1, h2, h3, R, G):
    """Four points in convex position, h0 ... h3 counter-clockwise: the
    triangles R = (R0, R1), R0 = (h0, h1, h2) and R1 = (h2, h3, h0), on the
    diagonal h0-h2, wrapped in the ghosts G = (G0, ..., G3) of the hull
    edges h0 -> h1 ... h3 -> h0::

            h3 ------ h2
             |  R1  / |
             |    /   |
             |  /  R0 |
            h0 ------ h1
    """
    R0, R1 = R
    G0, G1, G2, G3 = G
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
def _four(T, P, counts, ghost_out, x, y, z, v, slots):
    """The base case of four points: the triangle (x, y, z), counter-
    clockwise, and a fourth point v, triangulated in the six triangle slots
    ``slots`` their partitions held.  Returns (done, orient calls, in-circle
    calls);
    nothing is written when a triple is collinear (done False: the general
    merge takes over).

    Whether v lies right of each edge of (x, y, z) tells the case: of none,
    v is inside (a fan around v); of one, the four are in convex position
    and an in-circle test picks the diagonal; of two, their common vertex is
    inside the triangle of the other three and v (a fan around it).

    Called, not inlined, with one call of each builder: inlined into every
    merge, with two calls of each builder, it more than doubled the first
    call's compile time (docs/performance.md, "four-point base case"), and
    base cases of four points are only a tenth of the merges."""
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
        _quad(T, ghost_out, h0, h1, h2, h3, (slots[0], slots[1]),
              (slots[2], slots[3], slots[4], slots[5]))
        return True, 3, 1
    if seen == 2:  # rotate the vertex between the two edges v sees to y: the centre
        if n2 and n3:
            x, y, z = y, z, x
        elif n3 and n1:
            x, y, z = z, x, y
        x, y, z, v = x, v, z, y
    _fan(T, ghost_out, x, y, z, v, (slots[0], slots[1], slots[2]),
         (slots[3], slots[4], slots[5]))  # v, the centre
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
    g1 = ring_edge(T, g, 0)
    g2 = ring_edge(T, g, 1)
    set_triangle(T, tt, x, tail(T, g), GHOST)
    set_triangle(T, g, head(T, g), x, GHOST)
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
    g0 = inner(T, g)
    a = ring_edge(T, A, s)
    set_triangle(T, A, l, r, c)
    link_edges(T, A, 1 + s, g, 0)
    link(T, A, 2 - s, g0)
    link(T, g, 1 + s, a)


@njit(cache=True, inline="always")
def _dynamic_bounds(P, code, probe, fmt, level_filter):
    """Stage-1 bounds (orient, in-circle) of a merge: the level's, probed at
    one point of the node, or Triangle's constants."""
    if code >= ALT_X or not level_filter:
        return CCW_A, ICC_A
    ex = binade(P[u(probe), 0], fmt[4], fmt[3])
    ey = binade(P[u(probe), 1], fmt[4], fmt[3])
    return level_bounds(code, fmt[0], fmt[1], fmt[2], ex, ey)


@njit(cache=True, inline="always")
def _bounds(P, parts, lt, rt, code, fmt, level_filter):
    """The Bounds of the merge of partitions lt and rt."""
    ccw, icc = _dynamic_bounds(P, code, parts[lt, XMIN], fmt, level_filter)
    wx, wy = _box(P, parts, lt, rt)
    ccw_static, icc_static = static_bounds(wx, wy, ccw, icc)
    return Bounds(ccw, ccw_static, icc, icc_static)


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
    """The Walk of side s's end at ghost g (g >= 0): the walk of side 0
    (l) runs clockwise along the hull, to g's tail, side 1's (r) counter-
    clockwise, to its head."""
    c = tail(T, g) if s == 0 else head(T, g)
    return Walk(np.int64(g), _vertex(P, c), ring_ghost(T, g, s))


@njit(cache=True, inline="always")
def _no_walk():
    """The Walk of a lone vertex: no ghost, nothing ahead."""
    return Walk(np.int64(-1), _nowhere(), np.int64(-1))


@njit(cache=True, inline="always")
def _walk(T, P, counts, l, r, w, s, bounds):
    """One step of side s's end of the base l -> r (Vertexes) toward the
    lower common tangent, from that end's Walk w (w.g < 0: a lone vertex, no
    test): (moved, the end, its Walk, whether it made an orient test; an
    undecided stage 1 goes to ``counts``).  The next step's vertex is loaded
    before this step's test decides."""
    end = l if s == 0 else r
    if w.g < 0:
        return False, end, w, False
    then = _ahead(T, P, w.h, s)
    c = w.ahead
    o, st = orient2d_staged(l.x, l.y, r.x, r.y, c.x, c.y, bounds.ccw, bounds.ccw_static)
    tally_undecided(counts, ORIENT, st)
    if o < 0.0:
        return True, c, then, True
    return False, end, w, True


@njit(cache=True, inline="always")
def _beyond(T, P, g):
    """The Vertex across ghost g's hull edge, in the real triangle there
    (_nowhere where that is a ghost too)."""
    x = T[origin(prv(inner(T, g)))]
    if x == GHOST:
        return _nowhere()
    return _vertex(P, x)


@njit(cache=True, inline="always")
def _side(T, P, A, B, s):
    """Side s's Side next to the ghost A; its ghost is B when the side's
    hull is used up (then nothing else in it is meaningful).  Side 0's
    candidate is the head of its ghost's hull edge, side 1's the tail."""
    g = ring_ghost(T, A, 1 - s)
    if g == B:
        return Side(g, _nowhere(), _nowhere())
    c = head(T, g) if s == 0 else tail(T, g)
    return Side(g, _vertex(P, c), _beyond(T, P, g))


@njit(cache=True, inline="always")
def _candidate(T, P, counts, B, s, side, base, bounds):
    """Side s's candidate above the base (a Base) from the side's state (a
    Side, _side): (valid, the Side after it, the candidate's Rel, (orient
    calls, in-circle calls)); the calls stage 1 left undecided go to
    ``counts``.  Edges to the candidate whose next neighbour lies in the
    circle through l, r and it are deleted on the way.

    Every predicate subtracts l, so that what a test computes serves the
    next (lfqt.predicates.planar's *_decide take the products as computed):
    with b = r - l (its lift |b|^2), u = c - l and v = x - l::

        orient(l, r, c)       = orient(r, c, l)        = b x u
        incircle(l, r, c, x)  = -incircle(r, c, x, l)
                              = -(|b|^2 (u x v) + |u|^2 (v x b) + |v|^2 (b x u))

    b x u is the orient test's, |u|^2 and v's terms become u's when x
    becomes the candidate, and run_ops' choice between the sides reuses
    both sides' u, |u|^2 and b x u (the Rel): a third of an in-circle test's
    arithmetic, and two thirds of the choice's (docs/performance.md,
    "shared differences")."""
    g, c, x = side
    l, r = base.l, base.r
    bx, by, blift = base.bx, base.by, base.lift
    ok = False
    n_o = n_i = 0
    ux = uy = lift = k = 0.0
    if g != B:  # else the side's hull is used up
        ux = c.x - l.x
        uy = c.y - l.y
        k = bx * uy - by * ux
        o, st = orient2d_decide(k, (bx, by, ux, uy), (r.x, r.y, c.x, c.y, l.x, l.y),
                                bounds.ccw, bounds.ccw_static)
        n_o = 1
        tally_undecided(counts, ORIENT, st)
        ok = o > 0.0
        lift = ux * ux + uy * uy
        while ok and x.id != GHOST:  # delete edges to c while the next one is in its circle
            vx = x.x - l.x
            vy = x.y - l.y
            vlift = vx * vx + vy * vy
            bv = bx * vy - by * vx
            det = blift * (ux * vy - vx * uy) + lift * -bv + vlift * k
            ic, st = incircle_decide(det, (bx, by, ux, uy, vx, vy), (blift, lift, vlift),
                                     (r.x, r.y, c.x, c.y, x.x, x.y, l.x, l.y),
                                     bounds.icc, bounds.icc_static)
            n_i += 1
            tally_undecided(counts, INCIRCLE, st)
            if ic >= 0.0:  # incircle(l, r, c, x) <= 0: x is not inside
                break
            tt = _flip_ghost(T, g, inner(T, g), x.id)
            if s == 0:
                g = tt
            # x was strictly inside the circle through l, r and c, beyond the
            # deleted edge from the base: strictly above the base, valid
            # without an orient test (as in Triangle's merge).
            c = x
            ux, uy, lift, k = vx, vy, vlift, bv
            x = _beyond(T, P, g)
    return ok, Side(g, c, x), Rel(ux, uy, lift, k), (n_o, n_i)


@njit(cache=True, inline="always")
def _right_wins(counts, base, left, right, bounds):
    """Whether the right candidate makes the next cross edge when both sides
    have a valid one: incircle(cl, l, r, cr) = incircle(cl, r, cr, l).
    ``left`` and ``right``: each side's candidate (a Vertex) and its Rel
    (_candidate), whose differences, lifts and cross products it reuses."""
    ul, ur = left[1], right[1]
    cl, cr = left[0], right[0]
    det = ul.lift * ur.k + base.lift * (ur.ux * ul.uy - ul.ux * ur.uy) + ur.lift * -ul.k
    ic, st = incircle_decide(det, (ul.ux, ul.uy, base.bx, base.by, ur.ux, ur.uy),
                             (ul.lift, base.lift, ur.lift),
                             (cl.x, cl.y, base.r.x, base.r.y, cr.x, cr.y, base.l.x, base.l.y),
                             bounds.icc, bounds.icc_static)
    tally_undecided(counts, INCIRCLE, st)
    return ic > 0.0


@njit(cache=True, inline="always")
def _base_case(T, P, counts, ghost_out, parts, lt, rt, l, r, A):
    """Build the merge of partitions lt and rt directly if it is a base case
    (A, A + 1: the merge's slots; l, r: the base's ends): (built, the
    result's SMALL, orient calls, in-circle calls).

    Two lone vertices make an edge, a lone vertex and such an edge a
    triangle (one orient test where the general merge makes four; see
    docs/performance.md, "small base cases"): 54% of all merges on uniform
    points.  Four points, two edges
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
        y = head(T, s1)
        s2 = ghost_out[u(y)]
        z = head(T, s2)
        s3 = ghost_out[u(z)]
        s0 = tri(inner(T, s1))  # the real triangle, across the ghost's edge
    built, oc, ic = _four(T, P, counts, ghost_out, x, y, z, v, (s0, s1, s2, s3, A, A + 1))
    return built, 0, tested + oc, ic


@njit(cache=True, inline="always")
def _copy_row(dst, i, src, j):
    """dst[i] = src[j] for partition rows, entry by entry: a row assignment
    compiles numba's shape-mismatch error path, a noticeable part of the
    first call with a cold cache (docs/performance.md, "row copies")."""
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
    that both get code specialised for them: LLVM does not unroll a loop
    over the side.  An inlined helper that loops would pay two atomic
    reference counts per array per call, so it gets borrowed views of the
    arrays (lfqt.indexing.borrow), which cost none; so does ``_base_case``,
    which does not loop but runs for every merge (docs/performance.md,
    "borrowed views").
    """
    P, T, ghost_out, fmt, level_filter = mesh
    P, T, counts, ghost_out = borrow(P), borrow(T), borrow(counts), borrow(ghost_out)
    stack = np.empty((STACK, PART), dtype=np.int64)
    parts = borrow(stack)  # the views are for the inlined helpers (see above)
    # (stack is used once more at the end: numba frees an array after its
    # last use, and a borrowed view does not keep it alive)
    # Call counts and each side's state live in scalars and tuples, not in
    # small arrays: the stores to T may alias any array, which would cost
    # reloads.  The
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
        # access (docs/performance.md, "unsigned rows")
        lt, rt, code = u(top - 1), u(top), np.int64(codes[u(op)])
        x_split = splits_x(code)
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
        bounds = _bounds(P, parts, lt, rt, code, fmt, level_filter)
        # The base's and the candidates' coordinates stay in registers (the
        # Vertexes): the predicates on the critical path then load only the
        # point they test, and each walk step loads the next one's point
        # before its own test decides (docs/performance.md, "coordinates in
        # registers").
        lv, rv = _vertex(P, l), _vertex(P, r)
        # the Walk at each end: at l the ghost of the hull edge into l
        wl = _no_walk() if parts[lt, SMALL] == 1 else _ahead(
            T, P, ring_ghost(T, ghost_out[u(l)], 0), 0)
        wr = _no_walk() if parts[rt, SMALL] == 1 else _ahead(T, P, ghost_out[u(r)], 1)
        while True:  # lower common tangent: l walks clockwise, r counter-clockwise
            moved, lv, wl, tested = _walk(T, P, counts, lv, rv, wl, 0, bounds)
            o_calls += tested
            if moved:
                continue
            moved, rv, wr, tested = _walk(T, P, counts, lv, rv, wr, 1, bounds)
            o_calls += tested
            if not moved:
                break
        l, r = lv.id, rv.id
        B = A + 1
        _splice(T, A, B, l, r)
        _splice_side(T, A, B, wl.g, 0)
        _splice_side(T, A, B, wr.g, 1)
        l_bottom = l
        # Each side's state (a Side) is carried from step to step, and only
        # the side that advanced loads it again: a cross edge writes the
        # vertices of A and the new A and link entries, never the other
        # side's ghost, candidate or the vertex beyond, so that side's chain
        # of dependent loads leaves the critical path (docs/performance.md,
        # "merge's idle side").  The advancing side's next state cannot be
        # loaded ahead: the cross edge may become the real triangle beyond
        # its next ghost.
        left = _side(T, P, A, B, 0)
        right = _side(T, P, A, B, 1)
        while True:  # the rising bubble
            bx, by = rv.x - lv.x, rv.y - lv.y
            base = Base(lv, rv, bx, by, bx * bx + by * by)
            vl, left, rel_l, calls = _candidate(T, P, counts, B, 0, left, base, bounds)
            o_calls += calls[0]
            i_calls += calls[1]
            vr, right, rel_r, calls = _candidate(T, P, counts, B, 1, right, base, bounds)
            o_calls += calls[0]
            i_calls += calls[1]
            if not vl and not vr:
                break
            to_right = vr
            if vl and vr:
                to_right = _right_wins(counts, base, (left.c, rel_l), (right.c, rel_r), bounds)
                i_calls += 1
            side = right if to_right else left
            _cross_edge(T, A, side.g, l, r, side.c.id, 1 if to_right else 0)
            A = side.g
            if to_right:
                rv = right.c
                r = rv.id
                right = _side(T, P, A, B, 1)
            else:
                lv = left.c
                l = lv.id
                left = _side(T, P, A, B, 0)
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

