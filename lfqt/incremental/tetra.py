"""Incremental Delaunay in 3D (Bowyer–Watson) on tetrahedron records that
name the facet they share with each neighbour, after HXT (Marot, Pellerin
and Remacle 2019).

One record of int32 per tetrahedron, 32 bytes, two to a cache line::

    tetrahedron t:  | v0 v1 v2 v3 | a0 a1 a2 a3 |
                      vertices      a_i = 4 t' + i': the tetrahedron t'
                                    across facet i (opposite v_i), whose
                                    facet i' that is

The hull is closed by *infinite* tetrahedra, whose vertex INF (-1) is
always in slot 3: (a, b, c, INF) with a point beyond the hull facet a, b, c
in place of INF positive.  Finite tetrahedra are right-handed, as in
lfqt.incremental.kernel, whose 2D kernel this one parallels and whose
conflict rule it keeps (a circumsphere *strictly* containing the point), so
both give the same tetrahedra.

What the records buy, per inserted point (about 20 tetrahedra removed and
27 made at random 3D input):

- gluing a new tetrahedron to the one outside the cavity writes the
  outside one's slot directly, where a record of neighbour ids searched
  it;
- the new tetrahedra take the removed ones' records, whose lines are in
  cache from the cavity search;
- the new tetrahedra are glued to each other through a 32 x 32 table of
  the cavity boundary's directed edges, indexed by small local vertex
  numbers, where a hash of the edges' global ids probed.

Every new tetrahedron is (p, a, b, c) with p in slot 0 and (a, b, c) a
cavity boundary triangle, counter-clockwise seen from p; INF, where there
is one, stays in slot 3.  Across facet 1 (p, b, c) lies the new
tetrahedron whose triangle has the edge c -> b, and so on round::

            a                 facet 1: edge b -> c   (opposite a)
           / \                facet 2: edge c -> a   (opposite b)
          /   \               facet 3: edge a -> b   (opposite c)
         c --- b              facet 0: the triangle itself, glued outward
"""
from collections import namedtuple

import numpy as np
from numba import njit

from .. import workspace
from ..clock import cycle_counter
from ..indexing import borrow, prefetch, u
from ..predicates.counters import (CAVITY_CYCLES, CONFLICTS, DUPLICATES, INCIRCLE, LOCATE_CYCLES,
                                   N_INSERT, N_PREDICATE, ORIENT, tally)
from ..predicates.spatial import ISP_A, O3D_A, insphere_staged, orient3d_staged
from .kernel import (DEAD, INF, LAST, NCELLS, NFREE, STAMP, WALK_AHEAD, Insertion, Run, _commit,
                     _initial_simplex, _inside_facet_circle, statics)

CELLS_PER_POINT = 8  # the records insert_all starts with (they double when full)
MAX_CELLS = 2 ** 29 - 1  # 4 t + i is an int32
WIDTH = 8  # int32 per record
# The vertices of facet i of a tetrahedron, ordered so that (p, a, b, c)
# is right-handed when p lies on the side of vertex i, and INF (slot 3)
# comes last.
FACET = np.array([[1, 2, 3], [2, 0, 3], [0, 1, 3], [1, 0, 2]], dtype=np.int64)
SMALL = 32  # local vertex numbers the edge table takes (HXT's bound)

# The records (R; C and A are views of its columns), the cavity marks,
# a live tetrahedron of each vertex, and the free list.
Tets = namedtuple("Tets", "R mark vcell free")
# The cavity scratch: the removed tetrahedra (cav), the boundary triangles
# (tri: their vertices, then the outside facet), their local vertex numbers
# (loc), the local number of each vertex (vid, per point), the edge table
# (edges) and the hash table of large cavities (hkeys, hvals, hstamps).
Dig = namedtuple("Dig", "cav tri loc vid edges hkeys hvals hstamps")
Inserted = namedtuple("Inserted", "R mark ncells dup_of counts ok")


@njit(cache=True, inline="always")
def _xyz(P, v):
    return P[u(v), 0], P[u(v), 1], P[u(v), 2]


@njit(cache=True, inline="always")
def _finite(R, t):
    return R[u(t), 3] >= 0


@njit(cache=True, inline="always")
def _orient_with(P, R, t, i, p, static):
    """Orientation of tetrahedron t with its vertex i replaced by p
    (finite t): < 0 when p lies beyond facet i."""
    a = _xyz(P, p if i == 0 else R[u(t), 0])
    b = _xyz(P, p if i == 1 else R[u(t), 1])
    c = _xyz(P, p if i == 2 else R[u(t), 2])
    d = _xyz(P, p if i == 3 else R[u(t), 3])
    return orient3d_staged(a, b, c, d, O3D_A, static)


@njit(cache=True, inline="always")
def _conflicts(P, R, y, p, span, static):
    """(does tetrahedron y conflict with p, the in-sphere test's deciding
    stage or 0): a finite y whose circumsphere strictly contains p, or an
    infinite one with p beyond its hull facet, or on its plane and
    strictly inside the facet's circumcircle (kernel._conflicts)."""
    a = _xyz(P, R[u(y), 0])
    b = _xyz(P, R[u(y), 1])
    c = _xyz(P, R[u(y), 2])
    q = _xyz(P, p)
    g = R[u(y), 3]
    if g >= 0:
        s, st = insphere_staged(a, b, c, _xyz(P, g), q, ISP_A, static[1])
        return s > 0.0, st
    o, st = orient3d_staged(a, b, c, q, O3D_A, static[0])
    if o != 0.0:
        return o > 0.0, 0
    return _inside_facet_circle(3, a, b, c, q, span), 0


@njit(cache=True, inline="always")
def _locate(P, R, c, p, rnd, static, pending):
    """(the tetrahedron containing p, the walk's random state): a
    remembering visibility walk from tetrahedron c, or from the finite one
    next to it, that stops in a finite tetrahedron with p on no face's far
    side, or steps into an infinite one whose hull facet p lies beyond.
    Each step crosses the first face, from a random one on, that p lies
    beyond, which keeps the walk from cycling.  Its orientation tests go to
    ``pending``."""
    if not _finite(R, c):
        c = R[u(c), 7] >> 2
    prev = -1
    moved = True
    while moved and _finite(R, c):
        rnd ^= rnd << np.uint64(13)
        rnd ^= rnd >> np.uint64(7)
        rnd ^= rnd << np.uint64(17)
        rot = np.int64(rnd & np.uint64(3))
        moved = False
        for q in range(4):
            i = (q + rot) & 3
            nb = R[u(c), u(4 + i)] >> 2
            if nb == prev:
                continue
            o, st = _orient_with(P, R, c, i, p, static[0])
            pending[ORIENT] += 1
            if o < 0.0:
                prev, c, moved = c, nb, True
                break
    return c, rnd


@njit(cache=True, inline="always")
def _duplicate_in(P, R, c, p):
    """The vertex of finite tetrahedron c at p's position, or -1."""
    for i in range(4):
        v = R[u(c), u(i)]
        if P[u(v), 0] == P[u(p), 0] and P[u(v), 1] == P[u(p), 1] and P[u(v), 2] == P[u(p), 2]:
            return v
    return -1


# The cavity: the tetrahedra whose circumsphere strictly contains p
# (marked stamp; those found outside it, stamp + 1), breadth first.  Each
# boundary facet is copied out as it is found, its vertices in FACET's
# order and the outside facet it is glued to, since the removed
# tetrahedra's records are written over by the new ones.  When a
# tetrahedron joins the cavity, its neighbours' records and marks are
# asked for at once: they are read next, and cache misses otherwise.
@njit(cache=True, inline="always")
def _dig(P, tets, dig, c, p, stamp, span, static, pending):
    """(removed tetrahedra, boundary triangles, whether the scratch was too
    small) of p's cavity from tetrahedron c."""
    R, mark = tets.R, tets.mark
    cav, tri = dig.cav, dig.tri
    cav[0] = c
    mark[u(c)] = stamp
    ncav, nb, head = 1, 0, 0
    while head < ncav:
        x = cav[u(head)]
        head += 1
        for f in range(4):
            ref = R[u(x), u(4 + f)]
            y = ref >> 2
            m = mark[u(y)]
            if m == stamp:
                continue
            if m != stamp + 1:
                conflict, st = _conflicts(P, R, y, p, span, static)
                if st > 0:
                    tally(pending, INCIRCLE, st)
                if conflict:
                    if ncav == cav.shape[0]:
                        return ncav, nb, True
                    mark[u(y)] = stamp
                    cav[u(ncav)] = y
                    ncav += 1
                    for k in range(4):
                        prefetch(R, np.int64(R[u(y), u(4 + k)] >> 2))
                        prefetch(mark, np.int64(R[u(y), u(4 + k)] >> 2))
                    continue
                mark[u(y)] = stamp + 1
            if nb == tri.shape[0]:
                return ncav, nb, True
            tri[u(nb), 0] = R[u(x), u(FACET[f, 0])]
            tri[u(nb), 1] = R[u(x), u(FACET[f, 1])]
            tri[u(nb), 2] = R[u(x), u(FACET[f, 2])]
            tri[u(nb), 3] = ref
            nb += 1
    return ncav, nb, False


@njit(cache=True, inline="always")
def _new_id(tets, state, cav, ncav, b):
    """The record of the b-th new tetrahedron: the removed ones' first,
    then the free list's, then fresh ones."""
    if b < ncav:
        return cav[u(b)]
    if state[NFREE] > 0:
        state[NFREE] -= 1
        return tets.free[u(state[NFREE])]
    state[NCELLS] += 1
    return state[NCELLS] - 1


@njit(cache=True, inline="always")
def _fill(tets, dig, ncav, nb, p, state):
    """The new tetrahedra (p, a, b, c), one per boundary triangle, each
    glued outward across facet 0; the removed tetrahedra left over go to
    the free list.  Returns whether the edge table served (else _glue_large
    must)."""
    R, mark, vcell = tets.R, tets.mark, tets.vcell
    tri, loc, vid, cav = dig.tri, dig.loc, dig.vid, dig.cav
    for b in range(nb):
        w = _new_id(tets, state, cav, ncav, b)
        R[u(w), 0] = p
        R[u(w), 1] = tri[u(b), 0]
        R[u(w), 2] = tri[u(b), 1]
        R[u(w), 3] = tri[u(b), 2]
        ref = tri[u(b), 3]
        R[u(w), 4] = ref
        R[u(ref >> 2), u(4 + (ref & 3))] = 4 * w
        mark[u(w)] = 0
        tri[u(b), 3] = w
        for k in range(3):
            v = tri[u(b), u(k)]
            if v >= 0:
                vcell[u(v)] = w
                vid[u(v)] = -1
        vcell[u(p)] = w
    for b in range(nb, ncav):
        mark[u(cav[u(b)])] = DEAD
        tets.free[u(state[NFREE])] = cav[u(b)]
        state[NFREE] += 1
    # local numbers: INF is 0, the others 1, 2, ... in order of appearance
    count = 1
    for b in range(nb):
        for k in range(3):
            v = tri[u(b), u(k)]
            if v < 0:
                loc[u(b), u(k)] = 0
            else:
                if vid[u(v)] < 0:
                    vid[u(v)] = count
                    count += 1
                loc[u(b), u(k)] = vid[u(v)]
    if count > SMALL:
        return False
    edges = dig.edges
    for b in range(nb):
        w = tri[u(b), 3]
        la, lb, lc = loc[u(b), 0], loc[u(b), 1], loc[u(b), 2]
        edges[u(la * SMALL + lb)] = 4 * w + 3
        edges[u(lb * SMALL + lc)] = 4 * w + 1
        edges[u(lc * SMALL + la)] = 4 * w + 2
    for b in range(nb):
        w = tri[u(b), 3]
        la, lb, lc = loc[u(b), 0], loc[u(b), 1], loc[u(b), 2]
        R[u(w), 5] = edges[u(lc * SMALL + lb)]
        R[u(w), 6] = edges[u(la * SMALL + lc)]
        R[u(w), 7] = edges[u(lb * SMALL + la)]
    return True


@njit(cache=True)
def _glue_large(R, dig, nb, count, stamp):
    """_fill's gluing for a cavity with more than SMALL vertices: the
    directed edges in a hash table (stamped per point, never cleared)."""
    tri, loc = dig.tri, dig.loc
    hkeys, hvals, hstamps = dig.hkeys, dig.hvals, dig.hstamps
    hbits = 4
    while (1 << hbits) < 6 * nb:
        hbits += 1
    mask = (1 << hbits) - 1
    hshift = np.uint64(64 - hbits)
    for b in range(nb):
        w = tri[b, 3]
        for j in range(3):
            la = loc[b, j]
            lb = loc[b, (j + 1) % 3]
            slot = 3 if j == 0 else j  # edge a -> b: facet 3, b -> c: 1, c -> a: 2
            # the twin edge lb -> la may be in the table already
            e = _probe(hkeys, hstamps, lb * count + la, hshift, mask, stamp)
            if hstamps[e] == stamp and hkeys[e] == lb * count + la:
                twin = hvals[e]
                R[w, 4 + slot] = twin
                R[twin >> 2, 4 + (twin & 3)] = 4 * w + slot
            else:
                e = _probe(hkeys, hstamps, la * count + lb, hshift, mask, stamp)
                hstamps[e] = stamp
                hkeys[e] = la * count + lb
                hvals[e] = 4 * w + slot


@njit(cache=True, inline="always")
def _probe(hkeys, hstamps, key, hshift, mask, stamp):
    """The slot of ``key`` in the hash table, or the empty slot where it
    would go (Fibonacci hashing, linear probing)."""
    e = np.int64((np.uint64(key) * np.uint64(0x9E3779B97F4A7C15)) >> hshift)
    while hstamps[e] == stamp and hkeys[e] != key:
        e = (e + 1) & mask
    return e


# _insert_range inserts perm[t0:] until done (returns (n, 0)) or until the
# records (reason 1) or the cavity scratch (2) are too small for the next
# point, before changing anything but marks; it returns (t, reason) to
# resume after growing.  Each point: the walk (_locate), the cavity (_dig),
# the new tetrahedra (_fill, _glue_large).  The helpers get borrowed views
# of the arrays (lfqt.indexing.borrow), as kernel._insert_range's do.
@njit(cache=True)
def _insert_range(P, run, t0, tets, dig, timing):
    """Insert perm[t0:] (see above)."""
    perm, hint, pick, dup_of = run.perm, run.hint, run.pick, run.dup_of
    state, counts = borrow(run.state), borrow(run.counts)
    tets = Tets(borrow(tets.R), borrow(tets.mark), borrow(tets.vcell), borrow(tets.free))
    dig = Dig(borrow(dig.cav), borrow(dig.tri), borrow(dig.loc), borrow(dig.vid),
              borrow(dig.edges), dig.hkeys, dig.hvals, dig.hstamps)
    R, vcell = tets.R, tets.vcell
    n = perm.shape[0]
    pending = np.zeros(N_PREDICATE, dtype=np.int64)  # this point's counts, kept if it goes in
    rnd = np.uint64(88172645463325252 + t0)
    for t in range(t0, n):
        if pick[0] == t or pick[1] == t or pick[2] == t or pick[3] == t:
            continue  # a vertex of the initial simplex
        ahead = hint[u(min(t + WALK_AHEAD, n - 1))]
        prefetch(R, np.int64(vcell[u(ahead)] if ahead >= 0 else 0))
        p = perm[u(t)]
        h = hint[u(t)]
        c = vcell[u(h)] if h >= 0 and vcell[u(h)] >= 0 else vcell[u(state[LAST])]
        c_start = cycle_counter() if timing else 0
        c, rnd = _locate(P, R, c, p, rnd, run.static, borrow(pending))
        c_located = cycle_counter() if timing else 0
        dup = _duplicate_in(P, R, c, p) if _finite(R, c) else -1
        if dup >= 0:
            dup_of[u(p)] = dup
            counts[DUPLICATES] += 1
            _commit(counts, pending)
            continue
        state[STAMP] += 2
        ncav, nb, small = _dig(P, tets, dig, c, p, state[STAMP], run.span, run.static,
                               borrow(pending))
        if small or 6 * nb > dig.hkeys.shape[0]:
            pending[:] = 0  # nothing but marks is changed: retried after growing
            return t, 2
        if state[NCELLS] + max(nb - ncav - state[NFREE], 0) > R.shape[0]:
            pending[:] = 0
            return t, 1
        if not _fill(tets, dig, ncav, nb, p, state):
            _glue_large(R, dig, nb, n + 1, state[STAMP])
        counts[CONFLICTS] += ncav
        _commit(counts, pending)
        state[LAST] = p
        if timing:
            counts[LOCATE_CYCLES] += c_located - c_start
            counts[CAVITY_CYCLES] += cycle_counter() - c_located
    return n, 0


@njit(cache=True)
def _start(P, s, tets):
    """The tetrahedron of the points s (4 ids, reordered to be
    right-handed) and its 4 infinite ones, glued: returns 5, the number of
    records used."""
    R, mark, vcell = tets.R, tets.mark, tets.vcell
    o, st = orient3d_staged(_xyz(P, s[0]), _xyz(P, s[1]), _xyz(P, s[2]), _xyz(P, s[3]), O3D_A)
    if o < 0.0:
        s[0], s[1] = s[1], s[0]
    for k in range(4):
        R[0, k] = s[k]
    for i in range(4):
        for k in range(3):
            R[1 + i, k] = s[FACET[i, k]]
        R[1 + i, 3] = INF
    for c in range(5):
        mark[c] = 0
        for i in range(4):
            # across facet i: the other record holding c's vertices but R[c, i]
            for c2 in range(5):
                missing = -1
                shared = 0
                for k2 in range(4):
                    found = False
                    for k in range(4):
                        if k != i and R[c, k] == R[c2, k2]:
                            found = True
                    if found:
                        shared += 1
                    else:
                        missing = k2
                if c2 != c and shared == 3:
                    R[c, 4 + i] = 4 * c2 + missing
    for k in range(4):
        vcell[s[k]] = 0
    return 5


@njit(cache=True)
def _new_dig(size, n):
    """Cavity scratch for ``size`` tetrahedra and boundary triangles."""
    return Dig(np.empty(size, dtype=np.int32), np.empty((size, 4), dtype=np.int32),
               np.empty((size, 3), dtype=np.int64), np.empty(n, dtype=np.int32),
               np.empty(SMALL * SMALL, dtype=np.int32), np.empty(16 * size, dtype=np.int64),
               np.empty(16 * size, dtype=np.int64), np.zeros(16 * size, dtype=np.int64))


@njit(cache=True)
def _grown(tets, size):
    """The records at ``size`` tetrahedra (vcell is per point: kept)."""
    R, mark, vcell, free = tets
    m = R.shape[0]
    R2 = np.empty((size, WIDTH), dtype=np.int32)
    mark2 = np.empty(size, dtype=np.int32)
    for c in range(m):  # entry by entry (kernel._grown)
        for k in range(WIDTH):
            R2[c, k] = R[c, k]
        mark2[c] = mark[c]
    return Tets(R2, mark2, vcell, np.concatenate((free, np.empty(size - m, dtype=np.int32))))


def insert_all(P, perm, hint, span, capacity=0, max_cells=MAX_CELLS, timing=False):
    """Insert the 3D points P[perm] one by one; returns a
    kernel.Insertion whose N holds neighbour refs (4 t + i: decode with
    ``>> 2``), as kernel.insert_all does for 2D points (its parameters)."""
    n = P.shape[0]
    cap = min(capacity if capacity > 0 else max(16, CELLS_PER_POINT * n), max_cells)
    vcell = workspace.empty(n, np.int32)
    vcell.fill(-1)
    R = workspace.empty((cap, WIDTH), np.int32)
    tets = Tets(R, workspace.empty(cap, np.int32), vcell, workspace.empty(cap, np.int32))
    out = _insert_all(P, (perm, hint), span, tets, np.arange(n), max_cells, timing)
    grown = out.R.__array_interface__["data"][0] != R.__array_interface__["data"][0]
    return Insertion(out.R[:, :4], out.R[:, 4:], out.mark, out.ncells, out.dup_of, out.counts,
                     out.ok, None if grown else R)


@njit(cache=True, nogil=True)
def _insert_all(P, order, span, tets, dup_of, max_cells, timing):
    """insert_all's kernel, into ``tets`` (growing them when full), in
    ``order`` = (perm, hint); dup_of starts as the identity."""
    perm, hint = order
    counts = np.zeros(N_INSERT, dtype=np.int64)
    pick = _initial_simplex(P, 3, perm)
    ok = pick[0] >= 0 and pick[3] >= 0
    m = np.int64(0)
    if ok:
        s = np.empty(4, dtype=np.int64)
        for k in range(4):
            s[k] = perm[pick[k]]
        state = np.array([_start(P, s, tets), 0, 0, s[0]], dtype=np.int64)
        dig = _new_dig(np.int64(256), np.int64(P.shape[0]))
        run = Run(perm, hint, pick, state, counts, dup_of, span, statics(P, 3))
        t = np.int64(0)
        while True:
            t, reason = _insert_range(P, run, t, tets, dig, timing)
            if reason == 0:
                break
            if reason == 1:
                cap = tets.R.shape[0]
                if cap >= max_cells:
                    raise ValueError("the triangulation needs more tetrahedra than int32 "
                                     "facet refs can number")
                tets = _grown(tets, min(2 * cap, max_cells))
            else:
                dig = _new_dig(2 * dig.cav.shape[0], np.int64(P.shape[0]))
        m = state[NCELLS]
    return Inserted(tets.R[:m], tets.mark[:m], m, dup_of, counts, ok)
