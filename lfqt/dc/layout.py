"""The triangle structure of the divide and conquer (Triangle's, flat).

One int array ``T`` holds 6 entries per triangle: ``T[6t + i]`` (i = 0, 1, 2)
are its vertices, counter-clockwise, and ``T[6t + 3 + i]`` the twin of its
half-edge ``4t + i``, which runs from vertex i to vertex i+1::

              v2
             /  ^
      4t+2  /    \\  4t+1          half-edge 4t+i: v_i -> v_(i+1)
           v      \\               twin(4t+i) = T[6t + 3 + i]
          v0 ----> v1
              4t+0

A half-edge id keeps its triangle in the high bits and its edge in the two
low ones, so that the pointer chasing of a merge finds a triangle with a
shift and an edge with a mask (``tri``, ``nxt``, ``prv``); with ``3t + i``
each step was a division by 3, a multiply-high on the critical path.  The
ids run to 8n for n points, which sizes T's dtype (``t_dtype``).

Vertices and twins of a triangle share a cache line, which halves the misses
of the pointer chasing in a merge.  Vertex ids are positions in Morton order.
The convex hull is wrapped in *ghost* triangles ``(a, b, GHOST)``, hull edge
``b -> a``, always with the ghost vertex in slot 2, so that every partition
is a closed surface.  A partition is a row of 5 ints: the vertices with the
largest x, smallest x, largest y and smallest y (``XMAX`` ... ``YMIN``), and
``SMALL``: 1 for a lone vertex, which has no ghosts, 2 for two vertices
joined by the merge's base case (an edge between two ghosts), 3 for a
triangle of the base case (one real triangle in three ghosts), 0 for any
other partition.

The merge at split position ``p`` owns triangle slots ``2(p-1)`` and
``2(p-1)+1``, so slot ids depend only on the input, never on scheduling.
Every index goes through the unsigned helpers here (see lfqt.indexing).
"""
from collections import namedtuple

import numpy as np
from numba import njit

from ..indexing import u

GHOST = -1
XMAX, XMIN, YMAX, YMIN, SMALL = range(5)
PART = 5  # ints per partition row
STACK = 160  # partitions open at once: the quad-tree is at most 128 levels deep

# What every merge kernel reads and writes: P (n, 2) float64 points in Morton
# order, T the triangles, ghost_out[v] the ghost (w, v, GHOST) of v's
# outgoing hull edge v -> w, fmt = (coord_bits, exp_bits, mant_bits, emin,
# scale_exp) of the input format (for the level bounds), level_filter.
Mesh = namedtuple("Mesh", "P T ghost_out fmt level_filter")


def t_dtype(n):
    """The dtype of T for n points: its half-edge ids reach 4 * 2(n - 1) + 3."""
    return np.int32 if 8 * n + 8 < 2 ** 31 else np.int64


@njit(cache=True, inline="always")
def slot(t, i):
    """Index in T of entry i of triangle t (0-2 vertices, 3-5 twins)."""
    return np.uint64(6 * t + i)


@njit(cache=True, inline="always")
def edge(t, i):
    """The id of half-edge i of triangle t."""
    return 4 * t + i


@njit(cache=True, inline="always")
def tri(e):
    """The triangle of half-edge e (non-negative)."""
    return np.int64(np.uint64(e) >> np.uint64(2))


@njit(cache=True, inline="always")
def nxt(e):
    """The half-edge after e in its triangle (branch-free)."""
    return e + 1 - 3 * ((e & 3) == 2)


@njit(cache=True, inline="always")
def prv(e):
    """The half-edge before e in its triangle (branch-free)."""
    return e - 1 + 3 * ((e & 3) == 0)


@njit(cache=True, inline="always")
def origin(e):
    """Index in T of the origin vertex of half-edge e (4t + i -> 6t + i)."""
    v = np.uint64(e)
    return np.uint64(6) * (v >> np.uint64(2)) + (v & np.uint64(3))


@njit(cache=True, inline="always")
def twin(e):
    """Index in T of the twin of half-edge e."""
    return origin(e) + np.uint64(3)


# A ghost g = (w, v, GHOST) stands for the hull edge v -> w (ghost_out[v] = g)::
#
#          inside
#      v ---------> w          slot 0: w, the edge's head; slot 1: v, its tail
#       \   g     /           twin 3 (across w -> v): the real triangle's v -> w
#        \       /            twin 4 (across v -> GHOST): the ghost before g
#          GHOST               twin 5 (across GHOST -> w): the ghost after g
#
# "before" and "after" run counter-clockwise around the hull.  The helpers
# below name these reads.


@njit(cache=True, inline="always")
def head(T, g):
    """The head w of ghost g's hull edge v -> w."""
    return T[slot(g, 0)]


@njit(cache=True, inline="always")
def tail(T, g):
    """The tail v of ghost g's hull edge v -> w."""
    return T[slot(g, 1)]


@njit(cache=True, inline="always")
def inner(T, g):
    """The half-edge v -> w of the real triangle across ghost g's hull edge."""
    return T[slot(g, 3)]


@njit(cache=True, inline="always")
def ring_edge(T, g, ccw):
    """The half-edge of the ghost before g (ccw = 0: the ghost of the hull
    edge into g's tail) or after it (ccw = 1: of the edge out of its head)
    that is g's twin."""
    return T[slot(g, 4 + ccw)]


@njit(cache=True, inline="always")
def ring_ghost(T, g, ccw):
    """The ghost before g (ccw = 0) or after it (ccw = 1) on the hull."""
    return tri(ring_edge(T, g, ccw))


@njit(cache=True, inline="always")
def link(T, t, i, b):
    """Make edge i of triangle t and the half-edge b each other's twin.
    Taking the known edge as (t, i) spares the decoding of an id."""
    T[slot(t, 3 + i)] = b
    T[twin(b)] = edge(t, i)


@njit(cache=True, inline="always")
def link_edges(T, t, i, w, j):
    """Make edge i of triangle t and edge j of triangle w each other's twin."""
    T[slot(t, 3 + i)] = edge(w, j)
    T[slot(w, 3 + j)] = edge(t, i)


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


@njit(cache=True, inline="always")
def before(P, a, b, axis):
    """less for vertices a and b of P, without a branch: where which comes
    first is a coin toss (the merge's extremes), ``less``'s short-circuits
    mispredict half the time (docs/performance.md, "branch-free before")."""
    ka, kb = P[u(a), axis], P[u(b), axis]
    ta, tb = P[u(a), 1 - axis], P[u(b), 1 - axis]
    if axis == 1:
        ta, tb = -ta, -tb
    return (ka < kb) | ((ka == kb) & (ta < tb))
