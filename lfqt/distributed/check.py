"""An exact check of a distributed triangulation, share by share (a share is
one tile's file, or a slice of gathered triangles), that never loads the
whole point set on one process.  A mesh is the Delaunay triangulation of P
when:

1. every triangle is counter-clockwise (exact orientation > 0);
2. every directed edge occurs once, and each edge with a twin is locally
   Delaunay (exact in-circle of the opposite vertex <= 0);
3. the edges without a twin form one cycle that turns once around its
   first vertex, convex, with no point of P strictly outside it;
4. the triangles use as many vertices as P has distinct points.

(1)-(3) make the triangles cover the hull exactly once (their signed areas
add up to the cycle's); with locally Delaunay edges the cover is the
Delaunay triangulation of its vertices (Delaunay's lemma), and (4) makes
those all of P.  Edges inside a share are paired there; the others, a
share's border, are paired up a tree of tasks (``pair_borders``), whose
root holds the hull's edges only (``check_border``).  The coordinates
travel by shuffle files: each share writes the ids it needs grouped by
chunk, each chunk writes their coordinates grouped by share.
"""
import numpy as np
from numba import njit

from ..predicates.planar import CCW_A, ICC_A, incircle_staged, orient2d_staged
from . import partition, shuffle
from .sources import read


def share_triangles(kind, what):
    """A share's (m, 3) global ids."""
    if kind == "npy":
        return np.load(what).astype(np.int64).reshape(-1, 3)
    if kind == "parquet":
        import pyarrow.parquet as pq
        t = pq.read_table(what)
        return np.column_stack([t.column(c).to_numpy() for c in ("a", "b", "c")]).astype(np.int64)
    return np.asarray(what, dtype=np.int64).reshape(-1, 3)


def _share(kind, what, starts):
    """(triangles in share-local vertex numbers, their sorted global ids,
    how many triangles name a vertex that is no point; those are left
    out)."""
    S = share_triangles(kind, what)
    inside = ((S >= 0) & (S < starts[-1])).all(axis=1)
    ids, L = _unique_inverse(S[inside].ravel())
    return L.reshape(-1, 3), ids, int((~inside).sum())


def requests(kind, what, starts, path):
    """Write the share's vertex ids, grouped by the chunk that holds them
    (part c: chunk c), to a shuffle file, and its triangles in their
    numbers beside it (``check_share`` reads both: they wait on disk, not
    in memory); returns (the shuffle file's path, how many triangles name
    a vertex that is no point)."""
    L, ids, unknown = _share(kind, what, starts)
    with shuffle.writing(path):
        np.save(f"{path}.triangles.npy", L)
    return shuffle.write(path, np.searchsorted(ids, starts), ids), unknown


def _unique_inverse(x):
    """(sorted distinct values, index of each x among them), by one sort."""
    order = np.argsort(x, kind="stable")
    xs = x[order]
    new = np.ones(len(xs), dtype=bool)
    new[1:] = xs[1:] != xs[:-1]
    inverse = np.empty(len(x), dtype=np.int64)
    inverse[order] = np.cumsum(new) - 1
    return xs[new], inverse


def lookup(kind, what, start, scale_exp, c, requested, path):
    """Write the coordinates (scaled) of what each share asked of chunk
    ``c`` (part s: share s) to a shuffle file; returns (its path, how many
    distinct ids of the chunk are used at all)."""
    P = read(kind, what).astype(np.float64) * 2.0 ** scale_exp
    wanted = [shuffle.read(r, c)[0] for r in requested]
    w = np.concatenate(wanted + [np.empty(0, np.int64)])
    starts = np.concatenate(([0], np.cumsum([len(x) for x in wanted], dtype=np.int64)))
    return shuffle.write(path, starts, P[w - start]), _distinct(w)


def _distinct(x):
    """How many distinct values x holds."""
    if not len(x):
        return 0
    xs = np.sort(x)
    return int(np.count_nonzero(xs[1:] != xs[:-1])) + 1


def check_share(s, request, found):
    """Checks 1 and 2 inside share ``s``: (counts, border edges (u, v, w)
    and their coordinates); ``request``: what ``requests`` returned for it,
    ``found``: the lookups' files, whose part s holds the share's
    coordinates, chunk by chunk in id order."""
    path, unknown = request
    L = np.load(f"{path}.triangles.npy")
    ids = np.concatenate([shuffle.read(path, c)[0] for c in range(len(found))]
                         + [np.empty(0, np.int64)])
    P = np.concatenate([shuffle.read(f, s)[0] for f in found] + [np.empty((0, 2))])
    bad_orient = _bad_orientation(P, L)
    a, b, w = _edges(L)
    pairs, repeated, lone = _pair(a, b, len(ids))
    bad_local = _not_locally_delaunay(P, a, b, w, pairs)
    border = (ids[a[lone]], ids[b[lone]], ids[w[lone]], P[a[lone]], P[b[lone]], P[w[lone]])
    return dict(triangles=len(L), vertex_not_a_point=unknown, not_counter_clockwise=bad_orient,
                repeated_edges=repeated, not_locally_delaunay=bad_local), border


def _edges(L):
    """Directed edges a -> b of every triangle (the edge opposite vertex k),
    with the opposite vertex w."""
    a = L[:, [1, 2, 0]].ravel()
    b = L[:, [2, 0, 1]].ravel()
    w = L.ravel()
    return a, b, w


def _pair(a, b, n):
    """(twin pairs (i, j), count of edges seen more often than a triangle
    on each side allows, indices of the edges without a twin); a and b
    index n vertices.  One sort of the undirected keys: twins end up side
    by side."""
    n = np.int64(max(int(n), 1))
    lo, hi = np.minimum(a, b).astype(np.int64), np.maximum(a, b).astype(np.int64)
    order = np.argsort(lo * n + hi, kind="stable")
    key = (lo * n + hi)[order]
    forward = (a < b)[order]
    start = np.ones(len(key), dtype=bool)
    start[1:] = key[1:] != key[:-1]
    group = np.cumsum(start) - 1
    size = np.bincount(group) if len(key) else np.zeros(0, dtype=np.int64)
    firsts = np.flatnonzero(start)
    two = size == 2
    i, j = order[firsts[two]], order[firsts[two] + 1]
    opposite = forward[firsts[two]] != forward[firsts[two] + 1]
    repeated = int(np.count_nonzero(size > 2) + np.count_nonzero(~opposite))
    lone = order[firsts[size == 1]]
    return np.column_stack((i[opposite], j[opposite])), repeated, lone


@njit(cache=True)
def _bad_orientation(P, L):
    bad = 0
    for t in range(L.shape[0]):
        a, b, c = L[t, 0], L[t, 1], L[t, 2]
        v, _ = orient2d_staged(P[a, 0], P[a, 1], P[b, 0], P[b, 1], P[c, 0], P[c, 1], CCW_A)
        if not v > 0.0:
            bad += 1
    return bad


@njit(cache=True)
def _not_locally_delaunay(P, a, b, w, pairs):
    """Edges whose twin's opposite vertex is strictly inside the circle of
    the triangle (a, b, w)."""
    bad = 0
    for k in range(pairs.shape[0]):
        i, j = pairs[k, 0], pairs[k, 1]
        x, y, z, d = b[i], w[i], a[i], w[j]  # triangle (a, b, w) counter-clockwise: b, w, a
        v, _ = incircle_staged(P[x, 0], P[x, 1], P[y, 0], P[y, 1], P[z, 0], P[z, 1],
                               P[d, 0], P[d, 1], ICC_A)
        if v > 0.0:
            bad += 1
    return bad


def pair_borders(*borders):
    """Check 2 across a few shares' borders (one node of the reduction
    tree): (counts, the edges still without a twin, passed up)."""
    u, v, w = (np.concatenate([b[k] for b in borders] + [np.empty(0, np.int64)])
               for k in (0, 1, 2))
    Pu, Pv, Pw = (np.concatenate([b[k] for b in borders] + [np.empty((0, 2))]) for k in (3, 4, 5))
    ids, inv = np.unique(np.concatenate((u, v, w)), return_inverse=True)
    m = len(u)
    a, b, c = inv[:m], inv[m:2 * m], inv[2 * m:]
    P = np.empty((len(ids), 2))
    P[a], P[b], P[c] = Pu, Pv, Pw
    pairs, repeated, lone = _pair(a, b, len(ids))
    counts = dict(repeated_edges=repeated, not_locally_delaunay=_not_locally_delaunay(
        P, a, b, c, pairs))
    return counts, (u[lone], v[lone], w[lone], Pu[lone], Pv[lone], Pw[lone])


def check_border(*borders):
    """The root of the reduction tree: check 2 across what is left and the
    cycle of check 3: (counts, the hull loop's coordinates in order)."""
    counts, (u, v, _, Pu, Pv, _) = pair_borders(*borders)
    ids, inv = np.unique(np.concatenate((u, v)), return_inverse=True)
    a, b = inv[:len(u)], inv[len(u):]
    P = np.empty((len(ids), 2))
    P[a], P[b] = Pu, Pv
    loop, problem = _cycle(a, b)
    if problem:
        counts["hull_not_one_cycle"] = 1
        return counts, np.empty((0, 2))
    H = P[loop]
    counts["hull_not_convex"] = int(_not_convex(H))
    return counts, H


def _cycle(a, b):
    """The loop of the directed edges a -> b, or a problem when they are not
    one cycle through distinct vertices."""
    if not len(a):
        return np.empty(0, dtype=np.int64), False
    if len(np.unique(a)) != len(a) or len(np.unique(b)) != len(b):
        return None, True
    nxt = dict(zip(a.tolist(), b.tolist()))
    loop = [int(a[0])]
    while len(loop) <= len(a):
        nx = nxt.get(loop[-1])
        if nx is None:
            return None, True
        if nx == loop[0]:
            break
        loop.append(nx)
    return np.array(loop, dtype=np.int64), len(loop) != len(a)


@njit(cache=True)
def _orient(p, q, r):
    v, _ = orient2d_staged(p[0], p[1], q[0], q[1], r[0], r[1], CCW_A)
    return v


@njit(cache=True)
def _not_convex(H):
    """Turns of the cycle that go right, or a fan from H[0] that goes back
    (a cycle winding more than once)."""
    h = H.shape[0]
    bad = 0
    for k in range(h):
        if _orient(H[k - 1], H[k], H[(k + 1) % h]) < 0.0:
            bad += 1
    for k in range(1, h - 1):
        if _orient(H[0], H[k], H[k + 1]) < 0.0:
            bad += 1
    return bad


@njit(cache=True)
def _outside(P, H):
    """Points strictly outside the convex counter-clockwise polygon H, by a
    binary search of the fan from H[0] (exact orientations)."""
    h = H.shape[0]
    bad = 0
    for i in range(P.shape[0]):
        p = P[i]
        if _orient(H[0], H[1], p) < 0.0 or _orient(H[h - 1], H[0], p) < 0.0:
            bad += 1
            continue
        lo, hi = 1, h - 1  # p lies in the cone between rays H0->H[lo] and H0->H[hi]
        while hi - lo > 1:
            mid = (lo + hi) // 2
            if _orient(H[0], H[mid], p) >= 0.0:
                lo = mid
            else:
                hi = mid
        if _orient(H[lo], H[hi], p) < 0.0:
            bad += 1
    return bad


def outside_hull(kind, what, scale_exp, H):
    """Check 3 on one chunk: its points strictly outside the hull loop H."""
    if len(H) < 3:
        return 0
    P = read(kind, what).astype(np.float64) * 2.0 ** scale_exp
    return int(_outside(P, H))


def collinear_extremes(kind, what, scale_exp):
    """A chunk's lexicographically smallest and largest points."""
    P = read(kind, what).astype(np.float64) * 2.0 ** scale_exp
    if not len(P):
        return np.empty((0, 2))
    order = np.lexsort((P[:, 1], P[:, 0]))
    return P[order[[0, -1]]]


@njit(cache=True)
def _off_line(P, a, b):
    bad = 0
    for i in range(P.shape[0]):
        if _orient(a, b, P[i]) != 0.0:
            bad += 1
    return bad


def off_line(kind, what, scale_exp, a, b):
    """Points of the chunk off the line a-b."""
    P = read(kind, what).astype(np.float64) * 2.0 ** scale_exp
    return int(_off_line(P, a, b))


def tile_distinct(local):
    """Distinct points of one tile (equal points always share a tile)."""
    P = partition.load(local)["P"]
    if not len(P):
        return 0
    order = np.lexsort((P[:, 1], P[:, 0]))
    return int(np.count_nonzero((P[order[1:]] != P[order[:-1]]).any(axis=1))) + 1
