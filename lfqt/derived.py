"""Kernels for the derived attributes of ``lfqt.Delaunay``, in scipy's
definitions and floating point: barycentric transforms, the lifted
hyperplanes (``equations``), and the vertex adjacency in CSR form.

Each is one pass over the simplices, computed on first access (scipy builds
``equations`` with the mesh; we build it only when asked).
"""
import numpy as np
from numba import njit

COND_LIMIT = 1.0 / (1000.0 * np.finfo(np.float64).eps)  # scipy's: 3 significant digits left


@njit(cache=True, inline="always")
def _inverse(T, d, out, t):
    """out[t, :d, :] = T^-1 (d = 2 or 3) by the adjugate; False when T is
    singular or its 1-norm condition number exceeds COND_LIMIT."""
    if d == 2:
        det = T[0, 0] * T[1, 1] - T[0, 1] * T[1, 0]
        if det == 0.0:
            return False
        out[t, 0, 0] = T[1, 1] / det
        out[t, 0, 1] = -T[0, 1] / det
        out[t, 1, 0] = -T[1, 0] / det
        out[t, 1, 1] = T[0, 0] / det
    else:
        c00 = T[1, 1] * T[2, 2] - T[1, 2] * T[2, 1]
        c01 = T[1, 2] * T[2, 0] - T[1, 0] * T[2, 2]
        c02 = T[1, 0] * T[2, 1] - T[1, 1] * T[2, 0]
        det = T[0, 0] * c00 + T[0, 1] * c01 + T[0, 2] * c02
        if det == 0.0:
            return False
        out[t, 0, 0] = c00 / det
        out[t, 1, 0] = c01 / det
        out[t, 2, 0] = c02 / det
        out[t, 0, 1] = (T[0, 2] * T[2, 1] - T[0, 1] * T[2, 2]) / det
        out[t, 1, 1] = (T[0, 0] * T[2, 2] - T[0, 2] * T[2, 0]) / det
        out[t, 2, 1] = (T[0, 1] * T[2, 0] - T[0, 0] * T[2, 1]) / det
        out[t, 0, 2] = (T[0, 1] * T[1, 2] - T[0, 2] * T[1, 1]) / det
        out[t, 1, 2] = (T[0, 2] * T[1, 0] - T[0, 0] * T[1, 2]) / det
        out[t, 2, 2] = (T[0, 0] * T[1, 1] - T[0, 1] * T[1, 0]) / det
    norm, inv_norm = 0.0, 0.0
    for j in range(d):
        col, inv_col = 0.0, 0.0
        for i in range(d):
            col += abs(T[i, j])
            inv_col += abs(out[t, i, j])
        norm = max(norm, col)
        inv_norm = max(inv_norm, inv_col)
    return norm * inv_norm < COND_LIMIT


@njit(cache=True, nogil=True)
def transforms(P, S):
    """(m, d+1, d): rows :d hold T^-1 and row d holds r, for T c = x - r
    with T's columns x_j - r and r the simplex's last vertex (scipy's
    ``transform``); NaN in T^-1 where T is too ill-conditioned."""
    m, k1 = S.shape
    d = k1 - 1
    out = np.empty((m, k1, d))
    T = np.empty((d, d))
    for t in range(m):
        r = S[t, d]
        for a in range(d):
            out[t, d, a] = P[r, a]
        for j in range(d):
            v = S[t, j]
            for a in range(d):
                T[a, j] = P[v, a] - P[r, a]
        if not _inverse(T, d, out, t):
            for i in range(d):
                for a in range(d):
                    out[t, i, a] = np.nan
    return out


@njit(cache=True, nogil=True)
def hyperplanes(P, S, scale, shift):
    """(m, d+2): unit normal and offset of each simplex's plane through its
    lifted vertices (x, |x|^2 * scale + shift), the normal pointing down
    (last component < 0), as Qhull's ``equations``."""
    m, k1 = S.shape
    d = k1 - 1
    out = np.empty((m, d + 2))
    V = np.empty((k1, k1))
    E = np.empty((d, k1))
    n = np.empty(k1)
    for t in range(m):
        for j in range(k1):
            lift = 0.0
            for a in range(d):
                V[j, a] = P[S[t, j], a]
                lift += V[j, a] * V[j, a]
            V[j, d] = lift * scale + shift
        for j in range(d):
            for a in range(k1):
                E[j, a] = V[j + 1, a] - V[0, a]
        if d == 2:  # the cross product of the two edges in 3D
            n[0] = E[0, 1] * E[1, 2] - E[0, 2] * E[1, 1]
            n[1] = E[0, 2] * E[1, 0] - E[0, 0] * E[1, 2]
            n[2] = E[0, 0] * E[1, 1] - E[0, 1] * E[1, 0]
        else:  # the generalised cross product of three edges in 4D: signed 3x3 minors
            for c in range(4):
                c0, c1, c2 = 1 if c == 0 else 0, 2 if c <= 1 else 1, 3 if c <= 2 else 2
                minor = (E[0, c0] * (E[1, c1] * E[2, c2] - E[1, c2] * E[2, c1])
                         - E[0, c1] * (E[1, c0] * E[2, c2] - E[1, c2] * E[2, c0])
                         + E[0, c2] * (E[1, c0] * E[2, c1] - E[1, c1] * E[2, c0]))
                n[c] = minor if c % 2 == 0 else -minor
        norm = 0.0
        for a in range(k1):
            norm += n[a] * n[a]
        norm = np.sqrt(norm)
        if n[d] > 0.0:
            norm = -norm
        offset = 0.0
        for a in range(k1):
            out[t, a] = n[a] / norm
            offset -= out[t, a] * V[0, a]
        out[t, k1] = offset
    return out


@njit(cache=True, nogil=True)
def vertex_neighbours(S, n):
    """(indptr, indices): the sorted neighbours of vertex v are
    indices[indptr[v]:indptr[v+1]] (scipy's ``vertex_neighbor_vertices``).
    Each vertex first gets every (simplex, other vertex) pair, then its
    short list is sorted and its repeats dropped in place."""
    m, k1 = S.shape
    start = np.zeros(n + 1, dtype=np.int64)
    for t in range(m):
        for j in range(k1):
            start[S[t, j] + 1] += k1 - 1
    for v in range(n):
        start[v + 1] += start[v]
    fill = start[:n].copy()
    pairs = np.empty(start[n], dtype=np.int32)
    for t in range(m):
        for j in range(k1):
            v = S[t, j]
            for i in range(k1):
                if i != j:
                    pairs[fill[v]] = S[t, i]
                    fill[v] += 1
    indptr = np.zeros(n + 1, dtype=np.int32)
    w = 0
    for v in range(n):
        seg = np.sort(pairs[start[v]:start[v + 1]])
        for k in range(seg.shape[0]):
            if k == 0 or seg[k] != seg[k - 1]:
                pairs[w] = seg[k]
                w += 1
        indptr[v + 1] = w
    return indptr, pairs[:w].copy()
