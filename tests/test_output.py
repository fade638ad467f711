"""The output kernels of the divide and conquer (lfqt.dc.output) that work
apart from a mesh: the rows' parallel slide and the look for copies."""
import numpy as np
from hypothesis import given, strategies as st

from lfqt.dc import output
from lfqt.workers import Workers


@given(st.integers(0, 3000), st.integers(0, 3000), st.integers(0, 3000), st.integers(1, 4))
def test_parallel_move_equals_a_forward_copy(dst, gap, count, threads):
    # gaps shorter than the count make several pieces, each over the threads
    src = dst + gap
    T = np.arange(src + count + 5, dtype=np.int32)
    want = T.copy()
    want[dst:dst + count] = T[src:src + count].copy()
    with Workers(threads) as w:
        # small chunks, so that every thread count splits a piece
        w.chunks = lambda n, min_chunk=1, _c=w.chunks: _c(n, min_chunk=1)
        output.move_rows_parallel(T, src, dst, count, w)
    assert np.array_equal(T, want)
