"""TetGen (Hang Si) through ``meshpy.tet`` (PyPI ``meshpy``, Andreas
Kloeckner's wrapper).  ``meshpy.tet.build`` defaults to TetGen's ``pq``
switches (a piecewise linear complex, quality refinement with Steiner
points); the driver calls ``meshpy.tet.tetrahedralize`` with the switches
of a plain point set's Delaunay tetrahedralisation and nothing else
written: ``z`` (zero-based indices), ``Q`` (quiet), ``B``, ``F``, ``N``
(no boundary markers, faces or nodes: the tetrahedra index the input)."""
import numpy as np

from .base import PipPeer, Result

SWITCHES = "zQBFN"


class MeshpyTetPeer(PipPeer):
    name = "tetgen"
    dim = 3
    family = "meshpy_tet"
    module = "meshpy.tet"
    package = "meshpy"
    bytes_per_point = 1500

    def prepare(self, points, order=None, count=False):
        import meshpy.tet as mt
        self.check()
        self.info = mt.MeshInfo()
        self.info.set_points(np.ascontiguousarray(points, dtype=np.float64))
        self.switches = mt.Options(SWITCHES)
        self.out = None

    def run(self):
        import meshpy.tet as mt
        self.out = None
        self.out = mt.tetrahedralize(self.info, self.switches)

    def result(self):
        return Result(np.array(self.out.elements, dtype=np.int64).reshape(-1, 4))


PEERS = {"tetgen": MeshpyTetPeer}
