"""Qhull through ``scipy.spatial.Delaunay``, in 2D and 3D."""
from importlib import metadata

import numpy as np

from .base import Peer, Result


class QhullPeer(Peer):
    family = "qhull"
    bytes_per_point = 2500

    def __init__(self, dim):
        self.dim = dim
        self.name = f"qhull-{dim}d"

    def version(self):
        return "scipy " + metadata.version("scipy")

    def prepare(self, points, order=None, count=False):
        self.points = np.ascontiguousarray(points, dtype=np.float64)
        self.out = None

    def run(self):
        import scipy.spatial
        self.out = None
        self.out = scipy.spatial.Delaunay(self.points)

    def result(self):
        return Result(self.out.simplices)


PEERS = {"qhull-2d": lambda: QhullPeer(2), "qhull-3d": lambda: QhullPeer(3)}
