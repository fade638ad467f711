"""Triangle compiled from its own source with our flags, timed in-process by
our small C driver (driver.c beside this file): its divide and conquer
(``triangle-native``, the default), incremental and sweepline algorithms.

``python -m drivers build`` downloads the ``triangle`` package's source
distribution with pip (the last release that ships one carries Triangle
1.6's ``triangle.c``), inserts four counters into a copy of that source and
compiles it; nothing of Triangle is committed.  The counters count every
orientation and in-circle test and those that Triangle's stage-1 filter
leaves to its adaptive stages (paper 1, Table 1), without touching the
arithmetic: each edit adds one increment statement and is checked to apply
exactly once.
"""
import json
import shutil
import subprocess
import sys
import tarfile
import tempfile
from pathlib import Path

from ..base import CompiledPeer

HERE = Path(__file__).resolve().parent
BUILD_DIR = HERE / "build"
BINARY = BUILD_DIR / "triangle_driver"
SDIST = "triangle==20200424"  # the newest release of the package that ships its C source
FLAGS = ["-O3", "-march=native", "-ffp-contract=off"]  # as the CGAL driver; no FMA in the predicates
DEFINES = ["-DTRILIBRARY", "-DANSI_DECLARATORS", "-DREAL=double", "-DVOID=void", "-DNO_TIMER"]
INSTALL = "python -m drivers build (downloads the triangle sdist with pip, needs gcc)"
COUNTERS = "long lfqt_orient_calls, lfqt_orient_undecided, lfqt_incircle_calls, " \
           "lfqt_incircle_undecided;\n"
# (text in triangle.c, the same text with one counter increment added)
EDITS = [("  m->counterclockcount++;\n", "  m->counterclockcount++;\n  lfqt_orient_calls++;\n"),
         ("  return counterclockwiseadapt(pa, pb, pc, detsum);\n",
          "  lfqt_orient_undecided++;\n  return counterclockwiseadapt(pa, pb, pc, detsum);\n"),
         ("  m->incirclecount++;\n", "  m->incirclecount++;\n  lfqt_incircle_calls++;\n"),
         ("  return incircleadapt(pa, pb, pc, pd, permanent);\n",
          "  lfqt_incircle_undecided++;\n  return incircleadapt(pa, pb, pc, pd, permanent);\n")]


def counted_source(text):
    """triangle.c with the counters; ValueError when an edit does not apply
    exactly once (another Triangle version)."""
    for old, new in EDITS:
        if text.count(old) != 1:
            raise ValueError(f"triangle.c has {text.count(old)} copies of {old.strip()!r}, "
                             "expected 1: not the Triangle 1.6 this build knows")
        text = text.replace(old, new)
    return COUNTERS + text


def build():
    """Download, count and compile; returns the exit code."""
    try:
        BUILD_DIR.mkdir(exist_ok=True)
        with tempfile.TemporaryDirectory() as tmp:
            subprocess.run([sys.executable, "-m", "pip", "download", "-q", "--no-deps",
                            "--no-binary", ":all:", SDIST, "-d", tmp], check=True)
            archive = next(Path(tmp).glob("triangle-*.tar.gz"))
            with tarfile.open(archive) as tar:
                members = {Path(m.name).name: m for m in tar.getmembers()
                           if m.name.endswith(("/c/triangle.c", "/c/triangle.h"))}
                source = tar.extractfile(members["triangle.c"]).read().decode("latin-1")
                header = tar.extractfile(members["triangle.h"]).read()
        (BUILD_DIR / "triangle.c").write_text(counted_source(source), encoding="latin-1")
        (BUILD_DIR / "triangle.h").write_bytes(header)
        cmd = ["gcc", *FLAGS, *DEFINES, "-I", str(BUILD_DIR), "-o", str(BINARY),
               str(HERE / "driver.c"), str(BUILD_DIR / "triangle.c"), "-lm"]
        subprocess.run(cmd, check=True)
        gcc = subprocess.run(["gcc", "-dumpfullversion"], capture_output=True, text=True,
                             check=True).stdout.strip()
        info = {"library": "Triangle", "version": f"Triangle 1.6 (PyPI {SDIST} sdist)",
                "compiler": f"gcc {gcc}", "flags": " ".join(FLAGS + DEFINES)}
        (BUILD_DIR / "build_info.json").write_text(json.dumps(info, indent=2))
    except (OSError, ValueError, KeyError, StopIteration, subprocess.CalledProcessError) as e:
        shutil.rmtree(BUILD_DIR, ignore_errors=True)
        print(f"building triangle-native failed: {e}", file=sys.stderr)
        return 1
    print(BINARY)
    return 0


class TriangleNative(CompiledPeer):
    family = "triangle_native"
    bytes_per_point = 400
    install = INSTALL
    NAMES = {"": "triangle-native", "i": "triangle-native-incremental",
             "F": "triangle-native-sweepline"}

    def __init__(self, switches=""):
        self.switches = switches
        self.name = self.NAMES[switches]
        self.binary = BINARY

    def arguments(self, points_path, count):
        return [self.switches, points_path]

    def counts(self, r):
        keys = ("orientation_tests", "orientation_stage1_undecided", "incircle_tests",
                "incircle_stage1_undecided")
        return {k: r[k] for k in keys}


PEERS = {name: (lambda s: lambda: TriangleNative(s))(s) for s, name in TriangleNative.NAMES.items()}
