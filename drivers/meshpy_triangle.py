"""Triangle through ``meshpy.triangle`` (PyPI ``meshpy``, Andreas
Kloeckner's wrapper).  ``meshpy.triangle.build`` always passes Triangle's
``p`` switch (a planar straight-line graph), which with no segments eats
every triangle; the driver calls the same wrapped ``triangulate`` that
``build`` calls, with the switches of a plain point set: ``zQ`` (zero-based
indices, quiet), Triangle's default divide and conquer."""
import numpy as np

from .base import PipPeer, Result


class MeshpyTrianglePeer(PipPeer):
    name = "meshpy-triangle"
    family = "meshpy_triangle"
    module = "meshpy.triangle"
    package = "meshpy"
    bytes_per_point = 500

    def prepare(self, points, order=None, count=False):
        import meshpy.triangle as mt
        self.info = mt.MeshInfo()
        self.info.set_points(np.ascontiguousarray(points, dtype=np.float64))
        self.out = None

    def run(self):
        import meshpy.triangle as mt
        from meshpy import _internals
        self.out = None
        out = mt.MeshInfo()
        _internals.triangulate("zQ", self.info, out, mt.MeshInfo(), None)
        self.out = out

    def result(self):
        return Result(np.array(self.out.elements, dtype=np.int64).reshape(-1, 3))


PEERS = {"meshpy-triangle": MeshpyTrianglePeer}
