"""The thread pool of lfqt: nogil kernels over index ranges.

The calling thread works too: ``each`` hands the items out one at a time
to the caller and to threads - 1 pool threads, so that a parallel step
costs one wake-up of a pool thread and no sleep of the caller.  Two
threads, two chunks of a trivial kernel: 102-124 -> 69-85 us a step,
against 10 us inline; a 1M call on 2 threads takes about 20 steps.

The pools outlive a call, one of threads - 1 threads per thread count in
the process (``_pool``): a pool made for each call started its threads in
its first step and joined them at its end, 0.2-0.7 ms of a 1M call on 2
threads that takes about 85 ms."""
import os
import threading
from concurrent.futures import ThreadPoolExecutor

MIN_CHUNK = 1 << 16  # below this a chunk costs more to schedule than to run


class Workers:
    """A thread pool for nogil kernels over index ranges.  With one thread
    everything runs inline; ``threads`` may exceed the core count."""

    def __init__(self, threads):
        self.threads = max(1, int(threads))
        self.pool = _pool(self.threads - 1) if self.threads > 1 else None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        pass  # the pool stays for the next call (_pool)

    def chunks(self, n, min_chunk=MIN_CHUNK):
        """At most one range of [0, n) per thread, none shorter than
        ``min_chunk`` items (unless there is just one)."""
        k = max(1, min(self.threads, n // min_chunk))
        cuts = [n * i // k for i in range(k + 1)]
        return list(zip(cuts[:-1], cuts[1:]))

    def map(self, chunks, fn):
        """[fn(c, lo, hi) for each chunk c = (lo, hi)], in parallel."""
        return self.each(lambda c: fn(c, *chunks[c]), range(len(chunks)))

    def each(self, fn, items):
        """[fn(item) for item in items], in parallel: the caller and up to
        threads - 1 pool threads take the items in order, one at a time.
        Every item has ended, or was skipped after an error, when this
        returns; the first error is raised."""
        items = list(items)
        if self.pool is None or len(items) < 2:
            return [fn(item) for item in items]
        results = [None] * len(items)
        errors = []
        lock = threading.Lock()
        pending = iter(range(len(items)))

        def drain():
            while not errors:
                with lock:
                    i = next(pending, None)
                if i is None:
                    return
                try:
                    results[i] = fn(items[i])
                except BaseException as e:  # noqa: BLE001 - re-raised in the caller
                    errors.append(e)

        helpers = [self.pool.submit(drain)
                   for _ in range(min(self.threads, len(items)) - 1)]
        drain()
        for h in helpers:
            if not h.cancel():  # a helper still queued (the pool busy elsewhere) is not waited for
                h.result()
        if errors:
            raise errors[0]
        return results


_pools = {}
_pools_lock = threading.Lock()


def _pool(helpers):
    """The process's pool of ``helpers`` threads, made on first use."""
    with _pools_lock:
        if helpers not in _pools:
            _pools[helpers] = ThreadPoolExecutor(helpers, thread_name_prefix="lfqt")
        return _pools[helpers]


# A forked child has none of its parent's threads: its pools start afresh.
os.register_at_fork(after_in_child=_pools.clear)
