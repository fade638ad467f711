"""Point sets drawn chunk by chunk, for sets larger than one process should
hold (lfqt.distributed, experiments.distributed).  Chunk c of (name, n,
seed) depends only on those and c, so any chunk can be redrawn alone.

The distributions are those of ``generators.sets2d`` (same definitions),
drawn with a per-chunk stream ``default_rng([seed, c])``: the bytes differ
from ``generators.make(name, n)``, the distribution does not.
"""
from pathlib import Path

import numpy as np

CHUNK_ROWS = 1 << 22  # 64 MiB of float64 pairs


def _uniform(rng, start, rows, seed):
    return rng.random((rows, 2))


def _cluster(rng, start, rows, seed):
    # sets2d.cluster: 10 centres ~ U[0, 1)^2 (the same for every chunk),
    # point i at centre i mod 10 + N(0, 0.05^2), shifted by +1
    centres = np.random.default_rng(seed).random((10, 2))
    which = (start + np.arange(rows)) % 10
    return 1.0 + centres[which] + rng.normal(0.0, 0.05, (rows, 2))


DRAWS = {"uniform": _uniform, "cluster": _cluster}


def chunk(name, n, c, *, seed=0, rows=CHUNK_ROWS):
    """Chunk c (rows c*rows .. ) of the set ``name`` of n points."""
    if name not in DRAWS:
        raise ValueError(f"{name!r} has no chunk-wise generator; known: {', '.join(DRAWS)}")
    start = c * rows
    count = max(0, min(rows, n - start))
    return DRAWS[name](np.random.default_rng([seed, c]), start, count, seed)


def write(name, n, directory, *, seed=0, rows=CHUNK_ROWS):
    """Write the set as directory/<name>-<c>.npy, one chunk at a time;
    returns the glob that names them all."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    for c in range(-(-n // rows)):
        np.save(directory / f"{name}-{c:05d}.npy", chunk(name, n, c, seed=seed, rows=rows))
    return str(directory / f"{name}-*.npy")
