"""experiments.registry: one registry that --list and the main job read."""
from experiments import __main__ as cli
from experiments.core import registry


def test_every_published_item_is_listed_once_with_its_command(capsys):
    assert cli.main(["--list"]) == 0
    lines = capsys.readouterr().out.splitlines()
    exps = registry.experiments()
    for paper, item in registry.published():
        hits = [l for l in lines if l.startswith(f"{paper} {item} ")]
        assert len(hits) == 1, (paper, item)
        owner = [e for e in exps.values() if (paper, item) in e.reproduces]
        assert (owner[0].command in hits[0]) if owner else "not reproduced yet" in hits[0]
    assert any("python -m experiments.bench_dc" in l for l in lines)


def test_main_job_comes_from_the_registry():
    names = [e.name for e in registry.main_job()]
    assert {"fig3", "fig4", "liu_times", "liu_counts"} <= set(names)
    assert "bench_dc" not in names
