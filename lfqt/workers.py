"""The thread pool of lfqt: nogil kernels over index ranges."""
from concurrent.futures import ThreadPoolExecutor

MIN_CHUNK = 1 << 16  # below this a chunk costs more to schedule than to run


class Workers:
    """A thread pool for nogil kernels over index ranges.  With one thread
    everything runs inline; ``threads`` may exceed the core count."""

    def __init__(self, threads):
        self.threads = max(1, int(threads))
        self.pool = ThreadPoolExecutor(self.threads, thread_name_prefix="lfqt") \
            if self.threads > 1 else None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        if self.pool:
            self.pool.shutdown(wait=True)

    def chunks(self, n, min_chunk=MIN_CHUNK):
        """At most one range of [0, n) per thread, none shorter than
        ``min_chunk`` items (unless there is just one)."""
        k = max(1, min(self.threads, n // min_chunk))
        cuts = [n * i // k for i in range(k + 1)]
        return list(zip(cuts[:-1], cuts[1:]))

    def map(self, chunks, fn):
        """[fn(c, lo, hi) for each chunk c = (lo, hi)], in parallel."""
        if self.pool is None or len(chunks) == 1:
            return [fn(c, lo, hi) for c, (lo, hi) in enumerate(chunks)]
        return list(self.pool.map(lambda a: fn(a[0], *a[1]), enumerate(chunks)))
