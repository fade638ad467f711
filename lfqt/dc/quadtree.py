"""The linear floating-point quad-tree of a point set as a table, for
inspection and drawing (paper 1, Fig. 1): the same keys, sort and
subdivision as ``lfqt.triangulate`` uses, decoded into one row per split.

A node whose keys agree above bit ``b`` and differ at ``b`` splits at ``b``
(its *level* in the paper is ``b + 1``; the root of 64-bit keys is level 64).
x owns the odd key bits, y the even ones, so with ``j = b // 2``:

    odd b  (x split at x bit j):   free bits below the prefix  x: 0..j    y: 0..j
    even b (y split at y bit j):                               x: 0..j-1  y: 0..j

The node's cell is every coordinate with its prefix (free bits all 0 up to
all 1); the cut is the prefix with bit j set, the smallest value of the
upper child.  Bit j of a coordinate is its sign, an exponent bit or a
mantissa bit: exponent splits halve the distance to the axis, mantissa
splits form the regular grids of Fig. 1c.
"""
from __future__ import annotations

from collections import namedtuple
from typing import Any, NamedTuple

import numpy as np
import numpy.typing as npt
from numba import njit

from .. import morton
from .._input import FORMATS, exact_floats2d, index_dtype, magnitudes
from ..workers import Workers
from . import key_gaps, sorted_keys, subdivide

class Quadtree(NamedTuple):
    """The LFQT of a point set, one row per split (what ``quadtree`` returns).

    Attributes
    ----------
    order : ndarray of int64, shape (n,)
        The input indices in Morton order.
    nodes : dict of str to ndarray, each of shape (k,)
        One entry per split, children before parents (k is one fewer than
        the distinct points; the root is the last):

        * ``bit`` (int64): the key bit the node splits at, and ``level``
          (int64), its level in the paper, ``bit + 1``;
        * ``axis`` (int64): 0 for a cut of x, 1 of y;
        * ``field`` (str, <U8): the bit field the cut falls in, "sign",
          "exponent" or "mantissa";
        * ``cut`` (float64): the smallest coordinate of the upper child;
        * ``x0``, ``x1``, ``y0``, ``y1`` (float64): the node's cell, ±inf
          where it is unbounded;
        * ``depth`` (int64): 0 at the root;
        * ``parent`` (int64): the parent's row, -1 at the root;
        * ``lo``, ``split``, ``hi`` (int64): the node's positions
          [lo, hi) in ``order``, cut at ``split``.

    Examples
    --------
    Three points: the root cuts x between the first and the other two, its
    child cuts y between those.

    >>> import numpy as np, lfqt
    >>> tree = lfqt.quadtree(np.array([[0.25, 0.25], [0.75, 0.25], [0.75, 0.75]]))
    >>> tree.order.tolist()
    [0, 1, 2]
    >>> root = len(tree.nodes["bit"]) - 1  # children before parents
    >>> int(tree.nodes["axis"][root]), float(tree.nodes["cut"][root])
    (0, 0.5)
    >>> tree.nodes["lo"].tolist(), tree.nodes["split"].tolist(), tree.nodes["hi"].tolist()
    ([1, 0], [2, 1], [3, 3])
    >>> tree.nodes["parent"].tolist(), tree.nodes["depth"].tolist()
    ([1, -1], [1, 0])
    """
    order: npt.NDArray[np.int64]
    nodes: dict[str, npt.NDArray[Any]]


# The quad-tree's merge nodes, one entry per node in op order: its first
# position, its split position, its end, the split's bit, its parent (-1 at
# the root).
Nodes = namedtuple("Nodes", "lo split hi bit parent")


@njit(cache=True)
def _decode(ops, nops, n, gaps):
    """The Nodes (lo, split, hi, bit, parent) of the merge ops of a post-order op list
    (lfqt.dc.subdivide; a split's bit is its gap) over n sorted positions, in
    op order.  A node ends where the next vertex pushed after it starts (runs
    of equal keys are one vertex), or at n."""
    m = 0
    for k in range(nops):
        m += ops[k] >= 0
    lo = np.empty(m, np.int64)
    split = np.empty(m, np.int64)
    hi = np.empty(m, np.int64)
    bit = np.empty(m, np.int64)
    parent = np.full(m, -1, np.int64)
    s_lo = np.empty(nops + 1, np.int64)
    s_node = np.empty(nops + 1, np.int64)
    top = -1
    node = 0
    open_from = 0  # nodes [open_from, node) end where the next vertex starts
    for k in range(nops):
        op = ops[k]
        top += 1
        if op < 0:
            s_lo[top] = -(op + 1)
            s_node[top] = -1
            hi[open_from:node] = -(op + 1)
            open_from = node
            continue
        top -= 2  # the two children, left at top, right at top + 1
        lo[node] = s_lo[top]
        split[node] = op
        bit[node] = gaps[op]
        for c in (top, top + 1):
            if s_node[c] >= 0:
                parent[s_node[c]] = node
        s_node[top] = node
        node += 1
    hi[open_from:] = n
    return Nodes(lo, split, hi, bit, parent)


def _floats(ordered, dtype, fill):
    """The float64 values of ordered bits; bit patterns that are NaN become
    ``fill``."""
    f = morton.from_ordered_bits(ordered, dtype)
    return np.where(np.isnan(f), fill, f).astype(np.float64)


def _low_mask(count, width):
    """uint of ``count`` low one bits, element-wise (count in 0..width)."""
    u = np.dtype(f"uint{width}")
    ones = u.type(~u.type(0))
    shift = np.clip(width - count, 0, width - 1).astype(u)
    return np.where(count > 0, ones >> shift, u.type(0)).astype(u)


def quadtree(points: npt.ArrayLike) -> Quadtree:
    """The LFQT of 2D points (float32 or float64 bits, never rounded), as
    lfqt's divide and conquer subdivides it.

    Parameters
    ----------
    points : array_like, shape (n, 2)
        float32, float64 or integers (exact in float64), as for
        ``triangulate``: float32 input gives 64-bit keys, float64 input
        128-bit keys.

    Returns
    -------
    Quadtree
        ``order``, the input indices in Morton order, and ``nodes``, one
        row per split (see ``Quadtree``).

    Raises
    ------
    ValueError
        For points not of shape (n, 2), NaN or inf.
    TypeError
        For points that are not real numbers.

    Examples
    --------
    The four points of a square: the root cuts x at 0.5 (an exponent bit:
    0.25 and 0.75 lie in different binades), then each half cuts y.

    >>> import numpy as np
    >>> import lfqt
    >>> p = np.array([[0.25, 0.25], [0.75, 0.25], [0.25, 0.75], [0.75, 0.75]])
    >>> tree = lfqt.quadtree(p)
    >>> tree.order.tolist()
    [0, 2, 1, 3]
    >>> tree.nodes["axis"].tolist(), tree.nodes["cut"].tolist()  # the root last
    ([1, 1, 0], [0.5, 0.5, 0.5])
    >>> tree.nodes["field"].tolist(), tree.nodes["parent"].tolist()
    (['exponent', 'exponent', 'exponent'], [2, 2, -1])
    >>> tree.nodes["level"].tolist()  # of 128-bit keys; float32's have 64
    [107, 107, 108]
    >>> lfqt.quadtree(p.astype(np.float32)).nodes["level"].tolist()
    [49, 49, 50]
    """
    arr = exact_floats2d(points)
    x, y = arr[:, 0], arr[:, 1]
    n = x.shape[0]
    workers = Workers(1)
    khi, klo, perm, scan = sorted_keys(arr, workers, index_dtype(n))
    magnitudes(arr, scan)  # ValueError for NaN or inf
    gaps, _ = key_gaps(khi, klo, x.dtype == np.float64, workers)
    ops = np.empty(max(2 * n, 1), dtype=np.int64)
    nops = subdivide.subdivide_lfqt(gaps, 0, n, ops, 0)
    lo, split, hi, bit, parent = _decode(ops, nops, n, gaps)
    width, exp_bits, mant_bits, _ = FORMATS[x.dtype]
    u = np.dtype(f"uint{width}")
    first = perm[lo]  # any point of a node carries its prefix
    ox, oy = morton.ordered_bits(x[first]), morton.ordered_bits(y[first])
    j = bit // 2
    is_x = bit % 2 == 1
    free_x = np.where(is_x, j + 1, j)
    mx, my = _low_mask(free_x, width), _low_mask(j + 1, width)
    cut_bits = np.where(is_x, (ox & ~_low_mask(j + 1, width)) | (u.type(1) << j.astype(u)),
                        (oy & ~my) | (u.type(1) << j.astype(u)))
    depth = np.zeros(len(bit), np.int64)
    for k in range(len(bit) - 1, -1, -1):  # parents follow their children
        if parent[k] >= 0:
            depth[k] = depth[parent[k]] + 1
    field = np.where(j == width - 1, "sign", np.where(j >= mant_bits, "exponent", "mantissa"))
    nodes = dict(level=bit + 1, bit=bit, axis=np.where(is_x, 0, 1), field=field,
                 cut=_floats(cut_bits, x.dtype, np.inf),
                 x0=_floats(ox & ~mx, x.dtype, -np.inf), x1=_floats(ox | mx, x.dtype, np.inf),
                 y0=_floats(oy & ~my, x.dtype, -np.inf), y1=_floats(oy | my, x.dtype, np.inf),
                 depth=depth, parent=parent, lo=lo, split=split, hi=hi)
    return Quadtree(perm.astype(np.int64), nodes)
