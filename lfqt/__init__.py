"""lfqt: exact Delaunay triangulation on the linear floating-point quad-tree."""
from .api import Delaunay, DegenerateInputError, insert, triangulate
from .mesh import Triangulation, VerifyReport, verify

__all__ = ["triangulate", "insert", "Delaunay", "DegenerateInputError", "verify", "Triangulation",
           "VerifyReport"]
__version__ = "0.1.0"
