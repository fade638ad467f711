"""Incremental Delaunay (Bowyer–Watson) in 2D, in a given order, and the
pieces that the 3D kernel (lfqt.incremental.tetra) shares with it: the
initial simplex, the static filters, the hull's conflict rule, the output.

Cells are rows of flat arrays: ``C[c]`` holds the d+1 vertices (input
indices), ``N[c, i]`` the cell across the face opposite vertex i.  The hull
is closed by *infinite* cells containing the vertex ``INF`` (-1), so every
face has two cells.  Finite cells are positively oriented (counter-clockwise
in 2D, right-handed in 3D); an infinite cell is oriented so that putting a
point beyond its hull facet in place of ``INF`` gives a positive cell.

Inserting p: a remembering visibility walk from the hint's cell (counting
orientation tests, paper 2's location cost), then the cavity of cells whose
circumsphere *strictly* contains p (counting them, paper 2's conflicts), then
one new cell per cavity-boundary facet.  With the strict test p lies strictly
on the cavity side of every boundary facet, even for cospherical input (the
region inside one sphere and outside-or-on the other lies strictly on one
side of their common facet), so no cell is ever flat.  An infinite cell
conflicts when p is beyond its hull facet, or on its plane and strictly
inside the facet's circumcircle.  Freed cells go to a free list; storage
doubles when full.
"""
from collections import namedtuple

import numpy as np
from numba import njit

from .. import workspace
from ..clock import cycle_counter
from ..indexing import bit, borrow, popcount, prefetch, rank, u
from ..predicates.counters import (CAVITY_CYCLES, CONFLICTS, DUPLICATES, INCIRCLE, LOCATE_CYCLES,
                                   N_INSERT, N_PREDICATE, ORIENT, tally)
from ..predicates.planar import CCW_A, ICC_A, incircle_staged, orient2d_staged
from ..predicates.spatial import ISP_A, O3D_A, box, insphere_staged, orient3d_staged, statics

INF = -1
CELLS_PER_POINT = 8  # the cell storage insert_all starts with (it doubles when full)
MAX_CELLS = 2 ** 31 - 1  # cell ids are int32: the storage grows no further
DEAD = -1  # the mark of a freed cell; live cells hold 0 or a cavity stamp (> 0)
WALK_AHEAD = 8  # points between asking for a walk's first cell and walking it


@njit(cache=True, inline="always")
def _point(P, v):
    """Point v as (x, y)."""
    return P[u(v), 0], P[u(v), 1]


@njit(cache=True, inline="always")
def _orient_pts(a, b, c, static):
    """Orientation of the points (_point) a, b, c; ``static``: a static
    filter bound (statics), np.inf for none."""
    return orient2d_staged(a[0], a[1], b[0], b[1], c[0], c[1], CCW_A, static)


@njit(cache=True, inline="always")
def _insphere_pts(a, b, c, p, static):
    """In-circle of p against a, b, c (points as _point's); ``static`` as
    in _orient_pts."""
    return incircle_staged(a[0], a[1], b[0], b[1], c[0], c[1], p[0], p[1], ICC_A, static)


@njit(cache=True)
def _inside_facet_circle(d, a, b, e, p, span):
    """p lies on the line (2D: segment a-b) or plane (3D: triangle a, b, e)
    of a hull facet: is it strictly inside the facet's circumcircle (2D: the
    open segment)?  Points as (x, y, z) tuples, z unused in 2D: scalars
    only, like every helper of the insertion loop."""
    ax, ay, az = a
    bx, by, bz = b
    ex, ey, ez = e
    px, py, pz = p
    if d == 2:
        if min(ax, bx) < max(ax, bx):
            return min(ax, bx) < px < max(ax, bx)
        return min(ay, by) < py < max(ay, by)
    # Any sphere through a, b, e meets their plane in their circumcircle: use
    # one through a point q off the plane (found exactly among three offsets).
    for axis in range(3):
        qx = ax + span if axis == 0 else ax
        qy = ay + span if axis == 1 else ay
        qz = az + span if axis == 2 else az
        q = (qx, qy, qz)
        o, st = orient3d_staged(a, b, e, q, O3D_A)
        if o != 0.0:
            s, st = insphere_staged(a, b, e, q, p, ISP_A)
            return s * o > 0.0
    return False


@njit(cache=True)
def _initial_simplex(P, d, perm):
    """Positions in ``perm`` of the first d+1 affinely independent points, or
    (-1, ...) when there are none (all equal / collinear / coplanar)."""
    n = perm.shape[0]
    pick = np.full(4, -1, dtype=np.int64)
    if n == 0:
        return pick
    pick[0] = 0
    k = 1
    for t in range(1, n):
        q = perm[t]
        if k == 1:
            a = perm[pick[0]]
            if P[a, 0] != P[q, 0] or P[a, 1] != P[q, 1] or P[a, d - 1] != P[q, d - 1]:
                pick[1] = t
                k = 2
        elif k == 2:
            a = perm[pick[0]]
            b = perm[pick[1]]
            collinear = True
            for ax in range(3 if d == 3 else 1):
                i0, i1 = (0, 1) if ax == 0 else ((0, 2) if ax == 1 else (1, 2))
                o, st = orient2d_staged(P[a, i0], P[a, i1], P[b, i0], P[b, i1],
                                        P[q, i0], P[q, i1], CCW_A)
                if o != 0.0:
                    collinear = False
            if not collinear:
                pick[2] = t
                k = 3
                if d == 2:
                    return pick
        else:
            a, b, c = perm[pick[0]], perm[pick[1]], perm[pick[2]]
            o, st = orient3d_staged((P[u(a), 0], P[u(a), 1], P[u(a), 2]),
                                    (P[u(b), 0], P[u(b), 1], P[u(b), 2]),
                                    (P[u(c), 0], P[u(c), 1], P[u(c), 2]),
                                    (P[u(q), 0], P[u(q), 1], P[u(q), 2]), O3D_A, np.inf)
            if o != 0.0:
                pick[3] = t
                return pick
    pick[:] = -1
    return pick


# The cell storage and the cavity scratch, passed to the kernels as two
# tuples: C (m, 3) vertices, N (m, 3) neighbours and mark (cavity stamps,
# DEAD for a freed cell), three views of one record per cell (_records);
# vcell (a live cell of each vertex), free (the free list); stack and slots
# (the depth-first search), conflicts, bcell/bface (cavity-boundary facets).
Cells = namedtuple("Cells", "C N mark vcell free")
# insert_all's result: the live and dead cells' rows C and N and marks (DEAD
# for a freed cell), their count, dup_of, counts, ok, and the records that
# they are views of (None once the storage grew past them): finite_cells
# writes over them
Insertion = namedtuple("Insertion", "C N mark ncells dup_of counts ok records")
Inserted = namedtuple("Inserted", Insertion._fields[:-1])  # _insert_all's: all but records
Scratch = namedtuple("Scratch", "stack slots conflicts bcell bface")
# state: (cells in use, free-list length, cavity stamp, last inserted point)
NCELLS, NFREE, STAMP, LAST = range(4)


@njit(cache=True, inline="always")
def _orient_ids(P, v0, v1, v2, static):
    """Orientation of the points v0, v1, v2."""
    return _orient_pts(_point(P, v0), _point(P, v1), _point(P, v2), static)


@njit(cache=True, inline="always")
def _with_p(C, c, i, p):
    """The vertices of cell c with vertex i replaced by p."""
    v0 = p if i == 0 else C[u(c), 0]
    v1 = p if i == 1 else C[u(c), 1]
    v2 = p if i == 2 else C[u(c), 2]
    return v0, v1, v2


@njit(cache=True, inline="always")
def _infinite_slot(C, width, c):
    """The slot of INF in cell c, or -1 for a finite cell."""
    f = -1
    for k in range(width):
        if C[u(c), u(k)] == INF:
            f = k
    return f


@njit(cache=True, inline="always")
def _duplicate_in(P, C, c, p):
    """The vertex of cell c at p's position, or -1."""
    for i in range(3):
        v = C[u(c), u(i)]
        if P[u(v), 0] == P[u(p), 0] and P[u(v), 1] == P[u(p), 1]:
            return v
    return -1


@njit(cache=True, inline="always")
def _conflicts(P, C, y, p, span, static):
    """Does triangle y conflict with p: (a finite triangle whose circumcircle
    strictly contains p, or an infinite one with p beyond its hull edge, or
    on its line and strictly inside the edge; the in-circle test's deciding
    stage, 0 for an infinite triangle, which makes none).  Every array read
    comes before the predicates: an array used after a call that numba does
    not inline keeps its atomic reference count alive."""
    f = _infinite_slot(C, 3, y)
    if f < 0:
        a, b, e = C[u(y), 0], C[u(y), 1], C[u(y), 2]
        sv, st = _insphere_pts(_point(P, a), _point(P, b), _point(P, e), _point(P, p), static[1])
        return sv > 0.0, st
    v0, v1, v2 = _with_p(C, y, f, p)
    (ax, ay), (bx, by) = _point(P, C[u(y), u((f + 1) % 3)]), _point(P, C[u(y), u((f + 2) % 3)])
    px, py = _point(P, p)
    o, st = _orient_ids(P, v0, v1, v2, static[0])
    if o != 0.0:
        return o > 0.0, 0
    # _inside_facet_circle, shared with the 3D kernel, takes (x, y, z) points
    # and a third facet vertex: in 2D it reads neither z nor that vertex
    a = (ax, ay, ay)
    return _inside_facet_circle(2, a, (bx, by, by), a, (px, py, py), span), 0


@njit(cache=True, inline="always")
def _new_triangle(C, N, mark, vcell, w, x, i, p):
    """Triangle w = (p, a, b) for the edge a -> b of cavity triangle x
    opposite its slot i, glued to the triangle outside that edge; its
    slots 1 and 2 are left to the caller (the triangles before and after
    it around p).  With p in a fixed slot: the cavity triangle with p in
    slot i, and the ring glued through slots i + 1, i + 2, measured slower
    (docs/performance.md, "2D triangles with p in slot 0")."""
    a = C[u(x), u(i + 1 if i < 2 else 0)]
    b = C[u(x), u(i - 1 if i > 0 else 2)]
    y = N[u(x), u(i)]
    mark[u(w)] = 0
    C[u(w), 0] = p
    C[u(w), 1] = a
    C[u(w), 2] = b
    N[u(w), 0] = y
    for k in range(3):
        if N[u(y), u(k)] == x:
            N[u(y), u(k)] = w
    vcell[u(p)] = w
    if a >= 0:
        vcell[u(a)] = w
    if b >= 0:
        vcell[u(b)] = w


@njit(cache=True, inline="always")
def _ask_for_walk_start(C, vcell, hint, t):
    """Ask the caches for the record of the cell that the walk of the t-th
    point will start in, its hint's; by then the cell may be gone (it is a
    hint, like the hint itself).  Cell ids come from the free list, so that
    record is a miss wherever the points are."""
    h = hint[u(t)]
    prefetch(C, np.int64(vcell[u(h)] if h >= 0 else 0))


@njit(cache=True, inline="always")
def phase_cycles(counts, c_start, c_located):
    """Count a point's walk (c_start to c_located) and cavity (on to now)."""
    counts[LOCATE_CYCLES] += c_located - c_start
    counts[CAVITY_CYCLES] += cycle_counter() - c_located


@njit(cache=True, inline="always")
def _commit(counts, pending):
    """Add a point's counts to the totals and clear them."""
    for k in range(N_PREDICATE):
        counts[k] += pending[k]
        pending[k] = 0


# An insertion run's order and what it keeps between its range kernels:
# perm, hint and pick (the initial simplex's positions in perm), state (below),
# counts, dup_of, and the filters' span and static bounds (statics).
Run = namedtuple("Run", "perm hint pick state counts dup_of span static")


# _insert_range inserts perm[t0:] until done (returns (n, 0)) or until the
# cell arrays (reason 1) or the cavity scratch (2) are too small for the next
# point, before touching it; it returns (t, reason) to resume after growing.
#
# Each point goes through four steps, one inlined helper each: the walk
# (_locate), the cavity (_cavity), the new triangles (_fill_2d) and
# the freeing of the cavity's cells (_free).  The helpers loop over arrays:
# they get borrowed views of them (lfqt.indexing.borrow), since an inlined
# helper that loops pays numba two atomic reference counts per array and
# call otherwise (docs/performance.md, "insertion's helpers").  No array is
# reassigned in them for the same reason.  Indices go through ``u``
# (lfqt.indexing).
@njit(cache=True)
def _insert_range(P, run, t0, cells, scratch, timing):
    """Insert perm[t0:] (see above)."""
    perm, hint, pick, dup_of = run.perm, run.hint, run.pick, run.dup_of
    state, counts = borrow(run.state), borrow(run.counts)
    cells = Cells(borrow(cells.C), borrow(cells.N), borrow(cells.mark), borrow(cells.vcell),
                  borrow(cells.free))
    scratch = Scratch(borrow(scratch.stack), borrow(scratch.slots), borrow(scratch.conflicts),
                      borrow(scratch.bcell), borrow(scratch.bface))
    C, vcell = cells.C, cells.vcell
    n = perm.shape[0]
    pending = np.zeros(N_PREDICATE, dtype=np.int64)  # this point's counts, kept if it goes in
    rnd = np.uint64(88172645463325252 + t0)
    for t in range(t0, n):
        if pick[0] == t or pick[1] == t or pick[2] == t:
            continue  # a vertex of the initial simplex
        _ask_for_walk_start(C, vcell, hint, min(t + WALK_AHEAD, n - 1))
        p = perm[u(t)]
        h = hint[u(t)]
        c = vcell[u(h)] if h >= 0 and vcell[u(h)] >= 0 else vcell[u(state[LAST])]
        c_start = cycle_counter() if timing else 0
        c, rnd = _locate(P, cells, c, p, rnd, run.static, borrow(pending))
        c_located = cycle_counter() if timing else 0
        dup = -1 if _infinite_slot(C, 3, c) >= 0 else _duplicate_in(P, C, c, p)
        if dup >= 0:
            dup_of[u(p)] = dup
            counts[DUPLICATES] += 1
            _commit(counts, pending)
            continue
        state[STAMP] += 2
        nconf, nb_count, small = _cavity(P, cells, scratch, c, p, state[STAMP], run.span,
                                         run.static, borrow(pending))
        if small:
            pending[:] = 0  # nothing is modified yet: this point is retried after growing
            return t, 2
        if state[NCELLS] + max(nb_count - state[NFREE], 0) > C.shape[0]:
            pending[:] = 0
            return t, 1
        _new_ids(cells, state, scratch.stack, nb_count)
        _fill_2d(cells, scratch, nb_count, p)
        _free(cells, state, scratch.conflicts, nconf)
        counts[CONFLICTS] += nconf
        _commit(counts, pending)
        state[LAST] = p
        if timing:
            phase_cycles(counts, c_start, c_located)
    return n, 0


@njit(cache=True, inline="always")
def _locate(P, cells, c, p, rnd, static, pending):
    """The cell containing p: (that cell, the walk's random state).  A
    remembering visibility walk from cell c, or from the finite cell next to
    it; each step crosses the first face, from a random one on, that p lies
    beyond (which keeps the walk from cycling).  Its orient tests go to
    ``pending``."""
    C, N = cells.C, cells.N
    f = _infinite_slot(C, 3, c)
    if f >= 0:
        c = N[u(c), u(f)]
    prev = -1
    moved = True
    while moved and _infinite_slot(C, 3, c) < 0:
        rnd ^= rnd << np.uint64(13)
        rnd ^= rnd >> np.uint64(7)
        rnd ^= rnd << np.uint64(17)
        rot = np.int64(rnd % np.uint64(3))  # a random first face
        moved = False
        for q in range(3):
            i = q + rot if q + rot < 3 else q + rot - 3
            nb = N[u(c), u(i)]
            if nb == prev:
                continue
            v0, v1, v2 = _with_p(C, c, i, p)
            o, st = _orient_ids(P, v0, v1, v2, static[0])
            pending[ORIENT] += 1
            if o < 0.0:
                prev, c, moved = c, nb, True
                break
    return c, rnd


# The cavity: cells whose circumsphere strictly contains p (marked stamp;
# cells found outside it stamp + 1), depth first.  When a cell joins the
# cavity, the records and marks of its neighbours are asked for at once: they
# are read next, and the mark of a cell off the free list is a cache miss
# (docs/performance.md, "cavity prefetch").  A stack entry is a cell and the
# faces it has left to look across, as (count << 2) | next slot.  A cell
# entered from x looks across its two other edges in counter-clockwise
# order, x's slot + 1 then + 2: the cavity's cells form a tree (no vertex is
# inside it), so the boundary edges come out in counter-clockwise order
# around p, which glues the new triangles in a ring without a table.  With p
# in x, below the edge a-b, counter-clockwise around p runs from a (right)
# over w to b (left):
#
#              w          y, entered across b-a from x:
#            /   \          its slot j+1: edge a-w, then
#           b --- a        its slot j+2: edge w-b
#              x           (j: the slot of w, opposite x)
#              p
@njit(cache=True, inline="always")
def _cavity(P, cells, scratch, c, p, stamp, span, static, pending):
    """The cavity of p from cell c (see above): (its cells, in
    scratch.conflicts, the number of its boundary edges, each the edge
    scratch.bface of the cavity cell scratch.bcell, and whether the
    scratch was too small).  Its in-circle tests go to ``pending``."""
    N, mark = cells.N, cells.mark
    stack, slots, conflicts, bcell, bface = (scratch.stack, scratch.slots, scratch.conflicts,
                                             scratch.bcell, scratch.bface)
    nstack, nconf, nb_count, small = 1, 1, 0, False
    stack[0] = c
    slots[0] = 3 << 2  # the first cell looks across all its edges
    conflicts[0] = c
    mark[u(c)] = stamp
    while nstack > 0 and not small:
        x = stack[u(nstack - 1)]
        code = slots[u(nstack - 1)]
        if code < 4:
            nstack -= 1
            continue
        i = code & 3
        slots[u(nstack - 1)] = code - 4 + (1 if i < 2 else -2)
        y = N[u(x), u(i)]
        if mark[u(y)] == stamp:
            continue
        conflict = False
        if mark[u(y)] != stamp + 1:
            conflict, st = _conflicts(P, cells.C, y, p, span, static)
            if st > 0:
                tally(pending, INCIRCLE, st)
        if conflict:
            small = nstack == stack.shape[0] or nconf == conflicts.shape[0]
            if small:
                break
            mark[u(y)] = stamp
            conflicts[u(nconf)] = y
            nconf += 1
            stack[u(nstack)] = y
            for k in range(3):  # y's neighbours are read next (see above)
                prefetch(cells.C, np.int64(N[u(y), u(k)]))
                prefetch(mark, np.int64(N[u(y), u(k)]))
            j = 0 if N[u(y), 0] == x else (1 if N[u(y), 1] == x else 2)
            slots[u(nstack)] = (2 << 2) | (j + 1 if j < 2 else 0)
            nstack += 1
        else:
            mark[u(y)] = stamp + 1
            small = nb_count == bcell.shape[0]
            if small:
                break
            bcell[u(nb_count)] = x
            bface[u(nb_count)] = i
            nb_count += 1
    return nconf, nb_count, small


@njit(cache=True, inline="always")
def _new_ids(cells, state, ids, count):
    """ids[:count]: the ids of ``count`` new cells, off the free list first."""
    for b in range(count):
        if state[NFREE] > 0:
            state[NFREE] -= 1
            ids[u(b)] = cells.free[u(state[NFREE])]
        else:
            ids[u(b)] = state[NCELLS]
            state[NCELLS] += 1


@njit(cache=True, inline="always")
def _fill_2d(cells, scratch, count, p):
    """The new triangles (p, a, b), one per boundary edge a -> b of the
    cavity (in counter-clockwise order around p, _cavity), in the cells
    scratch.stack[:count]: each glued to the next one across b-p (slot 1)
    and to the previous one across p-a (slot 2)."""
    C, N, mark, vcell = cells.C, cells.N, cells.mark, cells.vcell
    ids = scratch.stack
    for b in range(count):
        _new_triangle(C, N, mark, vcell, ids[u(b)], scratch.bcell[u(b)], scratch.bface[u(b)], p)
    for b in range(count):
        w = ids[u(b)]
        N[u(w), 1] = ids[u(b + 1 if b + 1 < count else 0)]
        N[u(w), 2] = ids[u(b - 1 if b > 0 else count - 1)]


@njit(cache=True, inline="always")
def _free(cells, state, conflicts, count):
    """Free the cavity's cells conflicts[:count]: marked DEAD, onto the free
    list."""
    for q in range(count):
        cells.mark[u(conflicts[u(q)])] = DEAD
        cells.free[u(state[NFREE])] = conflicts[u(q)]
        state[NFREE] += 1


@njit(cache=True)
def _records(R, width):
    """C, N and mark: views of the records R, one row of int32 per cell, so
    that a visit to a cell reads one cache line, not one per array:

        cell c:  | v0 v1 v2 | n0 n1 n2 | mark |
                   C[c]       N[c]       mark[c]

    Rows are written when their cell is made (_new_triangle, _start)."""
    return R[:, :width], R[:, width:2 * width], R[:, 2 * width]


@njit(cache=True)
def _record_shape(cap, width):
    """The shape of the records of ``cap`` cells (_records)."""
    return cap, 2 * width + 1


@njit(cache=True)
def _grown(cells, size):
    """The cell storage at ``size`` cells (vcell is per point: kept).  In
    the kernel, on 4 KB pages (insert_all): growth is rare, since the
    storage starts at CELLS_PER_POINT cells per point."""
    C, N, mark, vcell, free = cells
    m = C.shape[0]
    C2, N2, mark2 = _records(np.empty(_record_shape(size, C.shape[1]), dtype=np.int32), C.shape[1])
    # entry by entry: a slice assignment (C2[:m] = C) compiles numba's
    # shape-mismatch error path (docs/performance.md, "row copies")
    for c in range(m):
        for k in range(C.shape[1]):
            C2[c, k] = C[c, k]
            N2[c, k] = N[c, k]
        mark2[c] = mark[c]
    return Cells(C2, N2, mark2, vcell, np.concatenate((free, np.empty(size - m, dtype=np.int32))))


@njit(cache=True)
def _new_scratch(size):
    """Cavity scratch for ``size`` cells."""
    return Scratch(np.empty(size, dtype=np.int64), np.empty(size, dtype=np.int64),
                   np.empty(size, dtype=np.int64),
                   np.empty(size, dtype=np.int64), np.empty(size, dtype=np.int64))


@njit(cache=True)
def _start(P, s, cells):
    """The triangle of the points s (3 ids, reordered to be positive) and
    its 3 infinite cells, all glued: returns the number of cells."""
    C, N, mark, vcell = cells.C, cells.N, cells.mark, cells.vcell
    width = 3
    o, st = _orient_ids(P, s[0], s[1], s[2], np.inf)
    if o < 0.0:
        s[0], s[1] = s[1], s[0]
    for k in range(width):
        C[0, k] = s[k]
    for i in range(width):
        c = 1 + i
        for k in range(width):
            C[c, k] = s[k]
        C[c, i] = INF
        # beyond facet i means on the other side from s[i]: swap two finite slots
        j0 = (i + 1) % width
        j1 = (i + 2) % width
        C[c, j0], C[c, j1] = C[c, j1], C[c, j0]
    ncells = width + 1
    for c in range(ncells):
        mark[c] = 0
    for c in range(ncells):
        for i in range(width):
            # neighbour across face i: the other cell holding all of c's vertices but C[c, i]
            for c2 in range(ncells):
                if c2 == c:
                    continue
                shared = 0
                for k in range(width):
                    if k == i:
                        continue
                    for k2 in range(width):
                        if C[c2, k2] == C[c, k]:
                            shared += 1
                if shared == width - 1:
                    N[c, i] = c2
    for k in range(width):
        vcell[s[k]] = 0
    return ncells


def relabel(perm, hint, store):
    """Renumber perm and hint, in place, by the points' places in ``store``
    (rank[store[k]] = k), the numbering insert_all's points come in; a hint
    of -1 stays -1.  One pass each, and no new arrays but the ranks, where
    numpy's scatter, gathers and where made several (docs/performance.md,
    "relabel")."""
    _relabel(perm, hint, store, np.empty(len(store), dtype=store.dtype))


@njit(cache=True)
def _relabel(perm, hint, store, rank):
    for k in range(store.shape[0]):
        rank[u(store[k])] = k
    for k in range(store.shape[0]):
        perm[k] = rank[u(perm[k])]
        hint[k] = rank[u(hint[k])] if hint[k] >= 0 else -1


def duplicate_of(store, dup_rank):
    """insert_all's duplicates, numbered by storage rank (dup_rank), in
    input indices: dup_of[store[k]] = store[dup_rank[k]]."""
    dup_of = np.empty(len(store), dtype=np.int64)
    _duplicate_of(store, dup_rank, dup_of)
    return dup_of


@njit(cache=True)
def _duplicate_of(store, dup_rank, dup_of):
    for k in range(store.shape[0]):
        dup_of[u(store[k])] = store[u(dup_rank[k])]


def coordinate_span(P, largest=None):
    """The largest |coordinate| of the (rescaled) points, at least 1: the
    scale insert_all's ``span`` expects.  ``largest``: that |coordinate|,
    when the caller knows it (lfqt._input.exact_points)."""
    return max(1.0, float(np.abs(P).max(initial=0.0)) if largest is None else largest)


def insert_all(P, perm, hint, span, capacity=0, max_cells=MAX_CELLS, timing=False):
    """Insert the 2D points P[perm] one by one (3D points go to
    lfqt.incremental.tetra.insert_all); returns an Insertion (C, N, mark,
    ncells, dup_of, counts, ok, records).  ok is False when the points are
    collinear.  Raises ValueError when the triangulation needs more than
    ``max_cells`` cells.
    ``capacity``: the cells to start with (CELLS_PER_POINT per point by
    default).  ``timing``: count the cycles of the walks and of the cavities
    (counts' LOCATE_CYCLES, CAVITY_CYCLES; three reads of the cycle counter
    per point, which cost a few percent of a 2D insertion:
    docs/performance.md, "phase cycles").

    The arrays of a size in points or cells come from lfqt.workspace, here,
    not from the kernel, on transparent huge pages where they pay
    (lfqt.pages.huge_pays), where numba's allocations would fault in 4 KB at a time
    on every call (docs/performance.md, "insertion's pages"), and on the
    mappings of earlier calls' freed results where there are."""
    if P.shape[1] != 2:
        raise ValueError(f"the 2D insertion kernel got {P.shape[1]}D points "
                         "(3D: tetra.insert_all)")
    n = P.shape[0]
    cap = capacity if capacity > 0 else max(16, CELLS_PER_POINT * n)
    vcell = workspace.empty(n, np.int32)
    vcell.fill(-1)
    records = workspace.empty(_record_shape(cap, 3), np.int32)
    cells = Cells(*_records(records, 3), vcell, workspace.empty(cap, np.int32))
    out = _insert_all(P, (perm, hint), span, cells, np.arange(n), max_cells, timing)
    grown = out.C.__array_interface__["data"][0] != records.__array_interface__["data"][0]
    return Insertion(*out, None if grown else records)


@njit(cache=True, nogil=True)
def _insert_all(P, order, span, cells, dup_of, max_cells, timing):
    """insert_all's kernel, into ``cells`` (growing them when full), in
    ``order`` = (perm, hint); dup_of starts as the identity.  Returns an
    Inserted."""
    perm, hint = order
    counts = np.zeros(N_INSERT, dtype=np.int64)
    pick = _initial_simplex(P, 2, perm)
    ok = pick[0] >= 0 and pick[2] >= 0
    m = np.int64(0)
    if ok:
        s = np.empty(3, dtype=np.int64)
        for k in range(3):
            s[k] = perm[pick[k]]
        state = np.array([_start(P, s, cells), 0, 0, s[0]], dtype=np.int64)
        # np.int64, not a literal: a literal argument would compile the callee
        # once for it and again for the int64 the loop passes back (numba)
        scratch = _new_scratch(np.int64(256))  # doubled whenever a cavity needs more
        lo, hi = box(P, 2)
        run = Run(perm, hint, pick, state, counts, dup_of, span, statics(lo, hi, 2))
        t = np.int64(0)
        while True:
            t, reason = _insert_range(P, run, t, cells, scratch, timing)
            if reason == 0:
                break
            if reason == 1:
                cap = cells.C.shape[0]
                if cap >= max_cells:
                    raise ValueError("the triangulation needs more cells than int32 ids can "
                                     "number")
                cells = _grown(cells, min(2 * cap, max_cells))
            else:
                scratch = _new_scratch(2 * scratch.stack.shape[0])
        m = state[NCELLS]
    return Inserted(cells.C[:m], cells.N[:m], cells.mark[:m], m, dup_of, counts, ok)


def finite_cells(C, N, mark, ids, records=None, shift=0, workers=None):
    """(simplices, neighbors, facets) of the live cells (``mark`` not
    DEAD): the finite ones with vertices mapped through ``ids``, neighbours
    renumbered, -1 across the hull, and the hull's facets, oriented
    outward, one per infinite cell (2D: edges, which the caller chains into
    a loop).  A cell's new id is its rank in a bitmap of the finite cells
    (lfqt.indexing.rank): the neighbours point anywhere in C, and a bit per
    cell plus a count per 64 stay in cache where an id per cell would not.

    With ``records``, the array that C and N are rows of (insert_all's),
    the simplices are written over its first bytes, and its pages past them
    given back (lfqt.workspace.keep_prefix).  The pass reads each cell's record
    before any simplex row lands on it: row j of the simplices, j <= c,
    ends at byte 4 * width * (j + 1), at most where record c starts,
    4 * (2 * width + 1) * c, from c = 1 on, and row 0 writes only cell 0's
    own vertices, each after reading it::

        records    | cell 0        | cell 1        | cell 2        | ...
        simplices  | 0   | 1   | 2   | ...   (1M points, 3D: 104 MB not faulted in)

    ``shift``: the neighbour of a cell is ``N >> shift`` (3D records hold
    facet refs, 4 t + i).  ``workers`` (lfqt.workers.Workers of more than
    one thread): both passes by ranges of cells on its threads, the
    simplices beside the records, since a range's rows would land on
    records another range has still to read.
    """
    if workers is not None and workers.threads > 1:
        return _finite_cells_parallel(C, N, mark, ids, shift, workers)
    bits, first, finite, live = _finite_bitmap(C, mark)
    width = C.shape[1]
    neighbors = workspace.empty((finite, width), np.int32)
    facets = np.empty((live - finite, width - 1), dtype=np.int64)
    if records is None:
        simplices = workspace.empty((finite, width), np.int32)
    else:
        flat = records.reshape(-1)
        simplices = flat[:finite * width].reshape(finite, width)
    _cells_rows(C, N, mark, ids, bits, first, (simplices, neighbors, facets), shift,
                (0, C.shape[0], 0, 0))
    if records is not None:
        simplices = workspace.keep_prefix(flat, finite * width).reshape(finite, width)
    return simplices, neighbors, facets


@njit(cache=True)
def _finite_bitmap(C, mark):
    """(bits, first, finite, live): a bit per cell, set for the live finite
    ones, the finite cells before each word of 64, and the counts
    (_bitmap_words over all the words)."""
    nwords = (C.shape[0] + 63) >> 6
    bits = np.empty(nwords, dtype=np.uint64)
    first = np.empty(nwords, dtype=np.int64)
    finite, live = _bitmap_words(C, mark, bits, first, 0, nwords)
    return bits, first, finite, live


# Cells come in the order they were made, which follows the insertion order
# across space, so the vertex ids of one cell and the next are far apart in
# ``ids``: the cell OUTPUT_AHEAD rows on asks for two of its vertices' entries
# (the third shares their cache lines, mostly; docs/performance.md,
# "output prefetch").
OUTPUT_AHEAD = 32


def _finite_cells_parallel(C, N, mark, ids, shift, workers):
    """finite_cells on the workers' threads (see there)."""
    m, width = C.shape
    nwords = (m + 63) >> 6
    bits = np.empty(nwords, dtype=np.uint64)
    first = np.empty(nwords, dtype=np.int64)
    chunks = workers.chunks(nwords, 1 << 12)
    counts = workers.map(chunks, lambda k, lo, hi: _bitmap_words(C, mark, bits, first, lo, hi))
    finite = sum(f for f, _ in counts)
    live = sum(v for _, v in counts)
    starts = np.cumsum([(0, 0)] + [list(c) for c in counts], axis=0)  # (finite, live) before
    neighbors = workspace.empty((finite, width), np.int32, populate=workers)
    simplices = workspace.empty((finite, width), np.int32, populate=workers)
    facets = np.empty((live - finite, width - 1), dtype=np.int64)
    out = (simplices, neighbors, facets)
    # every word's first is final before any range ranks a neighbour in it
    for k, (lo, hi) in enumerate(chunks):
        first[lo:hi] += int(starts[k][0])
    workers.map(chunks, lambda k, lo, hi: _cells_rows(
        C, N, mark, ids, bits, first, out, shift,
        (64 * lo, min(64 * hi, m), int(starts[k][0]), int(starts[k][1] - starts[k][0]))))
    return simplices, neighbors, facets


@njit(cache=True, nogil=True)
def _bitmap_words(C, mark, bits, first, lo, hi):
    """The finite bitmap over the words [lo, hi): their bits, each word's
    finite cells before it counted from lo; returns (finite, live) there.
    One pass over the records, without a branch: a cell is finite when no
    vertex is INF (-1), that is, when the OR of its vertices is not
    negative (docs/performance.md, "finite bitmap")."""
    m = C.shape[0]
    width = C.shape[1]
    k = 0
    live = 0
    for w in range(lo, hi):
        word = np.uint64(0)
        for c in range(64 * w, min(64 * w + 64, m)):
            alive = np.int64(mark[u(c)] != DEAD)
            vertices = C[u(c), 0] | C[u(c), 1] | C[u(c), 2]
            if width == 4:
                vertices |= C[u(c), 3]
            live += alive
            word |= np.uint64(alive & np.int64(vertices >= 0)) << np.uint64(c & 63)
        bits[u(w)] = word
        first[u(w)] = k
        k += popcount(word)
    return k, live


@njit(cache=True, nogil=True)
def _cells_rows(C, N, mark, ids, bits, first, out, shift, span):
    """finite_cells' rows out = (simplices, neighbors, facets) of the cells
    span = (lo, hi, their first row, their first hull facet)."""
    simplices, neighbors, facets = out
    lo, hi, j, n_inf = span
    width = C.shape[1]
    for c in range(lo, hi):
        ahead = min(c + OUTPUT_AHEAD, hi - 1)
        prefetch(ids, np.int64(C[u(ahead), 0]))
        prefetch(ids, np.int64(C[u(ahead), 1]))
        if not bit(bits, c):
            if mark[u(c)] != DEAD:
                _hull_facet(C, c, ids, facets, n_inf)
                n_inf += 1
            continue
        for i in range(width):
            simplices[u(j), u(i)] = ids[u(C[u(c), u(i)])]
            nb = N[u(c), u(i)] >> shift
            neighbors[u(j), u(i)] = rank(bits, first, nb) if bit(bits, nb) else -1
        j += 1



@njit(cache=True, inline="always")
def _hull_facet(C, c, ids, facets, k):
    """facets[k]: the hull facet of infinite cell c, oriented outward."""
    width = C.shape[1]
    f = _infinite_slot(C, width, c)
    # the infinite cell with INF -> beyond-point is positive: its facet,
    # in cyclic order after f, faces outward
    for j in range(width - 1):
        facets[k, j] = ids[C[c, (f + 1 + j) % width]]
    if width == 4 and f % 2 == 0:
        # rotating a 4-tuple by f+1 places is odd when f is even
        t = facets[k, 0]
        facets[k, 0] = facets[k, 1]
        facets[k, 1] = t
