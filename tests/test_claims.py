"""experiments.core.claims: the verdict rules at their thresholds, and a
claim judged from its experiment's declaration alone."""
import math

from experiments.core import registry, report, results
from experiments.core.claims import (FAILS, HOLDS, MISSING, PARTLY, AtLeast, AtMost, Claim,
                                     Results, Row, Share, judge)
from experiments.core.experiment import Experiment
from experiments.core.runner import Cell


def test_at_least_and_at_most_bands():
    rule = AtLeast(holds=0.95, partly=0.4)
    assert [rule(v) for v in (1.2, 0.95, 0.94, 0.4, 0.39, math.nan)] == \
        [HOLDS, HOLDS, PARTLY, PARTLY, FAILS, FAILS]
    assert AtLeast(holds=1.02)(1.01) == FAILS  # no partly band: holds or not
    rule = AtMost(holds=0.2, partly=0.5)
    assert [rule(v) for v in (0.0, 0.2, 0.21, 0.5, 0.51, math.nan)] == \
        [HOLDS, HOLDS, PARTLY, PARTLY, FAILS, FAILS]


def test_share_counts_the_cases_that_agree():
    assert Share(holds=1.0)(3, 3) == HOLDS
    assert Share(holds=1.0)(2, 3) == PARTLY
    assert Share(holds=0.5)(2, 4) == HOLDS
    assert Share(holds=0.5)(0, 4) == FAILS
    assert Share()(0, 0) == MISSING


def _store(root, sizes):
    outcome = {"status": "ok", "seconds": [1.0], "cycles": [3e9], "peak_bytes": 0, "version": "",
               "counts": {}}
    rows = [r for n in sizes for r in results.rows_for(Cell("lfqt-dc", "uniform", n), "made_up",
                                                         outcome)]
    (root / "made_up").mkdir(exist_ok=True)
    results.write(root / "made_up", rows)


def _experiment(judge_fn, name="made_up"):
    claim = Claim("a made-up claim", "stated somewhere", judge_fn, rule=AtLeast(holds=2.0),
                  limits={"n": 10})
    return Experiment(name, "a made-up experiment", lambda scale, threads: [],
                      lambda df, out: [], claims=(claim,))


def test_a_claim_is_judged_from_its_declaration(tmp_path, monkeypatch):
    """A new claim lives in its experiment's module alone: the report finds
    it through the registry, names the command while nothing is stored, and
    renders the claim's own row once results exist."""
    def judge_fn(claim, res):
        df = res.frame("made_up")
        return claim.row(f"{len(df)} rows, n = {claim.limits['n']}", claim.rule(len(df)), "why")

    exp = _experiment(judge_fn)
    monkeypatch.setattr(registry, "sections", lambda: [("A section", [exp])])
    monkeypatch.setattr(registry, "experiments", lambda: {exp.name: exp})
    assert "| 1 | a made-up claim | stated somewhere | - | **not measured yet** | run " \
           "`python -m experiments.made_up` | made_up |" in report.render(tmp_path, "default")
    _store(tmp_path, (10, 20, 30))
    row, = judge(exp, Results(tmp_path))
    assert row == Row("a made-up claim", "stated somewhere", "3 rows, n = 10", HOLDS, "why",
                      "made_up")
    assert "| 1 | a made-up claim | stated somewhere | 3 rows, n = 10 | **holds** |" in \
        report.render(tmp_path, "default")


def test_a_judge_may_give_its_own_reason_for_missing(tmp_path):
    exp = _experiment(lambda claim, res: claim.missing("needs two sizes"))
    _store(tmp_path, (10,))
    row, = judge(exp, Results(tmp_path))
    assert (row.verdict, row.why, row.source) == (MISSING, "needs two sizes", "made_up")


def test_every_declared_claim_has_its_rule_or_judge():
    claims = [c for e in registry.experiments().values() for c in e.claims]
    assert len(claims) >= 24
    for c in claims:
        assert c.text and c.published and callable(c.judge)
        assert c.rule is None or callable(c.rule)


def test_bench_dc_judges_what_a_program_sees_in_every_regime_on_one_thread(tmp_path):
    """The worst regime decides, lfqt on one thread; its two-thread rows are
    reported beside them and do not pool into the one-thread medians; a
    regime not measured leaves the claim not measured."""
    from experiments.bench import bench_dc
    times = {("lfqt-dc", 1): {"loop": 0.2, "kept": 0.25, "fresh": 0.3},
             ("lfqt-dc", 2): {"loop": 0.1, "kept": 0.1, "fresh": 0.1},
             ("cgal-dt2", 1): {"loop": 0.5, "kept": 0.5, "fresh": 0.5},
             ("triangle-native", 1): {"loop": 1.0, "kept": 1.0, "fresh": 1.0}}
    rows = []
    for (peer, threads), by_regime in times.items():
        for regime, t in by_regime.items():
            outcome = {"status": "ok", "seconds": [t, t], "cycles": [1, 1], "peak_bytes": 0,
                       "version": "", "counts": {}}
            cell = Cell(peer, "uniform", 1_000_000, threads=threads, regime=regime)
            rows += results.rows_for(cell, "bench_dc", outcome)
    (tmp_path / "bench_dc").mkdir()
    results.write(tmp_path / "bench_dc", rows)
    row, = judge(bench_dc.EXPERIMENT, Results(tmp_path))
    assert row.verdict == PARTLY  # CGAL on a first call: 0.5 / 0.3 = 1.67x, 67% of 2.5x
    assert "67%" in row.why
    assert "loop, 1 thread: lfqt 0.200 s, CGAL 2.50x (cgal-dt2)" in row.ours
    assert "fresh, 2 threads: lfqt 0.100 s, CGAL 5.00x" in row.ours
    results.write(tmp_path / "bench_dc", [r for r in rows if r["regime"] != "fresh"])
    row, = judge(bench_dc.EXPERIMENT, Results(tmp_path))
    assert row.verdict == MISSING and "--regime loop,kept,fresh" in row.why
