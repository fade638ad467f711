"""``Delaunay``: the interface of scipy.spatial.Delaunay in 2D and 3D over
lfqt's exact triangulations (the LFQT divide and conquer in 2D, incremental
insertion in 3D), with exact point location (lfqt.location)."""
from __future__ import annotations

import os
import warnings
from typing import Any

import numpy as np
import numpy.typing as npt

from ._input import MIN_ULP_EXP, MIN_ULP_EXP_3D
from .dc import triangulate
from .derived import extents, hyperplanes, lift, plane_distances, transforms, vertex_neighbours
from .incremental import insert
from .location import (TINY_SHIFT, coherent, curve_like, grid_order, in_frame, jump_sample,
                       locate_brute, locate_rational, locate_tiny, locate_tolerant, locate_walk,
                       simplex_boxes, split_queries, tiny_frame_ok, walk_frame, walk_static)
from .triangulation import DegenerateInputError, Triangulation
from . import workspace
from .workers import Workers

_ERRORS = {}
# A walk mesh this large (bytes) or less stays in the caches: queries in a row-major order
# are walked as given (2D 100k points, a 1M grid: 0.10 s as given, 0.17 s sorted first);
# above it only a curve's order is (location.curve_like, over CURVE_WINDOW rows).
MESH_IN_CACHE = 8 << 20
CURVE_WINDOW = 64


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
        Passed to ``lfqt.triangulate`` (2D) or ``lfqt.insert`` (3D).
        ``threads`` (default 1) builds the triangulation on that many
        threads, and runs ``find_simplex`` and the derived attributes'
        kernels on them, in 2D and 3D.

    Raises
    ------
    DegenerateInputError
        Also a ``scipy.spatial.QhullError``: fewer than d+1 affinely
        independent points, where scipy raises QhullError.
    ValueError
        Masked, NaN or inf input, or not (n, 2) or (n, 3).

    Attributes
    ----------
    points : ndarray of float64, shape (npoints, ndim)
        The input points.
    simplices : ndarray of intc, shape (nsimplex, ndim+1)
        Indices of the points forming each simplex: counter-clockwise
        triangles in 2D, right-handed tetrahedra in 3D.
    neighbors : ndarray of intc, shape (nsimplex, ndim+1)
        Neighbour k of a simplex is opposite its vertex k; -1 on the hull.
    equations : ndarray of float64, shape (nsimplex, ndim+2)
        Unit normal and offset of each simplex's plane on the lifted
        paraboloid, normal pointing down, as Qhull's (computed on first
        access).
    transform : ndarray of float64, shape (nsimplex, ndim+1, ndim)
        Affine transform to barycentric coordinates: ``c = T[:ndim] @ (x -
        T[ndim])`` gives the first ndim coordinates (NaN rows for a simplex
        too flat to invert in floating point, as scipy's).
    vertex_to_simplex : ndarray of intc, shape (npoints,)
        A simplex holding each vertex; a duplicate row maps to its twin's.
    vertex_neighbor_vertices : tuple of two ndarrays of intc
        ``(indptr, indices)``: the neighbours of vertex k are
        ``indices[indptr[k]:indptr[k+1]]``, in increasing order.
    convex_hull : ndarray of intc, shape (nfaces, ndim)
        The hull's edges (2D) or triangles (3D).
    coplanar : ndarray of intc, shape (ncoplanar, 3)
        Duplicate rows that are not vertices: (row, simplex holding its
        twin, the twin).
    ndim, npoints, nsimplex : int
    min_bound, max_bound : ndarray of float64, shape (ndim,)
        The points' bounding box.
    paraboloid_scale, paraboloid_shift : float
        The lift ``|x|^2 * scale + shift``: Qhull's "Qbb" with scipy's "Qz"
        (the lifted range, its top widened by 1.1 for the point at
        infinity, mapped onto ``[0, max |coordinate|]``), equal to scipy's; 1
        and 0 in incremental mode, as scipy's.
    good : ndarray of intc, shape (nsimplex,)
        All ones: every simplex is a Delaunay simplex.
    furthest_site : bool
        Always False.
    triangulation : Triangulation
        lfqt's result behind the object, with its ``stats``.

    Notes
    -----
    A query of ``find_simplex`` is located exactly, also where a coordinate
    lies below the exactness window of the triangulation's frame (module
    lfqt.location).  The derived attributes are computed on first access by
    jitted kernels (lfqt.derived), on ``threads`` threads.

    Examples
    --------
    >>> import numpy as np, lfqt
    >>> points = np.array([[0, 0], [0, 1.1], [1, 0], [1, 1]])
    >>> tri = lfqt.Delaunay(points)
    >>> tri.simplices
    array([[0, 2, 3],
           [3, 1, 0]], dtype=int32)
    >>> tri.find_simplex([[0.1, 0.2], [1.5, 0.5]])
    array([ 1, -1], dtype=int32)
    >>> lfqt.verify(points, tri).ok
    True

    Barycentric coordinates of a query, as with scipy:

    >>> T = tri.transform[1]
    >>> c = T[:2] @ (np.array([0.1, 0.2]) - T[2])
    >>> np.round(np.r_[c, 1 - c.sum()], 4)
    array([0.1   , 0.0909, 0.8091])
    """

    def __init__(self, points: npt.ArrayLike, furthest_site: bool = False,
                 incremental: bool = False, qhull_options: str | None = None,
                 **options: Any) -> None:
        """Triangulate ``points`` exactly (see the class's parameters)."""
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
        self.points = np.ascontiguousarray(arr, dtype=np.float64)
        self.ndim = d
        self.npoints = len(self.points)
        self._exponent = int(tri.stats["scale_exponent"])
        self._scale = 2.0 ** self._exponent
        self._cache = {}
        self._tri = tri
        self.simplices = np.ascontiguousarray(tri.simplices, dtype=np.intc)
        self.neighbors = np.ascontiguousarray(tri.neighbors, dtype=np.intc)
        # What the walk and the per-simplex kernels read: the points in the order the
        # simplices name them, in the location's frame (location.walk_frame), the same rows.
        P2, S2 = walk_frame(self.points, self.simplices, self._scale)
        self._mesh = (P2, S2, self.neighbors)
        self._mesh_bytes = P2.nbytes + S2.nbytes + self.neighbors.nbytes
        self.nsimplex = len(self.simplices)
        self.good = np.ones(self.nsimplex, dtype=np.intc)
        self.min_bound, self.max_bound, lifted = extents(self.points)
        self.paraboloid_scale, self.paraboloid_shift = self._paraboloid(*lifted)
        self._floor = 2.0 ** ((MIN_ULP_EXP if d == 2 else MIN_ULP_EXP_3D) + 52)

    def _paraboloid(self, lo, top, largest):
        """Qhull's "Qbb" with scipy's "Qz": the lifted coordinates (lowest
        ``lo``, highest ``top``), with the point at infinity's 1.1 times
        their maximum, are mapped to [0, ``largest`` |coordinate|] (scipy's
        formula from qh.last_low, last_high and last_newhigh); 1 and 0 in
        incremental mode, where scipy drops Qbb.  |x| near 1e155 and beyond
        overflows the lift, as Qhull's."""
        if self._incremental:
            return 1.0, 0.0
        with np.errstate(over="ignore"):
            hi = top * 1.1
        if not hi > lo:
            return 1.0, 0.0
        scale = float(largest / (hi - lo))
        return scale, float(-lo * scale)

    def _frame(self):
        """The points, in input order, in the location kernels' frame (the
        triangulation's exact rescale), for lfqt.natural; built on first
        use (the walk reads its own copy, along space: ``_mesh``)."""
        if self._exponent == 0:
            return self.points
        return self._cached("frame", lambda: self.points * self._scale)

    def _workers(self):
        """The build's thread count (None: every core, as lfqt.triangulate)."""
        threads = self._options.get("threads", 1)
        return Workers(os.cpu_count() or 1 if threads is None else threads)

    def _cached(self, name, build):
        if name not in self._cache:
            self._cache[name] = build()
        return self._cache[name]

    # -- the triangulation -------------------------------------------------

    @property
    def triangulation(self) -> Triangulation:
        """lfqt's Triangulation behind this object (with its stats)."""
        return self._tri

    @property
    def stats(self) -> dict:
        """The triangulation's statistics (``Triangulation.stats``): phase
        times, predicate counts, the frame's scale exponent."""
        return self._tri.stats

    @property
    def convex_hull(self):
        """(nfacets, ndim) int: the hull's edges (2D) or triangles (3D)."""
        def build():  # a few array writes: on a small mesh numpy's call overhead is the cost
            h = np.asarray(self._tri.hull)
            if self.ndim == 3:
                return np.ascontiguousarray(h, dtype=np.intc)
            edges = np.empty((len(h), 2), dtype=np.intc)
            edges[:, 0] = h
            edges[:-1, 1] = h[1:]
            edges[-1:, 1] = h[:1]
            return edges
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
        ``indices[indptr[k]:indptr[k+1]]``, in increasing order."""
        return self._cached("vnv", lambda: vertex_neighbours(self.simplices, self.npoints))

    # -- geometry in floating point, as scipy's --------------------------

    @property
    def transform(self):
        """(nsimplex, ndim+1, ndim): ``T^-1`` and ``r`` of ``T c = x - r``
        per simplex (barycentric coordinates); NaN for a simplex too flat
        to invert in floating point (1-norm condition number above
        1/(1000 eps), scipy's limit)."""
        return self._cached("transform", lambda: self._per_simplex(
            (self.ndim + 1, self.ndim), transforms, *self._mesh[:2], 1.0 / self._scale))

    @property
    def equations(self):
        """(nsimplex, ndim+2): unit normal and offset of each simplex's
        hyperplane in the lifted space, normal pointing down (out of the
        lower hull), as Qhull's."""
        return self._cached("equations", lambda: self._per_simplex(
            (self.ndim + 2,), hyperplanes, *self._mesh[:2], 1.0 / self._scale,
            float(self.paraboloid_scale), float(self.paraboloid_shift)))

    def _per_simplex(self, shape, kernel, *args):
        """A (nsimplex, *shape) array filled by ``kernel(*args, out, lo,
        hi)`` over ranges of simplices, on the triangulation's threads, in
        lfqt.workspace's memory (pages a freed array left, not fresh ones:
        at 2D 1M a fresh transform's 48 MB faulted in took about a third of
        its kernel's time)."""
        out = workspace.empty((self.nsimplex,) + shape, np.float64)
        workers = self._workers()
        workers.map(workers.chunks(self.nsimplex), lambda c, lo, hi: kernel(*args, out, lo, hi))
        return out

    def lift_points(self, x: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Lift points onto the paraboloid: (..., ndim) -> (..., ndim+1)."""
        x = np.asarray(x, dtype=np.float64)
        z = np.empty(x.shape[:-1] + (x.shape[-1] + 1,))
        if x.shape[-1] == 0 or z.size == 0:
            z[...] = self.paraboloid_shift
            return z
        lift(np.ascontiguousarray(x.reshape(-1, x.shape[-1])), self.paraboloid_scale,
             self.paraboloid_shift, z.reshape(-1, z.shape[-1]))
        return z

    def plane_distance(self, xi: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Distance of each lifted point to every simplex's hyperplane:
        (..., ndim) -> (..., nsimplex)."""
        xi = np.asarray(xi, dtype=np.float64)
        if xi.shape[-1] != self.ndim:
            raise ValueError("xi has different dimensionality than triangulation")
        eq = self.equations
        z = self.lift_points(xi.reshape(-1, self.ndim))
        out = np.empty((len(z), self.nsimplex))
        workers = self._workers()
        workers.map(workers.chunks(self.nsimplex),
                    lambda c, lo, hi: plane_distances(eq, z, out, lo, hi))
        return out.reshape(xi.shape[:-1] + (self.nsimplex,))

    # -- point location ---------------------------------------------------

    def find_simplex(self, xi: npt.ArrayLike, bruteforce: bool = False,
                     tol: float | None = None) -> npt.NDArray[np.intc]:
        """Index of a simplex containing each point of ``xi`` (..., ndim),
        -1 outside the hull or for NaN, as scipy's.  Exact: the answer
        always contains the query.  The queries are walked in the order of
        a space-filling curve, each from the previous answer, on the
        triangulation's threads.  ``bruteforce`` tests every simplex whose
        bounding box holds the query instead of walking (an answer on a
        shared facet may be the other simplex).  ``tol`` > 0 widens the
        answer only: a query outside every simplex gets one near the hull
        facets it sees whose barycentric coordinates are all >= -tol, as
        scipy's tolerance does, or -1."""
        xi = np.asanyarray(xi)
        if xi.shape[-1] != self.ndim:
            raise ValueError("wrong dimensionality in xi")
        shape = xi.shape[:-1]
        q = np.ascontiguousarray(xi.reshape(-1, self.ndim), dtype=np.float64)
        return self._locate(q, bruteforce, tol).astype(np.intc).reshape(shape)

    def _locate(self, q, bruteforce=False, tol=None):
        """find_simplex of the (n, ndim) contiguous float64 rows q, as int64
        (what lfqt.interpolate reads)."""
        tol = float(tol) if tol is not None and tol > 0 else 0.0
        if tol == 0 and self._exponent == 0 and in_frame(q, self.min_bound, self.max_bound,
                                                         self._floor):
            return self._walk(q, bruteforce)[0]  # q is its own frame: no copy
        # NaN and points outside the bounding box are outside: no predicate.  Q holds the
        # part of each query in the box that the frame holds exactly; tiny marks the rest.
        rows, Q, tiny, near = split_queries(q, self.min_bound, self.max_bound, self._scale,
                                            self._floor, tol)
        out, at = self._walk(Q, bruteforce)
        if tiny.any():
            out[tiny] = self._locate_tiny(q[rows[tiny]], Q[tiny], at[tiny])
        if len(rows) == len(q):  # every query in the box: out is in the caller's order
            found = out
        else:
            found = np.full(len(q), -1, dtype=np.int64)
            found[rows] = out
        if tol > 0:
            self._locate_tolerant(q, tol, found, rows[out < 0], at[out < 0], near)
        return found

    def _walk(self, Q, bruteforce):
        """(simplex of each row of Q or -1, the last simplex its search
        visited), on the threads for many queries."""
        out, at = np.empty(len(Q), dtype=np.int64), np.empty(len(Q), dtype=np.int64)
        if len(Q) == 0:
            return out, at
        workers = self._workers() if len(Q) > 4096 else Workers(1)
        chunks = workers.chunks(len(Q), min_chunk=4096)
        if bruteforce:
            P, S, _ = self._mesh
            B = simplex_boxes(P, S)
            workers.map(chunks, lambda c, lo, hi: locate_brute(P, S, B, Q, lo, hi, out))
            np.maximum(out, 0, out=at)
            return out, at
        mesh = self._mesh
        jump = jump_sample(len(Q), len(mesh[0]), len(mesh[1]))
        # the box of the mesh's points in the frame: its scale is a power of two, exact on them
        static = walk_static(np.array([self.min_bound, self.max_bound]) * self._scale, Q)
        if coherent(Q) and (self._mesh_bytes <= MESH_IN_CACHE or curve_like(Q, CURVE_WINDOW)):
            # the caller's order is already one along space (or the mesh fits in the caches)
            workers.map(chunks, lambda c, lo, hi: locate_walk(mesh, Q, lo, hi, out, at, jump,
                                                              static))
        else:  # the queries gathered in curve order, so that the walks read and write in a run
            order = grid_order(Q)
            Qs, found, last = Q[order], np.empty_like(out), np.empty_like(at)
            workers.map(chunks, lambda c, lo, hi: locate_walk(mesh, Qs, lo, hi, found, last,
                                                              jump, static))
            out[order], at[order] = found, last
        return out, at

    def _locate_tolerant(self, q, tol, found, rows, start, near):
        """scipy's tolerance for the queries outside every simplex: the
        best simplex near the hull facets the query sees, from where its
        walk left the hull (``start`` for ``rows``).  A query outside the
        bounding box but within tol of it (``near``) is first walked,
        clamped to the box, to the hull; one farther out stays -1, as
        scipy's first test has it."""
        if len(near):
            Q = np.clip(q[near], self.min_bound, self.max_bound) * self._scale
            rows, start = np.r_[rows, near], np.r_[start, self._walk(Q, False)[1]]
        if len(rows) == 0:
            return
        tr = self.transform
        for k, t in zip(rows, start):
            found[k] = locate_tolerant(self.simplices, self.neighbors, tr, q[k], tol, t)

    def _locate_tiny(self, q, H, start):
        """Queries with a component below the frame's floor, exactly, from
        where the walk of their in-frame part H ended (lfqt.location)."""
        if not tiny_frame_ok(self._exponent, self.ndim):
            return np.array([locate_rational(self.points, self.simplices, self.neighbors, x)
                             for x in q], dtype=np.int64)
        Ls = np.where(H == 0.0, np.ldexp(q, self._exponent + TINY_SHIFT), 0.0)
        return locate_tiny(*self._mesh, H, Ls, start)

    # -- incremental mode -------------------------------------------------

    def add_points(self, points: npt.ArrayLike, restart: bool = False) -> None:
        """Add points (incremental mode only): the union of the old and new
        points is triangulated again, exactly; ``restart`` gives the same
        result and is accepted for scipy's signature."""
        if not self._open:
            raise RuntimeError("incremental mode not enabled or already closed")
        new = _points_array(points, self.ndim)
        self._build(np.concatenate((self.points, np.asarray(new, dtype=np.float64)), axis=0))

    def close(self) -> None:
        """Finish incremental processing: no more ``add_points``."""
        self._open = False

    def __repr__(self):
        return (f"<lfqt.Delaunay {self.ndim}D: {self.npoints} points, {self.nsimplex} "
                f"simplices>")
