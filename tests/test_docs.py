"""The documentation under docs/: the Sphinx site builds without a warning
(as the README tells a reader to build it), the Python examples of its pages
run, every object of the API reference has a numpydoc Examples section
(tests/test_doctests.py runs them), and every ``python -m`` command the
pages show names a module that exists."""
import importlib
import importlib.util
import inspect
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"
PAGES = sorted(DOCS.glob("*.md"))
# Modules the harness page writes as examples of a new peer or experiment:
# they are not in the repository.
EXAMPLE_MODULES = {"experiments.uniform_race"}


def _blocks(page, language):
    return re.findall(rf"^```{language}\n(.*?)^```", page.read_text(), re.S | re.M)


def test_the_site_builds_without_warnings(tmp_path):
    pytest.importorskip("sphinx")
    out = tmp_path / "html"
    proc = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html",
                           "-d", str(tmp_path / "doctrees"), str(DOCS), str(out)],
                          cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-4000:]
    for page in ["index", "getting-started", "api", "exactness", "harness", "performance",
                 "changelog"]:
        assert (out / f"{page}.html").exists(), page
    api = (out / "api.html").read_text()
    for name in _documented():
        full = name if name.startswith("lfqt.") else f"lfqt.{name}"
        assert f'id="{full}"' in api, f"{full} has no entry on the API page"
    performance = (out / "performance.html").read_text()
    assert "Performance log" in performance  # docs/performance.md, through myst-parser


def _documented():
    """The objects the API page documents, as it names them."""
    text = (DOCS / "api.rst").read_text()
    return re.findall(r"^\.\. auto(?:function|class):: (\S+)", text, re.M)


def _resolve(name):
    parts = (name if name.startswith("lfqt.") else f"lfqt.{name}").split(".")
    for cut in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:cut]))
        except ImportError:
            continue
        for attr in parts[cut:]:
            obj = getattr(obj, attr)
        return obj
    raise ImportError(name)


def test_every_object_of_the_api_reference_has_examples():
    names = _documented()
    assert {"triangulate", "insert", "verify", "Delaunay", "Triangulation", "VerifyReport",
            "DegenerateInputError", "quadtree", "lfqt.orders.order",
            "lfqt.workspace.release"} <= set(names)
    missing = [n for n in names if "Examples\n--------" not in (inspect.getdoc(_resolve(n)) or "")]
    assert not missing, f"no numpydoc Examples section: {missing}"


def test_the_python_examples_of_the_pages_run():
    """Each ```python block of getting-started.md and exactness.md, in a
    fresh namespace, in one child process (the harness page's blocks are
    modules to add, not scripts)."""
    blocks = [b for name in ("getting-started", "exactness") for b in
              _blocks(DOCS / f"{name}.md", "python")]
    assert len(blocks) >= 5
    script = textwrap.dedent("""
        import sys
        for i, block in enumerate(BLOCKS):
            try:
                exec(compile(block, f"<docs block {i}>", "exec"), {"__name__": "__main__"})
            except BaseException as e:
                print(f"block {i} failed: {e!r}", file=sys.stderr)
                raise
        """).replace("BLOCKS", repr(blocks))
    proc = subprocess.run([sys.executable, "-c", script], cwd=ROOT, capture_output=True,
                          text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-4000:]


def test_every_module_a_command_names_exists():
    shown = {m for page in PAGES for block in _blocks(page, "sh")
             for m in re.findall(r"python -m ([\w.]+)", block)}
    shown |= {m for page in PAGES for m in re.findall(r"`python -m ([\w.]+)", page.read_text())}
    assert {"experiments", "experiments.all", "experiments.bench_dc", "drivers"} <= shown
    sys.path.insert(0, str(ROOT))
    try:
        gone = [m for m in sorted(shown - EXAMPLE_MODULES) if importlib.util.find_spec(m) is None]
    finally:
        sys.path.remove(str(ROOT))
    assert not gone
