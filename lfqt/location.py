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
brute force tests every simplex.  Coordinates are in the rescaled frame of
the triangulation; a query that frame cannot hold exactly is located on the
original coordinates in rational arithmetic instead (``locate_rational``).
"""
from fractions import Fraction

import numpy as np
from numba import njit

from .predicates.counters import N_PREDICATE, orient2d
from .predicates.planar import CCW_A
from .predicates.spatial import O3D_A, orient3d_staged


@njit(cache=True, inline="always")
def _vertex(P, v, q, replaced):
    if replaced:
        return q[0], q[1], q[2]
    return P[v, 0], P[v, 1], P[v, 2]


@njit(cache=True)
def _beyond(P, S, t, i, q, cnt):
    """True when q lies strictly beyond the facet of simplex t opposite
    vertex i."""
    if P.shape[1] == 2:
        a = S[t, (i + 1) % 3]
        b = S[t, (i + 2) % 3]
        return orient2d(P[a, 0], P[a, 1], P[b, 0], P[b, 1], q[0], q[1], CCW_A, cnt) < 0.0
    ax, ay, az = _vertex(P, S[t, 0], q, i == 0)
    bx, by, bz = _vertex(P, S[t, 1], q, i == 1)
    cx, cy, cz = _vertex(P, S[t, 2], q, i == 2)
    dx, dy, dz = _vertex(P, S[t, 3], q, i == 3)
    o, _ = orient3d_staged(ax, ay, az, bx, by, bz, cx, cy, cz, dx, dy, dz, O3D_A)
    return o < 0.0


@njit(cache=True)
def _contains(P, S, t, q, cnt):
    for i in range(S.shape[1]):
        if _beyond(P, S, t, i, q, cnt):
            return False
    return True


@njit(cache=True)
def locate_walk(P, S, N, Q, start):
    """Simplex of each query row of Q by the visibility walk, -1 outside;
    a walk that exceeds its step budget falls back to the brute force."""
    cnt = np.zeros(N_PREDICATE, dtype=np.int64)
    m, k1 = S.shape
    out = np.empty(Q.shape[0], dtype=np.int64)
    t = start
    for k in range(Q.shape[0]):
        q = Q[k]
        if t < 0:
            t = start
        found = -2  # -2: the budget ran out
        for _ in range(4 * m + 4):
            moved = False
            for j in range(k1):
                i = (j + k) % k1  # vary the first facet tried, so the walk cannot cycle
                if _beyond(P, S, t, i, q, cnt):
                    t = N[t, i]
                    moved = True
                    break
            if not moved:
                found = t
                break
            if t < 0:
                found = -1
                break
        if found == -2:
            found = -1
            for s in range(m):
                if _contains(P, S, s, q, cnt):
                    found = s
                    break
        out[k] = found
        if found >= 0:
            t = found
    return out


@njit(cache=True)
def locate_brute(P, S, Q):
    """Simplex of each query row of Q by testing every simplex, -1 outside."""
    cnt = np.zeros(N_PREDICATE, dtype=np.int64)
    out = np.full(Q.shape[0], -1, dtype=np.int64)
    for k in range(Q.shape[0]):
        for s in range(S.shape[0]):
            if _contains(P, S, s, Q[k], cnt):
                out[k] = s
                break
    return out


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
    exact rational arithmetic: for the rare query the rescaled frame cannot
    hold exactly.  Brute force when the walk's budget runs out."""
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
