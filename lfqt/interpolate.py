"""``lfqt.interpolate``: scipy.interpolate's scattered-data interpolators over
lfqt's exact Delaunay triangulation.

``LinearNDInterpolator``, ``CloughTocher2DInterpolator``,
``NearestNDInterpolator`` and ``griddata`` take scipy's arguments and give
scipy's results, and the triangulated ones also take an ``lfqt.Delaunay``
in place of the points, so that one triangulation serves many fields.
scipy's own reach into Qhull's C structures and cannot take one.
``NaturalNeighborInterpolator`` (and ``griddata(method="natural")``) adds
Sibson's natural-neighbour interpolation in 2D and 3D (lfqt.natural).

A query is located exactly (``Delaunay.find_simplex``): it gets a value
when it lies in the closed convex hull of the points.  A query just
outside, whose barycentric coordinates in a hull simplex are all >= -100
eps (scipy's tolerance, which keeps a point computed on the hull in
floating point inside), also gets one, as with scipy: it is nudged into the
hull by 1e-9 of its distance to the points' centroid, located again, and
its coordinates are checked in that simplex and its neighbours (on a
grazing hull, where the nudge lands farther than a simplex away, it gets
``fill_value`` where scipy's walk might have accepted it).  The weighted sums and the Clough-Tocher element are jitted kernels
(lfqt._interpolate_kernels) run over ranges of queries on ``threads``
threads; the gradient estimate of the Clough-Tocher interpolant is scipy's
minimum-curvature Gauss-Seidel iteration over ``vertex_neighbor_vertices``.
"""
from __future__ import annotations

import os
import sys
import warnings
from typing import Any

import numpy as np
import numpy.typing as npt

from ._interpolate_kernels import (_clough_tocher, _edge_geometry, _gradients, _linear,
                                   _near_hull)
from .delaunay import Delaunay
from .workers import Workers

__all__ = ["LinearNDInterpolator", "CloughTocher2DInterpolator", "NearestNDInterpolator",
           "NaturalNeighborInterpolator", "griddata", "estimate_gradients_2d_global",
           "GradientEstimationWarning"]

MIN_QUERIES_PER_THREAD = 1 << 14  # below this a range costs more to hand out than to run
HULL_EPS = 100 * np.finfo(np.float64).eps  # scipy's tolerance on barycentric coordinates
NUDGE = 1e-9  # of the way to the centroid: past the hull's rounding, short of a simplex


class GradientEstimationWarning(Warning):
    """The gradient estimate stopped at ``maxiter`` before reaching ``tol``."""


def _coordinates(points, ndim=None):
    """scipy's coordinate forms as one (..., ndim) array: a tuple of
    broadcastable coordinate arrays is stacked along a last axis; an array
    is taken as it is, a 1-D one as points of ``ndim`` coordinates (one
    column without ``ndim``).  A tuple of one element is that element (the
    ``*args`` of a call with one argument)."""
    if isinstance(points, tuple) and len(points) == 1:
        points = points[0]
    if isinstance(points, tuple):
        parts = np.broadcast_arrays(*points)
        out = np.empty(parts[0].shape + (len(parts),), dtype=np.float64)
        for j, part in enumerate(parts):
            out[..., j] = part
        return out
    arr = np.asanyarray(points)
    if arr.ndim == 1:
        arr = arr.reshape(-1, 1 if ndim is None else ndim)
    return arr


def _check_shapes(points, values, ndim=None):
    """scipy's checks of the data, with its messages."""
    if values.shape[0] != points.shape[0]:
        raise ValueError("different number of values and points")
    if points.ndim != 2:
        raise ValueError("invalid shape for input data points")
    if points.shape[1] < 2:
        raise ValueError("input data must be at least 2-D")
    if ndim is not None and points.shape[1] != ndim:
        raise ValueError(f"this mode of interpolation available only for {ndim}-D data")


def _kernel_array(a, dtype):
    """``a`` as a C-contiguous writable array of ``dtype``: numba compiles
    a kernel again for read-only arrays, so those are copied."""
    a = np.ascontiguousarray(a, dtype=dtype)
    return a if a.flags.writeable else a.copy()


def _is_scipy_delaunay(obj):
    spatial = sys.modules.get("scipy.spatial")
    return spatial is not None and isinstance(obj, spatial.Delaunay)


class _Interpolator:
    """What the interpolators share, as scipy's NDInterpolatorBase: the
    data (points or a Delaunay, values of shape (n, ...) float or complex),
    the rescale to the unit cube, and the call forms.

    Attributes: ``points`` (rescaled when ``rescale``), ``values`` as
    (npoints, nvalues), ``values_shape`` (the trailing shape of the
    values), ``is_complex``, ``fill_value``, ``tri`` (an lfqt.Delaunay or
    None), ``scale`` and ``offset`` (``scale`` None without rescale)."""

    _ndim: int | None = None  # the one dimension the method supports, None for any

    def _setup(self, points, values, fill_value, rescale, threads, triangulate=True):
        self._threads = threads
        self.tri = None
        if isinstance(points, Delaunay) or _is_scipy_delaunay(points):
            if rescale:
                raise ValueError("Rescaling is not supported when passing a Delaunay "
                                 "triangulation as ``points``.")
            if isinstance(points, Delaunay):
                self.tri = points
            points = points.points  # a scipy Delaunay is triangulated again, exactly
        points = _coordinates(points)
        if triangulate:
            points = _kernel_array(points, np.float64)
        self.scale = None
        if rescale:
            self.offset = np.mean(points, axis=0)
            self.scale = np.ptp(points, axis=0)
            self.scale[~(self.scale > 0)] = 1.0  # a flat axis stays as it is
            points = (points - self.offset) / self.scale
        self.points = points
        values = np.asarray(values)
        _check_shapes(points, values, self._ndim)
        if triangulate and self.tri is None:
            self.tri = Delaunay(points, threads=threads)
        self._set_values(values, fill_value)

    def _set_values(self, values, fill_value):
        self.values_shape = values.shape[1:]
        flat = values.reshape(values.shape[0], int(np.prod(values.shape[1:])))
        self.is_complex = np.issubdtype(flat.dtype, np.complexfloating)
        if self.is_complex:
            self.values = _kernel_array(flat, np.complex128)
            self.fill_value = complex(fill_value)
        else:
            self.values = _kernel_array(flat, np.float64)
            self.fill_value = float(fill_value)

    # -- queries -----------------------------------------------------------

    def _queries(self, args):
        """(queries as (m, ndim) float64 in the rescaled frame, their shape)."""
        xi = _coordinates(args, ndim=self.points.shape[1])
        xi = np.asanyarray(xi)
        if xi.shape[-1] != self.points.shape[1]:
            raise ValueError("number of dimensions in xi does not match x")
        shape = xi.shape
        xi = _kernel_array(xi.reshape(-1, shape[-1]), np.float64)
        if self.scale is not None:
            xi = (xi - self.offset) / self.scale
        return xi, shape

    def __call__(self, *args: npt.ArrayLike) -> np.ndarray:
        """Evaluate at ``xi``: one array of shape (..., ndim), or ndim
        broadcastable coordinate arrays (a meshgrid, say), as scipy's.
        Returns shape (...) + the values' trailing shape."""
        xi, shape = self._queries(args)
        out = self._evaluate(xi)
        return out.reshape(shape[:-1] + self.values_shape)

    def _real(self):
        """(values as float64 columns, the fill value of each column): a
        complex column becomes its real and imaginary columns."""
        if self.is_complex:
            fill = np.tile([self.fill_value.real, self.fill_value.imag], self.values.shape[1])
            return self.values.view(np.float64), fill
        return self.values, np.full(self.values.shape[1], self.fill_value)

    def _as_values(self, out):
        return out.view(np.complex128) if self.is_complex else out

    def _locate(self, xi):
        """The simplex of each query, exactly, and for the queries just
        outside the hull one that holds them within scipy's tolerance
        (module docstring), or -1."""
        tri = self.tri
        found = tri._locate(xi)  # int64 (find_simplex's intc, not converted twice)
        box = np.abs(tri.max_bound - tri.min_bound) * HULL_EPS
        outside = np.flatnonzero(found < 0)  # few: the box tests run on these rows only
        x = xi[outside]
        near = outside[(x >= tri.min_bound - box).all(axis=1)
                       & (x <= tri.max_bound + box).all(axis=1)]
        if len(near):
            x = xi[near]
            inward = tri.find_simplex(x + NUDGE * (tri.points.mean(axis=0) - x))
            again = np.empty(len(near), dtype=np.int64)
            _near_hull(tri.neighbors, tri.transform, inward.astype(np.int64), x, HULL_EPS, again)
            found[near] = again
        return found

    def _run(self, kernel, mesh, xi, *arrays):
        """kernel(mesh, simplex of each query, xi, *arrays, out, lo, hi)
        over ranges of the queries on the threads; returns out."""
        found = self._locate(xi)
        out = np.empty((len(xi), arrays[0].shape[1]))
        threads = (os.cpu_count() or 1) if self._threads is None else self._threads
        workers = Workers(threads)
        chunks = workers.chunks(len(xi), min_chunk=MIN_QUERIES_PER_THREAD)
        workers.map(chunks, lambda c, lo, hi: kernel(mesh, found, xi, *arrays, out, lo, hi))
        return out

    def __repr__(self):
        return (f"<lfqt.interpolate.{type(self).__name__}: {len(self.points)} points, "
                f"{self.points.shape[1]}D, values {self.values_shape}>")


class LinearNDInterpolator(_Interpolator):
    """Piecewise linear interpolator in 2D and 3D, as
    ``scipy.interpolate.LinearNDInterpolator``.

    Parameters
    ----------
    points : ndarray of float, shape (npoints, ndim); or lfqt.Delaunay
        The data points (or a tuple of ndim coordinate arrays), or a
        triangulation of them, which is used as it is (``self.tri is
        points``).  A ``scipy.spatial.Delaunay`` is taken as its points.
    values : ndarray of float or complex, shape (npoints, ...)
        The data at the points.
    fill_value : float, optional
        The value outside the convex hull of the points (NaN).
    rescale : bool, optional
        Rescale the points to the unit cube (centred on their mean) before
        triangulating, and the queries alike.  Not with a Delaunay.
    threads : int or None, keyword only
        Threads for the triangulation, the location and the weighted sums;
        None (the default) uses every core.  A given Delaunay locates on
        its own threads.

    Raises
    ------
    ValueError
        Mismatched or badly shaped input (scipy's messages), or points not
        in 2 or 3 dimensions.
    lfqt.DegenerateInputError
        Also ``scipy.spatial.QhullError``: points of a lower dimension.

    Examples
    --------
    >>> import numpy as np, lfqt
    >>> pts = np.array([[0, 0], [1, 0], [0, 1], [1, 1], [0.3, 0.6]])
    >>> ip = lfqt.interpolate.LinearNDInterpolator(pts, 2 * pts[:, 0] - pts[:, 1] + 1)
    >>> np.round(ip([[0.5, 0.25], [2.0, 0.0]]), 12)
    array([1.75,  nan])
    >>> second = lfqt.interpolate.LinearNDInterpolator(ip.tri, pts[:, 1])  # the same mesh
    >>> float(np.round(second(0.5, 0.25), 12)), second.tri is ip.tri
    (0.25, True)
    """

    def __init__(self, points: Any, values: npt.ArrayLike, fill_value: float = np.nan,
                 rescale: bool = False, *, threads: int | None = None) -> None:
        self._setup(points, values, fill_value, rescale, threads)

    def _evaluate(self, xi):
        V, fill = self._real()
        tri = self.tri
        mesh = (tri.points, tri.simplices, tri.neighbors, tri.transform)
        return self._as_values(self._run(_linear, mesh, xi, V, fill))


class CloughTocher2DInterpolator(_Interpolator):
    """Piecewise cubic, C1, curvature-minimising interpolator in 2D, as
    ``scipy.interpolate.CloughTocher2DInterpolator``.

    Parameters
    ----------
    points : ndarray of float, shape (npoints, 2); or lfqt.Delaunay
        As for ``LinearNDInterpolator``.
    values : ndarray of float or complex, shape (npoints, ...)
    fill_value : float, optional
        The value outside the convex hull (NaN).
    tol : float, optional
        Absolute/relative tolerance of the gradient estimate (1e-6).
    maxiter : int, optional
        Most Gauss-Seidel sweeps of the gradient estimate (400); a
        ``GradientEstimationWarning`` says when they did not reach ``tol``.
    rescale : bool, optional
        As for ``LinearNDInterpolator``.
    threads : int or None, keyword only
        As for ``LinearNDInterpolator``.

    Attributes
    ----------
    grad : ndarray, shape (npoints, nvalues, 2)
        The estimated gradient at each point; the element reads it at each
        call, so that it may be changed.

    Examples
    --------
    >>> import numpy as np, lfqt
    >>> pts = np.random.default_rng(0).random((200, 2))
    >>> ip = lfqt.interpolate.CloughTocher2DInterpolator(pts, 3 * pts[:, 0] - pts[:, 1])
    >>> np.round(ip([0.5, 0.5]), 8)
    array([1.])
    """

    _ndim = 2

    def __init__(self, points: Any, values: npt.ArrayLike, fill_value: float = np.nan,
                 tol: float = 1e-6, maxiter: int = 400, rescale: bool = False, *,
                 threads: int | None = None) -> None:
        self._tol = tol
        self._maxiter = maxiter
        self._setup(points, values, fill_value, rescale, threads)
        self.grad = estimate_gradients_2d_global(self.tri, self.values, maxiter=maxiter,
                                                 tol=tol)

    def _evaluate(self, xi):
        V, fill = self._real()
        grad = np.asarray(self.grad).reshape(len(self.values), -1, 2)
        if self.is_complex:  # real and imaginary columns side by side, as V's view
            G = np.empty((len(grad), grad.shape[1], 2, 2))
            G[:, :, 0, :], G[:, :, 1, :] = grad.real, grad.imag
            G = G.reshape(len(grad), -1, 2)
        else:
            G = np.ascontiguousarray(grad, dtype=np.float64)
        tri = self.tri
        mesh = (tri.points, tri.simplices, tri.neighbors, tri.transform)
        return self._as_values(self._run(_clough_tocher, mesh, xi, V, G, fill))


def estimate_gradients_2d_global(tri: Any, y: npt.ArrayLike, maxiter: int = 400,
                                 tol: float = 1e-6) -> np.ndarray:
    """Gradients at the vertices of a 2D triangulation that approximately
    minimise the curvature of the Clough-Tocher interpolant of ``y``, as
    scipy's ``estimate_gradients_2d_global``.

    Parameters
    ----------
    tri : lfqt.Delaunay (2D)
        Anything with ``points``, ``npoints`` and ``vertex_neighbor_vertices``.
    y : ndarray of float or complex, shape (npoints, ...)
    maxiter, tol : int, float
        The most Gauss-Seidel sweeps, and the largest change (relative above
        1) that stops them.

    Returns
    -------
    ndarray, shape y.shape + (2,)
        A ``GradientEstimationWarning`` is issued for each column whose
        sweeps did not converge.
    """
    y = np.asanyarray(y)
    if y.shape[0] != tri.npoints:
        raise ValueError("'y' has a wrong number of items")
    if np.issubdtype(y.dtype, np.complexfloating):
        out = np.empty(y.shape + (2,), dtype=complex)
        out.real = estimate_gradients_2d_global(tri, y.real, maxiter=maxiter, tol=tol)
        out.imag = estimate_gradients_2d_global(tri, y.imag, maxiter=maxiter, tol=tol)
        return out
    columns = np.ascontiguousarray(y.reshape(tri.npoints, -1).T, dtype=np.float64)
    P = np.ascontiguousarray(tri.points, dtype=np.float64)
    indptr, indices = tri.vertex_neighbor_vertices
    L3, Q = _edge_geometry(P, indptr, indices)
    grad = np.empty((len(columns), tri.npoints, 2))
    for k, f in enumerate(columns):
        if _gradients(P, indptr, indices, L3, Q, f, int(maxiter), float(tol), grad[k]) == 0:
            warnings.warn("Gradient estimation did not converge, the results may be "
                          "inaccurate", GradientEstimationWarning, stacklevel=2)
    return grad.transpose(1, 0, 2).reshape(y.shape + (2,))


class NearestNDInterpolator(_Interpolator):
    """Nearest-neighbour interpolator in any dimension, as
    ``scipy.interpolate.NearestNDInterpolator`` (a ``scipy.spatial.cKDTree``
    of the points).

    Parameters
    ----------
    x : ndarray of float, shape (npoints, ndim); or lfqt.Delaunay
        The data points (or a tuple of coordinate arrays), or a
        triangulation whose points are used.
    y : ndarray of float or complex, shape (npoints, ...)
    rescale : bool, optional
        Rescale the points (and the queries) to the unit cube.
    tree_options : dict, optional
        Passed to ``cKDTree``.

    Examples
    --------
    >>> import numpy as np, lfqt
    >>> ip = lfqt.interpolate.NearestNDInterpolator([[0, 0], [1, 0], [0, 1]], [10, 20, 30])
    >>> ip([[0.9, 0.2], [0.1, 0.1]])
    array([20., 10.])
    """

    def __init__(self, x: Any, y: npt.ArrayLike, rescale: bool = False,
                 tree_options: dict | None = None) -> None:
        from scipy.spatial import cKDTree
        self._setup(x, y, np.nan, rescale, 1, triangulate=False)
        self.tree = cKDTree(self.points, **(tree_options or {}))
        self.values = np.asarray(y)

    def __call__(self, *args: npt.ArrayLike, **query_options: Any) -> np.ndarray:
        """Evaluate at ``xi`` (the forms of the other interpolators);
        ``query_options`` (``eps``, ``p``, ``distance_upper_bound``,
        ``workers``) go to ``cKDTree.query``, and a query with no point
        within ``distance_upper_bound`` gets NaN."""
        xi, shape = self._queries(args)
        dist, nearest = self.tree.query(xi, **query_options)
        found = np.isfinite(dist)
        trailing = self.values.shape[1:]
        dtype = self.values.dtype if np.iscomplexobj(self.values) else np.float64
        out = np.full((len(xi),) + trailing, np.nan, dtype=dtype)
        out[found] = self.values[nearest[found], ...]
        return out.reshape(shape[:-1] + trailing)


class NaturalNeighborInterpolator(_Interpolator):
    """Sibson's natural-neighbour interpolator in 2D and 3D (lfqt.natural),
    with the data forms, rescale and call forms of the others.

    Parameters
    ----------
    points : ndarray of float, shape (npoints, 2 or 3); or lfqt.Delaunay
    values : ndarray of float or complex, shape (npoints, ...)
    fill_value : float, optional
        The value outside the convex hull (NaN).
    rescale : bool, optional
    threads : int or None, keyword only
        Threads for the triangulation it builds.

    Examples
    --------
    Sibson's interpolant reproduces a linear function exactly, and equals
    the data at the data points:

    >>> import numpy as np
    >>> from lfqt.interpolate import NaturalNeighborInterpolator
    >>> p = np.random.default_rng(0).random((200, 2))
    >>> f = NaturalNeighborInterpolator(p, 2 * p[:, 0] - p[:, 1] + 1)
    >>> np.round(f([[0.5, 0.5], [0.25, 0.75]]), 12)
    array([1.5 , 0.75])
    >>> bool(np.allclose(f(p[:5]), 2 * p[:5, 0] - p[:5, 1] + 1))
    True
    """

    def __init__(self, points: Any, values: npt.ArrayLike, fill_value: float = np.nan,
                 rescale: bool = False, *, threads: int | None = None) -> None:
        self._setup(points, values, fill_value, rescale, threads)

    def _evaluate(self, xi):
        from . import natural  # the kernels' module: this one imports without it
        if not self.is_complex:
            return natural.interpolate(self.tri, self.values, xi, self.fill_value)
        parts = [np.ascontiguousarray(part) for part in (self.values.real, self.values.imag)]
        real = natural.interpolate(self.tri, parts[0], xi, self.fill_value.real)
        imag = natural.interpolate(self.tri, parts[1], xi, self.fill_value.imag)
        return real + 1j * imag


_METHODS = {"linear": LinearNDInterpolator, "nearest": NearestNDInterpolator,
            "cubic": CloughTocher2DInterpolator, "natural": NaturalNeighborInterpolator}


def griddata(points: Any, values: npt.ArrayLike, xi: Any, method: str = "linear",
             fill_value: float = np.nan, rescale: bool = False) -> np.ndarray:
    """Interpolate scattered data at ``xi``, as ``scipy.interpolate.griddata``.

    Parameters
    ----------
    points : ndarray of float, shape (n, ndim), or a tuple of ndim arrays (n,)
    values : ndarray of float or complex, shape (n, ...)
    xi : ndarray of float, shape (..., ndim), or a tuple of ndim broadcastable arrays
    method : {"linear", "nearest", "cubic", "natural"}
        ``LinearNDInterpolator``, ``NearestNDInterpolator``,
        ``CloughTocher2DInterpolator`` (2D only) or
        ``NaturalNeighborInterpolator``.  1-D data go to scipy's
        ``griddata`` (``interp1d``), as scipy does.
    fill_value : float, optional
        The value outside the convex hull (not for "nearest").
    rescale : bool, optional
        Rescale the points and xi to the unit cube.

    Examples
    --------
    >>> import numpy as np, lfqt
    >>> pts = np.array([[0, 0], [1, 0], [0, 1], [1, 1]])
    >>> lfqt.interpolate.griddata(pts, pts.sum(axis=1), ([0.25, 0.5], [0.5, 2]))
    array([0.75,  nan])
    """
    coords = _coordinates(points)
    ndim = coords.ndim if coords.ndim < 2 else coords.shape[-1]
    if ndim == 1 and method in ("nearest", "linear", "cubic"):
        from scipy.interpolate import griddata as scipy_griddata
        return scipy_griddata(points, values, xi, method=method, fill_value=fill_value,
                              rescale=rescale)
    if method == "nearest":
        return NearestNDInterpolator(coords, values, rescale=rescale)(xi)
    if method in ("linear", "natural") or (method == "cubic" and ndim == 2):
        return _METHODS[method](coords, values, fill_value=fill_value, rescale=rescale)(xi)
    raise ValueError(f"Unknown interpolation method {method!r} for {ndim} dimensional data")
