import os
import subprocess
import sys

import numpy as np

import lfqt
from lfqt import jit_cache
from lfqt.dc import merge


def _write(path, text):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)


def test_the_stamp_changes_with_any_source_of_the_tree(tmp_path):
    _write(tmp_path / "a.py", "x = 1\n")
    _write(tmp_path / "sub" / "b.py", "y = 2\n")
    before = jit_cache.tree_stamp(tmp_path)
    assert [e[0] for e in before] == ["a.py", os.path.join("sub", "b.py")]
    _write(tmp_path / "__pycache__" / "c.py", "")  # caches and other files do not count
    _write(tmp_path / "notes.txt", "")
    assert jit_cache.tree_stamp(tmp_path) == before
    os.utime(tmp_path / "a.py", ns=(1, 1))  # a new time, the same contents (a checkout)
    assert jit_cache.tree_stamp(tmp_path) == before
    _write(tmp_path / "sub" / "b.py", "y = 3\n")  # the same size
    assert jit_cache.tree_stamp(tmp_path) != before


def test_lfqt_kernels_use_the_package_stamp_and_others_do_not():
    lfqt.triangulate(np.random.default_rng(0).random((50, 2)))
    locator = merge.run_ops._cache._impl.locator
    assert isinstance(locator, jit_cache._PackageStamp)
    assert locator.get_source_stamp() == jit_cache.tree_stamp()
    outside = os.path.join(os.path.dirname(jit_cache.ROOT), "elsewhere.py")
    assert all(cls.from_function(len, outside) is None for cls in jit_cache.PACKAGE_LOCATORS)


def test_an_edit_elsewhere_in_the_package_recompiles_an_inlining_kernel(tmp_path):
    """A copy of lfqt whose in-circle predicate is edited: verify's mesh
    check, which inlines it through lfqt.predicates.counters (two modules
    away), runs the edited code at once, not its cached build.  (verify
    compiles in half the time of the whole triangulation pipeline.)"""
    import shutil
    pkg = tmp_path / "lfqt"
    shutil.copytree(jit_cache.ROOT, pkg, ignore=shutil.ignore_patterns("__pycache__"))
    P = np.random.default_rng(1).random((300, 2))
    np.savez(tmp_path / "mesh.npz", points=P, simplices=lfqt.triangulate(P).simplices)
    script = ("import numpy as np, lfqt; "
              "from lfqt.verification import mesh_from_simplices; "
              "d = np.load('mesh.npz'); "
              "c = lfqt.verify(d['points'], mesh_from_simplices(d['simplices'], 300)).counts; "
              "print(c['non_delaunay_edges'], c['triangles'], c['boundary_edges'])")
    env = dict(os.environ, PYTHONPATH=str(tmp_path), NUMBA_CACHE_DIR=str(tmp_path / "cache"))

    def counts():
        out = subprocess.run([sys.executable, "-c", script], env=env, cwd=tmp_path,
                             capture_output=True, text=True, check=True).stdout
        return tuple(int(v) for v in out.split())

    bad, triangles, boundary = counts()
    assert bad == 0 and triangles > 500
    assert counts() == (bad, triangles, boundary)  # from the cache
    # the edit: every point lies strictly inside every circle
    with open(pkg / "predicates" / "planar.py", "a") as f:
        f.write("\n\n@njit(cache=True)\n"
                "def incircle_staged(ax, ay, bx, by, cx, cy, dx, dy, bound, static=np.inf):\n"
                "    return 1.0, 2\n")
    interior_edges = (3 * triangles - boundary) // 2
    assert counts() == (interior_edges, triangles, boundary)
