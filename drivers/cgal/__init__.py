"""CGAL through our C++ driver (driver.cpp beside this file, built with
cmake against Debian's libcgal-dev by ``python -m drivers build``).

The driver times itself inside its process (wall clock and TSC cycles,
file I/O excluded) and counts orientation tests, in-circle/in-sphere tests
and conflicting cells only when asked, through wrapped traits and
find_conflicts + insert_in_hole (paper 2's method).
"""
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from lfqt.orders import ORDERS

from ..base import CompiledPeer

CGAL_DIR = Path(__file__).resolve().parent
BUILD_DIR = CGAL_DIR / "build"
CGAL_BINARY = Path(os.environ.get("LFQT_CGAL_DRIVER", BUILD_DIR / "cgal_driver"))
TBB_BINARY = CGAL_BINARY.parent / "cgal_driver_tbb"
APT = "libcgal-dev libgmp-dev libmpfr-dev cmake"
INSTALL = f"as root: apt-get install -y {APT}; then python -m drivers build"


def build():
    """Build the drivers (cmake, Release) and record what they were built
    with in build/build_info.json; returns the exit code."""
    BUILD_DIR.mkdir(exist_ok=True)
    try:
        subprocess.run(["cmake", "-S", str(CGAL_DIR), "-B", str(BUILD_DIR),
                        "-DCMAKE_BUILD_TYPE=Release"], check=True, stdout=subprocess.DEVNULL)
        subprocess.run(["cmake", "--build", str(BUILD_DIR), "-j", "2"], check=True)
        with tempfile.TemporaryDirectory() as tmp:
            probe = os.path.join(tmp, "probe.npy")
            np.save(probe, np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]))
            out = subprocess.run([str(CGAL_BINARY), "dt2", probe], check=True,
                                 capture_output=True, text=True).stdout
        report = json.loads(out.strip().splitlines()[-1])
        info = {"library": "CGAL", "version": "CGAL " + report["cgal_version"],
                "compiler": report["compiler"], "flags": report["flags"],
                "parallel": TBB_BINARY.exists()}
        (BUILD_DIR / "build_info.json").write_text(json.dumps(info, indent=2))
    except (OSError, subprocess.CalledProcessError) as e:
        print(f"building the CGAL driver failed: {e}\nIt needs Debian's {APT}; {INSTALL}",
              file=sys.stderr)
        return 1
    print(CGAL_BINARY)
    return 0


class CgalPeer(CompiledPeer):
    """One operation of the driver (driver.cpp): plain range insertion (dt2,
    dt3: CGAL at its fastest), range insertion with vertex info (dt2-indexed,
    dt3-indexed), parallel 3D range insertion (dt3-parallel, TBB), or
    insertion one point at a time in an order with hints (dt2-order,
    dt3-order: the caller's order, or ``order_name`` built inside the timed
    run, as paper 2 includes it), or in the order of CGAL's own hilbert_sort
    or spatial_sort with the previous vertex as hint (dt3-hilbert-sort,
    dt3-spatial-sort: what paper 2's "Hilbert" and "BRIO" may have been)."""
    family = "cgal"
    install = INSTALL

    def __init__(self, op, order_name=None):
        self.op = op
        self.dim = 2 if op.startswith("dt2") else 3
        self.order_name = order_name
        self.name = f"cgal-{op[:3]}-{order_name}" if order_name else f"cgal-{op}"
        self.bytes_per_point = 400 if self.dim == 2 else 1200
        self.binary = TBB_BINARY if op == "dt3-parallel" else CGAL_BINARY
        self.options = ("threads",) if op == "dt3-parallel" else ()
        self.threads = 1

    def arguments(self, points_path, count):
        args = [self.op, points_path, "--threads", str(self.threads)]
        if self.op.endswith("-order"):
            if self._order is None and self.order_name is None:
                raise ValueError(f"{self.name} needs an insertion order")
            self.order_path = os.path.join(self.tmp, "order.npy")
            if self._order is not None:
                self._write_order(self._order)
            args += ["--order", self.order_path]
        return args + (["--count"] if count else [])

    def prepare(self, points, order=None, count=False):
        self._order = order
        self.points = points
        super().prepare(points, order, count)

    def _write_order(self, order):
        perm, hint = order
        np.save(self.order_path, np.stack((perm, hint), axis=1).astype(np.int64))

    def run(self):
        if self.order_name:
            from lfqt import orders
            t0 = time.perf_counter()
            built = orders.order(self.points, self.order_name)
            self.extra_seconds = time.perf_counter() - t0
            self._write_order(built)
        super().run()

    def counts(self, r):
        if not r["counted"]:
            return {}
        return {"orientation_tests": r["orientation"], "conflicts": r["conflicts"],
                "incircle_tests": r.get("incircle", r.get("insphere"))}


PEERS = {f"cgal-{op}": (lambda op: lambda: CgalPeer(op))(op)
         for op in ("dt2", "dt3", "dt2-indexed", "dt3-indexed", "dt3-parallel", "dt2-order",
                    "dt3-order", "dt3-hilbert-sort", "dt3-spatial-sort")}
PEERS.update({f"cgal-{op[:3]}-{o}": (lambda op, o: lambda: CgalPeer(op, o))(op, o)
              for o in ORDERS for op in ("dt2-order", "dt3-order")})
