"""gmsh's ``gmsh.algorithm.tetrahedralize`` (PyPI ``gmsh``): the points as
one flat coordinate vector, the tetrahedra back 1-based (and Steiner points,
none for a bare point set).  Two peers: gmsh-hxt with
``Mesh.Algorithm3D = 10`` (HXT, Marot, Pellerin and Remacle 2019, parallel
through ``Mesh.MaxNumThreads3D``), and gmsh-default with gmsh's default 3D
algorithm (1, Delaunay).  gmsh is initialised once in ``prepare`` and the
options are set there too (its start-up is not the tetrahedralisation); the
options are gmsh's global state, so each peer sets all of them each time.
gmsh's Delaunay code writes a warning line per point it skips to the C
streams whatever General.Verbosity says (thousands on duplicates): the
call's own output goes to /dev/null (two dup2 calls, microseconds)."""
import contextlib
import ctypes
import os
import sys

import numpy as np

from .base import PipPeer, Result

HXT = 10
DEFAULT = 1  # gmsh's documented default of Mesh.Algorithm3D
# (set, from how many points) on which a path found no result within 30 s
# in one call (experiments.dt3's hard sets): at 500 points HXT returns no
# tetrahedra there, after 0.3 s on subnormal-3d and 8 s on huge-3d
HANGS = {HXT: {"subnormal-3d": 8_000, "huge-3d": 8_000}, DEFAULT: {}}


@contextlib.contextmanager
def _silenced():
    """The process's stdout and stderr to /dev/null for the block; C's
    buffers flushed on the way in and out, so that nothing gmsh writes lands
    after the streams are back."""
    libc = ctypes.CDLL(None)
    sys.stdout.flush()
    sys.stderr.flush()
    libc.fflush(None)
    saved = [os.dup(1), os.dup(2)]
    null = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(null, 1)
        os.dup2(null, 2)
        yield
    finally:
        libc.fflush(None)
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        for fd in saved + [null]:
            os.close(fd)


class GmshTetPeer(PipPeer):
    dim = 3
    family = "gmsh_tetrahedralize"
    module = "gmsh"
    package = "gmsh"
    bytes_per_point = 1500

    def __init__(self, algorithm):
        self.algorithm = algorithm
        self.name = "gmsh-hxt" if algorithm == HXT else "gmsh-default"
        self.options = ("threads",) if algorithm == HXT else ()
        self.threads = 1
        if algorithm != HXT:
            self.inexact = ("gmsh's default 3D path drops tetrahedra along the convex hull, "
                            "even on uniform random points, and returns flat ones on a grid")

    def known_failure(self, distribution, n):
        if n >= HANGS[self.algorithm].get(distribution, float("inf")):
            return f"known hang: no result within 30 s on {distribution} at {n:,} points"
        return None

    def prepare(self, points, order=None, count=False):
        import gmsh
        self.check()
        if not gmsh.isInitialized():
            gmsh.initialize(readConfigFiles=False)
        gmsh.option.setNumber("General.Verbosity", 0)
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("Mesh.Algorithm3D", self.algorithm)
        gmsh.option.setNumber("General.NumThreads", self.threads)
        gmsh.option.setNumber("Mesh.MaxNumThreads3D", self.threads)
        self.flat = np.ascontiguousarray(points, dtype=np.float64).ravel()
        self.out = None

    def run(self):
        import gmsh
        self.out = None
        with _silenced():
            self.out = gmsh.algorithm.tetrahedralize(self.flat)

    def result(self):
        tets, steiner = self.out
        # gmsh's default path returns negatively oriented tetrahedra: verify
        # turns bare simplices around itself (orientation="either")
        return Result(np.asarray(tets, dtype=np.int64).reshape(-1, 4) - 1,
                      extra={"steiner_points": len(steiner) // 3})


PEERS = {"gmsh-hxt": lambda: GmshTetPeer(HXT), "gmsh-default": lambda: GmshTetPeer(DEFAULT)}
