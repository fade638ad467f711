"""The kernels of a process's first triangulation, loaded from numba's cache
while the program that imported lfqt goes on.

numba loads a cached kernel on its first call in a process, and before its
first load of all it imports its own typing and lowering registries
(``numba.np.arraymath`` imports ``scipy.linalg`` to look for a BLAS): that
alone takes longer than a warm 1M-point call.  A program imports lfqt, then
reads or makes its points; in that time a thread started by ``import lfqt``
(``start``) loads the registries and the divide and conquer's kernels, by
running it on one and on two threads on a set just large enough to take
every path of a large call (two chunks of ``lfqt.workers.MIN_CHUNK``), and
on float32 points; then 3D insertion's, alone and in lanes (_steps_3d).

A call that comes before the thread is done waits for numba's compiler lock
while the thread loads a kernel, no longer than it would have taken to load
the kernel itself.  The thread gives way to calls (lfqt.calls): it starts
none of its steps while a call runs, so that a 2D call is not slowed by 3D
kernels loading beside it (numba loads a kernel in Python, under the GIL;
docs/performance.md, "preload gives way").  It keeps the program's
priority: the pool threads it makes (lfqt.workers) serve the program's
calls after it, and a thread's priority passes to the threads it makes.
A fork waits for the thread first (``_before_fork``): a child must not
inherit numba's lock held.  ``LFQT_PRELOAD=0`` in the environment turns it
off.
"""
import os
import threading

import numpy as np

from . import calls

ENV = "LFQT_PRELOAD"
_thread = None
_stop = False  # set by a fork from inside a call: the preload ends at its next step


def start():
    """Start loading the kernels in a daemon thread, once per process,
    unless ``LFQT_PRELOAD=0``."""
    global _thread
    if _thread is not None or os.environ.get(ENV, "1") == "0":
        return
    _thread = threading.Thread(target=_load, name="lfqt-preload", daemon=True)
    calls.background = _thread
    _thread.start()


def wait():
    """Block until the kernels are loaded (at once if nothing is loading)."""
    if _thread is not None and _thread is not threading.current_thread():
        _thread.join()


def _steps():
    """The preload, in steps of a few kernels each: a generator that stops
    before each step, for ``_load`` to hold it while a call runs.  Small
    steps, so that a call that starts during one waits little for it."""
    from . import workspace
    from .dc import triangulate
    from .workers import MIN_CHUNK
    pts = np.random.default_rng(0).random((2 * MIN_CHUNK + 2, 2))
    yield
    triangulate(pts[:64])  # the default, one thread, first
    yield
    triangulate(pts, threads=2)
    yield
    triangulate(pts[:64].astype(np.float32))
    yield from _steps_3d()
    workspace.release()  # the preload leaves no idle memory behind


def _load():
    try:
        for _ in _steps():
            calls.wait_idle(lambda: _stop)
            if _stop:
                return
    except Exception:  # noqa: BLE001 - best effort: the first call loads whatever is missing
        pass


def _steps_3d():
    """3D insertion's kernels, on one thread and on two, on a set far
    smaller than the sizes at which a call takes those paths: the lanes
    after 64 points alone, the Kd order's subtrees past 2-point leaves."""
    from . import insert, orders
    from .incremental import kernel, tetra
    from .workers import Workers
    p = np.random.default_rng(0).random((600, 3))
    yield
    insert(p[:64])
    yield
    perm, hint, store, stored = orders.kdtree_order(p, False, False, presorted=2, threads=2)
    kernel.relabel(perm, hint, store)
    yield
    run = tetra.insert_all(stored, perm, hint, 1.0, threads=2, first=64)
    yield
    kernel.finite_cells(run.C, run.N, run.mark, store, shift=2, workers=Workers(2))


def _before_fork():
    """A child must not inherit numba's lock held: wait for the preload.  A
    fork from inside a call would wait for ever (the preload waits for the
    call), so the preload stops at its next step instead."""
    global _stop
    if calls.depth():
        _stop = True
        calls.wake()
    wait()


os.register_at_fork(before=_before_fork)
