"""Incremental Delaunay (Bowyer–Watson) in 2D and 3D, in a given order.

Cells are rows of flat arrays: ``C[c]`` holds the d+1 vertices (input
indices), ``N[c, i]`` the cell across the face opposite vertex i.  The hull
is closed by *infinite* cells containing the vertex ``INF`` (-1), so every
face has two cells.  Finite cells are positively oriented (counter-clockwise
in 2D, right-handed in 3D); an infinite cell is oriented so that putting a
point beyond its hull facet in place of ``INF`` gives a positive cell.

Inserting p: a remembering visibility walk from the hint's cell (counting
orientation tests, paper 2's location cost), then the cavity of cells whose
circumsphere *strictly* contains p (counting them, paper 2's conflicts), then
one new cell per cavity-boundary facet.  With the strict test p lies strictly
on the cavity side of every boundary facet, even for cospherical input (the
region inside one sphere and outside-or-on the other lies strictly on one
side of their common facet), so no cell is ever flat.  An infinite cell
conflicts when p is beyond its hull facet, or on its plane and strictly
inside the facet's circumcircle.  Freed cells go to a free list; storage
doubles when full.
"""
import time

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic

from .indexing import u
from .predicates import CCW_A, ICC_A, ISP_A, O3D_A, incircle_staged, insphere_staged, \
    orient2d_staged, orient3d_staged

INF = -1
# counters
K_ORIENT, K_CONFLICTS, K_INSPHERE, K_LOCATE_CYCLES, K_CAVITY_CYCLES, K_DUPLICATES, \
    K_EXACT = range(7)
N_K = 7
COUNTER_NAMES = ("orientation_tests", "conflicts", "insphere_tests", "locate_cycles",
                 "cavity_cycles", "duplicates", "exact_stage")


@intrinsic
def cycle_counter(typingctx):
    """The CPU's cycle counter (x86: TSC) via llvm.readcyclecounter."""
    def codegen(context, builder, signature, args):
        fn = cgutils.get_or_insert_function(builder.module, ir.FunctionType(ir.IntType(64), []),
                                            "llvm.readcyclecounter")
        return builder.call(fn, [])
    return types.int64(), codegen


@njit(cache=True)
def read_cycles():
    return cycle_counter()


_CYCLES_PER_SECOND = None


def cycles_per_second():
    """Cycle-counter frequency, calibrated once against perf_counter."""
    global _CYCLES_PER_SECOND
    if _CYCLES_PER_SECOND is None:
        c0, t0 = read_cycles(), time.perf_counter()
        time.sleep(0.05)
        c1, t1 = read_cycles(), time.perf_counter()
        _CYCLES_PER_SECOND = (c1 - c0) / (t1 - t0)
    return _CYCLES_PER_SECOND


@njit(cache=True, inline="always")
def _orient_pts(d, ax, ay, az, bx, by, bz, cx, cy, cz, ex, ey, ez):
    """Orientation of a, b, c (2D, z ignored) or of a, b, c, e (3D)."""
    if d == 2:
        return orient2d_staged(ax, ay, bx, by, cx, cy, CCW_A)
    return orient3d_staged(ax, ay, az, bx, by, bz, cx, cy, cz, ex, ey, ez, O3D_A)


@njit(cache=True, inline="always")
def _insphere_pts(d, ax, ay, az, bx, by, bz, cx, cy, cz, ex, ey, ez, px, py, pz):
    """In-circle of p against a, b, c (2D) or in-sphere against a, b, c, e."""
    if d == 2:
        return incircle_staged(ax, ay, bx, by, cx, cy, px, py, ICC_A)
    return insphere_staged(ax, ay, az, bx, by, bz, cx, cy, cz, ex, ey, ez, px, py, pz, ISP_A)


@njit(cache=True)
def _inside_facet_circle(d, ax, ay, az, bx, by, bz, ex, ey, ez, px, py, pz, span):
    """p lies on the line (2D: segment a-b) or plane (3D: triangle a, b, e)
    of a hull facet: is it strictly inside the facet's circumcircle (2D: the
    open segment)?  Scalars only, like every helper of the insertion loop."""
    if d == 2:
        if min(ax, bx) < max(ax, bx):
            return min(ax, bx) < px < max(ax, bx)
        return min(ay, by) < py < max(ay, by)
    # Any sphere through a, b, e meets their plane in their circumcircle: use
    # one through a point q off the plane (found exactly among three offsets).
    for axis in range(3):
        qx = ax + span if axis == 0 else ax
        qy = ay + span if axis == 1 else ay
        qz = az + span if axis == 2 else az
        o, st = orient3d_staged(ax, ay, az, bx, by, bz, ex, ey, ez, qx, qy, qz, O3D_A)
        if o != 0.0:
            s, st = insphere_staged(ax, ay, az, bx, by, bz, ex, ey, ez, qx, qy, qz,
                                    px, py, pz, ISP_A)
            return s * o > 0.0
    return False


@njit(cache=True)
def _initial_simplex(P, d, perm):
    """Positions in ``perm`` of the first d+1 affinely independent points, or
    (-1, ...) when there are none (all equal / collinear / coplanar)."""
    n = perm.shape[0]
    pick = np.full(4, -1, dtype=np.int64)
    if n == 0:
        return pick
    pick[0] = 0
    k = 1
    for t in range(1, n):
        q = perm[t]
        if k == 1:
            a = perm[pick[0]]
            if P[a, 0] != P[q, 0] or P[a, 1] != P[q, 1] or P[a, d - 1] != P[q, d - 1]:
                pick[1] = t
                k = 2
        elif k == 2:
            a = perm[pick[0]]
            b = perm[pick[1]]
            collinear = True
            for ax in range(3 if d == 3 else 1):
                i0, i1 = (0, 1) if ax == 0 else ((0, 2) if ax == 1 else (1, 2))
                o, st = orient2d_staged(P[a, i0], P[a, i1], P[b, i0], P[b, i1],
                                        P[q, i0], P[q, i1], CCW_A)
                if o != 0.0:
                    collinear = False
            if not collinear:
                pick[2] = t
                k = 3
                if d == 2:
                    return pick
        else:
            a, b, c = perm[pick[0]], perm[pick[1]], perm[pick[2]]
            o, st = _orient_pts(3, P[a, 0], P[a, 1], P[a, 2], P[b, 0], P[b, 1], P[b, 2],
                                P[c, 0], P[c, 1], P[c, 2], P[q, 0], P[q, 1], P[q, 2])
            if o != 0.0:
                pick[3] = t
                return pick
    pick[:] = -1
    return pick


@njit(cache=True, inline="always")
def _insert_range(P, d, perm, hint, span, pick, t0, C, N, alive, mark, vcell, free, state,
                  counts, dup_of, stack, conflicts, bcell, bface, hkeys, hvals, hstamps):
    """Insert perm[t0:] until done (returns (n, 0)) or until the cell arrays
    (reason 1) or the cavity scratch (2) are too small for the next point,
    before touching it; returns (t, reason) to resume after growing.  No
    array is reassigned in here: that would cost numba reference counting
    on every iteration.  Indices go through ``u`` (lfqt.indexing).  Inlined
    into one kernel per dimension, so that ``d`` is a constant there."""
    n = perm.shape[0]
    width = d + 1
    ncells, nfree, stamp, last = state[0], state[1], state[2], state[3]
    rnd = np.uint64(88172645463325252 + t0)
    for t in range(t0, n):
        is_pick = False
        for k in range(width):
            if pick[k] == t:
                is_pick = True
        if is_pick:
            continue
        p = perm[u(t)]
        h = hint[u(t)]
        orient_before = counts[K_ORIENT]
        insphere_before = counts[K_INSPHERE]
        exact_before = counts[K_EXACT]
        aborted = False
        start = vcell[u(h)] if h >= 0 and vcell[u(h)] >= 0 else vcell[u(last)]
        c_start = cycle_counter()
        # ---- locate: remembering visibility walk
        c = start
        for i in range(width):
            if C[u(c), u(i)] == INF:
                c = N[u(c), u(i)]
                break
        prev = -1
        outside = False
        while True:
            rnd ^= rnd << np.uint64(13)
            rnd ^= rnd >> np.uint64(7)
            rnd ^= rnd << np.uint64(17)
            rot = np.int64(rnd % np.uint64(width))
            moved = False
            for q in range(width):
                i = q + rot if q + rot < width else q + rot - width
                nb = N[u(c), u(i)]
                if nb == prev:
                    continue
                v0 = p if i == 0 else C[u(c), 0]
                v1 = p if i == 1 else C[u(c), 1]
                v2 = p if i == 2 else C[u(c), 2]
                v3 = (p if i == 3 else C[u(c), 3]) if d == 3 else v0
                o, st = _orient_pts(d, P[u(v0), 0], P[u(v0), 1], P[u(v0), d - 1], P[u(v1), 0], P[u(v1), 1],
                                    P[u(v1), d - 1], P[u(v2), 0], P[u(v2), 1], P[u(v2), d - 1],
                                    P[u(v3), 0], P[u(v3), 1], P[u(v3), d - 1])
                counts[K_ORIENT] += 1
                if o < 0.0:
                    prev = c
                    c = nb
                    moved = True
                    break
            if not moved:
                break
            is_inf = False
            for i in range(width):
                if C[u(c), u(i)] == INF:
                    is_inf = True
            if is_inf:
                outside = True
                break
        c_located = cycle_counter()
        if not outside:
            dup = -1
            for i in range(width):
                v = C[u(c), u(i)]
                if P[u(v), 0] == P[u(p), 0] and P[u(v), 1] == P[u(p), 1] and P[u(v), d - 1] == P[u(p), d - 1]:
                    dup = v
            if dup >= 0:
                dup_of[u(p)] = dup
                counts[K_DUPLICATES] += 1
                continue
        # ---- cavity: cells whose circumsphere strictly contains p
        stamp += 2
        nstack = 1
        stack[0] = c
        mark[u(c)] = stamp
        nconf = 0
        nb_count = 0
        while nstack > 0 and not aborted:
            nstack -= 1
            x = stack[u(nstack)]
            if nconf == conflicts.shape[0]:
                aborted = True
                break
            conflicts[u(nconf)] = x
            nconf += 1
            for i in range(width):
                y = N[u(x), u(i)]
                if mark[u(y)] == stamp:
                    continue
                conflict = False
                if mark[u(y)] != stamp + 1:
                    f = -1
                    for k in range(width):
                        if C[u(y), u(k)] == INF:
                            f = k
                    if f >= 0:
                        # infinite cell: p beyond its hull facet, or on the
                        # facet's plane and inside its circumcircle
                        v0 = p if f == 0 else C[u(y), 0]
                        v1 = p if f == 1 else C[u(y), 1]
                        v2 = p if f == 2 else C[u(y), 2]
                        v3 = (p if f == 3 else C[u(y), 3]) if d == 3 else v0
                        o, st = _orient_pts(d, P[u(v0), 0], P[u(v0), 1], P[u(v0), d - 1], P[u(v1), 0],
                                            P[u(v1), 1], P[u(v1), d - 1], P[u(v2), 0], P[u(v2), 1],
                                            P[u(v2), d - 1], P[u(v3), 0], P[u(v3), 1], P[u(v3), d - 1])
                        if o > 0.0:
                            conflict = True
                        elif o == 0.0:
                            fa = C[u(y), u((f + 1) % width)]
                            fb = C[u(y), u((f + 2) % width)]
                            fe = C[u(y), u((f + 3) % width)] if d == 3 else fa
                            conflict = _inside_facet_circle(
                                d, P[u(fa), 0], P[u(fa), 1], P[u(fa), d - 1], P[u(fb), 0], P[u(fb), 1],
                                P[u(fb), d - 1], P[u(fe), 0], P[u(fe), 1], P[u(fe), d - 1], P[u(p), 0],
                                P[u(p), 1], P[u(p), d - 1], span)
                    else:
                        counts[K_INSPHERE] += 1
                        a, b, e = C[u(y), 0], C[u(y), 1], C[u(y), 2]
                        g = C[u(y), 3] if d == 3 else a
                        sv, st = _insphere_pts(d, P[u(a), 0], P[u(a), 1], P[u(a), d - 1], P[u(b), 0],
                                               P[u(b), 1], P[u(b), d - 1], P[u(e), 0], P[u(e), 1],
                                               P[u(e), d - 1], P[u(g), 0], P[u(g), 1], P[u(g), d - 1],
                                               P[u(p), 0], P[u(p), 1], P[u(p), d - 1])
                        if st == 2:
                            counts[K_EXACT] += 1
                        conflict = sv > 0.0
                if conflict:
                    mark[u(y)] = stamp
                    if nstack == stack.shape[0]:
                        aborted = True
                        break
                    stack[u(nstack)] = y
                    nstack += 1
                else:
                    mark[u(y)] = stamp + 1
                    if nb_count == bcell.shape[0]:
                        aborted = True
                        break
                    bcell[u(nb_count)] = x
                    bface[u(nb_count)] = i
                    nb_count += 1
        if aborted or 4 * d * nb_count > hkeys.shape[0] or \
                ncells + max(nb_count - nfree, 0) > C.shape[0]:
            # nothing is modified yet: undo this point's counts and let the caller
            # grow the scratch (2) or the cell arrays (1), then retry the point
            counts[K_ORIENT] = orient_before
            counts[K_INSPHERE] = insphere_before
            counts[K_EXACT] = exact_before
            state[0], state[1], state[2], state[3] = ncells, nfree, stamp, last
            return t, (2 if aborted or 4 * d * nb_count > hkeys.shape[0] else 1)
        counts[K_CONFLICTS] += nconf
        # ---- one new cell per boundary facet
        # The ridge table uses only a prefix sized to this cavity (load at
        # most 1/4), so that it stays in L1; stamps invalidate old entries.
        hbits = 4
        while (1 << hbits) < 2 * d * nb_count:
            hbits += 1
        mask = (1 << hbits) - 1
        hshift = np.uint64(64 - hbits)
        for b in range(nb_count):
            x = bcell[u(b)]
            i = bface[u(b)]
            y = N[u(x), u(i)]
            if nfree > 0:
                nfree -= 1
                w = free[u(nfree)]
            else:
                w = ncells
                ncells += 1
            alive[u(w)] = True
            mark[u(w)] = 0
            for k in range(width):
                C[u(w), u(k)] = C[u(x), u(k)]
            C[u(w), u(i)] = p
            N[u(w), u(i)] = y
            for k in range(width):
                if N[u(y), u(k)] == x:
                    N[u(y), u(k)] = w
            for k in range(width):
                v = C[u(w), u(k)]
                if v >= 0:
                    vcell[u(v)] = w
            # faces through p: match them by their ridge (the facet minus one vertex)
            for k in range(width):
                if k == i:
                    continue
                if d == 2:
                    key = C[u(w), u(3 - i - k)] + 1
                else:
                    ra = -2
                    rb = -2
                    for m in range(width):
                        if m != i and m != k:
                            if ra == -2:
                                ra = C[u(w), u(m)]
                            else:
                                rb = C[u(w), u(m)]
                    lo = min(ra, rb) + 1
                    hi = max(ra, rb) + 1
                    key = lo * (n + 1) + hi
                # Fibonacci hashing: the product's high bits
                slot = np.int64((np.uint64(key) * np.uint64(0x9E3779B97F4A7C15)) >> hshift)
                while hstamps[u(slot)] == stamp and hkeys[u(slot)] != key:
                    slot = (slot + 1) & mask
                if hstamps[u(slot)] == stamp:
                    other = hvals[u(slot)]
                    w2 = np.int64(np.uint64(other) // np.uint64(width))
                    k2 = other - w2 * width
                    N[u(w), u(k)] = w2
                    N[u(w2), u(k2)] = w
                else:
                    hstamps[u(slot)] = stamp
                    hkeys[u(slot)] = key
                    hvals[u(slot)] = w * width + k
        for q in range(nconf):
            x = conflicts[u(q)]
            alive[u(x)] = False
            free[u(nfree)] = x
            nfree += 1
        last = p
        counts[K_LOCATE_CYCLES] += c_located - c_start
        counts[K_CAVITY_CYCLES] += cycle_counter() - c_located
    state[0], state[1], state[2], state[3] = ncells, nfree, stamp, last
    return n, 0

@njit(cache=True)
def _insert_range_2d(P, perm, hint, span, pick, t0, C, N, alive, mark, vcell, free, state,
                     counts, dup_of, stack, conflicts, bcell, bface, hkeys, hvals, hstamps):
    return _insert_range(P, 2, perm, hint, span, pick, t0, C, N, alive, mark, vcell, free,
                         state, counts, dup_of, stack, conflicts, bcell, bface, hkeys, hvals,
                         hstamps)


@njit(cache=True)
def _insert_range_3d(P, perm, hint, span, pick, t0, C, N, alive, mark, vcell, free, state,
                     counts, dup_of, stack, conflicts, bcell, bface, hkeys, hvals, hstamps):
    return _insert_range(P, 3, perm, hint, span, pick, t0, C, N, alive, mark, vcell, free,
                         state, counts, dup_of, stack, conflicts, bcell, bface, hkeys, hvals,
                         hstamps)


@njit(cache=True)
def insert_all(P, d, perm, hint, span, capacity=0):
    """Insert P[perm] one by one; returns (C, N, alive, ncells, dup_of,
    counts, ok).  ok is False when the points span fewer than d dimensions."""
    n = P.shape[0]
    counts = np.zeros(N_K, dtype=np.int64)
    dup_of = np.arange(n)
    width = d + 1
    cap = capacity if capacity > 0 else max(16, 8 * n)
    C = np.empty((cap, width), dtype=np.int32)
    N = np.empty((cap, width), dtype=np.int32)
    alive = np.zeros(cap, dtype=np.bool_)
    mark = np.zeros(cap, dtype=np.int32)
    vcell = np.full(n, -1, dtype=np.int32)
    free = np.empty(cap, dtype=np.int32)
    ncells = 0
    pick = _initial_simplex(P, d, perm)
    if pick[0] < 0 or pick[d] < 0:
        return C[:0], N[:0], alive[:0], 0, dup_of, counts, False

    # initial simplex and its d+1 infinite cells
    s = np.empty(width, dtype=np.int64)
    for k in range(width):
        s[k] = perm[pick[k]]
    s3 = s[3] if d == 3 else s[0]
    o, st = _orient_pts(d, P[s[0], 0], P[s[0], 1], P[s[0], d - 1], P[s[1], 0], P[s[1], 1],
                        P[s[1], d - 1], P[s[2], 0], P[s[2], 1], P[s[2], d - 1],
                        P[s3, 0], P[s3, 1], P[s3, d - 1])
    if o < 0.0:
        s[0], s[1] = s[1], s[0]
    for k in range(width):
        C[0, k] = s[k]
    for i in range(width):
        c = 1 + i
        for k in range(width):
            C[c, k] = s[k]
        C[c, i] = INF
        # beyond facet i means on the other side from s[i]: swap two finite slots
        j0 = (i + 1) % width
        j1 = (i + 2) % width
        C[c, j0], C[c, j1] = C[c, j1], C[c, j0]
    ncells = width + 1
    for c in range(ncells):
        alive[c] = True
    for c in range(ncells):
        for i in range(width):
            # neighbour across face i: the other cell holding all of c's vertices but C[c, i]
            for c2 in range(ncells):
                if c2 == c:
                    continue
                shared = 0
                for k in range(width):
                    if k == i:
                        continue
                    for k2 in range(width):
                        if C[c2, k2] == C[c, k]:
                            shared += 1
                if shared == d:
                    N[c, i] = c2
    for k in range(width):
        vcell[s[k]] = 0

    # scratch for cavities; _insert_range asks for more when a cavity needs it
    stack = np.empty(256, dtype=np.int64)
    conflicts = np.empty(256, dtype=np.int64)
    bcell = np.empty(256, dtype=np.int64)
    bface = np.empty(256, dtype=np.int64)
    hkeys = np.empty(4096, dtype=np.int64)
    hvals = np.empty(4096, dtype=np.int64)
    hstamps = np.zeros(4096, dtype=np.int64)
    state = np.array([ncells, 0, 0, s[0]], dtype=np.int64)
    t = 0
    while True:
        if d == 2:
            t, reason = _insert_range_2d(P, perm, hint, span, pick, t, C, N, alive, mark, vcell,
                                         free, state, counts, dup_of, stack, conflicts, bcell,
                                         bface, hkeys, hvals, hstamps)
        else:
            t, reason = _insert_range_3d(P, perm, hint, span, pick, t, C, N, alive, mark, vcell,
                                         free, state, counts, dup_of, stack, conflicts, bcell,
                                         bface, hkeys, hvals, hstamps)
        if reason == 0:
            break
        if reason == 1:
            grow = C.shape[0]
            C = np.concatenate((C, np.empty((grow, width), dtype=np.int32)))
            N = np.concatenate((N, np.empty((grow, width), dtype=np.int32)))
            alive = np.concatenate((alive, np.zeros(grow, dtype=np.bool_)))
            mark = np.concatenate((mark, np.zeros(grow, dtype=np.int32)))
            free = np.concatenate((free, np.empty(grow, dtype=np.int32)))
        else:
            m = 2 * stack.shape[0]
            stack = np.empty(m, dtype=np.int64)
            conflicts = np.empty(m, dtype=np.int64)
            bcell = np.empty(m, dtype=np.int64)
            bface = np.empty(m, dtype=np.int64)
            h = 2 * hkeys.shape[0]
            hkeys = np.empty(h, dtype=np.int64)
            hvals = np.empty(h, dtype=np.int64)
            hstamps = np.zeros(h, dtype=np.int64)
    ncells = state[0]
    return C[:ncells], N[:ncells], alive[:ncells], ncells, dup_of, counts, True


@njit(cache=True)
def finite_cells(C, N, alive, ids):
    """(simplices, neighbors) of the live finite cells, vertices mapped
    through ``ids``, neighbours renumbered, -1 across the hull."""
    m = C.shape[0]
    width = C.shape[1]
    newid = np.full(m, -1, dtype=np.int64)
    k = 0
    for c in range(m):
        if alive[c]:
            finite = True
            for i in range(width):
                if C[c, i] < 0:
                    finite = False
            if finite:
                newid[c] = k
                k += 1
    simplices = np.empty((k, width), dtype=np.int32)
    neighbors = np.empty((k, width), dtype=np.int32)
    for c in range(m):
        j = newid[c]
        if j < 0:
            continue
        for i in range(width):
            simplices[j, i] = ids[C[c, i]]
            neighbors[j, i] = newid[N[c, i]]
    return simplices, neighbors


@njit(cache=True)
def hull_facets(C, alive, ids):
    """Hull facets (2D: edges as a counter-clockwise loop is built by the
    caller) of the live infinite cells, oriented outward."""
    m = C.shape[0]
    width = C.shape[1]
    out = np.empty((m, width - 1), dtype=np.int64)
    k = 0
    for c in range(m):
        if not alive[c]:
            continue
        f = -1
        for i in range(width):
            if C[c, i] < 0:
                f = i
        if f < 0:
            continue
        # the infinite cell with INF -> beyond-point is positive: its facet,
        # in cyclic order after f, faces outward
        for j in range(width - 1):
            out[k, j] = ids[C[c, (f + 1 + j) % width]]
        if width == 4 and f % 2 == 0:
            # rotating a 4-tuple by f+1 places is odd when f is even
            t = out[k, 0]
            out[k, 0] = out[k, 1]
            out[k, 1] = t
        k += 1
    return out[:k]
