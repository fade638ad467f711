"""Level-dependent stage-1 bounds of the LFQT (fqDel section 2.4).

Points that share every Morton key bit above a level share sign, exponent and
leading mantissa bits, so their coordinate differences are exact and short,
and some products are exact too.  ``level_bounds`` turns that into tighter
stage-1 bounds for the merge at that level; each bound is derived below, at
its definition.
"""
from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic

from .expansion import EPS
from .planar import CCW_A, ICC_A

# Stage-1 bounds when the coordinate differences are exact (shared sign and
# exponent, Sterbenz): Shewchuk's analysis of his bound A without the
# differences' roundings.
CCW_EXACT_DIFF = (2.0 + 16.0 * EPS) * EPS
ICC_EXACT_DIFF = (7.0 + 56.0 * EPS) * EPS
# ... and when, in addition, the differences are short enough that the 2x2
# products are exact: only the lifts, the three terms and their sum round.
ICC_EXACT_PRODUCTS = (3.0 + 24.0 * EPS) * EPS


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


@njit(cache=True, inline="always")
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
    from the error analysis of stage 1 (Shewchuk's bound A).
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
