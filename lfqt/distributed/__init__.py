"""Exact Delaunay triangulation of point sets larger than one machine, on Dask.

The scheme is **Tile & Merge** (Caraffa, Memari, Yirci and Brédif, "Tile &
Merge: Distributed Delaunay Triangulations for Cloud Computing", IEEE
BigData 2019; proved consistent in Brédif et al., "Provably consistent
distributed Delaunay triangulation", ISPRS Annals V-2-2020):

1. one pass over the chunks measures them and draws a sample; a k-d split
   of the sample (median cuts) defines the tiles (lfqt.distributed.partition);
2. a second pass writes every chunk's points, grouped by tile, to one
   file with the offsets of each tile's rows and its box at its head
   (lfqt.distributed.shuffle); a tile reads its ranges of every file
   when a round needs its points, so they wait on disk, and the graph
   holds a task per chunk and per tile, never per pair;
3. rounds: each tile triangulates its points and those it has received
   with ``lfqt.triangulate``, and sends to every other tile the vertices of
   each face whose closed circumdisk meets that tile's box, until no tile
   has anything new to send (lfqt.distributed.tiles).  The first
   NEIGHBOUR_ROUNDS rounds send only to the tiles whose cells touch and
   leave the hull's infinite faces out; then the rule applies in full
   until no tile has anything new.  Without it, a tile's border (slivers along its
   box, and its hull) reaches half the tiles in the first round, and the
   exchange grows with the number of tiles;
4. each tile outputs the triangles whose smallest global id is its own;
   cocircular faces are cut as a fan from their smallest global id, so all
   tiles cut them alike.

Every decision is exact (lfqt.distributed.geometry).  The result is the
Delaunay triangulation; where it is not unique (grids, cocircular sets) it
is one valid Delaunay triangulation, checked tile by tile by ``verify``.
"""
from __future__ import annotations

import contextlib
import os
import time
from collections.abc import Iterator, Sequence
from operator import getitem
from typing import TYPE_CHECKING, Any, Literal, NamedTuple, Union

import numpy as np
import numpy.typing as npt

from .._input import MAX_EXP, MIN_ULP_EXP, window_exponent
from ..triangulation import Triangulation
from . import partition, shuffle, sources, tiles as tile_tasks
from .engine import Dask, Serial

if TYPE_CHECKING:
    from dask.distributed import Client

    from ..verification import VerifyReport

Points = Union[npt.ArrayLike, str, os.PathLike, Sequence[Union[str, os.PathLike]]]
"""In-memory (n, 2) points, a dask.array, or a path, a glob or a list of
``.npy`` or Parquet chunks (lfqt.distributed.sources)."""
Chunk = tuple[str, Any, int]
"""(kind, what, rows): one chunk of the input (lfqt.distributed.sources)."""
Engine = Union[Dask, Serial]

SAMPLE_SIZE = 1 << 17  # points drawn to place the k-d cuts
NEIGHBOUR_ROUNDS = 2  # rounds of the first phase (see step 3 above)
BORDER_FANIN = 8  # shares' borders paired per task of verify's reduction tree
SEED = 0
FORMATS = ("npy", "parquet")


def triangulate(points: Points, *, client: Client | str | None = None,
                tiles: int | np.integer[Any] | None = None, out: str | os.PathLike | None = None,
                format: Literal["npy", "parquet"] = "npy", progress: bool | None = None,
                scratch: str | os.PathLike | None = None) -> Triangulation | Tiles:
    """Exact 2D Delaunay triangulation on a Dask cluster (Tile & Merge).

    Parameters
    ----------
    points : array_like (n, 2), dask.array, or str / list of str
        In-memory points, a dask array (known chunk sizes), or a path or
        glob of ``.npy`` (n, 2) files or Parquet files (columns x and y, or
        the first two).  Chunks are read by the workers, one at a time; no
        process holds the whole set.  Global ids are row numbers in the
        concatenation of the chunks (files in sorted order).
    client : dask.distributed.Client, str or None
        A client, a scheduler address, or None to start a LocalCluster on
        the local cores for this call (one single-threaded worker process
        per core, at most 8 GiB each).  Its workers do not run the main
        script again: a script may call this at top level, without
        ``if __name__ == "__main__":``.
    tiles : int or None
        Number of tiles (default: about 2**20 points each, at least two per
        worker).
    out : str or None
        A directory: each tile writes its triangles there (``format``) and
        the call returns the paths.  None: the triangles are gathered into a
        :class:`lfqt.Triangulation` (for results that fit in memory).
    format : {"npy", "parquet"}
        Format of the files written to ``out``: (m, 3) int64 global ids, or
        Parquet columns a, b, c.
    progress : bool or None
        A progress bar per phase (default: when stderr is a terminal).
    scratch : str or None
        Where the partition's files wait (a directory every worker sees;
        default: inside ``out``, else a temporary directory).  They take
        about 24 bytes per point and are removed before the call returns.

    Returns
    -------
    Triangulation or Tiles
        The triangulation (int64 global ids), or with ``out`` the list of
        the files written (:class:`Tiles`).  Either has ``.stats``: tiles,
        rounds, points sent per round, points received per tile, peak
        memory per worker, seconds per phase, and the tasks per phase.

    Raises
    ------
    ValueError
        A bad ``format`` or ``tiles``, points that are not (n, 2), NaN or
        infinite, or that span more binades than the predicates' window.
    lfqt.distributed.shuffle.DiskFullError
        ``scratch`` or ``out`` ran out of space.  Whatever the call wrote
        is removed (the tiles' files of ``out`` and the partition's): the
        call is not resumable, free the space and call it again.

    See Also
    --------
    verify : the exact check of the result, share by share.
    lfqt.triangulate : the same triangulation on one process.

    Examples
    --------
    In-memory points, on a LocalCluster started for the call (a few
    seconds; an in-memory input is sent to the cluster once):

    >>> import numpy as np
    >>> import lfqt
    >>> pts = np.random.default_rng(0).random((20_000, 2))
    >>> tri = lfqt.distributed.triangulate(pts, tiles=4, progress=False)
    >>> tri.stats["tiles"], tri.simplices.dtype
    (4, dtype('int64'))
    >>> lfqt.verify(pts, tri).ok
    True

    Files in, files out, on an existing cluster:

    >>> got = lfqt.distributed.triangulate("cloud/part-*.npy", out="tiles/",
    ...                                    client="tcp://scheduler:8786")  # doctest: +SKIP
    """
    if format not in FORMATS:
        raise ValueError(f"format must be one of {FORMATS}, got {format!r}")
    if tiles is not None and (not isinstance(tiles, (int, np.integer)) or tiles < 1):
        raise ValueError(f"tiles must be a positive integer or None, got {tiles!r}")
    with _on_dask(points, client, progress) as (chunk_list, engine):
        return triangulate_on(chunk_list, engine, tiles, out, format, points, scratch)


@contextlib.contextmanager
def _on_dask(points: Points, client: Client | str | None,
             progress: bool | None) -> Iterator[tuple[list[Chunk], Dask]]:
    """(chunks of ``points``, the Dask engine), closed afterwards; a dask
    collection's blocks are computed on the cluster, once, and in-memory
    chunks sent there once (``Dask.put``): the tasks get futures."""
    chunk_list = sources.chunks(points)
    engine = Dask(client, progress)
    try:
        if chunk_list and chunk_list[0][0] == "dask":
            blocks = engine.client.compute([c[1] for c in chunk_list])
            chunk_list = [("dask", b, c[2]) for b, c in zip(blocks, chunk_list)]
        chunk_list = [(kind, engine.put(what) if kind == "array" else what, rows)
                      for kind, what, rows in chunk_list]
        yield chunk_list, engine
    finally:
        engine.close()


def triangulate_on(chunk_list: list[Chunk], engine: Engine,
                   tiles: int | np.integer[Any] | None = None,
                   out: str | os.PathLike | None = None, fmt: Literal["npy", "parquet"] = "npy",
                   points: Points | None = None,
                   scratch: str | os.PathLike | None = None) -> Triangulation | Tiles:
    """Tile & Merge over chunks, on an engine: ``triangulate`` without the
    validation of its arguments and the cluster it starts.

    Parameters
    ----------
    chunk_list : list of (kind, what, rows)
        The input's chunks (``lfqt.distributed.sources.chunks``), the
        data of an "array" or "dask" chunk in memory or as a future.
    engine : Serial or lfqt.distributed.engine.Dask
        Where the tasks run.
    tiles, out
        As for ``triangulate``.
    fmt : {"npy", "parquet"}
        ``triangulate``'s ``format``.
    points : array_like (n, 2) or None
        The points of the returned Triangulation when ``out`` is None; None
        or anything but an ndarray: the chunks, read back.
    scratch : str or None
        As for ``triangulate``.

    Returns
    -------
    Triangulation or Tiles
        As for ``triangulate``.

    Examples
    --------
    On this process, in chunks of 300 points:

    >>> import numpy as np
    >>> import lfqt
    >>> from lfqt.distributed import Serial, sources, triangulate_on
    >>> pts = np.random.default_rng(0).random((1000, 2))
    >>> tri = triangulate_on(sources.chunks(pts, 300), Serial(), tiles=3, points=pts)
    >>> len(tri.simplices) == len(lfqt.triangulate(pts).simplices)
    True
    """
    t0 = time.perf_counter()
    work = _scratch(scratch, out)
    plan: dict[str, int] = {}
    try:
        return _triangulate(chunk_list, engine, tiles, out, fmt, points, work, t0, plan)
    except BaseException:
        if out is not None:  # a partial output is useless: no call resumes it
            _remove_output(out, plan.get("tiles", 0), fmt)
        raise
    finally:
        shuffle.remove(work)


def _scratch(scratch, out):
    """A fresh directory for the partition's files: under ``scratch``, else
    under ``out``, else a temporary one."""
    import tempfile
    base = scratch if scratch is not None else out
    if base is not None:
        os.makedirs(base, exist_ok=True)
    return tempfile.mkdtemp(prefix=".lfqt-scratch-", dir=base)


def _remove_output(out, tiles, fmt):
    """Remove the files a failed call may have written to ``out``."""
    for t in range(tiles):
        for suffix in (fmt, "interior.npy"):
            with contextlib.suppress(OSError):
                os.unlink(os.path.join(out, f"tile-{t:05d}.{suffix}"))


def _triangulate(chunk_list, engine, tiles, out, fmt, points, work, t0, plan):
    tasks0 = engine.submitted
    starts, scale_exp, sample = _measure(chunk_list, engine)
    n = int(starts[-1])
    T = int(tiles or partition.auto_tiles(n, engine.workers))
    nodes, cells = partition.kd_tree(sample, T)
    plan["tiles"] = T
    t_measure, tasks_measure = time.perf_counter(), engine.submitted

    local = _tiles(chunk_list, starts, scale_exp, nodes, T, engine, work)
    boxes = np.array(engine.gather([engine.submit(getitem, loc, "box", key="box") for loc in local],
                                   "partition"))
    t_partition, tasks_partition = time.perf_counter(), engine.submitted

    live = [t for t in range(T) if not np.isnan(boxes[t, 0])]
    state = {t: tile_tasks.new_state(T) for t in live}
    inbox: dict[int, Any] = {t: [] for t in live}  # a list, then a future
    near = partition.touching(cells)
    active, everywhere = list(live), False
    history: list[dict[str, Any]] = []
    while active:
        t_round = time.perf_counter()
        stepped = {t: engine.submit(tile_tasks.step, t, local[t], state[t], inbox[t], cells[t],
                                    boxes, out, None if everywhere else near[t],
                                    key=f"round{len(history) + 1}-tile{t}", where=t)
                   for t in active}
        summaries = engine.gather([engine.submit(getitem, s, 2, key="summary")
                                   for s in stepped.values()], f"round {len(history) + 1}")
        outbox = {t: engine.submit(getitem, s, 1, key="outbox") for t, s in stepped.items()}
        for t, s in stepped.items():
            state[t] = engine.submit(getitem, s, 0, key="state")
        senders: dict[int, list[int]] = {}
        for s in summaries:
            for j in s["sent"]:
                senders.setdefault(j, []).append(s["tile"])
        inbox = {j: engine.submit(tile_tasks.collect, j, *[outbox[i] for i in senders[j]],
                                  key="inbox") for j in senders}
        history.append(dict(active=len(active), sent=sum(sum(s["sent"].values())
                                                         for s in summaries),
                            seconds=time.perf_counter() - t_round,
                            points=sum(s["points"] for s in summaries)))
        active = sorted(senders)
        if not everywhere and (not active or len(history) == NEIGHBOUR_ROUNDS):
            # the borders are closed: now the rule in full, for every tile
            active, everywhere = list(live), True
            inbox.update({t: [] for t in live if t not in inbox})
    t_rounds = time.perf_counter()

    finished = engine.gather([engine.submit(tile_tasks.finish, t, local[t], state[t], out, fmt,
                                            key="finish", where=t) for t in live], "finish")
    if out is not None:
        engine.gather([engine.submit(tile_tasks.cleanup, state[t], key="cleanup") for t in live])
    t_finish = time.perf_counter()
    tasks = {"measure": tasks_measure - tasks0, "partition": tasks_partition - tasks_measure,
             "rounds and finish": engine.submitted - tasks_partition}
    info = [f[2] for f in finished]
    result_stats = {
        "tiles": T, "rounds": len(history), "scale_exponent": scale_exp,
        "sent_per_round": [h["sent"] for h in history],
        "tiles_per_round": [h["active"] for h in history],
        "seconds_per_round": [h["seconds"] for h in history],
        "points_per_round": [h["points"] for h in history],  # triangulated, all tiles
        "points_per_tile": [i["local"] for i in info],
        "received_per_tile": [i["foreign"] for i in info],
        "triangles_per_tile": [i["triangles"] for i in info],
        "peak_rss": engine.peak_rss(),
        "seconds": {"measure": t_measure - t0, "partition": t_partition - t_measure,
                    "rounds": t_rounds - t_partition, "finish": t_finish - t_rounds,
                    "total": t_finish - t0},
        "workers": engine.workers, "chunks": len(chunk_list), "tasks": tasks,
    }
    if out is not None:
        return Tiles([f[0] for f in finished], n=n, stats=result_stats)
    simplices = np.concatenate([f[0] for f in finished] + [np.empty((0, 3), np.int64)])
    duplicate_of = np.arange(n, dtype=np.int64)
    for dup, rep in (f[1] for f in finished):
        duplicate_of[dup] = rep
    if not isinstance(points, np.ndarray):  # files, a dask array, or array-like rows
        points = np.concatenate([np.asarray(p) for p in engine.gather(
            [engine.submit(sources.read, kind, what, key="read") for kind, what, _ in chunk_list])]
            + [np.empty((0, 2))])
    return assemble(points, simplices, duplicate_of, result_stats)


def _measure(chunk_list, engine):
    """The first pass: (chunk start rows, the exact power of two that brings
    every coordinate into the predicates' window, a seeded sample scaled by
    it)."""
    starts = np.concatenate(([0], np.cumsum([c[2] for c in chunk_list]))).astype(np.int64)
    rate = min(1.0, SAMPLE_SIZE / max(int(starts[-1]), 1))
    stats = engine.gather([engine.submit(partition.chunk_stats, kind, what, int(s), rate, SEED,
                                         key="measure")
                           for (kind, what, _), s in zip(chunk_list, starts)], "measure")
    for (kind, what, expected), st in zip(chunk_list, stats):
        if st[0] != expected:
            raise ValueError(f"a {kind} chunk changed while being read: {expected} rows "
                             f"announced, {st[0]} read")
    scale_exp = window_exponent(max(s[1] for s in stats), min(s[2] for s in stats),
                                MAX_EXP, MIN_ULP_EXP)
    sample = np.concatenate([s[3] for s in stats] + [np.empty((0, 2))]) * 2.0 ** scale_exp
    return starts, scale_exp, sample


def _tiles(chunk_list, starts, scale_exp, nodes, T, engine, work):
    """The second pass, a shuffle through files in ``work``: every chunk
    writes its points grouped by tile to one file, and each tile's
    descriptor (a future) names its parts (lfqt.distributed.partition)."""
    cuts = [engine.submit(partition.cut_chunk, kind, what, int(s), scale_exp, nodes, T,
                          os.path.join(work, f"chunk-{c:06d}.npy"), key="cut")
            for c, ((kind, what, _), s) in enumerate(zip(chunk_list, starts))]
    paths = engine.submit(shuffle.written, *cuts, key="written")
    return [engine.submit(partition.tile, t, paths, key=f"tile-{t}", where=t) for t in range(T)]


class Tiles(list[str]):
    """The paths of the tiles' files (what ``triangulate`` returns with
    ``out``), with ``n`` (the points) and ``stats`` (as a Triangulation's)."""

    def __init__(self, paths: Sequence[str], *, n: int, stats: dict[str, Any]) -> None:
        super().__init__(paths)
        self.n, self.stats = n, stats


def assemble(points: npt.ArrayLike, simplices: npt.ArrayLike, duplicate_of: npt.ArrayLike,
             stats: dict[str, Any]) -> Triangulation:
    """A Triangulation from gathered triangles: neighbours by matching
    each edge with its twin, and the hull loop from the unmatched ones.

    Parameters
    ----------
    points : array_like, shape (n, 2)
        The points, kept as the result's ``points``.
    simplices : array_like of int, shape (m, 3)
        Counter-clockwise triangles of global ids, in any order.
    duplicate_of : array_like of int, shape (n,)
        Per point, the smallest id of the points equal to it.
    stats : dict
        The result's ``stats``.

    Returns
    -------
    Triangulation
        int64 ids; ``degenerate`` when there are no triangles, with the
        lexicographic extremes as its hull.

    Examples
    --------
    >>> import numpy as np
    >>> from lfqt.distributed import assemble
    >>> square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    >>> tri = assemble(square, [[0, 1, 2], [0, 2, 3]], np.arange(4), {})
    >>> tri.neighbors.tolist(), tri.hull.tolist()
    ([[-1, 1, -1], [-1, -1, 0]], [0, 1, 2, 3])
    """
    duplicate_of = np.asarray(duplicate_of, dtype=np.int64)
    n = len(duplicate_of)
    S = np.asarray(simplices, dtype=np.int64)
    m = len(S)
    a = S[:, [1, 2, 0]].ravel()  # edge opposite vertex k runs S[k+1] -> S[k+2]
    b = S[:, [2, 0, 1]].ravel()
    key = a * n + b
    order = np.argsort(key, kind="stable")
    sorted_keys = key[order]
    pos = np.minimum(np.searchsorted(sorted_keys, b * n + a), max(len(key) - 1, 0))
    found = sorted_keys[pos] == b * n + a if m else np.zeros(0, dtype=bool)
    nb = np.full(3 * m, -1, dtype=np.int64)
    nb[found] = order[pos[found]] // 3
    hull = _hull(points, a[~found], b[~found]) if m else _extremes(points, duplicate_of)
    reason = "" if m else "fewer than 3 distinct points or all points collinear"
    return Triangulation(points=points, simplices=S, neighbors=nb.reshape(m, 3), hull=hull,
                         duplicate_of=duplicate_of, stats=stats, degenerate=not m, reason=reason)


def _extremes(points, duplicate_of):
    """The hull of a set without triangles: its lexicographic extremes."""
    distinct = np.flatnonzero(duplicate_of == np.arange(len(duplicate_of)))
    if not len(distinct):
        return np.empty(0, dtype=np.int64)
    P = np.asarray(points, dtype=np.float64)[distinct]
    order = np.lexsort((P[:, 1], P[:, 0]))
    return distinct[np.unique(order[[0, -1]])] if len(distinct) > 1 else distinct


def _hull(points, a, b):
    """The counter-clockwise loop of boundary edges a -> b, from the one
    with the smallest (x, y)."""
    if not len(a):
        return np.empty(0, dtype=np.int64)
    nxt = dict(zip(a.tolist(), b.tolist()))
    P = np.asarray(points)
    start = int(a[np.lexsort((P[a, 1], P[a, 0]))[0]])
    loop = [start]
    while nxt[loop[-1]] != start and len(loop) <= len(a):
        loop.append(nxt[loop[-1]])
    return np.array(loop, dtype=np.int64)


def verify(result: Triangulation | Sequence[str | os.PathLike], points: Points, *,
           client: Client | str | None = None, progress: bool | None = None,
           scratch: str | os.PathLike | None = None) -> VerifyReport:
    """Exactly check a distributed triangulation share by share
    (lfqt.distributed.check), without loading the whole point set on one
    process.

    Parameters
    ----------
    result : Triangulation or list of str
        What ``triangulate`` returned: a Triangulation (any, with global
        ids as its indices), or the tiles' files.
    points : array_like (n, 2), dask.array, or str / list of str
        The input given to ``triangulate``.
    client, progress
        As for ``triangulate`` (None: a LocalCluster for this call, which
        a script may start at top level).
    scratch : str or None
        Where the check's files wait (a directory every worker sees;
        default: a temporary directory), removed before the call returns.

    Returns
    -------
    lfqt.VerifyReport
        ``ok`` when ``result`` is the Delaunay triangulation of the points;
        ``problems`` names what is wrong, ``counts`` holds the triangles,
        vertices and distinct points.

    See Also
    --------
    lfqt.verify : the same check on one process.

    Examples
    --------
    >>> import numpy as np
    >>> import lfqt
    >>> pts = np.random.default_rng(0).random((20_000, 2))
    >>> report = lfqt.distributed.verify(lfqt.triangulate(pts), pts, progress=False)
    >>> report.ok, report.counts["distinct_points"]
    (True, 20000)

    The files that ``triangulate(..., out="tiles/")`` wrote:

    >>> lfqt.distributed.verify(got, "cloud/part-*.npy").ok  # doctest: +SKIP
    True
    """
    with _on_dask(points, client, progress) as (chunk_list, engine):
        return verify_on(result, chunk_list, engine, scratch)


class _Verified(NamedTuple):
    """What verify_on's shuffles and reduction found."""
    counts: dict
    hull: Any  # the hull loop, a future: it stays on the cluster
    distinct: Any
    used: Any  # ids used per chunk
    scale_exp: int


def _verify(result, chunk_list, engine, work):
    """verify_on's shuffles and its reduction, as a _Verified."""
    from . import check as ck
    starts, scale_exp, sample = _measure(chunk_list, engine)
    # 4: distinct points, counted tile by tile (equal points share a tile)
    T = partition.auto_tiles(int(starts[-1]), engine.workers)
    nodes, _ = partition.kd_tree(sample, T)
    local = _tiles(chunk_list, starts, scale_exp, nodes, T, engine, work)
    distinct = sum(engine.gather([engine.submit(ck.tile_distinct, loc, key="distinct")
                                  for loc in local], "distinct points"))
    engine.release(local)

    # the coordinates of each share's vertices: two shuffles through files
    shares = _shares(result, engine)
    reqs = [engine.submit(ck.requests, kind, what, starts, os.path.join(work, f"share-{s:06d}.npy"),
                          key="requests") for s, (kind, what) in enumerate(shares)]
    requested = engine.submit(shuffle.written, *[engine.submit(getitem, r, 0, key="path")
                                                 for r in reqs], key="written")
    found = [engine.submit(ck.lookup, kind, what, int(s), scale_exp, c, requested,
                           os.path.join(work, f"found-{c:06d}.npy"), key="lookup")
             for c, ((kind, what, _), s) in enumerate(zip(chunk_list, starts))]
    found_paths = engine.submit(shuffle.written, *[engine.submit(getitem, f, 0, key="path")
                                                   for f in found], key="written")
    checked = [engine.submit(ck.check_share, s, r, found_paths, key="check")
               for s, r in enumerate(reqs)]
    counts: dict[str, int] = {}
    parts = engine.gather([engine.submit(getitem, x, 0, key="counts") for x in checked],
                          "check shares")
    # the borders, paired up a tree: each node's edges without a twin go up
    level = [engine.submit(getitem, x, 1, key="border") for x in checked]
    while len(level) > BORDER_FANIN:
        nodes_ = [engine.submit(ck.pair_borders, *level[i:i + BORDER_FANIN], key="pair")
                  for i in range(0, len(level), BORDER_FANIN)]
        parts += engine.gather([engine.submit(getitem, x, 0, key="counts") for x in nodes_])
        level = [engine.submit(getitem, x, 1, key="border") for x in nodes_]
    border = engine.submit(ck.check_border, *level, key="hull")
    parts += engine.gather([engine.submit(getitem, border, 0, key="counts")])
    for part in parts:
        for k, v in part.items():
            counts[k] = counts.get(k, 0) + int(v)
    used = engine.gather([engine.submit(getitem, f, 1, key="used") for f in found])
    return _Verified(counts, engine.submit(getitem, border, 1, key="hull"), distinct, used,
                     scale_exp)


def _shares(result: Triangulation | Sequence[str | os.PathLike],
            engine: Engine) -> list[tuple[str, Any]]:
    """The triangles as shares: (kind, what) per tile file, or per slice
    of a Triangulation's, sent to the cluster once (``put``)."""
    if not isinstance(result, Triangulation):
        return [("npy" if str(p).endswith(".npy") else "parquet", str(p)) for p in result]
    S = np.asarray(result.simplices, dtype=np.int64)
    per = (result.stats or {}).get("triangles_per_tile")
    if per and sum(per) == len(S):
        cuts = np.cumsum([0] + list(per))
    else:
        k = max(2 * engine.workers, -(-len(S) // (1 << 21)))
        cuts = np.linspace(0, len(S), k + 1).astype(np.int64)
    return [("array", engine.put(S[lo:hi])) for lo, hi in zip(cuts[:-1], cuts[1:])]


def verify_on(result: Triangulation | Sequence[str | os.PathLike], chunk_list: list[Chunk],
              engine: Engine, scratch: str | os.PathLike | None = None) -> VerifyReport:
    """``verify`` over chunks, on an engine (as ``triangulate_on``).

    Parameters
    ----------
    result : Triangulation or list of str
        As for ``verify``.
    chunk_list : list of (kind, what, rows)
        The points' chunks (``lfqt.distributed.sources.chunks``).
    engine : Serial or lfqt.distributed.engine.Dask
        Where the tasks run.
    scratch : str or None
        As for ``verify``.

    Returns
    -------
    lfqt.VerifyReport

    Examples
    --------
    >>> import numpy as np
    >>> import lfqt
    >>> from lfqt.distributed import Serial, sources, verify_on
    >>> pts = np.random.default_rng(0).random((1000, 2))
    >>> tri = lfqt.triangulate(pts)
    >>> verify_on(tri, sources.chunks(pts, 300), Serial()).ok
    True
    >>> tri.simplices = tri.simplices[1:]  # a hole
    >>> verify_on(tri, sources.chunks(pts, 300), Serial()).problems
    ['hull not one cycle: 1']
    """
    from ..verification import VerifyReport
    from . import check as ck
    work = _scratch(scratch, None)
    try:
        counts, H, distinct, used, scale_exp = _verify(result, chunk_list, engine, work)
    finally:
        shuffle.remove(work)

    def add(d: dict[str, Any]) -> None:
        for k, v in d.items():
            counts[k] = counts.get(k, 0) + int(v)

    if counts["triangles"]:
        add({"points_outside_hull": sum(engine.gather([
            engine.submit(ck.outside_hull, kind, what, scale_exp, H)
            for kind, what, _ in chunk_list], "hull"))})
        add({"vertices_not_distinct_points": int(sum(used) != distinct)})
    elif distinct >= 3:
        ends = np.concatenate(engine.gather([engine.submit(ck.collinear_extremes, kind, what,
                                                           scale_exp)
                                             for kind, what, _ in chunk_list]))
        order = np.lexsort((ends[:, 1], ends[:, 0]))
        a, b = ends[order[0]], ends[order[-1]]
        add({"no_triangles_but_not_collinear": int(sum(engine.gather([
            engine.submit(ck.off_line, kind, what, scale_exp, a, b)
            for kind, what, _ in chunk_list])) > 0)})
    problems = [f"{k.replace('_', ' ')}: {v}" for k, v in counts.items()
                if k != "triangles" and v]
    checks = {k: not v for k, v in counts.items() if k != "triangles"}
    counts["distinct_points"] = distinct
    counts["vertices"] = int(sum(used))
    return VerifyReport(not problems, checks, problems, {**counts})


__all__ = ["triangulate", "verify", "triangulate_on", "verify_on", "Serial", "assemble"]
