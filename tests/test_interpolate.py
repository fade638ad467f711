"""lfqt.interpolate against its definitions and against scipy.interpolate.

Properties (hypothesis) on random points, which are in general position so
that the Delaunay triangulation is unique and scipy's equals ours: affine
data are reproduced, the weights form a partition of unity, and the three
interpolators agree with scipy's to 1e-10.  Then the interface: fill
values, one Delaunay for two fields, complex and shaped values, rescale,
call forms, threads, scipy's error types.  Every lfqt.Delaunay built
while these tests run (by a test, an interpolator or griddata) is verified
exactly as it is built (``_every_mesh_is_verified``)."""
import doctest
import pickle
import threading
import warnings

import numpy as np
import pytest
import scipy.interpolate
import scipy.spatial
from hypothesis import given, settings
from hypothesis import strategies as st

import lfqt
from lfqt import interpolate

SEEDS = st.integers(0, 2 ** 32 - 1)
FAST = settings(max_examples=25, deadline=None)
CLASSES = {"linear": "LinearNDInterpolator", "cubic": "CloughTocher2DInterpolator",
           "nearest": "NearestNDInterpolator"}


VERIFIED = []  # the size of each mesh verified as it was built


@pytest.fixture(scope="module", autouse=True)
def _every_mesh_is_verified():
    """Each lfqt.Delaunay built in the module's tests passes lfqt.verify
    as it is built (its _build wrapped for the module's duration)."""
    build = lfqt.Delaunay._build

    def verified_build(self, arr):
        build(self, arr)
        report = lfqt.verify(self.points, self.triangulation)
        assert report.ok, report.problems
        VERIFIED.append(self.npoints)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(lfqt.Delaunay, "_build", verified_build)
        yield


def _verified(ip):
    """The interpolator, whose mesh was verified as it was built."""
    assert VERIFIED and VERIFIED[-1] == len(ip.tri.points)
    return ip


def test_meshes_are_verified_as_they_are_built(rng):
    before = len(VERIFIED)
    interpolate.griddata(rng.random((30, 2)), np.zeros(30), [0.5, 0.5])
    interpolate.CloughTocher2DInterpolator(rng.random((31, 2)), np.zeros(31))
    assert VERIFIED[before:] == [30, 31]


def _inside(rng, points, m):
    """m random convex combinations of the points, pulled 1% toward their
    centroid: inside their hull whatever the rounding."""
    w = rng.random((m, len(points))) ** 8  # a few points dominate: spread over the hull
    q = (w / w.sum(axis=1, keepdims=True)) @ points
    return 0.99 * q + 0.01 * points.mean(axis=0)


def _same_mesh(ours, theirs):
    return ({tuple(sorted(t)) for t in ours.simplices.tolist()}
            == {tuple(sorted(t)) for t in theirs.simplices.tolist()})


@FAST
@given(seed=SEEDS, n=st.integers(4, 60), dim=st.sampled_from([2, 3]))
def test_affine_data_are_reproduced(seed, n, dim):
    rng = np.random.default_rng(seed)
    points = rng.random((n, dim)) * rng.uniform(0.1, 100, dim) + rng.normal(0, 10, dim)
    a, b = rng.normal(size=dim), rng.normal()
    f = points @ a + b
    q = _inside(rng, points, 40)
    scale = np.abs(points).max() * np.abs(a).sum() + abs(b)
    linear = _verified(interpolate.LinearNDInterpolator(points, f))
    np.testing.assert_allclose(linear(q), q @ a + b, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(linear(points), f, rtol=0, atol=1e-12 * scale)
    assert np.array_equal(interpolate.NearestNDInterpolator(points, f)(points), f)
    if dim == 2:  # the gradient estimate is exact on affine data, so the cubic is affine
        cubic = interpolate.CloughTocher2DInterpolator(linear.tri, f, tol=1e-12)
        np.testing.assert_allclose(cubic(q), q @ a + b, rtol=0, atol=1e-8 * scale)
        np.testing.assert_allclose(cubic(points), f, rtol=0, atol=1e-12 * scale)


@FAST
@given(seed=SEEDS, n=st.integers(4, 40), dim=st.sampled_from([2, 3]))
def test_linear_weights_are_a_partition_of_unity(seed, n, dim):
    """With the identity as n fields, the interpolant's row is the weight
    vector: non-negative, summing to one, on the d+1 vertices of a simplex
    that holds the query, and reproducing the query as their mix."""
    rng = np.random.default_rng(seed)
    points = rng.random((n, dim))
    ip = _verified(interpolate.LinearNDInterpolator(points, np.eye(n)))
    q = _inside(rng, points, 30)
    w = ip(q)
    assert w.shape == (30, n)
    np.testing.assert_allclose(w.sum(axis=1), 1.0, atol=1e-12)
    assert (w > -1e-12).all() and ((np.abs(w) > 1e-12).sum(axis=1) <= dim + 1).all()
    np.testing.assert_allclose(w @ points, q, atol=1e-12)


@FAST
@given(seed=SEEDS, n=st.integers(5, 80))
def test_agrees_with_scipy_where_the_meshes_agree(seed, n):
    rng = np.random.default_rng(seed)
    points = rng.random((n, 2))
    values = np.sin(5 * points[:, 0]) + points[:, 1] ** 2
    tri = lfqt.Delaunay(points)
    assert lfqt.verify(points, tri).ok
    assert _same_mesh(tri, scipy.spatial.Delaunay(points))
    q = np.r_[_inside(rng, points, 50), rng.random((50, 2)) * 3 - 1]  # and far outside
    hull = scipy.spatial.Delaunay(points)
    clear = hull.find_simplex(q) >= 0
    clear |= hull.plane_distance(q).max(axis=1) > 1e-9  # off the hull's rim either way
    for method, name in CLASSES.items():
        ours = getattr(interpolate, name)(tri if method != "nearest" else points, values)(q)
        theirs = getattr(scipy.interpolate, name)(points, values)(q)
        np.testing.assert_allclose(ours[clear], theirs[clear], rtol=0, atol=1e-10,
                                   err_msg=method)
    ours = interpolate.CloughTocher2DInterpolator(tri, values)
    np.testing.assert_allclose(ours.grad, scipy.interpolate.CloughTocher2DInterpolator(
        points, values).grad, rtol=0, atol=1e-10)


@FAST
@given(seed=SEEDS, n=st.integers(5, 60))
def test_agrees_with_scipy_in_3d(seed, n):
    rng = np.random.default_rng(seed)
    points = rng.random((n, 3))
    values = np.cos(3 * points).sum(axis=1)
    ip = _verified(interpolate.LinearNDInterpolator(points, values))
    assert _same_mesh(ip.tri, scipy.spatial.Delaunay(points))
    q = _inside(rng, points, 50)
    np.testing.assert_allclose(ip(q), scipy.interpolate.LinearNDInterpolator(points, values)(q),
                               rtol=0, atol=1e-10)


@pytest.mark.parametrize("name", ["LinearNDInterpolator", "CloughTocher2DInterpolator"])
def test_fill_value_outside_the_hull(name, rng):
    points = rng.random((50, 2))
    outside = np.array([[2.0, 0.5], [-1.0, -1.0], [0.5, np.nan]])
    cls = getattr(interpolate, name)
    assert np.isnan(_verified(cls(points, points[:, 0]))(outside)).all()
    assert (cls(points, points[:, 0], fill_value=-7)(outside) == -7).all()
    got = cls(points, points[:, 0] * 1j, fill_value=-7)(outside)
    assert got.dtype == np.complex128 and (got == -7 + 0j).all()
    assert np.isfinite(cls(points, points[:, 0])(points)).all()  # the vertices are inside


def test_points_computed_on_the_hull_are_inside_as_with_scipy(rng):
    """Points computed on the hull's edges in floating point land about
    half a rounding outside.  scipy's tolerance keeps most of them, and so
    does ours; which few each loses is rounding noise (the coordinates'
    error is the tolerance's size), so the test asks for as few as
    scipy's, the same values where both keep one, and the fill value for
    points 1e-9 outside."""
    points = rng.random((3000, 2))
    values = points[:, 0] * 3 - points[:, 1]
    ip = _verified(interpolate.LinearNDInterpolator(points, values))
    edges = ip.tri.convex_hull
    t = rng.random((len(edges), 100, 1))
    a, b = points[edges[:, 0]][:, None], points[edges[:, 1]][:, None]
    on = (a + t * (b - a)).reshape(-1, 2)
    rounded_out = ip.tri.find_simplex(on) < 0
    assert rounded_out.mean() > 0.2  # the test tests the tolerance
    ours, theirs = ip(on), scipy.interpolate.LinearNDInterpolator(points, values)(on)
    assert np.isnan(ours).sum() <= 2 * np.isnan(theirs).sum() + 2
    assert np.isnan(ours).mean() < 0.2 * rounded_out.mean()  # keeps most: 91% here
    both = np.isfinite(ours) & np.isfinite(theirs)
    np.testing.assert_allclose(ours[both], theirs[both], rtol=0, atol=1e-12)
    normal = np.broadcast_to((b - a)[:, :, ::-1] * [1, -1], t.shape[:2] + (2,)).reshape(-1, 2)
    out = on + 1e-9 * normal / np.linalg.norm(normal, axis=1, keepdims=True)  # ccw hull
    assert np.isnan(ip(out)).all()


def test_one_delaunay_serves_two_fields(rng):
    points = rng.random((300, 2))
    tri = lfqt.Delaunay(points)
    assert lfqt.verify(points, tri).ok
    q = rng.random((100, 2))
    f, g = points[:, 0] ** 2, np.exp(points[:, 1])
    first = interpolate.LinearNDInterpolator(tri, f)
    second = interpolate.CloughTocher2DInterpolator(tri, g)
    assert first.tri is tri and second.tri is tri
    np.testing.assert_array_equal(first(q), interpolate.LinearNDInterpolator(points, f)(q))
    np.testing.assert_array_equal(second(q), interpolate.CloughTocher2DInterpolator(points, g)(q))
    near = interpolate.NearestNDInterpolator(tri, f)
    np.testing.assert_array_equal(near(q), interpolate.NearestNDInterpolator(points, f)(q))


def test_a_scipy_delaunay_is_taken_as_its_points(rng):
    points = rng.random((100, 2))
    theirs = scipy.spatial.Delaunay(points)
    ip = _verified(interpolate.LinearNDInterpolator(theirs, points[:, 1]))
    assert isinstance(ip.tri, lfqt.Delaunay) and _same_mesh(ip.tri, theirs)
    q = _inside(rng, points, 20)
    np.testing.assert_allclose(ip(q), q[:, 1], atol=1e-14)
    with pytest.raises(ValueError, match="Rescaling is not supported"):
        interpolate.CloughTocher2DInterpolator(theirs, points[:, 1], rescale=True)


@pytest.mark.parametrize("name", ["LinearNDInterpolator", "CloughTocher2DInterpolator"])
def test_complex_and_shaped_values(name, rng):
    points = rng.random((80, 2))
    re, im = rng.random((80, 2, 3)), rng.random((80, 2, 3))
    cls = getattr(interpolate, name)
    q = rng.random((7, 5, 2))
    got = _verified(cls(points, re + 1j * im))(q)
    assert got.shape == (7, 5, 2, 3) and got.dtype == np.complex128
    tri = lfqt.Delaunay(points)
    np.testing.assert_allclose(got.real, cls(tri, re)(q), rtol=0, atol=1e-14, equal_nan=True)
    inside = np.isfinite(got.real)
    assert 0 < inside.mean() < 1 and (got.imag[~inside] == 0).all()  # scipy's fill: nan + 0j
    np.testing.assert_allclose(got.imag[inside], cls(tri, im)(q)[inside], rtol=0, atol=1e-14)
    theirs = getattr(scipy.interpolate, name)(points, re + 1j * im)(q)
    np.testing.assert_allclose(got, theirs, rtol=0, atol=1e-10, equal_nan=True)


@pytest.mark.parametrize("method", ["linear", "cubic", "nearest"])
def test_rescale_is_the_unit_cube(method, rng):
    """rescale=True equals interpolating the points and the queries mapped
    by hand to the unit cube around their mean, and scipy's rescale."""
    points = rng.random((200, 2)) * [1.0, 1e6] + [5.0, -3e5]
    values = np.sin(points[:, 0] * 3) + points[:, 1] * 1e-6
    q = rng.random((60, 2)) * [1.0, 1e6] + [5.0, -3e5]
    offset, scale = points.mean(axis=0), np.ptp(points, axis=0)
    by_hand = interpolate.griddata((points - offset) / scale, values, (q - offset) / scale,
                                   method=method)
    got = interpolate.griddata(points, values, q, method=method, rescale=True)
    np.testing.assert_array_equal(got, by_hand)
    theirs = scipy.interpolate.griddata(points, values, q, method=method, rescale=True)
    np.testing.assert_allclose(got, theirs, rtol=0, atol=1e-10, equal_nan=True)
    if method != "nearest":
        with pytest.raises(ValueError, match="Rescaling is not supported"):
            interpolate.LinearNDInterpolator(lfqt.Delaunay(points), values, rescale=True)


def test_call_forms_match_scipy(rng):
    points = rng.random((40, 2))
    values = points[:, 0] - points[:, 1]
    X, Y = np.meshgrid(np.linspace(0.1, 0.9, 7), np.linspace(0.2, 0.8, 5))
    for name in CLASSES.values():
        ours = getattr(interpolate, name)(points, values)
        theirs = getattr(scipy.interpolate, name)(points, values)
        for args in [(np.stack((X, Y), axis=-1),), ((X, Y),), (X, Y), (X, 0.5), (0.3, 0.4),
                     ([0.3, 0.4],), ((points[:, 0], points[:, 1]),)]:
            got, want = ours(*args), theirs(*args)
            assert got.shape == want.shape, (name, args)
            np.testing.assert_allclose(got, want, rtol=0, atol=1e-10, equal_nan=True)


def test_scipy_error_types(rng):
    points = rng.random((20, 2))
    L, C = interpolate.LinearNDInterpolator, interpolate.CloughTocher2DInterpolator
    with pytest.raises(ValueError, match="different number of values and points"):
        L(points, np.zeros(19))
    with pytest.raises(ValueError, match="only for 2-D data"):
        C(rng.random((20, 3)), np.zeros(20))
    with pytest.raises(ValueError, match="at least 2-D"):
        L(points[:, 0], np.zeros(20))
    with pytest.raises(ValueError, match="number of dimensions in xi"):
        L(points, np.zeros(20))(rng.random((4, 3)))
    with pytest.raises(ValueError):
        L(points, np.zeros(20))([0.5])
    with pytest.raises(scipy.spatial.QhullError):  # collinear points: no triangle
        L(np.c_[np.arange(5.0), np.arange(5.0)], np.zeros(5))
    with pytest.raises(ValueError, match="Unknown interpolation method"):
        interpolate.griddata(points, np.zeros(20), points, method="quintic")
    with pytest.raises(ValueError, match="Unknown interpolation method 'cubic'"):
        interpolate.griddata(rng.random((20, 3)), np.zeros(20), points, method="cubic")
    with pytest.raises(TypeError):
        interpolate.NearestNDInterpolator(points, np.zeros(20))(points, no_such_option=1)


def test_threads_and_concurrent_calls_give_the_same_answer(rng):
    points = rng.random((2000, 2))
    values = np.c_[np.sin(points[:, 0] * 7), points[:, 1]]
    q = rng.random((70_000, 2))  # several ranges of queries per thread
    one = interpolate.CloughTocher2DInterpolator(points, values, threads=1)
    two = interpolate.CloughTocher2DInterpolator(one.tri, values, threads=2)
    want = one(q)
    np.testing.assert_array_equal(two(q), want)
    linear = interpolate.LinearNDInterpolator(one.tri, values, threads=2)
    got = [None] * 4

    def call(k):
        got[k] = linear(q[k::4])

    runs = [threading.Thread(target=call, args=(k,)) for k in range(4)]
    for t in runs:
        t.start()
    for t in runs:
        t.join()
    for k in range(4):
        np.testing.assert_array_equal(got[k], interpolate.LinearNDInterpolator(
            one.tri, values, threads=1)(q[k::4]))


def test_a_flat_simplex_interpolates_on_its_neighbour():
    """Three collinear points made almost collinear by scipy's rescale: the
    exact triangulation keeps their sliver, too flat for a ``transform``,
    and a query on one of its vertices still gets the vertex's value."""
    x = np.array([(0, 0), (-0.5, -0.5), (-0.5, 0.5), (0.5, 0.5), (0.25, 0.3)])
    y = np.arange(5.0)
    ip = _verified(interpolate.LinearNDInterpolator(x, y, rescale=True))
    assert np.isnan(ip.tri.transform[:, 0, 0]).any()
    np.testing.assert_allclose(ip(x), y, atol=1e-14)
    cubic = interpolate.CloughTocher2DInterpolator(x, y, rescale=True)
    np.testing.assert_allclose(cubic(x), y, atol=1e-14)


def test_gradient_estimate_warns_when_it_stops_early(rng):
    points = rng.random((200, 2))
    with pytest.warns(interpolate.GradientEstimationWarning):
        interpolate.CloughTocher2DInterpolator(points, np.sin(9 * points[:, 0]), maxiter=1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        interpolate.CloughTocher2DInterpolator(points, np.sin(9 * points[:, 0]))


def test_interpolators_pickle(rng):
    points = rng.random((30, 2))
    for name in CLASSES.values():
        ip = getattr(interpolate, name)(points, rng.random(30) + 1j * rng.random(30))
        again = pickle.loads(pickle.dumps(ip))
        np.testing.assert_array_equal(again(points), ip(points))


def test_griddata_1d_is_scipys(rng):
    x, y = rng.random(10), rng.random(10)
    for method in ("linear", "nearest", "cubic"):
        np.testing.assert_array_equal(interpolate.griddata(x, y, x[::2], method=method),
                                      scipy.interpolate.griddata(x, y, x[::2], method=method))


def test_docstring_examples_run():
    failed, attempted = doctest.testmod(interpolate, globs={}, report=False,
                                        optionflags=doctest.NORMALIZE_WHITESPACE)
    assert attempted > 0 and failed == 0


# -- natural neighbours: run once lfqt.natural (the kernels) is merged ------------------

@pytest.mark.parametrize("dim", [2, 3])
def test_natural_reproduces_affine_data(dim, rng):
    pytest.importorskip("lfqt.natural")
    points = rng.random((60, dim))
    a = rng.normal(size=dim)
    ip = _verified(interpolate.NaturalNeighborInterpolator(points, points @ a + 1.5))
    q = _inside(rng, points, 40)
    np.testing.assert_allclose(ip(q), q @ a + 1.5, atol=1e-10)
    np.testing.assert_allclose(ip(points), points @ a + 1.5, atol=1e-10)
    assert np.isnan(ip(np.full((2, dim), 5.0))).all()
    np.testing.assert_allclose(interpolate.griddata(points, points @ a, q, method="natural"),
                               q @ a, atol=1e-10)


def test_natural_shapes_complex_and_fill(rng):
    pytest.importorskip("lfqt.natural")
    points = rng.random((50, 2))
    re, im = rng.random((50, 3)), rng.random((50, 3))
    tri = lfqt.Delaunay(points)
    assert lfqt.verify(points, tri).ok
    ip = interpolate.NaturalNeighborInterpolator(tri, re + 1j * im, fill_value=2.0)
    assert ip.tri is tri
    q = np.r_[_inside(rng, points, 4), [[9.0, 9.0]]].reshape(5, 1, 2)
    got = ip(q)
    assert got.shape == (5, 1, 3) and got.dtype == np.complex128
    real = interpolate.NaturalNeighborInterpolator(tri, re, fill_value=2.0)(q)
    np.testing.assert_allclose(got.real, real, atol=1e-14)
    assert (got[4] == 2.0 + 0j).all()
