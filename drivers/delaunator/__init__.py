"""Delaunator (mapbox's JavaScript library, npm ``delaunator``) run by Node.

``python -m drivers build`` installs it from npm into ``node_modules/``
beside this file (package.json pins the version; setup installs Debian's
``nodejs`` and ``npm``).  Each run is one Node process of our runner,
``runner.mjs``: it reads the points as raw float64, warms up once on them,
times ``new Delaunator(coords)`` with Node's own clock (performance.now(),
file I/O outside) and writes the triangles back as uint32.  Delaunator's
predicates are robust-predicates' adaptive orientation, but its in-circle
test is plain floating point: its meshes can be wrong on cocircular input,
which the field experiment measures.
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from ..base import Peer, Result, Unavailable, run_reporting

HERE = Path(__file__).resolve().parent
RUNNER = HERE / "runner.mjs"
MODULE = HERE / "node_modules" / "delaunator" / "package.json"
INSTALL = ("as root: apt-get install -y nodejs npm; then python -m drivers build "
           "(npm install --prefix drivers/delaunator)")


def node():
    """The Node executable, or None."""
    return shutil.which("node") or shutil.which("nodejs")


def build():
    """npm install of the pinned Delaunator into node_modules/; returns the
    exit code (0 with a note when npm is missing: the peer is then listed as
    unavailable with the reason)."""
    npm = shutil.which("npm")
    if npm is None:
        print(f"Delaunator not installed: no npm here; {INSTALL}", file=sys.stderr)
        return 0
    proc = subprocess.run([npm, "install", "--no-audit", "--no-fund", "--prefix", str(HERE)],
                          capture_output=True, text=True)
    if proc.returncode != 0:
        print(f"npm install of delaunator failed: {proc.stderr.strip()}", file=sys.stderr)
    return proc.returncode


class DelaunatorPeer(Peer):
    name = "delaunator"
    family = "delaunator"
    bytes_per_point = 250
    install = INSTALL

    def check(self):
        if node() is None:
            raise Unavailable(f"delaunator: no Node.js here: {INSTALL}")
        if not MODULE.exists():
            raise Unavailable(f"delaunator: not installed at {MODULE.parent}: {INSTALL}")

    def version(self):
        try:
            return "delaunator " + json.loads(MODULE.read_text())["version"]
        except (OSError, ValueError, KeyError):
            return ""

    def prepare(self, points, order=None, count=False):
        self.check()
        self.tmp = tempfile.mkdtemp(prefix="lfqt-delaunator-")
        points_path = os.path.join(self.tmp, "points.bin")
        np.ascontiguousarray(points, dtype="<f8").tofile(points_path)
        self.out_path = os.path.join(self.tmp, "triangles.bin")
        self.command = [node(), str(RUNNER), points_path, self.out_path]

    def run(self):
        self.report = run_reporting(self.command, "node runner.mjs")

    def self_timing(self):
        return self.report["seconds"], None

    def self_memory(self):
        return max(self.report["peak_rss_bytes"] - self.report["baseline_rss_bytes"], 0)

    def result(self):
        tri = np.fromfile(self.out_path, dtype="<u4").astype(np.int64).reshape(-1, 3)
        shutil.rmtree(self.tmp, ignore_errors=True)
        # Delaunator's triangles run clockwise with y up (it is made for
        # screens, y down): turned counter-clockwise, our convention
        return Result(tri[:, ::-1].copy())


PEERS = {"delaunator": DelaunatorPeer}
