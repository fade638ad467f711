import subprocess
import sys
import textwrap

import numpy as np
import pytest
from hypothesis import given, strategies as st

from lfqt import morton, radix
from lfqt.workers import Workers

WORKERS = [Workers(1), Workers(3)]


def perm32(n):
    return np.arange(n, dtype=np.int32)


@given(st.lists(st.integers(0, 2 ** 64 - 1), max_size=200), st.sampled_from(WORKERS))
def test_sort64_matches_stable_argsort(values, workers):
    keys = np.array(values, dtype=np.uint64)
    sk, perm = radix.sort_keys(keys.copy(), perm32(len(keys)), workers)
    expect = np.argsort(keys, kind="stable")
    assert np.array_equal(perm, expect)
    assert np.array_equal(sk, keys[expect])


@given(st.lists(st.one_of(st.integers(0, 2 ** 64 - 1), st.integers(0, 3),
                          st.integers(0, 3).map(lambda v: v << 40 | 5)), max_size=300),
       st.sampled_from([1, 2, 5]))
def test_msd_down_to_tiny_leaves_matches_stable_argsort(values, leaf):
    # Tiny leaves make every range above a few keys split by its highest
    # varying digit, bucket after bucket, through both arrays.
    keys = np.array(values, dtype=np.uint64)
    sk, perm = radix.sort_keys(keys.copy(), perm32(len(keys)), Workers(1), leaf=leaf)
    expect = np.argsort(keys, kind="stable")
    assert np.array_equal(perm, expect)
    assert np.array_equal(sk, keys[expect])


@given(st.integers(0, 60), st.lists(st.integers(0, 2 ** 12 - 1), min_size=2, max_size=300),
       st.sampled_from([1, 3]), st.sampled_from(WORKERS))
def test_msd_digits_off_byte_boundaries_match_stable_argsort(shift, values, leaf, workers):
    # 12 varying bits at any offset: the MSD digits start at the highest
    # varying bit, mid-byte, and end below a byte boundary.
    keys = np.array(values, dtype=np.uint64) << np.uint64(shift)
    sk, perm = radix.sort_keys(keys.copy(), perm32(len(keys)), workers, leaf=leaf)
    expect = np.argsort(keys, kind="stable")
    assert np.array_equal(perm, expect)
    assert np.array_equal(sk, keys[expect])


@given(st.lists(st.tuples(st.integers(0, 3), st.integers(0, 2 ** 64 - 1)), max_size=300),
       st.sampled_from(WORKERS))
def test_sort128_orders_lexicographically_and_stably(pairs, workers):
    hi = np.array([p[0] for p in pairs], dtype=np.uint64)
    lo = np.array([p[1] for p in pairs], dtype=np.uint64)
    shi, slo, perm = radix.sort_keys128(hi.copy(), lo, perm32(len(hi)), workers)
    full = [(int(h) << 64) | int(l) for h, l in zip(hi, lo)]
    expect = sorted(range(len(full)), key=lambda i: (full[i], i))
    assert list(perm) == expect
    assert np.array_equal(shi, hi[perm])
    # low words are written where they can matter: inside runs of equal high words
    run = np.zeros(len(shi), dtype=bool)
    if len(shi) > 1:
        same = shi[1:] == shi[:-1]
        run[1:] |= same
        run[:-1] |= same
    assert np.array_equal(slo[run], lo[perm][run])


@pytest.mark.parametrize("threads", [1, 2])
def test_low_words_from_the_points_bits_sort_like_the_low_words(rng, threads):
    """sort_keys128 with the float64 points' bits in place of the low words
    (lfqt.morton.low_word) orders like the full 128-bit Morton keys: points
    that share the upper 32 bits of both coordinates form long runs of
    equal high words, told apart by the low words alone."""
    n = 200_000
    base = rng.random((50, 2)) + 1.0
    pts = base[rng.integers(0, 50, n)] + rng.integers(0, 1 << 20, (n, 2)) * 2.0 ** -52
    pts[::7] = pts[3]  # equal keys: stability decides
    x, y = pts[:, 0].copy(), pts[:, 1].copy()
    hi, lo = morton.morton_keys64(x, y)
    with Workers(threads) as w:
        shi, slo, perm = radix.sort_keys128(hi.copy(), pts.view(np.uint64), perm32(n), w)
    expect = np.lexsort((np.arange(n), lo, hi))
    assert np.array_equal(perm, expect)
    run = np.zeros(n, dtype=bool)
    run[1:] |= shi[1:] == shi[:-1]
    run[:-1] |= shi[1:] == shi[:-1]
    assert run.mean() > 0.9 and np.array_equal(slo[run], lo[expect][run])


def test_long_runs_of_equal_high_words_use_radix_and_stay_stable(rng):
    n = 5000
    hi = np.zeros(n, dtype=np.uint64)
    lo = rng.integers(0, 50, n).astype(np.uint64)
    _, slo, perm = radix.sort_keys128(hi, lo, perm32(n), Workers(1))
    assert np.array_equal(perm, np.argsort(lo, kind="stable"))


@pytest.mark.parametrize("threads", [1, 3])
def test_runs_of_equal_high_words_across_chunks_are_ordered_once(rng, threads):
    # Runs of every length, short (insertion sort) and long (radix), many of
    # them crossing the boundaries of the 3 chunks: each run must be sorted
    # by exactly one chunk, the one it starts in.
    n = 3 * (1 << 16) + 17
    lengths = rng.choice([1, 2, 5, 24, 25, 300, 40000], size=n,
                         p=[0.3, 0.25, 0.2, 0.1, 0.1, 0.04, 0.01])
    runs = int(np.searchsorted(np.cumsum(lengths), n)) + 1  # just enough runs for n keys
    hi = np.repeat(np.arange(runs, dtype=np.uint64), lengths[:runs])[:n][rng.permutation(n)]
    lo = rng.integers(0, 2 ** 64, n, dtype=np.uint64)
    lo[::5] = lo[1]  # equal full keys: stability decides
    with Workers(threads) as w:
        assert len(w.chunks(n)) == threads
        shi, slo, perm = radix.sort_keys128(hi.copy(), lo, perm32(n), w)
    expect = np.lexsort((np.arange(n), lo, hi))
    assert np.array_equal(perm, expect)
    assert np.array_equal(shi, hi[expect])
    run = np.zeros(n, dtype=bool)
    run[1:] |= shi[1:] == shi[:-1]
    run[:-1] |= shi[1:] == shi[:-1]
    assert run.sum() > n // 2
    assert np.array_equal(slo[run], lo[expect][run])


def _leaf_sorted(keys):
    """leaf_passes on all 8 digits of keys: (sorted keys, perm, scatters)."""
    n = len(keys)
    k, p = keys.copy(), perm32(n)
    kb, pb = np.empty_like(k), np.empty_like(p)
    passes = radix.leaf_passes(k, p, 0, n, kb, pb, 8)
    return (kb, pb, passes) if passes % 2 else (k, p, passes)


def test_leaf_sorts_by_its_top_digits_then_by_insertion(rng):
    # Random keys: two top digits (65536 prefixes for 4000 keys) leave a
    # few ties, which the insertion sort orders; copies test stability.
    keys = rng.integers(0, 2 ** 64, 4000, dtype=np.uint64)
    keys[::9] = keys[5]
    sk, perm, passes = _leaf_sorted(keys)
    assert passes == 2
    assert np.array_equal(perm, np.argsort(keys, kind="stable"))
    assert np.array_equal(sk, keys[perm])


def test_leaf_falls_back_to_every_digit_when_its_top_digits_correlate(rng):
    # The two top digits are equal: 256 values each, 256 prefixes in all,
    # about 16 keys a prefix, too many ties for the insertion sort's budget.
    n = 4000
    top = rng.integers(0, 256, n, dtype=np.uint64)
    keys = (top << np.uint64(56)) | (top << np.uint64(48)) | rng.integers(
        0, 2 ** 48, n, dtype=np.uint64)
    keys[::7] = keys[2]
    sk, perm, passes = _leaf_sorted(keys)
    assert passes > 2 + 6  # the two top digits, then all eight again
    assert np.array_equal(perm, np.argsort(keys, kind="stable"))
    assert np.array_equal(sk, keys[perm])


@given(st.lists(st.integers(0, 2 ** 64 - 1), max_size=60), st.integers(-1, 200))
def test_insertion_sort_keeps_its_keys_and_their_order_when_it_gives_up(values, budget):
    keys = np.array(values, dtype=np.uint64)
    k, p = keys.copy(), perm32(len(keys))
    done = radix.insertion_sort(k, p, 0, len(keys), budget)
    assert np.array_equal(k, keys[p])  # every key with its id
    if done:
        assert np.array_equal(p, np.argsort(keys, kind="stable"))
    for v in np.unique(keys):  # equal keys in their input order
        ids = p[k == v]
        assert np.all(np.diff(ids) > 0)


def test_constant_digits_are_skipped():
    keys = (np.arange(1000, dtype=np.uint64) << np.uint64(8)) | np.uint64(0xAB)
    keys = keys[::-1].copy()
    sorted_keys, perm = keys.copy(), np.arange(1000, dtype=np.int32)
    passes = radix.radix_sort_range(sorted_keys, perm, 0, 1000, np.empty_like(keys),
                                    np.empty_like(perm))
    assert passes == 2  # only digits 1 and 2 vary
    assert np.all(np.diff(sorted_keys.astype(np.float64)) > 0)


@given(st.lists(st.one_of(st.integers(0, 2 ** 64 - 1), st.just(0x0102030405060708)), max_size=50),
       st.integers(0, 7), st.integers(0, 3))
def test_digit_counts_equal_a_bincount_of_the_digit(values, digit, lo):
    # any length, so that the four partial histograms end on every remainder
    keys = np.array(values, dtype=np.uint64)
    lo = min(lo, len(keys))
    counts = np.full(256, -1, dtype=np.int64)
    radix.digit_counts(keys, lo, len(keys), 8 * digit, counts)
    want = np.bincount((keys[lo:] >> np.uint64(8 * digit)) & np.uint64(0xFF), minlength=256)
    assert np.array_equal(counts, want)


def test_chunked_sort_is_stable_across_chunks(rng):
    n = 3 * (1 << 16) + 17  # several chunks on 3 workers
    keys = (rng.integers(0, 300, n).astype(np.uint64) << np.uint64(40)) | np.uint64(7)
    with Workers(3) as w:
        assert len(w.chunks(n)) == 3
        sk, perm = radix.sort_keys(keys.copy(), perm32(n), w)
    assert np.array_equal(perm, np.argsort(keys, kind="stable"))
    assert np.array_equal(sk, keys[perm])


def test_parallel_splits_and_batches_are_stable(rng):
    # Long enough for the parallel path; a small leaf and skewed keys (one
    # digit value holds most keys, as the exponent bits of uniform floats do)
    # make it split the large bucket again before the threads take batches.
    n = 3 * (1 << 16) + 17
    keys = rng.integers(0, 2 ** 64, n, dtype=np.uint64)
    keys[: n // 2] &= np.uint64(0x00FF_FFFF_FFFF_FFFF)
    keys[::7] = keys[3]  # runs of equal keys across every chunk
    for leaf in (64, radix.MSD_LEAF):
        with Workers(3) as w:
            sk, perm = radix.sort_keys(keys.copy(), perm32(n), w, leaf=leaf)
        assert np.array_equal(perm, np.argsort(keys, kind="stable"))
        assert np.array_equal(sk, keys[perm])


def test_parallel_sort_of_equal_keys_ends():
    # A range above a thread's share whose keys are all equal has no digit to
    # split by: it must go to the threads as it is, not be split again (which
    # looped forever).  In a child process, so that a hang fails the test.
    code = textwrap.dedent("""
        import numpy as np
        from lfqt import radix
        from lfqt.workers import Workers
        n = 3 * (1 << 16) + 17
        for keys in (np.full(n, 5, dtype=np.uint64),
                     np.r_[np.full(n - 1, 9, dtype=np.uint64), np.uint64(1) << np.uint64(63)]):
            with Workers(2) as w:
                sk, perm = radix.sort_keys(keys.copy(), np.arange(n, dtype=np.int32), w)
            assert np.array_equal(perm, np.argsort(keys, kind="stable"))
            assert np.array_equal(sk, keys[perm])
        print("sorted")
    """)
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0 and proc.stdout.strip() == "sorted", proc.stderr[-2000:]
