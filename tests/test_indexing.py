import numpy as np
from numba import njit

from lfqt.indexing import u


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
