import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from numba import njit

from lfqt.indexing import bit, borrow, iota, popcount, prefetch, rank, stack_array, u


@njit(cache=True)
def _apply(values):
    """u and popcount of each value."""
    out_u = np.empty(values.shape[0], dtype=np.uint64)
    out_pop = np.empty(values.shape[0], dtype=np.int64)
    for i in range(values.shape[0]):
        out_u[i] = u(values[i])
        out_pop[i] = popcount(np.uint64(values[i]))
    return out_u, out_pop


def test_unsigned_index_matches_python():
    values = np.array([0, 1, 2, 3, 4, 5, 6, 2 ** 31 - 1, 2 ** 31, 3 * 2 ** 40 + 2, 2 ** 62 + 1],
                      dtype=np.int64)
    assert _apply(values)[0].tolist() == [int(v) for v in values]


@given(st.lists(st.integers(0, 2 ** 63 - 1), max_size=50))
def test_popcount_counts_set_bits(values):
    got = _apply(np.array(values, dtype=np.int64))[1]
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


@njit(cache=True)
def _bits_and_ranks(bits, first, n):
    out_bit = np.empty(n, dtype=np.int64)
    out_rank = np.empty(n, dtype=np.int64)
    for t in range(n):
        out_bit[t] = bit(bits, t)
        out_rank[t] = rank(bits, first, t)
    return out_bit, out_rank


@given(st.lists(st.booleans(), min_size=1, max_size=300))
def test_rank_counts_the_set_bits_before(flags):
    flags = np.array(flags)
    padded = np.zeros(-(-len(flags) // 64) * 64, dtype=bool)
    padded[:len(flags)] = flags
    bits = np.packbits(padded.reshape(-1, 64)[:, ::-1], axis=1).view(">u8").ravel().astype(np.uint64)
    first = np.concatenate([[0], np.cumsum(padded.reshape(-1, 64).sum(axis=1))[:-1]])
    got_bit, got_rank = _bits_and_ranks(bits, first.astype(np.int64), len(flags))
    assert got_bit.tolist() == flags.astype(int).tolist()
    assert got_rank.tolist() == (np.cumsum(flags) - flags).tolist()


@njit(cache=True)
def _sum_first(a, k):
    total = 0.0
    for i in range(k):
        total += a[i]
    return total


@njit(cache=True)
def _through_stack(values):
    work = stack_array(16)
    for i in range(values.shape[0]):
        work[i] = values[i]
    return work.shape[0], _sum_first(work, values.shape[0]), work[values.shape[0] - 1]


@given(st.lists(st.floats(-1e6, 1e6), min_size=1, max_size=16))
def test_stack_array_holds_what_is_written_and_passes_down(values):
    size, total, last = _through_stack(np.array(values))
    assert size == 16 and last == values[-1]
    assert total == _sum_first(np.array(values), len(values))


def test_prefetch_is_a_hint_that_never_faults():
    @njit  # not cached: the assembly of a cached kernel cannot be inspected
    def touch(A, i):
        prefetch(A, i)
        return A[0, 0]

    A = np.arange(12, dtype=np.int32).reshape(4, 3)
    for i in (0, 3, 1 << 40, -(1 << 40)):  # far outside: still no fault
        assert touch(A, i) == 0
    assert "prefetch" in touch.inspect_asm(touch.signatures[0])


@given(st.integers(0, 200), st.integers(0, 200))
def test_iota_writes_the_identity_over_its_range(lo, hi):
    out = np.full(220, -1, dtype=np.int64)
    iota(out, lo, hi)
    want = np.full(220, -1, dtype=np.int64)
    want[lo:hi] = np.arange(lo, max(lo, hi))
    assert np.array_equal(out, want)
