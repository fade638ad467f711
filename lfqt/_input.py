"""Input validation and exact rescaling, shared by both pipelines, verify and
Delaunay (stumpy's core.py: no public module imports another for a helper).

Input is accepted as float32, float64, float16 or integers that float64 holds
exactly, and is never rounded.  Coordinates are then rescaled by an exact
power of two into the *exactness window* of their dimension: every nonzero
|coordinate| in [2**(MIN_ULP_EXP + 52), 2**MAX_EXP), so that no product of
the predicates' degree (4 for in-circle, 5 for in-sphere) overflows or leaves
the normal range, which expansion arithmetic needs to be exact.
"""
import math

import numpy as np
from numba import njit

from .indexing import u
from .workers import Workers

MAX_EXP = 248
MIN_ULP_EXP = -240
MAX_EXP_3D = 198
MIN_ULP_EXP_3D = -192
FORMATS = {  # coord_bits, exp_bits, mant_bits, smallest normal exponent
    np.dtype(np.float32): (32, 8, 23, -126),
    np.dtype(np.float64): (64, 11, 52, -1022),
}


def as_exact_float(points, dims):
    """Validate an (n, d) array-like with d in ``dims``; return it as float32
    or float64 holding exactly the input values."""
    if isinstance(points, np.ma.MaskedArray):
        raise TypeError("points is a masked array; masked-out rows would be triangulated as "
                        "real points: pass points[~np.ma.getmaskarray(points).any(axis=1)] "
                        "(the unmasked rows) or points.filled(...) instead")
    arr = np.asarray(points)
    if arr.dtype == object or arr.dtype.kind not in "fiu":
        raise TypeError(f"points must be real numbers, got dtype {arr.dtype}")
    if arr.ndim != 2 or arr.shape[1] not in dims:
        want = " or ".join(f"(n, {d})" for d in dims)
        raise ValueError(f"points must have shape {want}, got {arr.shape}")
    if arr.dtype.kind in "iu":
        big = (arr > 2 ** 53) | (arr < -2 ** 53)
        inexact = np.zeros(len(arr), dtype=bool)
        for r, c in zip(*np.nonzero(big)):
            inexact[r] |= int(float(arr[r, c])) != int(arr[r, c])
        if inexact.any():
            rows = np.flatnonzero(inexact)
            raise ValueError(f"{len(rows)} integer rows are not exactly representable in float64 "
                             f"(beyond 2**53); the first is row {rows[0]}")
        return arr.astype(np.float64)
    if arr.dtype == np.float16:
        return arr.astype(np.float32)
    if arr.dtype not in (np.float32, np.float64):
        wide = arr
        arr = arr.astype(np.float64)
        if not np.array_equal(arr, wide, equal_nan=True):
            raise ValueError(f"{wide.dtype} points are not exactly representable as float64")
    return arr


def coordinates2d(points, workers=None):
    """Validate (n, 2) input; return (pts, scale exponent): pts is
    exact_floats2d's, the exponent exponent_for's."""
    arr = exact_floats2d(points)
    big, small = _checked_magnitudes(arr, workers)
    return arr, exponent_for(arr.dtype, big, small)


def exact_floats2d(points):
    """Validate (n, 2) input but for NaN and inf: a C-contiguous float32 or
    float64 (n, 2) array holding exactly the input values, the input itself
    when it is one (no copy; a point's x and y share a cache line, which the
    kernels read side by side)."""
    return np.ascontiguousarray(as_exact_float(points, (2,)))


def _checked_magnitudes(arr, workers=None):
    """(max |v|, min nonzero |v|) over the (n, d) float array, in one pass
    (split over ``workers``); ValueError for rows with NaN or inf.  A
    C-contiguous array is scanned by its bit patterns (``_scan_bits``); the
    rows are looked at one by one only to report a NaN or inf."""
    workers = workers or Workers(1)
    chunks = workers.chunks(arr.shape[0])
    if arr.flags.c_contiguous and arr.dtype in BITS:
        ints, mask, inf = BITS[arr.dtype]
        flat, d = arr.reshape(-1).view(ints), arr.shape[1]
        parts = workers.map(chunks, lambda c, lo, hi: _scan_bits(flat, d * lo, d * hi,
                                                                 mask, inf))
        return magnitudes(arr, parts, workers)
    parts = workers.map(chunks, lambda c, lo, hi: _scan(arr, lo, hi))
    _report_nonfinite(parts)
    return max((p[2] for p in parts), default=0.0), min((p[3] for p in parts), default=np.inf)


def _report_nonfinite(parts):
    """ValueError naming the rows with NaN or inf, from _scan's parts."""
    bad = sum(p[0] for p in parts)
    if bad:
        first = min(p[1] for p in parts if p[0])
        raise ValueError(f"points contain NaN or inf in {bad} rows; the first is row {first}")


def magnitudes(arr, parts, workers=None):
    """(max |v|, min nonzero |v|) of the C-contiguous float array ``arr``
    from the (nonfinite, big, small) of _scan_bits over its chunks; a NaN or
    inf is reported by the rows' scan (ValueError)."""
    if any(p[0] for p in parts):
        workers = workers or Workers(1)
        _report_nonfinite(workers.map(workers.chunks(arr.shape[0]),
                                      lambda c, lo, hi: _scan(arr, lo, hi)))
    ints, mask, _ = BITS[arr.dtype]
    big = max((p[1] for p in parts), default=ints(0))
    small = min((p[2] for p in parts), default=mask)
    return (_float_of_bits(big, ints, arr.dtype),
            np.inf if small == mask else _float_of_bits(small, ints, arr.dtype))


def _float_of_bits(bits, ints, dtype):
    """The float of ``dtype`` whose bit pattern is the integer ``bits``."""
    return float(np.array(bits, dtype=ints).view(dtype))


# float dtype -> (signed int of its width, mask of all but the sign bit,
# bit pattern of inf)
BITS = {np.dtype(np.float64): (np.int64, np.int64(0x7FFF_FFFF_FFFF_FFFF),
                               np.int64(0x7FF0_0000_0000_0000)),
        np.dtype(np.float32): (np.int32, np.int32(0x7FFF_FFFF), np.int32(0x7F80_0000))}


@njit(cache=True, nogil=True)
def _scan_bits(ints, lo, hi, mask, inf):
    """Over ints[lo:hi], float coordinates as signed ints of their bits:
    (whether one is NaN or inf, the bits of max |v|, of min nonzero |v|;
    ``mask`` when all are zero).  With the sign bit cleared, the patterns of
    finite floats are ordered as their magnitudes, so the loop is integer
    compares, which vectorize (float min and max do not, for NaN's sake:
    docs/performance.md, "magnitude scan")."""
    nonfinite = False
    big = mask - mask
    small = mask
    for k in range(lo, hi):
        nonfinite, big, small = fold_bits(ints[u(k)], nonfinite, big, small, mask, inf)
    return nonfinite, big, small


@njit(cache=True, inline="always")
def fold_bits(b, nonfinite, big, small, mask, inf):
    """One coordinate's bits, as a signed int of its width, folded into the
    scan's (nonfinite, big, small) (_scan_bits; the Morton pass of
    lfqt.dc folds them as it reads them for the keys)."""
    b &= mask
    return nonfinite | (b >= inf), max(big, b), min(small, b if b != 0 else mask)


@njit(cache=True, nogil=True)
def _scan(A, lo, hi):
    """One pass over rows [lo, hi) of A: (rows with NaN/inf, first such row,
    max |v|, min nonzero |v|)."""
    bad = 0
    first = -1
    big = 0.0
    small = np.inf
    for i in range(lo, hi):
        finite = True
        for a in range(A.shape[1]):
            finite &= abs(A[i, a]) < np.inf
        if not finite:
            bad += 1
            if first < 0:
                first = i
            continue
        for a in range(A.shape[1]):
            v = abs(A[i, a])
            big = max(big, v)
            if v > 0.0:
                small = min(small, v)
    return bad, first, big, small


def exponent_for(dtype, big, small):
    """Power of two that brings coordinates with nonzero magnitudes in
    [small, big] into the exactness window, or ValueError when they span too
    many binades."""
    if dtype == np.float32:
        return 0  # float32's whole range already fits the window
    return window_exponent(big, small, MAX_EXP, MIN_ULP_EXP)


def window_exponent(big, small, max_exp, min_ulp_exp):
    """Power of two s with every nonzero magnitude in [small, big] mapped into
    [2**(min_ulp_exp + 52), 2**max_exp).  The floor is on magnitudes, not on
    ulps: a subnormal input scaled only until its ulp is 2**min_ulp_exp
    would stay below the window, and the degree-5 products of the 3D
    predicates would lose their tails to underflow."""
    if big == 0.0:
        return 0
    top = math.frexp(big)[1] - 1
    bottom = math.frexp(small)[1] - 1  # exact for subnormals too
    lo = min_ulp_exp + 52 - bottom
    hi = max_exp - 1 - top
    if lo > hi:
        span = max_exp - 1 - min_ulp_exp - 52
        raise ValueError(
            f"coordinate magnitudes span 2**{bottom} to 2**{top}, more than {span} binades; "
            "exact predicates cannot represent every product without overflow or underflow. "
            "Translate or split the data so that the smallest nonzero magnitude is closer to "
            "the largest.")
    return min(max(0, lo), hi)


def exact_coordinates2d(points):
    """float64 coordinates, rescaled by an exact power of two so that the
    predicates are exact on them."""
    pts, s = coordinates2d(points)
    return pts[:, 0].astype(np.float64) * 2.0 ** s, pts[:, 1].astype(np.float64) * 2.0 ** s


def exact_points(points, dims, copy=True):
    """Validated (n, d) float64 coordinates rescaled by an exact power of two
    into the exactness window of dimension d; returns (P, scale exponent,
    the largest |coordinate| of P).  With ``copy=False``, P is the input
    itself when that needs neither a new dtype, nor a new layout, nor a
    rescaling: for callers that only read it (16 MB less to write for 1M 2D
    points)."""
    arr = as_exact_float(points, dims)
    big, small = _checked_magnitudes(arr)
    window = (MAX_EXP, MIN_ULP_EXP) if arr.shape[1] == 2 else (MAX_EXP_3D, MIN_ULP_EXP_3D)
    s = window_exponent(float(big), float(small), *window)
    if s:  # a new array either way, in one pass
        P = np.multiply(arr, 2.0 ** s, dtype=np.float64, order="C")
    else:
        P = np.array(arr, dtype=np.float64, order="C", copy=copy or None)
    return P, s, float(big) * 2.0 ** s


def exact_points3(points):
    return exact_points(points, (3,))[0]


def index_dtype(n):
    return np.int32 if n < 2 ** 31 - 2 else np.int64
