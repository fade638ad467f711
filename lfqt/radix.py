"""LSD radix sort on 8-bit digits (fqDel 3.1).

One pass over the keys builds the histograms of every digit; a digit that is
the same for all keys is skipped, so data that shares its leading bits (all
positive, one binade, ...) pays only for the digits that vary.  Sorting is
stable, which makes the first of a run of equal keys its smallest input index.
"""
import numpy as np
from numba import njit

from .indexing import u

_FF = np.uint64(0xFF)
_INSERTION_RUN = 24


@njit(cache=True, nogil=True)
def histograms(keys, lo, hi, counts):
    """Add the counts of all 8 digits of keys[lo:hi] to counts (8, 256)."""
    for i in range(lo, hi):
        k = keys[u(i)]
        for d in range(8):
            counts[d, (k >> np.uint64(8 * d)) & _FF] += 1


@njit(cache=True, nogil=True)
def digit_counts(keys, lo, hi, shift, counts):
    """counts (256,) of the digit at ``shift`` in keys[lo:hi]."""
    counts[:] = 0
    sh = np.uint64(shift)
    for i in range(lo, hi):
        counts[(keys[u(i)] >> sh) & _FF] += 1


@njit(cache=True, nogil=True)
def scatter(src_k, src_p, dst_k, dst_p, lo, hi, shift, offsets):
    """Stable scatter of [lo, hi) by the digit at ``shift``; offsets (256,)
    holds each bucket's next destination and is advanced."""
    sh = np.uint64(shift)
    for i in range(lo, hi):
        k = src_k[u(i)]
        b = (k >> sh) & _FF
        j = offsets[b]
        offsets[b] = j + 1
        dst_k[u(j)] = k
        dst_p[u(j)] = src_p[u(i)]


def varying_digits(counts, first_key, n):
    """Digits (0 = least significant) that are not the same for all keys."""
    return [d for d in range(8) if counts[d, (int(first_key) >> (8 * d)) & 0xFF] != n]


@njit(cache=True, nogil=True)
def radix_passes(keys, perm, lo, hi, key_buf, perm_buf):
    """Stable LSD sort of keys[lo:hi] (uint64) carrying perm[lo:hi]: one
    histogram pass for all digits, then one scatter per varying digit,
    alternating between the arrays and the scratch key_buf/perm_buf (same
    length as keys).  Returns the number of scatters: when odd, the sorted
    range is in the scratch.  (9- and 11-bit digits, for fewer scatters,
    measured slower on Morton keys.)"""
    n = hi - lo
    if n < 2:
        return 0
    counts = np.zeros((8, 256), dtype=np.int64)
    histograms(keys, lo, hi, counts)
    first = keys[lo]
    passes = 0
    offsets = np.empty(256, dtype=np.int64)
    src_k, src_p, dst_k, dst_p = keys, perm, key_buf, perm_buf
    for d in range(8):
        shift = np.uint64(8 * d)
        if counts[d, (first >> shift) & _FF] == n:
            continue
        total = lo
        for b in range(256):
            offsets[b] = total
            total += counts[d, b]
        scatter(src_k, src_p, dst_k, dst_p, lo, hi, 8 * d, offsets)
        src_k, src_p, dst_k, dst_p = dst_k, dst_p, src_k, src_p
        passes += 1
    return passes


@njit(cache=True, nogil=True)
def radix_sort_range(keys, perm, lo, hi, key_buf, perm_buf):
    """radix_passes, sorted in place: an odd pass count is copied back from
    the scratch.  Returns the number of passes."""
    passes = radix_passes(keys, perm, lo, hi, key_buf, perm_buf)
    if passes % 2 == 1:
        for i in range(lo, hi):
            keys[u(i)] = key_buf[u(i)]
            perm[u(i)] = perm_buf[u(i)]
    return passes


def sort_keys(keys, perm, workers):
    """Stable LSD sort of uint64 ``keys`` carrying ``perm``, chunked over
    ``workers`` (lfqt.parallel.Workers).  Returns (sorted keys, perm), which
    may be the given arrays or their scratch twins."""
    n = keys.shape[0]
    if n < 2:
        return keys, perm
    chunks = workers.chunks(n)
    if len(chunks) == 1:  # no per-chunk offsets: skip the count pass per digit
        key_buf, perm_buf = np.empty_like(keys), np.empty_like(perm)
        if radix_passes(keys, perm, 0, n, key_buf, perm_buf) % 2:
            return key_buf, perm_buf
        return keys, perm
    counts = np.sum(workers.map(chunks, lambda c, lo, hi: _hist_chunk(keys, lo, hi)), axis=0)
    src_k, src_p = keys, perm
    dst_k, dst_p = np.empty_like(keys), np.empty_like(perm)
    for d in varying_digits(counts, keys[0], n):
        per_chunk = np.stack(workers.map(chunks, lambda c, lo, hi: _digit_chunk(src_k, lo, hi, 8 * d)))
        # chunk c writes bucket b after every smaller bucket and after the
        # same bucket of chunks before it: stable
        starts = np.concatenate(([0], np.cumsum(per_chunk.sum(axis=0))[:-1]))
        offsets = starts + np.cumsum(per_chunk, axis=0) - per_chunk
        workers.map(chunks, lambda c, lo, hi: scatter(src_k, src_p, dst_k, dst_p, lo, hi, 8 * d,
                                                      offsets[c].copy()))
        src_k, src_p, dst_k, dst_p = dst_k, dst_p, src_k, src_p
    return src_k, src_p


def _hist_chunk(keys, lo, hi):
    counts = np.zeros((8, 256), dtype=np.int64)
    histograms(keys, lo, hi, counts)
    return counts


def _digit_chunk(keys, lo, hi, shift):
    counts = np.empty(256, dtype=np.int64)
    digit_counts(keys, lo, hi, shift, counts)
    return counts


@njit(cache=True, nogil=True)
def _longest_run(shi):
    n = shi.shape[0]
    longest = 0
    start = 0
    for i in range(1, n + 1):
        if i == n or shi[i] != shi[i - 1]:
            longest = max(longest, i - start)
            start = i
    return longest


@njit(cache=True, nogil=True)
def order_ties(shi, slo, perm):
    """Within each run of equal ``shi``, sort ``slo`` (carrying perm) stably:
    insertion sort for short runs, radix sort for long ones."""
    n = shi.shape[0]
    # Scratch is sized before the loop: an array variable reassigned inside
    # it costs numba reference counting on every iteration.
    size = n if _longest_run(shi) > _INSERTION_RUN else 0
    key_buf = np.empty(size, dtype=np.uint64)
    perm_buf = np.empty(size, dtype=perm.dtype)
    start = 0
    while start < n:
        end = start + 1
        while end < n and shi[end] == shi[start]:
            end += 1
        if end - start > _INSERTION_RUN:
            radix_sort_range(slo, perm, start, end, key_buf, perm_buf)
        elif end - start > 1:
            for i in range(start + 1, end):
                k = slo[i]
                p = perm[i]
                j = i - 1
                while j >= start and slo[j] > k:
                    slo[j + 1] = slo[j]
                    perm[j + 1] = perm[j]
                    j -= 1
                slo[j + 1] = k
                perm[j + 1] = p
        start = end


@njit(cache=True, nogil=True)
def gather_in_runs(shi, src, perm, dst, lo, hi):
    """dst[i] = src[perm[i]] for the i in [lo, hi) that share their high word
    ``shi[i]`` with a neighbour; the others are not written."""
    n = shi.shape[0]
    for i in range(lo, hi):
        k = shi[u(i)]
        if (i > 0 and shi[u(i - 1)] == k) or (i + 1 < n and shi[u(i + 1)] == k):
            dst[u(i)] = src[u(perm[u(i)])]


def sort_keys128(hi, lo, perm, workers):
    """Stable sort of 128-bit keys given as (hi, lo) uint64 arrays carrying
    ``perm``: radix on ``hi`` over ``workers``, then each run of equal ``hi``
    ordered by ``lo``.  Returns (sorted_hi, sorted_lo, perm); ``hi`` may be
    used as scratch.

    A low word only ever tells apart keys whose high words are equal, so
    sorted_lo is written inside runs of equal high words alone (elsewhere it
    holds garbage, which its readers never look at: lfqt.dc.subdivide).  On
    float64 input runs are rare, so this saves a random gather of 8 bytes
    per point, and the untouched pages."""
    shi, perm = sort_keys(hi, perm, workers)
    slo = np.empty(len(lo), dtype=np.uint64)
    workers.map(workers.chunks(len(lo)),
                lambda c, a, b: gather_in_runs(shi, lo, perm, slo, a, b))
    order_ties(shi, slo, perm)
    return shi, slo, perm
