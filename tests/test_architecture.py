"""The architecture's rules, checked on the source: the library never imports
the harness, no package has an import cycle, no library function is longer
than 150 lines."""
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
