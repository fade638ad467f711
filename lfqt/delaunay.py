"""``Delaunay``: the interface of scipy.spatial.Delaunay in 2D and 3D over
lfqt's exact triangulations (the LFQT divide and conquer in 2D, incremental
insertion in 3D), with exact point location (lfqt.location)."""
import warnings

import numpy as np

from ._input import MIN_ULP_EXP, MIN_ULP_EXP_3D
from .dc import triangulate
from .incremental import insert
from .location import locate_brute, locate_rational, locate_walk
from .triangulation import DegenerateInputError

_ERRORS = {}


def _degenerate_error(message):
    """A DegenerateInputError that is also scipy's QhullError (where scipy
    is installed), so that code written for scipy catches it as it would
    catch Qhull's.  scipy is imported only on this rare path."""
    if "class" not in _ERRORS:
        try:
            from scipy.spatial import QhullError
        except ImportError:  # scipy absent: lfqt's own error alone
            _ERRORS["class"] = DegenerateInputError
        else:
            _ERRORS["class"] = type("DelaunayDegenerateError", (DegenerateInputError, QhullError),
                                    {"__module__": __name__,
                                     "__doc__": DegenerateInputError.__doc__})
    return _ERRORS["class"](message)


def _points_array(points, ndim=None):
    """scipy's checks on the input array, then ours: 2 or 3 columns."""
    if np.ma.isMaskedArray(points):
        raise ValueError("Input points cannot be a masked array")
    arr = np.asarray(points)
    if arr.ndim != 2:
        raise ValueError("Input points array must have 2 dimensions.")
    if ndim is not None and arr.shape[1] != ndim:
        raise ValueError(f"invalid size for new points array: {arr.shape[1]} columns, the "
                         f"triangulation has {ndim} dimensions")
    if arr.shape[1] not in (2, 3):
        raise ValueError(f"lfqt.Delaunay triangulates in 2 or 3 dimensions; the points have "
                         f"{arr.shape[1]} dimensions")
    return arr


class Delaunay:
    """Drop-in for ``scipy.spatial.Delaunay`` in 2D and 3D, exact.

    Every simplex is Delaunay by exact predicates, and ``find_simplex``
    returns a simplex that contains the query exactly.  Attributes and
    methods follow scipy's shapes, dtypes and conventions.

    Parameters
    ----------
    points : array_like, shape (npoints, 2 or 3)
    furthest_site : bool
        Only False: the furthest-site triangulation (Qhull's "Qu") is not
        built, and True raises NotImplementedError.
    incremental : bool
        Allow ``add_points``, which triangulates the union of the old and
        new points again, exactly, with the same method as a fresh object
        (the divide and conquer in 2D, insertion in 3D).  An incremental
        object therefore equals ``Delaunay(all points)`` even where the
        triangulation is not unique (cocircular points), which scipy's own
        tests require and two different methods' tie-breaking would not
        give.
    qhull_options : str, optional
        Accepted and ignored, with a warning: an exact triangulation has no
        use for Qhull's joggling, scaling or precision options.
    **options
        Passed to ``lfqt.triangulate`` (2D) or ``lfqt.insert``.

    Raises
    ------
    DegenerateInputError
        Also a ``scipy.spatial.QhullError``: fewer than d+1 affinely
        independent points, where scipy raises QhullError.
    ValueError
        Masked, NaN or inf input, or not (n, 2) or (n, 3).

    Notes
    -----
    ``coplanar`` lists the duplicate rows that are not vertices, as (row,
    simplex containing its twin, the twin), and ``vertex_to_simplex`` maps
    such a row to that simplex.  ``paraboloid_scale`` and
    ``paraboloid_shift`` scale the lifted coordinate to the range of the
    others, as Qhull's "Qbb" does (1 and 0 in incremental mode, as scipy's).
    """

    def __init__(self, points, furthest_site=False, incremental=False, qhull_options=None,
                 **options):
        arr = _points_array(points)
        if furthest_site:
            raise NotImplementedError("furthest_site=True (Qhull's 'Qu'): lfqt builds the "
                                      "nearest-site Delaunay triangulation only")
        if qhull_options is not None:
            warnings.warn(f"lfqt.Delaunay ignores qhull_options={qhull_options!r}: the "
                          "triangulation is exact, Qhull's options do not apply",
                          UserWarning, stacklevel=2)
        self.furthest_site = False
        self._incremental = bool(incremental)
        self._open = self._incremental
        self._options = options
        self._build(arr)

    def _build(self, arr):
        d = arr.shape[1]
        if d == 2:
            tri = triangulate(arr, **self._options)
        else:
            tri = insert(arr, **self._options)
        if tri.degenerate:
            raise _degenerate_error(f"cannot triangulate: {tri.reason}")
        self._tri = tri
        self.points = np.ascontiguousarray(arr, dtype=np.float64)
        self.ndim = d
        self.npoints = len(self.points)
        self.simplices = np.ascontiguousarray(tri.simplices, dtype=np.intc)
        self.neighbors = np.ascontiguousarray(tri.neighbors, dtype=np.intc)
        self.nsimplex = len(self.simplices)
        self.good = np.ones(self.nsimplex, dtype=np.intc)
        self.min_bound = self.points.min(axis=0)
        self.max_bound = self.points.max(axis=0)
        self.paraboloid_scale, self.paraboloid_shift = self._paraboloid()
        self._scale = 2.0 ** tri.stats["scale_exponent"]
        self._floor = 2.0 ** ((MIN_ULP_EXP if d == 2 else MIN_ULP_EXP_3D) + 52)
        self._cache = {}

    def _paraboloid(self):
        if self._incremental:
            return 1.0, 0.0
        lifted = (self.points ** 2).sum(axis=1)
        lo, hi = lifted.min(), lifted.max()
        if not hi > lo:
            return 1.0, 0.0
        scale = float(np.abs(self.points).max() / (hi - lo))
        return scale, float(-lo * scale)

    def _location(self):
        """(rescaled points, simplices, neighbors) in the location kernels'
        frame and dtype, built on the first find_simplex, not with the mesh."""
        return self._cached("location", lambda: (self.points * self._scale,
                                                 self.simplices.astype(np.int64),
                                                 self.neighbors.astype(np.int64)))

    def _cached(self, name, build):
        if name not in self._cache:
            self._cache[name] = build()
        return self._cache[name]

    # -- the triangulation -------------------------------------------------

    @property
    def triangulation(self):
        """lfqt's Triangulation behind this object (with its stats)."""
        return self._tri

    @property
    def stats(self):
        return self._tri.stats

    @property
    def convex_hull(self):
        """(nfacets, ndim) int: the hull's edges (2D) or triangles (3D)."""
        def build():
            h = np.asarray(self._tri.hull)
            if self.ndim == 2:
                return np.stack((h, np.roll(h, -1)), axis=1).astype(np.intc)
            return np.ascontiguousarray(h, dtype=np.intc)
        return self._cached("hull", build)

    @property
    def coplanar(self):
        """(ncoplanar, 3) int: duplicate rows that are not vertices, the
        simplex containing their twin, and the twin."""
        def build():
            dup = self._tri.duplicate_of
            rows = np.flatnonzero(dup != np.arange(len(dup)))
            if len(rows) == 0:
                return np.empty((0, 3), dtype=np.intc)
            owner = self._owner()
            return np.stack((rows, owner[dup[rows]], dup[rows]), axis=1).astype(np.intc)
        return self._cached("coplanar", build)

    def _owner(self):
        """A simplex of each vertex, -1 for rows that are not vertices."""
        owner = np.full(self.npoints, -1, dtype=np.int64)
        ids = np.repeat(np.arange(self.nsimplex), self.ndim + 1)
        owner[self.simplices.ravel()[::-1]] = ids[::-1]  # the first simplex of each vertex
        return owner

    @property
    def vertex_to_simplex(self):
        """(npoints,) int: a simplex of each vertex; a coplanar row maps to
        the simplex of its twin."""
        def build():
            owner = self._owner()
            c = self.coplanar
            owner[c[:, 0]] = c[:, 1]
            return owner.astype(np.intc)
        return self._cached("v2s", build)

    @property
    def vertex_neighbor_vertices(self):
        """(indptr, indices): the neighbours of vertex k are
        ``indices[indptr[k]:indptr[k+1]]``."""
        def build():
            s = self.simplices.astype(np.int64)
            k = s.shape[1]
            a = np.concatenate([s[:, i] for i in range(k) for j in range(k) if i != j])
            b = np.concatenate([s[:, j] for i in range(k) for j in range(k) if i != j])
            key = np.unique(a * self.npoints + b)
            src, dst = key // self.npoints, key % self.npoints
            indptr = np.zeros(self.npoints + 1, dtype=np.intc)
            np.cumsum(np.bincount(src, minlength=self.npoints), out=indptr[1:])
            return indptr, dst.astype(np.intc)
        return self._cached("vnv", build)

    # -- geometry in floating point, as scipy's --------------------------

    @property
    def transform(self):
        """(nsimplex, ndim+1, ndim): ``T^-1`` and ``r`` of ``T c = x - r``
        per simplex (barycentric coordinates); NaN for a simplex too flat
        to invert in floating point (1-norm condition number above
        1/(1000 eps), scipy's limit)."""
        def build():
            d = self.ndim
            X = self.points[self.simplices]
            r = X[:, -1, :]
            T = np.transpose(X[:, :-1, :] - r[:, None, :], (0, 2, 1))
            out = np.full((self.nsimplex, d + 1, d), np.nan)
            out[:, d, :] = r
            if self.nsimplex:
                with np.errstate(all="ignore"):
                    # scipy's limit: at least three significant digits
                    ok = np.linalg.cond(T, 1) < 1.0 / (1000 * np.finfo(float).eps)
                    out[ok, :d, :] = np.linalg.inv(T[ok])
            return out
        return self._cached("transform", build)

    @property
    def equations(self):
        """(nsimplex, ndim+2): unit normal and offset of each simplex's
        hyperplane in the lifted space, normal pointing down (out of the
        lower hull), as Qhull's."""
        def build():
            V = self.lift_points(self.points)[self.simplices]
            E = V[:, 1:, :] - V[:, :1, :]
            k = self.ndim + 1
            normal = np.stack([(-1) ** j * np.linalg.det(np.delete(E, j, axis=2))
                               for j in range(k)], axis=1)
            normal /= np.linalg.norm(normal, axis=1, keepdims=True)
            normal *= -np.sign(normal[:, -1:])
            offset = -(normal * V[:, 0, :]).sum(axis=1)
            return np.concatenate((normal, offset[:, None]), axis=1)
        return self._cached("equations", build)

    def lift_points(self, x):
        """Lift points onto the paraboloid: (..., ndim) -> (..., ndim+1)."""
        x = np.asarray(x, dtype=np.float64)
        z = np.zeros(x.shape[:-1] + (x.shape[-1] + 1,))
        z[..., :-1] = x
        z[..., -1] = (x ** 2).sum(axis=-1) * self.paraboloid_scale + self.paraboloid_shift
        return z

    def plane_distance(self, xi):
        """Distance of each lifted point to every simplex's hyperplane:
        (..., ndim) -> (..., nsimplex)."""
        xi = np.asarray(xi, dtype=np.float64)
        if xi.shape[-1] != self.ndim:
            raise ValueError("xi has different dimensionality than triangulation")
        eq = self.equations
        z = self.lift_points(xi.reshape(-1, self.ndim))
        return (z @ eq[:, :-1].T + eq[:, -1]).reshape(xi.shape[:-1] + (self.nsimplex,))

    # -- point location ---------------------------------------------------

    def find_simplex(self, xi, bruteforce=False, tol=None):
        """Index of a simplex containing each point of ``xi`` (..., ndim),
        -1 outside the hull or for NaN, as scipy's.  Exact: the answer
        always contains the query.  ``bruteforce`` tests every simplex
        instead of walking (same answers).  ``tol`` > 0 widens the answer
        only: a query outside every simplex gets one whose barycentric
        coordinates are all >= -tol, as scipy's tolerance does."""
        xi = np.asanyarray(xi)
        if xi.shape[-1] != self.ndim:
            raise ValueError("wrong dimensionality in xi")
        shape = xi.shape[:-1]
        q = np.ascontiguousarray(xi.reshape(-1, self.ndim), dtype=np.float64)
        found = np.full(len(q), -1, dtype=np.int64)
        # NaN and points outside the bounding box are outside: no predicate
        inside = ((q >= self.min_bound) & (q <= self.max_bound)).all(axis=1)
        scaled = q * self._scale
        # A query the rescale would round, or move below the exactness
        # window, is located exactly on the original coordinates instead.
        with np.errstate(all="ignore"):
            representable = ((scaled / self._scale == q)
                             & ((scaled == 0.0) | (np.abs(scaled) >= self._floor))).all(axis=1)
        fast = np.flatnonzero(inside & representable)
        Q = np.ascontiguousarray(scaled[fast])
        P, S, N = self._location()
        found[fast] = locate_brute(P, S, Q) if bruteforce else locate_walk(P, S, N, Q, 0)
        for k in np.flatnonzero(inside & ~representable):
            found[k] = locate_rational(self.points, S, N, q[k])
        if tol is not None and tol > 0:
            for k in np.flatnonzero((found < 0) & np.isfinite(q).all(axis=1)):
                found[k] = self._within_tolerance(q[k], tol)
        return found.astype(np.intc).reshape(shape)

    def _within_tolerance(self, x, tol):
        """The first simplex whose barycentric coordinates of x are all
        >= -tol, or -1."""
        tr = self.transform
        c = np.einsum("ijk,ik->ij", tr[:, :-1, :], x - tr[:, -1, :])
        c = np.concatenate((c, 1 - c.sum(axis=1, keepdims=True)), axis=1)
        with np.errstate(invalid="ignore"):
            hit = np.flatnonzero((c >= -tol).all(axis=1))
        return int(hit[0]) if len(hit) else -1

    # -- incremental mode -------------------------------------------------

    def add_points(self, points, restart=False):
        """Add points (incremental mode only): the union of the old and new
        points is triangulated again, exactly; ``restart`` gives the same
        result and is accepted for scipy's signature."""
        if not self._open:
            raise RuntimeError("incremental mode not enabled or already closed")
        new = _points_array(points, self.ndim)
        self._build(np.concatenate((self.points, np.asarray(new, dtype=np.float64)), axis=0))

    def close(self):
        """Finish incremental processing: no more ``add_points``."""
        self._open = False

    def __repr__(self):
        return (f"<lfqt.Delaunay {self.ndim}D: {self.npoints} points, {self.nsimplex} "
                f"simplices>")
