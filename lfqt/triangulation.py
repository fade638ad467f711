"""What a triangulation returns: flat arrays in scipy's conventions."""
from dataclasses import dataclass, field

import numpy as np


class DegenerateInputError(ValueError):
    """Fewer than 3 distinct points, or all points collinear (scipy's Delaunay
    raises QhullError in that case)."""


@dataclass
class Triangulation:
    """A Delaunay triangulation in flat arrays (scipy's conventions).

    points: the input as given.  simplices: (m, 3) counter-clockwise rows of
    input indices, or (m, 4) right-handed tetrahedra from ``lfqt.insert`` in
    3D.  neighbors: same shape, neighbour i opposite vertex i, -1 on the
    hull.  hull: boundary vertex loop, counter-clockwise (3D: (k, 3) outward
    facets).  duplicate_of:
    per input row, the row that represents it.  degenerate: True when there
    are fewer than 3 distinct points or all are collinear (then simplices is
    empty and hull holds the extreme points); reason says which.
    """
    points: np.ndarray
    simplices: np.ndarray
    neighbors: np.ndarray
    hull: np.ndarray
    duplicate_of: np.ndarray
    stats: dict = field(default_factory=dict)
    degenerate: bool = False
    reason: str = ""

    @property
    def n_distinct(self):
        return int(np.count_nonzero(self.duplicate_of == np.arange(len(self.duplicate_of))))

    def __repr__(self):
        return (f"Triangulation(points={len(self.points)}, simplices={len(self.simplices)}, "
                f"hull={len(self.hull)}, degenerate={self.degenerate})")
