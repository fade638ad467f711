"""Where the tasks run: a Dask client (the default: a LocalCluster on the
local cores, started and closed by the call), or, for the algorithm's own
property tests, this process (``Serial``).  Both offer submit, gather and
the peak resident memory of each process that ran tasks."""
import os
import resource
import sys

GiB = 1 << 30
WORKER_MEMORY_CAP = 8 * GiB  # the bound per process; Dask spills past it


def _peak_rss():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


class Serial:
    """Run every task at once in this process (tests of the algorithm)."""
    workers = 1

    def submit(self, fn, *args, key=None):
        return fn(*args)

    def gather(self, futures, desc=None):
        return list(futures)

    def release(self, futures):
        pass

    def peak_rss(self):
        return {"this process": _peak_rss()}

    def close(self):
        pass


class Dask:
    """A dask.distributed client: ``client`` is a Client, a scheduler
    address, or None for a LocalCluster of one single-threaded worker
    process per core, each capped at WORKER_MEMORY_CAP."""

    def __init__(self, client=None, progress=None):
        try:
            from dask.distributed import Client, LocalCluster
        except ImportError as e:
            raise ImportError("lfqt.distributed needs Dask: pip install 'lfqt[distributed]' "
                              "(dask[distributed] and pyarrow)") from e
        self._own = []
        if client is None:
            import logging
            cores = os.cpu_count() or 1
            total = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
            cluster = LocalCluster(n_workers=cores, threads_per_worker=1, processes=True,
                                   memory_limit=min(WORKER_MEMORY_CAP, total // cores),
                                   dashboard_address=None, silence_logs=logging.CRITICAL)
            client = Client(cluster)
            self._own = [client, cluster]
        elif isinstance(client, str):
            client = Client(client)
            self._own = [client]
        self.client = client
        self.progress = sys.stderr.isatty() if progress is None else progress

    @property
    def workers(self):
        return max(len(self.client.scheduler_info()["workers"]), 1)

    def submit(self, fn, *args, key=None):
        return self.client.submit(fn, *args, pure=False, retries=2,
                                  **({"key": f"{key}-{os.urandom(4).hex()}"} if key else {}))

    def gather(self, futures, desc=None):
        futures = list(futures)
        if self.progress and desc and futures:
            from dask.distributed import as_completed
            from tqdm.auto import tqdm
            for _ in tqdm(as_completed(futures), total=len(futures), desc=desc, leave=False):
                pass
        return self.client.gather(futures)

    def release(self, futures):
        for f in futures:
            f.release()

    def peak_rss(self):
        return self.client.run(_peak_rss)

    def close(self):
        for thing in self._own:
            thing.close()
