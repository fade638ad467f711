import numpy as np
from hypothesis import given, strategies as st

from lfqt import radix

idx32 = np.zeros(1, dtype=np.int32)


@given(st.lists(st.integers(0, 2 ** 64 - 1), max_size=200))
def test_sort64_matches_stable_argsort(values):
    keys = np.array(values, dtype=np.uint64)
    sk, perm = radix.sort_keys64(keys, idx32)
    expect = np.argsort(keys, kind="stable")
    assert np.array_equal(perm, expect)
    assert np.array_equal(sk, keys[expect])


@given(st.lists(st.tuples(st.integers(0, 3), st.integers(0, 2 ** 64 - 1)), max_size=300))
def test_sort128_orders_lexicographically_and_stably(pairs):
    hi = np.array([p[0] for p in pairs], dtype=np.uint64)
    lo = np.array([p[1] for p in pairs], dtype=np.uint64)
    shi, slo, perm = radix.sort_keys128(hi, lo, idx32)
    full = [(int(h) << 64) | int(l) for h, l in zip(hi, lo)]
    expect = sorted(range(len(full)), key=lambda i: (full[i], i))
    assert list(perm) == expect
    assert np.array_equal(shi, hi[perm]) and np.array_equal(slo, lo[perm])


def test_long_runs_of_equal_high_words_use_radix_and_stay_stable(rng):
    n = 5000
    hi = np.zeros(n, dtype=np.uint64)
    lo = rng.integers(0, 50, n).astype(np.uint64)
    _, slo, perm = radix.sort_keys128(hi, lo, idx32)
    assert np.array_equal(perm, np.argsort(lo, kind="stable"))


def test_constant_digits_are_skipped():
    keys = (np.arange(1000, dtype=np.uint64) << np.uint64(8)) | np.uint64(0xAB)
    keys = keys[::-1].copy()
    sorted_keys, perm = keys.copy(), np.arange(1000, dtype=np.int32)
    passes = radix.radix_sort_range(sorted_keys, perm, 0, 1000, np.empty_like(keys),
                                    np.empty_like(perm))
    assert passes == 2  # only digits 1 and 2 vary
    assert np.all(np.diff(sorted_keys.astype(np.float64)) > 0)
