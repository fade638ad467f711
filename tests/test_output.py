"""The output kernels of the divide and conquer (lfqt.dc.output) that work
apart from a mesh: the rows written over the slots."""
import numpy as np
from hypothesis import given, strategies as st

from lfqt.dc import output
from lfqt.workers import Workers


@given(st.integers(0, 600), st.integers(0, 7), st.integers(1, 4), st.integers(1, 40),
       st.integers(0, 2 ** 32 - 1))
def test_rows_written_over_the_slots_equal_the_slots_read(m, spare, threads, first, seed):
    """The packed slots become the vertex rows T[0:3m] (input indices) and
    the neighbour rows T[3m:6m] (twins shifted to slots, -1 kept), whatever
    the thread count and the first piece, with the upper half's vertex rows
    in a buffer meanwhile."""
    rng = np.random.default_rng(seed)
    n = m + 3
    T = np.empty(6 * (m + spare), dtype=np.int32)
    slots = T[:6 * m].reshape(m, 6)
    slots[:, :3] = rng.integers(0, n, (m, 3))
    slots[:, 3:] = rng.integers(-1, 4 * m + 1, (m, 3))  # a twin 4t + i, or -1 on the hull
    perm = rng.permutation(n).astype(np.int32)
    want_simplices = perm[slots[:, :3]]
    want_neighbors = slots[:, [4, 5, 3]] >> 2  # opposite vertex 0, 1, 2
    buf = np.full(3 * (m - m // 2), -7, dtype=np.int32)
    with Workers(threads) as w:
        # small chunks, so that every thread count splits a piece
        w.chunks = lambda k, min_chunk=1, _c=w.chunks: _c(k, min_chunk=1)
        assert output.write_rows(T, perm, buf, m, w, first=first)
    assert np.array_equal(T[:3 * m].reshape(m, 3), want_simplices)
    assert np.array_equal(T[3 * m:6 * m].reshape(m, 3), want_neighbors)


def test_a_ghost_among_the_slots_is_refused():
    T = np.zeros(6 * 4, dtype=np.int32)
    T[6 * 3 + 2] = -1  # slot 3 is a ghost (w, v, GHOST)
    with Workers(1) as w:
        assert not output.write_rows(T, np.arange(3, dtype=np.int32),
                                     np.empty(6, dtype=np.int32), 4, w)