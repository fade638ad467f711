"""The wheel is the library alone: ``lfqt`` with its ``py.typed`` and the
licence, and no other top-level package (the harness, the tests and the
benchmarks run from the repository and must not land in a user's
site-packages as ``experiments``, ``drivers``, ...)."""
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
# Not copied into the build: outputs, environments and caches, which a
# stale build/lib would otherwise carry into the wheel.
SKIP = shutil.ignore_patterns(".git", ".venv", ".asv", ".hypothesis", ".pytest_cache",
                              ".benchmarks", "results", "build", "_build", "*.egg-info",
                              "__pycache__", "*.npy")


@pytest.fixture(scope="module")
def wheel(tmp_path_factory):
    """A wheel built from a clean copy of the repository: {name: bytes}."""
    tmp = tmp_path_factory.mktemp("wheel")
    src = tmp / "src"
    shutil.copytree(ROOT, src, ignore=SKIP)
    proc = subprocess.run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps",
                           "--no-build-isolation", "-w", str(tmp / "dist"), str(src)],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    (path,) = (tmp / "dist").glob("lfqt-*.whl")
    with zipfile.ZipFile(path) as z:
        return {name: z.read(name) for name in z.namelist()}


def test_the_wheel_ships_lfqt_and_its_annotations(wheel):
    sources = {p.relative_to(ROOT).as_posix() for p in (ROOT / "lfqt").rglob("*.py")}
    assert sources <= set(wheel), sorted(sources - set(wheel))[:5]
    assert "lfqt/py.typed" in wheel


def test_no_other_top_level_package(wheel):
    tops = {name.split("/")[0] for name in wheel}
    dist_info = {t for t in tops if t.endswith(".dist-info")}
    assert len(dist_info) == 1
    assert tops - dist_info == {"lfqt"}
    for harness in ("experiments", "drivers", "generators", "tests", "benchmarks",
                    "micro_benchmarks", "notebooks", "docs"):
        assert not [n for n in wheel if n.startswith(harness + "/")], harness


def test_the_licence_is_in_the_dist_info(wheel):
    licences = [n for n in wheel if ".dist-info/" in n and n.rsplit("/", 1)[-1] == "LICENSE"]
    assert [wheel[n] for n in licences] == [(ROOT / "LICENSE").read_bytes()], list(wheel)
    assert b"BSD 3-Clause License" in wheel[licences[0]]
    (metadata,) = [n for n in wheel if n.endswith(".dist-info/METADATA")]
    fields = wheel[metadata].decode().split("\n\n", 1)[0].splitlines()
    assert "License-Expression: BSD-3-Clause" in fields
    assert "License-File: LICENSE" in fields
