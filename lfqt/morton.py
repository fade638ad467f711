"""Morton keys of the linear floating-point quad-tree (fqDel 2.2).

Float bit patterns are mapped to unsigned integers whose order is the numeric
order (negative values: invert every bit; positive values: set the sign bit),
after folding ``-0.0`` into ``+0.0`` so that equal points get equal keys.  The
two coordinates are then interleaved with x on the odd bits, so the most
significant key bit is x's sign bit and a split at an odd bit divides in x.

float32 points give one 64-bit key.  float64 points give a 128-bit key, kept
as two uint64 arrays ``(hi, lo)``: ``hi`` interleaves the upper 32 bits of x
and y, ``lo`` the lower 32 bits.
"""
import numpy as np
from numba import njit

from ._input import BITS, fold_bits
from .indexing import u

_U64 = np.uint64
_SIGN64 = _U64(1 << 63)
_SIGN32 = np.uint32(1 << 31)
_LOW32 = _U64(0xFFFFFFFF)
_M16 = _U64(0x0000FFFF0000FFFF)
_M8 = _U64(0x00FF00FF00FF00FF)
_M4 = _U64(0x0F0F0F0F0F0F0F0F)
_M2 = _U64(0x3333333333333333)
_M1 = _U64(0x5555555555555555)
_S16, _S8, _S4, _S2, _S1, _S32 = _U64(16), _U64(8), _U64(4), _U64(2), _U64(1), _U64(32)
_MASK64, _INF64 = BITS[np.dtype(np.float64)][1:]  # |v|'s bits, inf's (lfqt._input.fold_bits)
_MASK32, _INF32 = BITS[np.dtype(np.float32)][1:]


@njit(cache=True, inline="always")
def ordered_bits64(bits):
    """Order-preserving image of float64 bits (as uint64); -0.0 maps like +0.0."""
    if bits == _SIGN64:
        bits = _U64(0)
    if bits & _SIGN64:
        return ~bits
    return bits | _SIGN64


@njit(cache=True, inline="always")
def ordered_bits32(bits):
    """Order-preserving image of float32 bits (as uint32); -0.0 maps like +0.0."""
    if bits == _SIGN32:
        bits = np.uint32(0)
    if bits & _SIGN32:
        return ~bits
    return bits | _SIGN32


@njit(cache=True, inline="always")
def spread_bits(v):
    """Move bit k of a 32-bit value to bit 2k."""
    v = (v | (v << _S16)) & _M16
    v = (v | (v << _S8)) & _M8
    v = (v | (v << _S4)) & _M4
    v = (v | (v << _S2)) & _M2
    v = (v | (v << _S1)) & _M1
    return v


@njit(cache=True, inline="always")
def interleave(x32, y32):
    return (spread_bits(x32) << _S1) | spread_bits(y32)


# The kernels read ``bits``, the (n, 2) unsigned view of C-contiguous points,
# flat: a point's x and y side by side at 2i and 2i + 1, a stride the compiler
# sees (``bits[i, 0]`` multiplies by the run-time shape), so that it
# vectorizes the loop (1M float64 points, warm: 5.0 ms from strided column
# views or 2D indexing, 2.2 ms flat).


# The pipeline's kernels (lfqt.dc) also start the sort's permutation,
# perm[i] = i, and run the input's scan for NaN, inf and the extreme
# magnitudes (lfqt._input._scan_bits) on each block of SCAN_BLOCK points
# just before its keys, while the block is in L1: one pass over the input
# instead of three, with each loop still vectorized; folding the scan into
# the keys' loop itself was slower (docs/performance.md, "keys' pass").
SCAN_BLOCK = 512


@njit(cache=True, inline="always")
def _scan_block(ints, b0, b1, scan, mask, inf):
    """The scan (nonfinite, big, small) carried over points [b0, b1)."""
    nonfinite, big, small = scan
    for k in range(2 * b0, 2 * b1):
        nonfinite, big, small = fold_bits(ints[u(k)], nonfinite, big, small, mask, inf)
    return nonfinite, big, small


@njit(cache=True, nogil=True)
def morton_keys32_into(bits, keys, perm, lo, hi):
    """64-bit keys of float32 points [lo, hi) into ``keys``, perm[i] = i;
    ``bits`` (n, 2) uint32.  Returns the scan of the coordinates, as
    lfqt._input._scan_bits: (nonfinite, big, small)."""
    flat = bits.reshape(-1)
    scan = False, _MASK32 - _MASK32, _MASK32
    for b0 in range(lo, hi, SCAN_BLOCK):
        b1 = min(b0 + SCAN_BLOCK, hi)
        scan = _scan_block(flat.view(np.int32), b0, b1, scan, _MASK32, _INF32)
        for i in range(b0, b1):
            keys[u(i)] = interleave(_U64(ordered_bits32(flat[u(2 * i)])),
                                    _U64(ordered_bits32(flat[u(2 * i + 1)])))
            perm[u(i)] = i
    return scan


@njit(cache=True, nogil=True)
def morton_keys64_into(bits, khi, klo, lo, hi):
    """128-bit keys of float64 points [lo, hi) into (khi, klo); ``bits``
    (n, 2) uint64."""
    flat = bits.reshape(-1)
    for i in range(lo, hi):
        ox = ordered_bits64(flat[u(2 * i)])
        oy = ordered_bits64(flat[u(2 * i + 1)])
        khi[u(i)] = interleave(ox >> _S32, oy >> _S32)
        klo[u(i)] = interleave(ox & _LOW32, oy & _LOW32)


@njit(cache=True, nogil=True)
def morton_high64_into(bits, khi, perm, lo, hi):
    """The high 64 bits alone of the keys of float64 points [lo, hi), perm[i]
    = i; returns the scan as morton_keys32_into.  The low bits tell apart
    only keys whose high bits are equal, rare on float64 input, and
    ``low_word`` gives them on demand, without writing the low words
    (docs/performance.md, "high words")."""
    flat = bits.reshape(-1)
    scan = False, _MASK64 - _MASK64, _MASK64
    for b0 in range(lo, hi, SCAN_BLOCK):
        b1 = min(b0 + SCAN_BLOCK, hi)
        scan = _scan_block(flat.view(np.int64), b0, b1, scan, _MASK64, _INF64)
        for i in range(b0, b1):
            khi[u(i)] = interleave(ordered_bits64(flat[u(2 * i)]) >> _S32,
                                   ordered_bits64(flat[u(2 * i + 1)]) >> _S32)
            perm[u(i)] = i
    return scan


@njit(cache=True)
def low_word(src, i):
    """The low 64 bits of key i: src[i] where ``src`` holds them (1D), else
    computed from the (n, 2) uint64 bits of float64 points.  Not inlined in
    numba's IR, where the branch on ``src.ndim`` would not be pruned before
    typing (LLVM may inline it)."""
    if src.ndim == 1:
        return src[u(i)]
    return interleave(ordered_bits64(src[u(i), 0]) & _LOW32, ordered_bits64(src[u(i), 1]) & _LOW32)


def point_bits(x, y, dtype):
    """The (n, 2) unsigned bit view of the points (x, y) as ``dtype``."""
    pts = np.column_stack((x, y)).astype(dtype, copy=False)
    return pts.view(np.uint64 if pts.dtype == np.float64 else np.uint32)


def ordered_bits(values):
    """The order-preserving unsigned images of a float32 or float64 array
    (ordered_bits32/64, element-wise in numpy): uint32 or uint64."""
    values = np.ascontiguousarray(values)
    u = np.dtype(f"uint{8 * values.dtype.itemsize}")
    sign = u.type(1 << (8 * values.dtype.itemsize - 1))
    b = values.view(u)
    b = np.where(b == sign, u.type(0), b)  # -0.0 as +0.0
    return np.where(b & sign, ~b, b | sign).astype(u)


def from_ordered_bits(bits, dtype):
    """The floats of ``dtype`` whose ordered_bits are ``bits`` (the inverse)."""
    dtype = np.dtype(dtype)
    u = np.dtype(f"uint{8 * dtype.itemsize}")
    bits = np.asarray(bits, dtype=u)
    sign = u.type(1 << (8 * dtype.itemsize - 1))
    return np.where(bits & sign, bits ^ sign, ~bits).astype(u).view(dtype)


def morton_keys32(x, y):
    """64-bit keys of float32 coordinate arrays."""
    keys = np.empty(x.shape[0], dtype=np.uint64)
    morton_keys32_into(point_bits(x, y, np.float32), keys, np.empty(x.shape[0], np.int64), 0,
                       x.shape[0])
    return keys


def morton_keys64(x, y):
    """128-bit keys of float64 coordinate arrays, as (hi, lo)."""
    hi = np.empty(x.shape[0], dtype=np.uint64)
    lo = np.empty(x.shape[0], dtype=np.uint64)
    morton_keys64_into(point_bits(x, y, np.float64), hi, lo, 0, x.shape[0])
    return hi, lo
