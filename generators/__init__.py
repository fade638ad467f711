"""Seeded point sets of both papers, in one registry.

``make(name, n, seed=0, dtype="float64")`` returns an (n, d) array; the same
arguments give the same bytes on every run and machine (numpy's PCG64
``default_rng``).  Neither paper gives formulas, so the definitions in
``sets2d``, ``sets3d`` and ``standins`` are ours, documented per function;
those docstrings are the reference.

Duplicates: a set whose policy is ``"none"`` never contains two equal rows
(rows that rounding to ``dtype`` makes equal are redrawn).  ``"rounding"``
keeps the duplicates that rounding creates, as paper 1's float32 Cluster did
at huge sizes; ``"by-design"`` sets repeat points on purpose.
"""
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from . import hard, hard3d, lidar, sets2d, sets3d, standins
from .cache import cached
from .load import LoadError, load, register

VERSION = "1"  # bump when any definition changes: it keys the cache


@dataclass(frozen=True)
class Distribution:
    name: str
    dim: int
    draw: object  # (rng, n) -> float64 array (n, dim)
    source: str
    duplicates: str = "none"
    default_n: int = 100_000
    # what the set is used for: "paper1" (paper 1's five 2D sets, in the order the
    # figures draw them: experiments read names(tag="paper1"), never a list of their own), "paper2",
    # "hard" (exactness, experiments.field), "lidar", "2.5d" (terrain: z over xy)
    tags: tuple = ()
    # the dtypes the set means something in: 1e-300 or 1e300 are not float32s
    dtypes: tuple = ("float32", "float64")

    @property
    def doc(self):
        return " ".join((self.draw.__doc__ or "").split())


REGISTRY = {d.name: d for d in [
    Distribution("uniform", 2, sets2d.uniform, "paper 1, section 4", tags=("paper1",)),
    Distribution("grid", 2, sets2d.grid, "paper 1, section 4", tags=("paper1", "hard")),
    Distribution("cluster", 2, sets2d.cluster, "paper 1, section 4", duplicates="rounding",
                 tags=("paper1",)),
    Distribution("circle", 2, sets2d.circle, "paper 1, section 4", tags=("paper1", "hard")),
    Distribution("spiral", 2, sets2d.spiral, "paper 1, section 4", tags=("paper1",)),
    Distribution("cube", 3, sets3d.cube, "paper 2, Fig. 6a"),
    Distribution("plane", 3, sets3d.plane, "paper 2, Fig. 6b"),
    Distribution("paraboloid", 3, sets3d.paraboloid, "paper 2, Fig. 6c"),
    Distribution("spiral3d", 3, sets3d.spiral3d, "paper 2, Fig. 6d"),
    Distribution("disc", 3, sets3d.disc, "paper 2, Fig. 6e"),
    Distribution("cylinder", 3, sets3d.cylinder, "paper 2, Fig. 6f"),
    Distribution("axes", 3, sets3d.axes, "paper 2, Fig. 6g"),
    Distribution("statue-standin", 3, standins.statue,
                 "stand-in for paper 2's Happy Buddha (Table 16)", default_n=543_652),
    Distribution("constrained-cube-standin", 3, standins.constrained_cube,
                 "stand-in for paper 2's constrained cube (Table 16)", default_n=4_386_533),
    Distribution("refined-cube-standin", 3, standins.refined_cube,
                 "stand-in for paper 2's refined constrained cube (Table 17)",
                 default_n=5_500_000),
    Distribution("gearbox-standin", 3, standins.gearbox,
                 "stand-in for paper 2's gear box (Table 16)", default_n=3_204_652),
    Distribution("lidar", 3, lidar.cloud, "LiDAR model (generators.lidar), x, y, z",
                 duplicates="by-design", tags=("lidar", "2.5d")),
    Distribution("lidar-xy", 2, lidar.cloud_xy, "LiDAR model (generators.lidar), x and y",
                 duplicates="by-design", tags=("lidar", "hard")),
    Distribution("cocircular", 2, hard.cocircular, "exactness (generators.hard)",
                 duplicates="by-design", tags=("hard",)),
    Distribution("collinear", 2, hard.collinear, "exactness (generators.hard)",
                 duplicates="by-design", tags=("hard",)),
    Distribution("collinear-fan", 2, hard.collinear_fan, "exactness (generators.hard)",
                 duplicates="by-design", tags=("hard",)),
    Distribution("duplicates", 2, hard.duplicates, "exactness (generators.hard)",
                 duplicates="by-design", tags=("hard",)),
    Distribution("signed-zeros", 2, hard.signed_zeros, "exactness (generators.hard)",
                 duplicates="by-design", tags=("hard",)),
    Distribution("tiny", 2, hard.tiny, "exactness (generators.hard)", tags=("hard",),
                 dtypes=("float64",)),
    Distribution("subnormal", 2, hard.subnormal, "exactness (generators.hard)", tags=("hard",),
                 dtypes=("float64",)),
    Distribution("huge", 2, hard.huge, "exactness (generators.hard)", tags=("hard",),
                 dtypes=("float64",)),
    Distribution("gis", 2, hard.gis, "exactness (generators.hard)", duplicates="by-design",
                 tags=("hard",)),
    Distribution("grid-3d", 3, hard3d.grid, "exactness in 3D (generators.hard3d)",
                 tags=("hard",)),
    Distribution("grid-3d-sorted", 3, hard3d.grid_sorted, "exactness in 3D (generators.hard3d)",
                 tags=("hard",)),
    Distribution("cospherical", 3, hard3d.cospherical, "exactness in 3D (generators.hard3d)",
                 tags=("hard",)),
    Distribution("sphere-rounded", 3, hard3d.sphere_rounded,
                 "exactness in 3D (generators.hard3d)", tags=("hard",), dtypes=("float64",)),
    Distribution("duplicates-3d", 3, hard3d.duplicates, "exactness in 3D (generators.hard3d)",
                 duplicates="by-design", tags=("hard",)),
    Distribution("subnormal-3d", 3, hard3d.subnormal, "exactness in 3D (generators.hard3d)",
                 tags=("hard",), dtypes=("float64",)),
    Distribution("huge-3d", 3, hard3d.huge, "exactness in 3D (generators.hard3d)",
                 tags=("hard",), dtypes=("float64",)),
]}

DTYPES = {"float32": np.float32, "float64": np.float64}
CACHE_MIN_POINTS = 1_000_000


def names(dim=None, tag=None):
    """Registered names, optionally only those of dimension ``dim`` and
    those tagged ``tag``."""
    return [k for k, d in REGISTRY.items()
            if (dim is None or d.dim == dim) and (tag is None or tag in d.tags)]


def get(name):
    try:
        return REGISTRY[name]
    except KeyError:
        raise ValueError(f"unknown distribution {name!r}; known: {', '.join(REGISTRY)}") from None


def _duplicate_rows(rounded):
    """Indices of rows equal to an earlier row.  Rows are hashed to 64 bits
    and only rows whose hashes collide are compared exactly."""
    bits = np.ascontiguousarray(rounded).view(np.uint32 if rounded.dtype == np.float32
                                              else np.uint64).astype(np.uint64)
    h = np.zeros(len(rounded), dtype=np.uint64)
    for j in range(bits.shape[1]):
        h = (h ^ bits[:, j]) * np.uint64(0x9E3779B97F4A7C15)
        h ^= h >> np.uint64(29)
    order = np.argsort(h)
    hs = h[order]
    collide = np.flatnonzero(hs[1:] == hs[:-1])
    if collide.size == 0:
        return collide
    cand = np.unique(np.concatenate((order[collide], order[collide + 1])))
    sub = rounded[cand]
    o = np.lexsort(sub.T[::-1])
    same = np.all(sub[o[1:]] == sub[o[:-1]], axis=1)
    return cand[o[1:][same]]


def _redraw_duplicates(dist, rng, pts, dtype):
    """Replace rows that are equal after rounding until none are left."""
    for _ in range(100):
        rounded = pts.astype(dtype)
        dup_rows = _duplicate_rows(rounded)
        if dup_rows.size == 0:
            return rounded
        pts[dup_rows] = dist.draw(rng, dup_rows.size)
    raise RuntimeError(f"{dist.name}: could not draw distinct points")


def generate(name, n, *, seed=0, dtype="float64"):
    """Draw the set without touching the cache."""
    dist = get(name)
    if dtype not in DTYPES:
        raise ValueError(f"dtype must be one of {list(DTYPES)}, got {dtype!r}")
    if dtype not in dist.dtypes:
        raise ValueError(f"{name} is a {' or '.join(dist.dtypes)} set, not {dtype}")
    n = int(n)
    if n < 0:
        raise ValueError("n must be non-negative")
    rng = np.random.default_rng([seed, sum(map(ord, name))])
    pts = dist.draw(rng, n)
    if dist.duplicates == "none":
        return np.ascontiguousarray(_redraw_duplicates(dist, rng, pts, DTYPES[dtype]))
    return np.ascontiguousarray(pts.astype(DTYPES[dtype]))


def make(name, n, *, seed=0, dtype="float64", cache=None):
    """(n, d) points of distribution ``name``.  Sets of at least a million
    points are cached on disk and returned memory-mapped read-only (``cache``
    forces either way)."""
    use_cache = n >= CACHE_MIN_POINTS if cache is None else cache
    use_cache = use_cache and "input" not in get(name).tags  # a user's file is read, not kept
    if not use_cache:
        return generate(name, n, seed=seed, dtype=dtype)
    key = f"{name}-n{int(n)}-s{seed}-{dtype}-{definition(name)}"
    return cached(key, lambda: generate(name, n, seed=seed, dtype=dtype))


@lru_cache(maxsize=None)
def definition(name):
    """A short hash of everything that defines set ``name``: VERSION, the
    source of its draw function's module and of the drawing and de-duplicating
    code here.  It keys the cache, so that a changed formula never serves a
    stale file, and results record it (experiments.core.runner).  Computed once
    per process: the sources do not change under a running process."""
    import hashlib
    import inspect
    import sys
    dist = get(name)
    h = hashlib.sha256(VERSION.encode())
    for part in (inspect.getsource(sys.modules[dist.draw.__module__]), inspect.getsource(generate),
                 inspect.getsource(_redraw_duplicates), inspect.getsource(_duplicate_rows),
                 repr((dist.name, dist.dim, dist.duplicates))
                 + (dist.source if "input" in dist.tags else "")):
        h.update(part.encode())
    return "d" + h.hexdigest()[:12]


def listing():
    """One line per distribution: name, dimension, source, duplicates, formula."""
    rows = []
    for d in REGISTRY.values():
        rows.append(f"{d.name:26s} {d.dim}D  {d.source}; duplicates: {d.duplicates}\n"
                    f"{'':26s}     {d.doc}")
    return "\n".join(rows)
