"""The one registry of experiments: every module of a section package
(experiments.SECTIONS: paper1, paper2, beyond, bench) that declares an
``EXPERIMENT`` (experiments.core.experiment.Experiment), found by walking
the sections, and the catalogue of the papers' published figures and tables
they regenerate (each paper's package declares its own)."""
import importlib
import os
import pkgutil
from functools import lru_cache

from . import results
from .experiment import MAIN_JOB_MINUTES, results_root


@lru_cache(maxsize=None)
def _sections():
    """[(section package, [its Experiments])], in experiments.SECTIONS'
    order; within a section, in the paper's order of the items they
    reproduce, then by name."""
    import experiments as package
    out = []
    for section in package.SECTIONS:
        pkg = importlib.import_module(f"{package.__name__}.{section}")
        found = []
        for m in pkgutil.iter_modules(pkg.__path__):
            mod = importlib.import_module(f"{pkg.__name__}.{m.name}")
            if hasattr(mod, "EXPERIMENT"):
                found.append(mod.EXPERIMENT)
        order = [(getattr(pkg, "PAPER", None), item) for item in getattr(pkg, "PUBLISHED", ())]
        first = {e.name: min((order.index(i) for i in e.reproduces if i in order),
                             default=len(order)) for e in found}
        out.append((pkg, sorted(found, key=lambda e: (first[e.name], e.name))))
    return out


def sections():
    """[(title, [Experiment])] of every section, in the report's order."""
    return [(pkg.TITLE, exps) for pkg, exps in _sections()]


def experiments():
    """{name: Experiment} of every experiment, section by section."""
    return {e.name: e for _, exps in _sections() for e in exps}


def papers():
    """{paper: its section's title}, e.g. {"Paper 1": "Paper 1: Fuetterling, ..."}."""
    return {pkg.PAPER: pkg.TITLE for pkg, _ in _sections() if hasattr(pkg, "PAPER")}


def published():
    """Every result of both papers, as (paper, item), in the papers' order."""
    return [(pkg.PAPER, item) for pkg, _ in _sections() if hasattr(pkg, "PAPER")
            for item in pkg.PUBLISHED]


def main_job():
    """The experiments ``python -m experiments.all`` runs."""
    return [e for e in experiments().values() if e.main_job]


def main_job_minutes():
    """{name: minutes at the default scale on 2 cores} of the main job's
    experiments, as each declares it (None where it does not)."""
    return {e.name: (e.minutes or {}).get("default") for e in main_job()}


def listing():
    """One line per published figure or table and the command that
    regenerates it, then the benchmarks; the main job's experiments are
    marked with their minutes at the default scale, totalled at the end."""
    exps = experiments()
    by_item = {item: e for e in exps.values() for item in e.reproduces}
    minutes = main_job_minutes()

    def mark(e):
        if e.name not in minutes:
            return ""
        m = minutes[e.name]
        return f" [main job, ~{m:g} min]" if m is not None else " [main job]"
    lines = []
    for item in published():
        e = by_item.get(item)
        what = f"{e.command:38s} {e.title}{mark(e)}" if e else "(not reproduced yet)"
        lines.append(f"{item[0]} {item[1]:9s} {what}")
    for e in exps.values():
        if not e.reproduces:
            kind = "benchmark" if e.name.startswith("bench") else "analysis"
            lines.append(f"{kind:17s} {e.command:38s} {e.title}{mark(e)}")
    total = sum(m for m in minutes.values() if m is not None)
    lines.append(f"main job: {'python -m experiments.all':38s} the {len(minutes)} experiments "
                 f"marked [main job] at the default scale, then results/REPORT.md: ~{total:g} "
                 f"min measured on 2 shared cores (budget: {MAIN_JOB_MINUTES} min on 2 quiet "
                 "cores)")
    return "\n".join(lines)


def for_notebook(default_root):
    """(scale, results root, stored) as a notebook reads them from the
    environment: LFQT_SCALE (default "default"), LFQT_RESULTS (default
    ``default_root``), and LFQT_RUN_MISSING=1 to run a missing smoke-scale
    experiment first.  ``stored(name)`` is the experiment's DataFrame or
    None, after a line naming the command that makes it."""
    scale = os.environ.get("LFQT_SCALE", "default")
    root = results_root(os.environ.get("LFQT_RESULTS", default_root), scale)
    run_missing = os.environ.get("LFQT_RUN_MISSING") == "1" and scale == "smoke"

    def fetch(name):
        df = results.stored(root, name, scale)
        if df is None and run_missing:
            experiments()[name].main(["--scale", "smoke", "--out", str(root.parent), "--quiet"])
            df = results.stored(root, name, scale)
        return df
    return scale, root, fetch
