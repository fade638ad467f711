"""scipy's own Delaunay tests (the installed scipy/spatial/tests/test_qhull.py)
with lfqt.Delaunay in place of scipy.spatial.Delaunay.

The module is loaded from the installed scipy and its ``qhull`` name is
pointed at a stand-in whose Delaunay (and tsearch) are lfqt's; everything
else stays scipy's (ConvexHull, the data sets).  A test is skipped only for
one of the reasons in SKIPPED: it tests another class, a dimension above 3,
a Qhull-only option, or Qhull's exact vertex order on cocircular input."""
import importlib.util
import pathlib
import types

import numpy as np
import pytest
import scipy.spatial

import lfqt

_PATH = pathlib.Path(scipy.spatial.__file__).parent / "tests" / "test_qhull.py"
if not _PATH.exists():
    pytest.skip(f"scipy's tests are not installed ({_PATH})", allow_module_level=True)

_real = scipy.spatial._qhull
_swapped = types.SimpleNamespace(**{
    **{k: getattr(_real, k) for k in dir(_real) if not k.startswith("__")},
    "Delaunay": lfqt.Delaunay, "tsearch": lambda tri, xi: tri.find_simplex(xi)})
_spec = importlib.util.spec_from_file_location("scipy_test_qhull_with_lfqt", _PATH)
_scipy_tests = importlib.util.module_from_spec(_spec)
# The module binds ``import scipy.spatial._qhull as qhull`` and uses
# qhull.Delaunay in decorators at import: swap it while the module runs.
scipy.spatial._qhull = _swapped
try:
    _spec.loader.exec_module(_scipy_tests)
finally:
    scipy.spatial._qhull = _real

COCIRCULAR_ORDER = "asserts Qhull's exact vertex order on the cocircular unit square"
OTHER_CLASS = "tests ConvexHull, Voronoi, HalfspaceIntersection or Qhull internals, not Delaunay"
HIGH_DIM = "Delaunay above 3 dimensions (lfqt triangulates in 2D and 3D)"
SKIPPED = {
    "TestUtilities::test_find_simplex": COCIRCULAR_ORDER,
    "TestUtilities::test_convex_hull": COCIRCULAR_ORDER,
    "TestDelaunay::test_2d_square": COCIRCULAR_ORDER,
    "TestUtilities::test_degenerate_barycentric_transforms": (
        "counts Qhull's own near-flat simplices (fewer than 23) on a degenerate set where "
        "Qhull's mesh is not Delaunay (6 inverted triangles, 2 non-Delaunay edges); the exact "
        "triangulation has 31, and passes the test's other checks "
        "(test_degenerate_pointset_passes_scipys_transform_checks)"),
    "TestDelaunay::test_joggle": "Qhull-only option: QJ joggles the input so that duplicates "
                                 "become vertices",
    "TestDelaunay::test_furthest_site": "Qhull-only option: the furthest-site triangulation "
                                        "(Qu), refused with NotImplementedError",
    "TestDelaunay::test_nd_simplex": HIGH_DIM + " (loops to 7D; tests/test_delaunay.py checks "
                                                "the 2D and 3D simplex)",
    "TestUtilities::test_more_barycentric_transforms": HIGH_DIM + " (loops to 5D; "
                                                                  "tests/test_delaunay.py checks "
                                                                  "the 2D and 3D grids)",
}
DELAUNAY_TESTS_OF_OTHER_CLASSES = {"TestConvexHull::test_hull_consistency_tri"}


def _reason(cls, name, params):
    key = f"{cls}::{name}" if cls else name
    if key in SKIPPED:
        return SKIPPED[key]
    if cls in ("Test_Qhull", "TestVoronoi", "Test_HalfspaceIntersection"):
        return OTHER_CLASS
    if cls == "TestConvexHull" and key not in DELAUNAY_TESTS_OF_OTHER_CLASSES:
        return OTHER_CLASS
    if cls == "TestUtilities" and "volume_area" in name:
        return OTHER_CLASS
    if any(f"{k}d" in params for k in range(4, 9)):
        return HIGH_DIM
    if "Voronoi" in params:
        return OTHER_CLASS
    return None


@pytest.fixture(autouse=True)
def _only_what_applies(request):
    cls = request.cls.__name__ if request.cls else ""
    name = request.function.__name__
    params = request.node.name[len(name):]
    reason = _reason(cls, name, params)
    if reason:
        pytest.skip(reason)


for _name in dir(_scipy_tests):
    if _name.startswith("Test") or _name.startswith("test_"):
        globals()[_name] = getattr(_scipy_tests, _name)


def test_the_swap_is_in_place():
    """The loaded module really calls lfqt: a failing swap would test scipy."""
    tri = _scipy_tests.qhull.Delaunay(np.random.default_rng(0).random((20, 2)))
    assert isinstance(tri, lfqt.Delaunay)
    assert _scipy_tests.qhull.ConvexHull is scipy.spatial.ConvexHull


def test_degenerate_pointset_passes_scipys_transform_checks():
    """scipy's test_degenerate_barycentric_transforms without its count of
    Qhull's near-flat simplices: every simplex has a NaN transform or the
    centroid inside, flat ones only, and find_simplex finds every centroid."""
    data = np.load(_PATH.parent / "data" / "degenerate_pointset.npz")
    points = data["c"]
    tri = lfqt.Delaunay(points)
    assert lfqt.verify(points, tri.triangulation).ok
    assert np.isnan(tri.transform[:, 0, 0]).sum() < 50
    _scipy_tests.TestUtilities()._check_barycentric_transforms(tri)
