"""The exact geometry of Tile & Merge on one tile: kernels over a tile's
triangulation (flat arrays, scipy's conventions, local vertex indices).

    faces        the Delaunay subdivision: triangles joined across edges
                 whose four points are cocircular (exact in-circle == 0)
    reach        which other tiles' boxes a face's closed circumdisk meets
    hull_runs    the infinite faces: maximal runs of collinear hull edges
    canonical    each cocircular face re-triangulated as a fan from its
                 smallest global id, so that every tile cuts it the same way

Coordinates are global ones scaled by one exact power of two into the
predicates' window (lfqt._input), so that no product here overflows or
leaves the normal range.  ``reach`` is a float filter with a rigorous error
bound: it may report a disk as meeting a box it misses (an extra message),
never the reverse.
"""
import numpy as np
from numba import njit

from ..predicates.expansion import EPS
from ..predicates.planar import CCW_A, ICC_A, incircle_staged, orient2d_staged

#  A face's circumdisk and a box: the closest point of the box to the centre
#  c is within r (and slack) of it.
#
#        +--------+  box j
#        |     .--|--.
#        |    /   |   \      meets: dist(c, box) <= r
#        +---|----+ c  |
#             \       /
#              '-----'


@njit(cache=True, inline="always")
def _find(parent, t):
    while parent[t] != t:
        parent[t] = parent[parent[t]]
        t = parent[t]
    return t


@njit(cache=True)
def faces(P, S, N):
    """face[t]: the smallest triangle index of t's face of the Delaunay
    subdivision (triangles joined across edges with cocircular ends)."""
    m = S.shape[0]
    parent = np.arange(m)
    for t in range(m):
        for k in range(3):
            s = N[t, k]
            if s <= t:
                continue  # the hull, or an edge seen from s already
            d = S[s, 0] + S[s, 1] + S[s, 2] - S[t, (k + 1) % 3] - S[t, (k + 2) % 3]
            a, b, c = S[t, 0], S[t, 1], S[t, 2]
            v, _ = incircle_staged(P[a, 0], P[a, 1], P[b, 0], P[b, 1], P[c, 0], P[c, 1],
                                   P[d, 0], P[d, 1], ICC_A)
            if v == 0.0:
                ra, rb = _find(parent, t), _find(parent, s)
                if ra != rb:
                    parent[max(ra, rb)] = min(ra, rb)
    for t in range(m):
        parent[t] = _find(parent, t)
    return parent


@njit(cache=True)
def _disk(P, a, b, c):
    """(cx, cy, r, slack) of the circumdisk of a, b, c: the true disk lies
    within the disk of centre (cx, cy) and radius r + slack.  slack is inf
    when the triangle is too flat for a float bound."""
    ax, ay = P[a, 0], P[a, 1]
    bx, by = P[b, 0] - ax, P[b, 1] - ay
    qx, qy = P[c, 0] - ax, P[c, 1] - ay
    d = bx * qy - by * qx
    e_d = 8.0 * EPS * (abs(bx * qy) + abs(by * qx))
    if not abs(d) > 4.0 * e_d:
        return ax, ay, 0.0, np.inf
    b2 = bx * bx + by * by
    q2 = qx * qx + qy * qy
    nx = qy * b2 - by * q2
    ny = bx * q2 - qx * b2
    e_nx = 12.0 * EPS * (abs(qy) * b2 + abs(by) * q2)
    e_ny = 12.0 * EPS * (abs(bx) * q2 + abs(qx) * b2)
    ux = nx / (2.0 * d)
    uy = ny / (2.0 * d)
    den = 2.0 * (abs(d) - e_d)
    dx = (e_nx + 2.0 * abs(ux) * e_d) / den + 2.0 * EPS * abs(ux)
    dy = (e_ny + 2.0 * abs(uy) * e_d) / den + 2.0 * EPS * abs(uy)
    cx, cy = ax + ux, ay + uy
    r = np.sqrt(ux * ux + uy * uy)
    slack = 2.0 * (dx + dy) + 8.0 * EPS * (abs(cx) + abs(cy) + r)
    return cx, cy, r, slack


@njit(cache=True, inline="always")
def _gap(v, lo, hi):
    return max(lo - v, 0.0, v - hi)


@njit(cache=True)
def _meets_box(cx, cy, r, slack, box):
    """The closed disk may meet the closed box (x0, y0, x1, y1)."""
    if slack == np.inf:
        return True
    gx = _gap(cx, box[0], box[2])
    gy = _gap(cy, box[1], box[3])
    dist = np.sqrt(gx * gx + gy * gy)
    scale = abs(cx) + abs(cy) + abs(box[0]) + abs(box[1]) + abs(box[2]) + abs(box[3])
    return dist * (1.0 - 16.0 * EPS) <= (r + slack) * (1.0 + 16.0 * EPS) + 16.0 * EPS * scale


@njit(cache=True)
def _inside_cell(cx, cy, r, slack, cell):
    """The closed disk lies strictly inside the open cell (x0, y0, x1, y1),
    whose sides may be infinite: then it meets no other tile's box."""
    if slack == np.inf:
        return False
    big = (r + slack) * (1.0 + 16.0 * EPS) + 16.0 * EPS * (abs(cx) + abs(cy))
    return (cx - big > cell[0] and cy - big > cell[1] and cx + big < cell[2]
            and cy + big < cell[3])


@njit(cache=True)
def reach(P, S, roots, cell, boxes, me):
    """(face, tile) pairs: the closed circumdisk of face ``roots[f]`` (a
    triangle of it) may meet tile j's box, j != me; and per face whether
    its disk lies strictly inside the tile's own cell.  Boxes of empty
    tiles are NaN and met by nothing."""
    out_f = np.empty(16, dtype=np.int64)
    out_j = np.empty(16, dtype=np.int64)
    inside = np.zeros(len(roots), dtype=np.bool_)
    k = 0
    for f in range(len(roots)):
        t = roots[f]
        cx, cy, r, slack = _disk(P, S[t, 0], S[t, 1], S[t, 2])
        if _inside_cell(cx, cy, r, slack, cell):
            inside[f] = True
            continue
        for j in range(boxes.shape[0]):
            if j == me or np.isnan(boxes[j, 0]):
                continue
            if _meets_box(cx, cy, r, slack, boxes[j]):
                if k == len(out_f):
                    out_f = np.concatenate((out_f, np.empty(k, dtype=np.int64)))
                    out_j = np.concatenate((out_j, np.empty(k, dtype=np.int64)))
                out_f[k] = f
                out_j[k] = j
                k += 1
    return out_f[:k], out_j[:k], inside


@njit(cache=True)
def unsealed(S, face_of_root, inside, hull, n_local):
    """Local vertices (index < n_local) whose star may still change: on the
    hull, or with a face whose closed disk is not strictly inside the cell
    (``inside`` per face, ``face_of_root`` maps a face's root triangle to
    its face number).  Points from other tiles lie outside the cell, so the
    other stars are final."""
    out = np.zeros(n_local, dtype=np.bool_)
    for t in range(S.shape[0]):
        if not inside[face_of_root[t]]:
            for k in range(3):
                if S[t, k] < n_local:
                    out[S[t, k]] = True
    for v in hull:
        if v < n_local:
            out[v] = True
    return out


@njit(cache=True)
def owned(S, gid, home, frontier, final):
    """Global ids of the triangles a tile outputs: smallest global id
    local, and no frontier vertex (``final``: the sealed interior) or at
    least one."""
    keep = np.zeros(S.shape[0], dtype=np.bool_)
    for t in range(S.shape[0]):
        a, b, c = S[t, 0], S[t, 1], S[t, 2]
        m = a
        if gid[b] < gid[m]:
            m = b
        if gid[c] < gid[m]:
            m = c
        touches = frontier[a] or frontier[b] or frontier[c]
        keep[t] = home[m] < 0 and touches != final
    out = np.empty((np.count_nonzero(keep), 3), dtype=np.int64)
    k = 0
    for t in range(S.shape[0]):
        if keep[t]:
            for i in range(3):
                out[k, i] = gid[S[t, i]]
            k += 1
    return out


@njit(cache=True)
def with_face_neighbours(S, marked, face):
    """marked, plus every vertex of a face of the Delaunay subdivision
    (``face[t]``: the root triangle of t's face, ``faces``) that has a
    marked vertex.  For a face of one triangle these are the vertex's
    neighbours; a cocircular face is taken whole, since its canonical fan
    (``canonical``) may join a marked vertex to any of its vertices::

        3 ------ 6*         raw triangles 3-5-2 and 6-5-3: 2 is no
        |  .   / |          neighbour of the marked 6, but the fan
        |    /   |          from 2 (the smallest id) cuts the face
        2 ------ 5          into 2-3-6 and 2-6-5, both at 6.
    """
    hit = np.zeros(S.shape[0], dtype=np.bool_)  # by root triangle
    for t in range(S.shape[0]):
        if marked[S[t, 0]] or marked[S[t, 1]] or marked[S[t, 2]]:
            hit[face[t]] = True
    out = marked.copy()
    for t in range(S.shape[0]):
        if hit[face[t]]:
            for k in range(3):
                if S[t, k] < len(out):
                    out[S[t, k]] = True
    return out


@njit(cache=True)
def _orient(P, a, b, x, y):
    v, _ = orient2d_staged(P[a, 0], P[a, 1], P[b, 0], P[b, 1], x, y, CCW_A)
    return v


@njit(cache=True)
def hull_runs(P, hull):
    """run[m]: the first edge of the maximal run of collinear hull edges
    that edge m = (hull[m], hull[m+1]) belongs to (the loop is CCW)."""
    h = len(hull)
    run = np.arange(h)
    # rotate so that a run never wraps: start after a corner
    start = 0
    for m in range(h):
        a, b, c = hull[m], hull[(m + 1) % h], hull[(m + 2) % h]
        if _orient(P, a, b, P[c, 0], P[c, 1]) != 0.0:
            start = (m + 1) % h
            break
    for i in range(1, h):
        m = (start + i) % h
        prev = (m - 1) % h
        a, b, c = hull[prev], hull[m], hull[(m + 1) % h]
        if _orient(P, a, b, P[c, 0], P[c, 1]) == 0.0:
            run[m] = run[prev]
    return run


@njit(cache=True)
def beyond(P, a, b, boxes, me):
    """Tiles whose box has a corner on or right of the line a -> b (the
    closed outer half-plane of a counter-clockwise hull edge)."""
    out = np.empty(boxes.shape[0], dtype=np.int64)
    k = 0
    for j in range(boxes.shape[0]):
        if j == me or np.isnan(boxes[j, 0]):
            continue
        for cx, cy in ((boxes[j, 0], boxes[j, 1]), (boxes[j, 2], boxes[j, 1]),
                       (boxes[j, 0], boxes[j, 3]), (boxes[j, 2], boxes[j, 3])):
            if _orient(P, a, b, cx, cy) <= 0.0:
                out[k] = j
                k += 1
                break
    return out[:k]


@njit(cache=True)
def canonical(S, N, face, order, starts, gid):
    """S with every face of more than one triangle re-triangulated as the
    fan from its vertex of smallest global id, keeping counter-clockwise
    rows.  ``order``/``starts``: the triangles grouped by face."""
    out = S.copy()
    nxt = np.full(len(gid), -1, dtype=np.int64)
    for g in range(len(starts) - 1):
        lo, hi = starts[g], starts[g + 1]
        if hi - lo < 2:
            continue
        f = face[order[lo]]
        best = -1
        for i in range(lo, hi):
            t = order[i]
            for k in range(3):
                s = N[t, k]
                if s == -1 or face[s] != f:  # a boundary edge of the face, CCW
                    u, w = S[t, (k + 1) % 3], S[t, (k + 2) % 3]
                    nxt[u] = w
                    if best == -1 or gid[u] < gid[best]:
                        best = u
        w1 = nxt[best]
        i = lo
        while True:
            w2 = nxt[w1]
            if w2 == best:
                break
            t = order[i]
            out[t, 0], out[t, 1], out[t, 2] = best, w1, w2
            i += 1
            w1 = w2
        if i != hi:
            raise ValueError("a cocircular face is not a convex polygon")
        v = best
        while nxt[v] != -1:  # reset the boundary map for the next face
            w = nxt[v]
            nxt[v] = -1
            v = w
    return out
