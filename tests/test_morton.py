import numpy as np
from hypothesis import given, settings, strategies as st

from lfqt import _input, morton

f64 = st.floats(allow_nan=False)
f32 = st.floats(allow_nan=False, width=32)


def ordered64(v):
    return int(morton.ordered_bits64(np.array([v]).view(np.uint64)[0]))


def ordered32(v):
    return int(morton.ordered_bits32(np.array([v], dtype=np.float32).view(np.uint32)[0]))


@given(f64, f64)
def test_float64_bits_preserve_order(a, b):
    assert (a < b) == (ordered64(a) < ordered64(b))
    assert (a == b) == (ordered64(a) == ordered64(b))


@given(f32, f32)
def test_float32_bits_preserve_order(a, b):
    assert (a < b) == (ordered32(a) < ordered32(b))
    assert (a == b) == (ordered32(a) == ordered32(b))


def test_negative_zero_folds_into_positive_zero():
    assert ordered64(-0.0) == ordered64(0.0) == 1 << 63
    assert ordered32(-0.0) == ordered32(0.0) == 1 << 31


def reference_interleave(x, y, bits):
    key = 0
    for k in range(bits):
        key |= ((x >> k) & 1) << (2 * k + 1)
        key |= ((y >> k) & 1) << (2 * k)
    return key


@given(st.integers(0, 2 ** 32 - 1), st.integers(0, 2 ** 32 - 1))
def test_interleave_puts_x_on_odd_bits(x, y):
    got = int(morton.interleave(np.uint64(x), np.uint64(y)))
    assert got == reference_interleave(x, y, 32)


@given(st.lists(st.tuples(f64, f64), min_size=1, max_size=20))
def test_128bit_keys_are_interleaved_ordered_bits(pts):
    x = np.array([p[0] for p in pts])
    y = np.array([p[1] for p in pts])
    hi, lo = morton.morton_keys64(x, y)
    for i in range(len(pts)):
        expect = reference_interleave(ordered64(x[i]), ordered64(y[i]), 64)
        assert (int(hi[i]) << 64) | int(lo[i]) == expect


def test_float32_keys_split_quadrants_by_sign():
    x = np.array([-1, 1, -1, 1], dtype=np.float32)
    y = np.array([-1, -1, 1, 1], dtype=np.float32)
    keys = morton.morton_keys32(x, y)
    # x sign is the top bit, y sign the next: (-,-) < (-,+) < (+,-) < (+,+)
    assert list(np.argsort(keys)) == [0, 2, 1, 3]


@given(st.lists(st.floats(allow_nan=False, width=32), min_size=1, max_size=50))
def test_numpy_ordered_bits_match_the_kernels_and_invert(values):
    from lfqt.morton import from_ordered_bits, ordered_bits, ordered_bits32, ordered_bits64
    for dtype, kernel, u in ((np.float32, ordered_bits32, np.uint32),
                             (np.float64, ordered_bits64, np.uint64)):
        v = np.array(values, dtype=dtype)
        b = ordered_bits(v)
        assert b.dtype == u
        assert [int(x) for x in b] == [int(kernel(u(x))) for x in v.view(u)]
        assert np.array_equal(from_ordered_bits(b, dtype), v + dtype(0.0))  # -0.0 as +0.0
        assert list(np.argsort(b, kind="stable")) == list(np.argsort(v, kind="stable"))


@settings(deadline=None)
@given(st.lists(st.floats(width=32) | st.sampled_from([0.0, -0.0, 5e-324]), min_size=2,
                max_size=2 * (morton.SCAN_BLOCK + 40)),
       st.sampled_from([np.float32, np.float64]), st.data())
def test_the_pipeline_keys_pass_scans_the_input_and_starts_the_permutation(values, dtype, data):
    """Over any range, the keys' pass of lfqt.dc gives the keys, perm[i] = i
    and the input's bit scan (_input._scan_bits), across SCAN_BLOCK blocks,
    with NaN, inf, zeros and subnormals."""
    with np.errstate(under="ignore"):
        pts = np.array(values[: len(values) // 2 * 2], dtype=dtype).reshape(-1, 2)
    n = len(pts)
    lo = data.draw(st.integers(0, n))
    hi = data.draw(st.integers(lo, n))
    keys, perm = np.zeros(n, np.uint64), np.full(n, -1, np.int32)
    ints, mask, inf = _input.BITS[pts.dtype]
    if dtype == np.float64:
        scan = morton.morton_high64_into(pts.view(np.uint64), keys, perm, lo, hi)
        want = morton.morton_keys64(pts[:, 0], pts[:, 1])[0]
    else:
        scan = morton.morton_keys32_into(pts.view(np.uint32), keys, perm, lo, hi)
        want = morton.morton_keys32(pts[:, 0], pts[:, 1])
    assert tuple(scan) == _input._scan_bits(pts.reshape(-1).view(ints), 2 * lo, 2 * hi, mask, inf)
    assert np.array_equal(keys[lo:hi], want[lo:hi]) and not keys[:lo].any() and not keys[hi:].any()
    assert np.array_equal(perm[lo:hi], np.arange(lo, hi)) and (perm[:lo] == -1).all()
    assert (perm[hi:] == -1).all()
