"""3D predicates, staged: orientation and in-sphere.

Same conventions as lfqt.predicates.planar: the sign of the returned value is
exact, ``*_staged`` returns (value, deciding stage 1, 2 or 3).  A point is
a tuple (x, y, z) of floats: a tuple is passed by value, so that the
predicates take no array (an array argument on a hot path costs numba an
atomic reference-count update per call).
Cells are right-handed: orient3d(a, b, c, d) = det[b-a, c-a, d-a] > 0.
Orientation goes from the float filter (stage 1) to the expansions (stage
3).  In-sphere has a stage 2 between them (``_insphere_adapt``): the
determinant of the
rounded differences in double-double plus the first-order terms of their
roundings, which decides nearly cospherical points (a sphere's surface
rounded to doubles) for a fraction of the expansions' cost.
"""
import numpy as np
from numba import njit

from .expansion import (DD_CEIL, DD_FLOOR, EPS, NOT_INT, as_int, cross_exact, dd_cross,
                        dd_lift3, dd_scale, dd_sum3, dd_times, exact_diff, expansion_product,
                        expansion_sign, expansion_sum, int_unit, negate, sign_int, two_diff,
                        two_sum)
from .planar import CCW_A, ICC_A, STATIC_MARGIN, static_bounds, usable_static

# Shewchuk's stage-1 bounds (his A) of orient3d and insphere (predicates.c,
# exactinit)
O3D_A = (7.0 + 56.0 * EPS) * EPS
ISP_A = (16.0 + 224.0 * EPS) * EPS
# _insphere_dd's error over the permanent: derived there, and used with room
# for the rounding of the permanent and of the returned value.
ISP_DD_DERIVED = 134.3 * EPS * EPS
ISP_DD = 256.0 * EPS * EPS
# ... and with the first-order change in the differences' tails added
# (_insphere_tails: 75.8 + 10.1 more).
ISP_C_DERIVED = 220.2 * EPS * EPS
ISP_C = 512.0 * EPS * EPS


@njit(cache=True, inline="always")
def static_bounds3(wx, wy, wz, o3d, isp):
    """Static stage-1 bounds (orient, in-sphere) for calls whose points all
    lie in a box of widths ``wx``, ``wy``, ``wz`` (each the rounded
    difference of two coordinates), given the dynamic bounds ``o3d``/``isp``;
    planar.static_bounds' argument in 3D.  Every rounded difference of a
    call is at most the box's width on its axis, and rounding is monotone:

        orient permanent     3 terms |z| (|xy| + |xy|)        <= 6 wx wy wz
        in-sphere permanent  4 lifts (<= wx^2 + wy^2 + wz^2)
                             times 3 terms |z| (|xy| + |xy|)
                                                 <= 24 (wx^2 + wy^2 + wz^2) wx wy wz

    padded by STATIC_MARGIN for the roundings of these two lines; a bound
    that left the normal range, or overflowed, is switched off."""
    vol = wx * wy * wz
    return (usable_static(o3d, o3d * (6.0 * vol) * STATIC_MARGIN),
            usable_static(isp, isp * (24.0 * (wx * wx + wy * wy + wz * wz) * vol)
                          * STATIC_MARGIN))


@njit(cache=True)
def widened(lo, hi, P, d):
    """lo and hi (at least d entries each) widened, in place, to hold the
    rows of P on their first d axes; returns them.  One pass: numpy's
    reductions over the short axis (``P.min(axis=0)``) took 21 ms each at
    1M 3D points, this 5 ms for both."""
    for k in range(P.shape[0]):
        for a in range(d):
            lo[a] = min(lo[a], P[k, a])
            hi[a] = max(hi[a], P[k, a])
    return lo, hi


@njit(cache=True)
def box(P, d):
    """(lowest, highest) coordinate of the points P on each of their d
    axes (3 entries each: inf and -inf beyond d, and for no points)."""
    return widened(np.full(3, np.inf), np.full(3, -np.inf), P, d)


@njit(cache=True)
def statics(lo, hi, d):
    """(orient, in-circle or in-sphere) static stage-1 bounds for calls
    whose points all lie in the box lo, hi on d axes (planar.static_bounds,
    static_bounds3); none (inf) for an empty box."""
    if lo[0] > hi[0]:
        return np.inf, np.inf
    if d == 2:
        return static_bounds(hi[0] - lo[0], hi[1] - lo[1], CCW_A, ICC_A)
    return static_bounds3(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], O3D_A, ISP_A)


@njit(cache=True, inline="always")
def orient3d_staged(a, b, c, d, bound, static=np.inf):
    """(value, stage): value > 0 when (a, b, c, d) is right-handed, i.e.
    det[b-a, c-a, d-a] > 0; stage 1 filter, 3 exact (no stage 2).  ``static`` as in
    planar's stage 1: ``static_bounds3`` bounds ``bound * permanent`` for
    every call whose points lie in one box."""
    ax, ay, az = a
    bx, by, bz = b
    cx, cy, cz = c
    dx, dy, dz = d
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
    if abs(det) > static:
        return det, 1
    permanent = ((abs(bdxcdy) + abs(cdxbdy)) * abs(adz) + (abs(cdxady) + abs(adxcdy)) * abs(bdz)
                 + (abs(adxbdy) + abs(bdxady)) * abs(cdz))
    if abs(det) > bound * permanent:
        return det, 1
    return orient3d_exact(a, b, c, d), 3


@njit(cache=True)
def orient3d_exact(a, b, c, d):
    """Exact sign of det[b-a, c-a, d-a]: > 0 for a right-handed tetrahedron."""
    ax, ay, az = a
    bx, by, bz = b
    cx, cy, cz = c
    dx, dy, dz = d
    q = _int_det3(bx - ax, by - ay, bz - az, cx - ax, cy - ay, cz - az, dx - ax, dy - ay,
                  dz - az, two_diff(bx, ax)[1] == 0.0 and two_diff(by, ay)[1] == 0.0
                  and two_diff(bz, az)[1] == 0.0 and two_diff(cx, ax)[1] == 0.0
                  and two_diff(cy, ay)[1] == 0.0 and two_diff(cz, az)[1] == 0.0
                  and two_diff(dx, ax)[1] == 0.0 and two_diff(dy, ay)[1] == 0.0
                  and two_diff(dz, az)[1] == 0.0)
    if q != 2.0:
        return q
    ux, uxl = exact_diff(bx, ax)
    uy, uyl = exact_diff(by, ay)
    uz, uzl = exact_diff(bz, az)
    vx, vxl = exact_diff(cx, ax)
    vy, vyl = exact_diff(cy, ay)
    vz, vzl = exact_diff(cz, az)
    wx, wxl = exact_diff(dx, ax)
    wy, wyl = exact_diff(dy, ay)
    wz, wzl = exact_diff(dz, az)
    det, detl = _det3_exact((ux, uxl, uy, uyl, uz, uzl), (vx, vxl, vy, vyl, vz, vzl),
                            (wx, wxl, wy, wyl, wz, wzl))
    return expansion_sign(det, detl)


@njit(cache=True)
def _det3_exact(u, v, w):
    """det[[u], [v], [w]] of expansion entries, expanded along z; a row is
    (x, its length, y, its length, z, its length)."""
    ux, uxl, uy, uyl, uz, uzl = u
    vx, vxl, vy, vyl, vz, vzl = v
    wx, wxl, wy, wyl, wz, wzl = w
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
        cr, crl = cross_exact(px, pxl, qy, qyl, py, pyl, qx, qxl)
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
    u = int_unit(m, 16)
    e = np.empty(9, dtype=np.int64)
    vals = (ux, uy, uz, vx, vy, vz, wx, wy, wz)
    for k in range(9):
        e[k] = as_int(vals[k], u)
        if e[k] == NOT_INT:
            return 2.0
    v = (e[0] * (e[4] * e[8] - e[5] * e[7]) - e[1] * (e[3] * e[8] - e[5] * e[6])
         + e[2] * (e[3] * e[7] - e[4] * e[6]))
    return sign_int(v)


@njit(cache=True, inline="always")
def insphere_staged(a, b, c, d, e, bound, static=np.inf):
    """(value, stage): value > 0 when e lies inside the sphere through the
    right-handed tetrahedron (a, b, c, d), < 0 outside, 0 on it; ``static``
    as in orient3d_staged."""
    ax, ay, az = a
    bx, by, bz = b
    cx, cy, cz = c
    dx, dy, dz = d
    ex, ey, ez = e
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
    if abs(det) > static:
        return det, 1
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
        return det, 1
    return _insphere_adapt(a, b, c, d, e, permanent)


@njit(cache=True)
def _insphere_adapt(a, b, c, d, e, permanent):
    """Stages 2 and 3 of insphere: (sign-exact value, deciding stage 2 or 3).

    Stage 2: the differences are rounded, x = xh + xt exactly (two_diff).
    The determinant of the xh in double-double (_insphere_dd, within
    ISP_DD_DERIVED P), plus its first-order change in the tails in floating
    point (_insphere_tails, as Shewchuk's C1 step in 2D), is within
    ISP_C_DERIVED P of the exact determinant.  Rounding the double-double
    pair and adding the tail terms cost <= u |est| + 5.01 u^2 P more (the
    tail terms are at most 5.01 u P, so a cancelling pair is that small):
    the 2 u |est| term and the room up to ISP_C hold them.  It decides
    unless that close to 0.  Underflow: as in planar._incircle_dd, with
    P >= DD_FLOOR a subnormal result costs < 2**-1074 per operation, far
    below the room between the derived bounds and ISP_DD, ISP_C.  Stage 3:
    the expansions."""
    ax, ay, az = a
    bx, by, bz = b
    cx, cy, cz = c
    dx, dy, dz = d
    ex, ey, ez = e
    if DD_FLOOR <= permanent <= DD_CEIL:
        aex, aet = two_diff(ax, ex)
        aey, aeu = two_diff(ay, ey)
        aez, aev = two_diff(az, ez)
        bex, bet = two_diff(bx, ex)
        bey, beu = two_diff(by, ey)
        bez, bev = two_diff(bz, ez)
        cex, cet = two_diff(cx, ex)
        cey, ceu = two_diff(cy, ey)
        cez, cev = two_diff(cz, ez)
        dex, det_ = two_diff(dx, ex)
        dey, deu = two_diff(dy, ey)
        dez, dev = two_diff(dz, ez)
        ae, be, ce, de = (aex, aey, aez), (bex, bey, bez), (cex, cey, cez), (dex, dey, dez)
        est = _insphere_dd(ae, be, ce, de)
        bound = ISP_DD * permanent
        if not (aet == 0.0 and aeu == 0.0 and aev == 0.0 and bet == 0.0 and beu == 0.0
                and bev == 0.0 and cet == 0.0 and ceu == 0.0 and cev == 0.0 and det_ == 0.0
                and deu == 0.0 and dev == 0.0):
            est += _insphere_tails(ae, be, ce, de, (aet, aeu, aev), (bet, beu, bev),
                                   (cet, ceu, cev), (det_, deu, dev))
            bound = ISP_C * permanent
        if abs(est) > bound + 2.0 * EPS * abs(est):
            return est, 2
    return insphere_exact(a, b, c, d, e), 3


@njit(cache=True, inline="always")
def _d_cross(a, at, b, bt, c, ct, d, dt):
    """First-order change of a*b - c*d under tails at, bt, ct, dt."""
    return (a * bt + at * b) - (c * dt + ct * d)


@njit(cache=True)
def _insphere_tails(ae, be, ce, de, at, bt, ct, dt):
    """The first-order change of insphere_staged's determinant when each
    difference x (here rounded: ae = a - e, ..., as (x, y, z)) gains its
    tail xt (at, ..., as (x, y, z)), in floating point.

    Bound (u = EPS, P the permanent of the rounded differences; each of the
    determinant's monomials has degree 5 and |xt| <= u |x|): the change is
    at most 5u P in permanent, and no monomial of it passes more than 15
    roundings, so this evaluation is within 15.1 u * 5.01 u P of it; the
    terms of second and higher order left out are within ((1 + u)^5 - 1 -
    5u) P <= 10.01 u^2 P."""
    aex, aey, aez = ae
    bex, bey, bez = be
    cex, cey, cez = ce
    dex, dey, dez = de
    aet, aeu, aev = at
    bet, beu, bev = bt
    cet, ceu, cev = ct
    det_, deu, dev = dt
    ab = aex * bey - bex * aey
    bc = bex * cey - cex * bey
    cd = cex * dey - dex * cey
    da = dex * aey - aex * dey
    ac = aex * cey - cex * aey
    bd = bex * dey - dex * bey
    dab_ = _d_cross(aex, aet, bey, beu, bex, bet, aey, aeu)
    dbc = _d_cross(bex, bet, cey, ceu, cex, cet, bey, beu)
    dcd = _d_cross(cex, cet, dey, deu, dex, det_, cey, ceu)
    dda = _d_cross(dex, det_, aey, aeu, aex, aet, dey, deu)
    dac = _d_cross(aex, aet, cey, ceu, cex, cet, aey, aeu)
    dbd = _d_cross(bex, bet, dey, deu, dex, det_, bey, beu)
    abc = aez * bc - bez * ac + cez * ab
    bcd = bez * cd - cez * bd + dez * bc
    cda = cez * da + dez * ac + aez * cd
    dab = dez * ab + aez * bd + bez * da
    d_abc = (aev * bc + aez * dbc) - (bev * ac + bez * dac) + (cev * ab + cez * dab_)
    d_bcd = (bev * cd + bez * dcd) - (cev * bd + cez * dbd) + (dev * bc + dez * dbc)
    d_cda = (cev * da + cez * dda) + (dev * ac + dez * dac) + (aev * cd + aez * dcd)
    d_dab = (dev * ab + dez * dab_) + (aev * bd + aez * dbd) + (bev * da + bez * dda)
    alift = aex * aex + aey * aey + aez * aez
    blift = bex * bex + bey * bey + bez * bez
    clift = cex * cex + cey * cey + cez * cez
    dlift = dex * dex + dey * dey + dez * dez
    d_alift = 2.0 * (aex * aet + aey * aeu + aez * aev)
    d_blift = 2.0 * (bex * bet + bey * beu + bez * bev)
    d_clift = 2.0 * (cex * cet + cey * ceu + cez * cev)
    d_dlift = 2.0 * (dex * det_ + dey * deu + dez * dev)
    # det = -((dlift abc - clift dab) + (blift cda - alift bcd))
    return -(((d_dlift * abc + dlift * d_abc) - (d_clift * dab + clift * d_dab))
             + ((d_blift * cda + blift * d_cda) - (d_alift * bcd + alift * d_bcd)))


@njit(cache=True)
def _insphere_dd(ae, be, ce, de):
    """insphere_staged's determinant of the differences ae = a - e, ..., as
    (x, y, z) (doubles, taken as exact) in double-double, rounded once at
    the end.

    Error bound, u = EPS, no underflow or overflow (DD_FLOOR <= P <= DD_CEIL,
    P the permanent of insphere_staged: sum of lift * |minor|p, a minor's
    permanent |minor|p being sum |z| |cross|p).  With the facts of
    lfqt.predicates.expansion's double-double section:

    - cross K (dd_cross): off by 3.01 u^2 |K|p; |hi| <= (1 + 2u) |K|p,
      |lo| <= 2.01 u |K|p;
    - z K (dd_scale): the fma rounds by <= 3.02 u^2 |z| |K|p, K's error
      carries 3.01: 6.03 u^2 |z| |K|p; |hi| <= (1 + 3.01u) |z| |K|p,
      |lo| <= 3.02 u |z| |K|p;
    - minor M, three of those (dd_sum3): the two_sums are exact and leave
      tails <= 2.01 u |M|p, the four roundings of the low sum add <= 4 *
      5.03 u^2 |M|p: 26.2 u^2 |M|p; |hi| <= (1 + 5.1u) |M|p, |lo| <= 5.03 u
      |M|p;
    - lift L (dd_lift3): tails <= 2.01 u L, the products' errors <= u L;
      four roundings: 7.03 u^2 L; |hi| <= (1 + 2u) L, |lo| <= 3.02 u L;
    - term L M (dd_times): the fmas round by <= 4.03 and 9.07 u^2 L |M|p,
      dropping lo * lo loses <= 15.2, the factors' errors carry 33.3:
      61.6 u^2 L |M|p; |hi| <= (1 + 8u) L |M|p, |lo| <= 9.08 u L |M|p;
    - sum of the four terms: three exact two_sums leave tails <= 3.01 u P,
      the six roundings of the low sum add <= 6 * 12.1 u^2 P.

    So hi + lo is within 134.3 u^2 P of the determinant, and the returned
    value, its rounding, has its sign whenever it exceeds ISP_DD * P (256 u^2
    P: room for the permanent's own roundings)."""
    aex, aey, aez = ae
    bex, bey, bez = be
    cex, cey, cez = ce
    dex, dey, dez = de
    ab, abs_ = dd_cross(aex, bey, bex, aey)
    bc, bcs = dd_cross(bex, cey, cex, bey)
    cd, cds = dd_cross(cex, dey, dex, cey)
    da, das = dd_cross(dex, aey, aex, dey)
    ac, acs = dd_cross(aex, cey, cex, aey)
    bd, bds = dd_cross(bex, dey, dex, bey)
    # the minors, as in insphere_staged (negating a pair is exact)
    h1, l1 = dd_scale(aez, bc, bcs)
    h2, l2 = dd_scale(-bez, ac, acs)
    h3, l3 = dd_scale(cez, ab, abs_)
    abc, abcs = dd_sum3(h1, l1, h2, l2, h3, l3)
    h1, l1 = dd_scale(bez, cd, cds)
    h2, l2 = dd_scale(-cez, bd, bds)
    h3, l3 = dd_scale(dez, bc, bcs)
    bcd, bcds = dd_sum3(h1, l1, h2, l2, h3, l3)
    h1, l1 = dd_scale(cez, da, das)
    h2, l2 = dd_scale(dez, ac, acs)
    h3, l3 = dd_scale(aez, cd, cds)
    cda, cdas = dd_sum3(h1, l1, h2, l2, h3, l3)
    h1, l1 = dd_scale(dez, ab, abs_)
    h2, l2 = dd_scale(aez, bd, bds)
    h3, l3 = dd_scale(bez, da, das)
    dab, dabs = dd_sum3(h1, l1, h2, l2, h3, l3)
    la, las = dd_lift3(aex, aey, aez)
    lb, lbs = dd_lift3(bex, bey, bez)
    lc, lcs = dd_lift3(cex, cey, cez)
    ld, lds = dd_lift3(dex, dey, dez)
    # det = -((dlift abc - clift dab) + (blift cda - alift bcd))
    t1, t1s = dd_times(ld, lds, abc, abcs)
    t2, t2s = dd_times(lc, lcs, -dab, -dabs)
    t3, t3s = dd_times(lb, lbs, cda, cdas)
    t4, t4s = dd_times(la, las, -bcd, -bcds)
    s, r1 = two_sum(t1, t2)
    s, r2 = two_sum(s, t3)
    hi, r3 = two_sum(s, t4)
    lo = ((r1 + r2) + r3) + ((t1s + t2s) + (t3s + t4s))
    return -(hi + lo)


@njit(cache=True)
def insphere_exact(a, b, c, d, e):
    """Exact sign: > 0 when e lies inside the sphere through the right-handed
    tetrahedron (a, b, c, d)."""
    ax, ay, az = a
    bx, by, bz = b
    cx, cy, cz = c
    dx, dy, dz = d
    ex, ey, ez = e
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
        u = int_unit(m, 10)
        D = np.empty((4, 4), dtype=np.int64)
        ok = True
        for k in range(4):
            for j in range(3):
                D[k, j] = as_int(diffs[k, j], u)
                ok = ok and D[k, j] != NOT_INT
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
            return -sign_int(v)
    total = np.zeros(1)
    total_len = 1
    # rows r_i = (p_i - e, |p_i - e|^2); det of the 4x4 by the last column
    for k in range(4):
        px, py, pz = rows[k, 0], rows[k, 1], rows[k, 2]
        sx, sxl = exact_diff(px, ex)
        sy, syl = exact_diff(py, ey)
        sz, szl = exact_diff(pz, ez)
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
        ux, uxl = exact_diff(q0[0], ex)
        uy, uyl = exact_diff(q0[1], ey)
        uz, uzl = exact_diff(q0[2], ez)
        vx, vxl = exact_diff(q1[0], ex)
        vy, vyl = exact_diff(q1[1], ey)
        vz, vzl = exact_diff(q1[2], ez)
        wx, wxl = exact_diff(q2[0], ex)
        wy, wyl = exact_diff(q2[1], ey)
        wz, wzl = exact_diff(q2[2], ez)
        minor, minorl = _det3_exact((ux, uxl, uy, uyl, uz, uzl), (vx, vxl, vy, vyl, vz, vzl),
                                    (wx, wxl, wy, wyl, wz, wzl))
        term, terml = expansion_product(lift, liftl, minor, minorl)
        # cofactor sign of column 4, row k: (-1)^(k+3); rows are (a-e, b-e, c-e, d-e)
        if k % 2 == 0:
            term = negate(term, terml)
        new_total = np.empty(total_len + terml)
        total_len = expansion_sum(total, total_len, term, terml, new_total)
        total = new_total
    # det[[a-e, |a-e|^2], ...] > 0 iff e inside for Shewchuk-positive (left-handed) order;
    # for our right-handed order the sign flips
    return -expansion_sign(total, total_len)
