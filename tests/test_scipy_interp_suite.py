"""scipy's own interpolator tests (the installed scipy/interpolate/tests/
test_interpnd.py and test_ndgriddata.py) with lfqt.interpolate's classes
in place of scipy's, every mesh they build verified exactly.

test_interpnd.py calls ``interpnd.X`` and ``qhull.Delaunay`` through two
module names, which are pointed at stand-ins holding lfqt's classes (and
lfqt.Delaunay, so that its "Delaunay as input" tests pass an lfqt one).
test_ndgriddata.py imports its names from scipy.interpolate and uses them
in decorators as it loads, so they are swapped there while it loads, as
tests/test_scipy_suite.py does for test_qhull.py.  A test is skipped only
for a reason in SKIPPED."""
import importlib.util
import pathlib
import types

import numpy as np
import pytest
import scipy.interpolate

import lfqt
from lfqt import interpolate
from test_interpolate import _every_mesh_is_verified  # noqa: F401 (autouse: verifies every mesh)

_DIR = pathlib.Path(scipy.interpolate.__file__).parent / "tests"
if not (_DIR / "test_interpnd.py").exists():
    pytest.skip(f"scipy's tests are not installed ({_DIR})", allow_module_level=True)

OURS = {name: getattr(interpolate, name) for name in
        ("LinearNDInterpolator", "CloughTocher2DInterpolator", "NearestNDInterpolator",
         "griddata", "estimate_gradients_2d_global", "GradientEstimationWarning")}


def _load(name, swap_in_scipy_interpolate=False):
    spec = importlib.util.spec_from_file_location(f"scipy_{name}_with_lfqt", _DIR / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    saved = {k: getattr(scipy.interpolate, k) for k in OURS if hasattr(scipy.interpolate, k)}
    if swap_in_scipy_interpolate:
        for k in saved:
            setattr(scipy.interpolate, k, OURS[k])
    try:
        spec.loader.exec_module(module)
    finally:
        for k, v in saved.items():
            setattr(scipy.interpolate, k, v)
    return module


_interpnd = _load("test_interpnd")
_interpnd.interpnd = types.SimpleNamespace(**OURS)
_interpnd.qhull = types.SimpleNamespace(Delaunay=lfqt.Delaunay)
_ndgriddata = _load("test_ndgriddata", swap_in_scipy_interpolate=True)

# Empty: every test of both files passes with lfqt's classes (none tests scipy's
# internals only or more than 3 dimensions).  The slowest is scipy's @slow
# TestLinearNDInterpolation::test_threading: 17.6M queries from 4 threads.
SKIPPED: dict[str, str] = {}


def _reason(cls, name):
    return SKIPPED.get(f"{cls}::{name}")


@pytest.fixture(autouse=True)
def _only_what_applies(request):
    cls = request.cls.__name__ if request.cls else ""
    reason = _reason(cls, request.function.__name__)
    if reason:
        pytest.skip(reason)


for _module in (_interpnd, _ndgriddata):
    for _name in dir(_module):
        if _name.startswith("Test"):
            globals()[_name] = getattr(_module, _name)


def test_the_swap_is_in_place():
    """The loaded modules really call lfqt: a failing swap would test scipy."""
    assert _ndgriddata.griddata is interpolate.griddata
    assert _ndgriddata.LinearNDInterpolator is interpolate.LinearNDInterpolator
    assert _interpnd.interpnd.CloughTocher2DInterpolator is interpolate.CloughTocher2DInterpolator
    ip = _interpnd.interpnd.LinearNDInterpolator(np.random.default_rng(0).random((20, 2)),
                                                 np.arange(20.0))
    assert isinstance(ip.tri, lfqt.Delaunay)
