"""lfqt ships its annotations (PEP 561): mypy, run on a user's script,
finds lfqt typed (``py.typed``), accepts every public item used as the
README uses it, and rejects misuses that only the annotations forbid.

mypy runs as a user's would: lfqt found on the interpreter's path (the
editable install's import hook is invisible to mypy, so the directory that
holds lfqt goes on PYTHONPATH, which mypy searches as installed packages:
py.typed required, errors inside lfqt not reported), ``--strict`` on the
script, except that calls of functions still unannotated are allowed."""
import os
import re
import runpy
import subprocess
import sys
import textwrap
import typing
from pathlib import Path

import lfqt
from lfqt import dc, orders
from lfqt.dc import hybrid

# --strict checks the script itself; --allow-untyped-calls because not every
# public function is annotated yet (--strict would reject the script's call
# of one): such a call is Any, which the script's own annotations still
# check.  No --ignore-missing-imports: lfqt without py.typed, or not
# found, must fail the run.  A fresh cache per run (--no-incremental).
MYPY_OPTIONS = ["--strict", "--allow-untyped-calls", "--no-incremental", "--show-error-codes",
                "--no-error-summary", "--no-pretty"]
UNTYPED = "missing library stubs or py.typed marker"

USER_SCRIPT = '''
from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

import lfqt
import lfqt.orders
import lfqt.workspace

Indices = npt.NDArray[np.integer[Any]]


def main() -> None:
    rng = np.random.default_rng(0)
    p: npt.NDArray[np.float64] = rng.random((200, 2))
    tri: lfqt.Triangulation = lfqt.triangulate(p, threads=np.int64(2))
    reveal_type(tri.simplices)
    simplices: Indices = tri.simplices
    neighbors: Indices = tri.neighbors
    hull: Indices = tri.hull
    duplicate_of: Indices = tri.duplicate_of
    stats: dict[str, Any] = tri.stats
    degenerate: bool = tri.degenerate
    reason: str = tri.reason
    n_distinct: int = tri.n_distinct
    points: npt.ArrayLike | None = tri.points
    print(simplices.shape, neighbors.shape, hull.shape, duplicate_of.shape, stats["seconds"],
          degenerate, reason, n_distinct, points is p)
    assert lfqt.verify(p, tri).ok
    report: lfqt.VerifyReport = lfqt.verify(p, tri)
    print(report.problems)

    p3: npt.NDArray[np.float64] = rng.random((200, 3))
    perm, hint = lfqt.orders.order(p3, "kdtree", hint="sibling")
    tet = lfqt.insert(p3, order=(perm, hint))
    facets: Indices = tet.hull
    print(facets.shape, tet.stats["per_point"])
    perm, hint, store, stored = lfqt.orders.layout(p3, "hilbert")
    names: tuple[str, ...] = lfqt.orders.ORDERS
    print(perm.dtype, hint.dtype, store.dtype, stored.shape, names)

    tree = lfqt.quadtree(p[:20])
    order: npt.NDArray[np.int64] = tree.order
    levels: npt.NDArray[Any] = tree.nodes["level"]
    print(order, levels)

    d = lfqt.Delaunay(p, incremental=True)
    print(d.find_simplex([[0.5, 0.5]]), d.simplices.shape, d.neighbors.shape,
          d.convex_hull.shape, d.transform.shape)
    indptr, indices = d.vertex_neighbor_vertices
    print(indptr.shape, indices.shape)
    d.add_points(rng.random((10, 2)))
    d.close()
    try:
        lfqt.Delaunay([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]])
    except lfqt.DegenerateInputError as error:
        problem: ValueError = error
        print(problem)
    lfqt.workspace.release()


def options(p: npt.NDArray[np.float64], p3: npt.NDArray[np.float64]) -> None:
    """Never called: mypy checks the options' types; running them would only
    compile their kernel variants (tests/test_dc.py and test_insert.py do)."""
    tri = lfqt.triangulate(p.tolist(), threads=None, subdivision="alternating", counters=False,
                           filter="constant", schedule="levels")
    tri = lfqt.triangulate(p, method="hybrid", leaf_size=64, leaf_order="kdtree")
    tet = lfqt.insert(p3, order="brio", seed=1, phase_times=True)
    tet = lfqt.insert(p3, order="kdtree", hint="parent", counters=False)
    print(tri, tet)


def on_a_cluster(pts: npt.NDArray[np.float64]) -> None:
    """Never called: mypy checks it, no cluster runs it."""
    got = lfqt.distributed.triangulate("cloud/part-*.npy", out="tiles/")
    print(got.stats)
    assert lfqt.distributed.verify(got, "cloud/part-*.npy").ok
    tri = lfqt.distributed.triangulate(pts, client="tcp://scheduler:8786")
    if isinstance(tri, lfqt.Triangulation):
        print(tri.simplices.shape)


if __name__ == "__main__":
    main()
'''

# Each line marked "# rejected" must draw an error, and no other line may.
MISUSE_SCRIPT = '''
from __future__ import annotations

import numpy as np

import lfqt
import lfqt.orders
import lfqt.workspace

p = np.random.default_rng(0).random((100, 2))
lfqt.triangulate(p, threads="two")  # rejected
lfqt.triangulate(p, subdivision="morton")  # rejected
lfqt.triangulate(p, leaf_size=2.5)  # rejected
name: str = lfqt.triangulate(p).simplices  # rejected
lfqt.insert(p, order="zorder")  # rejected
lfqt.insert(p, hint="uncle")  # rejected
lfqt.insert(p, seed="one")  # rejected
tri = lfqt.insert(p)
tri.degenerate = "no"  # rejected
count: str = tri.n_distinct  # rejected
lfqt.quadtree(p).order.keys()  # rejected
lfqt.orders.order(p, "morton")  # rejected
perm, hint, store = lfqt.orders.layout(p)  # rejected
nothing: int = lfqt.workspace.release()  # rejected
'''


def _mypy(tmp_path, source):
    """(exit code, output) of mypy on ``source`` written to a file in
    tmp_path, lfqt found as an installed package."""
    script = tmp_path / "user_script.py"
    script.write_text(textwrap.dedent(source))
    env = dict(os.environ, PYTHONPATH=str(Path(lfqt.__file__).resolve().parents[1]))
    env.pop("MYPYPATH", None)
    run = subprocess.run([sys.executable, "-m", "mypy", *MYPY_OPTIONS,
                          f"--cache-dir={tmp_path / 'cache'}", script.name],
                         cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)
    return run.returncode, run.stdout + run.stderr


def test_mypy_accepts_a_script_using_the_public_api(tmp_path):
    code, out = _mypy(tmp_path, USER_SCRIPT)
    assert UNTYPED not in out, out
    assert code == 0, out
    # the annotation reached the script: not Any
    revealed = re.search(r'Revealed type is "(.*)"', out)
    assert revealed and "numpy.ndarray" in revealed.group(1), out


def test_mypy_rejects_misuses_that_only_annotations_forbid(tmp_path):
    code, out = _mypy(tmp_path, MISUSE_SCRIPT)
    assert UNTYPED not in out, out
    assert code == 1, out
    lines = textwrap.dedent(MISUSE_SCRIPT).splitlines()
    marked = {k + 1 for k, line in enumerate(lines) if "# rejected" in line}
    flagged = {int(m) for m in re.findall(r"^user_script\.py:(\d+): error", out, re.M)}
    assert flagged == marked, out


def test_the_typed_script_runs(tmp_path):
    """What mypy accepts is how lfqt is used: the script runs, and its
    checks hold (on_a_cluster aside)."""
    script = tmp_path / "user_script.py"
    script.write_text(textwrap.dedent(USER_SCRIPT).replace("reveal_type(", "print("))
    runpy.run_path(str(script), run_name="__main__")


def test_the_literal_options_are_the_options_checked_at_run_time():
    assert typing.get_args(dc.LeafOrder) == hybrid.ORDERS
    assert dc.SUBDIVISIONS == ("lfqt", "alternating") and dc.METHODS == ("dc", "hybrid")
    assert orders.ORDERS == typing.get_args(orders.OrderName)
    assert typing.get_args(orders.Hint) == ("parent", "sibling")


def test_py_typed_ships_with_the_package():
    root = Path(lfqt.__file__).resolve().parent
    assert (root / "py.typed").is_file()
    pyproject = (root.parent / "pyproject.toml").read_text()
    assert re.search(r'\[tool\.setuptools\.package-data\]\s*\nlfqt = \["py\.typed"\]', pyproject)
