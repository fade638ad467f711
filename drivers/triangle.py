"""Triangle through its PyPI wrapper (``triangle``): the "called from Python"
peer, with its divide and conquer (default), incremental and sweepline."""
from importlib import metadata

import numpy as np

from .base import Peer, Result, Unavailable

INSTALL = "pip install triangle (the project's setup installs it)"


class TrianglePeer(Peer):
    family = "triangle"
    bytes_per_point = 400
    install = INSTALL
    SWITCHES = {"": "triangle", "i": "triangle-incremental", "F": "triangle-sweepline"}

    def __init__(self, switches=""):
        self.switches = switches
        self.name = self.SWITCHES[switches]

    def version(self):
        try:
            return metadata.version("triangle")
        except metadata.PackageNotFoundError:
            return ""

    def check(self):
        try:
            import triangle  # noqa: F401
        except ImportError as e:
            raise Unavailable(f"PyPI package 'triangle' is not installed: {INSTALL}") from e

    def prepare(self, points, order=None, count=False):
        # Triangle's wrapper needs a writable buffer (cached sets are read-only memmaps)
        self.arg = {"vertices": np.array(points, dtype=np.float64, order="C", copy=True)}
        self.out = None

    def run(self):
        import triangle
        self.out = None
        self.out = triangle.triangulate(self.arg, self.switches)

    def result(self):
        return Result(self.out.get("triangles", np.empty((0, 3), int)))


PEERS = {name: (lambda s: lambda: TrianglePeer(s))(s) for s, name in TrianglePeer.SWITCHES.items()}
