"""gmsh's ``gmsh.algorithm.triangulate`` (PyPI ``gmsh``): the points as one
flat coordinate vector, the triangles back 1-based.  gmsh is initialised
once in ``prepare`` (its start-up is not the triangulation)."""
import numpy as np

from .base import PipPeer, Result


class GmshPeer(PipPeer):
    name = "gmsh"
    family = "gmsh_triangulate"
    module = "gmsh"
    package = "gmsh"
    bytes_per_point = 600
    inexact = ("gmsh's triangulate drops triangles along the convex hull and mixes "
               "orientations, even on uniform random points")

    def prepare(self, points, order=None, count=False):
        import gmsh
        if not gmsh.isInitialized():
            gmsh.initialize(readConfigFiles=False)
            gmsh.option.setNumber("General.Verbosity", 0)
            gmsh.option.setNumber("General.Terminal", 0)
        self.flat = np.ascontiguousarray(points, dtype=np.float64).ravel()
        self.out = None

    def run(self):
        import gmsh
        self.out = None
        self.out = gmsh.algorithm.triangulate(self.flat)

    def result(self):
        tri = np.asarray(self.out, dtype=np.int64).reshape(-1, 3) - 1
        # gmsh mixes orientations: each triangle turned counter-clockwise
        # (our convention) by its floating-point orientation; a flat one stays
        # as it is, for verify to reject
        p = self.flat.reshape(-1, 2)
        a, b, c = p[tri[:, 0]], p[tri[:, 1]], p[tri[:, 2]]
        cw = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]) < 0
        tri[cw] = tri[cw][:, ::-1]
        return Result(tri)


def known_failure(distribution, n):
    """Why gmsh is known not to finish ``n`` points of ``distribution``
    within a cell's limit, or None: on the LiDAR
    model's xy from 100k points it found no result within 120 s."""
    if distribution == "lidar-xy" and n >= 100_000:
        return "known hang: no result within 120 s at the default scale"
    return None


PEERS = {"gmsh": GmshPeer}
