"""Tiles: a k-d split of the plane chosen on a sample of the points (median
cuts along the longer side, so unbalanced data still gives balanced tiles),
and the tasks that measure the chunks and cut them into tiles.

    chunk_stats   one pass over a chunk: rows, magnitudes, a seeded sample
    kd_tree       the splits, from the pooled sample
    cut_chunk     a chunk's points scaled and grouped by tile, to a file
                  (lfqt.distributed.shuffle)
    tile, load    a tile's parts of every chunk's file, in global id order

Cells are half-open: a point on a cut belongs to the upper side.  Points
that compare equal (0.0 and -0.0 included) always fall in the same tile.
"""
import math

import numpy as np
from numba import njit

from . import shuffle
from .sources import read


def chunk_stats(kind, what, start, rate, seed):
    """(rows, largest |coordinate|, smallest nonzero |coordinate|, sample)
    of one chunk; the sample keeps each row with probability ``rate``."""
    pts = read(kind, what).astype(np.float64, copy=False)
    mags = np.abs(pts[pts != 0])
    rng = np.random.default_rng([seed, start])
    keep = rng.random(len(pts)) < rate
    return (len(pts), float(mags.max(initial=0.0)), float(mags.min(initial=np.inf)),
            pts[keep].copy())


def kd_tree(sample, tiles):
    """(nodes, cells): nodes rows (axis, cut, left, right) with left < 0
    meaning leaf tile -left-1; cells (tiles, 4) open boxes x0, y0, x1, y1."""
    nodes, cells = [], np.empty((tiles, 4))
    inf = np.inf

    def leaf(me, k, first, box):
        """One tile for the whole box; the others of its k stay empty."""
        cells[first] = box
        cells[first + 1:first + k] = (inf, inf, -inf, -inf)
        return me

    def split(pts, k, first, box):
        me = len(nodes)
        nodes.append([0, 0.0, -first - 1, -first - 1])
        if k == 1 or len(pts) < 2:
            return leaf(me, k, first, box)
        kl = k // 2
        ext = pts.max(0) - pts.min(0)
        for axis in np.argsort(-ext, kind="stable"):
            vals = np.sort(pts[:, axis])
            cut = vals[min(len(vals) - 1, len(vals) * kl // k)]
            if cut > vals[0]:
                break
        else:  # every sampled point equal
            return leaf(me, k, first, box)
        low = pts[:, axis] < cut
        lbox, hbox = list(box), list(box)
        lbox[2 + axis], hbox[axis] = cut, cut
        left = split(pts[low], kl, first, lbox)
        right = split(pts[~low], k - kl, first + kl, hbox)
        nodes[me] = [axis, cut, left, right]
        return me

    split(np.asarray(sample, dtype=np.float64).reshape(-1, 2), tiles, 0, [-inf, -inf, inf, inf])
    return np.array(nodes, dtype=np.float64).reshape(-1, 4), cells


@njit(cache=True)
def assign(P, nodes):
    """Tile of every point: walk the k-d nodes from the root."""
    out = np.empty(P.shape[0], dtype=np.int64)
    for i in range(P.shape[0]):
        k = 0
        while True:
            axis, cut, left, right = nodes[k, 0], nodes[k, 1], nodes[k, 2], nodes[k, 3]
            if left < 0 and left == right:
                out[i] = -int(left) - 1
                break
            k = int(right) if P[i, int(axis)] >= cut else int(left)
    return out


def cut_chunk(kind, what, start, scale_exp, nodes, tiles, path):
    """Write the chunk's points scaled by 2**scale_exp (exact) with their
    global ids, grouped by tile, to one shuffle file (``path``): tile t is
    part t.  Returns the path."""
    P = read(kind, what).astype(np.float64) * 2.0 ** scale_exp
    P += 0.0  # -0.0 -> 0.0: equal points get equal coordinates
    tile = assign(P, nodes)
    order = np.argsort(tile, kind="stable")
    starts = np.searchsorted(tile[order], np.arange(tiles + 1))
    P = np.take(P, order, axis=0)
    return shuffle.write(path, starts, start + order.astype(np.int64), P,
                         summary=_boxes(P, starts))


@njit(cache=True)
def _boxes(P, starts):
    """Each part's box (x0, y0, x1, y1), NaN when empty."""
    out = np.full((len(starts) - 1, 4), np.nan)
    for t in range(len(starts) - 1):
        if starts[t + 1] > starts[t]:
            lo = starts[t]
            x0, y0, x1, y1 = P[lo, 0], P[lo, 1], P[lo, 0], P[lo, 1]
            for i in range(lo + 1, starts[t + 1]):
                x0, x1 = min(x0, P[i, 0]), max(x1, P[i, 0])
                y0, y1 = min(y0, P[i, 1]), max(y1, P[i, 1])
            out[t] = (x0, y0, x1, y1)
    return out


def tile(t, paths):
    """Tile t's descriptor: the files holding its points (part t of each),
    how many there are, and its box (NaN when empty), from the files'
    heads.  The points stay on disk until a task needs them (``load``)."""
    heads = [shuffle.summary(p, t) for p in paths]
    n = sum(h[0] for h in heads)
    boxes = np.array([h[1] for h in heads if h[0]]).reshape(-1, 4)
    box = (np.r_[boxes[:, :2].min(0), boxes[:, 2:].max(0)] if n else np.full(4, np.nan))
    return dict(t=t, paths=paths, n=n, box=box)


def load(local):
    """A tile's points: dict(ids, P) sorted by global id (the parts come in
    chunk order, each in id order).  Duplicates stay: the tile's first
    triangulation names them (lfqt keeps the smallest id)."""
    parts = [shuffle.read(p, local["t"]) for p in local["paths"]]
    return dict(ids=np.concatenate([p[0] for p in parts] + [np.empty(0, np.int64)]),
                P=np.concatenate([p[1] for p in parts] + [np.empty((0, 2))]))


def tasks(chunks, tiles):
    """The partition's tasks: a cut per chunk, one barrier, a descriptor and
    its box per tile."""
    return chunks + 1 + 2 * tiles


def touching(cells):
    """(tiles, tiles) bool: the closed cells meet (sides or corners)."""
    c = np.asarray(cells)
    return ((c[:, None, 0] <= c[None, :, 2]) & (c[None, :, 0] <= c[:, None, 2])
            & (c[:, None, 1] <= c[None, :, 3]) & (c[None, :, 1] <= c[:, None, 3]))


def auto_tiles(n, workers, points_per_tile=1 << 20):
    """Tiles by default: about a million points each, at least two per worker."""
    return max(2 * workers, math.ceil(n / points_per_tile), 1)
