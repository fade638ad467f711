"""Every peer: ours (lfqt), CGAL through the C++ driver, Triangle (PyPI
``triangle``) and Qhull (``scipy.spatial.Delaunay``)."""
import json
import os
import shutil
import subprocess
import tempfile
import time
from importlib import metadata
from pathlib import Path

import numpy as np

from .base import Peer, Result, Unavailable

CGAL_DIR = Path(__file__).resolve().parent / "cgal"
CGAL_BINARY = Path(os.environ.get("LFQT_CGAL_DRIVER", CGAL_DIR / "build" / "cgal_driver"))


def _pkg_version(name):
    try:
        return metadata.version(name)
    except metadata.PackageNotFoundError:
        return ""


class LfqtDC(Peer):
    family = "ours"

    def __init__(self, subdivision="lfqt", threads=1):
        self.subdivision = subdivision
        self.threads = threads
        self.name = "lfqt-dc" if subdivision == "lfqt" else f"lfqt-dc-{subdivision}"

    def version(self):
        import lfqt
        return lfqt.__version__

    def prepare(self, points, order=None, count=False):
        import lfqt
        self.points = np.ascontiguousarray(points)
        self.count = count
        self.tri = None
        lfqt.triangulate(self.points[:64], subdivision=self.subdivision)  # JIT warm-up

    def run(self):
        import lfqt
        self.tri = None  # the previous result must not inflate this run's peak memory
        self.tri = lfqt.triangulate(self.points, subdivision=self.subdivision,
                                    threads=self.threads, counters=self.count)

    def result(self):
        st = self.tri.stats
        counts = dict(st.get("counts", {}))
        counts.update({f"seconds_{k}": v for k, v in st["seconds"].items()})
        return Result(self.tri.simplices, counts)


class LfqtInsert(Peer):
    """lfqt.insert in a given order; the order is built inside the timed run,
    as paper 2's times include it."""
    family = "ours"
    dims = (2, 3)

    def __init__(self, order):
        self.order = order
        self.name = f"lfqt-insert-{order}"
        self.dim = 3

    def version(self):
        import lfqt
        return lfqt.__version__

    def prepare(self, points, order=None, count=False):
        import lfqt
        self.points = np.ascontiguousarray(points, dtype=np.float64)
        self.dim = self.points.shape[1]
        self.tri = None
        lfqt.insert(self.points[:64], order=self.order)  # JIT warm-up

    def run(self):
        import lfqt
        self.tri = None
        self.tri = lfqt.insert(self.points, order=self.order, counters=True)

    def result(self):
        st = self.tri.stats
        counts = dict(st["counts"])
        counts.update({f"seconds_{k}": v for k, v in st["seconds"].items()})
        return Result(self.tri.simplices, counts)


class TrianglePeer(Peer):
    family = "triangle"
    SWITCHES = {"": "triangle", "i": "triangle-incremental", "F": "triangle-sweepline"}

    def __init__(self, switches=""):
        self.switches = switches
        self.name = self.SWITCHES[switches]

    def version(self):
        return _pkg_version("triangle")

    def check(self):
        try:
            import triangle  # noqa: F401
        except ImportError as e:
            raise Unavailable("PyPI package 'triangle' is not installed") from e

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


class QhullPeer(Peer):
    family = "qhull"

    def __init__(self, dim):
        self.dim = dim
        self.name = f"qhull-{dim}d"

    def version(self):
        return "scipy " + _pkg_version("scipy")

    def prepare(self, points, order=None, count=False):
        self.points = np.ascontiguousarray(points, dtype=np.float64)
        self.out = None

    def run(self):
        import scipy.spatial
        self.out = None
        self.out = scipy.spatial.Delaunay(self.points)

    def result(self):
        return Result(self.out.simplices)


class CgalPeer(Peer):
    """CGAL through drivers/cgal (built by ``python -m drivers build``)."""
    family = "cgal"

    def __init__(self, op, order_name=None):
        self.op = op
        self.dim = 2 if op.startswith("dt2") else 3
        self.order_name = order_name  # build this order (lfqt.orders) inside the timed run
        self.name = f"cgal-{op[:3]}-{order_name}" if order_name else f"cgal-{op}"

    def check(self):
        if not CGAL_BINARY.exists():
            raise Unavailable(f"CGAL driver not built at {CGAL_BINARY}: run 'python -m drivers build' "
                              "(needs Debian's libcgal-dev, libgmp-dev, libmpfr-dev and cmake)")

    def version(self):
        return "CGAL " + getattr(self, "_version", "")

    def prepare(self, points, order=None, count=False):
        self.check()
        self.tmp = tempfile.mkdtemp(prefix="lfqt-cgal-")
        self.points_path = os.path.join(self.tmp, "points.npy")
        np.save(self.points_path, np.ascontiguousarray(points, dtype=np.float64))
        self.args = [str(CGAL_BINARY), self.op, self.points_path]
        self.points = points
        self.order_seconds = 0.0
        if self.op.endswith("-order"):
            if order is None and self.order_name is None:
                raise ValueError(f"{self.name} needs an insertion order")
            self.order_path = os.path.join(self.tmp, "order.npy")
            if order is not None:
                self._write_order(order)
            self.args += ["--order", self.order_path]
        if count:
            self.args.append("--count")
        self.out_path = os.path.join(self.tmp, "simplices.npy")
        self.args += ["--out", self.out_path]

    def _write_order(self, order):
        perm, hint = order
        np.save(self.order_path, np.stack((perm, hint), axis=1).astype(np.int64))

    def run(self):
        if self.order_name:
            from lfqt import orders
            t0 = time.perf_counter()
            built = orders.order(self.points, self.order_name)
            self.order_seconds = time.perf_counter() - t0
            self._write_order(built)
        proc = subprocess.run(self.args, capture_output=True, text=True)
        if proc.returncode != 0:
            raise RuntimeError(f"cgal_driver failed ({proc.returncode}): {proc.stderr.strip()}")
        self.report = json.loads(proc.stdout.strip().splitlines()[-1])
        self._version = self.report.get("cgal_version", "")

    def self_timing(self):
        """Driver's in-process time, plus building the order when we build it
        (paper 2 includes that); cycles are the driver's alone."""
        return self.report["seconds"] + self.order_seconds, self.report["tsc_cycles"]

    def self_memory(self):
        """Peak resident bytes of the driver above its state after loading."""
        return max(self.report["peak_rss_bytes"] - self.report["baseline_rss_bytes"], 0)

    def result(self):
        simplices = np.load(self.out_path)
        shutil.rmtree(self.tmp, ignore_errors=True)
        r = self.report
        counts = {}
        if r["counted"]:
            counts = {"orientation": r["orientation"], "conflicts": r["conflicts"],
                      "incircle" if self.dim == 2 else "insphere": r.get("incircle", r.get("insphere"))}
        return Result(simplices, counts, {"tsc_cycles": r["tsc_cycles"]})
