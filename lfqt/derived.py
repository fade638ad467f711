"""Kernels for the derived attributes of ``lfqt.Delaunay``, in scipy's
definitions and floating point: barycentric transforms, the lifted
hyperplanes (``equations``), and the vertex adjacency in CSR form.

Each is one pass over the simplices, computed on first access (scipy builds
``equations`` with the mesh; we build it only when asked), reading the mesh
stored along space (lfqt.location.walk_frame), whose corners lie close in
memory.
"""
import numpy as np
from numba import njit

COND_LIMIT = 1.0 / (1000.0 * np.finfo(np.float64).eps)  # scipy's: 3 significant digits left


@njit(cache=True, nogil=True)
def extents(P):
    """(lowest, highest coordinate per axis, [lowest |x|^2, highest |x|^2,
    largest |coordinate|]) of the rows of P in one pass: the bounding box
    and what Qhull's paraboloid scaling reads (numpy's reductions over the
    short axis took about 20 times as long at 1M points)."""
    n, d = P.shape
    lo, hi = P[0].copy(), P[0].copy()
    lifted = np.array([np.inf, -np.inf, 0.0])
    for k in range(n):
        s = 0.0
        for a in range(d):
            x = P[k, a]
            lo[a] = min(lo[a], x)
            hi[a] = max(hi[a], x)
            lifted[2] = max(lifted[2], abs(x))
            s += x * x
        lifted[0] = min(lifted[0], s)
        lifted[1] = max(lifted[1], s)
    return lo, hi, lifted


@njit(cache=True, nogil=True)
def lift(X, scale, shift, out):
    """out = (X, |X|^2 * scale + shift) row by row, in one pass and in
    scipy's order of operations (the squares summed from the first
    coordinate, then scaled, then shifted), so that the values are
    scipy's to the bit; numpy's sum over a short last axis is a strided
    reduction, and the expression made three temporaries."""
    n, d = X.shape
    for k in range(n):
        s = 0.0
        for a in range(d):
            x = X[k, a]
            out[k, a] = x
            s += x * x
        out[k, d] = s * scale + shift


@njit(cache=True, inline="always")
def _inverse(T, d, out, t):
    """out[t, :d, :] = T^-1 (d = 2 or 3) by the adjugate; False when T is
    singular or its 1-norm condition number exceeds COND_LIMIT."""
    if d == 2:
        det = T[0, 0] * T[1, 1] - T[0, 1] * T[1, 0]
        if det == 0.0:
            return False
        r = 1.0 / det
        out[t, 0, 0] = T[1, 1] * r
        out[t, 0, 1] = -T[0, 1] * r
        out[t, 1, 0] = -T[1, 0] * r
        out[t, 1, 1] = T[0, 0] * r
    else:
        c00 = T[1, 1] * T[2, 2] - T[1, 2] * T[2, 1]
        c01 = T[1, 2] * T[2, 0] - T[1, 0] * T[2, 2]
        c02 = T[1, 0] * T[2, 1] - T[1, 1] * T[2, 0]
        det = T[0, 0] * c00 + T[0, 1] * c01 + T[0, 2] * c02
        if det == 0.0:
            return False
        r = 1.0 / det
        out[t, 0, 0] = c00 * r
        out[t, 1, 0] = c01 * r
        out[t, 2, 0] = c02 * r
        out[t, 0, 1] = (T[0, 2] * T[2, 1] - T[0, 1] * T[2, 2]) * r
        out[t, 1, 1] = (T[0, 0] * T[2, 2] - T[0, 2] * T[2, 0]) * r
        out[t, 2, 1] = (T[0, 1] * T[2, 0] - T[0, 0] * T[2, 1]) * r
        out[t, 0, 2] = (T[0, 1] * T[1, 2] - T[0, 2] * T[1, 1]) * r
        out[t, 1, 2] = (T[0, 2] * T[1, 0] - T[0, 0] * T[1, 2]) * r
        out[t, 2, 2] = (T[0, 0] * T[1, 1] - T[0, 1] * T[1, 0]) * r
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
def transforms(P, S, unscale, out, lo, hi):
    """out[lo:hi] of (m, d+1, d): rows :d hold T^-1 and row d holds r, for
    T c = x - r with T's columns x_j - r and r the simplex's last vertex
    (scipy's ``transform``); NaN in T^-1 where T is too ill-conditioned.
    The points are P * unscale (a power of two: exact), so that P may be
    the location's frame."""
    d = S.shape[1] - 1
    T = np.empty((d, d))
    for t in range(lo, hi):
        r = S[t, d]
        for a in range(d):
            out[t, d, a] = P[r, a] * unscale
        for j in range(d):
            v = S[t, j]
            for a in range(d):
                T[a, j] = P[v, a] * unscale - P[r, a] * unscale
        if not _inverse(T, d, out, t):
            for i in range(d):
                for a in range(d):
                    out[t, i, a] = np.nan


@njit(cache=True, inline="always")
def _lift(P, v, unscale, scale, shift):
    x, y = P[v, 0] * unscale, P[v, 1] * unscale
    if P.shape[1] == 2:
        return x, y, 0.0, (x * x + y * y) * scale + shift
    z = P[v, 2] * unscale
    return x, y, z, (x * x + y * y + z * z) * scale + shift


@njit(cache=True, nogil=True)
def hyperplanes(P, S, unscale, scale, shift, out, lo, hi):
    """out[lo:hi] of (m, d+2): unit normal and offset of each simplex's
    plane through its lifted vertices (x, |x|^2 * scale + shift), the normal
    pointing down (last component < 0), as Qhull's ``equations``; the
    points are P * unscale, as in ``transforms``."""
    d = S.shape[1] - 1
    for t in range(lo, hi):
        ax, ay, az, aw = _lift(P, S[t, 0], unscale, scale, shift)
        bx, by, bz, bw = _lift(P, S[t, 1], unscale, scale, shift)
        cx, cy, cz, cw = _lift(P, S[t, 2], unscale, scale, shift)
        ux, uy, uz, uw = bx - ax, by - ay, bz - az, bw - aw
        vx, vy, vz, vw = cx - ax, cy - ay, cz - az, cw - aw
        if d == 2:  # the cross product of the two edges in (x, y, lift)
            n0 = uy * vw - uw * vy
            n1 = uw * vx - ux * vw
            n2 = ux * vy - uy * vx
            n3 = 0.0
            norm = np.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
            last = n2
        else:  # the generalised cross product of three edges in 4D: signed 3x3 minors
            dx, dy, dz, dw = _lift(P, S[t, 3], unscale, scale, shift)
            wx, wy, wz, ww = dx - ax, dy - ay, dz - az, dw - aw
            n0 = uy * (vz * ww - vw * wz) - uz * (vy * ww - vw * wy) + uw * (vy * wz - vz * wy)
            n1 = -(ux * (vz * ww - vw * wz) - uz * (vx * ww - vw * wx) + uw * (vx * wz - vz * wx))
            n2 = ux * (vy * ww - vw * wy) - uy * (vx * ww - vw * wx) + uw * (vx * wy - vy * wx)
            n3 = -(ux * (vy * wz - vz * wy) - uy * (vx * wz - vz * wx) + uz * (vx * wy - vy * wx))
            norm = np.sqrt(n0 * n0 + n1 * n1 + n2 * n2 + n3 * n3)
            last = n3
        r = -np.copysign(1.0 / norm, last)  # unit length, last component down
        n0, n1, n2, n3 = n0 * r, n1 * r, n2 * r, n3 * r
        out[t, 0] = n0
        out[t, 1] = n1
        out[t, 2] = n2
        if d == 2:
            out[t, 3] = -(n0 * ax + n1 * ay + n2 * aw)
        else:
            out[t, 3] = n3
            out[t, 4] = -(n0 * ax + n1 * ay + n2 * az + n3 * aw)


@njit(cache=True, nogil=True)
def plane_distances(E, Z, out, lo, hi):
    """out[:, lo:hi] = Z @ E[lo:hi, :-1].T + E[lo:hi, -1]: the signed
    distance of each lifted point (row of Z) to the hyperplanes of simplices
    lo:hi, written in place by blocks of simplices (numpy's expression makes
    a strided copy of E and a second output-sized array)."""
    k = E.shape[1] - 1
    for b in range(lo, hi, 1024):
        for r in range(Z.shape[0]):
            for t in range(b, min(b + 1024, hi)):
                acc = 0.0
                for a in range(k):
                    acc += Z[r, a] * E[t, a]
                out[r, t] = acc + E[t, k]


@njit(cache=True, nogil=True)
def vertex_neighbours(S, n):
    """(indptr, indices): the sorted neighbours of vertex v are
    indices[indptr[v]:indptr[v+1]] (scipy's ``vertex_neighbor_vertices``).
    From the simplices around each vertex (a counting sort of the
    simplices' vertices), each neighbour once by a stamp per vertex,
    insertion-sorted into its short list as it comes."""
    m, k1 = S.shape
    first = np.zeros(n + 1, dtype=np.int64)
    for t in range(m):
        for j in range(k1):
            first[S[t, j] + 1] += 1
    for v in range(n):
        first[v + 1] += first[v]
    fill = first[:n].copy()
    around = np.empty(first[n], dtype=np.int32)
    for t in range(m):
        for j in range(k1):
            v = S[t, j]
            around[fill[v]] = t
            fill[v] += 1
    stamp = np.full(n, -1, dtype=np.int32)
    indptr = np.zeros(n + 1, dtype=np.int32)
    indices = np.empty(first[n] * (k1 - 1), dtype=np.int32)  # room for every repeat
    w = 0
    for v in range(n):  # each new neighbour once, insertion-sorted among the few
        lo = w
        for z in range(first[v], first[v + 1]):
            t = around[z]
            for j in range(k1):
                x = S[t, j]
                if x != v and stamp[x] != v:
                    stamp[x] = v
                    k = w
                    while k > lo and indices[k - 1] > x:
                        indices[k] = indices[k - 1]
                        k -= 1
                    indices[k] = x
                    w += 1
        indptr[v + 1] = w
    return indptr, indices[:w].copy()
