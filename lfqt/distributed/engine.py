"""Where the tasks run: a Dask client (the default: a LocalCluster on the
local cores, started and closed by the call), or, for the algorithm's own
property tests, this process (``Serial``).  Both offer submit, put, gather
and the peak resident memory of each process that ran tasks."""
from __future__ import annotations

import contextlib
import os
import resource
import sys
import threading
from collections.abc import Callable, Iterable, Iterator
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from dask.distributed import Client

GiB = 1 << 30
WORKER_MEMORY_CAP = 8 * GiB  # the bound per process; Dask spills past it
PUT_BYTES = 1 << 23  # 8 MiB of data per task: Dask warns of a graph past 10 MB


def _peak_rss() -> int:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def _same(x: Any) -> Any:
    return x


def _joined(*parts: np.ndarray) -> np.ndarray:
    return np.concatenate(parts)


class Serial:
    """Run every task at once in this process (tests of the algorithm).

    Examples
    --------
    >>> from lfqt.distributed import Serial
    >>> engine = Serial()
    >>> engine.gather([engine.submit(max, 2, 3), engine.put([1, 2])])
    [3, [1, 2]]
    """
    workers = 1
    submitted = 0  # tasks run so far (the graph's size, as on Dask)

    def submit(self, fn: Callable[..., Any], *args: Any, key: str | None = None,
               where: int | None = None) -> Any:
        """``fn(*args)``, now."""
        self.submitted += 1
        return fn(*args)

    def put(self, array: Any) -> Any:
        """``array`` itself."""
        return array

    def gather(self, futures: Iterable[Any], desc: str | None = None) -> list[Any]:
        """The results, as a list."""
        return list(futures)

    def release(self, futures: Iterable[Any]) -> None:
        """Nothing to release."""

    def peak_rss(self) -> dict[str, int]:
        """{"this process": its peak resident memory in bytes}."""
        return {"this process": _peak_rss()}

    def close(self) -> None:
        """Nothing to close."""


class Dask:
    """A dask.distributed client: ``client`` is a Client, a scheduler
    address, or None for a LocalCluster of one single-threaded worker
    process per core, each capped at WORKER_MEMORY_CAP, whose workers do
    not run the main script again (``main_script_hidden``)."""

    def __init__(self, client: Client | str | None = None, progress: bool | None = None) -> None:
        try:
            from dask.distributed import Client, LocalCluster
        except ImportError as e:
            raise ImportError("lfqt.distributed needs Dask: pip install 'lfqt[distributed]' "
                              "(dask[distributed] and pyarrow)") from e
        with contextlib.ExitStack() as own:
            if client is None:
                import logging
                cores = os.cpu_count() or 1
                total = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
                own.enter_context(main_script_hidden())  # restored after the cluster is closed
                cluster = own.enter_context(LocalCluster(
                    n_workers=cores, threads_per_worker=1, processes=True,
                    memory_limit=min(WORKER_MEMORY_CAP, total // cores),
                    dashboard_address=None, silence_logs=logging.CRITICAL))
                self.client = own.enter_context(Client(cluster))
            elif isinstance(client, str):
                self.client = own.enter_context(Client(client))
            else:
                self.client = client
            self._own = own.pop_all()
        self.progress = sys.stderr.isatty() if progress is None else progress
        self.submitted = 0  # tasks submitted so far: the graph's size
        self._names: list[str] | None = None  # the workers' addresses, for ``where``

    @property
    def workers(self) -> int:
        return max(len(self.client.scheduler_info()["workers"]), 1)

    def submit(self, fn: Callable[..., Any], *args: Any, key: str | None = None,
               where: int | None = None) -> Any:
        """A future of ``fn(*args)``, retried twice; ``key`` names it.
        ``where``: preferably on worker ``where`` modulo their number (a
        tile's tasks stay on one worker, and the tiles spread over all:
        else they all follow the one task they depend on, and the other
        workers idle until Dask steals work)."""
        self.submitted += 1
        extra: dict[str, Any] = {"key": f"{key}-{os.urandom(4).hex()}"} if key else {}
        if where is not None:
            names = self._addresses()
            extra.update(workers=[names[where % len(names)]], allow_other_workers=True)
        return self.client.submit(fn, *args, pure=False, retries=2, **extra)

    def _addresses(self) -> list[str]:
        if self._names is None:
            self._names = sorted(self.client.scheduler_info()["workers"])
        return self._names

    def put(self, array: np.ndarray) -> Any:
        """A future of ``array``, sent once in tasks of at most PUT_BYTES
        (joined on a worker), so that the tasks that read it carry no data.
        Not ``client.scatter``: scattered data is lost with its worker,
        while a task's result is computed again."""
        rows = max(1, PUT_BYTES // max(array[:1].nbytes, 1))
        parts = [self.submit(_same, array[i:i + rows], key="data")
                 for i in range(0, max(len(array), 1), rows)]
        return parts[0] if len(parts) == 1 else self.submit(_joined, *parts, key="data")

    def gather(self, futures: Iterable[Any], desc: str | None = None) -> list[Any]:
        """The futures' results; a progress bar named ``desc`` meanwhile."""
        futures = list(futures)
        if self.progress and desc and futures:
            from dask.distributed import as_completed
            from tqdm.auto import tqdm  # type: ignore[import-untyped]
            for _ in tqdm(as_completed(futures), total=len(futures), desc=desc, leave=False):
                pass
        return self.client.gather(futures)

    def release(self, futures: Iterable[Any]) -> None:
        for f in futures:
            f.release()

    def peak_rss(self) -> dict[str, int]:
        """Peak resident memory in bytes of each worker, by address."""
        return self.client.run(_peak_rss)

    def close(self) -> None:
        """Close the client and the cluster this engine started."""
        self._own.close()


_hidden_lock = threading.Lock()
_hidden: dict[str, Any] = {"clusters": 0, "main": None, "saved": {}}


@contextlib.contextmanager
def main_script_hidden() -> Iterator[None]:
    """Keep the main script from running again in the processes started
    meanwhile (the workers of a LocalCluster, and those its nannies restart).

    multiprocessing starts them by "spawn": each imports ``__main__``
    again, by the name in its ``__spec__`` or from its ``__file__``, so a
    script that calls ``triangulate`` without ``if __name__ ==
    "__main__":`` would call it again in every worker, which cannot start
    processes while it starts ("RuntimeError: Nanny failed to start").
    The workers need nothing of the script: they run lfqt's functions, and
    Dask pickles what ``__main__`` defines by value.  Without both
    attributes, ``__main__`` is left alone, as in an interactive session;
    they are back once the last cluster started under this is closed.
    (Processes that other threads start meanwhile do not import it either.)
    """
    main = sys.modules["__main__"]
    with _hidden_lock:
        if not _hidden["clusters"]:
            _hidden.update(main=main, saved={k: vars(main)[k] for k in ("__spec__", "__file__")
                                             if k in vars(main)})
            main.__spec__ = None
            vars(main).pop("__file__", None)
        _hidden["clusters"] += 1
    try:
        yield
    finally:
        with _hidden_lock:
            _hidden["clusters"] -= 1
            if not _hidden["clusters"]:
                main, saved = _hidden["main"], _hidden["saved"]
                for k in ("__spec__", "__file__"):
                    if k in saved:
                        setattr(main, k, saved[k])
                    else:
                        vars(main).pop(k, None)
                _hidden.update(main=None, saved={})
