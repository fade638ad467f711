"""The jitted kernels behind ``lfqt.interpolate``: barycentric weighted sums
(linear), the Clough-Tocher element (cubic, 2D) and the global gradient
estimate it needs.

The queries arrive already located (``Delaunay.find_simplex``); each kernel
fills the rows ``lo:hi`` of its output, so that the wrapper can run ranges
on threads.  Values are real: a complex field is passed as its float64
view, one real and one imaginary column per complex column, which the
weighted sums and the element treat alike since their weights are real.
"""
import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def _solve_coordinates(P, S, s, X, i, c):
    """c[:d+1] = barycentric coordinates of query X[i] in simplex s by Cramer's rule
    on its vertices, the last resort for a simplex too flat for a
    ``transform`` whose neighbours are too (_coordinates); all the weight on
    the nearest vertex where the determinant rounds to zero."""
    d = P.shape[1]
    r = S[s, d]
    if d == 2:
        ax, ay = P[S[s, 0], 0] - P[r, 0], P[S[s, 0], 1] - P[r, 1]
        bx, by = P[S[s, 1], 0] - P[r, 0], P[S[s, 1], 1] - P[r, 1]
        qx, qy = X[i, 0] - P[r, 0], X[i, 1] - P[r, 1]
        det = ax * by - ay * bx
        if det == 0.0:
            _nearest_vertex(P, S, s, X, i, c)
            return
        c[0] = (qx * by - qy * bx) / det
        c[1] = (ax * qy - ay * qx) / det
        c[2] = 1.0 - c[0] - c[1]
        return
    M = np.empty((3, 3))
    q = np.empty(3)
    for a in range(3):
        q[a] = X[i, a] - P[r, a]
        for j in range(3):
            M[a, j] = P[S[s, j], a] - P[r, a]
    det = _det3(M[:, 0], M[:, 1], M[:, 2])
    if det == 0.0:
        _nearest_vertex(P, S, s, X, i, c)
        return
    c[0] = _det3(q, M[:, 1], M[:, 2]) / det
    c[1] = _det3(M[:, 0], q, M[:, 2]) / det
    c[2] = _det3(M[:, 0], M[:, 1], q) / det
    c[3] = 1.0 - c[0] - c[1] - c[2]


@njit(cache=True, inline="always")
def _det3(u, v, w):
    """The determinant of the 3x3 matrix with columns u, v, w."""
    return (u[0] * (v[1] * w[2] - v[2] * w[1]) - v[0] * (u[1] * w[2] - u[2] * w[1])
            + w[0] * (u[1] * v[2] - u[2] * v[1]))


@njit(cache=True, inline="always")
def _nearest_vertex(P, S, s, X, i, c):
    """c = 1 at the vertex of simplex s nearest to query X[i], 0 at the others."""
    best, at = np.inf, 0
    for j in range(S.shape[1]):
        dist = 0.0
        for a in range(P.shape[1]):
            dist += (P[S[s, j], a] - X[i, a]) ** 2
        if dist < best:
            best, at = dist, j
        c[j] = 0.0
    c[at] = 1.0


@njit(cache=True, inline="always")
def _transform_coordinates(T, s, X, i, c):
    """c[:d+1] = barycentric coordinates of query X[i] (row and index: a row view per
    query would cost a reference count) from scipy's ``transform`` of
    simplex s (the same arithmetic as scipy's interpolators, so that the
    two agree to rounding); returns the smallest."""
    d = T.shape[2]
    c[d] = 1.0
    for r in range(d):
        acc = 0.0
        for j in range(d):
            acc += T[s, r, j] * (X[i, j] - T[s, d, j])
        c[r] = acc
        c[d] -= acc
    low = c[d]
    for r in range(d):
        low = min(low, c[r])
    return low


@njit(cache=True, inline="always")
def _coordinates(P, S, N, T, s, X, i, c):
    """The simplex to interpolate on for query X[i], located in simplex s, with its
    barycentric coordinates in it (c).  s itself when its ``transform`` is
    finite.  A simplex too flat for one (NaN: beyond scipy's condition
    limit, which exact location may still return) passes x to the
    neighbour with a transform that holds x best, as scipy's location does
    (a flat simplex is thin, so x lies on that neighbour up to a sliver);
    without one, Cramer's rule on s's vertices."""
    if not np.isnan(T[s, 0, 0]):
        _transform_coordinates(T, s, X, i, c)
        return s
    best, best_low = -1, -np.inf
    for k in range(S.shape[1]):
        t = N[s, k]
        if t >= 0 and not np.isnan(T[t, 0, 0]):
            low = _transform_coordinates(T, t, X, i, c)
            if low > best_low:
                best, best_low = t, low
    if best < 0:
        _solve_coordinates(P, S, s, X, i, c)
        return s
    _transform_coordinates(T, best, X, i, c)
    return best


@njit(cache=True, inline="always")
def _fill(out, i, fill):
    """Row i of out is the fill value (a query outside the hull)."""
    for a in range(out.shape[1]):
        out[i, a] = fill[a]


@njit(cache=True, nogil=True)
def _linear(mesh, found, X, V, fill, out, lo, hi):
    """out[lo:hi] = the barycentric mix of V over the simplex found for each
    query row of X, or ``fill`` (one value per column) where found is -1.
    ``mesh`` = (points, simplices, neighbors, transform).  The common case,
    a simplex with a finite transform, is written out per dimension with
    scipy's order of operations (the same bits as _transform_coordinates):
    the general loops over a scratch array cost four times as much."""
    P, S, N, T = mesh
    d = P.shape[1]
    k = V.shape[1]
    c = np.empty(d + 1)
    for i in range(lo, hi):
        s = found[i]
        if s < 0:
            _fill(out, i, fill)
            continue
        if np.isnan(T[s, 0, 0]):
            s = _coordinates(P, S, N, T, s, X, i, c)
            c0, c1, c2, c3 = c[0], c[1], c[2], c[d]
        elif d == 2:
            x0, x1 = X[i, 0] - T[s, 2, 0], X[i, 1] - T[s, 2, 1]
            c0 = T[s, 0, 0] * x0 + T[s, 0, 1] * x1
            c1 = T[s, 1, 0] * x0 + T[s, 1, 1] * x1
            c2 = 1.0 - c0 - c1
            c3 = c2
        else:
            x0, x1, x2 = X[i, 0] - T[s, 3, 0], X[i, 1] - T[s, 3, 1], X[i, 2] - T[s, 3, 2]
            c0 = T[s, 0, 0] * x0 + T[s, 0, 1] * x1 + T[s, 0, 2] * x2
            c1 = T[s, 1, 0] * x0 + T[s, 1, 1] * x1 + T[s, 1, 2] * x2
            c2 = T[s, 2, 0] * x0 + T[s, 2, 1] * x1 + T[s, 2, 2] * x2
            c3 = 1.0 - c0 - c1 - c2
        if d == 2:
            v0, v1, v2 = S[s, 0], S[s, 1], S[s, 2]
            for a in range(k):
                out[i, a] = c0 * V[v0, a] + c1 * V[v1, a] + c3 * V[v2, a]
        else:
            v0, v1, v2, v3 = S[s, 0], S[s, 1], S[s, 2], S[s, 3]
            for a in range(k):
                out[i, a] = c0 * V[v0, a] + c1 * V[v1, a] + c2 * V[v2, a] + c3 * V[v3, a]


@njit(cache=True, inline="always")
def _twist(P, S, N, T, s, g, cc, y):
    """g[k]: the direction across the edge opposite vertex k along which the
    element's derivative is linear, as the barycentric form of the step
    from this triangle's centroid to the neighbour's (affine invariant, and
    the same from both sides, hence C1); -1/2 (the centroid direction) on
    the hull.  cc and y (one row) are scratch."""
    flat = np.isnan(T[s, 0, 0])  # Cramer's last resort (_coordinates): no transform to use
    for k in range(3):
        t = N[s, k]
        if t < 0 or flat:
            g[k] = -0.5
            continue
        for a in range(2):
            y[0, a] = (P[S[t, 0], a] + P[S[t, 1], a] + P[S[t, 2], a]) / 3.0
        _transform_coordinates(T, s, y, 0, cc)
        p, q = cc[(k + 2) % 3], cc[(k + 1) % 3]
        g[k] = (2.0 * p + q - 1.0) / (2.0 - 3.0 * p - 3.0 * q)


@njit(cache=True, inline="always")
def _element(E, f, D, g, b):
    """The Clough-Tocher cubic at barycentric b on a triangle with edges
    E (rows p1-p0, p2-p1, p0-p2), values f and gradients D (rows) at its
    vertices: Bezier ordinates of the three sub-triangles around the
    centroid (Farin 1986; Alfeld 1984), then de Casteljau's sum on the
    sub-triangle that holds b (the smallest coordinate splits off)."""
    d01 = D[0, 0] * E[0, 0] + D[0, 1] * E[0, 1]
    d10 = -(D[1, 0] * E[0, 0] + D[1, 1] * E[0, 1])
    d12 = D[1, 0] * E[1, 0] + D[1, 1] * E[1, 1]
    d21 = -(D[2, 0] * E[1, 0] + D[2, 1] * E[1, 1])
    d20 = D[2, 0] * E[2, 0] + D[2, 1] * E[2, 1]
    d02 = -(D[0, 0] * E[2, 0] + D[0, 1] * E[2, 1])
    # ordinates named by their multi-index over (v0, v1, v2, centroid)
    c3000, c0300, c0030 = f[0], f[1], f[2]
    c2100 = (d01 + 3.0 * c3000) / 3.0
    c2010 = (d02 + 3.0 * c3000) / 3.0
    c1200 = (d10 + 3.0 * c0300) / 3.0
    c0210 = (d12 + 3.0 * c0300) / 3.0
    c1020 = (d20 + 3.0 * c0030) / 3.0
    c0120 = (d21 + 3.0 * c0030) / 3.0
    c2001 = (c2100 + c2010 + c3000) / 3.0
    c0201 = (c1200 + c0300 + c0210) / 3.0
    c0021 = (c1020 + c0120 + c0030) / 3.0
    c0111 = (g[0] * (-c0300 + 3.0 * c0210 - 3.0 * c0120 + c0030)
             + (-c0300 + 2.0 * c0210 - c0120 + c0021 + c0201)) / 2.0
    c1011 = (g[1] * (-c0030 + 3.0 * c1020 - 3.0 * c2010 + c3000)
             + (-c0030 + 2.0 * c1020 - c2010 + c2001 + c0021)) / 2.0
    c1101 = (g[2] * (-c3000 + 3.0 * c2100 - 3.0 * c1200 + c0300)
             + (-c3000 + 2.0 * c2100 - c1200 + c2001 + c0201)) / 2.0
    c1002 = (c1101 + c1011 + c2001) / 3.0
    c0102 = (c1101 + c0111 + c0201) / 3.0
    c0012 = (c1011 + c0111 + c0021) / 3.0
    c0003 = (c1002 + c0102 + c0012) / 3.0
    low = min(b[0], b[1], b[2])
    b1, b2, b3, b4 = b[0] - low, b[1] - low, b[2] - low, 3.0 * low
    return (b1 ** 3 * c3000 + 3.0 * b1 ** 2 * b2 * c2100 + 3.0 * b1 ** 2 * b3 * c2010
            + 3.0 * b1 ** 2 * b4 * c2001 + 3.0 * b1 * b2 ** 2 * c1200
            + 6.0 * b1 * b2 * b4 * c1101 + 3.0 * b1 * b3 ** 2 * c1020
            + 6.0 * b1 * b3 * b4 * c1011 + 3.0 * b1 * b4 ** 2 * c1002 + b2 ** 3 * c0300
            + 3.0 * b2 ** 2 * b3 * c0210 + 3.0 * b2 ** 2 * b4 * c0201
            + 3.0 * b2 * b3 ** 2 * c0120 + 6.0 * b2 * b3 * b4 * c0111
            + 3.0 * b2 * b4 ** 2 * c0102 + b3 ** 3 * c0030 + 3.0 * b3 ** 2 * b4 * c0021
            + 3.0 * b3 * b4 ** 2 * c0012 + b4 ** 3 * c0003)


@njit(cache=True, nogil=True)
def _clough_tocher(mesh, found, X, V, G, fill, out, lo, hi):
    """out[lo:hi] = the Clough-Tocher interpolant of values V (n, k) with
    vertex gradients G (n, k, 2) at the query rows of X, or ``fill`` where
    found is -1.  ``mesh`` = (points, simplices, neighbors, transform)."""
    P, S, N, T = mesh
    k = V.shape[1]
    b, cc, g, y = np.empty(3), np.empty(3), np.empty(3), np.empty((1, 2))
    E, D, f = np.empty((3, 2)), np.empty((3, 2)), np.empty(3)
    for i in range(lo, hi):
        s = found[i]
        if s < 0:
            _fill(out, i, fill)
            continue
        s = _coordinates(P, S, N, T, s, X, i, b)
        _twist(P, S, N, T, s, g, cc, y)
        for j in range(3):
            u, v = S[s, j], S[s, (j + 1) % 3]
            E[j, 0] = P[v, 0] - P[u, 0]
            E[j, 1] = P[v, 1] - P[u, 1]
        for a in range(k):
            for j in range(3):
                v = S[s, j]
                f[j] = V[v, a]
                D[j, 0] = G[v, a, 0]
                D[j, 1] = G[v, a, 1]
            out[i, a] = _element(E, f, D, g, b)


@njit(cache=True, nogil=True)
def _edge_geometry(P, indptr, indices):
    """(L3, Q): the cubed length of each vertex-neighbour edge (CSR order),
    and per vertex the symmetric 2x2 matrix sum 4 E E^T / L^3 (xx, xy, yy)
    of the minimum-curvature system, both fixed over the iterations."""
    n = len(indptr) - 1
    L3 = np.empty(len(indices))
    Q = np.zeros((n, 3))
    for v in range(n):
        for z in range(indptr[v], indptr[v + 1]):
            u = indices[z]
            ex, ey = P[u, 0] - P[v, 0], P[u, 1] - P[v, 1]
            L = np.sqrt(ex * ex + ey * ey)
            L3[z] = L * L * L
            Q[v, 0] += 4.0 * ex * ex / L3[z]
            Q[v, 1] += 4.0 * ex * ey / L3[z]
            Q[v, 2] += 4.0 * ey * ey / L3[z]
    return L3, Q


@njit(cache=True, nogil=True)
def _gradients(P, indptr, indices, L3, Q, f, maxiter, tol, grad):
    """Vertex gradients grad (n, 2) of the data f that approximately
    minimise the Clough-Tocher interpolant's curvature along the edges
    (Nielson 1983; Renka and Cline 1984): Gauss-Seidel sweeps in vertex
    order, each vertex solving its 2x2 system with its neighbours' current
    gradients, until the largest change (relative where the gradient
    exceeds 1) drops below tol.  Returns the sweeps taken, 0 if maxiter
    was reached first.  A vertex without neighbours (a duplicate row)
    keeps gradient 0."""
    n = len(indptr) - 1
    grad[:] = 0.0
    for sweep in range(maxiter):
        err = 0.0
        for v in range(n):
            det = Q[v, 0] * Q[v, 2] - Q[v, 1] * Q[v, 1]
            if indptr[v] == indptr[v + 1] or det == 0.0:
                continue
            s0, s1 = 0.0, 0.0
            for z in range(indptr[v], indptr[v + 1]):
                u = indices[z]
                ex, ey = P[u, 0] - P[v, 0], P[u, 1] - P[v, 1]
                along = -ex * grad[u, 0] - ey * grad[u, 1]  # the neighbour's slope toward v
                rhs = 6.0 * (f[v] - f[u]) - 2.0 * along
                s0 += rhs * ex / L3[z]
                s1 += rhs * ey / L3[z]
            r0 = (Q[v, 2] * s0 - Q[v, 1] * s1) / det
            r1 = (-Q[v, 1] * s0 + Q[v, 0] * s1) / det
            change = max(abs(grad[v, 0] + r0), abs(grad[v, 1] + r1))
            grad[v, 0] = -r0
            grad[v, 1] = -r1
            change /= max(1.0, max(abs(r0), abs(r1)))
            err = max(err, change)
        if err < tol:
            return sweep + 1
    return 0


@njit(cache=True, nogil=True)
def _near_hull(N, T, inward, X, eps, found):
    """found[i] = a simplex in which query X[i], just outside the hull,
    has every barycentric coordinate >= -eps, or -1: the simplex that
    ``inward[i]`` located for it after a nudge into the hull, else one of
    that simplex's neighbours (scipy's location accepts such queries)."""
    k1 = N.shape[1]
    c = np.empty(k1)
    for i in range(len(X)):
        found[i] = -1
        s = inward[i]
        if s < 0:
            continue
        for j in range(-1, k1):
            t = s if j < 0 else N[s, j]
            if t < 0 or np.isnan(T[t, 0, 0]):
                continue
            if _transform_coordinates(T, t, X, i, c) >= -eps:
                found[i] = t
                break
