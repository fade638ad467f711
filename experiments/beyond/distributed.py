"""Beyond one machine: lfqt.distributed (Tile & Merge on Dask) on Uniform and
Cluster sets written chunk by chunk (generators.chunked), so that no process
ever holds the whole set, through a LocalCluster of one single-threaded
worker process per core.

Per cell: the wall time of the distributed call (cluster start included),
single-machine lfqt on all threads where it fits in half the memory (in a
child process, which also checks that both give the same triangles), the
exact tile-by-tile check (lfqt.distributed.verify), the peak resident memory
of each worker, the rounds, and the points each tile received from the
others (the stitching overhead).

Scales: smoke 1e5 (Uniform alone); default 1e6 (the main job's share); paper 1e6, 1e7 and
1e8 points (the claim's size: 24 GB of memory is enough).
--data names the scratch directory for the chunks and the tiles' files
(default: a temporary directory, removed after each cell)."""
import json
import multiprocessing
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from generators import chunked

from ..core import results
from ..core.claims import FAILS, HOLDS, UNTESTABLE, Claim, Needs
from ..core.experiment import Experiment, figure_paths
from ..core.machine import machine_info

SETS = ["uniform", "cluster"]
SMOKE_SETS = ["uniform"]  # the smoke scale is part of the smoke main job, which CI runs
SIZES = {"smoke": [100_000], "default": [1_000_000],
         "paper": [1_000_000, 10_000_000, 100_000_000]}
SINGLE_BYTES_PER_POINT = 160  # lfqt's peak per point at 10M (experiments.core.perf), with margin
SEED = 0


def grid(scale, threads):
    return []  # measured by ``measure``: a whole cluster per cell, not a peer in a child


def _cells(args):
    sizes = [n for n in SIZES[args.scale] if not args.sizes or n in args.sizes]
    sets = [d for d in (SMOKE_SETS if args.scale == "smoke" else SETS)
            if not args.dists or d in args.dists]
    return [(d, n) for n in sizes for d in sets]


def canonical(S):
    """Triangles with their smallest id first (orientation kept), sorted."""
    S = np.asarray(S, dtype=np.int64).reshape(-1, 3)
    k = np.argmin(S, axis=1)
    R = np.take_along_axis(S, (k[:, None] + np.arange(3)) % 3, axis=1)
    return R[np.lexsort(R.T[::-1])]


def _single(pattern, paths, threads, repeats, queue):
    """In a child: single-machine lfqt on the whole set, its times, its peak
    memory, and whether its triangles equal the tiles' files."""
    import glob
    import resource

    import lfqt
    pts = np.concatenate([np.load(f) for f in sorted(glob.glob(pattern))])
    lfqt.triangulate(pts[:10_000], threads=threads)  # load the kernels before timing
    seconds = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        tri = lfqt.triangulate(pts, threads=threads, counters=False)
        seconds.append(time.perf_counter() - t0)
    mine = canonical(tri.simplices)
    del tri, pts
    theirs = canonical(np.concatenate([np.load(p) for p in paths]))
    queue.put(dict(seconds=seconds, equal=bool(mine.shape == theirs.shape
                                               and np.array_equal(mine, theirs)),
                   peak=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024))


def _run_single(pattern, paths, threads, repeats):
    ctx = multiprocessing.get_context("spawn")
    queue = ctx.Queue()
    child = ctx.Process(target=_single, args=(pattern, paths, threads, repeats, queue))
    child.start()
    out = queue.get()
    child.join()
    return out


def measure_one(distribution, n, repeats, scratch, progress):
    """The result rows of one cell."""
    import lfqt
    data = Path(scratch) / f"{distribution}-{n}"
    shutil.rmtree(data, ignore_errors=True)
    pattern = chunked.write(distribution, n, data / "points", seed=SEED)
    rows, base = [], dict(experiment="distributed", distribution=distribution, n=n,
                          dtype="float64", seed=SEED, count=False, round=0, status="ok",
                          detail="", version=lfqt.__version__)
    workers = os.cpu_count() or 1
    for k in range(repeats):
        out = data / "triangles"
        shutil.rmtree(out, ignore_errors=True)
        out.mkdir(parents=True)
        t0 = time.perf_counter()
        got = lfqt.distributed.triangulate(pattern, out=out, progress=progress)
        seconds = time.perf_counter() - t0
        st = got.stats
        peak = max(st["peak_rss"].values())
        rows.append(dict(base, peer="lfqt-distributed", threads=st["workers"], repeat=k,
                         seconds=seconds, mpts_per_s=results.rate(n, seconds), peak_bytes=peak,
                         bytes_per_point=peak * st["workers"] / n,
                         counts=_counts(st, n)))
    report = lfqt.distributed.verify(got, pattern, progress=progress)
    for r in rows:
        r["counts"]["verified"] = bool(report.ok)
        r["counts"]["problems"] = report.problems
    fits = n * SINGLE_BYTES_PER_POINT < 0.5 * os.sysconf("SC_PAGE_SIZE") * os.sysconf(
        "SC_PHYS_PAGES")
    if fits:
        single = _run_single(pattern, list(got), workers, repeats)
        for r in rows:
            r["counts"]["equal_to_lfqt"] = single["equal"]
        for k, sec in enumerate(single["seconds"]):
            rows.append(dict(base, peer="lfqt", threads=workers, repeat=k, seconds=sec,
                             mpts_per_s=results.rate(n, sec), peak_bytes=single["peak"],
                             bytes_per_point=single["peak"] / n, counts={}))
    shutil.rmtree(data, ignore_errors=True)
    for r in rows:
        r["counts"] = json.dumps(r["counts"])
    return rows


def _counts(st, n):
    received = np.array(st["received_per_tile"])
    local = np.maximum(np.array(st["points_per_tile"]), 1)
    return dict(tiles=st["tiles"], rounds=st["rounds"], workers=st["workers"],
                sent_per_round=st["sent_per_round"], phases=st["seconds"],
                seconds_per_round=st["seconds_per_round"],
                points_per_round=st["points_per_round"],
                received_median=float(np.median(received)), received_max=int(received.max()),
                received_share_median=float(np.median(received / local)),
                received_share_max=float((received / local).max()),
                points_per_tile_median=float(np.median(local)),
                peak_rss_per_worker=st["peak_rss"], tasks=st.get("tasks"),
                chunks=st.get("chunks"))


def task_counts(workers=2, sizes=(10**6, 10**8, 10**10)):
    """{n: (chunks, tiles, partition tasks as tiles + chunks, as their
    product before)} at the default tiles and this experiment's chunks, for
    the metadata (computed, not measured: 10^10 is beyond this machine)."""
    from lfqt.distributed import partition
    out = {}
    for n in sizes:
        c, t = -(-n // chunked.CHUNK_ROWS), partition.auto_tiles(n, workers)
        out[str(n)] = dict(chunks=c, tiles=t, partition_tasks=partition.tasks(c, t),
                           product_before=c * t)
    return out


def measure(args, out_dir, command):
    """Measure every cell not yet in cells.jsonl (resumable), then write
    results.csv and the metadata sidecar."""
    out_dir.mkdir(parents=True, exist_ok=True)
    log = out_dir / "cells.jsonl"
    if args.force and log.exists():
        log.unlink()
    done = {k: rec["rows"] for k, rec in results.read_log(log, lambda rec: (
        rec["key"][0], int(rec["key"][1]))).items()}
    cells = _cells(args)
    todo = [c for c in cells if c not in done]
    meta = dict(experiment="distributed", command=command, scale=args.scale,
                date=time.strftime("%Y-%m-%d %H:%M:%S %z"), repeats=args.repeats,
                cells=len(cells), resumed_cells=len(cells) - len(todo),
                engine="dask.distributed LocalCluster, one single-threaded worker per core",
                distributions={d: chunked.__doc__.split("\n\n")[0] for d in SETS},
                partition_tasks=task_counts(),
                **_versions(), **machine_info())
    results.atomic_write(out_dir / "metadata.json", json.dumps(meta, indent=2, default=str))
    scratch = Path(args.data) if args.data else Path(tempfile.mkdtemp(prefix="lfqt-distributed-"))
    try:
        for cell in todo:
            print(f"[distributed] {cell[0]} {cell[1]:,}", file=sys.stderr)
            rows = measure_one(*cell, args.repeats, scratch, progress=not args.quiet)
            with open(log, "a+") as f:
                results.append_log(f, {"key": list(cell), "rows": rows})
            done[cell] = rows
    finally:
        if not args.data:
            shutil.rmtree(scratch, ignore_errors=True)
    results.write(out_dir, [r for c in cells for r in done[c]])


def _versions():
    import dask
    import distributed
    return {"dask": dask.__version__, "distributed": distributed.__version__}


def plot(df, out):
    import matplotlib.pyplot as plt
    dist = df[df["peer"] == "lfqt-distributed"]
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 4.6))
    print(f"\n{'set':8} {'n':>12} {'wall s':>8} {'lfqt s':>8} {'ratio':>6} {'tiles':>5} "
          f"{'rounds':>6} {'recv/tile med':>13} {'max':>6} {'peak/worker':>11} {'exact':>6}")
    colors = {"uniform": "#1f77b4", "cluster": "#d62728"}
    for name, g in dist.groupby("distribution", sort=False):
        med = g.groupby("n")["seconds"].median()
        ax1.plot(med.index, med.values, "o-", color=colors.get(name), label=f"{name}: distributed")
        single = df[(df["peer"] == "lfqt") & (df["distribution"] == name)]
        if len(single):
            sm = single.groupby("n")["seconds"].median()
            ax1.plot(sm.index, sm.values, "s--", color=colors.get(name), alpha=0.6,
                     label=f"{name}: lfqt, one process")
        shares = g.groupby("n")["counts"].first()
        ax2.plot(shares.index, [100 * c["received_share_median"] for c in shares], "o-",
                 color=colors.get(name), label=f"{name}: median tile")
        ax2.plot(shares.index, [100 * c["received_share_max"] for c in shares], "^:",
                 color=colors.get(name), label=f"{name}: worst tile")
        for n, c in shares.items():
            s1 = single[single["n"] == n]["seconds"].median() if len(single) else float("nan")
            exact = ("equal" if c.get("equal_to_lfqt") else "verified" if c.get("verified")
                     else "FAILED")
            print(f"{name:8} {n:>12,} {med[n]:8.2f} {s1:8.2f} {med[n] / s1:6.2f} "
                  f"{c['tiles']:5d} {c['rounds']:6d} {c['received_median']:13,.0f} "
                  f"{c['received_max']:6,} {max(c['peak_rss_per_worker'].values()) / 2**30:9.2f}"
                  f" G {exact:>6}")
            ax1.annotate(f"{c['rounds']} rounds", (n, med[n]), textcoords="offset points",
                         xytext=(4, -12), fontsize=8, color=colors.get(name))
    for ax in (ax1, ax2):
        ax.set_xscale("log")
        ax.set_xlabel("points")
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
    ax1.set_yscale("log")
    ax1.set_ylabel("wall seconds (median)")
    ax1.set_title("Tile & Merge on a LocalCluster vs lfqt in one process")
    ax2.set_ylabel("points received, % of the tile's own")
    ax2.set_title("Stitching overhead per tile")
    return figure_paths(fig, out, "distributed")


def _exact_and_small(claim, res):
    df = res.frame("distributed")
    parts, exact, small = [], True, True
    dist = df[df["peer"] == "lfqt-distributed"]
    for (d, n), g in dist.groupby(["distribution", "n"], sort=True):
        c = g["counts"].iloc[0]
        one = df[(df["peer"] == "lfqt") & (df["distribution"] == d) & (df["n"] == n)]
        peak = g["peak_bytes"].max()
        ok = c.get("equal_to_lfqt", c.get("verified")) and c.get("verified")
        exact &= bool(ok)
        small &= peak < claim.limits["peak_bytes"]
        vs = (f", {results.fmt_ratio(g['seconds'].median() / one['seconds'].median())} one "
              "process's time" if len(one) else "")
        check = "equal to lfqt" if c.get("equal_to_lfqt") else "verified" if ok else "WRONG"
        parts.append(f"{d} {n:,}: {g['seconds'].median():.1f} s{vs}, {c['rounds']} rounds, "
                     f"peak {peak / 2**30:.1f} GiB per worker, {check}")
    # a wrong result fails at any size; holding needs the claim's size
    big = dist["n"].max() >= claim.limits["n"]
    verdict = (HOLDS if big else UNTESTABLE) if exact and small else FAILS
    return claim.row("; ".join(parts), verdict,
                     "equality with lfqt.triangulate where it fits, lfqt.distributed.verify "
                     "(exact, tile by tile) everywhere; on one machine the rounds cost more than "
                     "they save (each tile is triangulated again with its border)"
                     + ("" if big else f"; exact here, but the claim is about "
                        f"{claim.limits['n']:,} points")
                     if exact and small else "a result was not exact or a worker exceeded 8 GiB")


CLAIMS = (
    # holds when every result is exact and no worker's peak reaches peak_bytes
    Claim("an exact triangulation of sets beyond one machine, on Dask (Tile & Merge), no "
          "process above about 8 GB", "Tile & Merge on Spark (Caraffa et al. 2019), not a "
          "library; issue: 10^8 points under 8 GB per process", _exact_and_small,
          limits={"peak_bytes": 8 * 2**30, "n": 100_000_000},
          needs=Needs("the paper scale's 1e8 points, which 24 GB of memory holds (minutes "
                      "per set)",
                      "python -m experiments.distributed --scale paper --sizes 1e8")),
)


EXPERIMENT = Experiment(
    name="distributed", title="Tile & Merge on Dask: 1e6 to 1e8 points, exact", grid=grid,
    plot=plot, repeats=1, measure=measure, main_job=True, minutes={"default": 0.9},
    options=(("--data", dict(help="scratch directory for the chunks and the tiles' files")),),
    claims=CLAIMS)

if __name__ == "__main__":
    sys.exit(EXPERIMENT.main())
