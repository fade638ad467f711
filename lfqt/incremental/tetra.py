r"""Incremental Delaunay in 3D (Bowyer–Watson) on tetrahedron records that
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
from ..predicates.counters import (CONFLICTS, DUPLICATES, INCIRCLE, N_INSERT, N_PREDICATE, ORIENT,
                                   tally)
from ..predicates.spatial import ISP_A, O3D_A, box, insphere_staged, orient3d_staged, statics
from ..workers import Workers
from .kernel import (DEAD, INF, WALK_AHEAD, Insertion, _commit, _initial_simplex,
                     _inside_facet_circle, phase_cycles)

CELLS_PER_POINT = 8  # the records insert_all starts with (they double when full)
MAX_CELLS = 2 ** 29 - 1  # 4 t + i is an int32
WIDTH = 8  # int32 per record
# The vertices of facet i of a tetrahedron, ordered so that (p, a, b, c)
# is right-handed when p lies on the side of vertex i, and INF (slot 3)
# comes last.
FACET = np.array([[1, 2, 3], [2, 0, 3], [0, 1, 3], [1, 0, 2]], dtype=np.int64)
SMALL = 32  # local vertex numbers the edge table takes (HXT's bound)

# The records, the cavity marks and a live tetrahedron of each vertex.
Tets = namedtuple("Tets", "R mark vcell")
# The cavity scratch: the removed tetrahedra (cav), the boundary triangles
# (tri: their vertices, then the outside facet), their local vertex numbers
# (loc), the local number of each vertex (vid, per point), the edge table
# (edges) and the hash table of large cavities (hkeys, hvals, hstamps).
Dig = namedtuple("Dig", "cav tri loc vid edges hkeys hvals hstamps")


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
def _ours(part, v):
    """Is vertex v in the lane's part: part = (x, lo, hi, lane), the slab
    lo <= x[v] < hi of a coordinate x, or, when lo > hi, the rest of the
    line; lane -1 for every vertex.  INF belongs to every part.  The test
    reads v's coordinate, which the walk or the cavity has read anyway."""
    x, lo, hi, lane = part
    if lane < 0 or v < 0:
        return True
    c = x[u(v)]
    if lo <= hi:
        return lo <= c < hi
    return c >= lo or c < hi


@njit(cache=True, inline="always")
def _all_ours(R, part, t):
    return (_ours(part, R[u(t), 0]) and _ours(part, R[u(t), 1]) and _ours(part, R[u(t), 2])
            and _ours(part, R[u(t), 3]))


@njit(cache=True, inline="always")
def _locate(P, R, c, p, rnd, static, part, pending):
    """(the tetrahedron containing p, the walk's random state, whether the
    walk stayed in the lane's part): a remembering visibility walk from
    tetrahedron c, or from the finite one next to it, that stops in a
    finite tetrahedron with p on no face's far side, or steps into an
    infinite one whose hull facet p lies beyond.  Each step crosses the
    first face, from a random one on, that p lies beyond, which keeps the
    walk from cycling.  It enters only tetrahedra whose vertices are all in
    ``part`` (see _insert_lane).  Its orientation tests go to ``pending``."""
    if not _finite(R, c):
        ref = R[u(c), 7]
        c = ref >> 2
        if not _ours(part, R[u(c), u(ref & 3)]):
            return c, rnd, False
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
            ref = R[u(c), u(4 + i)]
            nb = ref >> 2
            if nb == prev:
                continue
            o, st = _orient_with(P, R, c, i, p, static[0])
            pending[ORIENT] += 1
            if o < 0.0:
                if not _ours(part, R[u(nb), u(ref & 3)]):
                    return nb, rnd, False
                prev, c, moved = c, nb, True
                break
    return c, rnd, True


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
def _dig(P, tets, dig, c, p, stamp, run, part, pending):
    """(removed tetrahedra, boundary triangles, status) of p's cavity from
    tetrahedron c: status 0, or SMALL_SCRATCH when the scratch was too
    small, or FOREIGN when the cavity reaches a vertex outside ``part``.
    Only marks are changed."""
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
                conflict, st = _conflicts(P, R, y, p, run.span, run.static)
                if st > 0:
                    tally(pending, INCIRCLE, st)
                if conflict:
                    if not _ours(part, R[u(y), u(ref & 3)]):
                        return ncav, nb, FOREIGN
                    if ncav == cav.shape[0]:
                        return ncav, nb, SMALL_SCRATCH
                    mark[u(y)] = stamp
                    cav[u(ncav)] = y
                    ncav += 1
                    for k in range(4):
                        prefetch(R, np.int64(R[u(y), u(4 + k)] >> 2))
                        prefetch(mark, np.int64(R[u(y), u(4 + k)] >> 2))
                    continue
                mark[u(y)] = stamp + 1
            if nb == tri.shape[0]:
                return ncav, nb, SMALL_SCRATCH
            tri[u(nb), 0] = R[u(x), u(FACET[f, 0])]
            tri[u(nb), 1] = R[u(x), u(FACET[f, 1])]
            tri[u(nb), 2] = R[u(x), u(FACET[f, 2])]
            tri[u(nb), 3] = ref
            nb += 1
    return ncav, nb, 0


@njit(cache=True, inline="always")
def _new_id(lane, cav, ncav, b):
    """The record of the b-th new tetrahedron: the removed ones' first,
    then the lane's free list's, then fresh ones of the lane's range."""
    state = lane.state
    if b < ncav:
        return cav[u(b)]
    if state[NFREE] > 0:
        state[NFREE] -= 1
        return lane.free[u(state[NFREE])]
    state[NEXT] += 1
    return state[NEXT] - 1


@njit(cache=True, inline="always")
def _fill(tets, dig, lane, ncav, nb, p):
    """The new tetrahedra (p, a, b, c), one per boundary triangle, each
    glued outward across facet 0; the removed tetrahedra left over go to
    the lane's free list.  Returns whether the edge table glued them to
    each other (else _glue_large must)."""
    R, mark, vcell = tets.R, tets.mark, tets.vcell
    tri, loc, vid, cav = dig.tri, dig.loc, dig.vid, dig.cav
    for b in range(nb):
        w = _new_id(lane, cav, ncav, b)
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
                vid[u(v)] = -1
        vcell[u(p)] = w
    state = lane.state
    for b in range(nb, ncav):
        mark[u(cav[u(b)])] = DEAD
        if state[NFREE] < lane.free.shape[0]:  # else the record is lost until the end
            lane.free[u(state[NFREE])] = cav[u(b)]
            state[NFREE] += 1
    # local numbers: INF is 0, the others 1, 2, ... in order of appearance;
    # a boundary vertex's old tetrahedra may be gone: its first new one
    # becomes its vcell
    count = 1
    for b in range(nb):
        for k in range(3):
            v = tri[u(b), u(k)]
            if v < 0:
                loc[u(b), u(k)] = 0
            else:
                if vid[u(v)] < 0:
                    vid[u(v)] = count
                    vcell[u(v)] = tri[u(b), 3]
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


# A lane inserts a list of points (positions in perm) into the shared
# records, alone (one lane: the whole insertion) or beside other lanes on
# other threads.  Each lane owns a part of the vertex ids, and touches
# only tetrahedra with three or four vertices in it; the ids follow
# space (orders.layout), so a part is a region.  A lane walks only through
# tetrahedra all of whose vertices are its own, and a cavity it digs must
# be made of such tetrahedra: a point whose walk or cavity reaches
# another part is deferred.  Then no two lanes write the same record, or
# read one that another writes: a tetrahedron that a lane removes or
# makes has all four vertices in its part, and one whose outward facet it
# re-glues, three.  INF is in every part.  A lane takes new records from
# its own range and free list, and marks with its own stamps (stamp,
# stamp + 1, then + step, where lanes start at different even numbers).
#
# lane.state: the lane's next fresh record and the end of its range, its
# free list's length, its stamp and step, its last point, and the number
# of points it deferred (positions in lane.deferred).
NEXT, END, NFREE, STAMP, STEP, LAST, NDEFER = range(7)
FOREIGN, SMALL_SCRATCH = 1, 2
Lane = namedtuple("Lane", "state free counts part deferred")
# The insertion's order, duplicates and filters: perm, hint, pick (the
# initial simplex's positions in perm), dup_of, and the filters' span and
# static bounds (predicates.spatial.statics).
Run = namedtuple("Run", "perm hint pick dup_of span static")


# _insert_lane inserts perm[todo[k0:]] until done (returns (len, 0)) or
# until the records (reason 1) or the cavity scratch (2) are too small for
# the next point, before changing anything but marks; it returns (k,
# reason) to resume after growing.  Each point: the walk (_locate), the
# cavity (_dig), the new tetrahedra (_fill, _glue_large).  The helpers get
# borrowed views of the arrays (lfqt.indexing.borrow), as
# kernel._insert_range's do.
@njit(cache=True, nogil=True)
def _insert_lane(P, run, todo, k0, tets, dig, lane, seed, timing):
    """Insert perm[todo[k0:]] in the lane (see above)."""
    perm, hint, pick, dup_of = run.perm, run.hint, run.pick, run.dup_of
    state, counts, part = borrow(lane.state), borrow(lane.counts), lane.part
    lane = Lane(state, borrow(lane.free), counts, part, borrow(lane.deferred))
    tets = Tets(borrow(tets.R), borrow(tets.mark), borrow(tets.vcell))
    dig = Dig(borrow(dig.cav), borrow(dig.tri), borrow(dig.loc), borrow(dig.vid),
              borrow(dig.edges), dig.hkeys, dig.hvals, dig.hstamps)
    R, vcell = tets.R, tets.vcell
    m = todo.shape[0]
    pending = np.zeros(N_PREDICATE, dtype=np.int64)  # this point's counts, kept if it goes in
    rnd = np.uint64(88172645463325252) + np.uint64(seed)
    for k in range(k0, m):
        t = todo[u(k)]
        if pick[0] == t or pick[1] == t or pick[2] == t or pick[3] == t:
            continue  # a vertex of the initial simplex
        ahead = hint[u(todo[u(min(k + WALK_AHEAD, m - 1))])]
        prefetch(R, np.int64(vcell[u(ahead)] if ahead >= 0 else 0))
        p = perm[u(t)]
        h = hint[u(t)]
        c = vcell[u(h)] if h >= 0 and vcell[u(h)] >= 0 else -1
        if c < 0 or not _all_ours(R, part, c):
            c = vcell[u(state[LAST])]
        c_start = cycle_counter() if timing else 0
        ok = _all_ours(R, part, c)
        if ok:
            c, rnd, ok = _locate(P, R, c, p, rnd, run.static, part, borrow(pending))
        c_located = cycle_counter() if timing else 0
        if ok:
            dup = _duplicate_in(P, R, c, p) if _finite(R, c) else -1
            if dup >= 0:
                dup_of[u(p)] = dup
                counts[DUPLICATES] += 1
                _commit(counts, pending)
                continue
            state[STAMP] += state[STEP]
            ncav, nb, status = _dig(P, tets, dig, c, p, state[STAMP], run, part, borrow(pending))
            if status == SMALL_SCRATCH or 6 * nb > dig.hkeys.shape[0]:
                pending[:] = 0  # nothing but marks is changed: retried after growing
                return k, 2
            ok = status == 0
        if not ok:
            pending[:] = 0
            lane.deferred[u(state[NDEFER])] = t
            state[NDEFER] += 1
            continue
        if max(nb - ncav - state[NFREE], 0) > state[END] - state[NEXT]:
            pending[:] = 0
            return k, 1
        if not _fill(tets, dig, lane, ncav, nb, p):
            _glue_large(R, dig, nb, vcell.shape[0] + 1, state[STAMP])
        counts[CONFLICTS] += ncav
        _commit(counts, pending)
        state[LAST] = p
        if timing:
            phase_cycles(counts, c_start, c_located)
    return m, 0


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
def _new_dig(size, vid):
    """Cavity scratch for ``size`` tetrahedra and boundary triangles, on
    the shared local-number array ``vid`` (lanes number disjoint vertices)."""
    return Dig(np.empty(size, dtype=np.int32), np.empty((size, 4), dtype=np.int32),
               np.empty((size, 3), dtype=np.int64), vid,
               np.empty(SMALL * SMALL, dtype=np.int32), np.empty(16 * size, dtype=np.int64),
               np.empty(16 * size, dtype=np.int64), np.zeros(16 * size, dtype=np.int64))


@njit(cache=True)
def _grown(tets, lane, size):
    """(tets, lane) at ``size`` tetrahedra: the records copied, the lane's
    free list as long and its range up to the end (vcell is per point:
    kept)."""
    R, mark, vcell = tets
    m = R.shape[0]
    R2 = np.empty((size, WIDTH), dtype=np.int32)
    mark2 = np.empty(size, dtype=np.int32)
    for c in range(m):  # entry by entry (kernel._grown)
        for k in range(WIDTH):
            R2[c, k] = R[c, k]
        mark2[c] = mark[c]
    free = np.empty(size, dtype=np.int32)
    free[:lane.free.shape[0]] = lane.free
    lane.state[END] = size
    return Tets(R2, mark2, vcell), Lane(lane.state, free, lane.counts, lane.part, lane.deferred)


@njit(cache=True)
def _run_alone(P, run, todo, tets, dig, lane, max_cells, timing):
    """The one lane of a sequential insertion (its part: every vertex),
    growing the records, its free list and the scratch when they are full:
    returns (tets, dig, lane)."""
    k = np.int64(0)
    while True:
        k, reason = _insert_lane(P, run, todo, k, tets, dig, lane, k, timing)
        if reason == 0:
            return tets, dig, lane
        if reason == 1:
            cap = tets.R.shape[0]
            if cap >= max_cells:
                raise ValueError("the triangulation needs more tetrahedra than int32 "
                                 "facet refs can number")
            tets, lane = _grown(tets, lane, min(2 * cap, max_cells))
        else:
            dig = _new_dig(2 * dig.cav.shape[0], dig.vid)


@njit(cache=True, nogil=True)
def _run_beside(P, run, todo, tets, dig, lane, seed, timing):
    """One of several lanes, on its own thread: a point that does not fit
    the lane's records is deferred with the rest of its list.  Returns the
    lane's scratch, grown if a cavity needed it."""
    k = np.int64(0)
    while True:
        k, reason = _insert_lane(P, run, todo, k, tets, dig, lane, seed + k, timing)
        if reason == 0:
            return dig
        if reason == 1:
            for j in range(k, todo.shape[0]):
                lane.deferred[lane.state[NDEFER]] = todo[j]
                lane.state[NDEFER] += 1
            return dig
        dig = _new_dig(2 * dig.cav.shape[0], dig.vid)


@njit(cache=True)
def _split(perm, todo, x, cuts):
    """The lists of the lanes: todo's positions by the slab of their
    point's coordinate x (_slab), each in todo's order; returns (order,
    starts)."""
    lanes = cuts.shape[0]
    count = np.zeros(lanes + 1, dtype=np.int64)
    which = np.empty(todo.shape[0], dtype=np.int64)
    for k in range(todo.shape[0]):
        which[k] = _slab(x[perm[todo[k]]], cuts)
        count[which[k] + 1] += 1
    starts = np.cumsum(count)
    fill = starts[:-1].copy()
    order = np.empty(todo.shape[0], dtype=todo.dtype)
    for k in range(todo.shape[0]):
        order[fill[which[k]]] = todo[k]
        fill[which[k]] += 1
    return order, starts


@njit(cache=True, inline="always")
def _slab(c, cuts):
    """The lane of coordinate c: lane j's slab is [cuts[j], cuts[j + 1]),
    and the last lane's the rest (cuts[0] is -inf); _ours agrees."""
    lanes = cuts.shape[0]
    for k in range(lanes - 1):
        if cuts[k] <= c < cuts[k + 1]:
            return k
    return lanes - 1


@njit(cache=True)
def _close_lane(tets, lane, free, nfree):
    """After a parallel pass: the lane's unused fresh records and its free
    list onto the shared free list (free[:nfree]); returns its new length."""
    for c in range(lane.state[NEXT], lane.state[END]):
        tets.mark[c] = DEAD
        free[nfree] = c
        nfree += 1
    for j in range(lane.state[NFREE]):
        free[nfree] = lane.free[j]
        nfree += 1
    return nfree


@njit(cache=True)
def _reset_marks(mark, m):
    """Marks of live records back to 0, before the stamps would overflow."""
    for c in range(m):
        if mark[c] != DEAD:
            mark[c] = 0


SAMPLE = 4096  # a pass's slab borders are quantiles of this many of its points


def _slabs(P, perm, todo, axis, lanes):
    """Slab borders along ``axis`` holding equal shares of todo's points
    (quantiles of a sample of them; _slab)."""
    sample = todo[::max(1, len(todo) // SAMPLE)]
    cuts = np.quantile(P[perm[sample], axis], np.arange(lanes) / lanes)
    cuts[0] = -np.inf
    return cuts


SEQUENTIAL = 1 << 14  # points inserted alone first: a coarse mesh leaves lanes little room
# A lane's fresh records: LANE_RECORDS a point (3D Delaunay makes 6.7 on
# average) and LANE_SLACK more; a lane that runs out defers its other points.
LANE_RECORDS, LANE_SLACK = 8, 1024
ROUND_FACTOR = 2  # each round takes the insertion order on to this multiple of its start
STAMP_LIMIT = 2 ** 30  # marks are int32: stamps start over before they reach it


def insert_all(P, perm, hint, span, capacity=0, max_cells=MAX_CELLS, timing=False, threads=1,
               first=None):
    """Insert the 3D points P[perm] one by one; returns a kernel.Insertion
    whose N holds neighbour refs (4 t + i: decode with ``>> 2``), as
    kernel.insert_all does for 2D points (its parameters).  ``threads``
    above 1: after the first SEQUENTIAL points, rounds of the order in
    lanes (_insert_lane), each in its own slab of space, the points a lane
    cannot take retried in slabs across the next longest side; the last
    round's leftovers in slabs across the third, and the rest alone at the
    end.  ``first``: the points inserted alone first (SEQUENTIAL by
    default)."""
    n = P.shape[0]
    cap = min(capacity if capacity > 0 else max(16, CELLS_PER_POINT * n), max_cells)
    vcell = workspace.empty(n, np.int32)
    vcell.fill(-1)
    R = workspace.empty((cap, WIDTH), np.int32)
    tets = Tets(R, workspace.empty(cap, np.int32), vcell)
    counts = np.zeros(N_INSERT, dtype=np.int64)
    dup_of = np.arange(n)
    pick = _initial_simplex(P, 3, perm)
    if not (pick[0] >= 0 and pick[3] >= 0):
        return Insertion(R[:0, :4], R[:0, 4:], tets.mark[:0], 0, dup_of, counts, False, R)
    s = perm[pick].astype(np.int64)
    used = _start(P, s, tets)
    low, high = box(P, 3)
    run = Run(perm, hint, pick, dup_of, span, statics(low, high, 3))
    dig = _new_dig(np.int64(256), np.empty(n, dtype=np.int32))
    # the lanes' slabs cross the longest side of the points' box, then the
    # next longest, then the third
    axes = [int(a) for a in np.argsort(high - low)[::-1]]
    axis = axes[0]
    alone = Lane(np.array([used, cap, 0, 0, 2, s[0], 0], dtype=np.int64),
                 workspace.empty(cap, np.int32), counts, (P[:, axis], -np.inf, np.inf,
                                                          np.int64(-1)),
                 np.empty(0, dtype=np.int64))
    rounds = _rounds(n, threads, SEQUENTIAL if first is None else first)
    todo = np.arange(rounds[0][1], dtype=np.int64)
    tets, dig, alone = _run_alone(P, run, todo, tets, dig, alone, max_cells, timing)
    left = np.empty(0, dtype=np.int64)
    for lo, hi in rounds[1:]:
        todo = np.concatenate((left, np.arange(lo, hi, dtype=np.int64)))
        # both passes' slabs from the round's points (the deferred ones
        # crowd along the first pass's borders), the second's across the
        # first's: only the points near where their borders cross are left
        round_todo = todo
        for a in axes[:2]:
            cuts = _slabs(P, run.perm, round_todo, a, threads)
            tets, alone, todo = _parallel_pass(P, run, todo, tets, alone, dig.vid,
                                               (threads, a, cuts), timing)
        left = todo
    if len(left):
        # the last round's leftovers lie along the line where its two
        # passes' borders cross: slabs across the third side leave only
        # those near where all three cross
        cuts = _slabs(P, run.perm, left, axes[2], threads)
        tets, alone, left = _parallel_pass(P, run, left, tets, alone, dig.vid,
                                           (threads, axes[2], cuts), timing)
    tets, dig, alone = _run_alone(P, run, left, tets, dig, alone, max_cells, timing)
    m = alone.state[NEXT]
    grown = tets.R.__array_interface__["data"][0] != R.__array_interface__["data"][0]
    return Insertion(tets.R[:m, :4], tets.R[:m, 4:], tets.mark[:m], m, dup_of, counts, True,
                     None if grown else R)


def _rounds(n, threads, alone):
    """[(0, alone)] then the rounds' ranges of positions in the order: all
    of it alone for one thread."""
    if threads <= 1 or n <= alone:
        return [(0, n)]
    out = [(0, max(alone, 1))]
    while out[-1][1] < n:
        lo = out[-1][1]
        out.append((lo, min(n, ROUND_FACTOR * lo)))
    return out


def _parallel_pass(P, run, todo, tets, alone, vid, lanes, timing):
    """Insert todo's points in lanes = (threads, axis, cuts), in the slabs
    of ``axis`` that cuts borders (_slab); returns (tets, alone, the points
    deferred, in order)."""
    threads, axis, cuts = lanes
    state = alone.state
    if len(todo) == 0:
        return tets, alone, todo
    x = P[:, axis]
    order, starts = _split(run.perm, todo, x, cuts)
    sizes = np.diff(starts)
    # fresh records (LANE_RECORDS), less the shared free list's, dealt out evenly
    nfree = int(state[NFREE])
    shares = [nfree * k // threads for k in range(threads + 1)]
    fresh = [max(0, LANE_RECORDS * int(sizes[k]) + LANE_SLACK - (shares[k + 1] - shares[k]))
             for k in range(threads)]
    need = int(state[NEXT]) + sum(fresh)
    if need > tets.R.shape[0]:
        size = min(max(2 * tets.R.shape[0], need), MAX_CELLS)
        if need > size:
            raise ValueError("the triangulation needs more tetrahedra than int32 facet refs "
                             "can number")
        tets, alone = _grown(tets, alone, size)
    if state[STAMP] + 2 * threads * (len(todo) + 2) >= STAMP_LIMIT:
        _reset_marks(tets.mark, int(state[NEXT]))
        state[STAMP] = 0
    lanes = []
    start = int(state[NEXT])
    for k in range(threads):
        own = alone.free[shares[k]:shares[k + 1]]
        free = np.empty(len(own) + 2 * int(sizes[k]) + LANE_SLACK, dtype=np.int32)
        free[:len(own)] = own
        lane_state = np.array([start, start + fresh[k], len(own), state[STAMP] + 2 * k,
                               2 * threads, state[LAST], 0], dtype=np.int64)
        start += fresh[k]
        part = (x, float(cuts[k]), float(cuts[k + 1] if k + 1 < threads else cuts[0]),
                np.int64(k))
        lanes.append(Lane(lane_state, free, np.zeros(N_INSERT, dtype=np.int64), part,
                          np.empty(int(sizes[k]), dtype=np.int64)))
    state[NEXT] = start
    state[NFREE] = 0

    def job(k):
        # each lane its own scratch, around the shared local numbers (its
        # vertices are its own)
        mine = order[starts[k]:starts[k + 1]]
        return _run_beside(P, run, mine, tets, _new_dig(np.int64(256), vid), lanes[k],
                           np.int64(k), timing)

    Workers(threads).each(job, range(threads))
    nfree = 0
    deferred = []
    for lane in lanes:
        nfree = _close_lane(tets, lane, alone.free, nfree)
        alone.counts[:] += lane.counts
        deferred.append(lane.deferred[:lane.state[NDEFER]])
        state[STAMP] = max(state[STAMP], lane.state[STAMP])
    state[NFREE] = nfree
    state[STAMP] += 2
    left = np.sort(np.concatenate(deferred))
    return tets, alone, left
