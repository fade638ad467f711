"""The one registry of experiments: every module of this package that
declares an ``EXPERIMENT`` (experiments.experiment.Experiment), and the
catalogue of the papers' published figures and tables they regenerate."""
import importlib
import os
import pkgutil

from . import results
from .experiment import results_root

_NOT_EXPERIMENTS = {"__main__", "all", "experiment", "liu", "machine", "perf", "registry",
                    "report", "results", "runner"}

# Every result of both papers, in the papers' order.
PUBLISHED = ([("Paper 1", f"Fig. {k}") for k in (1, 3, 4, 5, 6, 7)] + [("Paper 1", "Table 1")]
             + [("Paper 2", f"Table {k}") for k in range(1, 18)])
PAPERS = {"Paper 1": "Fuetterling, Lojewski and Pfreundt 2014 (fqDel)",
          "Paper 2": "Liu, Yan and Lo 2013 (Kd-tree insertion order)"}


def experiments():
    """{name: Experiment} of every experiment module, in name order."""
    import experiments as package
    found = {}
    for m in pkgutil.iter_modules(package.__path__):
        if m.name in _NOT_EXPERIMENTS:
            continue
        mod = importlib.import_module(f"{package.__name__}.{m.name}")
        if hasattr(mod, "EXPERIMENT"):
            found[mod.EXPERIMENT.name] = mod.EXPERIMENT
    return found


def main_job():
    """The experiments ``python -m experiments.all`` runs."""
    return [e for e in experiments().values() if e.main_job]


def listing():
    """One line per published figure or table and the command that
    regenerates it, then the benchmarks."""
    exps = experiments()
    by_item = {item: e for e in exps.values() for item in e.reproduces}
    lines = []
    for item in PUBLISHED:
        e = by_item.get(item)
        what = f"{e.command:38s} {e.title}" if e else "(not reproduced yet)"
        lines.append(f"{item[0]} {item[1]:9s} {what}")
    for e in exps.values():
        if not e.reproduces:
            kind = "benchmark" if e.name.startswith("bench") else "analysis"
            lines.append(f"{kind:17s} {e.command:38s} {e.title}")
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
