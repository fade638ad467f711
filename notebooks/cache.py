# ---
# jupyter:
#   jupytext:
#     formats: ipynb,py:percent
#     text_representation:
#       extension: .py
#       format_name: percent
#       format_version: '1.3'
#       jupytext_version: 1.19.6
#   kernelspec:
#     display_name: Python 3
#     language: python
#     name: python3
# ---

# %% [markdown]
# # Cache effects: where the rate bends, and which phase makes it bend
#
# Read from stored results (`fig4`'s sweep of N, with lfqt's phase times in
# each row's counts); the only thing computed here is a 100k-point mesh for
# the locality measure, under a second.  `LFQT_SCALE`, `LFQT_RESULTS` and
# `LFQT_RUN_MISSING` as in `scaling.ipynb`.

# %%
import os
import sys
from pathlib import Path

ROOT = Path(os.environ.get("LFQT_PROJECT", Path.cwd().parent if Path.cwd().name == "notebooks"
                           else Path.cwd()))
sys.path.insert(0, str(ROOT))

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from experiments.core import results
from experiments.core.registry import for_notebook
from experiments.paper1.fig4 import WORKING_SET_BYTES_PER_POINT

SCALE, RESULTS, stored = for_notebook(ROOT / "results")
df = stored("fig4")
meta = results.metadata(RESULTS, "fig4")
caches = meta.get("caches", {})
print(f"results: {RESULTS}; machine: {meta.get('cpu', '?')}; caches: "
      + ", ".join(f"{k} {v / 2**20:g} MiB" for k, v in caches.items()))

# %% [markdown]
# ## The rate against N, with the caches and the working set
#
# The working set is about 64 bytes per point (coordinates in Morton order
# and the triangle records); the measured peak memory per point is beside
# it.  A bend where the working set passes a cache size is a cache effect.

# %%
if df is None:
    df = pd.DataFrame(columns=results.FIELDS)
ok = df[(df["status"] == "ok") & (df["peer"] == "lfqt-dc")]
best = ok.groupby(["distribution", "n"]).agg(seconds=("seconds", "min"),
                                              peak_bytes_per_point=("bytes_per_point", "max"))
best["MP/s"] = best.index.get_level_values("n") / best["seconds"] / 1e6
best["working set MiB"] = best.index.get_level_values("n") * WORKING_SET_BYTES_PER_POINT / 2**20
print(best.round(3).to_string())

fig, ax = plt.subplots(figsize=(7, 4))
for d, g in best.groupby(level="distribution"):
    ns = g.index.get_level_values("n")
    ax.plot(ns, g["MP/s"], "-o", ms=3, label=d)
for name, size in caches.items():
    if name.endswith("i"):
        continue
    n = size / WORKING_SET_BYTES_PER_POINT
    ax.axvline(n, color="#999999", ls="--", lw=0.8)
    ax.text(n, ax.get_ylim()[1] if len(best) else 1, f" {name}", va="top", fontsize=8)
ax.set_xscale("log")
ax.set_xlabel("N (vertical lines: N whose working set fills the cache)")
ax.set_ylabel("MP/s, single thread (minimum time)")
ax.legend(fontsize=7)

# %% [markdown]
# ## Phase times per point against N
#
# Each lfqt row carries its phase times (`seconds_*` in its counts).  The
# phase whose time per point rises where the rate dips is the one that
# makes the dip.

# %%
PHASES = ["validate", "sort", "allocate", "subdivide", "merge", "output"]
rows = []
for r in ok.itertuples():
    rows.append({"distribution": r.distribution, "n": r.n,
                 **{p: r.counts.get(f"seconds_{p}", np.nan) / r.n * 1e9 for p in PHASES}})
phases = pd.DataFrame(rows).groupby(["distribution", "n"]).median() if rows else pd.DataFrame()
print("nanoseconds per point, median of the repeats")
print(phases.round(1).to_string())
if len(phases):
    uni = phases.loc["uniform"] if "uniform" in phases.index.get_level_values(0) else phases
    fig, ax = plt.subplots(figsize=(7, 4))
    uni.plot.area(ax=ax, logx=True, alpha=0.8)
    ax.set_ylabel("ns per point (uniform)")
    ax.set_xlabel("N")
    step = uni.sum(axis=1)
    if len(step) > 1:
        worst = (uni.diff().div(step.shift(), axis=0)).stack().idxmax()
        print(f"largest rise between two sizes: {worst[1]} before N = {worst[0]:,}")

# %% [markdown]
# ## Hardware counters
#
# Instructions and cache misses per point of lfqt and CGAL, measured with
# `perf stat` by `experiments.core.perf`, where the machine lets perf count.

# %%
from experiments.core import perf

can_count, why = perf.available()
if not can_count:
    print(f"no hardware counters on this machine: {why}")
else:
    import tempfile

    import generators
    from drivers.cgal import CGAL_BINARY
    n = 1_000_000
    pts = np.asarray(generators.make("uniform", n))
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "points.npy")
        np.save(path, pts)
        code = ("import numpy, lfqt; p = numpy.load({!r}); lfqt.triangulate(p[:1000]); "
                "lfqt.triangulate(p)")
        runs = {"lfqt": [sys.executable, "-c", code.format(path)],
                "lfqt (startup only)": [sys.executable, "-c", code.format(path).rsplit(";", 1)[0]],
                "CGAL": [str(CGAL_BINARY), "dt2", path]}
        counted = {k: perf.stat(v)[0] for k, v in runs.items()}
    base = counted.pop("lfqt (startup only)")
    counted["lfqt"] = {k: v - base[k] for k, v in counted["lfqt"].items()}
    print(pd.DataFrame(counted).div(n).round(1).to_string())

# %% [markdown]
# ## Locality of the Morton order
#
# Mean distance, in index, between the two ends of each mesh edge when the
# vertices are numbered in an order: a small distance means neighbours sit
# close in memory.  Morton is lfqt's (the LFQT's sort), against the Hilbert
# and Kd-tree orders of `lfqt.orders` and a random numbering.

# %%
import lfqt
from lfqt import orders

pts = np.random.default_rng(0).random((100_000, 2))
tri = lfqt.triangulate(pts)
s = tri.simplices.astype(np.int64)
edges = np.unique(np.sort(np.concatenate([s[:, [0, 1]], s[:, [1, 2]], s[:, [2, 0]]]), axis=1),
                  axis=0)
numberings = {"Morton (lfqt)": lfqt.quadtree(pts).order,
              "Hilbert": orders.order(pts, "hilbert")[0],
              "Kd-tree": orders.order(pts, "kdtree")[0],
              "random": np.random.default_rng(1).permutation(len(pts))}
locality = {}
for name, perm in numberings.items():
    rank = np.empty(len(pts), dtype=np.int64)
    rank[perm] = np.arange(len(pts))
    gap = np.abs(rank[edges[:, 0]] - rank[edges[:, 1]])
    locality[name] = {"mean index distance": gap.mean(), "median": np.median(gap),
                      "within 64 (one 4 KiB page of 64-byte records)": (gap < 64).mean()}
print(pd.DataFrame(locality).T.round(3).to_string())
