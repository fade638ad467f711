"""The benchmark scripts run end to end at a tiny scale."""
import csv

from experiments import bench_dc


def test_bench_dc_tiny_run(tmp_path, capsys):
    out = tmp_path / "bench"
    assert bench_dc.main(["--scale", "small", "--sizes", "3000", "--repeats", "1",
                          "--peers", "lfqt-dc,triangle", "--dists", "uniform,grid",
                          "--out", str(out), "--no-compile-time"]) == 0
    rows = list(csv.DictReader(open(out / "bench_dc.csv")))
    assert {(r["distribution"], r["peer"]) for r in rows} == {
        ("uniform", "lfqt-dc"), ("uniform", "triangle"), ("grid", "lfqt-dc"), ("grid", "triangle")}
    assert all(r["status"] == "ok" and float(r["median_s"]) > 0 for r in rows)
    assert (out / "bench_dc.meta.json").exists()
