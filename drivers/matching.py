"""Input rows of a peer's vertices, for peers that return coordinates (or
renumber their vertices) instead of input indices: the CGAL bindings,
startinpy.  Matched exactly, float for float; a vertex that is no input row
(a peer that moved a point) gets -1, and verify rejects the mesh."""
import numpy as np


def rows_of(points, coords):
    """For each row of ``coords`` (k, 2), the first input row of ``points``
    (n, 2) with exactly those coordinates, or -1.  -0.0 and 0.0 are one
    coordinate, as they are one point."""
    pts = np.ascontiguousarray(points, dtype=np.float64)[:, :2] + 0.0  # -0.0 -> 0.0
    q = np.ascontiguousarray(coords, dtype=np.float64)[:, :2] + 0.0
    order = np.lexsort((np.arange(len(pts)), pts[:, 1], pts[:, 0]))
    keys = pts[order]
    lo = np.searchsorted(_view(keys), _view(q), side="left")
    lo = np.minimum(lo, max(len(keys) - 1, 0))
    if len(keys) == 0:
        return np.full(len(q), -1, dtype=np.int64)
    hit = np.all(keys[lo] == q, axis=1)
    return np.where(hit, order[lo], -1).astype(np.int64)


def _view(a):
    """Rows of (k, 2) float64 as one structured value each, compared x then y
    as numbers (searchsorted on a structured dtype compares field by field)."""
    return np.ascontiguousarray(a).view([("x", np.float64), ("y", np.float64)]).ravel()
