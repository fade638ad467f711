"""pytest-benchmark micro-benchmarks (not part of the test suite):

    .venv/bin/python -m pytest micro_benchmarks --benchmark-only
"""
import numpy as np
import pytest
from numba import njit

from lfqt import morton, predicates as P, radix
from lfqt.workers import Workers

N = 100_000


@njit
def _orient_loop(pts, bound):
    s = 0.0
    for k in range(pts.shape[0] - 2):
        v, st = P.orient2d_staged(pts[k, 0], pts[k, 1], pts[k + 1, 0], pts[k + 1, 1],
                                  pts[k + 2, 0], pts[k + 2, 1], bound)
        s += v > 0
    return s


@njit
def _incircle_loop(pts, bound):
    s = 0.0
    for k in range(pts.shape[0] - 3):
        v, st = P.incircle_staged(pts[k, 0], pts[k, 1], pts[k + 1, 0], pts[k + 1, 1],
                                  pts[k + 2, 0], pts[k + 2, 1], pts[k + 3, 0], pts[k + 3, 1], bound)
        s += v > 0
    return s


@pytest.fixture(scope="module")
def pts():
    return np.random.default_rng(0).random((N, 2))


@pytest.fixture(scope="module")
def grid_pts():
    g = np.stack(np.meshgrid(np.arange(317), np.arange(317)), -1).reshape(-1, 2).astype(float)
    return g[:N]


def test_orient2d_random(benchmark, pts):
    _orient_loop(pts[:10], P.CCW_A)
    benchmark(_orient_loop, pts, P.CCW_A)


def test_incircle_random(benchmark, pts):
    _incircle_loop(pts[:10], P.ICC_A)
    benchmark(_incircle_loop, pts, P.ICC_A)


def test_incircle_grid_exact_path(benchmark, grid_pts):
    _incircle_loop(grid_pts[:10], P.ICC_A)
    benchmark(_incircle_loop, grid_pts, P.ICC_A)


def test_morton_keys_128bit(benchmark, pts):
    x, y = np.ascontiguousarray(pts[:, 0]), np.ascontiguousarray(pts[:, 1])
    morton.morton_keys64(x[:10], y[:10])
    benchmark(morton.morton_keys64, x, y)


def test_radix_sort_64bit(benchmark, pts):
    keys = morton.morton_keys32(pts[:, 0].astype(np.float32), pts[:, 1].astype(np.float32))
    w = Workers(1)
    radix.sort_keys(keys[:10].copy(), np.arange(10, dtype=np.int32), w)
    benchmark(lambda: radix.sort_keys(keys.copy(), np.arange(N, dtype=np.int32), w))
