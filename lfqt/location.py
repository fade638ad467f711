"""Exact point location in a 2D or 3D Delaunay triangulation: which simplex
contains a query, with exact orientation tests, so that the answer always
contains the query (-1: outside the hull).

A query is *beyond* the facet of simplex t opposite vertex i when the simplex
with vertex i replaced by the query is negatively oriented (simplices are
counter-clockwise in 2D, right-handed in 3D)::

        c                      q beyond the edge opposite a:
       / \\                     orient(q, b, c) < 0
      /   \\    q
     a-----b

The visibility walk steps through such a facet until there is none; on a
Delaunay triangulation it terminates in any dimension (Edelsbrunner).  The
brute force tests every simplex whose bounding box holds the query.

Coordinates are in the rescaled frame of the triangulation (lfqt._input).  A
query component too small for that frame (below its floor, 2**-188 in 2D) is
split off: the query is q = H + L, with H in the frame and L tiny.  An
orientation with q in slot i is affine in q, (q - a).g for a vertex a and
the facet's normal g, so its value is E1 + E2 with E1 = (H - a).g, exact in
the frame, and E2 = L.g, exact once L is scaled up by 2**TINY_SHIFT::

        sign(E1 + E2):  |E1| >> |E2|  ->  sign(E1)
                        |E2| >> |E1|  ->  sign(E2)
                        else          ->  sign(E1 * 2**K + E2 * 2**K)

(``_beyond_tiny``).  Only a frame too far from the query's magnitude for
that shift (data above about 2**300 with subnormal queries) leaves the
query to ``locate_rational``, in Python's rationals.

``tol`` (scipy's tolerance, in barycentric coordinates and floating point)
is answered near the hull: a query outside every simplex is walked to a hull
facet it sees, and the simplices around the vertices of the hull facets it
sees are its candidates (``locate_tolerant``); no call scans every simplex.
"""
import math
from fractions import Fraction

import numpy as np
from numba import njit

from .predicates.expansion import (EPS, cross_exact, exact_diff, expansion_product,
                                   expansion_sum, scale_expansion)
from .predicates.planar import CCW_A, orient2d_staged
from .predicates.spatial import O3D_A, orient3d_staged, statics, widened
from .morton import spread_bits
from .radix import sort_keys
from .workers import Workers

TINY_SHIFT = 600  # K above: the tiny parts' scale-up (derivation in tiny_frame_ok)
HULL_FACETS = 64  # hull facets a tolerant query looks at, at most
STAR = 512        # simplices around one vertex, at most (a 3D star has about 27)
SEEN = 4096       # simplices a tolerant query evaluates, at most


@njit(cache=True, inline="always")
def _vertex(P, v, qx, qy, qz, replaced):
    if replaced:
        return qx, qy, qz
    return P[v, 0], P[v, 1], P[v, 2]


@njit(cache=True, inline="always")
def _edge(S, t, i):
    """The edge of triangle t opposite vertex i, counter-clockwise: (a, b)
    with orient(a, b, q) < 0 when q lies beyond it."""
    return S[t, i + 1 if i < 2 else 0], S[t, i + 2 if i < 1 else i - 1]


@njit(cache=True, inline="always")
def _others(S, t, i):
    """The vertices of tetrahedron t but vertex i, in slot order."""
    return S[t, 1 if i == 0 else 0], S[t, 2 if i <= 1 else 1], S[t, 3 if i <= 2 else 2]


@njit(cache=True, inline="always")
def _beyond(P, S, t, i, qx, qy, qz):
    """True when q lies strictly beyond the facet of simplex t opposite
    vertex i.  Scalars only: an array argument here would cost an atomic
    reference-count update per test (lfqt.predicates.planar)."""
    if P.shape[1] == 2:
        a, b = _edge(S, t, i)
        o, _ = orient2d_staged(P[a, 0], P[a, 1], P[b, 0], P[b, 1], qx, qy, CCW_A)
        return o < 0.0
    ax, ay, az = _vertex(P, S[t, 0], qx, qy, qz, i == 0)
    bx, by, bz = _vertex(P, S[t, 1], qx, qy, qz, i == 1)
    cx, cy, cz = _vertex(P, S[t, 2], qx, qy, qz, i == 2)
    dx, dy, dz = _vertex(P, S[t, 3], qx, qy, qz, i == 3)
    o, _ = orient3d_staged((ax, ay, az), (bx, by, bz), (cx, cy, cz), (dx, dy, dz), O3D_A)
    return o < 0.0


@njit(cache=True, inline="always")
def _query(Q, k):
    return Q[k, 0], Q[k, 1], Q[k, Q.shape[1] - 1]


@njit(cache=True, nogil=True)
def _contains(P, S, t, qx, qy, qz):
    for i in range(S.shape[1]):
        if _beyond(P, S, t, i, qx, qy, qz):
            return False
    return True


@njit(cache=True, inline="always")
def _step2(P, S, t, qx, qy, static):
    """The edge of triangle t that q lies farthest beyond, or -1 (q is in
    t).  The three orientations are evaluated together, each with q as the
    origin (one set of differences), and certified by ``static``
    (walk_static) or else by stage A's bound (``orient2d_staged``); only an
    uncertain one is decided again, exactly.  No branch per edge: on a
    large mesh the walk waits on memory and on mispredicted branches, not
    on arithmetic.  The edge the walk came
    through is never chosen (q is on its other side, or on it), and on a
    Delaunay triangulation any choice among the edges q is beyond ends
    (Edelsbrunner), the farthest one in fewer steps::

            c
           / \\        edge i is the one opposite corner i:
          1   0       0 = b -> c, 1 = c -> a, 2 = a -> b
         /     \\
        a---2---b
    """
    a, b, c = S[t, 0], S[t, 1], S[t, 2]
    ax, ay, bx, by, cx, cy = P[a, 0], P[a, 1], P[b, 0], P[b, 1], P[c, 0], P[c, 1]
    aqx, aqy, bqx, bqy, cqx, cqy = ax - qx, ay - qy, bx - qx, by - qy, cx - qx, cy - qy
    # orient(b, c, q), orient(c, a, q), orient(a, b, q) as orient2d_staged forms them
    u0, v0 = bqx * cqy, bqy * cqx
    u1, v1 = cqx * aqy, cqy * aqx
    u2, v2 = aqx * bqy, aqy * bqx
    d0, d1, d2 = u0 - v0, u1 - v1, u2 - v2
    sure = min(abs(d0), abs(d1), abs(d2)) > static or (
        (abs(d0) >= CCW_A * (abs(u0) + abs(v0))) & (abs(d1) >= CCW_A * (abs(u1) + abs(v1)))
        & (abs(d2) >= CCW_A * (abs(u2) + abs(v2))))
    if not sure:
        d0, _ = orient2d_staged(bx, by, cx, cy, qx, qy, CCW_A)
        d1, _ = orient2d_staged(cx, cy, ax, ay, qx, qy, CCW_A)
        d2, _ = orient2d_staged(ax, ay, bx, by, qx, qy, CCW_A)
    return _most_beyond(d0, d1, d2, np.inf)


@njit(cache=True, inline="always")
def _most_beyond(d0, d1, d2, d3):
    """The corner whose opposite facet q lies farthest beyond (the most
    negative of the orientations d0..d3, the first of equal ones), or -1
    when q lies beyond none; a triangle passes d3 = inf."""
    i, low = 0, d0
    if d1 < low:
        i, low = 1, d1
    if d2 < low:
        i, low = 2, d2
    if d3 < low:
        i, low = 3, d3
    return i if low < 0.0 else -1


@njit(cache=True, inline="always")
def _step3(P, S, t, qx, qy, qz, static):
    """_step2 for tetrahedra: q lies beyond the facet opposite corner i when
    the tetrahedron with q in slot i is negatively oriented.  With q as the
    origin and A..D the corners minus q, those four orientations are
    det[B, C, D], -det[A, C, D], det[A, B, D] and -det[A, B, C]: two cross
    products, C x D and A x B, serve all four, each a triple product of
    rounded differences as orient3d_staged evaluates it (the same error
    bound, on the same permanent).  ``static`` (walk_static) certifies all
    four at once, without their permanents, unless one is that small."""
    a, b, c, d = S[t, 0], S[t, 1], S[t, 2], S[t, 3]
    ax, ay, az = P[a, 0], P[a, 1], P[a, 2]
    bx, by, bz = P[b, 0], P[b, 1], P[b, 2]
    cx, cy, cz = P[c, 0], P[c, 1], P[c, 2]
    dx, dy, dz = P[d, 0], P[d, 1], P[d, 2]
    Ax, Ay, Az, Bx, By, Bz = ax - qx, ay - qy, az - qz, bx - qx, by - qy, bz - qz
    Cx, Cy, Cz, Dx, Dy, Dz = cx - qx, cy - qy, cz - qz, dx - qx, dy - qy, dz - qz
    u0, v0, u1, v1, u2, v2 = Cy * Dz, Cz * Dy, Cz * Dx, Cx * Dz, Cx * Dy, Cy * Dx
    x0, x1, x2 = u0 - v0, u1 - v1, u2 - v2  # C x D
    s0, t0, s1, t1, s2, t2 = Ay * Bz, Az * By, Az * Bx, Ax * Bz, Ax * By, Ay * Bx
    y0, y1, y2 = s0 - t0, s1 - t1, s2 - t2  # A x B
    d0 = Bx * x0 + By * x1 + Bz * x2
    d1 = -(Ax * x0 + Ay * x1 + Az * x2)
    d2 = Dx * y0 + Dy * y1 + Dz * y2
    d3 = -(Cx * y0 + Cy * y1 + Cz * y2)
    sure = min(min(abs(d0), abs(d1)), min(abs(d2), abs(d3))) > static
    if not sure:  # the permanents, only now
        p0, p1, p2 = abs(u0) + abs(v0), abs(u1) + abs(v1), abs(u2) + abs(v2)
        r0, r1, r2 = abs(s0) + abs(t0), abs(s1) + abs(t1), abs(s2) + abs(t2)
        sure = ((abs(d0) > O3D_A * (abs(Bx) * p0 + abs(By) * p1 + abs(Bz) * p2))
                & (abs(d1) > O3D_A * (abs(Ax) * p0 + abs(Ay) * p1 + abs(Az) * p2))
                & (abs(d2) > O3D_A * (abs(Dx) * r0 + abs(Dy) * r1 + abs(Dz) * r2))
                & (abs(d3) > O3D_A * (abs(Cx) * r0 + abs(Cy) * r1 + abs(Cz) * r2)))
    if not sure:
        d0, _ = orient3d_staged((qx, qy, qz), (bx, by, bz), (cx, cy, cz), (dx, dy, dz), O3D_A)
        d1, _ = orient3d_staged((ax, ay, az), (qx, qy, qz), (cx, cy, cz), (dx, dy, dz), O3D_A)
        d2, _ = orient3d_staged((ax, ay, az), (bx, by, bz), (qx, qy, qz), (dx, dy, dz), O3D_A)
        d3, _ = orient3d_staged((ax, ay, az), (bx, by, bz), (cx, cy, cz), (qx, qy, qz), O3D_A)
    return _most_beyond(d0, d1, d2, d3)


@njit(cache=True, nogil=True)
def walk_static(box, Q):
    """The static orientation bound of the walk's steps (their stage A's,
    predicates.spatial.statics): the box holds every corner and query of a
    step, here the box of the mesh's points (``box``: their lowest and
    highest coordinates, rows 0 and 1, in the frame) widened to the queries
    Q, read as they are.  inf (no static bound) where the box leaves the
    range those bounds hold in."""
    d = Q.shape[1]
    lo, hi = widened(box[0].copy(), box[1].copy(), Q, d)
    return statics(lo, hi, d)[0]


@njit(cache=True, nogil=True)
def locate_walk(mesh, Q, lo, hi, out, last, sample, static):
    """Simplex of each query row lo:hi of Q by the visibility walk, in row
    order (sort the rows along a curve first: ``grid_order``), each walk
    starting from the previous answer or, when ``sample`` > 0, from the
    nearest of that many simplices spread over the array (jump and walk,
    for queries too sparse for the previous answer to be near); -1
    outside.  ``last[k]`` is the last simplex query k's walk visited (where
    an outside query left the hull).  A walk that exceeds its step budget
    falls back to the brute force.  mesh = (P, S, N), the points, simplices
    and neighbours, may be a ``walk_frame``'s: the answers are then its
    rows (``order`` maps them back).  ``static``: walk_static's bound for
    these queries.

    The walk is written out in this loop rather than called: an inlined
    function that returns a tuple per query doubled the time
    (docs/performance.md, "location walk")."""
    if mesh[0].shape[1] == 2:
        _walk_rows(mesh, Q, lo, hi, out, last, sample, static, 2)
    else:
        _walk_rows(mesh, Q, lo, hi, out, last, sample, static, 3)


@njit(cache=True, inline="always")
def _walk_rows(mesh, Q, lo, hi, out, last, sample, static, d):
    """locate_walk's loop, with the dimension ``d`` a constant where it is
    inlined (one walk in the loop, not a branch between two)."""
    P, S, N = mesh
    budget = 4 * S.shape[0] + 4
    t = 0
    for k in range(lo, hi):
        qx, qy, qz = _query(Q, k)
        if sample > 0:
            t = _nearest_start(P, S, sample, qx, qy, qz, t)
        found = -2
        for _ in range(budget):
            i = _step2(P, S, t, qx, qy, static) if d == 2 else _step3(P, S, t, qx, qy, qz, static)
            if i < 0:
                found = t
                break
            u = N[t, i]
            if u < 0:
                found = -1
                break
            t = u
        if found == -2:
            found = _scan(P, S, qx, qy, qz)
            t = max(found, 0)
        out[k] = found
        last[k] = t


@njit(cache=True, nogil=True)
def walk_frame(P, S, scale):
    """(P2, S2): the mesh's points, times ``scale`` (the location's frame,
    exact: a power of two), in the order the simplices first name them, and
    the simplices (same rows, same slots) in that numbering, so that a walk
    between neighbouring queries, and a pass over the simplices, read the
    corners of neighbouring simplices from neighbouring memory.  The simplices' own order is the build's, which follows space
    (the divide and conquer's merges along the Morton curve, the insertion's
    Kd order), and one pass gives the numbering: no sort, and the rows stay
    the object's, neighbours included.  P2 holds only the points the
    simplices use.  Sorting the points along a curve and the simplices by
    their lowest vertex made the walk about a quarter faster and cost as
    much as the triangulation itself (docs/performance.md, "mesh along
    space")."""
    n = P.shape[0]
    m, k1 = S.shape
    new = np.full(n, -1, dtype=S.dtype)  # the narrow dtype: read at random
    old = np.empty(n, dtype=np.int64)
    S2 = np.empty_like(S)
    used = 0
    for t in range(m):
        for j in range(k1):
            v = S[t, j]
            w = new[v]
            if w < 0:
                w = used
                new[v] = w
                old[w] = v
                used += 1
            S2[t, j] = w
    P2 = np.empty((used, P.shape[1]))
    for i in range(used):
        for a in range(P.shape[1]):
            P2[i, a] = P[old[i], a] * scale
    return P2, S2


# Queries fewer than the mesh's points over JUMP_SPARSITY start each walk
# from the nearest of a sample of simplices (jump and walk); denser ones
# from the previous answer, which their curve order keeps near.  The
# break-even, warm, uniform queries (docs/performance.md, "jump or walk"):
# 2D, 1M points, between 20k and 40k queries; 3D, 300k points, between
# 10k and 20k.
JUMP_SPARSITY = 32


def jump_sample(queries, points, simplices):
    """How many simplices a walk's start is chosen from: none when the
    queries are dense enough (JUMP_SPARSITY) that, sorted, each starts near
    the previous answer; else about m**(1/3), which balances the jump's
    distance tests against the walk's expected length."""
    if JUMP_SPARSITY * queries >= points:
        return 0
    return int(round(simplices ** (1.0 / 3.0)))


@njit(cache=True, inline="always")
def _nearest_start(P, S, sample, qx, qy, qz, t):
    """t, or the simplex among ``sample`` evenly spaced ones (the mesh's
    simplices lie in a spatial order) whose first vertex is nearer q."""
    d = P.shape[1]
    best = _distance2(P, S[t, 0], qx, qy, qz, d)
    step = max(S.shape[0] // sample, 1)
    for s in range(0, S.shape[0], step):
        dd = _distance2(P, S[s, 0], qx, qy, qz, d)
        if dd < best:
            best, t = dd, s
    return t


@njit(cache=True, inline="always")
def _distance2(P, v, qx, qy, qz, d):
    dx, dy = P[v, 0] - qx, P[v, 1] - qy
    dz = P[v, d - 1] - qz if d == 3 else 0.0
    return dx * dx + dy * dy + dz * dz


@njit(cache=True)
def split_queries(q, lo, hi, scale, floor, tol):
    """(rows of q inside the box [lo, hi], those rows in the frame with
    every component the frame cannot hold zeroed, whether a row had one,
    the rows outside the box but within ``tol`` of it): a NaN is outside,
    and a component is tiny when it is nonzero but below ``floor`` once
    scaled."""
    n, d = q.shape
    rows = np.empty(n, dtype=np.int64)
    near = np.empty(n, dtype=np.int64)
    H = np.empty((n, d))
    tiny = np.zeros(n, dtype=np.bool_)
    w = z = 0
    for k in range(n):
        inside = widened = True
        for a in range(d):
            inside &= lo[a] <= q[k, a] <= hi[a]
            widened &= lo[a] - tol <= q[k, a] <= hi[a] + tol
        if not inside:
            if widened:
                near[z] = k
                z += 1
            continue
        rows[w] = k
        for a in range(d):
            v = q[k, a] * scale
            small = q[k, a] != 0.0 and abs(v) < floor
            H[w, a] = 0.0 if small else v
            tiny[w] |= small
        w += 1
    return rows[:w], H[:w], tiny[:w], near[:z]


@njit(cache=True, nogil=True)
def in_frame(q, lo, hi, floor):
    """True when every row of q lies in the box [lo, hi] (no NaN) with no
    component below ``floor``: in a frame of scale 1, q is then its own
    ``split_queries`` (every row, nothing tiny, none near), read once
    instead of copied."""
    ok = True
    for a in range(q.shape[1]):  # a column at a time, no branch: a pass at memory speed
        low, high = lo[a], hi[a]
        for k in range(q.shape[0]):
            v = q[k, a]
            ok &= (low <= v) & (v <= high) & ((v == 0.0) | (abs(v) >= floor))
    return ok


@njit(cache=True, inline="always")
def _sampled_steps(Q, window):
    """(steps, lo, hi) of coherent and curve_like: the L1 steps from rows
    k to k + window at up to 1024 k spread over Q, and the box of those
    rows k."""
    n, d = Q.shape
    pairs = min(n - window, 1024)
    stride = (n - window) // pairs
    gap = np.empty(pairs)
    lo, hi = Q[0].copy(), Q[0].copy()
    for j in range(pairs):
        k = j * stride
        s = 0.0
        for a in range(d):
            s += abs(Q[k + window, a] - Q[k, a])
            lo[a] = min(lo[a], Q[k, a])
            hi[a] = max(hi[a], Q[k, a])
        gap[j] = s
    return gap, lo, hi


@njit(cache=True, nogil=True)
def coherent(Q):
    """True when the rows of Q already follow each other in space (a caller
    sorted them, or they come from a grid): then the walk takes them in the
    caller's order, and sorting them again would cost more than it saves.
    The test, on a sample of consecutive pairs spread over Q: the mean
    step is within a few cells of a grid of one query per cell over the
    sample's box (the mean, not the median: the queries of a grid that lie
    outside the hull, in row order, alternate between the box's faces, and
    half their steps cross it)."""
    n, d = Q.shape
    if n < 64:
        return True
    gap, lo, hi = _sampled_steps(Q, 1)
    cell = 0.0
    for a in range(d):
        cell += (hi[a] - lo[a]) / n ** (1.0 / d)
    return gap.mean() <= 4.0 * cell


@njit(cache=True, nogil=True)
def curve_like(Q, window):
    """True when the rows of Q stay close over ``window`` rows too, as
    along a space-filling curve (within a few times window**(1/d) cells of
    a grid of one query per cell, at the median of a sample), not only
    from row to row: a row-major grid is ``coherent`` but sweeps each row across the
    box, and on a mesh larger than the caches its walk reads a new part of
    memory at every step (3D 300k points, a 1M grid: 1.40 s in row order,
    0.95 s sorted first; docs/performance.md, "mesh along space")."""
    n, d = Q.shape
    if n < 4 * window:
        return True
    gap, lo, hi = _sampled_steps(Q, window)
    cell = 0.0  # the largest axis's: a row moves along one axis only
    for a in range(d):
        cell = max(cell, (hi[a] - lo[a]) / n ** (1.0 / d))
    return np.median(gap) <= 4.0 * cell * window ** (1.0 / d)


def grid_order(Q):
    """An order of the query rows along the Morton curve of a grid over
    their bounding box, so that each walk starts near its answer (lfqt's
    radix sort of the keys)."""
    order = np.arange(len(Q), dtype=np.int64)
    if len(Q) < 64:
        return order
    keys = _grid_keys(Q, 16 if Q.shape[1] == 2 else 21)
    return sort_keys(keys, order, Workers(1))[1]


@njit(cache=True, inline="always")
def _spread3(v):
    """Move bit k of a 21-bit value to bit 3k."""
    v &= np.uint64(0x1FFFFF)
    v = (v | (v << np.uint64(32))) & np.uint64(0x1F00000000FFFF)
    v = (v | (v << np.uint64(16))) & np.uint64(0x1F0000FF0000FF)
    v = (v | (v << np.uint64(8))) & np.uint64(0x100F00F00F00F00F)
    v = (v | (v << np.uint64(4))) & np.uint64(0x10C30C30C30C30C3)
    v = (v | (v << np.uint64(2))) & np.uint64(0x1249249249249249)
    return v


@njit(cache=True, nogil=True)
def _grid_keys(Q, bits):
    """Morton keys of the rows of Q on a 2**bits grid per axis (16 bits in
    2D, 21 in 3D)."""
    n, d = Q.shape
    lo = np.empty(d)
    step = np.empty(d)
    for a in range(d):
        lo[a] = Q[:, a].min()
        span = Q[:, a].max() - lo[a]
        step[a] = (2.0 ** bits - 1.0) / span if span > 0.0 else 0.0
    keys = np.empty(n, dtype=np.uint64)
    for k in range(n):
        x = np.uint64((Q[k, 0] - lo[0]) * step[0])
        y = np.uint64((Q[k, 1] - lo[1]) * step[1])
        if d == 2:
            keys[k] = spread_bits(x) | (spread_bits(y) << np.uint64(1))
        else:
            z = np.uint64((Q[k, 2] - lo[2]) * step[2])
            keys[k] = _spread3(x) | (_spread3(y) << np.uint64(1)) | (_spread3(z) << np.uint64(2))
    return keys


@njit(cache=True, nogil=True)
def _scan(P, S, qx, qy, qz):
    for s in range(S.shape[0]):
        if _contains(P, S, s, qx, qy, qz):
            return s
    return -1


@njit(cache=True, nogil=True)
def simplex_boxes(P, S):
    """(2d, m) bounding boxes of the simplices, a row per bound (x low, x
    high, y low, ...), so that the brute force reads each bound in a run."""
    m, k1 = S.shape
    d = P.shape[1]
    B = np.empty((2 * d, m))
    for t in range(m):
        for a in range(d):
            lo = hi = P[S[t, 0], a]
            for j in range(1, k1):
                lo = min(lo, P[S[t, j], a])
                hi = max(hi, P[S[t, j], a])
            B[2 * a, t] = lo
            B[2 * a + 1, t] = hi
    return B


BLOCK = 256  # simplices whose boxes the brute force tests branch-free before a predicate


@njit(cache=True, nogil=True)
def locate_brute(P, S, B, Q, lo, hi, out):
    """Rows lo:hi of Q by testing every simplex whose box (``simplex_boxes``)
    holds the query, in index order; -1 outside.  The boxes of a block are
    tested without a branch (the loop vectorises), the predicates run only
    on the hits."""
    m = S.shape[0]
    d = P.shape[1]
    hit = np.empty(BLOCK, dtype=np.bool_)
    for k in range(lo, hi):
        out[k] = -1
        qx, qy, qz = _query(Q, k)
        for s0 in range(0, m, BLOCK):
            s1 = min(s0 + BLOCK, m)
            some = False
            for s in range(s0, s1):
                h = (B[0, s] <= qx) & (qx <= B[1, s]) & (B[2, s] <= qy) & (qy <= B[3, s])
                if d == 3:
                    h &= (B[4, s] <= qz) & (qz <= B[5, s])
                hit[s - s0] = h
                some |= h
            if some:
                for s in range(s0, s1):
                    if hit[s - s0] and _contains(P, S, s, qx, qy, qz):
                        out[k] = s
                        break
            if out[k] >= 0:
                break


# -- queries below the frame's floor ----------------------------------------

def tiny_frame_ok(scale_exponent, d):
    """Whether ``_beyond_tiny`` is exact in a frame scaled by
    2**scale_exponent.  Its products are exact when no bit falls below
    2**-1074 and none overflows.  The normal g has its lowest bit at or
    above 2**-240 (2D: differences of frame coordinates, whose ulps are at
    least 2**MIN_ULP_EXP) or 2**-384 (3D: products of two such), and a tiny
    component's lowest bit is 2**-1074 at worst in the input, so
    2**(-1074 + s + K) once scaled: s + K >= 240 (2D) or 384 (3D).  The
    scaled part stays below 2**(K - 140) and |g| below 2**398, so K = 600
    cannot overflow."""
    return scale_exponent + TINY_SHIFT >= (240 if d == 2 else 384)


@njit(cache=True)
def _normal(P, S, t, i):
    """(g as (d, len) expansions, their lengths, sign, base vertex) of the
    facet of t opposite i: orientation with q in slot i = sign * (q - base).g."""
    d = P.shape[1]
    G = np.zeros((d, 16))
    glen = np.zeros(d, dtype=np.int64)
    if d == 2:
        a, b = _edge(S, t, i)  # orient(a, b, q) = (q - a).(ay - by, bx - ax)
        _put(G, glen, 0, exact_diff(P[a, 1], P[b, 1]))
        _put(G, glen, 1, exact_diff(P[b, 0], P[a, 0]))
        return G, glen, 1.0, a
    # det[w1 - w0, w2 - w0, w3 - w0] with q in slot i is (-1)**(i + 1) (q - a).((b - a) x (c - a))
    # for the other vertices a, b, c in slot order: moving q to slot 0 takes i transpositions.
    a, b, c = _others(S, t, i)
    ux, uxl = exact_diff(P[b, 0], P[a, 0])
    uy, uyl = exact_diff(P[b, 1], P[a, 1])
    uz, uzl = exact_diff(P[b, 2], P[a, 2])
    vx, vxl = exact_diff(P[c, 0], P[a, 0])
    vy, vyl = exact_diff(P[c, 1], P[a, 1])
    vz, vzl = exact_diff(P[c, 2], P[a, 2])
    _put(G, glen, 0, cross_exact(uy, uyl, vz, vzl, uz, uzl, vy, vyl))
    _put(G, glen, 1, cross_exact(uz, uzl, vx, vxl, ux, uxl, vz, vzl))
    _put(G, glen, 2, cross_exact(ux, uxl, vy, vyl, uy, uyl, vx, vxl))
    return G, glen, -1.0 if i % 2 == 0 else 1.0, a


@njit(cache=True, inline="always")
def _put(G, glen, k, expansion):
    e, n = expansion
    G[k, :n] = e[:n]
    glen[k] = n


@njit(cache=True)
def _dot(G, glen, x, base):
    """sum_k (x_k - base_k) g_k as an expansion (sum_k x_k g_k without a
    base)."""
    acc = np.zeros(1)
    alen = 1
    for k in range(G.shape[0]):
        if base is None:
            term = np.empty(2 * glen[k])
            tl = scale_expansion(G[k, :glen[k]], glen[k], x[k], term)
        else:
            dk, dl = exact_diff(x[k], base[k])
            term, tl = expansion_product(dk, dl, G[k, :glen[k]], glen[k])
        out = np.empty(alen + tl)
        alen = expansion_sum(acc, alen, term, tl, out)
        acc = out
    return acc, alen


@njit(cache=True, inline="always")
def _tiny_filter(P, S, t, i, H, Ls):
    """The sign ``_beyond_tiny`` tests, from floats, when E1's estimate
    clears its rounding error (a generous 32 eps of its permanent; the
    operands lie in the frame, so nothing underflows) and twice a bound on
    |E2| (the normal's permanent times |L|, compared at the scale of Ls);
    0 when that does not decide, and the expansions do."""
    if P.shape[1] == 2:
        a, b = _edge(S, t, i)
        g0, g1, g2 = P[a, 1] - P[b, 1], P[b, 0] - P[a, 0], 0.0
        p0, p1, p2 = abs(g0), abs(g1), 0.0
        sign = 1.0
        ax, ay, az = P[a, 0], P[a, 1], 0.0
        hz, lz = 0.0, 0.0
    else:
        a, b, c = _others(S, t, i)
        ax, ay, az = P[a, 0], P[a, 1], P[a, 2]
        ux, uy, uz = P[b, 0] - ax, P[b, 1] - ay, P[b, 2] - az
        vx, vy, vz = P[c, 0] - ax, P[c, 1] - ay, P[c, 2] - az
        g0, p0 = uy * vz - uz * vy, abs(uy * vz) + abs(uz * vy)
        g1, p1 = uz * vx - ux * vz, abs(uz * vx) + abs(ux * vz)
        g2, p2 = ux * vy - uy * vx, abs(ux * vy) + abs(uy * vx)
        sign = -1.0 if i % 2 == 0 else 1.0
        hz, lz = H[2], Ls[2]
    dx, dy, dz = H[0] - ax, H[1] - ay, hz - az
    e1 = dx * g0 + dy * g1 + dz * g2
    clear = abs(e1) - 32.0 * EPS * (abs(dx) * p0 + abs(dy) * p1 + abs(dz) * p2)
    e2 = (1.0 + 2.0 ** -40) * (p0 * abs(Ls[0]) + p1 * abs(Ls[1]) + p2 * abs(lz))
    if clear > 2.0 ** -900 and clear * 2.0 ** TINY_SHIFT > 2.0 * e2:
        return sign * e1
    return 0.0


@njit(cache=True)
def _beyond_tiny(P, S, t, i, H, Ls):
    """``_beyond`` for q = H + Ls * 2**-TINY_SHIFT (module docstring)."""
    quick = _tiny_filter(P, S, t, i, H, Ls)
    if quick != 0.0:
        return quick < 0.0
    G, glen, sign, a = _normal(P, S, t, i)
    e1, n1 = _dot(G, glen, H, P[a])
    e2, n2 = _dot(G, glen, Ls, None)
    top1, top2 = e1[n1 - 1], e2[n2 - 1]
    if top2 == 0.0:
        return sign * top1 < 0.0
    if top1 != 0.0:
        x1 = math.frexp(top1)[1]
        x2 = math.frexp(top2)[1] - TINY_SHIFT
        if x1 - 1 > x2 + 1:  # |E1| >= 2**(x1 - 1) (1 - eps) > 2**(x2 + 1) > |E2|
            return sign * top1 < 0.0
        if x2 - 1 > x1 + 1:
            return sign * top2 < 0.0
    up = e1[:n1] * 2.0 ** TINY_SHIFT  # exact: powers of two, and |E1| is near |E2| here
    total = np.empty(n1 + n2)
    n = expansion_sum(up, n1, e2, n2, total)
    return sign * total[n - 1] < 0.0


@njit(cache=True)
def _contains_tiny(P, S, t, H, Ls):
    for i in range(S.shape[1]):
        if _beyond_tiny(P, S, t, i, H, Ls):
            return False
    return True


@njit(cache=True)
def locate_tiny(P, S, N, H, Ls, start):
    """Simplex of each query H[k] + Ls[k] * 2**-TINY_SHIFT, walking from
    ``start[k]`` (the simplex where H[k]'s own walk ended: a step or two
    away), -1 outside; brute force past the step budget."""
    out = np.empty(H.shape[0], dtype=np.int64)
    k1 = S.shape[1]
    for k in range(H.shape[0]):
        t = start[k]
        found = -2
        for step in range(4 * S.shape[0] + 4):
            moved = False
            for j in range(k1):
                i = (j + step) % k1
                if _beyond_tiny(P, S, t, i, H[k], Ls[k]):
                    moved = True
                    t = N[t, i]
                    break
            if not moved:
                found = t
                break
            if t < 0:
                found = -1
                break
        if found == -2:
            found = -1
            for s in range(S.shape[0]):
                if _contains_tiny(P, S, s, H[k], Ls[k]):
                    found = s
                    break
        out[k] = found
    return out


# -- scipy's tolerance, near the hull ----------------------------------------

@njit(cache=True, inline="always")
def _coordinate(Tr, t, j, x):
    """Barycentric coordinate j < d of x in simplex t (scipy's transform);
    the last one is 1 minus the others."""
    d = Tr.shape[2]
    c = 0.0
    for a in range(d):
        c += Tr[t, j, a] * (x[a] - Tr[t, d, a])
    return c


@njit(cache=True, inline="always")
def _barycentric_min(Tr, t, x):
    """(smallest barycentric coordinate of x in simplex t, its vertex);
    NaN for a simplex too flat for its transform."""
    d = Tr.shape[2]
    last = 1.0
    low, at = np.inf, -1
    for j in range(d):
        c = _coordinate(Tr, t, j, x)
        last -= c
        if c < low:
            low, at = c, j
    if last < low:
        low, at = last, d
    if last != last:  # NaN rows of T^-1 make every coordinate NaN, the last one too
        return np.nan, -1
    return low, at


@njit(cache=True, inline="always")
def _pivot(S, N, t, i, j):
    """The hull facet next to hull facet (t, i) across its ridge without
    vertex S[t, j]: turn about the ridge through the simplices around it
    until a facet without a neighbour."""
    for _ in range(S.shape[0] + 1):
        u = N[t, j]
        if u < 0:
            return t, j
        apex = S[t, i]
        k = m = -1
        for r in range(S.shape[1]):
            if N[u, r] == t:
                k = r
            if S[u, r] == apex:
                m = r
        t, i, j = u, k, m
    return -1, -1


@njit(cache=True)
def _star_best(S, N, Tr, t, v, x, seen, nseen, best, best_t):
    """Best (largest smallest barycentric coordinate of x) over the
    simplices around vertex v, from t, which holds v."""
    stack = np.empty(STAR, dtype=np.int64)
    stack[0] = t
    top = 1
    mark = nseen
    seen[nseen] = t
    nseen += 1
    while top > 0:
        top -= 1
        s = stack[top]
        low, _ = _barycentric_min(Tr, s, x)
        if low > best:
            best, best_t = low, s
        for r in range(S.shape[1]):
            nb = N[s, r]
            if S[s, r] == v or nb < 0:
                continue  # the facet opposite v does not hold v
            known = False
            for z in range(mark, nseen):
                known |= seen[z] == nb
            if not known and nseen < seen.shape[0] and top < STAR:
                seen[nseen] = nb
                nseen += 1
                stack[top] = nb
                top += 1
    return best, best_t, nseen


@njit(cache=True)
def locate_tolerant(S, N, Tr, x, tol, t):
    """Simplex whose barycentric coordinates of x are all >= -tol, or -1,
    for a query outside every simplex: a float walk from t to the hull, then
    the stars of the vertices of the hull facets x sees (at most
    HULL_FACETS), the best of them."""
    k1 = S.shape[1]
    for _ in range(4 * S.shape[0] + 4):
        low, at = _barycentric_min(Tr, t, x)
        if at < 0:
            return -1  # a flat simplex: no direction to follow
        if low >= -tol:
            return t
        if N[t, at] < 0:
            break
        t = N[t, at]
    facets = np.empty((HULL_FACETS, 2), dtype=np.int64)
    facets[0, 0], facets[0, 1] = t, at
    nf, head = 1, 0
    best, best_t = -np.inf, -1
    seen = np.empty(SEEN, dtype=np.int64)
    nseen = 0
    while head < nf:
        f, i = facets[head, 0], facets[head, 1]
        head += 1
        for j in range(k1):
            if j == i:
                continue
            best, best_t, nseen = _star_best(S, N, Tr, f, S[f, j], x, seen, nseen, best, best_t)
            g, gi = _pivot(S, N, f, i, j)
            if g < 0 or nf == HULL_FACETS:
                continue
            known = False
            for z in range(nf):
                known |= facets[z, 0] == g and facets[z, 1] == gi
            if not known and _facet_coordinate(Tr, g, gi, x) < 0.0:
                facets[nf, 0], facets[nf, 1] = g, gi
                nf += 1
    return best_t if best >= -tol else -1


@njit(cache=True, inline="always")
def _facet_coordinate(Tr, t, i, x):
    """Barycentric coordinate of x for vertex i of t (< 0: x sees the
    facet opposite i)."""
    d = Tr.shape[2]
    if i < d:
        return _coordinate(Tr, t, i, x)
    total = 0.0
    for j in range(d):
        total += _coordinate(Tr, t, j, x)
    return 1.0 - total


# -- the last resort: Python's rationals -------------------------------------

def _det_sign(rows):
    """Sign of the determinant of a small square matrix of Fractions."""
    m = [list(r) for r in rows]
    n, sign = len(m), 1
    for c in range(n):
        p = next((r for r in range(c, n) if m[r][c] != 0), None)
        if p is None:
            return 0
        if p != c:
            m[c], m[p] = m[p], m[c]
            sign = -sign
        for r in range(c + 1, n):
            f = m[r][c] / m[c][c]
            m[r] = [a - f * b for a, b in zip(m[r], m[c])]
        sign *= 1 if m[c][c] > 0 else -1
    return sign


def _orient(points):
    """Exact orientation sign of d+1 points in d dimensions (Fractions)."""
    base = points[0]
    return _det_sign([[a - b for a, b in zip(p, base)] for p in points[1:]])


def locate_rational(points, S, N, q):
    """The visibility walk for one query, on the original coordinates in
    exact rational arithmetic: only for a frame ``tiny_frame_ok`` rejects.
    Brute force when the walk's budget runs out."""
    q = [Fraction(float(v)) for v in q]
    coords = {}

    def vertex(v):
        if v not in coords:
            coords[v] = [Fraction(float(c)) for c in points[v]]
        return coords[v]

    def beyond(t, i):
        return _orient([q if j == i else vertex(S[t, j]) for j in range(S.shape[1])]) < 0

    t = 0
    for _ in range(4 * len(S) + 4):
        step = next((i for i in range(S.shape[1]) if beyond(t, i)), None)
        if step is None:
            return t
        t = N[t, step]
        if t < 0:
            return -1
    for t in range(len(S)):
        if not any(beyond(t, i) for i in range(S.shape[1])):
            return t
    return -1
