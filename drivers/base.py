"""The one interface every triangulator is measured through (ann-benchmarks'
BaseANN, benchopt's Solver).

A peer is prepared (untimed: data conversion, files, warm-up), then ``run()``
is timed, then ``result()`` gives the simplices (input indices) and counts.
A peer that measures itself in-process (the CGAL driver) reports that
through ``self_timing()``, and the runner prefers it to its own clock.

Each peer family is one module of this package with a ``PEERS`` dict
(registry name -> factory); ``drivers.REGISTRY`` collects them.
"""
import json
import os
import shutil
import subprocess
import tempfile
from dataclasses import dataclass, field

import numpy as np

from .isolate import die_with_parent


class Unavailable(RuntimeError):
    """The peer cannot run on this machine; the message says what to do."""


@dataclass
class Result:
    simplices: object = None  # (m, d+1) int array of input indices, or None
    counts: dict = field(default_factory=dict)  # lfqt.predicates.counters' vocabulary
    extra: dict = field(default_factory=dict)


class Peer:
    name = "abstract"
    dim = 2  # 2 or 3
    family = ""  # the module of drivers/ that defines it
    options = ()  # options set() takes besides their defaults, e.g. ("threads",)
    bytes_per_point = 300  # a generous peak-memory estimate, to skip what cannot fit
    triangulates = True  # False for a peer that times one phase alone (lfqt-radix)
    install = ""  # what to do when check() fails
    # True in the fresh regime (drivers.isolate.REGIMES): prepare() must not
    # warm anything up, so that the timed run is the process's first call
    cold = False
    # why the peer's meshes are not Delaunay even on random points, or "":
    # tests that compare a peer with lfqt leave such a peer to its own test
    # (the field experiment measures how wrong it is)
    inexact = ""

    @property
    def dims(self):
        """Dimensions the peer accepts."""
        return (self.dim,)

    def set(self, threads=1):
        """Apply the runner's options; a peer without an option accepts only
        its default."""
        if threads != 1 and "threads" not in self.options:
            raise ValueError(f"{self.name} runs on one thread; it has no threads option")
        self.threads = threads
        return self

    def known_failure(self, distribution, n):
        """Why this peer is known not to finish ``n`` points of
        ``distribution`` within a cell's limit, or None (where the family
        module's ``known_failure`` does not say it for all its peers)."""
        return None

    def estimated_bytes(self, n):
        return n * self.bytes_per_point

    def version(self):
        return ""

    def build_info(self):
        """{compiler, flags, library version} of a compiled peer, else {}."""
        return {}

    def check(self):
        """Raise Unavailable when the peer cannot run here."""

    def prepare(self, points, order=None, count=False):
        """Untimed set-up.  ``order``: (perm, hint) for ordered insertion;
        ``count``: collect predicate/conflict counts (may slow ``run``)."""
        raise NotImplementedError

    def run(self):
        """The timed operation."""
        raise NotImplementedError

    def keep(self):
        """Hold the last run's output alive until the measurement ends (the
        kept regime).  A peer whose output lives in this process overrides
        this with the whole object a user would hold."""
        self.kept = getattr(self, "kept", []) + [self.result()]

    def self_timing(self):
        """(seconds, cycles or None) measured by the peer itself, or None."""
        return None

    def self_memory(self):
        """Peak bytes the operation used, measured by the peer itself (a
        peer in another process), or None to use this process's."""
        return None

    def result(self):
        return Result()

    def __repr__(self):
        return f"<peer {self.name}>"


def run_reporting(command, what):
    """Run a peer's own process (it dies with ours) and return the JSON
    report it prints last; RuntimeError with its stderr's end if it fails."""
    proc = subprocess.run(command, capture_output=True, text=True, preexec_fn=die_with_parent)
    if proc.returncode != 0:
        raise RuntimeError(f"{what} failed ({proc.returncode}): {proc.stderr.strip()[-500:]}")
    return json.loads(proc.stdout.strip().splitlines()[-1])


class CompiledPeer(Peer):
    """A peer run as one of our compiled drivers in its own process: the
    points go in as a .npy file, the driver times the operation itself
    (wall clock and TSC, file I/O outside) and prints one JSON line; the
    simplices come back as a .npy file.  Subclasses give the binary and the
    arguments, and map the report's counts."""
    binary = None  # Path

    def check(self):
        if self.binary is None or not self.binary.exists():
            raise Unavailable(f"{self.name}: driver not built at {self.binary}: {self.install}")

    def arguments(self, points_path, count):
        """The driver's command line after the binary."""
        raise NotImplementedError

    def counts(self, report):
        """The report's counts in lfqt.predicates.counters' vocabulary."""
        return {}

    def build_info(self):
        info_path = self.binary.parent / "build_info.json" if self.binary else None
        if info_path is None or not info_path.exists():
            return {}
        return json.loads(info_path.read_text())

    def version(self):
        return self.build_info().get("version", "")

    def prepare(self, points, order=None, count=False):
        self.check()
        self.tmp = tempfile.mkdtemp(prefix=f"lfqt-{self.family}-")
        points_path = os.path.join(self.tmp, "points.npy")
        np.save(points_path, np.ascontiguousarray(points, dtype=np.float64))
        self.out_path = os.path.join(self.tmp, "simplices.npy")
        self.command = [str(self.binary)] + self.arguments(points_path, count) + ["--out",
                                                                                  self.out_path]
        self.extra_seconds = 0.0  # work of ours inside the timed run (an order we build)

    def run(self):
        self.report = run_reporting(self.command, self.binary.name)

    def self_timing(self):
        return self.report["seconds"] + self.extra_seconds, self.report["tsc_cycles"]

    def keep(self):
        """Nothing to hold: each run is a driver process of its own, which
        allocates afresh and exits, so every regime times a first call."""

    def self_memory(self):
        """Peak resident bytes of the driver above its state after loading."""
        return max(self.report["peak_rss_bytes"] - self.report["baseline_rss_bytes"], 0)

    def result(self):
        simplices = np.load(self.out_path)
        shutil.rmtree(self.tmp, ignore_errors=True)
        return Result(simplices, self.counts(self.report),
                      {"tsc_cycles": self.report["tsc_cycles"]})


class PipPeer(Peer):
    """A peer from a PyPI package, called in this process: ``check`` imports
    ``module`` and says which package to install when it cannot."""
    module = ""  # what to import
    package = ""  # the PyPI distribution

    @property
    def install(self):
        return f"pip install {self.package} (the project's setup installs it: the 'all' extra)"

    def check(self):
        import importlib
        try:
            importlib.import_module(self.module)
        except ImportError as e:
            raise Unavailable(f"{self.name}: PyPI package {self.package!r} is not installed "
                              f"({e}): {self.install}") from e

    def version(self):
        from importlib import metadata
        try:
            return f"{self.package} {metadata.version(self.package)}"
        except metadata.PackageNotFoundError:
            return ""
