"""``Delaunay``: the scipy.spatial.Delaunay interface over lfqt's exact
triangulation, with exact point location."""
import numpy as np
from numba import njit

from ._input import MIN_ULP_EXP
from .dc import triangulate
from .predicates.counters import N_PREDICATE, orient2d
from .predicates.planar import CCW_A
from .triangulation import DegenerateInputError


@njit(cache=True)
def _locate(xs, ys, simplices, neighbors, qx, qy, start):
    """Visibility walk with exact orientation; -1 outside the hull."""
    cnt = np.zeros(N_PREDICATE, dtype=np.int64)
    m = simplices.shape[0]
    out = np.empty(qx.shape[0], dtype=np.int64)
    t = start
    for k in range(qx.shape[0]):
        if t < 0:
            t = start
        px = qx[k]
        py = qy[k]
        found = -1
        for _ in range(4 * m + 4):
            moved = False
            for j in range(3):
                i = (j + k) % 3  # rotate the first edge tried so the walk cannot cycle
                a = simplices[t, (i + 1) % 3]
                b = simplices[t, (i + 2) % 3]
                if orient2d(xs[a], ys[a], xs[b], ys[b], px, py, CCW_A, cnt) < 0.0:
                    nb = neighbors[t, i]
                    if nb < 0:
                        t = -1
                    else:
                        t = nb
                    moved = True
                    break
            if not moved:
                found = t
                break
            if t < 0:
                break
        out[k] = found
        if found >= 0:
            t = found
    return out


def _locate_rational(points, simplices, neighbors, q):
    """The visibility walk of ``_locate`` for one query, with orientation in
    exact rational arithmetic on the original coordinates: for the rare query
    that the rescaled frame cannot hold exactly.  The walk terminates on a
    Delaunay triangulation."""
    from fractions import Fraction
    qx, qy = Fraction(float(q[0])), Fraction(float(q[1]))
    t = 0
    for _ in range(4 * len(simplices) + 4):
        for i in range(3):
            a, b = simplices[t, (i + 1) % 3], simplices[t, (i + 2) % 3]
            ax, ay = Fraction(float(points[a, 0])), Fraction(float(points[a, 1]))
            bx, by = Fraction(float(points[b, 0])), Fraction(float(points[b, 1]))
            if (ax - qx) * (by - qy) - (ay - qy) * (bx - qx) < 0:
                t = neighbors[t, i]
                break
        else:
            return t
        if t < 0:
            return -1
    return -1


class Delaunay:
    """Drop-in for the common use of ``scipy.spatial.Delaunay`` in 2D.

    Raises :class:`DegenerateInputError` where scipy raises QhullError
    (fewer than 3 distinct points or all collinear).  ``coplanar`` lists the
    duplicate rows that are not vertices, as (row, simplex, vertex) like
    scipy's.
    """

    def __init__(self, points, **kwargs):
        self._tri = triangulate(points, **kwargs)
        if self._tri.degenerate:
            raise DegenerateInputError(f"cannot triangulate: {self._tri.reason}")
        self.points = np.asarray(points, dtype=np.float64)
        self.simplices = self._tri.simplices
        self.neighbors = self._tri.neighbors
        self.ndim = 2
        self.npoints = len(self.points)
        self.nsimplex = len(self.simplices)
        self.stats = self._tri.stats
        self._scale = 2.0 ** self.stats["scale_exponent"]
        self._xs = self.points[:, 0] * self._scale
        self._ys = self.points[:, 1] * self._scale
        self._lo = self.points.min(axis=0)
        self._hi = self.points.max(axis=0)
        self._simplices64 = self.simplices.astype(np.int64)
        self._neighbors64 = self.neighbors.astype(np.int64)
        self._vnv = None

    @property
    def triangulation(self):
        return self._tri

    @property
    def convex_hull(self):
        h = self._tri.hull
        return np.stack((h, np.roll(h, -1)), axis=1)

    @property
    def coplanar(self):
        dup = self._tri.duplicate_of
        rows = np.flatnonzero(dup != np.arange(len(dup)))
        if len(rows) == 0:
            return np.empty((0, 3), dtype=np.int32)
        owner = np.empty(self.npoints, dtype=np.int64)
        owner[self.simplices.ravel()] = np.repeat(np.arange(self.nsimplex), 3)
        return np.stack((rows, owner[dup[rows]], dup[rows]), axis=1).astype(np.int32)

    def find_simplex(self, xi, bruteforce=False, tol=None):
        """Index of a triangle containing each point of ``xi`` (..., 2), -1
        outside the hull or for NaN, as scipy's.  Exact: the answer always
        contains the query.  ``bruteforce`` and ``tol`` are accepted for
        scipy's signature; an exact answer needs neither."""
        q = np.asanyarray(xi, dtype=np.float64)
        if q.shape[-1] != 2:
            raise ValueError("wrong dimensionality in xi")
        shape = q.shape[:-1]
        q = q.reshape(-1, 2)
        found = np.full(len(q), -1, dtype=np.int64)
        # NaN and points outside the bounding box are outside: no predicate
        # (and none that could overflow)
        inside = ((q[:, 0] >= self._lo[0]) & (q[:, 0] <= self._hi[0])
                  & (q[:, 1] >= self._lo[1]) & (q[:, 1] <= self._hi[1]))
        qx = q[:, 0] * self._scale
        qy = q[:, 1] * self._scale
        # A query the rescale would round, or move below the exactness
        # window, is located exactly on the original coordinates instead.
        floor = 2.0 ** (MIN_ULP_EXP + 52)
        representable = np.ones(len(q), dtype=bool)
        for scaled, orig in ((qx, q[:, 0]), (qy, q[:, 1])):
            representable &= (scaled / self._scale == orig) & \
                ((scaled == 0.0) | (np.abs(scaled) >= floor))
        fast = inside & representable
        found[fast] = _locate(self._xs, self._ys, self._simplices64, self._neighbors64,
                              np.ascontiguousarray(qx[fast]), np.ascontiguousarray(qy[fast]), 0)
        for k in np.flatnonzero(inside & ~representable):
            found[k] = _locate_rational(self.points, self._simplices64, self._neighbors64,
                                        q[k])
        return found.astype(np.int32).reshape(shape)

    @property
    def vertex_neighbor_vertices(self):
        if self._vnv is None:
            s = self.simplices.astype(np.int64)
            a = np.concatenate((s[:, 0], s[:, 1], s[:, 2], s[:, 1], s[:, 2], s[:, 0]))
            b = np.concatenate((s[:, 1], s[:, 2], s[:, 0], s[:, 0], s[:, 1], s[:, 2]))
            key = np.unique(a * self.npoints + b)
            src, dst = key // self.npoints, key % self.npoints
            indptr = np.zeros(self.npoints + 1, dtype=np.int32)
            np.cumsum(np.bincount(src, minlength=self.npoints), out=indptr[1:])
            self._vnv = (indptr, dst.astype(np.int32))
        return self._vnv
