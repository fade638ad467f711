"""The one interface every triangulator is measured through (ann-benchmarks'
BaseANN, benchopt's Solver).

A peer is prepared (untimed: data conversion, files, warm-up), then ``run()``
is timed, then ``result()`` gives the simplices (input indices) and counts.
A peer that measures itself in-process (the CGAL driver) reports that
through ``self_timing()``, and the runner prefers it to its own clock.

Each peer family is one module of this package with a ``PEERS`` dict
(registry name -> factory); ``drivers.REGISTRY`` collects them.
"""
from dataclasses import dataclass, field


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
    install = ""  # what to do when check() fails

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
