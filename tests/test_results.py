"""experiments.results: tidy rows, the typed DataFrame, summaries, and the
published values."""
import csv

import numpy as np
import pytest

from experiments import results
from experiments.runner import Cell


def test_every_published_csv_parses_the_same_with_pandas_and_csv():
    paths = sorted(results.PUBLISHED.glob("*.csv"))
    assert paths
    for path in paths:
        with open(path, newline="") as f:
            rows = list(csv.DictReader(f))
        frame = results.published(path.stem)
        assert all(None not in r and len(r) == len(frame.columns) for r in rows), path
        assert list(frame.columns) == list(rows[0])
        assert frame.to_dict("records") == rows


def _outcome(seconds):
    return {"status": "ok", "seconds": seconds, "cycles": [3_000_000] * len(seconds),
            "peak_bytes": 4000, "version": "1", "counts": {"orientation_tests": 7}}


def test_rows_load_typed_and_summaries_pool_rounds(tmp_path):
    a, b = Cell("lfqt-dc", "uniform", 1000), Cell("triangle", "uniform", 1000, round=1)
    rows = (results.rows_for(a, "t", _outcome([0.4, 0.1, 0.2]))
            + results.rows_for(Cell("lfqt-dc", "uniform", 1000, round=1), "t", _outcome([0.3]))
            + results.rows_for(b, "t", {"status": "timeout", "detail": "no result within 1 s"}))
    results.write(tmp_path, rows)
    df = results.load(tmp_path)
    assert len(df) == 5 and df["n"].dtype == np.int64 and df["count"].dtype == bool
    assert df.loc[0, "counts"] == {"orientation_tests": 7}
    assert df.loc[0, "mpts_per_s"] == pytest.approx(1000 / 0.4 / 1e6)
    assert df.loc[0, "seconds_at_3ghz"] == pytest.approx(1e-3)
    s = results.summarize(df)
    ours = results.cell(s, "lfqt-dc", "uniform", 1000, False)
    assert ours["median"] == pytest.approx(0.25) and ours["min"] == pytest.approx(0.1)
    assert ours["runs"] == 4  # both rounds pooled
    theirs = results.cell(s, "triangle", "uniform", 1000, False)
    assert theirs["status"] == "timeout" and theirs["median"] is None
    assert results.cell(s, "cgal-dt2", "uniform", 1000, False) == {}
    assert results.fmt_ratio(results.ratio(None, 1.0)) == "-"


def test_a_log_line_cut_by_a_crash_is_skipped_and_the_next_record_survives(tmp_path):
    log = tmp_path / "cells.jsonl"
    with open(log, "a+") as f:
        results.append_log(f, {"key": "a", "v": 1})
        f.write('{"key": "b", "v"')  # the crash
    with open(log, "a+") as f:
        results.append_log(f, {"key": "c", "v": 3})
    done = results.read_log(log, lambda rec: rec["key"])
    assert {k: r["v"] for k, r in done.items()} == {"a": 1, "c": 3}
    assert results.read_log(tmp_path / "missing.jsonl", lambda rec: rec["key"]) == {}
