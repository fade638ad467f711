"""experiments.core.results: tidy rows, the typed DataFrame, summaries, and the
published values."""
import csv

import numpy as np
import pytest

from experiments.core import results
from experiments.core.runner import Cell


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


def test_round_ratio_pairs_each_rounds_medians_before_pooling(tmp_path):
    """A slow second round (the machine drifting) doubles both peers' times,
    and more of the peer's runs fell in it: pooled medians pair lfqt's fast
    runs with the peer's slow ones (2.5x), same-round medians give 2x and
    2.2x.  A round that timed only one peer counts for nothing."""
    rows = []
    for rnd, (ours, theirs) in enumerate([([0.10, 0.11, 0.12], [0.20, 0.22, 0.24]),
                                          ([0.20, 0.22], [0.40, 0.44, 0.48, 0.50])]):
        rows += results.rows_for(Cell("lfqt-dc", "uniform", 1000, round=rnd), "t",
                                 _outcome(ours))
        rows += results.rows_for(Cell("cgal-dt2", "uniform", 1000, round=rnd), "t",
                                 _outcome(theirs))
    rows += results.rows_for(Cell("lfqt-dc", "uniform", 1000, round=2), "t", _outcome([0.9]))
    rows += results.rows_for(Cell("cgal-dt2", "uniform", 1000, round=2), "t",
                             {"status": "timeout", "detail": "no result within 1 s"})
    results.write(tmp_path, rows)
    df = results.load(tmp_path)
    s = results.summarize(df)
    pooled = results.ratio(results.median(s, "cgal-dt2", "uniform", 1000, False),
                           results.median(s, "lfqt-dc", "uniform", 1000, False))
    assert pooled == pytest.approx(0.40 / 0.16)  # the slow round dominates the peer's median
    r, per = results.round_ratio(df, "cgal-dt2", "lfqt-dc", "uniform", 1000, False)
    assert per == pytest.approx([0.22 / 0.11, 0.46 / 0.21]) and r == pytest.approx(np.median(per))
    assert results.round_ratio(df, "cgal-dt2", "lfqt-dc", "grid", 1000, False)[1] == []
    assert results.round_ratio(df, "triangle", "lfqt-dc", "uniform", 1000, False)[1] == []


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
