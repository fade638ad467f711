"""CDT (artem-ogre's C++ constrained Delaunay library) through its PyPI
bindings, ``pythoncdt``: the points inserted at once in CDT's own order
(``VertexInsertionOrder.AUTO``: a k-d tree breadth-first order), then the
super-triangle erased.  CDT refuses duplicate points with an error (its
C++ side offers a duplicate-removal helper the bindings do not expose)."""
import numpy as np

from .base import PipPeer, Result


class CdtPeer(PipPeer):
    name = "cdt"
    family = "cdt"
    module = "pythoncdt"
    package = "pythoncdt"
    bytes_per_point = 400

    def prepare(self, points, order=None, count=False):
        self.points = np.ascontiguousarray(points, dtype=np.float64)
        self.out = None

    def run(self):
        import pythoncdt
        self.out = None
        t = pythoncdt.Triangulation(pythoncdt.VertexInsertionOrder.AUTO,
                                    pythoncdt.IntersectingConstraintEdges.NOT_ALLOWED, 0.0)
        t.insert_vertices(self.points)
        t.erase_super_triangle()
        self.out = t

    def result(self):
        # after erase_super_triangle vertex i is input row i again
        tri = self.out.triangles_array(copy=True)["vertices"].astype(np.int64)
        return Result(tri.reshape(-1, 3))


def known_failure(distribution, n):
    """Why CDT is known not to finish ``n`` points of ``distribution``
    within a cell's limit, or None: on 1e300 magnitudes (generators.hard) it
    found no result within 120 s, at any size."""
    if distribution == "huge":
        return "known hang: no result within 120 s at the default scale"
    return None


PEERS = {"cdt": CdtPeer}
