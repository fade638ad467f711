"""The architecture's rules, checked on the source: the library never imports
the harness, no package has an import cycle, no library function is longer
than 150 lines, takes more than 10 arguments or returns a tuple of more than
4 (a kernel's state travels as a small named record instead)."""
import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PACKAGES = ("lfqt", "generators", "drivers", "experiments")


def _module_name(path):
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path):
    """Project modules imported by the file at ``path`` (absolute names)."""
    name = _module_name(path)
    package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    out = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[:len(package.split(".")) - node.level + 1]
                base = ".".join(anchor + ([base] if base else []))
            out.add(base)
            out |= {f"{base}.{a.name}" for a in node.names}
    return {m for m in out if m.split(".")[0] in PACKAGES}


def _graph():
    files = {_module_name(p): p for pkg in PACKAGES for p in (ROOT / pkg).rglob("*.py")}
    return {m: {i for i in _imports(p) if i in files and i != m} for m, p in files.items()}


def test_the_library_never_imports_the_harness():
    bad = {m: sorted(i for i in deps if not i.startswith("lfqt"))
           for m, deps in _graph().items() if m.startswith("lfqt")}
    assert not {m: d for m, d in bad.items() if d}


def test_no_import_cycles():
    graph = _graph()
    state = {}

    def visit(m, path):
        state[m] = "open"
        for d in graph[m]:
            if d.startswith(m + "."):
                continue  # a package importing its own submodules is not a cycle
            if state.get(d) == "open":
                pytest.fail("import cycle: " + " -> ".join(path + [d]))
            if d not in state:
                visit(d, path + [d])
        state[m] = "done"

    for m in graph:
        if m not in state:
            visit(m, [m])


def test_no_library_function_is_longer_than_150_lines():
    long = [(str(p.relative_to(ROOT)), node.name, node.end_lineno - node.lineno + 1)
            for p in (ROOT / "lfqt").rglob("*.py") for node in ast.walk(ast.parse(p.read_text()))
            if isinstance(node, ast.FunctionDef) and node.end_lineno - node.lineno >= 150]
    assert not long


def _harness_graph():
    return {m: deps for m, deps in _graph().items() if m.startswith("experiments")}


def _section(module):
    """The section an experiments module sits in, or None for the machinery
    (experiments.core, and the package's own commands)."""
    import experiments
    parts = module.split(".")
    return parts[1] if len(parts) > 2 and parts[1] in experiments.SECTIONS else None


def test_the_harness_machinery_never_imports_an_experiment():
    """experiments.core (runner, results, registry, report, ...) and the
    package's commands find the experiments through the registry alone: no
    import names an experiment module, so the report renders what each
    experiment declares and imports none of their internals."""
    graph = _harness_graph()
    machinery = [m for m in graph if _section(m) is None]
    assert "experiments.core.report" in machinery and "experiments.core.registry" in machinery
    bad = {m: sorted(d for d in graph[m] if _section(d)) for m in machinery}
    assert not {m: d for m, d in bad.items() if d}


def test_experiments_import_only_the_machinery_and_their_own_section():
    graph = _harness_graph()
    bad = {m: sorted(d for d in deps if _section(d) not in (None, _section(m)))
           for m, deps in graph.items() if _section(m)}
    assert not {m: d for m, d in bad.items() if d}


def test_the_report_holds_no_threshold():
    """Thresholds are named data beside each claim's rule, in its
    experiment's module: the report's source compares nothing with a
    number and holds no fraction."""
    tree = ast.parse((ROOT / "experiments" / "core" / "report.py").read_text())

    def number(node):
        return (isinstance(node, ast.Constant) and isinstance(node.value, (int, float))
                and not isinstance(node.value, bool))
    fractions = [n.value for n in ast.walk(tree) if number(n) and isinstance(n.value, float)]
    compared = [ast.unparse(n) for n in ast.walk(tree) if isinstance(n, ast.Compare)
                and any(number(x) for x in [n.left, *n.comparators])]
    assert not fractions and not compared


MAX_ARGUMENTS = 10
MAX_RETURNED = 4
def _functions():
    for p in sorted((ROOT / "lfqt").rglob("*.py")):
        for node in ast.walk(ast.parse(p.read_text())):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                yield str(p.relative_to(ROOT)), node


def _arguments(node):
    a = node.args
    return (len(a.posonlyargs) + len(a.args) + len(a.kwonlyargs) + (a.vararg is not None)
            + (a.kwarg is not None))


def _returned(node):
    """The largest tuple a return statement of ``node`` (not of a function
    nested in it) writes out."""
    def walk(n):
        for child in ast.iter_child_nodes(n):
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)):
                continue
            yield child
            yield from walk(child)
    return max((len(r.value.elts) for r in walk(node)
                if isinstance(r, ast.Return) and isinstance(r.value, ast.Tuple)), default=0)


def test_the_rule_counts_arguments_and_returned_tuples():
    node = ast.parse("def f(a, b, *c, d=1, **e):\n    def g():\n        return 1, 2, 3, 4, 5\n"
                     "    return a, b\n").body[0]
    assert _arguments(node) == 5
    assert _returned(node) == 2


def _breaking():
    return {(path, node.name): (_arguments(node), _returned(node)) for path, node in _functions()
            if _arguments(node) > MAX_ARGUMENTS or _returned(node) > MAX_RETURNED}


def test_no_library_function_takes_more_than_10_arguments():
    many = {k: v[0] for k, v in _breaking().items() if v[0] > MAX_ARGUMENTS }
    assert not many


def test_no_library_function_returns_a_tuple_of_more_than_4():
    wide = {k: v[1] for k, v in _breaking().items() if v[1] > MAX_RETURNED }
    assert not wide
