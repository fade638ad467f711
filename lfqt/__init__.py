"""lfqt: exact Delaunay triangulation on the linear floating-point quad-tree.

    triangulate   2D divide and conquer on the LFQT (lfqt.dc)
    insert        2D/3D incremental insertion in a given order (lfqt.incremental)
    verify        exact proof that a mesh is the Delaunay triangulation (lfqt.verification)
    Delaunay      the scipy.spatial.Delaunay interface (lfqt.delaunay)
    quadtree      the LFQT of a point set as a table (lfqt.dc.quadtree)
    distributed   Tile & Merge on Dask for sets beyond one machine (lfqt.distributed)
    interpolate   scipy.interpolate's scattered-data interpolators over lfqt.Delaunay
    workspace     scratch memory kept for the next call; workspace.release() frees it now
    preload       the first call's kernels, loaded in a thread from the import on
"""
from . import jit_cache  # noqa: F401  (first: before any kernel is defined)
from . import distributed, interpolate, preload, workspace
from .dc import triangulate
from .dc.quadtree import quadtree
from .delaunay import Delaunay
from .incremental import insert
from .triangulation import DegenerateInputError, Triangulation
from .verification import VerifyReport, verify

__all__ = ["triangulate", "insert", "Delaunay", "DegenerateInputError", "verify", "Triangulation",
           "VerifyReport", "quadtree", "distributed", "interpolate", "workspace"]
__version__ = "0.1.0"

preload.start()  # last: the thread imports nothing that is not imported by now
