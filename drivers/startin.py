"""startinpy (Hugo Ledoux's Rust library for terrains, PyPI ``startinpy``):
a 2.5D triangulation, so each point gets z = 0.

Its snap tolerance (two points closer than it in xy are merged; 1e-3 by
default, which merges distinct points of a unit square) cannot be 0 (the
setter ignores 0); we set the smallest positive double, 5e-324, so only
equal points merge.  startinpy inserts one point at a time and walks to
each point from the last triangle it made, so a spatially coherent order
keeps the walks short (its docs: insert in the order the points come, or
``insertionstrategy="BBox"``, the bounding box's corners first, for
rasters; a LAS file is coherent already): the driver sorts the points in
Morton (Z-curve) order inside the timed run, then inserts them with "BBox".
A user with unsorted points must do the same; in the order given, 1M
uniform points did not finish within minutes.  Its vertices are mapped back
to input rows by their coordinates, after the timed run."""
import numpy as np

from .base import PipPeer, Result
from .matching import rows_of

SNAP = 5e-324


def morton_order(points):
    """The Z-curve order of ``points`` (n, 2) on a 2^21 x 2^21 grid over
    their bounding box."""
    p = np.asarray(points, dtype=np.float64)
    lo, hi = p.min(axis=0), p.max(axis=0)
    span = np.where(hi > lo, hi - lo, 1.0)
    q = ((p - lo) / span * (2 ** 21 - 1)).astype(np.uint64)
    return np.argsort(_spread(q[:, 0]) | (_spread(q[:, 1]) << np.uint64(1)), kind="stable")


def _spread(v):
    """The 21 low bits of ``v`` moved to the even bit positions."""
    v = v & np.uint64(0x1FFFFF)
    for shift, mask in ((16, 0x0000FFFF0000FFFF), (8, 0x00FF00FF00FF00FF),
                        (4, 0x0F0F0F0F0F0F0F0F), (2, 0x3333333333333333),
                        (1, 0x5555555555555555)):
        v = (v | (v << np.uint64(shift))) & np.uint64(mask)
    return v


class StartinPeer(PipPeer):
    name = "startinpy"
    family = "startin"
    module = "startinpy"
    package = "startinpy"
    bytes_per_point = 600

    def prepare(self, points, order=None, count=False):
        p = np.asarray(points, dtype=np.float64)
        self.points = p
        self.xyz = np.column_stack((p[:, :2], np.zeros(len(p))))
        self.dt = None

    def run(self):
        import startinpy
        self.dt = None
        dt = startinpy.DT()
        dt.snap_tolerance = SNAP
        dt.insert(self.xyz[morton_order(self.xyz[:, :2])], insertionstrategy="BBox")
        self.dt = dt

    def result(self):
        tri = np.asarray(self.dt.triangles, dtype=np.int64).reshape(-1, 3)
        coords = np.asarray(self.dt.points, dtype=np.float64)
        rows = rows_of(self.points, coords[:, :2])
        return Result(rows[tri] if len(tri) else tri, extra={"snap_tolerance":
                                                             self.dt.snap_tolerance})


def known_failure(distribution, n):
    """Why startinpy is known not to finish ``n`` points of ``distribution``
    within a cell's limit, or None: on paper 1's Circle
    from 100k points (nearly cocircular) it found no result within 120 s."""
    if distribution == "circle" and n >= 100_000:
        return "known hang: no result within 120 s at the default scale"
    return None


PEERS = {"startinpy": StartinPeer}
