import math
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import assume, given, strategies as st
from numba import njit

from lfqt import morton, predicates as P
from lfqt.predicates import counters as C
from lfqt.predicates import binade
from lfqt.predicates import planar, spatial
from lfqt.predicates.expansion import EPS, two_product
from lfqt._input import coordinates2d, exact_coordinates2d, exact_points3

# Magnitudes within one exactness window (the API refuses wider spans).
finite = st.floats(min_value=-1e30, max_value=1e30).filter(lambda v: v == 0 or abs(v) > 1e-90)
unit = st.floats(0, 1).filter(lambda v: v == 0 or v > 1e-90)
signed_unit = st.floats(-1, 1).filter(lambda v: v == 0 or abs(v) > 1e-90)
small_ints = st.integers(-8, 8).map(float)
coords = st.one_of(finite, small_ints)
point = st.tuples(coords, coords)


def orient_ref(a, b, c):
    v = ((Fraction(a[0]) - Fraction(c[0])) * (Fraction(b[1]) - Fraction(c[1]))
         - (Fraction(a[1]) - Fraction(c[1])) * (Fraction(b[0]) - Fraction(c[0])))
    return (v > 0) - (v < 0)


def incircle_ref(a, b, c, d):
    rows = []
    for p in (a, b, c):
        x = Fraction(p[0]) - Fraction(d[0])
        y = Fraction(p[1]) - Fraction(d[1])
        rows.append((x, y, x * x + y * y))
    (a0, a1, a2), (b0, b1, b2), (c0, c1, c2) = rows
    v = a0 * (b1 * c2 - c1 * b2) - a1 * (b0 * c2 - c0 * b2) + a2 * (b0 * c1 - c0 * b1)
    return (v > 0) - (v < 0)


def sign(v):
    return int(np.sign(v))


def in_window(*pts):
    """The points rescaled by the API's exact power of two (predicates are
    exact only inside that window); signs are invariant under the rescale.
    Sets the API refuses (magnitudes too far apart) are skipped."""
    try:
        xs, ys = exact_coordinates2d(np.array(pts, dtype=np.float64))
    except ValueError:
        assume(False)
    return [(float(x), float(y)) for x, y in zip(xs, ys)]


def orient(a, b, c, bound=P.CCW_A):
    a, b, c = in_window(a, b, c)
    return sign(P.orient2d(*a, *b, *c, bound, P.new_counters()))


def incircle(a, b, c, d, bound=P.ICC_A):
    a, b, c, d = in_window(a, b, c, d)
    return sign(P.incircle(*a, *b, *c, *d, bound, P.new_counters()))


@st.composite
def near_line(draw):
    """Three points on (or one ulp off) a line: the filter cannot decide them."""
    a = (draw(unit), draw(unit))
    d = (draw(signed_unit), draw(signed_unit))
    t = draw(st.floats(-2, 2).filter(lambda v: v == 0 or abs(v) > 1e-90))
    c = (a[0] + t * d[0], a[1] + t * d[1])
    nudge = draw(st.integers(-2, 2))
    c = (float(np.nextafter(c[0], np.inf * nudge)) if nudge else c[0], c[1])
    b = (a[0] + d[0], a[1] + d[1])
    return a, b, c


@st.composite
def near_circle(draw):
    angles = [draw(st.floats(0, 6.283)) for _ in range(4)]
    cx, cy, r = draw(signed_unit), draw(signed_unit), draw(st.floats(0.01, 10))
    pts = [(cx + r * np.cos(t), cy + r * np.sin(t)) for t in angles]
    k = draw(st.integers(0, 3))
    nudge = draw(st.integers(-1, 1))
    if nudge:
        x, y = pts[k]
        pts[k] = (float(np.nextafter(x, np.inf * nudge)), y)
    return pts


@given(point, point, point)
def test_orient_matches_fractions(a, b, c):
    assert orient(a, b, c) == orient_ref(a, b, c)


@given(near_line())
def test_orient_exact_near_collinear(pts):
    assert orient(*pts) == orient_ref(*pts)
    a, b, c = in_window(*pts)
    assert sign(P.orient2d_exact(*a, *b, *c)) == orient_ref(*pts)


@given(point, point, point)
def test_orient_sign_flips_under_odd_permutation(a, b, c):
    s = orient(a, b, c)
    assert orient(b, c, a) == s and orient(c, a, b) == s
    assert orient(b, a, c) == -s and orient(a, c, b) == -s


@given(point, point, point, point)
def test_incircle_matches_fractions(a, b, c, d):
    assume(orient_ref(a, b, c) != 0)
    assert incircle(a, b, c, d) == incircle_ref(a, b, c, d)


@given(near_circle())
def test_incircle_exact_near_cocircular(pts):
    expected = incircle_ref(*pts)
    assert incircle(*pts) == expected
    a, b, c, d = in_window(*pts)
    assert sign(P.incircle_exact(*a, *b, *c, *d)) == expected


def _incircle_diffs_ref(adx, ady, bdx, bdy, cdx, cdy):
    """(exact determinant, permanent) of the in-circle form of differences."""
    a, b, c = ((Fraction(adx), Fraction(ady)), (Fraction(bdx), Fraction(bdy)),
               (Fraction(cdx), Fraction(cdy)))
    det = perm = Fraction(0)
    for p, q, r in ((a, b, c), (b, c, a), (c, a, b)):
        lift = p[0] * p[0] + p[1] * p[1]
        det += lift * (q[0] * r[1] - r[0] * q[1])
        perm += lift * (abs(q[0] * r[1]) + abs(r[0] * q[1]))
    return det, perm


@given(st.one_of(near_circle(), st.tuples(point, point, point, point)))
def test_incircle_double_double_within_its_bound(pts):
    # _incircle_dd's derivation: hi + lo within ICC_DD_DERIVED P of the
    # determinant of its (exact double) arguments, then one rounding.
    # Near-cocircular sets, whose determinant cancels to about u P, are the
    # ones that reach it in the predicate.
    (ax, ay), (bx, by), (cx, cy), (dx, dy) = in_window(*pts)
    diffs = (ax - dx, ay - dy, bx - dx, by - dy, cx - dx, cy - dy)
    det, perm = _incircle_diffs_ref(*diffs)
    assume(planar.DD_FLOOR <= perm <= planar.DD_CEIL)
    got = Fraction(planar._incircle_dd(*diffs))
    u = Fraction(EPS)
    assert abs(got - det) <= Fraction(planar.ICC_DD_DERIVED) * perm + u * abs(got)
    # the predicate's threshold leaves room for the permanent's roundings
    assert planar.ICC_DD * (1 - 8 * EPS) > planar.ICC_DD_DERIVED * (1 + 2 * EPS)


def test_incircle_exactly_cocircular_beyond_the_integer_path():
    # A rectangle's corners are cocircular whatever their coordinates.  With
    # exact differences too long for the int64 path, the double-double stage
    # cannot decide 0 and must hand it to the expansions, which return 0.
    x0, x1 = 1.0, 1.0 + 12345679 * 2.0 ** -40
    y0, y1 = 1.5, 1.5 + 987654321 * 2.0 ** -45
    cnt = P.new_counters()
    assert P.incircle(x0, y0, x1, y0, x1, y1, x0, y1, P.ICC_A, cnt) == 0.0
    assert cnt[C.INCIRCLE_S1] == 1 and cnt[C.INCIRCLE_S2] == 0
    # one ulp outside the circle (d moved away from the rectangle)
    assert P.incircle(x0, y0, x1, y0, x1, y1, np.nextafter(x0, 0.0), y1, P.ICC_A, cnt) < 0.0


def test_incircle_rounded_circle_decided_before_the_exact_stage():
    # gDel2D's circle: four neighbours on a circle rounded to doubles are
    # decided by stage 2 (double-double) or stage 3's C1 step, with the exact sign.
    rng = np.random.default_rng(3)
    for _ in range(200):
        t = np.sort(rng.random(4)) * 0.01 + rng.random() * 6.0
        pts = [(0.45 * np.cos(v), 0.45 * np.sin(v)) for v in t]
        flat = [c for p in pts for c in p]
        assert sign(P.incircle(*flat, P.ICC_A, P.new_counters())) == incircle_ref(*pts)


def _insphere_diffs_ref(rows):
    """(exact determinant, permanent) of insphere_staged's form, from the
    differences rows = [(ax - ex, ay - ey, az - ez), ...] (as Fractions)."""
    (ax, ay, az), (bx, by, bz), (cx, cy, cz), (dx, dy, dz) = rows

    def cross(p, q, r, s):
        return p * q - r * s, abs(p * q) + abs(r * s)

    ab, abp = cross(ax, by, bx, ay)
    bc, bcp = cross(bx, cy, cx, by)
    cd, cdp = cross(cx, dy, dx, cy)
    da, dap = cross(dx, ay, ax, dy)
    ac, acp = cross(ax, cy, cx, ay)
    bd, bdp = cross(bx, dy, dx, by)
    abc = az * bc - bz * ac + cz * ab
    bcd = bz * cd - cz * bd + dz * bc
    cda = cz * da + dz * ac + az * cd
    dab = dz * ab + az * bd + bz * da
    abcp = abs(az) * bcp + abs(bz) * acp + abs(cz) * abp
    bcdp = abs(bz) * cdp + abs(cz) * bdp + abs(dz) * bcp
    cdap = abs(cz) * dap + abs(dz) * acp + abs(az) * cdp
    dabp = abs(dz) * abp + abs(az) * bdp + abs(bz) * dap
    lifts = [x * x + y * y + z * z for x, y, z in rows]
    det = -((lifts[3] * abc - lifts[2] * dab) + (lifts[1] * cda - lifts[0] * bcd))
    perm = lifts[3] * abcp + lifts[2] * dabp + lifts[1] * cdap + lifts[0] * bcdp
    return det, perm


def orient3d_ref(a, b, c, d):
    u, v, w = ([Fraction(q[k]) - Fraction(a[k]) for k in range(3)] for q in (b, c, d))
    det = (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
           + u[2] * (v[0] * w[1] - v[1] * w[0]))
    return (det > 0) - (det < 0)


def insphere_ref(a, b, c, d, e):
    """> 0 when e is inside the sphere through the right-handed (a, b, c, d)."""
    rows = [tuple(Fraction(p[k]) - Fraction(e[k]) for k in range(3)) for p in (a, b, c, d)]
    det = _insphere_diffs_ref(rows)[0]
    return (det > 0) - (det < 0)


def test_insphere_ref_convention():
    a, b, c, d = (0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)
    assert orient3d_ref(a, b, c, d) == 1
    assert insphere_ref(a, b, c, d, (0.25, 0.25, 0.25)) == 1
    assert insphere_ref(a, b, c, d, (2.0, 2.0, 2.0)) == -1
    assert insphere_ref(a, b, c, d, (1.0, 1.0, 1.0)) == 0  # a corner of the cube: on it


@st.composite
def near_sphere(draw):
    """Five points on a sphere, rounded to doubles; its centre is often the
    origin, so that differences straddle zero and are rounded too."""
    centre = draw(st.one_of(st.just((0.0, 0.0, 0.0)),
                            st.tuples(signed_unit, signed_unit, signed_unit)))
    r = draw(st.floats(0.01, 10))
    pts = []
    for _ in range(5):
        t, z = draw(st.floats(0, 6.283)), draw(st.floats(-1, 1))
        w = math.sqrt(1 - z * z)
        pts.append(tuple(float(c + r * v) for c, v in zip(centre, (w * math.cos(t),
                                                                   w * math.sin(t), z))))
    k, nudge = draw(st.integers(0, 4)), draw(st.integers(-1, 1))
    if nudge:
        x, y, z = pts[k]
        pts[k] = (float(np.nextafter(x, np.inf * nudge)), y, z)
    return pts


def _right_handed(pts):
    """The points in the 3D exactness window, the first four right-handed."""
    try:
        P3 = exact_points3(np.array(pts, dtype=np.float64))
    except ValueError:  # magnitudes too far apart for the window
        assume(False)
    pts = [tuple(map(float, p)) for p in P3]
    o = orient3d_ref(*pts[:4])
    assume(o != 0)
    if o < 0:
        pts[0], pts[1] = pts[1], pts[0]
    return pts


point3 = st.tuples(coords, coords, coords)


@given(st.one_of(near_sphere(), st.tuples(point3, point3, point3, point3, point3)))
def test_insphere_matches_fractions(pts):
    pts = _right_handed(pts)
    w = [tuple(map(float, p)) for p in pts]
    got, stage = P.insphere_staged(*w, P.ISP_A)
    assert sign(got) == insphere_ref(*pts)
    assert sign(P.insphere_exact(*w)) == insphere_ref(*pts)


@given(st.one_of(near_sphere(), st.tuples(point3, point3, point3, point3, point3)))
def test_insphere_double_double_within_its_bound(pts):
    pts = _right_handed(pts)
    e = pts[4]
    diffs = [tuple(p[k] - e[k] for k in range(3)) for p in pts[:4]]
    det, perm = _insphere_diffs_ref([tuple(map(Fraction, r)) for r in diffs])
    assume(spatial.DD_FLOOR <= perm <= spatial.DD_CEIL)
    got = Fraction(spatial._insphere_dd(*[tuple(map(float, r)) for r in diffs]))
    assert abs(got - det) <= Fraction(spatial.ISP_DD_DERIVED) * perm + Fraction(EPS) * abs(got)
    assert spatial.ISP_DD * (1 - 16 * EPS) > spatial.ISP_DD_DERIVED * (1 + 2 * EPS)
    assert spatial.ISP_C * (1 - 16 * EPS) > spatial.ISP_C_DERIVED * (1 + 2 * EPS)


@given(near_sphere())
def test_insphere_with_tails_within_its_bound(pts):
    # rounded differences plus their first-order tail terms: within
    # ISP_C_DERIVED P of the exact determinant of the true differences
    pts = _right_handed(pts)
    e = pts[4]
    exact_rows = [tuple(Fraction(p[k]) - Fraction(e[k]) for k in range(3)) for p in pts[:4]]
    rounded = [tuple(p[k] - e[k] for k in range(3)) for p in pts[:4]]
    tails = [tuple(float(x - Fraction(r)) for x, r in zip(xr, rr))
             for xr, rr in zip(exact_rows, rounded)]
    det = _insphere_diffs_ref(exact_rows)[0]
    perm = _insphere_diffs_ref([tuple(map(Fraction, r)) for r in rounded])[1]
    assume(spatial.DD_FLOOR <= perm <= spatial.DD_CEIL)
    args = [tuple(map(float, r)) for r in rounded]
    got = Fraction(spatial._insphere_dd(*args)) + Fraction(
        spatial._insphere_tails(*args, *tails))
    assert abs(got - det) <= Fraction(spatial.ISP_C_DERIVED) * perm + 2 * Fraction(EPS) * abs(got)


def test_insphere_rounded_sphere_decided_before_the_expansions():
    # points on a sphere around the origin, rounded to doubles: the stage-1
    # filter fails on nearly all; stage 2 decides them, with the exact sign
    rng = np.random.default_rng(5)
    stages = []
    for _ in range(300):
        v = rng.normal(size=3)
        near = v / np.linalg.norm(v) + 0.02 * rng.normal(size=(5, 3))
        pts = [tuple(map(float, 0.45 * p / np.linalg.norm(p))) for p in near]
        o = orient3d_ref(*pts[:4])
        if o == 0:
            continue
        if o < 0:
            pts[0], pts[1] = pts[1], pts[0]
        got, stage = P.insphere_staged(*pts, P.ISP_A)
        assert sign(got) == insphere_ref(*pts)
        stages.append(stage)
    assert set(stages) <= {1, 2, 3}
    assert stages.count(1) < len(stages) // 2  # the float filter fails on most
    assert stages.count(3) <= len(stages) // 50  # the expansions are rare


@given(point, point, point, point)
def test_incircle_symmetry(a, b, c, d):
    s = incircle(a, b, c, d)
    assert incircle(b, c, a, d) == s
    assert incircle(b, a, c, d) == -s


@given(finite, finite)
def test_two_product_is_exact(a, b):
    # the exact stages' products: x + err is a * b, with x the rounded product
    x, err = two_product(a, b)
    assert x == a * b
    assert Fraction(x) + Fraction(err) == Fraction(a) * Fraction(b)


def test_integer_cocircular_decided_exactly():
    # Unit square corners are cocircular; stage 1 cannot decide, stage 2 must give 0.
    cnt = P.new_counters()
    v = P.incircle(0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0, P.ICC_A, cnt)
    assert v == 0.0
    assert cnt[C.INCIRCLE_S1] == 1 and cnt[C.INCIRCLE_S2] == 0


def test_counters_count_calls_and_undecided():
    cnt = P.new_counters()
    P.orient2d(0.0, 0.0, 1.0, 1.0, 2.0, 2.0, P.CCW_A, cnt)
    P.orient2d(0.0, 0.0, 1.0, 0.0, 0.0, 1.0, P.CCW_A, cnt)
    assert cnt[C.ORIENT] == 2 and cnt[C.ORIENT_S1] == 1


def test_tally_undecided_counts_the_stages_alone():
    cnt = P.new_counters()
    C.tally_undecided(cnt, C.INCIRCLE, 2)
    C.tally_undecided(cnt, C.INCIRCLE, 3)
    C.tally_undecided(cnt, C.ORIENT, 2)
    C.tally_undecided(cnt, C.ORIENT, 1)  # decided by stage 1: not counted here
    assert list(cnt[:6]) == [0, 1, 0, 0, 2, 1]  # calls are the caller's to count


def test_the_stages_are_numbered_1_2_3():
    # one numbering in the return values and the counters: stage 1 decides
    # an easy call, stage 2 an exactly collinear one with exact differences,
    # stage 3 (exact) one whose differences round
    cnt = P.new_counters()
    assert P.orient2d_staged(0.0, 0.0, 1.0, 0.0, 0.0, 1.0, P.CCW_A)[1] == 1
    assert P.orient2d_staged(0.0, 0.0, 1.0, 1.0, 2.0, 2.0, P.CCW_A)[1] == 2
    tiny = 2.0 ** -60
    v, stage = P.orient2d_staged(0.1, 0.1, 0.3, 0.3 + tiny, 1e10, 1e10, P.CCW_A)
    assert stage == 3
    C.tally(cnt, C.ORIENT, stage)
    assert list(cnt[:3]) == [1, 1, 1]  # undecided by stages 1 and 2


def _level_of(points, dtype):
    x = np.array([p[0] for p in points], dtype=dtype)
    y = np.array([p[1] for p in points], dtype=dtype)
    if dtype == np.float32:
        keys = [int(k) for k in morton.morton_keys32(x, y)]
    else:
        hi, lo = morton.morton_keys64(x, y)
        keys = [(int(h) << 64) | int(l) for h, l in zip(hi, lo)]
    diff = 0
    for k in keys[1:]:
        diff |= k ^ keys[0]
    return diff.bit_length() - 1, x.astype(np.float64), y.astype(np.float64)


@st.composite
def node_points(draw, count):
    """Points sharing a Morton prefix: a base point plus small integer offsets
    of a few ulps, so they fall in one deep LFQT node."""
    dtype = draw(st.sampled_from([np.float32, np.float64]))
    bx = draw(st.floats(-1e6, 1e6, width=32 if dtype == np.float32 else 64))
    by = draw(st.floats(-1e6, 1e6, width=32 if dtype == np.float32 else 64))
    span = draw(st.integers(1, 40))
    pts = []
    for _ in range(count):
        ox, oy = draw(st.integers(0, span)), draw(st.integers(0, span))
        x, y = dtype(bx), dtype(by)
        for _ in range(ox):
            x = np.nextafter(x, dtype(np.inf))
        for _ in range(oy):
            y = np.nextafter(y, dtype(np.inf))
        pts.append((float(x), float(y)))
    return dtype, pts


@given(node_points(4))
def test_level_bounds_are_sound(sample):
    dtype, pts = sample
    level, x, y = _level_of(pts, dtype)
    assume(level >= 0)
    bits, ebits, mbits, emin = (32, 8, 23, -126) if dtype == np.float32 else (64, 11, 52, -1022)
    try:
        s = coordinates2d(np.c_[x, y].astype(dtype))[1]
    except ValueError:
        assume(False)
    xs, ys = x * 2.0 ** s, y * 2.0 ** s
    ex, ey = binade(xs[0], s, emin), binade(ys[0], s, emin)
    ccw, icc = P.level_bounds(level, bits, ebits, mbits, ex, ey)
    assert ccw <= P.CCW_A and icc <= P.ICC_A
    a, b, c, d = [(float(xs[i]), float(ys[i])) for i in range(4)]
    original = [(float(x[i]), float(y[i])) for i in range(4)]
    cnt = P.new_counters()
    assert sign(P.orient2d(*a, *b, *c, ccw, cnt)) == orient_ref(*original[:3])
    if orient_ref(*original[:3]) != 0:
        assert sign(P.incircle(*a, *b, *c, *d, icc, cnt)) == incircle_ref(*original)


def test_level_bounds_tighten_below_the_exponent_bits():
    # Top of the tree: sign/exponent not shared, Triangle's constants.
    assert P.level_bounds(127, 64, 11, 52, 0, 0) == (P.CCW_A, P.ICC_A)
    # Deep level of a float32 node: differences have few bits, both exact.
    assert P.level_bounds(4, 32, 8, 23, 0, 0) == (0.0, 0.0)
    ccw, icc = P.level_bounds(60, 64, 11, 52, 0, 0)
    assert ccw == P.CCW_EXACT_DIFF and icc == P.ICC_EXACT_DIFF


@njit(cache=True)
def _binades(values, scale_exp, emin):
    out = np.empty(values.shape[0], dtype=np.int64)
    for i in range(values.shape[0]):
        out[i] = binade(values[i], scale_exp, emin)
    return out


@pytest.mark.parametrize("scale_exp, emin", [(0, -1022), (40, -126), (-300, -1022)])
def test_binade_matches_frexp(scale_exp, emin):
    rng = np.random.default_rng(7)
    values = np.concatenate([rng.random(200) * 2.0 ** rng.integers(-1000, 1000, 200),
                             [0.0, -0.0, -2.0 ** -1022, 1.0, -3.0, 2.0 ** 1023]])
    got = _binades(values, scale_exp, emin)
    for v, g in zip(values, got):
        want = emin if v == 0.0 else max(math.frexp(v)[1] - 1 - scale_exp, emin)
        assert g == want, (v, g, want)
    # stored values are rescaled into the normal range; a subnormal counts as emin
    assert _binades(np.array([5e-324, -2.0 ** -1030]), scale_exp, emin).tolist() == [emin, emin]


@njit(cache=True)
def _with_and_without_static(pts, ccw, icc):
    """(orient, in-circle) of the 4 points as (value, stage) pairs, by the
    dynamic filter alone and with the static bounds of the points' box."""
    wx = pts[:, 0].max() - pts[:, 0].min()
    wy = pts[:, 1].max() - pts[:, 1].min()
    so, si = P.static_bounds(wx, wy, ccw, icc)
    a, b, c, d = pts[0], pts[1], pts[2], pts[3]
    o1 = P.orient2d_staged(a[0], a[1], b[0], b[1], c[0], c[1], ccw)
    o2 = P.orient2d_staged(a[0], a[1], b[0], b[1], c[0], c[1], ccw, so)
    i1 = P.incircle_staged(a[0], a[1], b[0], b[1], c[0], c[1], d[0], d[1], icc)
    i2 = P.incircle_staged(a[0], a[1], b[0], b[1], c[0], c[1], d[0], d[1], icc, si)
    return o1, o2, i1, i2


@st.composite
def integer_quads(draw):
    """Four small-integer points times 2**e, from subnormal to huge: near the
    window's floor the static bound must switch itself off."""
    e = draw(st.integers(-1074, 900))
    return [(draw(st.integers(-9, 9)) * 2.0 ** e, draw(st.integers(-9, 9)) * 2.0 ** e)
            for _ in range(4)]


BOUND_PAIRS = [(P.CCW_A, P.ICC_A), (P.CCW_EXACT_DIFF, P.ICC_EXACT_PRODUCTS), (0.0, 0.0)]


@given(st.one_of(near_circle(), integer_quads(), near_line().map(lambda t: [*t, t[0]])),
       st.sampled_from(BOUND_PAIRS))
def test_static_bounds_decide_only_what_the_dynamic_filter_decides(pts, bounds):
    """fqDel 2.4's static filter: |det| > static may only decide a call the
    dynamic test would decide too, so value and deciding stage are the same
    with and without it (near-degenerate sets put |det| at the error's scale)."""
    quad = np.array(in_window(*pts), dtype=np.float64)
    o1, o2, i1, i2 = _with_and_without_static(quad, *bounds)
    assert o1 == o2 and i1 == i2


@njit(cache=True)
def _with_and_without_static3(pts):
    """(orient, in-sphere) of the 5 points as (value, stage) pairs, by the
    dynamic filter alone and with the static bounds of the points' box."""
    w = np.empty(3)
    for k in range(3):
        w[k] = pts[:, k].max() - pts[:, k].min()
    so, si = P.static_bounds3(w[0], w[1], w[2], P.O3D_A, P.ISP_A)
    a, b, c = (pts[0, 0], pts[0, 1], pts[0, 2]), (pts[1, 0], pts[1, 1], pts[1, 2]), \
        (pts[2, 0], pts[2, 1], pts[2, 2])
    d, e = (pts[3, 0], pts[3, 1], pts[3, 2]), (pts[4, 0], pts[4, 1], pts[4, 2])
    o1 = P.orient3d_staged(a, b, c, d, P.O3D_A)
    o2 = P.orient3d_staged(a, b, c, d, P.O3D_A, so)
    i1 = P.insphere_staged(a, b, c, d, e, P.ISP_A)
    i2 = P.insphere_staged(a, b, c, d, e, P.ISP_A, si)
    return o1, o2, i1, i2


@st.composite
def integer_quints3(draw):
    """Five small-integer 3D points times 2**e, as integer_quads."""
    e = draw(st.integers(-1074, 900))
    return [tuple(draw(st.integers(-9, 9)) * 2.0 ** e for _ in range(3)) for _ in range(5)]


@given(st.one_of(near_sphere(), integer_quints3(),
                 near_sphere().map(lambda t: [t[0], t[1], t[2], t[2], t[4]])))
def test_static_bounds3_decide_only_what_the_dynamic_filter_decides(pts):
    """The inserter's 3D static filter (spatial.static_bounds3): same value
    and deciding stage with and without it, on nearly cospherical and
    coplanar sets, and on small integers from subnormal to huge, each
    rescaled into the exactness window as the API does."""
    try:
        window = exact_points3(np.array(pts, dtype=np.float64))
    except ValueError:  # magnitudes too far apart for the window
        assume(False)
    o1, o2, i1, i2 = _with_and_without_static3(window)
    assert o1 == o2 and i1 == i2


def test_static_bounds3_are_off_where_they_would_leave_the_normal_range():
    assert P.static_bounds3(2.0 ** -200, 2.0 ** -200, 2.0 ** -200, P.O3D_A, P.ISP_A)[1] == np.inf
    o, i = P.static_bounds3(2.0 ** 250, 2.0 ** 250, 2.0 ** 250, P.O3D_A, P.ISP_A)
    assert np.isfinite(o) and i == np.inf  # degree 5 overflows
    o, i = P.static_bounds3(1.0, 1.0, 1.0, P.O3D_A, P.ISP_A)
    assert o == pytest.approx(6 * P.O3D_A) and i == pytest.approx(72 * P.ISP_A)


def test_static_bounds_are_off_where_they_would_leave_the_normal_range():
    assert P.static_bounds(2.0 ** -240, 2.0 ** -240, P.CCW_A, P.ICC_A)[1] == np.inf
    o, i = P.static_bounds(2.0 ** 300, 2.0 ** 300, P.CCW_A, P.ICC_A)  # degree 4 overflows
    assert np.isfinite(o) and i == np.inf
    o, i = P.static_bounds(1.0, 1.0, P.CCW_A, P.ICC_A)
    assert o == pytest.approx(2 * P.CCW_A) and i == pytest.approx(12 * P.ICC_A)


def test_raw_subnormal_products_underflow_which_is_why_the_window_exists():
    """The predicates' precondition (lfqt.predicates): coordinates inside
    the exactness window.  Raw, a product of two subnormals underflows to
    zero with no error term, and a left turn reads as collinear."""
    t = 5e-324
    assert orient_ref((0.0, 0.0), (t, 0.0), (0.0, t)) == 1
    assert P.orient2d_exact(0.0, 0.0, t, 0.0, 0.0, t) == 0.0
    (ax, ay), (bx, by), (cx, cy) = in_window((0.0, 0.0), (t, 0.0), (0.0, t))
    assert P.orient2d_exact(ax, ay, bx, by, cx, cy) == 1.0


tiny_ints = st.tuples(st.integers(-8, 8), st.integers(-8, 8), st.integers(-8, 8))


@given(st.lists(tiny_ints, min_size=5, max_size=5), st.integers(-1074, -1010))
def test_subnormal_sets_are_exact_once_in_the_window(ints, e):
    """Small-integer points scaled into the subnormal range: once the API's
    rescale has put them in the window, every predicate's sign is the
    Fractions' (2D on the first two coordinates)."""
    pts = [tuple(math.ldexp(v, e) for v in p) for p in ints]
    flat = [p[:2] for p in pts]
    a, b, c, d = in_window(*flat[:4])
    assert sign(P.orient2d_exact(*a, *b, *c)) == orient_ref(*flat[:3])
    assert sign(P.incircle_exact(*a, *b, *c, *d)) == incircle_ref(*flat[:4])
    try:
        w = [tuple(map(float, p)) for p in exact_points3(np.array(pts, dtype=np.float64))]
    except ValueError:  # all zero, or too far apart
        assume(False)
    assert sign(P.orient3d_exact(*w[:4])) == orient3d_ref(*pts[:4])
    assert sign(P.insphere_exact(*w)) == insphere_ref(*pts)
