import numpy as np
from numba import njit

from hypothesis import given
from hypothesis import strategies as st

from lfqt.indexing import borrow, popcount, u


@njit(cache=True)
def _apply(values):
    out_u = np.empty(values.shape[0], dtype=np.uint64)
    for i in range(values.shape[0]):
        out_u[i] = u(values[i])
    return out_u


def test_unsigned_index_matches_python():
    values = np.array([0, 1, 2, 3, 4, 5, 6, 2 ** 31 - 1, 2 ** 31, 3 * 2 ** 40 + 2, 2 ** 62 + 1],
                      dtype=np.int64)
    assert _apply(values).tolist() == [int(v) for v in values]


@njit(cache=True)
def _popcounts(values):
    out = np.empty(values.shape[0], dtype=np.int64)
    for i in range(values.shape[0]):
        out[i] = popcount(values[i])
    return out


@given(st.lists(st.integers(0, 2 ** 64 - 1), max_size=50))
def test_popcount_counts_set_bits(values):
    got = _popcounts(np.array(values, dtype=np.uint64))
    assert got.tolist() == [bin(v).count("1") for v in values]


@njit(cache=True)
def _through_borrowed(a):
    v = borrow(a)
    v[1, 0] = 7.0  # writes land in a
    return v.shape[0], v.shape[1], v[2, 1], v.sum()


def test_borrowed_view_is_the_same_array():
    a = np.arange(12.0).reshape(6, 2)
    rows, cols, x, total = _through_borrowed(a)
    assert (rows, cols, x) == (6, 2, 5.0)
    assert a[1, 0] == 7.0 and total == a.sum()
