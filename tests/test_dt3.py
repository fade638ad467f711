"""experiments.beyond.dt3 (issue 52): its grid, a smoke run on a few peers
and sets, its tables, issue 52's claims judged on stored results, and its
rows in REPORT.md."""
import argparse

import pandas as pd
import pytest

import drivers
import generators
from experiments.beyond import dt3
from experiments.core import report, results
from experiments.core.claims import FAILS, HOLDS, MISSING, PARTLY, Results, judge
from experiments.core.runner import Cell

N = 1_000_000


def test_the_grid_times_every_3d_peer_on_its_thread_counts_and_judges_every_hard_set():
    cells = dt3.grid("default", 1)
    timed = {(c.peer, c.n, c.threads) for c in cells if c.distribution == dt3.TIME_SET}
    assert set(dt3.PEERS) <= set(drivers.names(3))
    for n in (100_000, 300_000, 1_000_000):
        for t in (1, 2):
            assert ("cgal-dt3-parallel", n, t) in timed and ("gmsh-hxt", n, t) in timed
        assert {("cgal-dt3", n, 1), ("tetgen", n, 1), ("lfqt-insert-kdtree", n, 1),
                ("lfqt-delaunay", n, 1)} <= timed
        assert ("lfqt-insert-kdtree", n, 2) in timed and ("lfqt-delaunay", n, 2) in timed
    assert ("qhull-3d", 300_000, 1) in timed and ("qhull-3d", N, 1) not in timed
    assert ("gmsh-default", N, 1) not in timed and ("gmsh-default", N, 1) in {
        (c.peer, c.n, c.threads) for c in dt3.grid("paper", 1)}
    hard = {(c.peer, c.distribution, c.threads) for c in cells if c.n == dt3.HARD_N["default"]}
    assert {d for _, d, _ in hard} == set(generators.names(3, tag="hard")) >= {
        "grid-3d", "cospherical", "subnormal-3d", "huge-3d"}
    assert {(p, d) for p, d, _ in hard} == {(p, d) for p in dt3.PEERS for d in dt3.HARD_SETS}
    assert ("gmsh-hxt", "grid-3d", 2) in hard
    # every hard-set mesh is judged, a timed one up to CHECK_MAX_N
    assert all(dt3.judged(c) for c in cells if c.distribution in dt3.HARD_SETS)
    assert {c.n for c in cells if dt3.judged(c) and c.distribution == dt3.TIME_SET} == {
        n for n in dt3.SIZES["default"] if n <= dt3.CHECK_MAX_N} == {100_000}
    # a peer's known hang is skipped below the paper scale, with its reason
    hung = Cell("gmsh-hxt", "huge-3d", 8_000)
    assert dt3.known_failure("default", hung).startswith("known hang")
    assert dt3.known_failure("paper", hung) is None


def test_the_hard_sets_run_in_the_loop_regime_alone():
    args = argparse.Namespace(scale="smoke", threads=1, peers=None, sizes=None, dists=None,
                              input=None, regime=["loop", "kept"])
    cells = dt3.EXPERIMENT.cells(args)
    assert {c.distribution for c in cells if c.regime == "kept"} == {dt3.TIME_SET}
    assert {c.distribution for c in cells if c.regime == "loop"} == {dt3.TIME_SET,
                                                                     *dt3.HARD_SETS}


def test_smoke_run_times_judges_and_records_a_wrong_mesh_as_a_finding(tmp_path, capsys):
    for name in ("gmsh-hxt", "gmsh-default"):
        ok, why = drivers.available(name)
        if not ok:
            pytest.skip(why)
    assert dt3.main(["--scale", "smoke", "--out", str(tmp_path), "--quiet", "--repeats", "1",
                     "--peers", "lfqt-insert-kdtree,gmsh-hxt,gmsh-default",
                     "--dists", f"{dt3.TIME_SET},grid-3d-sorted"]) == 0
    df = results.load(tmp_path / "smoke" / "dt3")
    assert set(df["status"]) == {"ok"} and set(df["regime"]) == {"loop", "kept"}
    cells = dt3.cells_of(df)
    assert cells[("lfqt-insert-kdtree", "grid-3d-sorted", 500, 1)][3] == "exact"
    assert cells[("gmsh-hxt", "grid-3d-sorted", 500, 2)][3] == "exact"
    kind, text = cells[("gmsh-default", "grid-3d-sorted", 500, 1)][3:]
    assert kind == "wrong" and "flat tetrahedra" in text
    out = capsys.readouterr().out
    assert "== regime: kept" in out and "| gmsh-default | 1 | **wrong: " in out
    assert (tmp_path / "smoke" / "figures" / "dt3.png").stat().st_size > 20000
    assert (tmp_path / "smoke" / "figures" / "dt3-kept.png").exists()


def _store(root, times, hard=()):
    """dt3's results for {(peer, n, threads): seconds} on the cube, and
    (peer, set, check) on the hard sets, as the runner writes them."""
    rows = []
    for (peer, n, t), sec in times.items():
        rows += results.rows_for(Cell(peer, dt3.TIME_SET, n, threads=t), "dt3", {
            "status": "ok", "seconds": [sec] * 3, "cycles": [1] * 3, "peak_bytes": 0,
            "version": "", "counts": {}, "check": {"verdict": "exact"}})
    for peer, d, check in hard:
        rows += results.rows_for(Cell(peer, d, 8_000), "dt3", {
            "status": "ok", "seconds": [0.1], "cycles": [1], "peak_bytes": 0, "version": "",
            "counts": {}, "check": check})
    (root / "dt3").mkdir(parents=True, exist_ok=True)
    results.write(root / "dt3", rows)


WRONG = {"verdict": "wrong", "flat": 9085, "tetrahedra": 49330, "problems": ["orientation"]}


def _verdicts(root):
    return [(r.claim.split(":")[0], r.verdict) for r in judge(dt3.EXPERIMENT, Results(root))]


def test_issue_52s_targets_hold_and_fall_short_on_stored_results(tmp_path):
    _store(tmp_path, {("lfqt-insert-kdtree", N, 1): 1.9, ("gmsh-hxt", N, 1): 3.4,
                      ("cgal-dt3", N, 1): 3.6, ("lfqt-insert-kdtree", N, 2): 1.0,
                      ("gmsh-hxt", N, 2): 2.5},
           hard=[("lfqt-insert-kdtree", "grid-3d", {"verdict": "exact"}),
                 ("gmsh-default", "grid-3d", WRONG)])
    rows = judge(dt3.EXPERIMENT, Results(tmp_path))
    assert [r.verdict for r in rows] == [HOLDS] * 5
    assert "1M: lfqt 1.90 s, gmsh-hxt 3.40 s: 1.79x" == rows[0].ours
    assert rows[1].ours == "1M: lfqt/CGAL DT3 0.53x" and rows[2].ours.endswith("1.90x")
    assert {r.source for r in rows} == {"dt3"}
    _store(tmp_path, {("lfqt-insert-kdtree", N, 1): 3.5, ("gmsh-hxt", N, 1): 3.4,
                      ("cgal-dt3", N, 1): 3.6, ("lfqt-insert-kdtree", N, 2): 2.5,
                      ("gmsh-hxt", N, 2): 2.5},
           hard=[("lfqt-insert-kdtree", "grid-3d", WRONG)])
    rows = judge(dt3.EXPERIMENT, Results(tmp_path))
    assert [r.verdict for r in rows] == [FAILS, FAILS, FAILS, HOLDS, PARTLY]  # 1 of 2 cells
    assert "lfqt-insert-kdtree grid-3d 1T: wrong: 9,085 flat tetrahedra" in rows[4].why


def test_without_a_2_thread_cell_the_parallel_targets_say_what_is_missing(tmp_path):
    _store(tmp_path, {("lfqt-insert-kdtree", N, 1): 1.9, ("gmsh-hxt", N, 1): 3.4,
                      ("cgal-dt3", N, 1): 3.6, ("gmsh-hxt", N, 2): 2.5})
    rows = judge(dt3.EXPERIMENT, Results(tmp_path))
    assert [r.verdict for r in rows][2:4] == [MISSING, MISSING]
    assert "no 2-thread cell of lfqt.insert" in rows[2].why


def test_the_report_has_the_3d_rows_and_tables_from_stored_results_only(tmp_path):
    text = report.render(tmp_path, "default")
    assert "## 3D: lfqt against every 3D peer" in text and "run `python -m experiments.dt3`" in text
    _store(tmp_path, {("lfqt-insert-kdtree", N, 1): 2.0, ("gmsh-hxt", N, 1): 3.0,
                      ("gmsh-hxt", N, 2): 1.5, ("cgal-dt3", N, 1): 4.0},
           hard=[("lfqt-insert-kdtree", "grid-3d", {"verdict": "exact"}),
                 ("gmsh-default", "grid-3d", WRONG)])
    text = report.render(tmp_path, "default")
    beyond = text.split("## Beyond the papers", 1)[1].split("\n## ", 1)[0]
    assert "1 thread, 1M uniform: lfqt's 3D insertion at least as fast as HXT" in beyond
    assert "| dt3 |" in beyond
    tables = text.split("## 3D: lfqt against every 3D peer", 1)[1]
    assert "| gmsh-hxt | 1 | 3 s (1.50x) |" in tables
    assert "| gmsh-hxt | 2 | 1.5 s (0.75x) |" in tables  # against lfqt's 1 thread: it has no 2
    assert "| gmsh-default | 1 | **wrong: 9,085 flat tetrahedra** |" in tables


def test_tables_say_refused_crashed_and_hung():
    def rows(peer, status, detail=""):
        return [dict(peer=peer, distribution="huge-3d", n=8000, threads=1, count=False,
                     status=status, detail=detail, seconds=None, check={}, round=0,
                     bytes_per_point=None, counts={}, regime="loop")]
    df = pd.DataFrame(rows("tetgen", "error", "RuntimeError: TetGen runtime error code 2")
                      + rows("gmsh-default", "crash", "child died of SIGABRT")
                      + rows("gmsh-hxt", "skipped", "known hang: no result within 30 s"))
    table = "\n".join(dt3.exactness_table(df))
    assert "| tetgen | 1 | refused (RuntimeError) |" in table
    assert "| gmsh-default | 1 | crashed |" in table and "| gmsh-hxt | 1 | hung |" in table


def test_a_timed_cell_past_the_checked_sizes_shows_its_time_unmarked():
    def rows(peer, seconds, check):
        return [dict(peer=peer, distribution=dt3.TIME_SET, n=1_000_000, threads=1, count=False,
                     status="ok", detail="", seconds=seconds, check=check, round=0,
                     bytes_per_point=None, counts={}, regime="loop")]
    df = pd.DataFrame(rows("lfqt-insert-kdtree", 2.0, {}) + rows("tetgen", 4.0, {})
                      + rows("gmsh-default", 8.0, WRONG))
    assert dt3.cells_of(df)[("tetgen", dt3.TIME_SET, 1_000_000, 1)][3:] == ("unchecked", "")
    table = "\n".join(dt3.timing_table(df))
    assert "| tetgen | 1 | 4 s (2.00x) |" in table
    assert "| gmsh-default | 1 | 8 s (4.00x), **wrong: 9,085 flat tetrahedra** |" in table
