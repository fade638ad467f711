"""Staged exact orientation and in-circle predicates (Shewchuk 1997, fqDel 2.4).

Every predicate returns a float whose *sign* is exact; its magnitude is only an
estimate.  Three stages:

1. a float filter: ``|det| > bound * permanent`` decides.  The bound is either
   Triangle's constant (``CCW_A`` / ``ICC_A``) or the level-dependent bound of
   the LFQT (:func:`level_bounds`), passed in by the caller;
2. Shewchuk's stage B: the determinant of the *rounded* coordinate differences,
   computed exactly as an expansion.  It decides when the differences were
   exact or when it clears ``CCW_B`` / ``ICC_B``;
3. exact expansion arithmetic from the coordinates themselves.

Expansion arithmetic is exact only without overflow and underflow; callers keep
coordinates inside ``[2**-150, 2**250]`` (see ``lfqt.api``), which guarantees
that every intermediate value is zero or a normal number.

``counters`` is an int64 array laid out as the ``C_*`` indices below.
"""
import math

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic

EPS = 2.0 ** -53
SPLITTER = 2.0 ** 27 + 1.0
CCW_A = (3.0 + 16.0 * EPS) * EPS
CCW_B = (2.0 + 12.0 * EPS) * EPS
ICC_A = (10.0 + 96.0 * EPS) * EPS
ICC_B = (4.0 + 48.0 * EPS) * EPS
O3D_A = (7.0 + 56.0 * EPS) * EPS
ISP_A = (16.0 + 224.0 * EPS) * EPS
# Level-dependent stage-1 bounds (fqDel 2.4), derived in level_bounds below.
CCW_EXACT_DIFF = (2.0 + 16.0 * EPS) * EPS
ICC_EXACT_DIFF = (7.0 + 56.0 * EPS) * EPS
ICC_EXACT_PRODUCTS = (3.0 + 24.0 * EPS) * EPS

C_ORIENT, C_ORIENT_S1, C_ORIENT_S2, C_INCIRCLE, C_INCIRCLE_S1, C_INCIRCLE_S2 = range(6)
N_COUNTERS = 6
COUNTER_NAMES = ("orient", "orient_stage1_undecided", "orient_stage2_undecided",
                 "incircle", "incircle_stage1_undecided", "incircle_stage2_undecided")
WORK_SIZE = 512  # doubles of scratch space of incircle's stage B


@njit(cache=True, inline="always")
def two_sum(a, b):
    x = a + b
    bv = x - a
    av = x - bv
    return x, (a - av) + (b - bv)


@njit(cache=True, inline="always")
def two_diff(a, b):
    x = a - b
    bv = a - x
    av = x + bv
    return x, (a - av) + (bv - b)


@njit(cache=True, inline="always")
def _split(a):
    c = SPLITTER * a
    hi = c - (c - a)
    return hi, a - hi


@njit(cache=True, inline="always")
def two_product(a, b):
    x = a * b
    ahi, alo = _split(a)
    bhi, blo = _split(b)
    err = x - ahi * bhi
    err = err - alo * bhi
    err = err - ahi * blo
    return x, alo * blo - err


@njit(cache=True)
def expansion_sum(e, elen, f, flen, h):
    """h = e + f for nonoverlapping expansions (Shewchuk's fast expansion sum,
    zero-eliminating); returns the length of h."""
    i = 0
    j = 0
    if j >= flen or (i < elen and abs(e[i]) < abs(f[j])):
        q = e[i]
        i += 1
    else:
        q = f[j]
        j += 1
    hlen = 0
    while i < elen or j < flen:
        if j >= flen or (i < elen and abs(e[i]) < abs(f[j])):
            g = e[i]
            i += 1
        else:
            g = f[j]
            j += 1
        q, err = two_sum(q, g)
        if err != 0.0:
            h[hlen] = err
            hlen += 1
    if q != 0.0 or hlen == 0:
        h[hlen] = q
        hlen += 1
    return hlen


@njit(cache=True)
def scale_expansion(e, elen, b, h):
    """h = b * e, zero-eliminating; returns the length of h."""
    q, hh = two_product(e[0], b)
    hlen = 0
    if hh != 0.0:
        h[hlen] = hh
        hlen += 1
    for i in range(1, elen):
        p1, p0 = two_product(e[i], b)
        s, hh = two_sum(q, p0)
        if hh != 0.0:
            h[hlen] = hh
            hlen += 1
        q, hh = two_sum(p1, s)
        if hh != 0.0:
            h[hlen] = hh
            hlen += 1
    if q != 0.0 or hlen == 0:
        h[hlen] = q
        hlen += 1
    return hlen


@njit(cache=True)
def expansion_product(e, elen, f, flen):
    """e * f as a new expansion (rarely used: only the exact stage needs it)."""
    cap = 2 * elen * flen + 1
    acc = np.zeros(cap)
    acc_len = 1
    tmp = np.empty(2 * elen)
    out = np.empty(cap)
    for j in range(flen):
        tlen = scale_expansion(e, elen, f[j], tmp)
        olen = expansion_sum(acc, acc_len, tmp, tlen, out)
        acc, out = out, acc
        acc_len = olen
    return acc, acc_len


@njit(cache=True)
def _negate(e, elen):
    out = np.empty(elen)
    for i in range(elen):
        out[i] = -e[i]
    return out


@njit(cache=True)
def _exact_diff(a, b):
    x, y = two_diff(a, b)
    out = np.empty(2)
    if y == 0.0:
        out[0] = x
        return out, 1
    out[0] = y
    out[1] = x
    return out, 2


@njit(cache=True)
def _expansion_sign(e, elen):
    top = e[elen - 1]
    return 1.0 if top > 0.0 else (-1.0 if top < 0.0 else 0.0)


@njit(cache=True)
def _cross_exact(ux, uxl, vy, vyl, uy, uyl, vx, vxl):
    """ux*vy - uy*vx for expansion operands."""
    p, pl = expansion_product(ux, uxl, vy, vyl)
    q, ql = expansion_product(uy, uyl, vx, vxl)
    out = np.empty(pl + ql)
    n = expansion_sum(p, pl, _negate(q, ql), ql, out)
    return out, n


@njit(cache=True)
def orient2d_exact(ax, ay, bx, by, cx, cy):
    """Exact sign of det[[ax-cx, ay-cy], [bx-cx, by-cy]] as -1.0, 0.0 or 1.0."""
    acx, acxl = _exact_diff(ax, cx)
    acy, acyl = _exact_diff(ay, cy)
    bcx, bcxl = _exact_diff(bx, cx)
    bcy, bcyl = _exact_diff(by, cy)
    d, dl = _cross_exact(acx, acxl, bcy, bcyl, acy, acyl, bcx, bcxl)
    return _expansion_sign(d, dl)


@njit(cache=True)
def incircle_exact(ax, ay, bx, by, cx, cy, dx, dy):
    """Exact sign of the in-circle determinant: > 0 when d lies inside the
    circle through a, b, c (counter-clockwise)."""
    adx, adxl = _exact_diff(ax, dx)
    ady, adyl = _exact_diff(ay, dy)
    bdx, bdxl = _exact_diff(bx, dx)
    bdy, bdyl = _exact_diff(by, dy)
    cdx, cdxl = _exact_diff(cx, dx)
    cdy, cdyl = _exact_diff(cy, dy)
    total = np.zeros(1)
    total_len = 1
    for k in range(3):
        if k == 0:
            px, pxl, py, pyl = adx, adxl, ady, adyl
            ux, uxl, uy, uyl, vx, vxl, vy, vyl = bdx, bdxl, bdy, bdyl, cdx, cdxl, cdy, cdyl
        elif k == 1:
            px, pxl, py, pyl = bdx, bdxl, bdy, bdyl
            ux, uxl, uy, uyl, vx, vxl, vy, vyl = cdx, cdxl, cdy, cdyl, adx, adxl, ady, adyl
        else:
            px, pxl, py, pyl = cdx, cdxl, cdy, cdyl
            ux, uxl, uy, uyl, vx, vxl, vy, vyl = adx, adxl, ady, adyl, bdx, bdxl, bdy, bdyl
        xx, xxl = expansion_product(px, pxl, px, pxl)
        yy, yyl = expansion_product(py, pyl, py, pyl)
        lift = np.empty(xxl + yyl)
        liftl = expansion_sum(xx, xxl, yy, yyl, lift)
        cr, crl = _cross_exact(ux, uxl, vy, vyl, uy, uyl, vx, vxl)
        term, terml = expansion_product(lift, liftl, cr, crl)
        new_total = np.empty(total_len + terml)
        total_len = expansion_sum(total, total_len, term, terml, new_total)
        total = new_total
    return _expansion_sign(total, total_len)


@njit(cache=True, inline="always")
def _int_unit(m, limit_bits):
    """Power of two u with m / u < 2**limit_bits, for the integer fast paths."""
    return math.ldexp(1.0, math.frexp(m)[1] - limit_bits)


@njit(cache=True, inline="always")
def _as_int(v, u):
    """v / u as an int64 when that is an integer, else a sentinel."""
    q = v / u  # exact: u is a power of two and no value leaves the normal range
    return np.int64(q) if q == np.floor(q) else np.int64(-(1 << 62))


_NOT_INT = -(1 << 62)


@njit(cache=True, inline="always")
def _sign_int(v):
    return 1.0 if v > 0 else (-1.0 if v < 0 else 0.0)


@njit(cache=True, inline="always")
def _sign4(x3, x2, x1, x0):
    for v in (x3, x2, x1, x0):
        if v != 0.0:
            return 1.0 if v > 0.0 else -1.0
    return 0.0


@njit(cache=True, inline="always")
def orient2d_staged(ax, ay, bx, by, cx, cy, bound):
    """(value, stage): value > 0 when a, b, c turn counter-clockwise, < 0
    clockwise, 0 collinear; stage is 0, 1 or 2 for the stage that decided.
    Scalars only: an array argument on this hot path would cost an atomic
    reference-count update per call."""
    acx = ax - cx
    bcx = bx - cx
    acy = ay - cy
    bcy = by - cy
    detleft = acx * bcy
    detright = acy * bcx
    det = detleft - detright
    # One well-predicted branch: Shewchuk's sign shortcuts mispredict on
    # random input and cost more than they save.
    detsum = abs(detleft) + abs(detright)
    if abs(det) >= bound * detsum:
        return det, 0
    return _orient2d_adapt(ax, ay, bx, by, cx, cy, detsum)


@njit(cache=True, inline="always")
def orient2d(ax, ay, bx, by, cx, cy, bound, counters):
    """orient2d_staged, counting calls and undecided stages in ``counters``."""
    det, stage = orient2d_staged(ax, ay, bx, by, cx, cy, bound)
    counters[C_ORIENT] += 1
    if stage > 0:
        counters[C_ORIENT_S1] += 1
        if stage > 1:
            counters[C_ORIENT_S2] += 1
    return det


@njit(cache=True)
def _orient2d_adapt(ax, ay, bx, by, cx, cy, detsum):
    """Stages 2 and 3 of orient2d: (sign-exact value, deciding stage)."""
    acx = ax - cx
    bcx = bx - cx
    acy = ay - cy
    bcy = by - cy
    # Stage B: exact determinant of the rounded differences.
    l1, l0 = two_product(acx, bcy)
    r1, r0 = two_product(acy, bcx)
    i, x0 = two_diff(l0, r0)
    j, x1 = two_sum(l1, i)
    k, x1b = two_diff(x1, r1)
    x3, x2 = two_sum(j, k)
    # (x3, x2, x1b, x0) is the Two-Two-Diff expansion of (l1 + l0) - (r1 + r0)
    tails_zero = (two_diff(ax, cx)[1] == 0.0 and two_diff(bx, cx)[1] == 0.0
                  and two_diff(ay, cy)[1] == 0.0 and two_diff(by, cy)[1] == 0.0)
    if tails_zero:
        return _sign4(x3, x2, x1b, x0), 1
    est = x3 + x2 + x1b + x0
    if abs(est) >= CCW_B * detsum:
        return est, 1
    return orient2d_exact(ax, ay, bx, by, cx, cy), 2


@njit(cache=True)
def _lifted_term(px, py, ux, uy, vx, vy, work, base):
    """(px^2 + py^2) * (ux*vy - vx*uy) for exact doubles, as an expansion
    stored at work[base : base + len]; returns len (<= 32).  work[256:304]
    is scratch."""
    l1, l0 = two_product(ux, vy)
    r1, r0 = two_product(vx, uy)
    i, x0 = two_diff(l0, r0)
    j, x1 = two_sum(l1, i)
    k, x1b = two_diff(x1, r1)
    x3, x2 = two_sum(j, k)
    cr = work[256:260]
    cr[0] = x0
    cr[1] = x1b
    cr[2] = x2
    cr[3] = x3
    t8 = work[260:268]
    t16a = work[272:288]
    t16b = work[288:304]
    n8 = scale_expansion(cr, 4, px, t8)
    na = scale_expansion(t8, n8, px, t16a)
    n8 = scale_expansion(cr, 4, py, t8)
    nb = scale_expansion(t8, n8, py, t16b)
    return expansion_sum(t16a, na, t16b, nb, work[base: base + 32])


@njit(cache=True, inline="always")
def incircle_staged(ax, ay, bx, by, cx, cy, dx, dy, bound):
    """(value, stage): value > 0 when d lies inside the circle through a, b, c
    (counter-clockwise), < 0 outside, 0 on it; stage as in orient2d_staged."""
    adx = ax - dx
    bdx = bx - dx
    cdx = cx - dx
    ady = ay - dy
    bdy = by - dy
    cdy = cy - dy
    bdxcdy = bdx * cdy
    cdxbdy = cdx * bdy
    alift = adx * adx + ady * ady
    cdxady = cdx * ady
    adxcdy = adx * cdy
    blift = bdx * bdx + bdy * bdy
    adxbdy = adx * bdy
    bdxady = bdx * ady
    clift = cdx * cdx + cdy * cdy
    det = (alift * (bdxcdy - cdxbdy) + blift * (cdxady - adxcdy)
           + clift * (adxbdy - bdxady))
    permanent = ((abs(bdxcdy) + abs(cdxbdy)) * alift
                 + (abs(cdxady) + abs(adxcdy)) * blift
                 + (abs(adxbdy) + abs(bdxady)) * clift)
    if abs(det) > bound * permanent:
        return det, 0
    return _incircle_adapt(ax, ay, bx, by, cx, cy, dx, dy, permanent)


@njit(cache=True, inline="always")
def incircle(ax, ay, bx, by, cx, cy, dx, dy, bound, counters):
    """incircle_staged, counting calls and undecided stages in ``counters``."""
    det, stage = incircle_staged(ax, ay, bx, by, cx, cy, dx, dy, bound)
    counters[C_INCIRCLE] += 1
    if stage > 0:
        counters[C_INCIRCLE_S1] += 1
        if stage > 1:
            counters[C_INCIRCLE_S2] += 1
    return det


@njit(cache=True)
def _incircle_adapt(ax, ay, bx, by, cx, cy, dx, dy, permanent):
    """Stages 2 and 3 of incircle: (sign-exact value, deciding stage)."""
    adx = ax - dx
    bdx = bx - dx
    cdx = cx - dx
    ady = ay - dy
    bdy = by - dy
    cdy = cy - dy
    tails_zero = (two_diff(ax, dx)[1] == 0.0 and two_diff(bx, dx)[1] == 0.0
                  and two_diff(cx, dx)[1] == 0.0 and two_diff(ay, dy)[1] == 0.0
                  and two_diff(by, dy)[1] == 0.0 and two_diff(cy, dy)[1] == 0.0)
    if tails_zero:
        # Exact differences that are small integers in a common power-of-two
        # unit (grids, cocircular integer sets): an int64 determinant, no
        # expansions (|d| < 2**13 keeps every product below 2**56).
        m = max(abs(adx), abs(bdx), abs(cdx), abs(ady), abs(bdy), abs(cdy))
        if m == 0.0:
            return 0.0, 1
        u = _int_unit(m, 13)
        a0, a1, b0, b1, c0, c1 = (_as_int(adx, u), _as_int(ady, u), _as_int(bdx, u),
                                  _as_int(bdy, u), _as_int(cdx, u), _as_int(cdy, u))
        if min(a0, a1, b0, b1, c0, c1) != _NOT_INT:
            v = ((a0 * a0 + a1 * a1) * (b0 * c1 - c0 * b1)
                 + (b0 * b0 + b1 * b1) * (c0 * a1 - a0 * c1)
                 + (c0 * c0 + c1 * c1) * (a0 * b1 - b0 * a1))
            return _sign_int(v), 1
    work = np.empty(WORK_SIZE)
    # Stage B: exact determinant of the rounded differences.
    na = _lifted_term(adx, ady, bdx, bdy, cdx, cdy, work, 0)
    nb = _lifted_term(bdx, bdy, cdx, cdy, adx, ady, work, 32)
    nc = _lifted_term(cdx, cdy, adx, ady, bdx, bdy, work, 64)
    ab = work[96:160]
    nab = expansion_sum(work[0:32], na, work[32:64], nb, ab)
    fin = work[160:256]
    nfin = expansion_sum(ab, nab, work[64:96], nc, fin)
    if tails_zero:
        return _expansion_sign(fin, nfin), 1
    est = 0.0
    for i in range(nfin):
        est += fin[i]
    if abs(est) >= ICC_B * permanent:
        return est, 1
    return incircle_exact(ax, ay, bx, by, cx, cy, dx, dy), 2


@njit(cache=True)
def _det3_exact(ux, uxl, uy, uyl, uz, uzl, vx, vxl, vy, vyl, vz, vzl, wx, wxl, wy, wyl, wz, wzl):
    """det[[u], [v], [w]] of expansion entries, expanded along z."""
    total = np.zeros(1)
    total_len = 1
    for k in range(3):
        if k == 0:
            z, zl = uz, uzl
            px, pxl, py, pyl, qx, qxl, qy, qyl = vx, vxl, vy, vyl, wx, wxl, wy, wyl
        elif k == 1:
            z, zl = vz, vzl
            px, pxl, py, pyl, qx, qxl, qy, qyl = wx, wxl, wy, wyl, ux, uxl, uy, uyl
        else:
            z, zl = wz, wzl
            px, pxl, py, pyl, qx, qxl, qy, qyl = ux, uxl, uy, uyl, vx, vxl, vy, vyl
        cr, crl = _cross_exact(px, pxl, qy, qyl, py, pyl, qx, qxl)
        term, terml = expansion_product(z, zl, cr, crl)
        new_total = np.empty(total_len + terml)
        total_len = expansion_sum(total, total_len, term, terml, new_total)
        total = new_total
    return total, total_len


@njit(cache=True)
def _int_det3(ux, uy, uz, vx, vy, vz, wx, wy, wz, exact):
    """Sign of det[u, v, w] in int64 when the (exact) entries are integers
    below 2**16 in a common power-of-two unit; 2.0 when not applicable."""
    if not exact:
        return 2.0
    m = max(abs(ux), abs(uy), abs(uz), abs(vx), abs(vy), abs(vz), abs(wx), abs(wy), abs(wz))
    if m == 0.0:
        return 0.0
    u = _int_unit(m, 16)
    e = np.empty(9, dtype=np.int64)
    vals = (ux, uy, uz, vx, vy, vz, wx, wy, wz)
    for k in range(9):
        e[k] = _as_int(vals[k], u)
        if e[k] == _NOT_INT:
            return 2.0
    v = (e[0] * (e[4] * e[8] - e[5] * e[7]) - e[1] * (e[3] * e[8] - e[5] * e[6])
         + e[2] * (e[3] * e[7] - e[4] * e[6]))
    return _sign_int(v)


@njit(cache=True)
def orient3d_exact(ax, ay, az, bx, by, bz, cx, cy, cz, dx, dy, dz):
    """Exact sign of det[b-a, c-a, d-a]: > 0 for a right-handed tetrahedron."""
    q = _int_det3(bx - ax, by - ay, bz - az, cx - ax, cy - ay, cz - az, dx - ax, dy - ay,
                  dz - az, two_diff(bx, ax)[1] == 0.0 and two_diff(by, ay)[1] == 0.0
                  and two_diff(bz, az)[1] == 0.0 and two_diff(cx, ax)[1] == 0.0
                  and two_diff(cy, ay)[1] == 0.0 and two_diff(cz, az)[1] == 0.0
                  and two_diff(dx, ax)[1] == 0.0 and two_diff(dy, ay)[1] == 0.0
                  and two_diff(dz, az)[1] == 0.0)
    if q != 2.0:
        return q
    ux, uxl = _exact_diff(bx, ax)
    uy, uyl = _exact_diff(by, ay)
    uz, uzl = _exact_diff(bz, az)
    vx, vxl = _exact_diff(cx, ax)
    vy, vyl = _exact_diff(cy, ay)
    vz, vzl = _exact_diff(cz, az)
    wx, wxl = _exact_diff(dx, ax)
    wy, wyl = _exact_diff(dy, ay)
    wz, wzl = _exact_diff(dz, az)
    d, dl = _det3_exact(ux, uxl, uy, uyl, uz, uzl, vx, vxl, vy, vyl, vz, vzl,
                        wx, wxl, wy, wyl, wz, wzl)
    return _expansion_sign(d, dl)


@njit(cache=True, inline="always")
def orient3d_staged(ax, ay, az, bx, by, bz, cx, cy, cz, dx, dy, dz, bound):
    """(value, stage): value > 0 when (a, b, c, d) is right-handed, i.e.
    det[b-a, c-a, d-a] > 0; stage 0 filter, 2 exact."""
    adx = ax - dx
    bdx = bx - dx
    cdx = cx - dx
    ady = ay - dy
    bdy = by - dy
    cdy = cy - dy
    adz = az - dz
    bdz = bz - dz
    cdz = cz - dz
    bdxcdy = bdx * cdy
    cdxbdy = cdx * bdy
    cdxady = cdx * ady
    adxcdy = adx * cdy
    adxbdy = adx * bdy
    bdxady = bdx * ady
    # Shewchuk's det[a-d, b-d, c-d] is minus ours
    det = -(adz * (bdxcdy - cdxbdy) + bdz * (cdxady - adxcdy) + cdz * (adxbdy - bdxady))
    permanent = ((abs(bdxcdy) + abs(cdxbdy)) * abs(adz) + (abs(cdxady) + abs(adxcdy)) * abs(bdz)
                 + (abs(adxbdy) + abs(bdxady)) * abs(cdz))
    if abs(det) > bound * permanent:
        return det, 0
    return orient3d_exact(ax, ay, az, bx, by, bz, cx, cy, cz, dx, dy, dz), 2


@njit(cache=True)
def insphere_exact(ax, ay, az, bx, by, bz, cx, cy, cz, dx, dy, dz, ex, ey, ez):
    """Exact sign: > 0 when e lies inside the sphere through the right-handed
    tetrahedron (a, b, c, d)."""
    rows = np.array([[ax, ay, az], [bx, by, bz], [cx, cy, cz], [dx, dy, dz]], dtype=np.float64)
    # Integer fast path (cospherical grids): exact differences, integers
    # below 2**10 in a common unit, keep every product below 2**57.
    diffs = np.empty((4, 3))
    exact = True
    m = 0.0
    for k in range(4):
        for j in range(3):
            ev = ex if j == 0 else (ey if j == 1 else ez)
            dv, tail = two_diff(rows[k, j], ev)
            diffs[k, j] = dv
            exact = exact and tail == 0.0
            m = max(m, abs(dv))
    if exact:
        if m == 0.0:
            return 0.0
        u = _int_unit(m, 10)
        D = np.empty((4, 4), dtype=np.int64)
        ok = True
        for k in range(4):
            for j in range(3):
                D[k, j] = _as_int(diffs[k, j], u)
                ok = ok and D[k, j] != _NOT_INT
            D[k, 3] = D[k, 0] * D[k, 0] + D[k, 1] * D[k, 1] + D[k, 2] * D[k, 2]
        if ok:
            v = np.int64(0)
            for k in range(4):
                r0 = 1 if k == 0 else 0
                r1 = 2 if k <= 1 else 1
                r2 = 3 if k <= 2 else 2
                minor = (D[r0, 0] * (D[r1, 1] * D[r2, 2] - D[r1, 2] * D[r2, 1])
                         - D[r0, 1] * (D[r1, 0] * D[r2, 2] - D[r1, 2] * D[r2, 0])
                         + D[r0, 2] * (D[r1, 0] * D[r2, 1] - D[r1, 1] * D[r2, 0]))
                term = D[k, 3] * minor
                v += -term if k % 2 == 0 else term
            return -_sign_int(v)
    total = np.zeros(1)
    total_len = 1
    # rows r_i = (p_i - e, |p_i - e|^2); det of the 4x4 by the last column
    for k in range(4):
        px, py, pz = rows[k, 0], rows[k, 1], rows[k, 2]
        sx, sxl = _exact_diff(px, ex)
        sy, syl = _exact_diff(py, ey)
        sz, szl = _exact_diff(pz, ez)
        xx, xxl = expansion_product(sx, sxl, sx, sxl)
        yy, yyl = expansion_product(sy, syl, sy, syl)
        zz, zzl = expansion_product(sz, szl, sz, szl)
        lift = np.empty(xxl + yyl + zzl)
        t = np.empty(xxl + yyl)
        tl = expansion_sum(xx, xxl, yy, yyl, t)
        liftl = expansion_sum(t, tl, zz, zzl, lift)
        i0 = 1 if k == 0 else 0
        i1 = 2 if k <= 1 else 1
        i2 = 3 if k <= 2 else 2
        q0 = rows[i0]
        q1 = rows[i1]
        q2 = rows[i2]
        ux, uxl = _exact_diff(q0[0], ex)
        uy, uyl = _exact_diff(q0[1], ey)
        uz, uzl = _exact_diff(q0[2], ez)
        vx, vxl = _exact_diff(q1[0], ex)
        vy, vyl = _exact_diff(q1[1], ey)
        vz, vzl = _exact_diff(q1[2], ez)
        wx, wxl = _exact_diff(q2[0], ex)
        wy, wyl = _exact_diff(q2[1], ey)
        wz, wzl = _exact_diff(q2[2], ez)
        minor, minorl = _det3_exact(ux, uxl, uy, uyl, uz, uzl, vx, vxl, vy, vyl, vz, vzl,
                                    wx, wxl, wy, wyl, wz, wzl)
        term, terml = expansion_product(lift, liftl, minor, minorl)
        # cofactor sign of column 4, row k: (-1)^(k+3); rows are (a-e, b-e, c-e, d-e)
        if k % 2 == 0:
            term = _negate(term, terml)
        new_total = np.empty(total_len + terml)
        total_len = expansion_sum(total, total_len, term, terml, new_total)
        total = new_total
    # det[[a-e, |a-e|^2], ...] > 0 iff e inside for Shewchuk-positive (left-handed) order;
    # for our right-handed order the sign flips
    return -_expansion_sign(total, total_len)


@njit(cache=True, inline="always")
def insphere_staged(ax, ay, az, bx, by, bz, cx, cy, cz, dx, dy, dz, ex, ey, ez, bound):
    """(value, stage): value > 0 when e lies inside the sphere through the
    right-handed tetrahedron (a, b, c, d), < 0 outside, 0 on it."""
    aex = ax - ex
    bex = bx - ex
    cex = cx - ex
    dex = dx - ex
    aey = ay - ey
    bey = by - ey
    cey = cy - ey
    dey = dy - ey
    aez = az - ez
    bez = bz - ez
    cez = cz - ez
    dez = dz - ez
    aexbey = aex * bey
    bexaey = bex * aey
    bexcey = bex * cey
    cexbey = cex * bey
    cexdey = cex * dey
    dexcey = dex * cey
    dexaey = dex * aey
    aexdey = aex * dey
    aexcey = aex * cey
    cexaey = cex * aey
    bexdey = bex * dey
    dexbey = dex * bey
    ab = aexbey - bexaey
    bc = bexcey - cexbey
    cd = cexdey - dexcey
    da = dexaey - aexdey
    ac = aexcey - cexaey
    bd = bexdey - dexbey
    abc = aez * bc - bez * ac + cez * ab
    bcd = bez * cd - cez * bd + dez * bc
    cda = cez * da + dez * ac + aez * cd
    dab = dez * ab + aez * bd + bez * da
    alift = aex * aex + aey * aey + aez * aez
    blift = bex * bex + bey * bey + bez * bez
    clift = cex * cex + cey * cey + cez * cez
    dlift = dex * dex + dey * dey + dez * dez
    det = -((dlift * abc - clift * dab) + (blift * cda - alift * bcd))
    abp = abs(aexbey) + abs(bexaey)
    bcp = abs(bexcey) + abs(cexbey)
    cdp = abs(cexdey) + abs(dexcey)
    dap = abs(dexaey) + abs(aexdey)
    acp = abs(aexcey) + abs(cexaey)
    bdp = abs(bexdey) + abs(dexbey)
    abcp = abs(aez) * bcp + abs(bez) * acp + abs(cez) * abp
    bcdp = abs(bez) * cdp + abs(cez) * bdp + abs(dez) * bcp
    cdap = abs(cez) * dap + abs(dez) * acp + abs(aez) * cdp
    dabp = abs(dez) * abp + abs(aez) * bdp + abs(bez) * dap
    permanent = dlift * abcp + clift * dabp + blift * cdap + alift * bcdp
    if abs(det) > bound * permanent:
        return det, 0
    return insphere_exact(ax, ay, az, bx, by, bz, cx, cy, cz, dx, dy, dz, ex, ey, ez), 2


@intrinsic
def float_bits(typingctx, v):
    """The IEEE bits of a float64 as an int64 (a register move)."""
    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], ir.IntType(64))
    return types.int64(types.float64), codegen


@njit(cache=True, inline="always")
def binade(v, scale_exp, emin):
    """floor(log2 |v|) - scale_exp, at least emin (emin for zero): the
    binade of an input value stored scaled by 2**scale_exp.  Stored values
    are normal (the rescale window); a subnormal would count as emin.  From
    the exponent bits, since frexp is a library call and this runs once per
    merge."""
    biased = (float_bits(v) >> 52) & 0x7FF
    if biased == 0:
        return emin
    e = biased - 1023 - scale_exp
    return e if e > emin else emin


@njit(cache=True)
def level_bounds(level, coord_bits, exp_bits, mant_bits, ex, ey):
    """Stage-1 bounds (orient, incircle) for predicates on points that share
    every Morton key bit above ``level`` (fqDel section 2.4).

    ``ex``/``ey`` are the binade exponents of the node's x and y in the input
    format (floor(log2|v|), or the smallest normal exponent for zero and
    subnormals).  Once a node shares sign and exponent in both coordinates,
    coordinate differences are exact (Sterbenz), multiples of one ulp and
    shorter than the unshared mantissa.  With ``b`` the bit span of all
    differences: products are exact when they fit 53 bits, which makes the
    orientation sign exact (bound 0) and, for in-circle, removes roundings
    from the error analysis of Shewchuk's stage A.
    """
    sx = coord_bits - (level + 1) // 2
    sy = coord_bits - level // 2 - 1
    need = 1 + exp_bits
    if sx < need or sy < need:
        return CCW_A, ICC_A
    mx = sx - need
    my = sy - need
    lx = ex - mant_bits
    ly = ey - mant_bits
    bits_x = mant_bits - mx
    bits_y = mant_bits - my
    ccw = 0.0 if bits_x + bits_y <= 53 else CCW_EXACT_DIFF
    span = max(ex - mx, ey - my) - min(lx, ly)
    if 4 * span + 4 <= 53:
        icc = 0.0
    elif 2 * span + 1 <= 53:
        icc = ICC_EXACT_PRODUCTS
    else:
        icc = ICC_EXACT_DIFF
    return ccw, icc


def new_counters():
    return np.zeros(N_COUNTERS, dtype=np.int64)
