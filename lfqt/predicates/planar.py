"""2D predicates, staged (Shewchuk 1997): orientation and in-circle.

Every predicate returns a float whose *sign* is exact; its magnitude is only
an estimate.  Three stages, numbered 1, 2, 3 everywhere in lfqt (the stage a
``*_staged`` function returns, the counters' ``stage1_undecided`` and
``stage2_undecided``, lfqt.predicates.counters); their error bounds keep
the letters of Shewchuk's predicates.c (``CCW_A``, ``ICC_B``, ...):

1. a float filter: ``|det| > bound * permanent`` decides.  The bound is
   Triangle's constant (``CCW_A`` / ``ICC_A``) or the level-dependent bound of
   the LFQT (lfqt.predicates.levels), passed in by the caller.  A caller that
   knows a bound on the permanent of every call in a batch (the merge: the
   points of one quad-tree node) passes ``static >= bound * permanent``, and
   ``|det| > static`` decides before the permanent is computed (fqDel 2.4's
   static filter; ``static_bounds``).  What it leaves goes on to the dynamic
   test, so the stage that decides a call is the same with or without it;
2. ``*_adapt``, first part: the determinant of the *rounded* coordinate
   differences.  It decides when the differences were exact or when it
   clears ``CCW_B`` / ``ICC_B``.  Orientation computes it exactly as an
   expansion; in-circle first in double-double (``_incircle_dd``, within
   ``ICC_DD`` times the permanent), which decides all but the truly
   near-degenerate calls at a fraction of the expansions' cost, and only
   then exactly;
3. the exact stage (``*_adapt``, second part): for in-circle first
   Shewchuk's C1 correction (the
   first-order terms of the differences' roundings, in floating point, with
   its own error bound), then ``*_exact``: expansion arithmetic from the
   coordinates themselves.

The ``*_staged`` functions return (value, deciding stage 1, 2 or 3) and take
scalars only: an array argument on a hot path costs numba an atomic
reference-count update per call.
"""
import numpy as np
from numba import njit

from ..indexing import stack_array
from .expansion import (DD_CEIL, DD_FLOOR, EPS, NOT_INT, as_int, cross_exact, dd_cross, dd_lift2,
                        dd_sum3, dd_times, exact_diff, expansion_product, expansion_sign,
                        expansion_sum, int_unit, scale_expansion, sign4, sign_int, two_diff,
                        two_product, two_sum)

# Shewchuk's error bounds (predicates.c, exactinit): |det - exact| <= bound *
# permanent for stage 1's float evaluation (his A), and for stage 2's
# estimate (his B).
CCW_A = (3.0 + 16.0 * EPS) * EPS
CCW_B = (2.0 + 12.0 * EPS) * EPS
ICC_A = (10.0 + 96.0 * EPS) * EPS
ICC_B = (4.0 + 48.0 * EPS) * EPS
ICC_C = (44.0 + 576.0 * EPS) * EPS * EPS  # stage 3's first step (Shewchuk's C1)
RESULT_ERR = (3.0 + 8.0 * EPS) * EPS  # the rounding of the stage-2 estimate
# _incircle_dd's error over the permanent: derived there, and used with room
# for the rounding of the permanent and of the returned value.
ICC_DD_DERIVED = 39.4 * EPS * EPS
ICC_DD = 64.0 * EPS * EPS
WORK_SIZE = 304  # doubles of scratch space of incircle's stage 2 (see _lifted_term)


@njit(cache=True, inline="always")
def orient2d_staged(ax, ay, bx, by, cx, cy, bound, static=np.inf):
    """(value, stage): value > 0 when a, b, c turn counter-clockwise, < 0
    clockwise, 0 collinear; stage is 1, 2 or 3 for the stage that decided.
    ``static``: see the module's stage 1.  Scalars only: an array argument on
    this hot path would cost an atomic reference-count update per call."""
    acx = ax - cx
    bcx = bx - cx
    acy = ay - cy
    bcy = by - cy
    return orient2d_decide(acx * bcy - acy * bcx, (acx, acy, bcx, bcy), (ax, ay, bx, by, cx, cy),
                           bound, static)


@njit(cache=True, inline="always")
def orient2d_decide(det, diffs, points, bound, static):
    """orient2d_staged of the points (ax, ay, bx, by, cx, cy) from ``det``,
    which the caller computed as ``acx * bcy - acy * bcx`` of the rounded
    differences ``diffs`` = (acx, acy, bcx, bcy), ac = a - c and bc = b - c
    (the merge shares differences and products between predicates,
    lfqt.dc.merge): the same value and stage."""
    acx, acy, bcx, bcy = diffs
    if abs(det) > static:
        return det, 1
    # One well-predicted branch: Shewchuk's sign shortcuts mispredict on
    # random input and cost more than they save.
    detsum = abs(acx * bcy) + abs(acy * bcx)
    if abs(det) >= bound * detsum:
        return det, 1
    ax, ay, bx, by, cx, cy = points
    return _orient2d_adapt(ax, ay, bx, by, cx, cy, detsum)


# Static bounds are switched off (infinite) below this: a product that left
# the normal range would have lost the relative accuracy the bound relies on.
STATIC_FLOOR = 2.0 ** -1000
STATIC_MARGIN = 1.0 + 2.0 ** -20  # covers the roundings of the bound itself


@njit(cache=True, inline="always")
def static_bounds(wx, wy, ccw, icc):
    """Static stage-1 bounds (orient, in-circle) for calls whose points all lie
    in a box of width ``wx`` and height ``wy`` (each the rounded difference of
    two coordinates), given the dynamic bounds ``ccw``/``icc``.

    Rounding is monotone, so every rounded difference in a call is at most
    wx or wy in magnitude, and so is each rounded product and sum below
    what the same expression of wx and wy rounds to:

        orient permanent     |acx bcy| + |acy bcx|        <= 2 wx wy
        in-circle permanent  sum of 3 lifts (<= wx^2 + wy^2)
                             times 2 cross terms (<= wx wy each)
                                                          <= 6 (wx^2 + wy^2) wx wy

    which STATIC_MARGIN pads for the roundings of these two lines.  A bound
    that left the normal range, or overflowed, is switched off."""
    area = wx * wy
    return (usable_static(ccw, ccw * (2.0 * area) * STATIC_MARGIN),
            usable_static(icc, icc * (6.0 * (wx * wx + wy * wy) * area) * STATIC_MARGIN))


@njit(cache=True, inline="always")
def usable_static(bound, static):
    """``static`` (a static bound for the dynamic ``bound``), or inf (off)
    where it left the normal range or overflowed; a zero ``bound`` keeps
    its zero static bound."""
    if bound > 0.0 and not (STATIC_FLOOR <= static < np.inf):
        return np.inf
    return static


@njit(cache=True)
def _orient2d_adapt(ax, ay, bx, by, cx, cy, detsum):
    """Stages 2 and 3 of orient2d: (sign-exact value, deciding stage 2 or 3)."""
    acx = ax - cx
    bcx = bx - cx
    acy = ay - cy
    bcy = by - cy
    # Stage 2: exact determinant of the rounded differences (bound B).
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
        return sign4(x3, x2, x1b, x0), 2
    est = x3 + x2 + x1b + x0
    if abs(est) >= CCW_B * detsum:
        return est, 2
    return orient2d_exact(ax, ay, bx, by, cx, cy), 3


@njit(cache=True)
def orient2d_exact(ax, ay, bx, by, cx, cy):
    """Exact sign of det[[ax-cx, ay-cy], [bx-cx, by-cy]] as -1.0, 0.0 or 1.0."""
    acx, acxl = exact_diff(ax, cx)
    acy, acyl = exact_diff(ay, cy)
    bcx, bcxl = exact_diff(bx, cx)
    bcy, bcyl = exact_diff(by, cy)
    d, dl = cross_exact(acx, acxl, bcy, bcyl, acy, acyl, bcx, bcxl)
    return expansion_sign(d, dl)


@njit(cache=True, inline="always")
def incircle_staged(ax, ay, bx, by, cx, cy, dx, dy, bound, static=np.inf):
    """(value, stage): value > 0 when d lies inside the circle through a, b, c
    (counter-clockwise), < 0 outside, 0 on it; stage and ``static`` as in
    orient2d_staged."""
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
    return incircle_decide(det, (adx, ady, bdx, bdy, cdx, cdy), (alift, blift, clift),
                           (ax, ay, bx, by, cx, cy, dx, dy), bound, static)


@njit(cache=True, inline="always")
def incircle_decide(det, diffs, lifts, points, bound, static):
    """incircle_staged of the points (ax, ay, bx, by, cx, cy, dx, dy) from
    ``det``, which the caller computed as incircle_staged does from the
    rounded differences ``diffs`` = (adx, ady, bdx, bdy, cdx, cdy), ad =
    a - d, bd, cd, and their ``lifts`` (alift = ``adx * adx + ady * ady``,
    blift, clift):

        alift * (bdx * cdy - cdx * bdy) + blift * (cdx * ady - adx * cdy)
            + clift * (adx * bdy - bdx * ady)

    each product and sum as written, in this order (a cross product may be
    the negation of the one with its factors swapped: that is exact).  The
    same value and stage."""
    adx, ady, bdx, bdy, cdx, cdy = diffs
    alift, blift, clift = lifts
    if abs(det) > static:
        return det, 1
    permanent = ((abs(bdx * cdy) + abs(cdx * bdy)) * alift
                 + (abs(cdx * ady) + abs(adx * cdy)) * blift
                 + (abs(adx * bdy) + abs(bdx * ady)) * clift)
    if abs(det) > bound * permanent:
        return det, 1
    ax, ay, bx, by, cx, cy, dx, dy = points
    return _incircle_adapt(ax, ay, bx, by, cx, cy, dx, dy, permanent)


@njit(cache=True)
def _incircle_adapt(ax, ay, bx, by, cx, cy, dx, dy, permanent):
    """Stages 2 and 3 of incircle: (sign-exact value, deciding stage 2 or 3)."""
    adx = ax - dx
    bdx = bx - dx
    cdx = cx - dx
    ady = ay - dy
    bdy = by - dy
    cdy = cy - dy
    # the roundings of the differences: a - d = adx + adxt exactly
    adxt, adyt = two_diff(ax, dx)[1], two_diff(ay, dy)[1]
    bdxt, bdyt = two_diff(bx, dx)[1], two_diff(by, dy)[1]
    cdxt, cdyt = two_diff(cx, dx)[1], two_diff(cy, dy)[1]
    tails_zero = (adxt == 0.0 and bdxt == 0.0 and cdxt == 0.0 and adyt == 0.0
                  and bdyt == 0.0 and cdyt == 0.0)
    if tails_zero:
        # Exact differences that are small integers in a common power-of-two
        # unit (grids, cocircular integer sets): an int64 determinant, no
        # expansions (|d| < 2**13 keeps every product below 2**56).
        m = max(abs(adx), abs(bdx), abs(cdx), abs(ady), abs(bdy), abs(cdy))
        if m == 0.0:
            return 0.0, 2
        u = int_unit(m, 13)
        a0, a1, b0, b1, c0, c1 = (as_int(adx, u), as_int(ady, u), as_int(bdx, u),
                                  as_int(bdy, u), as_int(cdx, u), as_int(cdy, u))
        if min(a0, a1, b0, b1, c0, c1) != NOT_INT:
            v = ((a0 * a0 + a1 * a1) * (b0 * c1 - c0 * b1)
                 + (b0 * b0 + b1 * b1) * (c0 * a1 - a0 * c1)
                 + (c0 * c0 + c1 * c1) * (a0 * b1 - b0 * a1))
            return sign_int(v), 2
    # Stage 2: the determinant of the rounded differences, first in
    # double-double, within est_err of it; where that cannot decide, or the
    # permanent is outside _incircle_dd's range, exactly.
    in_dd_range = DD_FLOOR <= permanent <= DD_CEIL
    if in_dd_range:
        est = _incircle_dd(adx, ady, bdx, bdy, cdx, cdy)
        est_err = ICC_DD * permanent
        if tails_zero and abs(est) > est_err:
            return est, 2
    if tails_zero or not in_dd_range:
        est, exact_sign = _incircle_b(adx, ady, bdx, bdy, cdx, cdy)
        if tails_zero:
            return exact_sign, 2
        est_err = 0.0  # the expansions' own rounding is in ICC_B and RESULT_ERR
    if abs(est) >= ICC_B * permanent + est_err:
        return est, 2
    # Stage 3, first Shewchuk's C1 step (predicates.c, incircleadapt): the
    # terms of first order in the tails, added to the estimate in floating
    # point, decide unless within ICC_C * permanent + RESULT_ERR * |est| (and
    # the estimate's own error) of 0 (near-cocircular points that are not
    # exactly cocircular, such as points on a circle rounded to doubles);
    # else the expansions.
    bound = ICC_C * permanent + RESULT_ERR * abs(est) + est_err
    est += (((adx * adx + ady * ady) * ((bdx * cdyt + cdy * bdxt) - (bdy * cdxt + cdx * bdyt))
             + 2.0 * (adx * adxt + ady * adyt) * (bdx * cdy - bdy * cdx))
            + ((bdx * bdx + bdy * bdy) * ((cdx * adyt + ady * cdxt) - (cdy * adxt + adx * cdyt))
               + 2.0 * (bdx * bdxt + bdy * bdyt) * (cdx * ady - cdy * adx))
            + ((cdx * cdx + cdy * cdy) * ((adx * bdyt + bdy * adxt) - (ady * bdxt + bdx * adyt))
               + 2.0 * (cdx * cdxt + cdy * cdyt) * (adx * bdy - ady * bdx)))
    if abs(est) >= bound:
        return est, 3
    return incircle_exact(ax, ay, bx, by, cx, cy, dx, dy), 3


@njit(cache=True)
def _incircle_dd(adx, ady, bdx, bdy, cdx, cdy):
    """The in-circle determinant of the differences (doubles, taken as exact)
    in double-double: D = sum over the rotations (a, b, c) of lift(a) *
    cross(b, c), rounded once at the end.

    Error bound, u = EPS, no underflow or overflow (``DD_FLOOR`` and
    ``DD_CEIL`` on the permanent P = sum lift(a) |cross|(b, c), |cross| being
    |bx cy| + |cx by|).  Every two_product, two_sum and two_diff is exact and
    every other operation rounds once, by at most u of its result:

    - lift L = x^2 + y^2: the pair is off by u|e + f| + u|t + (e + f)| <=
      3.01 u^2 L, with |hi| <= (1 + 2u) L, |lo| <= 2.01 u L;
    - cross K: the same steps, off by <= 3.01 u^2 |K|p (its permanent), with
      |hi| <= (1 + 2u) |K|p, |lo| <= 2.01 u |K|p;
    - term L K: the two fmas round by <= 3.02 and 5.05 u^2 L |K|p, dropping
      lo * lo loses <= 4.05, the factors' own errors carry 6.03: 18.2 u^2 L
      |K|p in all, with |lo| <= 5.03 u L |K|p;
    - sum (dd_sum3): two two_sums are exact and leave tails <= 2.01 u P;
      the four roundings of the low parts' sum add <= 21.2 u^2 P.

    So hi + lo is within 39.4 u^2 P of D, and the returned value, its
    rounding, has D's sign whenever it exceeds ICC_DD * P (64 u^2 P: room for
    the permanent's own roundings).  Underflow: with P >= DD_FLOOR every
    product that matters is normal; a subnormal low part costs < 2**-1074
    absolute per operation, far below the slack."""
    la, las = dd_lift2(adx, ady)
    lb, lbs = dd_lift2(bdx, bdy)
    lc, lcs = dd_lift2(cdx, cdy)
    ka, kas = dd_cross(bdx, cdy, cdx, bdy)
    kb, kbs = dd_cross(cdx, ady, adx, cdy)
    kc, kcs = dd_cross(adx, bdy, bdx, ady)
    ta, tas = dd_times(la, las, ka, kas)
    tb, tbs = dd_times(lb, lbs, kb, kbs)
    tc, tcs = dd_times(lc, lcs, kc, kcs)
    hi, lo = dd_sum3(ta, tas, tb, tbs, tc, tcs)
    return hi + lo


@njit(cache=True)
def _incircle_b(adx, ady, bdx, bdy, cdx, cdy):
    """Stage 2 exactly: the in-circle determinant of the differences as an
    expansion, returned as (its float estimate, its exact sign)."""
    work = stack_array(WORK_SIZE)  # no heap allocation per call
    na = _lifted_term(adx, ady, bdx, bdy, cdx, cdy, work, 0)
    nb = _lifted_term(bdx, bdy, cdx, cdy, adx, ady, work, 32)
    nc = _lifted_term(cdx, cdy, adx, ady, bdx, bdy, work, 64)
    ab = work[96:160]
    nab = expansion_sum(work[0:32], na, work[32:64], nb, ab)
    fin = work[160:256]
    nfin = expansion_sum(ab, nab, work[64:96], nc, fin)
    est = 0.0
    for i in range(nfin):
        est += fin[i]
    return est, expansion_sign(fin, nfin)


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


@njit(cache=True)
def incircle_exact(ax, ay, bx, by, cx, cy, dx, dy):
    """Exact sign of the in-circle determinant: > 0 when d lies inside the
    circle through a, b, c (counter-clockwise)."""
    adx, adxl = exact_diff(ax, dx)
    ady, adyl = exact_diff(ay, dy)
    bdx, bdxl = exact_diff(bx, dx)
    bdy, bdyl = exact_diff(by, dy)
    cdx, cdxl = exact_diff(cx, dx)
    cdy, cdyl = exact_diff(cy, dy)
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
        cr, crl = cross_exact(ux, uxl, vy, vyl, uy, uyl, vx, vxl)
        term, terml = expansion_product(lift, liftl, cr, crl)
        new_total = np.empty(total_len + terml)
        total_len = expansion_sum(total, total_len, term, terml, new_total)
        total = new_total
    return expansion_sign(total, total_len)
