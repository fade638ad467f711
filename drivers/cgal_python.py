"""CGAL through its PyPI SWIG bindings (``cgal``, the CGAL project's
cgal-swig-bindings): ``Delaunay_triangulation_2.insert`` of a Python list
of ``Point_2``.  Two registry names: ``cgal-python`` times the insertion of
points already built as CGAL objects (CGAL at its fastest from Python),
``cgal-python-points`` also times building the ``Point_2`` list from the
array, which a Python user with a NumPy array cannot avoid.  The faces'
vertices are mapped back to input rows by their coordinates, after the
timed run."""
import numpy as np

from .base import PipPeer, Result
from .matching import rows_of


class CgalPythonPeer(PipPeer):
    family = "cgal_python"
    module = "CGAL.CGAL_Triangulation_2"
    package = "cgal"
    bytes_per_point = 1500

    def __init__(self, with_points):
        self.with_points = with_points
        self.name = "cgal-python-points" if with_points else "cgal-python"

    def prepare(self, points, order=None, count=False):
        self.points = np.ascontiguousarray(points, dtype=np.float64)
        self.prebuilt = None if self.with_points else self._cgal_points()
        self.dt = None

    def _cgal_points(self):
        from CGAL.CGAL_Kernel import Point_2
        return [Point_2(x, y) for x, y in self.points[:, :2].tolist()]

    def run(self):
        from CGAL.CGAL_Triangulation_2 import Delaunay_triangulation_2
        self.dt = None
        pts = self._cgal_points() if self.with_points else self.prebuilt
        dt = Delaunay_triangulation_2()
        dt.insert(pts)
        self.dt = dt

    def result(self):
        coords = []
        for f in self.dt.finite_faces():
            for i in range(3):
                q = f.vertex(i).point()
                coords.append((q.x(), q.y()))
        coords = np.array(coords, dtype=np.float64).reshape(-1, 2)
        return Result(rows_of(self.points, coords).reshape(-1, 3))


PEERS = {"cgal-python": lambda: CgalPythonPeer(False),
         "cgal-python-points": lambda: CgalPythonPeer(True)}
