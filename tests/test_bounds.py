"""Nothing reads or writes outside its arrays: the merge, insertion and input
tests run once more in a child process with numba's bounds checking on (a
fresh cache, so that every kernel is compiled with the checks).

The child starts as soon as the suite is collected with this test in it
(``start``, from conftest's pytest_collection_modifyitems), so that it runs
on the second core beside the rest of the suite, which is mostly single
threaded; the test, moved to the end, then waits for it."""
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
CHECKED = ["test_dc.py", "test_parallel.py", "test_insert.py", "test_input.py"]
TIMEOUT = 1500  # seconds, from the child's start
_child = {}


def start(config=None):
    """Start the bounds-checked run (once); ``config`` stops it at the end of
    the session if the test never waited for it."""
    if _child:
        return
    tmp = Path(tempfile.mkdtemp(prefix="lfqt-bounds-"))
    env = dict(os.environ, NUMBA_BOUNDSCHECK="1", NUMBA_CACHE_DIR=str(tmp / "numba"))
    log = open(tmp / "log", "w+")
    proc = subprocess.Popen([sys.executable, "-m", "pytest", "-q", "-x", "-p", "no:cacheprovider",
                             *[str(HERE / f) for f in CHECKED]], cwd=HERE.parent, env=env,
                            stdout=log, stderr=subprocess.STDOUT)
    _child.update(proc=proc, log=log, tmp=tmp)
    if config is not None:
        config.add_cleanup(_stop)


def _stop():
    if not _child:
        return
    proc, log, tmp = _child.pop("proc"), _child.pop("log"), _child.pop("tmp")
    if proc.poll() is None:
        proc.kill()
        proc.wait()
    log.close()
    shutil.rmtree(tmp, ignore_errors=True)


def test_kernels_stay_inside_their_arrays():
    start()
    try:
        returncode = _child["proc"].wait(timeout=TIMEOUT)
        _child["log"].seek(0)
        out = _child["log"].read()
    finally:
        _stop()
    assert returncode == 0, out[-5000:]
    assert " passed" in out.strip().splitlines()[-1], out[-3000:]
