"""Natural-neighbour (Sibson) interpolation in 2D and 3D on lfqt's exact
Delaunay triangulations.

Sibson's coordinate of a data point v at a query q is the share of q's
Voronoi cell, were q inserted, that it takes from v's cell::

    v2                     v1      Four data points: their Voronoi cells
                ^                  are the quadrants split by the axes.
               /|\\                 Inserting q cuts its new cell (the
              / | \\                diamond, bounded by the bisectors of
             /R2|R1\\               q and each v_i) out of theirs: R_i is
            <---q--->              the piece taken from v_i, and
             \\R3|R4/               lambda_i = |R_i| / sum_j |R_j|.
              \\ | /                The interpolant is sum_i lambda_i f_i.
               \\|/
                v
    v3                     v4

The natural neighbours are the vertices of q's cavity (Bowyer-Watson: the
simplices whose circumcircle or circumsphere strictly contains q).

Exact where it decides, floating point where it measures:

- the cavity is decided by lfqt's staged in-circle / in-sphere predicates
  (exact signs), from the simplex ``Delaunay.find_simplex`` returns (exact),
  by a walk over ``neighbors``.  So the set of natural neighbours is exact,
  also on cocircular input (grids): a simplex whose circle passes through q
  is not in the cavity, and the neighbour it would add has a stolen area of
  exactly zero, so leaving it out changes nothing and keeps the value
  continuous;
- the stolen areas and volumes are computed in floating point, relative to
  q, from the old circumcentres and the new ones (of q with each facet of
  the cavity's boundary).  ``|R_v|`` is a sum over its faces of cones from the
  midpoint of q and v, which lies on the new face (the bisector of q and
  v): that face adds nothing and needs no ordering.  The other faces lie
  on the old Voronoi edges (faces) of v, whose ends are old circumcentres,
  or new ones where they leave q's cell.  In 2D each cavity triangle t and
  each of its edges a->b adds a term linear in the piece of the Voronoi
  edge from its split point (q, for an edge inside the cavity) to t's
  circumcentre; in 3D each cavity edge (v, x) adds (x - q).A / 12 to v and
  (q - v).A / 12 to x, with A the vector area of the polygon of
  circumcentres around the edge, closed by the new circumcentres where
  its ring of tetrahedra leaves the cavity; A is summed from one part per
  cavity tetrahedron (``_edge_part``), so no ring is walked.  New
  circumcentres are needed only on the cavity's boundary, where q is
  never in a facet's plane for q inside the hull: Watson's classic
  per-simplex formula also uses them for the cavity's inner edges, and
  blows up for q on such an edge.

Degenerate queries, each decided exactly:

- q at a data point: weight 1 there (the cavity is empty), whatever the
  neighbours.  A duplicate row is merged by the triangulation
  (``Delaunay.coplanar``), and the value at its location is that of the row
  kept as the vertex (``triangulation.duplicate_of``), as scipy's
  interpolators do;
- q on an interior edge or facet: nothing special (the simplices on both
  sides are in the cavity);
- q on the 2D hull: its new cell is unbounded, and the value is the limit
  from inside, which is linear interpolation between the ends of the hull
  edge that holds q (in the limit the stolen areas grow like 1/distance and
  their ratio tends to that of 1D Sibson coordinates, which are linear);
- q on the 3D hull: the same limit.  Stolen volumes grow like 1/distance,
  as prisms over the hull face's plane, and in the limit lambda_v is
  proportional to the integral over v's stolen region *in that plane* (the
  2D Voronoi diagram of the data points in it, which the hull facets in it
  triangulate) of ``|y - v|^2 - |y - q|^2``.  That integrand is linear in y, so
  it is computed like an area, from a fan of triangles.  On a hull edge
  where two faces of different planes meet, the limit (from any side) is
  linear along that edge.  The tests check each limit against values a
  hair inside, which approach it at the rate of the distance;
- q outside the hull (exactly: ``find_simplex`` < 0): ``fill_value``.

A query coordinate too small for the triangulation's exact frame (nonzero
but below the frame's floor once scaled: 2**-188 in 2D, 2**-140 in 3D,
lfqt._input) is taken as 0:
the interpolant is continuous, so this moves the value by nothing a float
shows, but it can decide that a query that close outside the hull is on it.

The kernels run one query at a time on fixed scratch arrays, the queries in
Morton order (``location.grid_order``) so that consecutive cavities share
the mesh's cache lines, in chunks over the triangulation's threads.  A query
whose cavity does not fit (many cocircular or cospherical points) is done
again with four times the scratch, never answered from a partial cavity.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt
from numba import njit

from .location import _edge, _others, grid_order
from .predicates.planar import CCW_A, ICC_A, incircle_staged, orient2d_staged
from .predicates.spatial import ISP_A, O3D_A, insphere_staged, orient3d_staged
from .workers import Workers

if TYPE_CHECKING:  # annotations only: the interpolant reads a built Delaunay
    from .delaunay import Delaunay

CAPACITY = 64  # simplices in a cavity the first pass has room for (a 3D cavity has about 20)
MIN_CHUNK = 4096  # queries per thread below which one thread does all
# rows of the integer scratch: the cavity's simplices, the neighbours tested and left
# out, the natural neighbours, the hull facets q lies on, and from NBS on, one row per
# facet i: the cavity slot of the neighbour across facet i of each slot, -1 outside
CAV, REJ, IDS, RING, NBS = range(5)
# (v, x, y, z) slot orders of a tetrahedron's six edges, each an even permutation of
# the right-handed slots, so that turning from y to z turns right-handed about v -> x
EDGES = np.array([[0, 1, 2, 3], [0, 2, 3, 1], [0, 3, 1, 2],
                  [1, 2, 0, 3], [1, 3, 2, 0], [2, 3, 0, 1]], dtype=np.int64)


@njit(cache=True)
def _scratch(capacity, d):
    """(integers, weights, points) for cavities of up to ``capacity``
    simplices: the rows above; a weight per natural neighbour; the old
    circumcentres (rows below capacity), then in 3D the new circumcentre of
    each cavity facet f of slot s (row capacity + 4 s + f)."""
    width = (d + 2) * capacity
    return (np.empty((NBS + d + 1, width), dtype=np.int64), np.empty(width),
            np.empty((width, 3)))


@njit(cache=True, inline="always")
def _slot(iw, row, n, x):
    """The first k < n with iw[row, k] == x, or -1.  Rows are read in
    place: a view per call would cost numba two atomic reference counts."""
    for k in range(n):
        if iw[row, k] == x:
            return k
    return -1


@njit(cache=True, inline="always")
def _member(iw, row, n, x):
    return _slot(iw, row, n, x) >= 0


@njit(cache=True, inline="always")
def _add(iw, w, n, v, amount):
    """w[slot of v] += amount, v appended to the natural neighbours (iw[IDS]
    of length n) when new; returns the new length."""
    k = _slot(iw, IDS, n, v)
    if k < 0:
        iw[IDS, n] = v
        w[n] = amount
        return n + 1
    w[k] += amount
    return n


@njit(cache=True, inline="always")
def _rel(P, v, q):
    """Vertex v relative to q, as a 3-tuple (z = 0 in 2D)."""
    if P.shape[1] == 2:
        return P[v, 0] - q[0], P[v, 1] - q[1], 0.0
    return P[v, 0] - q[0], P[v, 1] - q[1], P[v, 2] - q[2]


@njit(cache=True, inline="always")
def _conflict(P, S, t, q):
    """Whether q lies strictly inside the circumcircle (circumsphere) of
    simplex t: the exact sign of the staged predicate."""
    if P.shape[1] == 2:
        a, b, c = S[t, 0], S[t, 1], S[t, 2]
        s, _ = incircle_staged(P[a, 0], P[a, 1], P[b, 0], P[b, 1], P[c, 0], P[c, 1],
                               q[0], q[1], ICC_A)
        return s > 0.0
    a, b, c, d = S[t, 0], S[t, 1], S[t, 2], S[t, 3]
    s, _ = insphere_staged((P[a, 0], P[a, 1], P[a, 2]), (P[b, 0], P[b, 1], P[b, 2]),
                           (P[c, 0], P[c, 1], P[c, 2]), (P[d, 0], P[d, 1], P[d, 2]),
                           (q[0], q[1], q[2]), ISP_A)
    return s > 0.0


@njit(cache=True)
def _cavity(P, S, N, q, t, iw):
    """The cavity of q from simplex t, which holds q and is in it: its
    simplices in iw[CAV] and their neighbours' slots in iw[NBS + i] (the
    neighbours tested and left out in iw[REJ]); returns their number, -1
    when the scratch is full."""
    iw[CAV, 0] = t
    nc, nr, head = 1, 0, 0
    while head < nc:
        c = iw[CAV, head]
        for i in range(S.shape[1]):
            u = N[c, i]
            k = -1
            if u >= 0 and not _member(iw, REJ, nr, u):
                k = _slot(iw, CAV, nc, u)
                if k < 0 and _conflict(P, S, u, q):
                    if nc == iw.shape[1] // (S.shape[1] + 1):
                        return -1
                    k = nc
                    iw[CAV, nc] = u
                    nc += 1
                elif k < 0:
                    iw[REJ, nr] = u  # fits: at most d + 1 per cavity simplex
                    nr += 1
            iw[NBS + i, head] = k
        head += 1
    return nc


@njit(cache=True)
def _at_vertex(P, S, t, q):
    """The vertex of simplex t at q, or -1."""
    for j in range(S.shape[1]):
        v = S[t, j]
        same = True
        for a in range(P.shape[1]):
            same &= P[v, a] == q[a]
        if same:
            return v
    return -1


@njit(cache=True, inline="always")
def _linear(P, a, b, q, iw, w):
    """Linear interpolation between a and b for q on the segment ab: 2."""
    ux, uy, uz = _rel(P, b, q)
    vx, vy, vz = _rel(P, a, q)
    ex, ey, ez = ux - vx, uy - vy, uz - vz
    s = -(vx * ex + vy * ey + vz * ez) / (ex * ex + ey * ey + ez * ez)
    s = min(max(s, 0.0), 1.0)
    iw[IDS, 0], iw[IDS, 1] = a, b
    w[0], w[1] = 1.0 - s, s
    return 2


# -- 2D ----------------------------------------------------------------------

@njit(cache=True, inline="always")
def _centre2(ax, ay, bx, by, cx, cy):
    """Circumcentre of triangle abc, relative to the frame of a, b, c."""
    ux, uy, vx, vy = bx - ax, by - ay, cx - ax, cy - ay
    uu, vv = ux * ux + uy * uy, vx * vx + vy * vy
    den = 2.0 * (ux * vy - uy * vx)
    return ax + (vy * uu - uy * vv) / den, ay + (ux * vv - vx * uu) / den


@njit(cache=True)
def _sibson2(P, S, N, q, t, iw, w):
    """Natural neighbours of q in iw[IDS] and their weights in w (not yet
    normalised); returns their number, -1 when the scratch is full.
    Simplex t holds q, which is no vertex and not on the hull."""
    nc = _cavity(P, S, N, q, t, iw)
    if nc < 0:
        return -1
    n = 0
    for s in range(nc):
        t = iw[CAV, s]
        ax, ay, _ = _rel(P, S[t, 0], q)
        bx, by, _ = _rel(P, S[t, 1], q)
        cx, cy, _ = _rel(P, S[t, 2], q)
        ox, oy = _centre2(ax, ay, bx, by, cx, cy)
        for i in range(3):
            a, b = _edge(S, t, i)  # t lies left of a -> b
            # Counter-clockwise round R_a, its piece d of the bisector of a and b runs from
            # the far side to t's circumcentre: from q, where the far side's own term (if
            # that triangle is in the cavity) starts, else from the new circumcentre of
            # (q, a, b).  The cone over d from (q + a) / 2 has area (b - q) x d / 4, and the
            # cone over the same piece, reversed, from (q + b) / 2 has -(a - q) x d / 4.
            px, py, _ = _rel(P, a, q)
            rx, ry, _ = _rel(P, b, q)
            gx, gy = 0.0, 0.0
            if iw[NBS + i, s] < 0:
                gx, gy = _centre2(0.0, 0.0, px, py, rx, ry)
            dx, dy = ox - gx, oy - gy
            n = _add(iw, w, n, a, 0.25 * (rx * dy - ry * dx))
            n = _add(iw, w, n, b, -0.25 * (px * dy - py * dx))
    return n


@njit(cache=True)
def _weights2(P, S, N, q, t, iw, w):
    """Natural-neighbour coordinates of q in simplex t (2D): their number,
    -1 when the scratch is full."""
    v = _at_vertex(P, S, t, q)
    if v >= 0:
        iw[IDS, 0], w[0] = v, 1.0
        return 1
    for i in range(3):
        if N[t, i] < 0:
            a, b = _edge(S, t, i)
            o, _ = orient2d_staged(P[a, 0], P[a, 1], P[b, 0], P[b, 1], q[0], q[1], CCW_A)
            if o == 0.0:
                return _linear(P, a, b, q, iw, w)
    return _sibson2(P, S, N, q, t, iw, w)


# -- 3D ----------------------------------------------------------------------
# Points are 3-tuples of floats relative to q, so that each helper reads as vector algebra.

@njit(cache=True, inline="always")
def _sub(a, b):
    return a[0] - b[0], a[1] - b[1], a[2] - b[2]


@njit(cache=True, inline="always")
def _plus(a, b):
    return a[0] + b[0], a[1] + b[1], a[2] + b[2]


@njit(cache=True, inline="always")
def _times(s, a):
    return s * a[0], s * a[1], s * a[2]


@njit(cache=True, inline="always")
def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit(cache=True, inline="always")
def _cross(a, b):
    return a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]


@njit(cache=True, inline="always")
def _centre3(a, b, c, d):
    """Circumcentre of tetrahedron abcd."""
    u, v, w = _sub(b, a), _sub(c, a), _sub(d, a)
    vw, wu, uv = _cross(v, w), _cross(w, u), _cross(u, v)
    num = _plus(_plus(_times(_dot(u, u), vw), _times(_dot(v, v), wu)), _times(_dot(w, w), uv))
    return _plus(a, _times(0.5 / _dot(u, vw), num))


@njit(cache=True, inline="always")
def _tri_centre(a, b):
    """Circumcentre of the triangle (0, a, b) in 3D."""
    n = _cross(a, b)
    m = _cross(_sub(_times(_dot(a, a), b), _times(_dot(b, b), a)), n)
    return _times(0.5 / _dot(n, n), m)


@njit(cache=True, inline="always")
def _vertex_of(S, t, v):
    for j in range(4):
        if S[t, j] == v:
            return j
    return -1


@njit(cache=True, inline="always")
def _fourth(S, t, v, x, y):
    """The vertex of tetrahedron t other than v, x and y."""
    for j in range(4):
        u = S[t, j]
        if u != v and u != x and u != y:
            return u
    return -1


@njit(cache=True, inline="always")
def _new_centre(P, q, v, x, y):
    """Circumcentre of the new tetrahedron (q, v, x, y), relative to q."""
    return _centre3((0.0, 0.0, 0.0), _rel(P, v, q), _rel(P, x, q), _rel(P, y, q))


@njit(cache=True, inline="always")
def _centre_of(C, k):
    return C[k, 0], C[k, 1], C[k, 2]


@njit(cache=True, inline="always")
def _edge_part(P, S, q, iw, s, edge, C):
    """Slot s's part of twice the vector area A (right-handed about v -> x)
    of the face of v's and x's Voronoi cells inside q's new cell, for its
    ``edge`` = (v, x, y, z) (y, z: its other vertices, right-handed).  The
    face is the polygon of the old circumcentres of the run of cavity
    tetrahedra around the edge (the whole ring, when every tetrahedron
    around it is in the cavity), entered and left through the new
    circumcentres g_in, g_out of the facets where the run crosses the
    cavity's boundary, and closed by the segment g_out -> g_in.  Slot s
    adds its segment to the next circumcentre round the edge; the run's
    first slot adds g_in -> C_s, and its last C_s -> g_out.  The closing
    segment lies on the line of points equidistant from q, v and x, which
    holds the circumcentre h of (q, v, x), so that its term cross(g_out,
    g_in) = cross(h, g_in) - cross(h, g_out) splits between the first and
    the last slot: each slot's part is local, and no slot walks the ring.
    h is finite there: q is never in the plane of a boundary facet."""
    v, x, y, z = edge
    new = iw.shape[1] // 5  # the new circumcentres' first row in C
    t = iw[CAV, s]
    c = _centre_of(C, s)
    ahead, behind = _vertex_of(S, t, y), _vertex_of(S, t, z)  # round the edge: y -> z
    nxt, prev = iw[NBS + ahead, s], iw[NBS + behind, s]
    if nxt >= 0 and prev >= 0:  # inside the run: the common case, no new circumcentre
        return _cross(c, _centre_of(C, nxt))
    h = _tri_centre(_rel(P, v, q), _rel(P, x, q))
    if nxt >= 0:
        part = _cross(c, _centre_of(C, nxt))
    else:  # the run's last slot
        g = _centre_of(C, new + 4 * s + ahead)
        part = _sub(_cross(c, g), _cross(h, g))
    if prev < 0:  # the run's first slot
        g = _centre_of(C, new + 4 * s + behind)
        part = _plus(part, _plus(_cross(g, c), _cross(h, g)))
    return part


@njit(cache=True)
def _centres3(P, S, q, nc, iw, C):
    """The circumcentres of the cavity's tetrahedra, and the new ones of q
    with each facet of the cavity's boundary, relative to q (rows of C as
    in ``_scratch``)."""
    new = iw.shape[1] // 5
    for s in range(nc):
        t = iw[CAV, s]
        C[s, 0], C[s, 1], C[s, 2] = _centre3(_rel(P, S[t, 0], q), _rel(P, S[t, 1], q),
                                             _rel(P, S[t, 2], q), _rel(P, S[t, 3], q))
        for j in range(4):
            if iw[NBS + j, s] < 0:
                a, b, c = _others(S, t, j)
                r = new + 4 * s + j
                C[r, 0], C[r, 1], C[r, 2] = _new_centre(P, q, a, b, c)


@njit(cache=True)
def _sibson3(P, S, q, nc, iw, w, C):
    """Natural neighbours of q in iw[IDS] and their stolen volumes (times
    12) in w, for q inside the hull with its cavity in iw[CAV]; returns
    their number.  Each cavity edge (v, x) adds the cones over its face
    from the midpoints of q and v and of q and x (module docstring)."""
    _centres3(P, S, q, nc, iw, C)
    acc = np.empty(4)  # the slot's parts per vertex, added to w once per vertex
    n = 0
    for s in range(nc):
        t = iw[CAV, s]
        acc[:] = 0.0
        for e in range(6):
            i, j = EDGES[e, 0], EDGES[e, 1]
            v, x, y, z = S[t, i], S[t, j], S[t, EDGES[e, 2]], S[t, EDGES[e, 3]]
            if v > x:  # one direction per edge, so that its slots' parts join up
                i, j, v, x, y, z = j, i, x, v, z, y
            area = _edge_part(P, S, q, iw, s, (v, x, y, z), C)
            acc[i] += _dot(_rel(P, x, q), area)
            acc[j] -= _dot(_rel(P, v, q), area)
        for i in range(4):
            n = _add(iw, w, n, S[t, i], acc[i])
    return n


@njit(cache=True)
def _weights3(P, S, N, q, t, iw, w, C):
    """Natural-neighbour coordinates of q in tetrahedron t (3D): their
    number, -1 when the scratch is full."""
    v = _at_vertex(P, S, t, q)
    if v >= 0:
        iw[IDS, 0], w[0] = v, 1.0
        return 1
    nc = _cavity(P, S, N, q, t, iw)
    if nc < 0:
        return -1
    nh = _hull_facets(P, S, N, q, nc, iw)
    if nh > 0:
        return _on_hull3(P, S, q, nh, iw, w)
    return _sibson3(P, S, q, nc, iw, w, C)


@njit(cache=True, inline="always")
def _orient3(P, a, b, c, p):
    """The exact sign of orient3d(a, b, c, p) for vertices a, b, c and the
    point p (three floats)."""
    o, _ = orient3d_staged((P[a, 0], P[a, 1], P[a, 2]), (P[b, 0], P[b, 1], P[b, 2]),
                           (P[c, 0], P[c, 1], P[c, 2]), (p[0], p[1], p[2]), O3D_A)
    return o


@njit(cache=True)
def _hull_facets(P, S, N, q, nc, iw):
    """The hull facets of the cavity's tetrahedra that q lies in the plane
    of, as 4 * tetrahedron + facet in iw[RING]; returns their number (0: q
    is inside the hull)."""
    nh = 0
    for s in range(nc):
        t = iw[CAV, s]
        for i in range(4):
            if N[t, i] < 0:
                a, b, c = _others(S, t, i)
                if _orient3(P, a, b, c, q) == 0.0:
                    iw[RING, nh] = 4 * t + i
                    nh += 1
    return nh


@njit(cache=True, inline="always")
def _outward(S, f):
    """The vertices of hull facet f = 4 * t + i, counter-clockwise seen from
    outside the hull (location._normal's sign rule)."""
    a, b, c = _others(S, f // 4, f % 4)
    if f % 4 % 2 == 1:
        return a, c, b
    return a, b, c


@njit(cache=True)
def _coplanar(P, S, f, g):
    """Whether the vertices of facet g lie in the plane of facet f."""
    a, b, c = _others(S, f // 4, f % 4)
    for v in _others(S, g // 4, g % 4):
        if _orient3(P, a, b, c, P[v]) != 0.0:
            return False
    return True


@njit(cache=True)
def _between(P, a, b, q):
    """Whether q lies on the segment ab strictly between its ends (exact:
    collinear in the three coordinate planes, and inside the box)."""
    for (i, j) in ((0, 1), (1, 2), (2, 0)):
        o, _ = orient2d_staged(P[a, i], P[a, j], P[b, i], P[b, j], q[i], q[j], CCW_A)
        if o != 0.0:
            return False
    inside = True
    for i in range(3):
        inside &= min(P[a, i], P[b, i]) <= q[i] <= max(P[a, i], P[b, i])
    return inside


@njit(cache=True)
def _on_hull3(P, S, q, nh, iw, w):
    """Weights of q on the hull (facets in iw[RING]): linear along a hull
    edge where faces of two planes meet, else the limit from inside over
    the plane of the facets (``_plane_limit``)."""
    f0 = iw[RING, 0]
    single = True
    for h in range(1, nh):
        single &= _coplanar(P, S, f0, iw[RING, h])
    if single:
        return _plane_limit(P, S, q, nh, iw, w)
    for h in range(nh):
        a, b, c = _others(S, iw[RING, h] // 4, iw[RING, h] % 4)
        for (u, v) in ((a, b), (b, c), (c, a)):
            if _between(P, u, v, q):
                return _linear(P, u, v, q, iw, w)
    return -1  # unreachable on a valid mesh: q on two planes lies on an edge of both


@njit(cache=True, inline="always")
def _shared(S, iw, nh, h, a, b):
    """Whether another facet of iw[RING] has the edge b -> a (outward
    order): the face across a -> b is in the plane's cavity too."""
    for g in range(nh):
        if g != h:
            u, v, x = _outward(S, iw[RING, g])
            if (u == b and v == a) or (v == b and x == a) or (x == b and u == a):
                return True
    return False


@njit(cache=True, inline="always")
def _fan(a, p, r, normal):
    """Integral over the triangle (a / 2, p, r) (signed, about the unit
    normal) of |y - a|^2 - |y|^2 = -2 a.(y - a / 2), which is 0 at a / 2:
    the area times the mean of the integrand at the three corners."""
    m = _times(0.5, a)
    area = 0.5 * _dot(_cross(_sub(p, m), _sub(r, m)), normal)
    return area * -2.0 * (_dot(a, _sub(p, m)) + _dot(a, _sub(r, m))) / 3.0


@njit(cache=True)
def _plane_limit(P, S, q, nh, iw, w):
    """The limit from inside of the Sibson coordinates of q on a hull face:
    lambda_v proportional to the integral of |y - v|^2 - |y - q|^2 over v's
    stolen region in the face's plane, cut from the 2D Voronoi diagram of
    the plane's data points by the hull facets whose circumcircle holds q
    (iw[RING]: exactly those of the cavity in the plane).  As in 2D, each
    facet and edge a -> b adds the fan triangle (m_a, base, C_f) to a and
    (m_b, C_f, base) to b, m_v the midpoint of q and v; base is the midpoint
    of a and b when the facet across is in the plane's cavity (both fans
    then split the same Voronoi edge at one point), else the new
    circumcentre of (q, a, b)."""
    a, b, c = _outward(S, iw[RING, 0])
    normal = _cross(_sub(P[b], P[a]), _sub(P[c], P[a]))
    normal = _times(1.0 / np.sqrt(_dot(normal, normal)), normal)
    n = 0
    for h in range(nh):
        a, b, c = _outward(S, iw[RING, h])
        pa = _rel(P, a, q)
        centre = _plus(pa, _tri_centre(_sub(_rel(P, b, q), pa), _sub(_rel(P, c, q), pa)))
        for (u, v) in ((a, b), (b, c), (c, a)):
            pu, pv = _rel(P, u, q), _rel(P, v, q)
            if _shared(S, iw, nh, h, u, v):
                base = _times(0.5, _plus(pu, pv))
            else:
                base = _tri_centre(pu, pv)
            n = _add(iw, w, n, u, _fan(pu, base, centre, normal))
            n = _add(iw, w, n, v, _fan(pv, centre, base, normal))
    return n


# -- the queries -------------------------------------------------------------

@njit(cache=True)
def _weights(P, S, N, q, t, iw, w, C):
    """Natural-neighbour coordinates of q in simplex t, normalised: their
    number, -1 when the scratch is full."""
    if P.shape[1] == 2:
        n = _weights2(P, S, N, q, t, iw, w)
    else:
        n = _weights3(P, S, N, q, t, iw, w, C)
    if n > 1:
        total = 0.0
        for k in range(n):
            total += w[k]
        for k in range(n):
            w[k] /= total
    return n


@njit(cache=True, nogil=True)
def _interpolate(P, S, N, values, Q, simplex, fill, out, rows, capacity):
    """out[k] for each k in ``rows``: the natural-neighbour interpolant of
    ``values`` at Q[k] (in the frame of P), found in simplex[k] (-1: fill).
    Returns how many queries had a cavity of more than ``capacity``
    simplices; their rows are moved to the front of ``rows``."""
    d = P.shape[1]
    iw, w, C = _scratch(capacity, d)
    q = np.empty(d)
    failed = 0
    for r in range(rows.shape[0]):
        k = rows[r]
        t = simplex[k]
        if t < 0:
            out[k, :] = fill
            continue
        for a in range(d):
            q[a] = Q[k, a]
        n = _weights(P, S, N, q, t, iw, w, C)
        if n < 0:
            rows[failed] = k
            failed += 1
            continue
        out[k, :] = 0.0
        for j in range(n):
            v, lam = iw[IDS, j], w[j]
            for c in range(values.shape[1]):
                out[k, c] += lam * values[v, c]
    return failed


def _frame_queries(tri, xi):
    """(queries in the frame of tri, their simplices): a component that the
    frame cannot hold (nonzero, below its floor once scaled) is taken as 0,
    and the simplices are those of the queries so changed."""
    with np.errstate(over="ignore"):  # far outside the box: inf, and find_simplex says -1
        Q = xi * tri._scale
    tiny = (Q != 0.0) & (np.abs(Q) < tri._floor)
    if tiny.any():
        Q[tiny] = 0.0
        xi = np.where(tiny, 0.0, xi)
    return Q, np.ascontiguousarray(tri.find_simplex(xi), dtype=np.int64)


def _larger(capacity, tri):
    """Four times the scratch; a cavity never holds more than every simplex,
    so a query that did not fit that is a bug, reported rather than looped
    on or answered."""
    if capacity > tri.nsimplex:
        raise RuntimeError("lfqt.natural: a cavity did not fit the scratch for every simplex "
                           "of the mesh; please report this with the data")
    return 4 * capacity


def interpolate(tri: Delaunay, values: npt.ArrayLike, xi: npt.ArrayLike,
                fill_value: float) -> npt.NDArray[np.float64]:
    """The natural-neighbour (Sibson) interpolant of ``values`` at ``xi``.

    Parameters
    ----------
    tri : lfqt.Delaunay
        2D or 3D; its ``threads`` serve the queries too.
    values : ndarray of float64, shape (npoints, k), C-contiguous
        The data, one row per input point (a duplicate row's value is not
        used: its location takes the value of the row kept as the vertex).
    xi : ndarray of float64, shape (m, ndim)
    fill_value : float
        The value outside the convex hull (and at NaN queries).

    Returns
    -------
    ndarray of float64, shape (m, k)

    Raises
    ------
    ValueError
        ``values`` or ``xi`` of the wrong shape.

    Notes
    -----
    On the hull the value is the limit from inside (module docstring): in
    2D linear along the hull edge.  The natural neighbours are exact; the
    weights are accurate to a few ulps of their sum in well-shaped
    configurations.

    Examples
    --------
    >>> import numpy as np, lfqt
    >>> from lfqt import natural
    >>> pts = np.array([[0, 0], [1, 0], [0, 1], [1, 1], [0.5, 0.6]])
    >>> tri = lfqt.Delaunay(pts)
    >>> f = pts @ [[1.0], [2.0]]                  # x + 2y: reproduced exactly
    >>> natural.interpolate(tri, f, np.array([[0.3, 0.25], [2.0, 0.0]]), np.nan)
    array([[0.8],
           [nan]])
    """
    values = np.ascontiguousarray(values, dtype=np.float64)
    xi = np.ascontiguousarray(xi, dtype=np.float64)
    if values.ndim != 2 or values.shape[0] != tri.npoints:
        raise ValueError(f"values must have shape ({tri.npoints}, k), got {values.shape}")
    if xi.ndim != 2 or xi.shape[1] != tri.ndim:
        raise ValueError(f"xi must have shape (m, {tri.ndim}), got {xi.shape}")
    Q, simplex = _frame_queries(tri, xi)
    out = np.empty((len(xi), values.shape[1]))
    P, S, N = tri._frame(), tri.simplices, tri.neighbors
    # curve order: consecutive cavities share the mesh's cache lines (docs/performance.md,
    # "natural-neighbour queries")
    rows = grid_order(Q)
    capacity = CAPACITY
    while True:
        workers = tri._workers() if len(rows) > MIN_CHUNK else Workers(1)
        chunks = workers.chunks(len(rows), min_chunk=MIN_CHUNK)
        failed = workers.map(chunks, lambda c, lo, hi: _interpolate(
            P, S, N, values, Q, simplex, float(fill_value), out, rows[lo:hi], capacity))
        if not any(failed):
            return out
        rows = np.concatenate([rows[lo:lo + f] for (lo, _), f in zip(chunks, failed)])
        capacity = _larger(capacity, tri)


def weights(tri: Delaunay, q: npt.ArrayLike
            ) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.float64]]:
    """The natural neighbours of one point and their Sibson coordinates.

    Parameters
    ----------
    tri : lfqt.Delaunay
    q : array_like, shape (ndim,)

    Returns
    -------
    indices : ndarray of int64
        Rows of ``tri.points`` (vertices: a duplicate row is represented by
        the row kept), in increasing order; empty outside the hull.
    weights : ndarray of float64
        Their coordinates: nonnegative (up to rounding), summing to 1, and
        q = sum of weights * points.

    Examples
    --------
    >>> import numpy as np, lfqt
    >>> from lfqt import natural
    >>> pts = np.array([[0, 0], [1, 0], [0, 1], [1, 1], [0.5, 0.6]])
    >>> tri = lfqt.Delaunay(pts)
    >>> natural.weights(tri, [0.5, 0.0])         # on the hull: linear along its edge
    (array([0, 1]), array([0.5, 0.5]))
    >>> ids, w = natural.weights(tri, [0.3, 0.25])
    >>> ids, np.round(w, 4)
    (array([0, 1, 2, 4]), array([0.4873, 0.1134, 0.0261, 0.3731]))
    """
    xi = np.asarray(q, dtype=np.float64).reshape(1, -1)
    if xi.shape[1] != tri.ndim:
        raise ValueError(f"q must have {tri.ndim} coordinates, got {xi.shape[1]}")
    Q, simplex = _frame_queries(tri, xi)
    if simplex[0] < 0:
        return np.empty(0, dtype=np.int64), np.empty(0)
    capacity = CAPACITY
    while True:
        iw, w, C = _scratch(capacity, tri.ndim)
        n = _weights(tri._frame(), tri.simplices, tri.neighbors, Q[0], simplex[0], iw, w, C)
        if n >= 0:
            break
        capacity = _larger(capacity, tri)
    order = np.argsort(iw[IDS, :n], kind="stable")
    return iw[IDS, :n][order].copy(), w[:n][order].copy()
