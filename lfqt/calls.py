"""The public calls running now, for background work to give way to them.

``lfqt.preload`` loads kernels in a thread while the program goes on; on a
machine with no more cores than a call has threads, it would take a core
and the GIL from the call.  ``triangulate`` and ``insert`` are decorated
with ``entry``; the preload waits (``wait_idle``) before each of its steps
until no call runs.
"""
import functools
import threading
from typing import Callable, ParamSpec, TypeVar

_P = ParamSpec("_P")
_R = TypeVar("_R")

_running = 0  # entries running now, in any thread but the background one
_changed = threading.Condition()
_here = threading.local()  # .depth: this thread's entries running now
background = None  # the thread whose own calls do not count (lfqt.preload's)


def entry(function: Callable[_P, _R]) -> Callable[_P, _R]:
    """Decorate a public entry point: count it as running while it runs
    (typed, so that the entry point keeps its signature for type checkers)."""
    @functools.wraps(function)
    def counted(*args: _P.args, **kwargs: _P.kwargs) -> _R:
        global _running
        if threading.current_thread() is background:
            return function(*args, **kwargs)
        with _changed:
            _running += 1
        _here.depth = depth() + 1
        try:
            return function(*args, **kwargs)
        finally:
            _here.depth -= 1
            with _changed:
                _running -= 1
                _changed.notify_all()
    return counted


def depth():
    """How many entries this thread is inside now."""
    return getattr(_here, "depth", 0)


def wait_idle(cancelled=lambda: False):
    """Block until no entry runs, or ``cancelled()`` (checked whenever
    ``wake`` is called or an entry ends)."""
    with _changed:
        _changed.wait_for(lambda: _running == 0 or cancelled())


def wake():
    """Wake the waiters of ``wait_idle`` to check their ``cancelled``."""
    with _changed:
        _changed.notify_all()
