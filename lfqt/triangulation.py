"""What a triangulation returns: flat arrays in scipy's conventions."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

IndexArray = npt.NDArray[np.signedinteger[Any]]
"""Vertex or simplex ids: int32 below 2**31 - 2 points, int64 from there
(lfqt._input.index_dtype; lfqt.distributed gives int64)."""


class DegenerateInputError(ValueError):
    """Fewer than 3 distinct points, or all points collinear (scipy's Delaunay
    raises QhullError in that case).

    ``lfqt.Delaunay`` raises it; ``triangulate`` and ``insert`` return a
    Triangulation with ``degenerate=True`` instead.  Where scipy is
    installed, what ``lfqt.Delaunay`` raises is also a
    ``scipy.spatial.QhullError``.

    Examples
    --------
    >>> import numpy as np, lfqt
    >>> line = np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]])
    >>> try:
    ...     lfqt.Delaunay(line)
    ... except lfqt.DegenerateInputError as e:
    ...     print(e)
    cannot triangulate: all points collinear
    >>> tri = lfqt.triangulate(line)  # no error: an empty result, flagged
    >>> tri.degenerate, tri.simplices.shape, tri.hull.tolist()
    (True, (0, 3), [0, 2])
    """


@dataclass
class Triangulation:
    """A Delaunay triangulation in flat arrays (scipy's conventions).

    What ``lfqt.triangulate`` and ``lfqt.insert`` return; ``lfqt.verify``
    checks one exactly.

    Attributes
    ----------
    points : array_like, shape (n, 2) or (n, 3)
        The input as given (not copied, not rescaled); None for a mesh
        built from its simplices alone
        (lfqt.verification.mesh_from_simplices).
    simplices : ndarray of int32 or int64, shape (m, 3) or (m, 4)
        Rows of input indices: counter-clockwise triangles, or right-handed
        tetrahedra from ``lfqt.insert`` in 3D.  int32 below 2**31 - 2
        points, int64 from there.  Empty, shape (0, d + 1), when
        ``degenerate``.
    neighbors : ndarray of int32 or int64, shape (m, 3) or (m, 4)
        ``neighbors[j, i]``: the simplex opposite vertex ``simplices[j, i]``,
        -1 on the hull.
    hull : ndarray of int32 or int64, shape (h,) or (h, 3)
        2D: the boundary vertex loop, counter-clockwise.  3D: the outward
        hull facets, one row per triangle.  When ``degenerate``: the
        extreme points.
    duplicate_of : ndarray of int32 or int64, shape (n,)
        Per input row, the row that represents it (the smallest index among
        equal points); ``duplicate_of[i] == i`` for a distinct point.
    stats : dict
        Seconds per phase (``stats["seconds"]``), predicate counts
        (``stats["counts"]`` and ``stats["per_point"]``, when asked for)
        and how the call ran (threads, key bits, order, ...).
    degenerate : bool
        True when there are fewer than 3 distinct points or all are
        collinear (3D: fewer than 4, or all coplanar): then ``simplices``
        is empty and ``hull`` holds the extreme points.
    reason : str
        Why the input is degenerate ("" otherwise).
    n_distinct : int
        The number of distinct input points (a property, from
        ``duplicate_of``).

    Examples
    --------
    >>> import numpy as np
    >>> import lfqt
    >>> p = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0], [1.0, 1.0]])
    >>> tri = lfqt.triangulate(p)
    >>> tri
    Triangulation(points=5, simplices=2, hull=4, degenerate=False)
    >>> tri.simplices.shape, tri.simplices.dtype
    ((2, 3), dtype('int32'))
    >>> tri.duplicate_of
    array([0, 1, 2, 3, 3], dtype=int32)
    >>> tri.n_distinct
    4
    >>> lfqt.triangulate(p[:2]).reason
    'fewer than 3 distinct points'
    """
    points: npt.ArrayLike | None
    simplices: IndexArray
    neighbors: IndexArray
    hull: IndexArray
    duplicate_of: IndexArray
    stats: dict[str, Any] = field(default_factory=dict)
    degenerate: bool = False
    reason: str = ""

    @property
    def n_distinct(self) -> int:
        return int(np.count_nonzero(self.duplicate_of == np.arange(len(self.duplicate_of))))

    def __repr__(self) -> str:
        points = len(self.points)  # type: ignore[arg-type]  # the input, a sequence
        return (f"Triangulation(points={points}, simplices={len(self.simplices)}, "
                f"hull={len(self.hull)}, degenerate={self.degenerate})")
