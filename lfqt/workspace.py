"""Memory reused from call to call: the large arrays of a triangulation
(keys, permutations, the points in Morton order, the triangles, and the
result's arrays) come from a process-wide pool of anonymous mappings, and
each goes back to the pool when the last array on it dies, for the next
request to write pages that are already there instead of faulting in fresh
ones.

Without the pool, glibc hands a freed large block back to the system, and
the next call pays a page fault per 4 KiB it writes (on a virtual machine,
a fault on the host too); fresh huge pages fault less often but cost as
much, for the kernel zeroes them.  Uniform points, one thread, calls back
to back, each result freed before the next call (with lfqt.dc's two shared
mappings, its ``_memory``)::

                      1M: a call    page faults    10M: a call    peak RSS
    numpy's memory    198-204 ms    4964           2.27-2.46 s    115 B/point
    this pool         180-194 ms     238           1.92-1.96 s    115 B/point

Each request takes the smallest idle mapping large enough, so that calls on
the same number of points reuse the same mappings; one much larger than
the request gives back its pages past it (``OVERSIZE``), for an array that
outlives the call holds only its own.  Memory is not held for
long: a mapping idle for ``IDLE_SECONDS`` is unmapped by a timer thread,
and so is any past ``LIMIT`` idle bytes; ``release()`` unmaps every idle
mapping now.  A request that finds none large enough unmaps the idle
mappings smaller than itself first (a call on other sizes), so that the
pool never holds memory the call could have used beside what it maps.

A result that keeps only a range of its mapping (``keep_range``: the
divide and conquer's simplices and neighbours, written over T but for its
ghosts' slots) gives the pages around
it back late: at the pool's next request, if the result is still
alive then (so a caller that keeps each result while it asks for the next
holds no more than before), after IDLE_SECONDS, or at ``release()``; and
never if the result dies first and its mapping comes back to the pool
whole, for the next call to write pages that are there.  Uniform points,
one thread, each result freed before the next call, interleaved: 1M
172.4-173.2 -> 169.0-169.6 ms a call, 100k 14.8-15.5 -> 14.7-14.8 ms.
"""
from __future__ import annotations

import mmap
import os
import threading
import time
import weakref

import numpy as np

from . import pages

SMALLEST = 1 << 20  # bytes: smaller arrays come from numpy's allocator
IDLE_SECONDS = 2.0  # an idle mapping is unmapped this long after its last use
LIMIT = 2 << 30  # idle bytes the pool keeps at most
POPULATE_CHUNK = 8 << 20  # bytes: less is not worth a thread
# an idle mapping longer than a request by more than 1/OVERSIZE of it (and
# 2 MiB) gives back its pages past the request when it is lent
OVERSIZE = 4


class Pool:
    """Idle mappings, lent out as arrays and taken back when the arrays die."""

    def __init__(self, limit=LIMIT, idle_seconds=IDLE_SECONDS):
        self.limit = limit
        self.idle_seconds = idle_seconds
        self._idle = []  # [size in bytes, time given back, mmap]
        self._trims = {}  # id of a lent mmap: (mmap, [(from byte, to byte or None)], time asked)
        # reentrant: a finalizer may give a mapping back in the middle of
        # any allocation, this pool's own included (a collection of cycles)
        self._lock = threading.RLock()
        self._timer = None

    def empty(self, shape, dtype, huge=None, populate=None):
        """An uninitialized C-contiguous array, on an idle mapping of the
        pool or a fresh one (lfqt.pages), on huge pages if ``huge``, by
        default where they pay (pages.huge_pays): the advice of a fresh
        mapping, for an idle one keeps its own.  ``populate`` (an
        lfqt.workers.Workers), for an array the call writes whole: a fresh
        mapping's pages are faulted in at once, in parallel over the
        workers (pages.populate), before the kernels write them.  Arrays
        under SMALLEST bytes come from numpy."""
        dtype = np.dtype(dtype)
        count = int(np.prod(shape))
        nbytes = count * dtype.itemsize
        if nbytes < SMALLEST:
            return np.empty(shape, dtype=dtype)
        buf = self._take(nbytes)
        if buf is None:
            buf = pages.mapping(nbytes, pages.huge_pays() if huge is None else huge)
            if populate is not None:
                _populate(buf, nbytes, populate)
        base = np.frombuffer(buf, dtype=dtype, count=count)
        # when base dies, every view of it has died: the mapping is free
        weakref.finalize(base, self._give, buf).atexit = False
        return base.reshape(shape)

    def keep_prefix(self, a, count):
        """keep_range(a, 0, count)."""
        return self.keep_range(a, 0, count)

    def keep_range(self, a, lo, hi):
        """a[lo:hi] (a 1D array); the whole pages of ``a`` before it and of
        the mapping past it go back to the system later (the module's last
        paragraph), where ``a`` lies on a mapping of the pool.  From the
        call on, nothing may read those: their pages turn to zeros at any
        time."""
        found = pages.mapping_of(a)
        if found is not None:
            buf, offset = found
            ranges = [(offset + hi * a.itemsize, None)]
            if lo > 0:
                ranges.append((offset, offset + lo * a.itemsize))
            with self._lock:
                self._trims[id(buf)] = (buf, ranges, time.monotonic())
                if self._timer is None:
                    self._arm(self.idle_seconds)
        return a[lo:hi]

    def idle_bytes(self):
        with self._lock:
            return sum(entry[0] for entry in self._idle)

    def release(self) -> None:
        """Unmap every idle mapping (they are unmapped once nothing refers to
        them)."""
        with self._lock:
            self._idle.clear()
            self._trim(0.0)

    def _take(self, nbytes):
        with self._lock:
            self._trim(0.0)  # the results still alive need their spare pages no more
            fits = [e for e in self._idle if e[0] >= nbytes]
            if not fits:  # all smaller: a call on other sizes
                self._idle = []
                return None
            best = min(fits, key=lambda e: e[0])
            self._idle.remove(best)
            if best[0] - nbytes > max(nbytes // OVERSIZE, 1 << 21):
                # a mapping of a larger call: the array would keep the
                # pages past it resident for as long as it lives
                pages.give_back(best[2], nbytes)
            return best[2]

    def _give(self, buf):
        with self._lock:
            self._trims.pop(id(buf), None)  # back whole, for the next call
            if sum(e[0] for e in self._idle) + len(buf) > self.limit:
                return  # dropped: unmapped when its last reference goes
            self._idle.append([len(buf), time.monotonic(), buf])
            if self._timer is None:
                self._arm(self.idle_seconds)

    def _arm(self, delay):
        self._timer = threading.Timer(delay, self._expire)
        self._timer.daemon = True
        self._timer.start()

    def _expire(self):
        with self._lock:
            now = time.monotonic()
            self._idle = [e for e in self._idle if now - e[1] < self.idle_seconds]
            self._timer = None
            self._trim(self.idle_seconds)
            due = [e[1] for e in self._idle] + [t[2] for t in self._trims.values()]
            if due:
                self._arm(max(0.0, min(due) + self.idle_seconds - now))

    def _trim(self, age):
        """Give back the pages asked for by keep_range at least ``age``
        seconds ago (under the lock)."""
        now = time.monotonic()
        for key, (buf, ranges, asked) in list(self._trims.items()):
            if now - asked >= age:
                for start, stop in ranges:
                    pages.give_back(buf, start, stop)
                del self._trims[key]

    def _after_fork(self):
        """In a forked child: the parent's timer thread is gone."""
        self._lock = threading.RLock()
        self._timer = None
        if self._idle or self._trims:
            self._arm(self.idle_seconds)


def _populate(buf, nbytes, workers):
    """pages.populate over the whole pages of ``buf``'s first ``nbytes``,
    a range per worker."""
    npages = -(-nbytes // mmap.PAGESIZE)
    workers.map(workers.chunks(npages, min_chunk=POPULATE_CHUNK // mmap.PAGESIZE),
                lambda c, lo, hi: pages.populate(buf, lo * mmap.PAGESIZE,
                                                 min(hi * mmap.PAGESIZE, len(buf))))


def views(buf, *specs):
    """Consecutive arrays in the bytes of ``buf`` (a 1D uint8 array), one per
    (count, dtype) of ``specs``, each at a 64-byte aligned offset: arrays
    whose lives do not overlap those of other views of buf share a mapping.
    Raises ValueError when buf is too short."""
    out, at = [], 0
    for count, dtype in specs:
        dtype = np.dtype(dtype)
        end = at + count * dtype.itemsize
        if end > buf.shape[0]:
            raise ValueError(f"{buf.shape[0]} bytes hold no {count} x {dtype} at {at}")
        out.append(buf[at:end].view(dtype))
        at = -(-end // 64) * 64
    return out


def view_bytes(*specs):
    """The bytes ``views`` needs for ``specs``."""
    at = 0
    for count, dtype in specs:
        at = -(-(at + count * np.dtype(dtype).itemsize) // 64) * 64
    return at


POOL = Pool()
if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=POOL._after_fork)


def empty(shape, dtype, huge=None, populate=None):
    """POOL.empty: memory for a call's large arrays."""
    return POOL.empty(shape, dtype, huge, populate)


def keep_prefix(a, count):
    """POOL.keep_prefix: a result's prefix of a call's array."""
    return POOL.keep_prefix(a, count)


def keep_range(a, lo, hi):
    """POOL.keep_range: a result's range of a call's array."""
    return POOL.keep_range(a, lo, hi)


def release() -> None:
    """Unmap the pool's idle mappings now, rather than IDLE_SECONDS after
    their last use.

    The pages of results still alive that they do not use go back to the
    system too (``keep_range``); the results' arrays stay valid.  Call it
    after a batch of large triangulations, before the process does
    something else with its memory.

    Examples
    --------
    >>> import numpy as np, lfqt
    >>> pts = np.random.default_rng(0).random((300_000, 2))
    >>> tri = lfqt.triangulate(pts)
    >>> lfqt.workspace.release()  # the call's scratch mappings go now
    >>> lfqt.workspace.POOL.idle_bytes()
    0
    >>> lfqt.verify(pts, tri).ok  # the result's arrays stay valid
    True
    """
    POOL.release()
