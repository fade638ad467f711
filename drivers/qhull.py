"""Qhull through ``scipy.spatial.Delaunay``, in 2D and 3D, with its size
caps and its known failure (the experiments read them here)."""
from importlib import metadata

import numpy as np

from .base import Peer, Result

# The largest set each scale measures Qhull on.  It needs 11-14 s per run at
# 1M uniform points, 30-40x lfqt's time, and no target of ours depends on it:
# at 1M it took two thirds of the default bench_dc's 25 minutes.
MAX_N = {"smoke": 100_000, "default": 100_000, "paper": 1_000_000}
# Nearly cocircular points (paper 1's Circle) from this size on take Qhull
# far more than the default scale's 120 s cell limit (measured at 100k).
COCIRCULAR_HANG_N = 100_000


def measured_at(scale, n):
    """Whether the ``scale`` measures Qhull on ``n`` points (MAX_N)."""
    return n <= MAX_N[scale]


def known_failure(distribution, n):
    """Why Qhull is known not to finish ``n`` points of ``distribution``
    within a cell's limit, or None."""
    if distribution == "circle" and n >= COCIRCULAR_HANG_N:
        return ("known hang: Qhull needs far more than 120 s on nearly cocircular points "
                f"({COCIRCULAR_HANG_N:,} and more)")
    return None


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
