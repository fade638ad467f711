"""experiments.field: its grid, its tables, and a user's LAS/LAZ file as
input end to end (issue 53)."""
import argparse
import json
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

import generators
from experiments.beyond import field
from experiments.core.registry import experiments, listing


def test_the_grid_times_every_peer_on_paper_1s_sets_and_the_lidar_model():
    cells = field.grid("default", 1)
    timed = {(c.peer, c.distribution, c.n) for c in cells if c.n >= 100_000}
    for d in generators.names(2, tag="paper1") + ["lidar-xy"]:
        for p in field.PEERS:
            assert (p, d, 100_000) in timed
    assert ("delaunator", "uniform", 1_000_000) in timed
    assert ("qhull-2d", "uniform", 1_000_000) not in timed
    assert field.known_failure("default", field.Cell("cdt", "huge", 2000))
    assert not field.known_failure("paper", field.Cell("cdt", "huge", 2000))
    paper = {(c.distribution, c.n) for c in field.grid("paper", 1)}
    assert ("spiral", 10_000_000) in paper and ("lidar-xy", 10_000_000) in paper


def test_the_grid_judges_every_peer_on_every_hard_set():
    hard = {(c.peer, c.distribution) for c in field.grid("smoke", 1)
            if c.n == field.HARD_N["smoke"]}
    assert hard == {(p, d) for p in field.PEERS for d in generators.names(2, tag="hard")}
    assert {"tiny", "subnormal", "huge", "gis", "signed-zeros", "duplicates", "collinear",
            "cocircular", "lidar-xy", "grid", "circle"} <= {d for _, d in hard}
    assert field.EXPERIMENT.check and "experiments.field" in listing()
    assert experiments()["field"] is field.EXPERIMENT


def _rows(peer, dist, n, status="ok", check=None, seconds=(1.0,), detail="", regime="loop"):
    return [dict(peer=peer, distribution=dist, n=n, count=False, status=status, detail=detail,
                 seconds=s if status == "ok" else None, check=check or {}, round=0,
                 bytes_per_point=None, counts={}, regime=regime) for s in seconds]


def test_tables_say_exact_wrong_refused_crashed_and_hung():
    exact = {"verdict": "exact"}
    wrong = {"verdict": "wrong", "non_delaunay_edges": 250, "missing_triangles": 0,
             "problems": ["delaunay"]}
    df = pd.DataFrame(
        _rows("lfqt-dc", "circle", 500, check=exact) + _rows("delaunator", "circle", 500, check=wrong)
        + _rows("cdt", "circle", 500, "error", detail="RuntimeError: duplicate vertex\n...")
        + _rows("gmsh", "circle", 500, "crash") + _rows("qhull-2d", "circle", 500, "timeout")
        + _rows("triangle-native", "circle", 500, "error",
                detail="RuntimeError: triangle_driver failed (-11): ")
        + _rows("startinpy", "circle", 500, "skipped", detail="known hang: no result")
        + _rows("lfqt-dc", "uniform", 100_000, check=exact, seconds=(0.01, 0.02, 0.03))
        + _rows("delaunator", "uniform", 100_000, check=wrong, seconds=(0.04, 0.04, 0.05)))
    table = "\n".join(field.exactness_table(df))
    assert "| delaunator | **wrong: 250 bad edges** |" in table
    assert "| cdt | refused (RuntimeError) |" in table and "| gmsh | crashed |" in table
    assert "| qhull-2d | hung |" in table and "| lfqt-dc | exact |" in table
    assert "| triangle-native | crashed |" in table and "| startinpy | hung |" in table
    timing = "\n".join(field.timing_table(df))
    assert "| lfqt-dc | 0.02 s |" in timing
    assert "| delaunator | 0.04 s (2.00x), **wrong: 250 bad edges** |" in timing
    assert field.report_lines(None)[2].startswith("Not measured yet")


def test_each_regime_has_its_own_timing_table_and_the_exactness_sets_run_in_the_loop_alone():
    exact = {"verdict": "exact"}
    df = pd.DataFrame(
        _rows("lfqt-dc", "uniform", 100_000, check=exact, seconds=(0.01,))
        + _rows("cgal-dt2", "uniform", 100_000, check=exact, seconds=(0.03,))
        + _rows("lfqt-dc", "uniform", 100_000, check=exact, seconds=(0.02,), regime="fresh")
        + _rows("cgal-dt2", "uniform", 100_000, check=exact, seconds=(0.03,), regime="fresh"))
    lines = field.timing_tables(df)
    heads = [k for k, l in enumerate(lines) if l.startswith("Regime **")]
    assert [lines[k].split("**")[1] for k in heads] == ["loop", "fresh"]
    loop, fresh = "\n".join(lines[heads[0]:heads[1]]), "\n".join(lines[heads[1]:])
    assert "| cgal-dt2 | 0.03 s (3.00x) |" in loop and "| cgal-dt2 | 0.03 s (1.50x) |" in fresh
    args = argparse.Namespace(scale="smoke", threads=1, peers=None, sizes=None, dists=None,
                              input=None, regime=["loop", "fresh"])
    cells = field.EXPERIMENT.cells(args)
    assert {c.distribution for c in cells if c.regime == "fresh"} <= set(field.TIME_SETS)
    assert {c.distribution for c in cells if c.regime == "loop"} >= set(field.HARD_SETS)


def _laz(path, n):
    laspy = pytest.importorskip("laspy")
    pts = generators.make("lidar", n, seed=3)
    header = laspy.LasHeader(point_format=3, version="1.2")
    header.scales, header.offsets = [0.01] * 3, [500_000.0, 4_000_000.0, 0.0]
    las = laspy.LasData(header)
    las.x, las.y, las.z = pts[:, 0], pts[:, 1], pts[:, 2]
    las.write(path)
    return pts


def _run(module, *args):
    proc = subprocess.run([sys.executable, "-m", f"experiments.{module}", *map(str, args)],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    return proc


def test_field_runs_on_a_users_laz_file(tmp_path):
    laz = tmp_path / "cloud.laz"
    pts = _laz(laz, 600)
    out = tmp_path / "out"
    proc = _run("field", "--scale", "smoke", "--input", laz, "--out", out, "--quiet",
                "--peers", "lfqt-dc,cgal-dt2,delaunator,startinpy")
    df = pd.read_csv(out / "smoke" / "input" / "field" / "results.csv", keep_default_na=False)
    assert set(df["distribution"]) == {"input:cloud.laz"} and set(df["n"]) == {len(pts)}
    assert set(df["peer"]) == {"lfqt-dc", "cgal-dt2", "delaunator", "startinpy"}
    ours = df[df["peer"] == "lfqt-dc"]
    assert len(ours) == 3 and json.loads(ours["check"].iloc[0])["verdict"] == "exact"
    assert "input:cloud.laz (600)" in proc.stdout  # the exactness table has the file's column
    assert not (out / "smoke" / "field").exists()  # never mixed with the report's results


def test_bench_dc_takes_a_file_and_its_prefixes(tmp_path):
    np.save(tmp_path / "pts.npy", generators.make("uniform", 3000, seed=1))
    _run("bench_dc", "--scale", "smoke", "--input", tmp_path / "pts.npy", "--out", tmp_path,
         "--quiet", "--peers", "lfqt-dc", "--no-compile-time", "--rounds", "1", "--repeats", "1",
         "--sizes", "1000,3000")
    df = pd.read_csv(tmp_path / "smoke" / "input" / "bench_dc" / "results.csv")
    assert sorted(set(df["n"])) == [1000, 3000] and set(df["distribution"]) == {"input:pts.npy"}


@pytest.mark.parametrize("args,message", [
    (["--input", "/nonexistent/cloud.laz"], "no such point cloud"),
    (["--input", "{tmp}/a.txt"], "unknown format"),
    (["--input", "{tmp}/pts.npy", "--sizes", "5000"], "more than the 3,000 points"),
    (["--input", "{tmp}/pts.npy", "--dists", "uniform"], "exclude each other"),
])
def test_bad_input_is_a_clear_error(tmp_path, args, message):
    np.save(tmp_path / "pts.npy", np.zeros((3000, 2)) + np.arange(3000)[:, None])
    (tmp_path / "a.txt").write_text("1 2\n")
    args = [a.format(tmp=tmp_path) for a in args]
    with pytest.raises(SystemExit, match=message):
        field.EXPERIMENT.main(["--scale", "smoke", "--out", str(tmp_path), "--quiet", *args])


def test_an_experiment_that_draws_its_own_sets_refuses_input(tmp_path):
    from experiments.beyond import distributed
    with pytest.raises(SystemExit, match="not supported"):
        distributed.EXPERIMENT.main(["--scale", "smoke", "--input", str(tmp_path / "x.npy"),
                                     "--out", str(tmp_path)])
