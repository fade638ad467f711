"""3D predicates, staged: orientation and in-sphere (filter, then exact).

Same conventions as lfqt.predicates.planar: the sign of the returned value is
exact, ``*_staged`` returns (value, deciding stage), scalars only.  Cells are
right-handed: orient3d(a, b, c, d) = det[b-a, c-a, d-a] > 0.
"""
import numpy as np
from numba import njit

from .expansion import (EPS, NOT_INT, as_int, cross_exact, exact_diff, expansion_product,
                        expansion_sign, expansion_sum, int_unit, negate, sign_int, two_diff)

# Shewchuk's stage-A bounds of orient3d and insphere (predicates.c, exactinit)
O3D_A = (7.0 + 56.0 * EPS) * EPS
ISP_A = (16.0 + 224.0 * EPS) * EPS


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
    ux, uxl = exact_diff(bx, ax)
    uy, uyl = exact_diff(by, ay)
    uz, uzl = exact_diff(bz, az)
    vx, vxl = exact_diff(cx, ax)
    vy, vyl = exact_diff(cy, ay)
    vz, vzl = exact_diff(cz, az)
    wx, wxl = exact_diff(dx, ax)
    wy, wyl = exact_diff(dy, ay)
    wz, wzl = exact_diff(dz, az)
    d, dl = _det3_exact(ux, uxl, uy, uyl, uz, uzl, vx, vxl, vy, vyl, vz, vzl,
                        wx, wxl, wy, wyl, wz, wzl)
    return expansion_sign(d, dl)


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
        minor, minorl = _det3_exact(ux, uxl, uy, uyl, uz, uzl, vx, vxl, vy, vyl, vz, vzl,
                                    wx, wxl, wy, wyl, wz, wzl)
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
