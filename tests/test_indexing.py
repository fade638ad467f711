import numpy as np
from numba import njit

from lfqt.indexing import div3, u


@njit(cache=True)
def _apply(values):
    out_u = np.empty(values.shape[0], dtype=np.uint64)
    out_d = np.empty(values.shape[0], dtype=np.int64)
    for i in range(values.shape[0]):
        out_u[i] = u(values[i])
        out_d[i] = div3(values[i])
    return out_u, out_d


def test_unsigned_index_and_division_by_three_match_python():
    values = np.array([0, 1, 2, 3, 4, 5, 6, 2 ** 31 - 1, 2 ** 31, 3 * 2 ** 40 + 2, 2 ** 62 + 1],
                      dtype=np.int64)
    as_u, thirds = _apply(values)
    assert as_u.tolist() == [int(v) for v in values]
    assert thirds.tolist() == [int(v) // 3 for v in values]
