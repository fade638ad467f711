"""Insertion orders for incremental Delaunay (Liu et al. 2013, and peers).

Every order is data: ``(perm, hint)`` int64 arrays, where ``perm[k]`` is the
input index inserted k-th and ``hint[k]`` the input index of an already
inserted point to start locating from (-1: none).

* ``kdtree``: breadth-first labels of a Kd-tree built by cutting the longest
  edge of each subset's bounding box at the median (O(n) selection per node,
  O(n log n) in all; subtrees of up to PRESORTED points from their points
  sorted along every axis); hint = parent (paper Appendix I), or the left
  sibling for right children with ``hint="sibling"``.
* ``kdtree-alternate``: the same with the cyclic x, y(, z) rule, which the
  paper found slower (ablation).
* ``hilbert``: CGAL-style median Hilbert sort: split at the median along x,
  then each half along y (and z), recursing into the 4 (8) parts with the
  axes and directions of the Hilbert curve; adapts to the points' density.
* ``hilbert-grid``: paper 2's variant: points sorted by the index of their
  cell on a Hilbert curve of the bounding cube cut into (2^k)^d cells.
* ``brio``: shuffle, then rounds of geometrically growing size (ratio 0.25
  in 2D, 0.125 in 3D), each round median-Hilbert sorted (Amenta et al.;
  CGAL's multiscale sort).
* ``random`` and ``input``.

For every order but the Kd ones the hint is the point inserted just before.

``layout`` adds a permutation along space to lay the points out in memory
by, whatever order inserts them: the Kd-tree's in-order comes free with the
Kd orders, the Hilbert order with "hilbert", a coarse Hilbert sort otherwise.
"""
from __future__ import annotations

from collections import namedtuple
from typing import Literal, get_args

import numpy as np
import numpy.typing as npt
from numba import njit
from numba.cpython.unsafe.numbers import leading_zeros

from ._input import index_dtype
from .indexing import random_index, range_seed, u
from .morton import ordered_bits64
from .radix import radix_sort_range
from .triangulation import IndexArray
from .workers import Workers

OrderName = Literal["kdtree", "kdtree-alternate", "hilbert", "hilbert-grid", "brio", "random",
                    "input"]
Hint = Literal["parent", "sibling"]
ORDERS: tuple[OrderName, ...] = get_args(OrderName)
Order = tuple[npt.NDArray[np.int64], npt.NDArray[np.int64]]  # (perm, hint)
Layout = tuple[npt.NDArray[np.int64], npt.NDArray[np.int64], IndexArray,
               npt.NDArray[np.float64]]  # (perm, hint, store, stored): layout
BRIO_RATIO = {2: 0.25, 3: 0.125}
BRIO_MIN_ROUND = 64


@njit(cache=True, inline="always")
def _swap_rows(X, ids, i, j):
    t = ids[u(i)]
    ids[u(i)] = ids[u(j)]
    ids[u(j)] = t
    for a in range(X.shape[1]):
        v = X[u(i), a]
        X[u(i), a] = X[u(j), a]
        X[u(j), a] = v


@njit(cache=True, inline="always")
def _before(X, ids, i, axis, pv, pi):
    """Row i comes before the pivot (value pv, id pi): by value, ties by id.
    Without short-circuits, so that it compiles to no branch."""
    v = X[u(i), axis]
    return (v < pv) | ((v == pv) & (ids[u(i)] < pi))


_BLOCK = 64  # rows classified per block of the branch-free partition


@njit(cache=True, inline="always")
def _partition(X, ids, a, b, axis, pv, pi, off):
    """Partition rows [a, b) into those before the pivot, then the others;
    returns where the others start.  Blocks of rows are classified without
    branches into offset buffers (``off``: the left block's in its first
    _BLOCK entries, the right one's in the rest), and only misplaced rows
    are swapped, in
    pairs (BlockQuicksort, Edelkamp and Weiss 2016): a comparison that goes
    either way at random costs no misprediction::

        [ before | left block ->  ...  <- right block | not before ]
          a        l                                r              b
    """
    l = a
    r = b
    n_l = n_r = s_l = s_r = 0
    while r - l > 2 * _BLOCK:
        if n_l == 0:
            s_l = 0
            for j in range(_BLOCK):
                off[n_l] = j
                n_l += not _before(X, ids, l + j, axis, pv, pi)
        if n_r == 0:
            s_r = 0
            for j in range(_BLOCK):
                off[_BLOCK + n_r] = j
                n_r += _before(X, ids, r - 1 - j, axis, pv, pi)
        m = min(n_l, n_r)
        for j in range(m):
            _swap_rows(X, ids, l + off[s_l + j], r - 1 - off[_BLOCK + s_r + j])
        n_l -= m
        n_r -= m
        s_l += m
        s_r += m
        if n_l == 0:
            l += _BLOCK
        if n_r == 0:
            r -= _BLOCK
    # the rest, half-classified blocks included: [a, l) is before, [r, b) not
    for j in range(l, r):  # Lomuto's, swapping always: [l, j) is not before
        before = _before(X, ids, j, axis, pv, pi)
        _swap_rows(X, ids, l, j)
        l += before
    return l


@njit(cache=True, inline="always")
def _split(X, ids, lo, hi, p, axis, off):
    """One round of selection: partition rows [lo, hi) about row p's value
    (and id); returns the pivot's place, with the rows before it in front."""
    _swap_rows(X, ids, p, hi - 1)  # the pivot waits at the end while the rest is split
    pv, pi = X[u(hi - 1), axis], ids[u(hi - 1)]
    at = _partition(X, ids, lo, hi - 1, axis, pv, pi, off)
    _swap_rows(X, ids, at, hi - 1)
    return at


@njit(cache=True, inline="always")
def _narrowed(k, at, lo, hi):
    """The part of [lo, hi) that holds rank k after a round that put its
    pivot at ``at``: [k, k + 1), one row, when that is k."""
    if k < at:
        return lo, at
    if k > at:
        return at + 1, hi
    return k, k + 1


@njit(cache=True, inline="always")
def _rounds_budget(size):
    """Selection rounds allowed before pseudo-random pivots (_select_axis):
    twice the depth of a balanced recursion over ``size`` rows, plus 8."""
    return 2 * (64 - leading_zeros(np.uint64(size))) + 8


@njit(cache=True)
def _select_axis(X, ids, lo, hi, k, axis, off, budget=-1):
    """Partition rows [lo, hi) of X (coordinates, kept in step with ids) by
    X[:, axis] so that row k holds the element of rank k - lo
    (nth_element); ties broken by id for determinism.  Moving the
    coordinates with the ids keeps every pass sequential in memory.
    off: scratch for 2 * _BLOCK offsets (_partition), allocated once by the
    caller for all its selections.

    Long ranges take their pivots from a sample (_sampled_pivot) while they
    are long, short ones median of three (_select_short).  Both suit
    ordinary and sorted data, but inputs exist that make them quadratic: a
    ``budget`` of rounds (default: twice the depth of a balanced recursion
    plus 8, which ordinary data does not reach) bounds them, after which the
    pivots are pseudo-random rows (splitmix64 of the range), expected linear
    on any input.  The guard measured free (1M points, 2D and 3D, min of 7)."""
    if budget < 0:
        budget = _rounds_budget(hi - lo)
    while hi - lo >= _SAMPLED and budget > 0:
        budget -= 1
        at = _split(X, ids, lo, hi, _sampled_pivot(X, ids, lo, hi, k, axis, off), axis, off)
        lo, hi = _narrowed(k, at, lo, hi)
    _select_short(X, ids, lo, hi, k, axis, off, budget)


@njit(cache=True)
def _select_short(X, ids, lo, hi, k, axis, off, budget):
    """_select_axis's rounds with median-of-three pivots (pseudo-random ones
    past ``budget`` rounds)."""
    state = range_seed(lo, hi)
    while hi - lo > 1:
        budget -= 1
        if budget < 0:
            state, p = random_index(state, lo, hi)
        else:
            p = _median_of_three(X, lo, hi, axis)
        lo, hi = _narrowed(k, _split(X, ids, lo, hi, p, axis, off), lo, hi)


@njit(cache=True, inline="always")
def _median_of_three(X, lo, hi, axis):
    """The row of the median of rows lo, mid, hi - 1's values."""
    mid = (lo + hi) >> 1
    va, vb, vc = X[u(lo), axis], X[u(mid), axis], X[u(hi - 1), axis]
    if (va <= vb) == (vb <= vc):
        return mid
    if (vb <= va) == (va <= vc):
        return lo
    return hi - 1


_SAMPLED = 4096  # ranges at least this long take their pivot from a sample


@njit(cache=True)
def _sampled_pivot(X, ids, lo, hi, k, axis, off):
    """The row of a pivot for rank k of rows [lo, hi): in a sample of
    sqrt(hi - lo) rows spread over the range, the row a few of the sample's
    standard deviations past k's quantile, on the side away from the
    range's nearer end, so that k falls in the smaller part with high
    probability (Floyd and Rivest 1975)::

        [ .....  k  ^  ..................... ]   k near the low end:
                  pivot                         keep [lo, pivot)
        [ ..................... ^  k  .....  ]   near the high end:
                              pivot             keep (pivot, hi)

    A median selection then partitions the whole range about 1.5 times
    (once, then the larger half once more), where median of three takes
    about 3.  The sample's rows are copied with their positions, and
    selected by value and id like the range itself (by _select_short: a
    numba function that calls itself back does not survive its cache)."""
    size = hi - lo
    s = np.int64(np.sqrt(size))
    step = size // s
    sample = np.empty((s, 2))
    sample_ids = np.empty(s, dtype=ids.dtype)
    for j in range(s):
        row = lo + j * step + (step >> 1)
        sample[j, 0] = X[u(row), axis]
        sample[j, 1] = row
        sample_ids[j] = ids[u(row)]
    f = (k - lo) / size
    gap = 1.5 * np.sqrt(s)  # three standard deviations of a median's sample rank
    j = np.int64(f * s + gap) if f < 0.5 else np.int64(f * s - gap)
    j = min(max(j, 0), s - 1)
    # int64 zeros, not literals: literals would compile _select_short again (1 s)
    zero = np.int64(0)
    _select_short(sample, sample_ids, zero, s, j, zero, off, _rounds_budget(s))
    return np.int64(sample[j, 1])


# Without NaN and infinities (validated input), min and max reduce in
# vector registers; without reassociation every value is still IEEE's.
_NO_NAN = {"nnan", "ninf", "nsz"}


@njit(cache=True, inline="always")
def _axis_of(w0, w1, w2):
    """The axis of the longest of a box's edges w0, w1, w2 (the first among equals)."""
    if w2 > w0 and w2 > w1:
        return 2
    return 1 if w1 > w0 else 0


@njit(cache=True, fastmath=_NO_NAN)
def _longest_axis(X, lo, hi):
    """The axis of the longest edge of the bounding box of rows [lo, hi)
    of X (the first, among equals).  One running minimum and maximum per
    axis, written out for 2 and 3 axes so that they stay in registers (the
    scan runs over every point at every level of the Kd-tree)."""
    d = X.shape[1]  # 2 or 3 (_order)
    lo0 = hi0 = X[u(lo), 0]
    lo1 = hi1 = X[u(lo), 1]
    lo2 = hi2 = X[u(lo), 2] if d > 2 else 0.0
    for t in range(lo + 1, hi):
        lo0 = min(lo0, X[u(t), 0])
        hi0 = max(hi0, X[u(t), 0])
        lo1 = min(lo1, X[u(t), 1])
        hi1 = max(hi1, X[u(t), 1])
        if d > 2:
            lo2 = min(lo2, X[u(t), 2])
            hi2 = max(hi2, X[u(t), 2])
    return _axis_of(hi0 - lo0, hi1 - lo1, hi2 - lo2)


# Kd subtrees of at most this many points are built from their points sorted
# along every axis (_presorted_subtree), larger nodes by selection.  2**14
# was the fastest size measured; 2**16 no longer stays in a core's cache
# (docs/performance.md, "presorted subtrees").
PRESORTED = 1 << 14
_KEY_BITS = 32  # of the coordinates' varying bits, sorted by radix (_sorted_lists)

# _presorted_subtree's arrays, for subtrees of up to ``size`` points:
# keys, key_buf, perm_buf: a radix sort's; lists (2, d, size + 1): every
# node's list along each axis, in one of two buffers; rank (d, size): each
# point's place in the subtree's sorted list along each axis; out: the
# in-order; rows, row_ids: the rows in it; stack: pending nodes.
Presorted = namedtuple("Presorted", "keys key_buf perm_buf lists rank out rows row_ids stack")


@njit(cache=True)
def _presorted_arrays(size, d, ids_dtype):
    return Presorted(np.empty(size, dtype=np.uint64), np.empty(size, dtype=np.uint64),
                     np.empty(size, dtype=np.int32), np.empty((2, d, size + 1), dtype=np.int32),
                     np.empty((d, size), dtype=np.int32), np.empty(size, dtype=np.int32),
                     np.empty((size, d)), np.empty(size, dtype=ids_dtype),
                     np.empty((4, 66), dtype=np.int64))


@njit(cache=True)
def _sorted_lists(X, ids, lo0, s, ws):
    """ws.lists[0, a]: the points lo0 + k, k < s, as their k, sorted along
    axis a by value, equal values by id (the order of _before); ws.rank[a]:
    each k's place in that list.  A radix sort, stable, of the values'
    order-preserving bits (-0.0 like 0.0) cut to the highest _KEY_BITS
    that vary among them, then the rare runs of equal keys insertion-sorted
    by value and id: fewer scatters per axis (docs/performance.md, "cut
    keys")."""
    d = X.shape[1]
    keys = ws.keys
    for a in range(d):
        L = ws.lists[0, a]
        first = ordered_bits64(np.float64(X[u(lo0), a]).view(np.uint64))
        differ = np.uint64(0)
        for k in range(s):
            keys[k] = ordered_bits64(np.float64(X[u(lo0 + k), a]).view(np.uint64))
            differ |= keys[k] ^ first
            L[k] = k
        varying = 64 - leading_zeros(differ) if differ else 0
        if varying > _KEY_BITS:
            cut = np.uint64(varying - _KEY_BITS)
            for k in range(s):
                keys[k] >>= cut
        radix_sort_range(keys, L, 0, s, ws.key_buf, ws.perm_buf)
        k = 0
        while k < s:
            e = k + 1
            while e < s and keys[e] == keys[k]:
                e += 1
            for i in range(k + 1, e):
                v = L[i]
                value, id_ = X[u(lo0 + v), a], ids[u(lo0 + v)]
                j = i
                while j > k and not _before(X, ids, lo0 + L[j - 1], a, value, id_):
                    L[j] = L[j - 1]
                    j -= 1
                L[j] = v
            k = e
        R = ws.rank[a]
        for k in range(s):
            R[L[k]] = k


@njit(cache=True)
def _presorted_subtree(X, ids, lo0, hi0, depth0, alternate, ws):
    """_kdtree_inorder's work for the subtree of rows [lo0, hi0) at depth
    depth0, from the lists of its points sorted along each axis
    (_sorted_lists).  A node's bounding box is its lists' ends, its median
    the middle of its axis's list, and its children's lists along that axis
    the halves as they stand; along every other axis its list is split by
    each point's rank along the cut axis, stably, so that each half stays
    sorted, into the other of two buffers::

        cut axis a    [ 3 7 1 | 5 | 0 6 2 ]          (ranks along a: 0 .. 6)
        axis b        [ 0 7 5 3 6 1 2 ]  ->  [ 7 3 1 | . | 0 6 2 ]

    A level then moves d - 1 lists, without a comparison that can go either
    way at random, where a selection compares and swaps rows about 2.5
    times over.  Bit a of a node's ``where`` tells which buffer holds its
    list along axis a.  The rows are put in in-order once, at the end."""
    s = hi0 - lo0
    d = X.shape[1]
    _sorted_lists(X, ids, lo0, s, ws)
    lists, rank, out, stack = ws.lists, ws.rank, ws.out, ws.stack
    top = 1
    stack[0, 0], stack[1, 0], stack[2, 0], stack[3, 0] = 0, s, 0, 0
    while top > 0:
        top -= 1
        lo, hi, t, where = stack[0, top], stack[1, top], stack[2, top], stack[3, top]
        if alternate:
            axis = (depth0 + t) % d
        else:
            L0 = lists[where & 1, 0]
            L1 = lists[(where >> 1) & 1, 1]
            w0 = X[u(lo0 + L0[hi - 1]), 0] - X[u(lo0 + L0[lo]), 0]
            w1 = X[u(lo0 + L1[hi - 1]), 1] - X[u(lo0 + L1[lo]), 1]
            w2 = 0.0
            if d > 2:
                L2 = lists[(where >> 2) & 1, 2]
                w2 = X[u(lo0 + L2[hi - 1]), 2] - X[u(lo0 + L2[lo]), 2]
            axis = _axis_of(w0, w1, w2)
        m = lo + (hi - lo) // 2
        A = lists[(where >> axis) & 1, axis]
        out[m] = A[m]
        if m - lo == 1:  # a child of one point is that point
            out[lo] = A[lo]
        if hi - m == 2:
            out[hi - 1] = A[hi - 1]
        if hi - lo < 4:  # no child of two points or more
            continue
        R = rank[axis]
        r_median = R[A[m]]
        for b in range(d):
            if b == axis:
                continue
            src = lists[(where >> b) & 1, b]
            dst = lists[1 - ((where >> b) & 1), b]
            left = lo
            right = m + 1
            for k in range(lo, hi):
                v = src[k]
                r = R[v]
                # written to both halves, kept in one: no branch.  Past
                # either half's end lies the median's place or, at most,
                # the list's spare last entry, which no node reads
                dst[left] = v
                dst[right] = v
                left += r < r_median
                right += r > r_median
        children = where ^ (((1 << d) - 1) ^ (1 << axis))
        if hi - m > 2:
            stack[0, top], stack[1, top], stack[2, top], stack[3, top] = m + 1, hi, t + 1, children
            top += 1
        if m - lo > 1:
            stack[0, top], stack[1, top], stack[2, top], stack[3, top] = lo, m, t + 1, children
            top += 1
    rows, row_ids = ws.rows, ws.row_ids
    for k in range(s):
        for a in range(d):
            rows[k, a] = X[u(lo0 + out[k]), a]
        row_ids[k] = ids[u(lo0 + out[k])]
    for k in range(s):
        for a in range(d):
            X[u(lo0 + k), a] = rows[k, a]
        ids[u(lo0 + k)] = row_ids[k]


@njit(cache=True, nogil=True)
def _kdtree_inorder(X, ids, alternate, presorted, root):
    """Every selection of the Kd-tree on rows of X (kept in step with ids)
    in the subtree root = (lo, hi, depth), depth first: each node's rows
    [lo, hi) split at their median lo + (hi - lo) // 2 along its axis, and
    then its children's.  The tree's shape follows from n alone, so the
    order of the selections is free: depth first, a node's rows are still
    in cache for its children, and a subtree of at most ``presorted``
    points is built whole from its points sorted along every axis
    (_presorted_subtree; 0: every node by selection).  A stack of pending
    nodes never holds more than the depth + 1."""
    n, d = X.shape
    off = np.empty(2 * _BLOCK, dtype=np.int64)
    ws = _presorted_arrays(min(presorted, n), d, ids.dtype)
    s_lo = np.empty(66, dtype=np.int64)
    s_hi = np.empty(66, dtype=np.int64)
    s_depth = np.empty(66, dtype=np.int64)
    top = 0
    if root[1] - root[0] > 1:
        s_lo[0], s_hi[0], s_depth[0] = root
        top = 1
    while top > 0:
        top -= 1
        lo, hi, depth = s_lo[top], s_hi[top], s_depth[top]
        if hi - lo <= presorted:
            _presorted_subtree(X, ids, lo, hi, depth, alternate, ws)
            continue
        axis = depth % d if alternate else _longest_axis(X, lo, hi)
        m = lo + (hi - lo) // 2
        _select_axis(X, ids, lo, hi, m, axis, off)
        if hi - m - 1 > 1:
            s_lo[top], s_hi[top], s_depth[top] = m + 1, hi, depth + 1
            top += 1
        if m - lo > 1:
            s_lo[top], s_hi[top], s_depth[top] = lo, m, depth + 1
            top += 1


@njit(cache=True)
def _kdtree_top(X, ids, alternate, count, smallest):
    """The selections of the Kd-tree's top levels, breadth first, until
    there are ``count`` subtrees below them or one has ``smallest`` rows
    or fewer: returns the subtrees' (lo, hi, depth) rows, which
    _kdtree_inorder builds apart."""
    d = X.shape[1]
    off = np.empty(2 * _BLOCK, dtype=np.int64)
    nodes = [(np.int64(0), np.int64(X.shape[0]), np.int64(0))]
    while len(nodes) < count and nodes[0][1] - nodes[0][0] > smallest:
        lo, hi, depth = nodes.pop(0)
        axis = depth % d if alternate else _longest_axis(X, lo, hi)
        m = lo + (hi - lo) // 2
        _select_axis(X, ids, lo, hi, m, axis, off)
        nodes.append((lo, m, depth + 1))
        nodes.append((m + 1, hi, depth + 1))
    out = np.empty((len(nodes), 3), dtype=np.int64)
    for k in range(len(nodes)):
        out[k, 0], out[k, 1], out[k, 2] = nodes[k]
    return out


def kdtree_order(P: npt.NDArray[np.float64], alternate: bool, sibling: bool,
                 presorted: int = PRESORTED, threads: int = 1) -> Layout:
    """(perm, hint, inorder, P[inorder]): the breadth-first labels and
    their hints, the ids as _kdtree_inorder leaves them, the tree's
    in-order: every subtree a contiguous range with its median in the
    middle::

        inorder   [ left subtree | median | right subtree ]
                    [ l | m | r ]            [ l | m | r ]

    and the rows of P in that order, which it leaves too.  numpy allocates
    the arrays (it asks for huge pages for large ones itself; lfqt.pages
    measured no faster here).  ``presorted``: the size of the subtrees built
    from sorted lists (_kdtree_inorder); the tree is the same whatever it
    is.  ``threads``: the subtrees below the top levels are built on that
    many threads (_kdtree_top); the tree is the same."""
    n = len(P)
    ids, X = np.arange(n, dtype=index_dtype(n)), P.copy()
    perm, hint, q_lo, q_hi = (np.empty(n, dtype=np.int64) for _ in range(4))
    if threads > 1 and n > 4 * max(presorted, 1):
        roots = _kdtree_top(X, ids, alternate, 4 * threads, 2 * max(presorted, 1))
        Workers(threads).each(lambda r: _kdtree_inorder(X, ids, alternate, presorted, r),
                              [tuple(int(v) for v in row) for row in roots])
    else:
        _kdtree_inorder(X, ids, alternate, presorted, (0, n, 0))
    _kdtree_order(X, ids, perm, hint, q_lo, q_hi, sibling)
    return perm, hint, ids, X


@njit(cache=True, nogil=True)
def _kdtree_order(X, ids, perm, hint, q_lo, q_hi, sibling):
    n = X.shape[0]
    # Breadth-first queue of ranges; a node's label is its queue slot.  Its
    # point, and its left sibling's, are medians of known ranges of the
    # in-order, so a child's hint is written when it is queued.
    head = 0
    tail = 0
    if n:
        q_lo[0], q_hi[0], hint[0] = 0, n, -1
        tail = 1
    while head < tail:
        lo, hi = q_lo[head], q_hi[head]
        m = lo + (hi - lo) // 2
        v = ids[m]
        perm[head] = v
        left = -1  # the left child's point
        if m > lo:
            q_lo[tail], q_hi[tail], hint[tail] = lo, m, v
            left = ids[lo + (m - lo) // 2]
            tail += 1
        if hi > m + 1:
            q_lo[tail], q_hi[tail] = m + 1, hi
            hint[tail] = left if (sibling and left >= 0) else v
            tail += 1
        head += 1


@njit(cache=True, inline="always")
def _exchange(X0, Xi, Q):
    """One step of Skilling's transform at bit Q: axis i against axis 0 (an
    inversion of X0's low bits, or an exchange of the low bits where they
    differ).  Axis 0 against itself is the inversion or nothing."""
    P_ = Q - 1
    if Xi & Q:
        return X0 ^ P_, Xi
    t = (X0 ^ Xi) & P_
    return X0 ^ t, Xi ^ t


@njit(cache=True, inline="always")
def _gray_mask(last, M):
    """The mask that Skilling's transform xors into every axis after the Gray
    encoding, from the last axis."""
    t = 0
    Q = M
    while Q > 1:
        if last & Q:
            t ^= Q - 1
        Q >>= 1
    return t


@njit(cache=True, inline="always")
def _hilbert_index_2d(x, y, bits):
    """Skilling's transform: Hilbert index of integer cell (x, y)."""
    X0, X1 = x, y
    M = 1 << (bits - 1)
    Q = M
    while Q > 1:
        X0, _ = _exchange(X0, X0, Q)
        X0, X1 = _exchange(X0, X1, Q)
        Q >>= 1
    X1 ^= X0
    t = _gray_mask(X1, M)
    X0 ^= t
    X1 ^= t
    h = 0
    for b in range(bits - 1, -1, -1):
        h = (h << 2) | (((X0 >> b) & 1) << 1) | ((X1 >> b) & 1)
    return h


@njit(cache=True, inline="always")
def _hilbert_index_3d(x, y, z, bits):
    """Skilling's transform: Hilbert index of integer cell (x, y, z).  In
    scalars: a small array per call costs a heap allocation, which made the
    keys of a million points take 0.1 s."""
    X0, X1, X2 = x, y, z
    M = 1 << (bits - 1)
    Q = M
    while Q > 1:
        X0, _ = _exchange(X0, X0, Q)
        X0, X1 = _exchange(X0, X1, Q)
        X0, X2 = _exchange(X0, X2, Q)
        Q >>= 1
    X1 ^= X0
    X2 ^= X1
    t = _gray_mask(X2, M)
    X0 ^= t
    X1 ^= t
    X2 ^= t
    h = 0
    for b in range(bits - 1, -1, -1):
        h = (h << 3) | (((X0 >> b) & 1) << 2) | (((X1 >> b) & 1) << 1) | ((X2 >> b) & 1)
    return h


@njit(cache=True)
def hilbert_keys(P, ids, bits=0):
    """Hilbert index of each point's cell in the bounding cube of P[ids]
    cut into (2^k)^d cells (k = ``bits``, default 31 in 2D, 21 in 3D)."""
    n = ids.shape[0]
    d = P.shape[1]
    if bits == 0:
        bits = 31 if d == 2 else 21
    lo = np.full(d, np.inf)
    hi = np.full(d, -np.inf)
    for t in range(n):
        for a in range(d):
            v = P[ids[t], a]
            lo[a] = min(lo[a], v)
            hi[a] = max(hi[a], v)
    span = 0.0
    for a in range(d):
        span = max(span, hi[a] - lo[a])
    scale = ((1 << bits) - 1) / span if span > 0 else 0.0
    keys = np.empty(n, dtype=np.int64)
    for t in range(n):
        c0 = min(int((P[ids[t], 0] - lo[0]) * scale), (1 << bits) - 1)
        c1 = min(int((P[ids[t], 1] - lo[1]) * scale), (1 << bits) - 1)
        if d == 2:
            keys[t] = _hilbert_index_2d(c0, c1, bits)
        else:
            c2 = min(int((P[ids[t], 2] - lo[2]) * scale), (1 << bits) - 1)
            keys[t] = _hilbert_index_3d(c0, c1, c2, bits)
    return keys


@njit(cache=True)
def _median_split(ids, lo, hi, X, axis, up, off):
    """Split rows [lo, hi) of X and ids at their median along ``axis``: the
    lower half first when ``up``, the upper half first otherwise; returns
    the split position.  off: _select_axis's scratch."""
    if hi - lo < 2:
        return lo + (hi - lo) // 2
    mid = lo + (hi - lo) // 2
    _select_axis(X, ids, lo, hi, mid, axis, off)
    if up:
        return mid
    i = lo
    j = hi - 1
    while i < j:
        _swap_rows(X, ids, i, j)
        i += 1
        j -= 1
    return lo + (hi - mid)


@njit(cache=True, nogil=True)
def _hilbert_median_2d(X, ids, lo, hi, x, upx, upy, off):
    if hi - lo <= 1:
        return
    y = 1 - x
    m2 = _median_split(ids, lo, hi, X, x, upx, off)
    m1 = _median_split(ids, lo, m2, X, y, upy, off)
    m3 = _median_split(ids, m2, hi, X, y, not upy, off)
    _hilbert_median_2d(X, ids, lo, m1, y, upy, upx, off)
    _hilbert_median_2d(X, ids, m1, m2, x, upx, upy, off)
    _hilbert_median_2d(X, ids, m2, m3, x, upx, upy, off)
    _hilbert_median_2d(X, ids, m3, hi, y, not upy, not upx, off)


@njit(cache=True, nogil=True)
def _hilbert_median_3d(X, ids, lo, hi, x, upx, upy, upz, off):
    if hi - lo <= 1:
        return
    y = (x + 1) % 3
    z = (x + 2) % 3
    m4 = _median_split(ids, lo, hi, X, x, upx, off)
    m2 = _median_split(ids, lo, m4, X, y, upy, off)
    m1 = _median_split(ids, lo, m2, X, z, upz, off)
    m3 = _median_split(ids, m2, m4, X, z, not upz, off)
    m6 = _median_split(ids, m4, hi, X, y, not upy, off)
    m5 = _median_split(ids, m4, m6, X, z, upz, off)
    m7 = _median_split(ids, m6, hi, X, z, not upz, off)
    _hilbert_median_3d(X, ids, lo, m1, z, upz, upx, upy, off)
    _hilbert_median_3d(X, ids, m1, m2, y, upy, upz, upx, off)
    _hilbert_median_3d(X, ids, m2, m3, y, upy, upz, upx, off)
    _hilbert_median_3d(X, ids, m3, m4, x, upx, not upy, not upz, off)
    _hilbert_median_3d(X, ids, m4, m5, x, upx, not upy, not upz, off)
    _hilbert_median_3d(X, ids, m5, m6, y, not upy, upz, not upx, off)
    _hilbert_median_3d(X, ids, m6, m7, y, not upy, upz, not upx, off)
    _hilbert_median_3d(X, ids, m7, hi, z, not upz, not upx, upy, off)


def _hilbert_sorted(P, ids, grid=False):
    """ids in Hilbert order: median policy (CGAL's) or grid cells (paper 2)."""
    if grid:
        return ids[sorted_by_key(hilbert_keys(P, ids))]
    ids = np.array(ids, dtype=np.int64)
    X = np.take(P, ids, axis=0)  # rows: a fraction of fancy indexing's time
    off = np.empty(2 * _BLOCK, dtype=np.int64)
    if P.shape[1] == 2:
        _hilbert_median_2d(X, ids, 0, len(ids), 0, True, True, off)
    else:
        _hilbert_median_3d(X, ids, 0, len(ids), 0, True, True, True, off)
    return ids


def sorted_by_key(keys: npt.NDArray[np.int64]) -> npt.NDArray[np.int64]:
    """Stable argsort of non-negative int64 keys by radix sort."""
    sorted_keys = keys.view(np.uint64).copy()
    perm = np.arange(len(keys), dtype=np.int64)
    radix_sort_range(sorted_keys, perm, 0, len(keys), np.empty_like(sorted_keys),
                     np.empty_like(perm))
    return perm


def _previous_as_hint(perm):
    hint = np.empty_like(perm)
    if len(perm):
        hint[0] = -1
        hint[1:] = perm[:-1]
    return hint


def order(points: npt.ArrayLike, name: OrderName = "kdtree", *, hint: Hint = "parent",
          seed: int = 0) -> Order:
    """(perm, hint) for inserting ``points`` (n, d) in order ``name``.

    Parameters
    ----------
    points : array_like, shape (n, 2) or (n, 3)
        Read as float64.
    name : {"kdtree", "kdtree-alternate", "hilbert", "hilbert-grid", "brio", "random", "input"}
        The order (the module's docstring describes each).
    hint : {"parent", "sibling"}
        For the Kd orders: each point's hint is its parent in the Kd-tree,
        or, for a right child, its left sibling.
    seed : int
        For "brio" and "random".

    Returns
    -------
    perm : ndarray of int64, shape (n,)
        ``perm[k]``: the input index inserted k-th.
    hint : ndarray of int64, shape (n,)
        ``hint[k]``: the input index of a point inserted before
        ``perm[k]`` to start locating it from, -1 for none.

    Examples
    --------
    >>> import numpy as np
    >>> from lfqt import orders
    >>> p = np.random.default_rng(0).random((1000, 3))
    >>> perm, hint = orders.order(p, "kdtree")
    >>> sorted(perm.tolist()) == list(range(1000))
    True
    >>> int(hint[0]), bool(hint[1] == hint[2] == perm[0])  # the root, then its children
    (-1, True)
    >>> perm, hint = orders.order(p, "brio", seed=1)
    >>> np.array_equal(hint[1:], perm[:-1])  # the point inserted just before
    True
    """
    return _order(points, name, hint, seed)[:2]


def layout(points: npt.ArrayLike, name: OrderName = "kdtree", *, hint: Hint = "parent",
           seed: int = 0, threads: int = 1) -> Layout:
    """(perm, hint, store, stored): ``order``'s pair, ``store``, a
    permutation of the points along space to lay them out in memory by (the
    Kd-tree's in-order, the Hilbert order itself, or a coarse Hilbert sort),
    and ``stored``, the points (float64 rows) in that order, which the Kd
    orders leave behind for free.  ``store`` is int32 below 2**31 points
    (index_dtype): the output maps every vertex of every cell through it, at
    random, and half the bytes miss the cache half as often
    (docs/performance.md, "int32 store").

    Parameters and ``perm``, ``hint``: as ``order``'s.

    Returns
    -------
    perm, hint : ndarray of int64, shape (n,)
    store : ndarray of int32 or int64, shape (n,)
    stored : ndarray of float64, shape (n, d)
        ``points[store]``.

    Examples
    --------
    >>> import numpy as np
    >>> from lfqt import orders
    >>> p = np.random.default_rng(0).random((1000, 2))
    >>> perm, hint, store, stored = orders.layout(p, "random")
    >>> store.dtype, np.array_equal(stored, p[store])
    (dtype('int32'), True)
    """
    P = np.ascontiguousarray(points, dtype=np.float64)  # once: _order's is then free
    perm, h, store, stored = _order(P, name, hint, seed, threads)
    if store is None:
        # Cells of 2^-16 (2D) or 2^-10 (3D) of the bounding box are fine
        # enough for locality, and cheaper to index than 31/21 bits.
        bits = 16 if P.shape[1] == 2 else 10
        store = (sorted_by_key(hilbert_keys(P, np.arange(len(P)), bits)) if len(P)
                 else np.arange(0))
    if stored is None:
        stored = np.take(P, store, axis=0)  # a fifth of fancy indexing's time (1M rows)
    return perm, h, store.astype(index_dtype(len(P)), copy=False), stored


def _order(points, name, hint, seed, threads=1):
    """(perm, hint, store, stored), the last two None when the order does
    not give them for free (layout)."""
    P = np.ascontiguousarray(points, dtype=np.float64)
    n = len(P)
    if P.ndim != 2 or P.shape[1] not in (2, 3):
        raise ValueError(f"points must have shape (n, 2) or (n, 3), got {P.shape}")
    if name not in ORDERS:
        raise ValueError(f"unknown order {name!r}; known: {', '.join(ORDERS)}")
    if hint not in ("parent", "sibling"):
        raise ValueError("hint must be 'parent' or 'sibling'")
    if name in ("kdtree", "kdtree-alternate"):
        return kdtree_order(P, name == "kdtree-alternate", hint == "sibling", threads=threads)
    rng = np.random.default_rng(seed)
    store = None
    if name == "input":
        perm = np.arange(n, dtype=np.int64)
    elif name == "random":
        perm = rng.permutation(n).astype(np.int64)
    elif name in ("hilbert", "hilbert-grid"):
        perm = _hilbert_sorted(P, np.arange(n, dtype=np.int64), grid=name == "hilbert-grid")
        store = perm
    else:  # brio
        shuffled = rng.permutation(n).astype(np.int64)
        ratio = BRIO_RATIO[P.shape[1]]
        cuts = [n]
        while cuts[-1] * ratio >= BRIO_MIN_ROUND:
            cuts.append(int(cuts[-1] * ratio))
        cuts.append(0)
        rounds = [shuffled[cuts[i + 1]:cuts[i]] for i in range(len(cuts) - 1)][::-1]
        perm = np.concatenate([_hilbert_sorted(P, r) for r in rounds]) if n else shuffled
    return perm, _previous_as_hint(perm), store, None
