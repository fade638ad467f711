"""lfqt.preload: the kernels of a first call are loaded by the import's
thread, and a fork while it runs does not hang.  Each check runs in a new
interpreter, the only place where nothing is loaded yet."""
import os
import subprocess
import sys
import textwrap

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

LOADED = textwrap.dedent("""
    import sys
    import numba.core.registry


    def loaded():
        out = {}
        for name, mod in list(sys.modules.items()):
            if name == "lfqt" or name.startswith("lfqt."):
                for attr, f in list(vars(mod).items()):
                    if isinstance(f, numba.core.registry.CPUDispatcher):
                        out[f"{name}.{attr}"] = set(map(str, f.signatures))
        return out
""")


def _run(code, preload="1", timeout=600):
    env = dict(os.environ, LFQT_PRELOAD=preload)
    res = subprocess.run([sys.executable, "-c", LOADED + textwrap.dedent(code)], cwd=ROOT,
                         env=env, capture_output=True, text=True, timeout=timeout)
    assert res.returncode == 0, res.stderr
    return res.stdout


def test_a_first_call_of_any_size_and_thread_count_loads_nothing_the_import_did_not():
    out = _run("""
        import numpy as np
        import lfqt
        from lfqt import preload
        from lfqt.workers import MIN_CHUNK
        preload.wait()
        before = loaded()
        assert sum(map(len, before.values())) > 10, before
        rng = np.random.default_rng(5)
        pts = rng.random((2 * MIN_CHUNK + 1000, 2))
        small = pts[:5000].astype(np.float32)
        tris = [lfqt.triangulate(pts, threads=t) for t in (1, 2)] + [lfqt.triangulate(small)]
        after = loaded()
        new = {k: v - before.get(k, set()) for k, v in after.items() if v - before.get(k, set())}
        assert all(lfqt.verify(p, t).ok for p, t in zip((pts, pts, small), tris))
        # a first call gives the same mesh on one thread and on two
        assert np.array_equal(tris[0].simplices, tris[1].simplices)
        assert np.array_equal(tris[0].neighbors, tris[1].neighbors)
        print("new:", new)
    """)
    assert out.strip() == "new: {}", out


def test_the_environment_turns_it_off():
    out = _run("""
        import lfqt
        from lfqt import preload
        preload.wait()
        print(preload._thread is None, sum(map(len, loaded().values())))
    """, preload="0")
    assert out.split() == ["True", "0"]


@pytest.mark.skipif(not hasattr(os, "fork"), reason="needs os.fork")
def test_a_fork_during_the_preload_waits_for_it_and_the_child_works():
    out = _run("""
        import os
        import numpy as np
        import lfqt
        from lfqt import preload
        pid = os.fork()  # at once: the thread is still loading
        if pid == 0:
            pts = np.random.default_rng(1).random((500, 2))
            os._exit(0 if lfqt.verify(pts, lfqt.triangulate(pts)).ok else 3)
        alive = preload._thread.is_alive()
        _, status = os.waitpid(pid, 0)
        print(alive, os.waitstatus_to_exitcode(status))
    """, timeout=300)
    assert out.split() == ["False", "0"]


def test_a_running_call_holds_the_preload_at_its_next_step_and_it_goes_on_after():
    out = _run("""
        import time
        import lfqt
        from lfqt import calls, preload

        def three_d():
            return sum(len(v) for k, v in loaded().items()
                       if k.startswith("lfqt.incremental.tetra"))

        @calls.entry
        def a_long_call():  # as a triangulation that starts right after the import
            time.sleep(3.0)
            return three_d(), preload._thread.is_alive()

        during, alive = a_long_call()
        preload.wait()
        print(during, alive, three_d() > 0)
    """)
    assert out.split() == ["0", "True", "True"], out


@pytest.mark.skipif(not hasattr(os, "fork"), reason="needs os.fork")
def test_a_fork_from_inside_a_call_does_not_wait_for_the_preload_that_waits_for_it():
    out = _run("""
        import os
        import numpy as np
        import lfqt
        from lfqt import calls, preload

        @calls.entry
        def forks():
            pid = os.fork()
            if pid == 0:
                pts = np.random.default_rng(1).random((500, 2))
                os._exit(0 if lfqt.verify(pts, lfqt.triangulate(pts)).ok else 3)
            return os.waitstatus_to_exitcode(os.waitpid(pid, 0)[1])

        print(forks(), preload._thread.is_alive())
    """, timeout=300)
    assert out.split() == ["0", "False"], out


@pytest.mark.skipif(not os.path.isdir("/proc/self/task"), reason="reads Linux's /proc")
def test_the_threads_a_call_runs_on_keep_the_programs_priority():
    """The pool threads that a call runs on, made while the preload loaded
    the 2-thread kernels, have the program's priority: a preload at a low
    one would pass it on to them, and a busy machine would starve them."""
    out = _run("""
        import os
        import numpy as np
        import lfqt
        from lfqt import preload
        from lfqt.workers import MIN_CHUNK
        preload.wait()
        lfqt.triangulate(np.random.default_rng(3).random((4 * MIN_CHUNK, 2)), threads=2)

        def nice(tid):
            with open(f"/proc/self/task/{tid}/stat") as f:
                return int(f.read().rsplit(")", 1)[1].split()[16])

        print(sorted({nice(tid) for tid in os.listdir("/proc/self/task")}), nice(os.getpid()))
    """)
    levels, main = out.rsplit("]", 1)
    assert levels.strip() == f"[{main.strip()}", out
