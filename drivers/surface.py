"""The whole scipy.spatial.Delaunay surface, one library per peer: lfqt's
drop-in (``lfqt.Delaunay``, ``lfqt.interpolate``) and scipy's own.

One run performs every operation a user calls after ``import``, in the
order of OPERATIONS, on the same points and the same queries for both
libraries, and times each one apart (``counts["seconds_<op>"]``, one value
per run); the run's own time is their sum.  Every operation after the
first works on the mesh that the first (construct) built in the same run,
as a program would.  In
the fresh regime (drivers.isolate.REGIMES) each operation is then the
first call of its kind in a new process, kernels loaded included.

A cached attribute (transform, equations, vertex_neighbor_vertices) is
dropped before it is timed, so that every run measures its computation, as
on a mesh a user has just built.  scipy computes ``equations`` with the mesh
(Qhull's facet planes), so its access costs nothing; lfqt computes it on
first access, which the construction's time does not include.
"""
from importlib import metadata

import numpy as np

from .base import Peer, Result

# Queries, uniform in the points' bounding box, at most QUERIES_PER_POINT per
# point (small sets stay quick).  RANDOM in random order: the ratio against
# scipy (which walks from where its previous query ended, so that random
# order is its slow case, about 0.14 ms a query on a 1M mesh: that is why the
# count is small).  SORTED along a Hilbert curve, the order a caller who sorts
# gets.  MANY in random order, lfqt alone: issue 51's targets (1M queries on a
# 1M-point 2D mesh in 0.3 s, on a 300k 3D mesh in 1 s).
RANDOM, SORTED, MANY = 10_000, 1_000_000, 1_000_000
QUERIES_PER_POINT = 100
# plane_distance returns a (queries, simplices) array: a few queries only
PLANE_QUERIES = 10
# what the interpolators evaluate at: a grid over the box, row by row, as
# griddata's users pass, of at most GRID_POINTS points
GRID_POINTS = 1_000_000
# add_points adds this many points (at most half) to a mesh of the rest, as a
# program adds a batch: scipy's incremental Qhull took 28 s for 50k at 100k
ADDED = 10_000

OPERATIONS = ("construct", "find_simplex_random", "find_simplex_sorted", "find_simplex_many",
              "vertex_neighbor_vertices", "convex_hull", "transform", "equations",
              "lift_points", "plane_distance", "add_points", "linear", "cubic", "nearest",
              "natural")
# what scipy does not have, or what would take it minutes
NOT_SCIPY = {"find_simplex_many": "random order at 1M queries takes scipy minutes",
             "natural": "scipy has no natural-neighbour interpolation"}


def queries(points, count, seed):
    """``count`` uniform points in the bounding box of ``points``."""
    lo, hi = points.min(axis=0), points.max(axis=0)
    return lo + (hi - lo) * np.random.default_rng(seed).random((count, points.shape[1]))


def grid_queries(points):
    n, d = points.shape
    side = int(round(min(GRID_POINTS, QUERIES_PER_POINT * n) ** (1.0 / d)))
    lo, hi = points.min(axis=0), points.max(axis=0)
    axes = [np.linspace(a, b, side) for a, b in zip(lo, hi)]
    return np.stack([g.ravel() for g in np.meshgrid(*axes, indexing="ij")], axis=1)


def hilbert_sorted(q):
    """``q`` along a Hilbert curve (lfqt.orders; untimed, in prepare)."""
    from lfqt.orders import order
    return np.ascontiguousarray(q[order(q, "hilbert")[0]])


class Surface(Peer):
    family = "surface"
    triangulates = False
    bytes_per_point = 3000
    dims_ = (2, 3)

    @property
    def dims(self):
        return self.dims_

    def __init__(self, library):
        self.library = library
        self.name = f"surface-{library}"
        self.options = ("threads",) if library == "lfqt" else ()
        self.threads = 1

    def version(self):
        return (f"lfqt {metadata.version('lfqt')}" if self.library == "lfqt"
                else f"scipy {metadata.version('scipy')}")

    def operations(self):
        return [op for op in OPERATIONS if self.library == "lfqt" or op not in NOT_SCIPY]

    def prepare(self, points, order=None, count=False):
        self.points = np.ascontiguousarray(points, dtype=np.float64)
        n, d = self.points.shape
        most = QUERIES_PER_POINT * n
        self.random = queries(self.points, min(RANDOM, n), 1)
        self.sorted = hilbert_sorted(queries(self.points, min(SORTED, most), 2))
        self.many = queries(self.points, min(MANY, most), 3)
        self.plane = queries(self.points, PLANE_QUERIES, 4)
        self.grid = grid_queries(self.points)
        x = self.points
        self.values = np.sin(3 * x[:, 0]) + x[:, 1] ** 2 + (x[:, 2] if d == 3 else 0)
        self.half = n - min(n // 2, ADDED)
        self.times = {op: [] for op in self.operations()}
        self.mesh = None
        if self.library == "scipy":
            # scipy's fastest setting here: with more BLAS threads, its
            # per-simplex LAPACK calls stall when the machine is loaded
            from threadpoolctl import threadpool_limits
            self.blas = threadpool_limits(1)
        # nothing is built or warmed here: the run's first operation builds
        # the mesh the others use, so in the fresh regime it is the first call

    # -- the libraries -------------------------------------------------------

    def _delaunay(self, points, incremental=False):
        if self.library == "lfqt":
            import lfqt
            return lfqt.Delaunay(points, incremental=incremental, threads=self.threads)
        import scipy.spatial
        return scipy.spatial.Delaunay(points, incremental=incremental)

    def _interpolate(self):
        if self.library == "lfqt":
            import lfqt.interpolate
            return lfqt.interpolate
        import scipy.interpolate
        return scipy.interpolate

    def _forget(self, mesh, name):
        """Drop a cached attribute, so that the next access computes it."""
        if self.library == "lfqt":
            mesh._cache.pop(name, None)
        elif hasattr(mesh, f"_{name}"):
            setattr(mesh, f"_{name}", None)

    def _operation(self, op):
        """A callable that performs ``op`` (its set-up done, untimed)."""
        m, interp = self.mesh, None
        if op in ("linear", "cubic", "nearest", "natural"):
            interp = self._interpolate()
        if op in ("vertex_neighbor_vertices", "transform", "equations", "convex_hull"):
            self._forget(m, op)
        if op == "add_points":
            inc = self._delaunay(self.points[:self.half], incremental=True)
            return lambda: inc.add_points(self.points[self.half:])
        fields = {
            "construct": lambda: self._delaunay(self.points),
            "find_simplex_random": lambda: m.find_simplex(self.random),
            "find_simplex_sorted": lambda: m.find_simplex(self.sorted),
            "find_simplex_many": lambda: m.find_simplex(self.many),
            "vertex_neighbor_vertices": lambda: m.vertex_neighbor_vertices,
            "convex_hull": lambda: m.convex_hull,
            "transform": lambda: m.transform,
            "equations": lambda: m.equations,
            "lift_points": lambda: m.lift_points(self.sorted),
            "plane_distance": lambda: m.plane_distance(self.plane),
            "linear": lambda: interp.LinearNDInterpolator(m, self.values)(self.grid),
            "nearest": lambda: interp.NearestNDInterpolator(self.points, self.values)(self.grid),
            "natural": lambda: interp.NaturalNeighborInterpolator(m, self.values)(self.grid),
        }
        if op == "cubic":
            if self.points.shape[1] != 2:
                return None  # CloughTocher is 2D only, in scipy and here
            return lambda: interp.CloughTocher2DInterpolator(m, self.values)(self.grid)
        return fields[op]

    # -- the timed run ---------------------------------------------------------

    def run(self):
        """Every operation in turn; each output is held until the run ends,
        as a program holds what it computed, then dropped (the loop regime).
        The warm-up run is timed too: the experiment keeps each process's
        last ``repeats`` values."""
        import time
        outputs = []
        for op in self.operations():
            call = self._operation(op)
            if call is None:
                continue
            t0 = time.perf_counter()
            outputs.append(call())
            self.times[op].append(time.perf_counter() - t0)
            if op == "construct":
                self.mesh = outputs[-1]

    def self_timing(self):
        total = sum(t[-1] for t in self.times.values() if t)
        return total, None

    def result(self):
        return Result(None, {f"seconds_{op}": t for op, t in self.times.items() if t})


PEERS = {"surface-lfqt": lambda: Surface("lfqt"), "surface-scipy": lambda: Surface("scipy")}
