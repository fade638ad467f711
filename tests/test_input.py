"""lfqt._input: validation and the exact rescale, over the whole float range.
Inputs that once crashed run in a child process, so that a crash fails the
test instead of killing the test run."""
import math
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from hypothesis import given, strategies as st

from lfqt import _input


@pytest.mark.parametrize("dims,window", [(2, (_input.MAX_EXP, _input.MIN_ULP_EXP)),
                                         (3, (_input.MAX_EXP_3D, _input.MIN_ULP_EXP_3D))])
@pytest.mark.parametrize("e", [-1074, -1066, -1050, -1023, -1000, -300, 0, 300, 1000])
def test_rescale_puts_every_magnitude_in_the_window(dims, window, e):
    """Subnormal input included: the smallest scaled magnitude, not its ulp,
    must clear the window's floor (products of degree 5 keep normal tails)."""
    small, big = 2.0 ** e, 4 * 2.0 ** e if e < 1000 else 2.0 ** e
    s = _input.window_exponent(big, small, *window)
    lo, hi = math.ldexp(small, s), math.ldexp(big, s)
    assert 2.0 ** (window[1] + 52) <= lo and hi < 2.0 ** window[0]


def _child(code):
    proc = subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True,
                          text=True, timeout=600)
    assert proc.returncode == 0, f"child died ({proc.returncode}): {proc.stderr[-2000:]}"
    return proc.stdout


def test_all_subnormal_grids_and_integer_sets_verify_in_2d_and_3d():
    """Grids and random integer sets scaled by 2**-1074 to 2**-1000, each
    built and verified, 50 calls in one process (a crash fails the test)."""
    out = _child("""
        import numpy as np, lfqt
        rng = np.random.default_rng(5)
        g2 = np.stack(np.meshgrid(np.arange(8.0), np.arange(8.0)), -1).reshape(-1, 2)
        g3 = np.stack(np.meshgrid(*[np.arange(5.0)] * 3), -1).reshape(-1, 3)
        bad, calls = [], 0
        for e in (-1074, -1070, -1066, -1060, -1050, -1040, -1030, -1022, -1010, -1000):
            sets = [g2, g3, rng.integers(0, 9, (60, 2)).astype(float),
                    rng.integers(0, 9, (60, 3)).astype(float)]
            for pts in sets:
                pts = pts * 2.0 ** e
                builds = [lfqt.insert] + ([lfqt.triangulate] if pts.shape[1] == 2 else [])
                for build in builds:
                    tri = build(pts)
                    calls += 1
                    if not lfqt.verify(pts, tri).ok:
                        bad.append((e, pts.shape, build.__name__))
        print(calls, bad)
    """)
    calls, bad = out.strip().split(" ", 1)
    assert int(calls) >= 50 and bad == "[]", out


def test_masked_arrays_are_refused():
    import lfqt
    pts = np.ma.masked_array(np.random.default_rng(0).random((20, 2)), mask=False)
    pts[3, 0] = np.ma.masked
    for build, error in ((lfqt.triangulate, TypeError), (lfqt.insert, TypeError),
                         (lfqt.Delaunay, ValueError)):  # ValueError: scipy's
        with pytest.raises(error, match="masked"):
            build(pts)


@pytest.mark.parametrize("case", ["float64", "fortran", "float32", "rescaled", "integers"])
@pytest.mark.parametrize("copy", [True, False])
def test_exact_points_shares_the_input_only_when_asked_and_unchanged(case, copy):
    """copy=False hands back the caller's own array when it is already C
    float64 in the window, a new one otherwise; the input is never written,
    and the reported largest magnitude is P's."""
    base = np.random.default_rng(3).random((300, 2)) - 0.5
    arr = {"float64": base, "fortran": np.asfortranarray(base),
           "float32": base.astype(np.float32), "rescaled": base * 2.0 ** -1060,
           "integers": np.round(base * 1000).astype(np.int64)}[case]
    before = arr.copy()
    P, s, largest = _input.exact_points(arr, (2,), copy=copy)
    assert np.array_equal(arr, before)
    assert P.dtype == np.float64 and P.flags.c_contiguous
    assert np.array_equal(P, arr.astype(np.float64) * 2.0 ** s)
    assert largest == np.abs(P).max()
    shared = np.shares_memory(P, arr)
    assert shared == (not copy and case == "float64")
    assert (s != 0) == (case == "rescaled")


_MAGNITUDES = st.one_of(st.just(0.0), st.just(-0.0), st.floats(allow_nan=False,
                                                              allow_infinity=False),
                        st.floats(-1e-300, 1e-300), st.floats(-2e-308, 2e-308))


@given(st.lists(_MAGNITUDES, min_size=0, max_size=60), st.sampled_from([2, 3]),
       st.sampled_from([np.float64, np.float32]), st.booleans())
def test_bit_scan_finds_the_magnitudes_of_the_row_scan(values, d, dtype, strided):
    """The extremes from the bit patterns (C-contiguous arrays) are the row
    scan's, zeros, signed zeros, subnormals and float32 included."""
    with np.errstate(over="ignore", under="ignore"):
        arr = np.array(values[: len(values) // d * d], dtype=np.float64).astype(dtype)
    arr = np.nan_to_num(arr, posinf=1.0, neginf=-1.0).reshape(-1, d)  # float32 overflow
    if strided:
        arr = np.repeat(arr, 2, axis=0)[::2]
    assert arr.flags.c_contiguous != strided or len(arr) <= 1
    _, _, big, small = _input._scan(arr, 0, len(arr))
    assert _input._checked_magnitudes(arr) == (big, small)


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_bit_scan_hands_nan_and_inf_to_the_row_report(dtype, bad):
    arr = np.ones((7, 2), dtype=dtype)
    arr[4, 1] = arr[6, 0] = bad
    with pytest.raises(ValueError, match="in 2 rows; the first is row 4"):
        _input._checked_magnitudes(arr)
