"""Exact floating-point expansion arithmetic (Shewchuk 1997).

An *expansion* is an array of doubles, nonoverlapping and ordered by
increasing magnitude, whose exact sum is the value it represents.  Every
routine here is exact as long as no operation overflows or leaves the
normal range; lfqt._input keeps coordinates in a window where that holds.
Also the small-integer fast paths of the exact stages: exact differences
that are integers in a common power-of-two unit are multiplied in int64.
"""
import math

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic

EPS = 2.0 ** -53  # half an ulp of 1.0: the relative rounding error of one operation


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


@intrinsic
def fma(typingctx, a, b, c):
    """a * b + c rounded once (llvm.fma.f64: one instruction where the CPU
    has FMA, an exact libm call where it has not)."""
    def codegen(context, builder, signature, args):
        f64 = ir.DoubleType()
        fn = cgutils.get_or_insert_function(builder.module, ir.FunctionType(f64, [f64] * 3),
                                            "llvm.fma.f64")
        return builder.call(fn, args)
    return types.float64(types.float64, types.float64, types.float64), codegen


@njit(cache=True, inline="always")
def two_product(a, b):
    """a * b = x + err exactly: err is the rounding of the product, which a
    fused multiply-add gets exactly (Dekker's split would take 17 flops)."""
    x = a * b
    return x, fma(a, b, -x)


# Double-double ("dd") evaluation, the predicates' stage before expansions:
# a value is an unevaluated pair hi + lo.  Each helper's error, for exact
# double arguments, is derived where it is used (planar._incircle_dd,
# spatial._insphere_dd) from three facts: two_sum, two_diff and two_product
# are exact; every other operation rounds by at most EPS of its result; and
# nothing underflows or overflows, which the callers ensure by using it only
# for permanents in [DD_FLOOR, DD_CEIL].
DD_FLOOR = 2.0 ** -900
DD_CEIL = 2.0 ** 990


@njit(cache=True, inline="always")
def dd_cross(a, b, c, d):
    """a*b - c*d as a pair: off by <= 3.01 EPS^2 (|ab| + |cd|), with |hi| <=
    (1 + 2 EPS) (|ab| + |cd|) and |lo| <= 2.01 EPS (|ab| + |cd|)."""
    p, e = two_product(a, b)
    q, f = two_product(c, d)
    s, t = two_diff(p, q)
    return s, t + (e - f)


@njit(cache=True, inline="always")
def dd_times(ah, al, bh, bl):
    """(ah + al) * (bh + bl) as a pair, al * bl dropped."""
    p, e = two_product(ah, bh)
    return p, fma(ah, bl, fma(al, bh, e))


@njit(cache=True, inline="always")
def dd_scale(z, kh, kl):
    """z * (kh + kl) as a pair."""
    p, e = two_product(z, kh)
    return p, fma(z, kl, e)


@njit(cache=True, inline="always")
def dd_sum3(h1, l1, h2, l2, h3, l3):
    """(h1 + l1) + (h2 + l2) + (h3 + l3) as a pair: two exact two_sums, and
    their tails and the low parts added in four roundings."""
    s, t = two_sum(h1, h2)
    hi, t2 = two_sum(s, h3)
    return hi, ((t + t2) + (l1 + l2)) + l3


@njit(cache=True, inline="always")
def dd_lift2(x, y):
    """x^2 + y^2 as a pair."""
    p, e = two_product(x, x)
    q, f = two_product(y, y)
    s, t = two_sum(p, q)
    return s, t + (e + f)


@njit(cache=True, inline="always")
def dd_lift3(x, y, z):
    """x^2 + y^2 + z^2 as a pair."""
    p, e = two_product(x, x)
    q, f = two_product(y, y)
    r, g = two_product(z, z)
    s, t = two_sum(p, q)
    hi, t2 = two_sum(s, r)
    return hi, (t + t2) + ((e + f) + g)


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
def negate(e, elen):
    out = np.empty(elen)
    for i in range(elen):
        out[i] = -e[i]
    return out


@njit(cache=True)
def exact_diff(a, b):
    x, y = two_diff(a, b)
    out = np.empty(2)
    if y == 0.0:
        out[0] = x
        return out, 1
    out[0] = y
    out[1] = x
    return out, 2


@njit(cache=True)
def expansion_sign(e, elen):
    top = e[elen - 1]
    return 1.0 if top > 0.0 else (-1.0 if top < 0.0 else 0.0)


@njit(cache=True)
def cross_exact(ux, uxl, vy, vyl, uy, uyl, vx, vxl):
    """ux*vy - uy*vx for expansion operands."""
    p, pl = expansion_product(ux, uxl, vy, vyl)
    q, ql = expansion_product(uy, uyl, vx, vxl)
    out = np.empty(pl + ql)
    n = expansion_sum(p, pl, negate(q, ql), ql, out)
    return out, n


@njit(cache=True, inline="always")
def int_unit(m, limit_bits):
    """Power of two u with m / u < 2**limit_bits, for the integer fast paths."""
    return math.ldexp(1.0, math.frexp(m)[1] - limit_bits)


@njit(cache=True, inline="always")
def as_int(v, u):
    """v / u as an int64 when that is an integer, else a sentinel."""
    q = v / u  # exact: u is a power of two and no value leaves the normal range
    return np.int64(q) if q == np.floor(q) else np.int64(-(1 << 62))


NOT_INT = -(1 << 62)


@njit(cache=True, inline="always")
def sign_int(v):
    return 1.0 if v > 0 else (-1.0 if v < 0 else 0.0)


@njit(cache=True, inline="always")
def sign4(x3, x2, x1, x0):
    for v in (x3, x2, x1, x0):
        if v != 0.0:
            return 1.0 if v > 0.0 else -1.0
    return 0.0
