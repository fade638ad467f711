"""CGAL through our C++ driver (driver.cpp beside this file, built with
cmake against Debian's libcgal-dev by ``python -m drivers build``).

The driver times itself inside its process (wall clock and TSC cycles,
file I/O excluded) and counts orientation tests, in-circle/in-sphere tests
and conflicting cells only when asked, through wrapped traits and
find_conflicts + insert_in_hole (paper 2's method).
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from lfqt.orders import ORDERS

from ..base import Peer, Result, Unavailable

CGAL_DIR = Path(__file__).resolve().parent
BUILD_DIR = CGAL_DIR / "build"
CGAL_BINARY = Path(os.environ.get("LFQT_CGAL_DRIVER", BUILD_DIR / "cgal_driver"))
APT = "libcgal-dev libgmp-dev libmpfr-dev cmake"
INSTALL = f"as root: apt-get install -y {APT}; then python -m drivers build"


def build():
    """Build the driver (cmake, Release); returns the exit code."""
    BUILD_DIR.mkdir(exist_ok=True)
    try:
        subprocess.run(["cmake", "-S", str(CGAL_DIR), "-B", str(BUILD_DIR),
                        "-DCMAKE_BUILD_TYPE=Release"], check=True, stdout=subprocess.DEVNULL)
        subprocess.run(["cmake", "--build", str(BUILD_DIR), "-j", "2"], check=True)
    except (OSError, subprocess.CalledProcessError) as e:
        print(f"building the CGAL driver failed: {e}\nIt needs Debian's {APT}; {INSTALL}",
              file=sys.stderr)
        return 1
    print(CGAL_BINARY)
    return 0


class CgalPeer(Peer):
    """One operation of the driver: range insertion (dt2, dt3) or insertion
    one point at a time in an order with hints (dt2-order, dt3-order: the
    caller's order, or ``order_name`` built inside the timed run)."""
    family = "cgal"
    install = INSTALL

    def __init__(self, op, order_name=None):
        self.op = op
        self.dim = 2 if op.startswith("dt2") else 3
        self.order_name = order_name  # build this order (lfqt.orders) inside the timed run
        self.name = f"cgal-{op[:3]}-{order_name}" if order_name else f"cgal-{op}"
        self.bytes_per_point = 400 if self.dim == 2 else 1200

    def check(self):
        if not CGAL_BINARY.exists():
            raise Unavailable(f"CGAL driver not built at {CGAL_BINARY}: run 'python -m drivers "
                              f"build' (needs Debian's {APT})")

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
        if r["counted"]:  # in lfqt.predicates.counters' vocabulary
            counts = {"orientation_tests": r["orientation"], "conflicts": r["conflicts"],
                      "incircle_tests": r.get("incircle", r.get("insphere"))}
        return Result(simplices, counts, {"tsc_cycles": r["tsc_cycles"]})


PEERS = {f"cgal-{op}": (lambda op: lambda: CgalPeer(op))(op)
         for op in ("dt2", "dt3", "dt2-order", "dt3-order")}
PEERS.update({f"cgal-{op[:3]}-{o}": (lambda op, o: lambda: CgalPeer(op, o))(op, o)
              for o in ORDERS for op in ("dt2-order", "dt3-order")})
