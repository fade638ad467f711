"""The triangle structure of the divide and conquer (Triangle's, flat).

One int array ``T`` holds 6 entries per triangle: ``T[6t + i]`` (i = 0, 1, 2)
are its vertices, counter-clockwise, and ``T[6t + 3 + i]`` the twin of its
half-edge ``3t + i``, which runs from vertex i to vertex i+1::

              v2
             /  ^
      3t+2  /    \\  3t+1          half-edge 3t+i: v_i -> v_(i+1)
           v      \\               twin(3t+i) = T[6t + 3 + i]
          v0 ----> v1
              3t+0

Vertices and twins of a triangle share a cache line, which halves the misses
of the pointer chasing in a merge.  Vertex ids are positions in Morton order.
The convex hull is wrapped in *ghost* triangles ``(a, b, GHOST)``, hull edge
``b -> a``, always with the ghost vertex in slot 2, so that every partition
is a closed surface.  A partition is a row of 5 ints: the vertices with the
largest x, smallest x, largest y and smallest y (``XMAX`` ... ``YMIN``), and
``SINGLE`` (1 for a lone vertex, which has no ghosts).

The merge at split position ``p`` owns triangle slots ``2(p-1)`` and
``2(p-1)+1``, so slot ids depend only on the input, never on scheduling.
Every index goes through the unsigned helpers here (see lfqt.indexing).
"""
from collections import namedtuple

import numpy as np
from numba import njit

GHOST = -1
UNUSED = -2
XMAX, XMIN, YMAX, YMIN, SINGLE = range(5)
PART = 5  # ints per partition row
STACK = 160  # partitions open at once: the quad-tree is at most 128 levels deep

# What every merge kernel reads and writes: P (n, 2) float64 points in Morton
# order, T the triangles, ghost_out[v] the ghost (w, v, GHOST) of v's
# outgoing hull edge v -> w, fmt = (coord_bits, exp_bits, mant_bits, emin,
# scale_exp) of the input format (for the level bounds), level_filter.
Mesh = namedtuple("Mesh", "P T ghost_out fmt level_filter")


@njit(cache=True, inline="always")
def slot(t, i):
    """Index in T of entry i of triangle t (0-2 vertices, 3-5 twins)."""
    return np.uint64(6 * t + i)


@njit(cache=True, inline="always")
def nxt(e):
    """The half-edge after e in its triangle (branch-free)."""
    return e + 1 - 3 * (np.uint64(e) % np.uint64(3) == np.uint64(2))


@njit(cache=True, inline="always")
def prv(e):
    """The half-edge before e in its triangle (branch-free)."""
    return e - 1 + 3 * (np.uint64(e) % np.uint64(3) == np.uint64(0))


@njit(cache=True, inline="always")
def origin(e):
    """Index in T of the origin vertex of half-edge e (3t + i -> 6t + i)."""
    v = np.uint64(e)
    return v + np.uint64(3) * (v // np.uint64(3))


@njit(cache=True, inline="always")
def twin(e):
    """Index in T of the twin of half-edge e."""
    return origin(e) + np.uint64(3)


@njit(cache=True, inline="always")
def link(T, a, b):
    """Make half-edges a and b each other's twin."""
    T[twin(a)] = b
    T[twin(b)] = a


@njit(cache=True, inline="always")
def set_triangle(T, t, a, b, c):
    """Triangle t gets the vertices (a, b, c); its twins are left as they are."""
    T[slot(t, 0)] = a
    T[slot(t, 1)] = b
    T[slot(t, 2)] = c


@njit(cache=True, inline="always")
def less(ax, ay, bx, by, axis):
    """Total order of distinct points: (x, y) for axis 0, (y, -x) for axis 1."""
    if axis == 0:
        return ax < bx or (ax == bx and ay < by)
    return ay < by or (ay == by and ax > bx)
