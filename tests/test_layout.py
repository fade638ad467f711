"""The half-edge encoding of lfqt.dc.layout against a plain Python model:
half-edge 4t + i of triangle t runs from vertex i to vertex i + 1, its
vertex at T[6t + i] and its twin at T[6t + 3 + i]."""
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from numba import njit

from lfqt.dc.layout import (before, edge, less, link, link_edges, nxt, origin, prv, t_dtype,
                             tri, twin)


@njit(cache=True)
def _decode(es):
    out = np.empty((es.shape[0], 5), dtype=np.int64)
    for k in range(es.shape[0]):
        e = es[k]
        out[k, 0] = tri(e)
        out[k, 1] = nxt(e)
        out[k, 2] = prv(e)
        out[k, 3] = origin(e)
        out[k, 4] = twin(e)
    return out


@njit(cache=True)
def _link(T, t, i, w, j, raw):
    if raw:
        link(T, t, i, edge(w, j))
    else:
        link_edges(T, t, i, w, j)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.integers(0, 2 ** 40), st.integers(0, 2)), min_size=1, max_size=50))
def test_helpers_match_the_model(pairs):
    es = np.array([4 * t + i for t, i in pairs], dtype=np.int64)
    got = _decode(es)
    for (t, i), row in zip(pairs, got):
        assert row[0] == t
        assert row[1] == 4 * t + (i + 1) % 3
        assert row[2] == 4 * t + (i + 2) % 3
        assert row[3] == 6 * t + i
        assert row[4] == 6 * t + 3 + i


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 7), st.integers(0, 2), st.integers(0, 7), st.integers(0, 2), st.booleans())
def test_link_writes_both_twins(t, i, w, j, raw):
    T = np.full(6 * 8, -9, dtype=np.int32)
    _link(T, t, i, w, j, raw)
    assert T[6 * w + 3 + j] == 4 * t + i
    assert T[6 * t + 3 + i] == 4 * w + j
    touched = {6 * t + 3 + i, 6 * w + 3 + j}
    assert all(T[k] == -9 for k in range(len(T)) if k not in touched)


def test_t_dtype_holds_the_largest_half_edge_id():
    for n in (3, 10 ** 6, 2 ** 28 - 2, 2 ** 28, 2 ** 31):
        largest = 4 * (2 * (n - 1) - 1) + 2
        assert np.iinfo(t_dtype(n)).max >= largest
    assert t_dtype(10 ** 6) == np.int32  # small inputs keep the compact layout


_coordinate = st.sampled_from([-1.0, -0.0, 0.0, 0.5, 1.0])


@given(st.tuples(_coordinate, _coordinate), st.tuples(_coordinate, _coordinate),
       st.sampled_from([0, 1]))
def test_before_is_less_on_vertices(a, b, axis):
    # few values, so that ties on either coordinate (and -0.0 against 0.0) come up
    P = np.array([a, b])
    assert before(P, 0, 1, axis) == less(a[0], a[1], b[0], b[1], axis)
    assert before(P, 1, 0, axis) == less(b[0], b[1], a[0], a[1], axis)
