"""Radix sort on 8-bit digits (fqDel 3.1): most significant digit first
down to ranges that fit in cache, least significant digit first in them.

LSD: one pass over the keys builds the histograms of every digit; a digit
that is the same for all keys is skipped, so data that shares its leading
bits (all positive, one binade, ...) pays only for the digits that vary.
Each LSD pass moves every key, so on arrays larger than the cache every pass
goes to memory.  MSD first (``msd_sort_range``): a range larger than
``MSD_LEAF`` keys is split into 256 buckets by the 8 bits from its highest
varying bit down (a counting pass and a scatter), each bucket in turn, until
the ranges fit in cache, where LSD sorts them: two passes through memory per
split level (1M uniform keys: 2 levels) against one per varying digit (7)
for LSD alone, and the buckets are independent work for the threads
(``sort_keys``).  The MSD digits start at the highest varying bit, not at a
byte boundary: on float keys that bit is often alone in its byte (the
exponent bits of the few points near 0), and a byte-aligned split would
move every key to separate those few.  In a leaf, the few top digits that
tell its keys apart are scattered and an insertion sort orders the ties
(``leaf_passes``), instead of a pass for every varying digit.  Sorting is
stable, which makes the first of a run of equal keys its smallest input
index.
"""
import numpy as np
from numba import njit
from numba.cpython.unsafe.numbers import leading_zeros

from .indexing import u
from .morton import low_word

_FF = np.uint64(0xFF)
_INSERTION_RUN = 24
# Keys per range sorted by LSD: 64k keys and their int32 ids are 768 KB,
# about a core's L2 cache.  Measured on 1M uniform and cluster keys, one and
# two threads: leaves of 2**14 to 2**19 keys within noise of each other,
# 2**16 among the best, 1.3-1.8x faster than LSD on the whole array.
MSD_LEAF = 1 << 16
# A leaf sorts by the top digits that could tell apart PREFIX_REACH values
# per key, then by insertion, which gives up after FIX_BUDGET moves per key
# (leaf_passes).
PREFIX_REACH = 16
FIX_BUDGET = 4
_MSD_STACK = 8 * 256 + 1  # pending ranges: at most 255 per level of 8, plus one


@njit(cache=True, nogil=True)
def histograms(keys, lo, hi, counts, digits):
    """Add the counts of the lowest ``digits`` digits of keys[lo:hi] to
    counts (8, 256)."""
    for i in range(lo, hi):
        k = keys[u(i)]
        for d in range(digits):
            counts[d, (k >> np.uint64(8 * d)) & _FF] += 1


@njit(cache=True, nogil=True)
def digit_counts(keys, lo, hi, shift, counts):
    """counts (256,) of the digit at ``shift`` in keys[lo:hi], in four
    partial histograms: on skewed digits (the exponent bits of one binade)
    one counter would chain every increment on the last (docs/performance.md,
    "partial histograms")."""
    part = np.zeros((4, 256), dtype=np.int64)
    sh = np.uint64(shift)
    i = lo
    while i + 4 <= hi:
        for j in range(4):
            part[j, (keys[u(i + j)] >> sh) & _FF] += 1
        i += 4
    for j in range(hi - i):
        part[j, (keys[u(i + j)] >> sh) & _FF] += 1
    for b in range(256):
        counts[b] = part[0, b] + part[1, b] + part[2, b] + part[3, b]


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


@njit(cache=True, nogil=True)
def radix_passes(keys, perm, lo, hi, key_buf, perm_buf, digits=8):
    """Stable LSD sort of keys[lo:hi] (uint64), whose digits from ``digits``
    up are known to agree, carrying perm[lo:hi]: one histogram pass for the
    digits below, then one scatter per varying digit,
    alternating between the arrays and the scratch key_buf/perm_buf (same
    length as keys).  Returns the number of scatters: when odd, the sorted
    range is in the scratch.  (9- and 11-bit digits, for fewer scatters,
    measured slower on Morton keys.)"""
    if hi - lo < 2:
        return 0
    counts = np.zeros((8, 256), dtype=np.int64)
    histograms(keys, lo, hi, counts, digits)
    return _lsd(keys, perm, (key_buf, perm_buf), lo, hi, counts, keys[u(lo)], 0, digits, 0)


@njit(cache=True, nogil=True)
def _lsd(keys, perm, scratch, lo, hi, counts, first, d_lo, d_hi, done):
    """Scatter passes of [lo, hi) by each digit d_lo <= d < d_hi that varies
    (counts: histograms, first: any key of the range), between keys, perm
    and ``scratch`` = (key_buf, perm_buf), after ``done`` passes (their
    parity tells which pair holds the range).  Returns the passes, ``done``
    included."""
    key_buf, perm_buf = scratch
    offsets = np.empty(256, dtype=np.int64)
    src_k, src_p, dst_k, dst_p = keys, perm, key_buf, perm_buf
    if done % 2 == 1:
        src_k, src_p, dst_k, dst_p = key_buf, perm_buf, keys, perm
    for d in range(d_lo, d_hi):
        shift = np.uint64(8 * d)
        if counts[d, (first >> shift) & _FF] == hi - lo:
            continue
        total = lo
        for b in range(256):
            offsets[b] = total
            total += counts[d, b]
        scatter(src_k, src_p, dst_k, dst_p, lo, hi, 8 * d, offsets)
        src_k, src_p, dst_k, dst_p = dst_k, dst_p, src_k, src_p
        done += 1
    return done


@njit(cache=True, nogil=True)
def insertion_sort(keys, perm, lo, hi, budget):
    """Stable insertion sort of keys[lo:hi] carrying perm, giving up once it
    has moved more than ``budget`` keys (returns False; what it did keeps
    every key with its id, and equal keys in their order)."""
    moves = 0
    for i in range(lo + 1, hi):
        k = keys[u(i)]
        if keys[u(i - 1)] <= k:
            continue
        p = perm[u(i)]
        j = i - 1
        while j >= lo and keys[u(j)] > k:
            keys[u(j + 1)] = keys[u(j)]
            perm[u(j + 1)] = perm[u(j)]
            j -= 1
        keys[u(j + 1)] = k
        perm[u(j + 1)] = p
        moves += i - 1 - j
        if moves > budget:
            return False
    return True


@njit(cache=True, nogil=True)
def leaf_passes(keys, perm, lo, hi, key_buf, perm_buf, digits):
    """radix_passes for a range that fits in cache, where most digits are
    not needed: keys told apart by their top digits alone are in order
    after those, and an insertion sort of the whole keys puts the few that
    tie in theirs.  The top digits taken are the fewest, from the highest
    varying down, whose values seen (the histograms' nonzero counts)
    multiply to ``PREFIX_REACH`` per key; an insertion sort that moves more
    than ``FIX_BUDGET`` keys per key (clustered keys, whose top digits
    combine in fewer ways) gives up, and LSD on every digit finishes from
    there.  Returns the number of scatters, as radix_passes.  (1M uniform
    points: 256 leaves of about 4k keys, 2 digits of 6 or 7 scattered.)"""
    n = hi - lo
    if n < 2:
        return 0
    counts = np.empty((8, 256), dtype=np.int64)
    first = keys[u(lo)]
    low = digits
    reach = 1.0
    while low > 0 and reach < PREFIX_REACH * n:  # each digit's histogram, from the top
        low -= 1
        digit_counts(keys, lo, hi, 8 * low, counts[low])
        seen = 0
        for b in range(256):
            seen += counts[low, b] != 0
        reach *= seen
    passes = _lsd(keys, perm, (key_buf, perm_buf), lo, hi, counts, first, low, digits, 0)
    if low == 0:
        return passes
    src_k, src_p = (key_buf, perm_buf) if passes % 2 == 1 else (keys, perm)
    if insertion_sort(src_k, src_p, lo, hi, FIX_BUDGET * n):
        return passes
    counts[:low] = 0
    histograms(src_k, lo, hi, counts, low)
    return _lsd(keys, perm, (key_buf, perm_buf), lo, hi, counts, first, 0, digits, passes)


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


def sort_keys(keys, perm, workers, leaf=MSD_LEAF, scratch=None):
    """Stable sort of uint64 ``keys`` carrying ``perm`` (msd_sort_range), in
    place, over ``workers`` (lfqt.workers.Workers): ranges larger than a
    thread's share are split in parallel (each split by chunks of the range),
    then the ranges are sorted on the threads, largest first.  ``scratch``:
    arrays like keys and perm to sort through (default: new ones).  Returns
    (keys, perm)."""
    n = keys.shape[0]
    if n < 2:
        return keys, perm
    key_buf, perm_buf = scratch or (np.empty_like(keys), np.empty_like(perm))
    if len(workers.chunks(n)) == 1:
        msd_sort_range(keys, perm, 0, n, key_buf, perm_buf, 63, False, leaf)
        return keys, perm
    share = max(leaf, n // (2 * workers.threads))
    pending, ready = [(0, n, 63, False)], []
    while pending:
        a, b, h, in_buf = pending.pop()  # h: the highest bit that may vary
        if b - a <= share or h < 0:  # h < 0: all keys equal (nothing to split)
            ready.append((a, b, h, in_buf))
        else:
            pending += _split_parallel(keys, perm, key_buf, perm_buf, a, b, in_buf, workers)
    # largest first, each to the least loaded of 4 batches per thread
    ready.sort(key=lambda r: r[0] - r[1])
    batches = [[] for _ in range(min(len(ready), 4 * workers.threads))]
    load = [0] * len(batches)
    for r in ready:
        k = load.index(min(load))
        batches[k].append(r)
        load[k] += r[1] - r[0]

    def run(c, lo, hi):
        rows = np.array(batches[c], dtype=np.int64).reshape(-1, 4)
        msd_sort_ranges(keys, perm, key_buf, perm_buf, rows, leaf)

    workers.map([(0, 0)] * len(batches), run)
    return keys, perm


def _split_parallel(keys, perm, key_buf, perm_buf, a, b, in_buf, workers):
    """Split range [a, b) (in the scratch when ``in_buf``) into buckets by
    the 8 bits from its highest varying one down (msd_sort_range), in
    parallel over chunks of the range, into the other array; returns the
    buckets as (lo, hi, highest bit that may vary, in_buf)."""
    src_k, src_p, dst_k, dst_p = ((key_buf, perm_buf, keys, perm) if in_buf else
                                  (keys, perm, key_buf, perm_buf))
    chunks = [(a + lo, a + hi) for lo, hi in workers.chunks(b - a)]
    h = max(workers.map(chunks, lambda c, lo, hi: top_bit(src_k, src_k[a], lo, hi)))
    if h < 0:  # all keys equal: in order (msd_sort_range moves it back from the scratch)
        return [(a, b, -1, in_buf)]
    shift = digit_shift(h)
    per_chunk = np.stack(workers.map(chunks, lambda c, lo, hi: _digit_chunk(src_k, lo, hi, shift)))
    # chunk c writes bucket b after every smaller bucket and after the same
    # bucket of chunks before it: stable
    totals = per_chunk.sum(axis=0)
    starts = a + np.concatenate(([0], np.cumsum(totals)[:-1]))
    offsets = starts + np.cumsum(per_chunk, axis=0) - per_chunk
    workers.map(chunks, lambda c, lo, hi: scatter(src_k, src_p, dst_k, dst_p, lo, hi, shift,
                                                  offsets[c].copy()))
    return [(int(s0), int(s0 + t), shift - 1, not in_buf) for s0, t in zip(starts, totals) if t]


@njit(cache=True, nogil=True)
def top_bit(keys, first, lo, hi):
    """Highest bit in which a key of keys[lo:hi] differs from ``first``, or
    -1."""
    diff = np.uint64(0)
    for i in range(lo, hi):
        diff |= keys[u(i)] ^ first
    if diff == 0:
        return -1
    return 63 - leading_zeros(diff)


@njit(cache=True, inline="always")
def digit_shift(top):
    """The shift of the MSD digit whose highest bit is ``top`` (>= 0): the 8
    bits from it down, fewer at the bottom of the key."""
    return max(top - 7, 0)


@njit(cache=True, nogil=True)
def msd_sort_ranges(keys, perm, key_buf, perm_buf, rows, leaf):
    """msd_sort_range of each row (lo, hi, bit, in_buf) of ``rows``."""
    for r in range(rows.shape[0]):
        msd_sort_range(keys, perm, rows[r, 0], rows[r, 1], key_buf, perm_buf, rows[r, 2],
                       rows[r, 3] != 0, leaf)


@njit(cache=True, nogil=True)
def msd_sort_range(keys, perm, lo, hi, key_buf, perm_buf, bit, in_buf, leaf):
    """Stable sort of range [lo, hi), whose keys agree above ``bit``, into
    keys/perm; the range starts in key_buf/perm_buf when ``in_buf``.

    A range of more than ``leaf`` keys is counted by the 8 bits from its
    highest varying bit h down and scattered by them into the other array,
    where each bucket, whose keys agree above h - 8, is sorted the same way;
    a range of at most ``leaf`` keys is sorted by LSD (radix_passes) and
    copied back to keys/perm if it ends in the scratch::

        keys [ a . . . . . . . . . b )   split by bits h ... h-7
        buf  [ 0 0 0 | 1 1 | ... | ff )  buckets, each split below h-7
        keys [ . . . )                   ... until LSD in cache
    """
    s_lo = np.empty(_MSD_STACK, dtype=np.int64)
    s_hi = np.empty(_MSD_STACK, dtype=np.int64)
    s_bit = np.empty(_MSD_STACK, dtype=np.int64)
    s_buf = np.empty(_MSD_STACK, dtype=np.bool_)
    counts = np.empty(256, dtype=np.int64)
    offsets = np.empty(256, dtype=np.int64)
    top = 0
    s_lo[0], s_hi[0], s_bit[0], s_buf[0] = lo, hi, bit, in_buf
    while top >= 0:
        a, b, h, here = s_lo[top], s_hi[top], s_bit[top], s_buf[top]
        top -= 1
        src_k, src_p, dst_k, dst_p = keys, perm, key_buf, perm_buf
        if here:
            src_k, src_p, dst_k, dst_p = key_buf, perm_buf, keys, perm
        if b - a > leaf:
            # the highest bit that varies (-1: all keys equal), found by
            # top_bit's one cheap pass, not by counting the constant digits
            # (sign and exponent: docs/performance.md, "top bit")
            h = min(h, top_bit(src_k, src_k[u(a)], a, b))
            if h >= 0:
                shift = digit_shift(h)
                digit_counts(src_k, a, b, shift, counts)
                start = a
                for k in range(256):
                    offsets[k] = start
                    if counts[k]:
                        top += 1
                        s_lo[top], s_hi[top], s_bit[top] = start, start + counts[k], shift - 1
                        s_buf[top] = not here
                    start += counts[k]
                scatter(src_k, src_p, dst_k, dst_p, a, b, shift, offsets)
                continue
            passes = 0  # all keys equal: in order
        else:
            # digits above h's agree: not counted (a leaf of 1M uniform keys
            # has three constant digits, each a chain of increments on one
            # counter)
            passes = leaf_passes(src_k, src_p, a, b, dst_k, dst_p, h // 8 + 1)
        if here != (passes % 2 == 1):  # the sorted range is in the scratch
            for i in range(a, b):
                keys[u(i)] = key_buf[u(i)]
                perm[u(i)] = perm_buf[u(i)]


def _digit_chunk(keys, lo, hi, shift):
    counts = np.empty(256, dtype=np.int64)
    digit_counts(keys, lo, hi, shift, counts)
    return counts


@njit(cache=True, nogil=True)
def _sort_run(slo, perm, a, b):
    """Stable sort of slo[a:b] carrying perm: insertion sort for a short run,
    radix sort with scratch of the run's own size for a long one."""
    if b - a > _INSERTION_RUN:
        radix_sort_range(slo[a:b], perm[a:b], 0, b - a, np.empty(b - a, dtype=np.uint64),
                         np.empty(b - a, dtype=perm.dtype))
        return
    insertion_sort(slo, perm, a, b, _INSERTION_RUN * _INSERTION_RUN)


@njit(cache=True, nogil=True)
def order_runs(shi, src, perm, slo, lo, hi):
    """Each run of equal high words ``shi`` that starts in [lo, hi) (it may
    end past hi; one that starts before lo is its chunk's): gather its low
    words, slo[i] = low word perm[i] of ``src`` (the low words, or the
    points' bits: lfqt.morton.low_word), and sort them stably, carrying
    perm.  The positions outside runs are not written."""
    n = shi.shape[0]
    i = lo
    while 0 < i < hi and shi[u(i)] == shi[u(i - 1)]:
        i += 1
    while i < hi:
        k = shi[u(i)]
        end = i + 1
        while end < n and shi[u(end)] == k:
            end += 1
        if end - i > 1:
            for j in range(i, end):
                slo[u(j)] = low_word(src, perm[u(j)])
            _sort_run(slo, perm, i, end)
        i = end


def sort_keys128(hi, lo, perm, workers, scratch=None, slo=None):
    """Stable sort of 128-bit keys given as (hi, lo) uint64 arrays carrying
    ``perm``: radix on ``hi`` over ``workers`` (through ``scratch``, as
    sort_keys), then each run of equal ``hi`` ordered by ``lo`` into ``slo``
    (default: a new array).  ``lo`` may instead be the (n, 2) uint64 bits
    of the float64 points whose Morton keys these are, for the low words
    to be computed where they are needed (order_runs).  Returns (sorted_hi,
    sorted_lo, perm); ``hi`` and ``perm`` are sorted in place.

    A low word only ever tells apart keys whose high words are equal, so
    sorted_lo is written inside runs of equal high words alone (elsewhere it
    holds garbage, which its readers never look at: lfqt.dc.subdivide).  On
    float64 input runs are rare, so this saves a random gather of 8 bytes
    per point, and the untouched pages."""
    shi, perm = sort_keys(hi, perm, workers, scratch=scratch)
    slo = np.empty(len(lo), dtype=np.uint64) if slo is None else slo
    workers.map(workers.chunks(len(lo)), lambda c, a, b: order_runs(shi, lo, perm, slo, a, b))
    return shi, slo, perm
