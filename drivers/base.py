"""The one interface every triangulator is measured through (ann-benchmarks'
BaseANN, benchopt's Solver).

A peer is prepared (untimed: data conversion, files, warm-up), then ``run()``
is timed, then ``result()`` gives the simplices (input indices) and counts.
A peer that measures itself in-process (the CGAL driver) reports that
through ``self_timing()``, and the runner prefers it to its own clock.
"""
from dataclasses import dataclass, field


class Unavailable(RuntimeError):
    """The peer cannot run on this machine; the message says what to do."""


@dataclass
class Result:
    simplices: object = None  # (m, d+1) int array of input indices, or None
    counts: dict = field(default_factory=dict)
    extra: dict = field(default_factory=dict)


class Peer:
    name = "abstract"
    dim = 2  # 2 or 3
    family = ""  # "ours", "cgal", "triangle", "qhull"

    @property
    def dims(self):
        """Dimensions the peer accepts."""
        return (self.dim,)

    def version(self):
        return ""

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
