"""Our peers: lfqt's divide and conquer (and its alternating-cuts ablation),
lfqt's incremental insertion in every order of lfqt.orders, lfqt's scipy
drop-in ``lfqt.Delaunay``, and lfqt's radix sort alone (paper 1's sort
claim)."""
import time

import numpy as np

import lfqt
import lfqt.clock
from lfqt.orders import ORDERS

from .base import Peer, Result

# the hybrid method's leaf sizes as peers (experiments.hybrid sweeps them)
LEAF_SIZES = [16, 64, 256, 1024, 4096, 16384, 65536, 262144, 1048576]
# points of the divide and conquer's warm-up: past lfqt.radix.MSD_LEAF, so that
# every kernel of a large call is compiled or loaded before the memory
# baseline, not counted in the first run's peak
WARMUP_POINTS = 1 << 17


def _warmed(peer, build):
    """Run ``build()`` (a warm-up call), then unmap what it left idle in
    lfqt.workspace, so that the baseline the runs are measured from holds
    none of it: the first run maps its memory afresh, inside its peak.
    Nothing at all for a cold peer (the fresh regime: the timed run is the
    process's first call)."""
    if peer.cold:
        return
    build()
    lfqt.workspace.release()


def _build_info():
    import numba
    return {"library": "lfqt", "version": f"lfqt {lfqt.__version__}",
            "compiler": f"numba {numba.__version__} (LLVM)",
            "flags": "compiled for the host CPU (numba's default target, no fastmath)"}


class _Ours(Peer):
    """What every peer of ours shares: the family, lfqt's version and the
    numba build that compiled it."""
    family = "ours"

    def keep(self):
        """The whole Triangulation, as a user holds it, not only its simplices."""
        if not hasattr(self, "tri"):
            return super().keep()
        self.kept = getattr(self, "kept", []) + [self.tri]

    def version(self):
        return lfqt.__version__

    def build_info(self):
        return _build_info()


def _result(tri):
    counts = dict(tri.stats.get("counts", {}))
    counts.update({f"seconds_{k}": v for k, v in tri.stats["seconds"].items()})
    # paper 1's Fig. 5 phases (thread-seconds in the bins, wall time in the top)
    counts.update({f"phase_{k}": v for k, v in tri.stats.get("phases", {}).items()})
    return Result(tri.simplices, counts)


class LfqtDC(_Ours):
    options = ("threads",)
    # the whole process's peak per point, with a margin: 133-137 B measured at 5M
    # (uniform on 2 threads, grid and cluster on 1), 106 B at 20M; so that 1e8
    # points (fig4's paper scale) run on a 24 GB machine
    bytes_per_point = 160

    def __init__(self, subdivision="lfqt", filter="level", leaf_size=None):
        self.subdivision = subdivision
        self.filter = filter  # the stage-1 bound: the LFQT's level bound or Triangle's constant
        self.threads = 1
        # leaf_size: the hybrid method (insertion in the LFQT's cells, paper 1's open question)
        self.method = "hybrid" if leaf_size else "dc"
        self.leaf_size = leaf_size
        self.name = "lfqt-dc" if subdivision == "lfqt" else f"lfqt-dc-{subdivision}"
        if filter != "level":
            self.name += f"-{filter}"
        if leaf_size:
            self.name = f"lfqt-hybrid-{leaf_size}"

    def prepare(self, points, order=None, count=False):
        # counts come with every run: the kernels count anyway (free)
        self.points = np.ascontiguousarray(points)
        self.tri = None
        _warmed(self, lambda: lfqt.triangulate(self.points[:WARMUP_POINTS], threads=self.threads,
                                         subdivision=self.subdivision, **self._method()))

    def _method(self):
        return dict(method="hybrid", leaf_size=self.leaf_size) if self.leaf_size else {}

    def run(self):
        self.tri = None  # the previous result must not inflate this run's peak memory
        self.tri = lfqt.triangulate(self.points, subdivision=self.subdivision,
                                    threads=self.threads, filter=self.filter, **self._method())

    def result(self):
        return _result(self.tri)


class _Inserting(_Ours):
    """A peer of ours built on lfqt.insert, on threads in 3D (2D ignores
    them)."""
    dims = (2, 3)
    bytes_per_point = 1200
    options = ("threads",)

    def _take(self, points):
        """Hold the points as float64 rows; their dimension is the peer's."""
        self.points = np.ascontiguousarray(points, dtype=np.float64)
        self.dim = self.points.shape[1]
        self.tri = None

    def _warm_points(self, points):
        """The warm-up's points: on threads, past the points inserted alone,
        so that the lanes' kernels are loaded too."""
        if self.threads == 1:
            return points[:64]
        return points[:2 * lfqt.incremental.tetra.SEQUENTIAL]


class LfqtInsert(_Inserting):
    """lfqt.insert in a given order; the order is built inside the timed run,
    as paper 2's times include it."""

    def __init__(self, order):
        self.order = order
        self.name = f"lfqt-insert-{order}"
        self.dim = 3
        self.threads = 1

    def prepare(self, points, order=None, count=False):
        self._take(points)
        warm = self._warm_points(self.points)
        _warmed(self, lambda: lfqt.insert(warm, order=self.order, threads=self.threads))

    def run(self):
        self.tri = None
        self.tri = lfqt.insert(self.points, order=self.order, threads=self.threads)

    def result(self):
        return _result(self.tri)


class LfqtDelaunay(_Inserting):
    """``lfqt.Delaunay``, the scipy drop-in, as a scipy user calls it (in 3D
    it runs lfqt.insert in Kd order)."""

    def __init__(self):
        self.name = "lfqt-delaunay"
        self.dim = 3
        self.threads = 1

    def prepare(self, points, order=None, count=False):
        self._take(points)
        # on points of its own: the input's first rows may be coplanar (a sorted
        # grid's are), where Delaunay raises and insert returns a flagged mesh
        rows = len(self._warm_points(self.points))
        warm = np.random.default_rng(0).random((rows, self.dim))
        _warmed(self, lambda: lfqt.Delaunay(warm, threads=self.threads))

    def run(self):
        self.tri = None
        self.tri = lfqt.Delaunay(self.points, threads=self.threads)

    def result(self):
        return _result(self.tri.triangulation)


class LfqtRadixSort(_Ours):
    """lfqt's radix sort (fqDel 3.1) on the points' x values as float32: the
    operation of paper 1's claim "1M floats sorted in 0.89 ms".  Each run
    sorts a fresh copy of the order-preserving keys; the peer times the sort
    alone, without the copy."""
    options = ("threads",)
    bytes_per_point = 64
    triangulates = False

    def __init__(self):
        self.name = "lfqt-radix"
        self.threads = 1

    def prepare(self, points, order=None, count=False):
        from lfqt.radix import sort_keys
        from lfqt.workers import Workers
        from lfqt.morton import ordered_bits
        x = np.ascontiguousarray(points[:, 0], dtype=np.float32)
        self.keys = ordered_bits(x).astype(np.uint64)
        self.sort = sort_keys
        self.workers = Workers(self.threads)
        _warmed(self, lambda: self.sort(self.keys[:64].copy(), np.arange(64, dtype=np.int32),
                                        self.workers))

    def run(self):
        keys, perm = self.keys.copy(), np.arange(len(self.keys), dtype=np.int32)
        c0, t0 = lfqt.clock.read_cycles(), time.perf_counter()
        self.sorted, _ = self.sort(keys, perm, self.workers)
        self.timing = (time.perf_counter() - t0, lfqt.clock.read_cycles() - c0)

    def self_timing(self):
        return self.timing

    def result(self):
        ok = bool(np.all(self.sorted[1:] >= self.sorted[:-1]))
        return Result(None, {"sorted": int(ok), "values": len(self.keys)})


class LfqtOrder(_Ours):
    """Building one insertion order of lfqt.orders alone (paper 2, Table 15:
    sequence building time)."""
    dims = (2, 3)
    bytes_per_point = 200
    triangulates = False

    def __init__(self, order):
        self.order = order
        self.name = f"lfqt-order-{order}"
        self.dim = 3

    def prepare(self, points, order=None, count=False):
        from lfqt import orders
        self.points = np.ascontiguousarray(points, dtype=np.float64)
        self.build = orders.order
        _warmed(self, lambda: self.build(self.points[:64], self.order))  # JIT warm-up

    def run(self):
        self.perm = None
        self.perm, _ = self.build(self.points, self.order)

    def result(self):
        ok = np.array_equal(np.sort(self.perm), np.arange(len(self.points)))
        return Result(None, {"permutation": int(ok)})


PEERS = {"lfqt-dc": lambda: LfqtDC("lfqt"),
         "lfqt-dc-constant": lambda: LfqtDC("lfqt", "constant"),
         "lfqt-dc-alternating": lambda: LfqtDC("alternating")}
PEERS.update({f"lfqt-hybrid-{k}": (lambda k: lambda: LfqtDC(leaf_size=k))(k) for k in LEAF_SIZES})
PEERS["lfqt-radix"] = LfqtRadixSort
PEERS.update({f"lfqt-order-{o}": (lambda o: lambda: LfqtOrder(o))(o) for o in ORDERS})
PEERS.update({f"lfqt-insert-{o}": (lambda o: lambda: LfqtInsert(o))(o) for o in ORDERS})
PEERS["lfqt-delaunay"] = LfqtDelaunay
