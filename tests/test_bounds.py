"""Nothing reads or writes outside its arrays: the merge, insertion and input
tests run once more in a child process with numba's bounds checking on (a
fresh cache, so that every kernel is compiled with the checks)."""
import os
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
CHECKED = ["test_dc.py", "test_parallel.py", "test_insert.py", "test_input.py"]


def test_kernels_stay_inside_their_arrays(tmp_path):
    env = dict(os.environ, NUMBA_BOUNDSCHECK="1", NUMBA_CACHE_DIR=str(tmp_path / "numba"))
    proc = subprocess.run([sys.executable, "-m", "pytest", "-q", "-x", "-p", "no:cacheprovider",
                           *[str(HERE / f) for f in CHECKED]], cwd=HERE.parent, env=env,
                          capture_output=True, text=True, timeout=1500)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-2000:]
    assert " passed" in proc.stdout.splitlines()[-1]
