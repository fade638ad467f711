"""The harness's experiments, apart from the machinery that runs them.

    core/     the machinery: what an experiment declares (experiment.py, and
              claims.py for its verdicts), the runner, the results store, the
              machine's description, the registry, the report, the probes
    paper1/   Fuetterling, Lojewski and Pfreundt 2014 (fqDel): one module per
              figure or table
    paper2/   Liu, Yan and Lo 2013 (Kd-tree insertion order): one module per
              group of tables, liu.py what they share
    beyond/   questions beyond the papers (hybrid, distributed, the field of
              2026, the scipy surface)
    bench/    the benchmarks against the peers

Every experiment module declares one ``EXPERIMENT`` (its grid, its plot, the
published items it reproduces, its claims) and runs by its short name, as it
did before the sections existed: ``python -m experiments.fig3`` is
``experiments.paper1.fig3``'s command line, and ``import experiments.fig3``
gives that module.  The short names are found on demand (_ShortNames) rather
than kept as a file each, so that the package's top level shows its layout."""
import importlib
import importlib.abc
import importlib.machinery
import sys
from pathlib import Path

# The sections holding experiments, in the report's order.
SECTIONS = ("paper1", "paper2", "beyond", "bench")
# Machinery that is also a command: its short name and its module.
COMMANDS = {"report": "core.report"}
_HERE = Path(__file__).resolve().parent


def module_of(short):
    """The full name of the experiment (or command) called ``short``, or None."""
    if short in COMMANDS:
        return f"{__name__}.{COMMANDS[short]}"
    for section in SECTIONS:
        if (_HERE / section / f"{short}.py").is_file():
            return f"{__name__}.{section}.{short}"
    return None


class _ShortNames(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """``experiments.<short>`` as an alias of the module it names: imported,
    it is that very module (never a second copy); run with ``python -m``,
    it runs that module's ``main``.  It answers only for names that are not
    a module of this package's top level, and it is consulted first (an
    editable install's finder would otherwise look for the short name in
    the installed checkout)."""

    def find_spec(self, fullname, path=None, target=None):
        parent, _, short = fullname.rpartition(".")
        real = module_of(short) if parent == __name__ else None
        if real is None or (_HERE / f"{short}.py").exists():
            return None
        return importlib.machinery.ModuleSpec(fullname, self, origin=real)

    def create_module(self, spec):
        return None  # a placeholder, replaced by the real module in exec_module

    def exec_module(self, module):
        sys.modules[module.__name__] = importlib.import_module(module.__spec__.origin)

    def get_code(self, fullname):
        # runpy (``python -m``) executes this code as __main__
        real = module_of(fullname.rpartition(".")[2])
        # guarded: a process spawned by multiprocessing (the fresh regime's)
        # runs this code again as __mp_main__, and must not run main there
        return compile(f"import sys\nfrom {real} import main\nif __name__ == '__main__':\n"
                       "    sys.exit(main())\n", f"<{fullname}, running {real}>", "exec")


if not any(isinstance(f, _ShortNames) for f in sys.meta_path):
    sys.meta_path.insert(0, _ShortNames())
