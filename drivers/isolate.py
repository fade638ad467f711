"""Measure a peer, in this process or in a child with time and memory limits.

A crash, a timeout, running out of memory or an exception in the child come
back as a :class:`Failure` with the reason, so that a sweep goes on (paper 1
reports Triangle failing at 100M points; we must be able to report that).
"""
import ctypes
import faulthandler
import multiprocessing as mp
import os
import resource
import signal
import time
import traceback
from dataclasses import dataclass, field

import numpy as np

from lfqt.clock import read_cycles


@dataclass
class Measurement:
    seconds: list  # one per repeat, warm-up excluded
    cycles: list  # peer's own cycle counts per repeat (None where it has none)
    counts: dict = field(default_factory=dict)
    peak_rss_bytes: int = 0
    baseline_rss_bytes: int = 0  # resident size after prepare, before the first run
    version: str = ""
    simplices: object = None
    check: dict = None  # drivers.exactness.judge of the last run's mesh, when asked

    @property
    def ok(self):
        return True

    @property
    def extra_peak_bytes(self):
        """Peak memory above the prepared state: what the operation itself used."""
        return max(self.peak_rss_bytes - self.baseline_rss_bytes, 0)


@dataclass
class Failure:
    reason: str
    detail: str = ""

    @property
    def ok(self):
        return False


# How a run is timed (issue 50: where a user calls the library):
#   loop   a warm process, each result dropped before the next run
#          (paper 1's steady state);
#   kept   a warm process, every result held until the measurement ends (a
#          program that keeps what it computes: fresh pages on every call);
#   fresh  a new interpreter that has imported the peer and never run it:
#          one timed first call per process (kernels loaded, nothing warm).
# A compiled driver (CGAL, triangle-native) runs each call in a process of
# its own, so each of its runs is a first call in every regime; it times
# itself inside that process, after reading its input.
REGIMES = ("loop", "kept", "fresh")
REGIME_TEXT = {"loop": "a warm process, each result dropped",
               "kept": "a warm process, every result kept alive",
               "fresh": "a new process's first call, after import"}


def measure(peer, points, *, repeats=3, order=None, count=False, keep_simplices=False,
            warmup=True, on_prepared=None, regime="loop", check=False):
    """Prepare once (``on_prepared()`` is called then), warm up (not
    counted), then time ``repeats`` runs, in ``regime`` (REGIMES; fresh
    means no warm-up at all and one run); ``check``: judge the mesh exactly
    (drivers.exactness) after the timed runs."""
    if regime not in REGIMES:
        raise ValueError(f"unknown regime {regime!r}; known: {', '.join(REGIMES)}")
    if regime == "fresh":
        peer.cold, warmup, repeats = True, False, 1
    peer.check()
    peer.prepare(points, order=order, count=count)
    if on_prepared:
        on_prepared()
    baseline = current_rss()
    if warmup:
        peer.run()
    seconds, cycles, own_memory = [], [], []
    for _ in range(repeats):
        c0 = read_cycles()
        t0 = time.perf_counter()
        peer.run()
        wall = time.perf_counter() - t0
        c1 = read_cycles()
        if regime == "kept":
            peer.keep()
        own = peer.self_timing()
        seconds.append(own[0] if own else wall)
        # raw cycles: the peer's own (CGAL driver's TSC) or ours around run()
        cycles.append(own[1] if own else c1 - c0)
        if peer.self_memory() is not None:
            own_memory.append(peer.self_memory())
    res = peer.result()
    if own_memory:  # the peer ran elsewhere: its own figure, against a zero baseline
        peak, baseline = max(own_memory), 0
    else:
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    judged = None
    if check:
        from .exactness import judge
        judged = judge(points, res.simplices)
    return Measurement(seconds, cycles, res.counts, peak, baseline, peer.version(),
                       res.simplices if keep_simplices else None, judged)


def current_rss():
    """Resident set size of this process now, in bytes."""
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * resource.getpagesize()


PR_SET_PDEATHSIG = 1


def die_with_parent(parent=None):
    """Linux: have the kernel kill this process when its parent dies, even by
    SIGKILL, so that a measuring child never outlives its runner and loads
    the machine under a resumed sweep.  For subprocess's preexec_fn too."""
    parent = os.getppid() if parent is None else parent
    try:
        ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGKILL)
    except (OSError, AttributeError):  # not Linux: the old behaviour
        return
    if os.getppid() != parent:  # the parent died before the call
        os._exit(1)


def _child(conn, peer, points, kwargs, memory_bytes, parent):
    die_with_parent(parent)
    faulthandler.disable()  # a crash is a result here, not something to dump
    if memory_bytes:
        resource.setrlimit(resource.RLIMIT_AS, (memory_bytes, memory_bytes))
    try:
        conn.send(("ok", measure(peer, points, on_prepared=lambda: conn.send(("prepared", None)),
                                 **kwargs)))
    except MemoryError:
        conn.send(("fail", Failure("memory", "MemoryError")))
    except BaseException as e:  # noqa: BLE001 - every failure is data here
        conn.send(("fail", Failure("error", f"{type(e).__name__}: {e}\n{traceback.format_exc(limit=3)}")))
    finally:
        conn.close()


# How long a child may take to prepare, at least: lfqt's peers compile their
# kernels there (on 64 points), and numba compiles everything afresh on a
# cold cache (a new install, or any change to the package: lfqt.jit_cache),
# which took over 120 s for the inserter, the default scale's whole limit.
PREPARE_SECONDS = 900.0


def measure_isolated(peer, points, *, timeout=600.0, prepare_timeout=None, memory_bytes=None,
                     **kwargs):
    """``measure`` in a forked child.  Returns a Measurement or a Failure.
    ``timeout`` bounds the warm-up and the timed runs, from the end of the
    preparation; the preparation gets ``prepare_timeout`` (default: the
    larger of ``timeout`` and PREPARE_SECONDS), so that a cold JIT cache is
    not recorded as the peer's timeout, and a peer that is slow on the
    input still is one.  In the fresh regime the child is a new interpreter
    (spawned, not forked), so that nothing this process compiled or warmed
    is in it."""
    fresh = kwargs.get("regime") == "fresh"
    ctx = mp.get_context("spawn" if fresh else "fork")
    recv, send = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_child, args=(send, peer, np.asarray(points), kwargs, memory_bytes,
                                            os.getpid()))
    proc.start()
    send.close()
    prepare_limit = max(timeout, PREPARE_SECONDS) if prepare_timeout is None else prepare_timeout
    deadline = time.monotonic() + prepare_limit
    prepared = False
    msg = None
    while msg is None:
        left = deadline - time.monotonic()
        if left <= 0:
            proc.kill()
            proc.join()
            return Failure("timeout", f"no result within {timeout:g} s" if prepared else
                           f"not prepared within {prepare_limit:g} s (its set-up, JIT "
                           "compilation included)")
        if recv.poll(min(left, 0.2)):
            try:
                msg = recv.recv()
            except EOFError:
                break
            if msg[0] == "prepared":  # the runs start: the timeout from now
                prepared, msg = True, None
                deadline = time.monotonic() + timeout
        elif not proc.is_alive():
            if recv.poll(0):
                continue
            break
    proc.join()
    if msg is not None:
        status, payload = msg
        if status == "fail" and "bad_alloc" in payload.detail:
            payload.reason = "memory"
        return payload
    code = proc.exitcode
    if code is not None and code < 0:
        name = signal.Signals(-code).name
        reason = "memory" if name == "SIGKILL" else "crash"
        return Failure(reason, f"child died of {name}")
    return Failure("crash", f"child exited with code {code} and no result")
