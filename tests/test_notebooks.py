"""The notebooks execute, top to bottom, on the smoke-scale results of the
main job, and each shows a figure and a table; their .ipynb twins hold the
same cells as the jupytext .py files they are paired with."""
from pathlib import Path

import pytest

jupytext = pytest.importorskip("jupytext")
nbclient = pytest.importorskip("nbclient")

NOTEBOOKS = Path(__file__).resolve().parent.parent / "notebooks"
NAMES = ["scaling", "cache"]


def _sources(nb):
    return [(c.cell_type, c.source.strip()) for c in nb.cells]


@pytest.mark.parametrize("name", NAMES)
def test_the_ipynb_is_the_paired_py(name):
    py = jupytext.read(NOTEBOOKS / f"{name}.py")
    ipynb = jupytext.read(NOTEBOOKS / f"{name}.ipynb")
    assert _sources(py) == _sources(ipynb), f"run: jupytext --sync notebooks/{name}.py"


@pytest.mark.parametrize("name", NAMES)
def test_notebook_runs_on_smoke_results(name, smoke_results, monkeypatch):
    root, _ = smoke_results
    monkeypatch.setenv("LFQT_SCALE", "smoke")
    monkeypatch.setenv("LFQT_RESULTS", str(root.parent))  # the scale's folder is below
    monkeypatch.setenv("LFQT_PROJECT", str(NOTEBOOKS.parent))
    nb = jupytext.read(NOTEBOOKS / f"{name}.py")
    nbclient.NotebookClient(nb, timeout=600, kernel_name="python3",
                            resources={"metadata": {"path": str(NOTEBOOKS)}}).execute()
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])]
    assert not [o for o in outputs if o.output_type == "error"]
    assert any("image/png" in o.get("data", {}) for o in outputs), "no figure"
    text = "\n".join(o.get("text", "") for o in outputs if o.output_type == "stream")
    assert "no fig4 results" not in text
    assert len([line for line in text.splitlines() if line.count("  ") >= 3]) >= 3, "no table"
