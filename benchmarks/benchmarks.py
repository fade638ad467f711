"""asv benchmarks.  Quick check against the installed package:

    asv run --python=same --quick

Every class warms numba up in ``setup`` (compile time is measured on its own
by TimeCompile), so the timings are of compiled code."""
import os
import subprocess
import sys
import tempfile

import numpy as np

import generators
import lfqt
from lfqt import morton, radix
from lfqt.workers import Workers


class TimeTriangulate:
    params = (["uniform", "grid", "cluster"], [10_000, 100_000, 1_000_000])
    param_names = ["distribution", "n"]
    timeout = 300

    def setup(self, dist, n):
        self.points = np.array(generators.make(dist, n))
        lfqt.triangulate(self.points[:1000])

    def time_triangulate(self, dist, n):
        lfqt.triangulate(self.points)

    def time_triangulate_alternating(self, dist, n):
        lfqt.triangulate(self.points, subdivision="alternating")

    def peakmem_triangulate(self, dist, n):
        lfqt.triangulate(self.points)

    def track_incircle_calls_per_point(self, dist, n):
        return lfqt.triangulate(self.points).stats["per_point"]["incircle_tests"]
    track_incircle_calls_per_point.unit = "count"

    def track_undecided_incircle(self, dist, n):
        return lfqt.triangulate(self.points).stats["counts"]["incircle_stage1_undecided"]
    track_undecided_incircle.unit = "count"


class TimeInsert:
    params = (["kdtree", "hilbert", "brio"], ["cube", "axes"])
    param_names = ["order", "distribution"]
    timeout = 300

    def setup(self, order, dist):
        self.points = np.array(generators.make(dist, 50_000))
        lfqt.insert(self.points[:500], order=order)

    def time_insert(self, order, dist):
        lfqt.insert(self.points, order=order)

    def peakmem_insert(self, order, dist):
        lfqt.insert(self.points, order=order)

    def track_orientation_tests_per_point(self, order, dist):
        return lfqt.insert(self.points, order=order).stats["per_point"]["orientation_tests"]
    track_orientation_tests_per_point.unit = "count"

    def track_conflicts_per_point(self, order, dist):
        return lfqt.insert(self.points, order=order).stats["per_point"]["conflicts"]
    track_conflicts_per_point.unit = "count"


class TimeRadix:
    params = [100_000, 1_000_000]
    param_names = ["n"]

    def setup(self, n):
        rng = np.random.default_rng(0)
        x, y = rng.random(n), rng.random(n)
        self.hi, self.lo = morton.morton_keys64(x, y)
        self.workers = Workers(1)
        radix.sort_keys(self.hi[:100].copy(), np.arange(100, dtype=np.int32), self.workers)

    def time_radix_sort_128bit_high_word(self, n):
        radix.sort_keys(self.hi.copy(), np.arange(n, dtype=np.int32), self.workers)


class TimeCompile:
    """First call in a fresh interpreter with an empty numba cache."""
    timeout = 600
    number = 1
    repeat = 1

    def time_first_call_cold_cache(self):
        with tempfile.TemporaryDirectory() as cache:
            subprocess.run([sys.executable, "-c",
                            "import numpy as np, lfqt; "
                            "lfqt.triangulate(np.random.default_rng(0).random((100, 2)))"],
                           env=dict(os.environ, NUMBA_CACHE_DIR=cache), check=True)
