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


MAX_ARGUMENTS = 10
MAX_RETURNED = 4
# Functions that still break the rule, in files other sessions were reshaping
# when it came in (issue 54): each is to be fixed there and its entry removed;
# test_the_waiting_list_only_shrinks fails once an entry keeps the rule.
WAITING = {("lfqt/dc/__init__.py", "_state"),          # memory and workspace (the lead)
           ("lfqt/dc/__init__.py", "_sorted_points"),
           ("lfqt/dc/__init__.py", "_output"),
           ("lfqt/location.py", "_flat")}              # location and interpolation


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
    many = {k: v[0] for k, v in _breaking().items() if v[0] > MAX_ARGUMENTS and k not in WAITING}
    assert not many


def test_no_library_function_returns_a_tuple_of_more_than_4():
    wide = {k: v[1] for k, v in _breaking().items() if v[1] > MAX_RETURNED and k not in WAITING}
    assert not wide


def test_the_waiting_list_only_shrinks():
    assert not WAITING - set(_breaking())  # fixed: remove its entry
