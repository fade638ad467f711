"""Peers behind one interface, in one registry.  An experiment names peers
only by registry key; ``make(name)`` returns a fresh instance."""
from .base import Peer, Result, Unavailable
from .isolate import Failure, Measurement, measure, measure_isolated
from .peers import CgalPeer, LfqtDC, LfqtInsert, QhullPeer, TrianglePeer

INSERT_ORDERS = ("kdtree", "kdtree-alternate", "hilbert", "hilbert-grid", "brio", "random", "input")

REGISTRY = {
    "lfqt-dc": lambda: LfqtDC("lfqt"),
    "lfqt-dc-alternating": lambda: LfqtDC("alternating"),
    "triangle": lambda: TrianglePeer(""),
    "triangle-incremental": lambda: TrianglePeer("i"),
    "triangle-sweepline": lambda: TrianglePeer("F"),
    "qhull-2d": lambda: QhullPeer(2),
    "qhull-3d": lambda: QhullPeer(3),
    "cgal-dt2": lambda: CgalPeer("dt2"),
    "cgal-dt3": lambda: CgalPeer("dt3"),
    "cgal-dt2-order": lambda: CgalPeer("dt2-order"),
    "cgal-dt3-order": lambda: CgalPeer("dt3-order"),
}
for _o in INSERT_ORDERS:
    REGISTRY[f"lfqt-insert-{_o}"] = (lambda o: lambda: LfqtInsert(o))(_o)
    for _op in ("dt2-order", "dt3-order"):
        REGISTRY[f"cgal-{_op[:3]}-{_o}"] = (lambda op, o: lambda: CgalPeer(op, o))(_op, _o)


def make(name):
    try:
        return REGISTRY[name]()
    except KeyError:
        raise ValueError(f"unknown peer {name!r}; known: {', '.join(REGISTRY)}") from None


def names(dim=None):
    return [k for k in REGISTRY if dim is None or dim in make(k).dims]


def available(name):
    """(True, "") or (False, reason)."""
    try:
        make(name).check()
        return True, ""
    except Unavailable as e:
        return False, str(e)


__all__ = ["Peer", "Result", "Unavailable", "Failure", "Measurement", "measure",
           "measure_isolated", "REGISTRY", "make", "names", "available"]
