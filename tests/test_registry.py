"""experiments.core.registry: one registry that --list and the main job read."""
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


def test_main_job_judges_every_claim_and_lists_its_minutes(capsys):
    from experiments.core.experiment import MAIN_JOB_MINUTES
    jobs = {e.name for e in registry.main_job()}
    assert {"liu_practical", "liu_hilbert", "hybrid", "distributed"} <= jobs
    judged = {e.name for e in registry.experiments().values() if e.claims}
    # judged by their own runs, each longer than the whole budget at its default scale
    # (bench_dc about 25 minutes, scipy_surface more than 30, dt3 about 30)
    assert judged - jobs == {"bench_dc", "scipy_surface", "dt3"}
    minutes = registry.main_job_minutes()
    assert set(minutes) == jobs and None not in minutes.values()
    assert cli.main(["--list"]) == 0
    lines = capsys.readouterr().out.splitlines()
    hybrid = next(l for l in lines if "python -m experiments.hybrid " in l)
    assert hybrid.endswith(f"[main job, ~{minutes['hybrid']:g} min]")
    assert not any("[main job" in l for l in lines if "experiments.bench_dc " in l)
    assert lines[-1].startswith("main job: ") and lines[-1].endswith(
        f"~{sum(minutes.values()):g} min measured on 2 shared cores (budget: "
        f"{MAIN_JOB_MINUTES} min on 2 quiet cores)")


def test_every_experiment_runs_by_its_short_name():
    """``python -m experiments.<name>`` and ``import experiments.<name>``
    reach the module in its section: the very module, not a copy."""
    import importlib
    import importlib.util
    import subprocess
    import sys
    for name, e in registry.experiments().items():
        assert importlib.util.find_spec(f"experiments.{name}") is not None
        module = importlib.import_module(f"experiments.{name}")
        assert module.EXPERIMENT is e and module.__name__.count(".") == 2
    assert importlib.util.find_spec("experiments.no_such_experiment") is None
    assert importlib.import_module("experiments.report").__name__ == "experiments.core.report"
    out = subprocess.run([sys.executable, "-m", "experiments.table1", "--help"],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0 and "usage: python -m experiments.table1" in out.stdout


def test_each_section_lists_what_its_modules_declare():
    import experiments
    sections = registry.sections()
    assert [t for t, _ in sections][:2] == list(registry.papers().values())
    assert len(sections) == len(experiments.SECTIONS)
    names = [e.name for _, exps in sections for e in exps]
    assert len(names) == len(set(names)) and "liu" not in names  # a helper module, no EXPERIMENT
