"""Peers behind one interface, in one registry.

Each peer family is one module of this package (ours, cgal, triangle,
qhull, ...) with a ``PEERS`` dict of registry name -> factory; a new family
is one new module.  An experiment names peers only by registry key;
``make(name, threads=...)`` returns a fresh, configured instance."""
import importlib
import pkgutil

from .base import Peer, Result, Unavailable
from .isolate import Failure, Measurement, measure, measure_isolated

_NOT_FAMILIES = {"base", "isolate", "__main__"}


def _families():
    """The family modules of this package, in name order."""
    mods = [importlib.import_module(f"{__name__}.{m.name}") for m in pkgutil.iter_modules(__path__)
            if m.name not in _NOT_FAMILIES]
    return [m for m in mods if hasattr(m, "PEERS")]


FAMILIES = _families()
REGISTRY = {name: factory for fam in FAMILIES for name, factory in fam.PEERS.items()}


def make(name, **options):
    """A fresh peer ``name`` with ``options`` (threads) applied."""
    try:
        factory = REGISTRY[name]
    except KeyError:
        raise ValueError(f"unknown peer {name!r}; known: {', '.join(REGISTRY)}") from None
    return factory().set(**options)


def names(dim=None):
    """The triangulators (of dimension ``dim``); a peer that times one phase
    alone is in REGISTRY but not here."""
    return [k for k in REGISTRY if make(k).triangulates and (dim is None or dim in make(k).dims)]


def known_failure(name, distribution, n):
    """Why peer ``name`` is known not to finish ``n`` points of
    ``distribution`` within a cell's limit (its family module's
    ``known_failure``, else the peer's own), or None."""
    for fam in FAMILIES:
        if name in fam.PEERS:
            if hasattr(fam, "known_failure"):
                return fam.known_failure(distribution, n)
            return make(name).known_failure(distribution, n)
    raise ValueError(f"unknown peer {name!r}; known: {', '.join(REGISTRY)}")


def available(name):
    """(True, "") or (False, reason)."""
    try:
        make(name).check()
        return True, ""
    except Unavailable as e:
        return False, str(e)


def build():
    """Build every compiled family; returns the worst exit code."""
    return max([fam.build() for fam in FAMILIES if hasattr(fam, "build")], default=0)


__all__ = ["Peer", "Result", "Unavailable", "Failure", "Measurement", "measure",
           "measure_isolated", "REGISTRY", "FAMILIES", "make", "names", "known_failure",
           "available", "build"]
