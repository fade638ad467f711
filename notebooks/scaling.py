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
# # Scaling: how run time grows with N, per peer and distribution
#
# Everything here is read from stored results (`experiments.core.results`); the
# notebook measures nothing.  Set `LFQT_SCALE` (smoke, default, paper) and
# `LFQT_RESULTS` (the results folder) in the environment, or edit the cell
# below.  With `LFQT_RUN_MISSING=1` a missing smoke-scale experiment is run
# first; otherwise the notebook names the command that makes it.

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

SCALE, RESULTS, stored = for_notebook(ROOT / "results")
print(f"results: {RESULTS} (scale {SCALE})")

# %% [markdown]
# ## Time and rate against N, every peer
#
# Pooled from the experiments that sweep N (`fig3`, `fig4`, `bench_dc`);
# one median per (peer, distribution, N), over every repeat and round.

# %%
frames = [df for df in (stored(n) for n in ("fig3", "fig4", "bench_dc")) if df is not None]
ok = pd.concat(frames) if frames else pd.DataFrame(columns=results.FIELDS)
ok = ok[(ok["status"] == "ok") & ~ok["count"].astype(bool) & (ok["threads"] == 1)]
medians = (ok.groupby(["peer", "distribution", "n"])["seconds"].median().rename("seconds")
           .reset_index())
medians["MP/s"] = medians["n"] / medians["seconds"] / 1e6
print(medians.pivot_table(index=["distribution", "n"], columns="peer", values="MP/s")
      .round(2).to_string())

# %%
dists = sorted(medians["distribution"].unique())
fig, axes = plt.subplots(1, max(len(dists), 1), figsize=(4 * max(len(dists), 1), 3.6),
                         squeeze=False, sharey=True)
for ax, d in zip(axes[0], dists):
    for peer, g in medians[medians["distribution"] == d].groupby("peer"):
        if g["n"].nunique() > 1:
            ax.plot(g["n"], g["MP/s"], "-o", ms=3, label=peer)
    ax.set_xscale("log")
    ax.set_title(d)
    ax.set_xlabel("N")
    ax.grid(alpha=0.3)
axes[0][0].set_ylabel("million points per second (median)")
axes[0][0].legend(fontsize=7)
fig.tight_layout()

# %% [markdown]
# ## A fitted exponent per peer and distribution
#
# `t = c N^b` fitted by least squares on log t against log N, with a 95%
# interval from the slope's standard error.  `b = 1` is linear.  N log N over
# one decade near N looks like `b = 1 + 1/ln N` (about 1.08 at 10^5-10^6), so
# an interval above that line, and clear of 1, says "not linear": paper 1's
# claim about Triangle.

# %%
def exponent(g):
    x, y = np.log(g["n"].to_numpy(float)), np.log(g["seconds"].to_numpy(float))
    if len(x) < 2 or np.ptp(x) == 0:
        return pd.Series({"b": np.nan, "lo": np.nan, "hi": np.nan, "sizes": len(x)})
    slope, intercept = np.polyfit(x, y, 1)
    resid = y - (slope * x + intercept)
    dof = max(len(x) - 2, 1)
    se = np.sqrt(resid @ resid / dof / ((x - x.mean()) @ (x - x.mean()))) if len(x) > 2 else 0.0
    half = 1.96 * se
    return pd.Series({"b": slope, "lo": slope - half, "hi": slope + half, "sizes": len(x)})


if len(medians):
    fits = medians.groupby(["peer", "distribution"]).apply(exponent, include_groups=False)
    fits = fits[fits["sizes"] > 1]
    nlogn = 1 + 1 / np.log(medians["n"].median())
    fits["reading"] = np.where(fits["lo"] > 1.02, "super-linear",
                               np.where(fits["hi"] < 1.02, "linear", "undecided"))
    print(f"N log N near the median N reads as b = {nlogn:.3f}; with two sizes the interval is "
          "0 wide")
    print(fits.round(3).to_string())
else:
    print("no sweep of N stored: nothing to fit")

# %% [markdown]
# ## Thread scaling (Fig. 6)

# %%
f6 = stored("fig6")
if f6 is not None:
    from experiments.paper1.fig6 import speedups
    rows = [(peer, d, n, t, sp) for (peer, d, n), s in speedups(f6).items() for t, sp, _ in s]
    table = pd.DataFrame(rows, columns=["peer", "distribution", "n", "threads", "speedup"])
    print(table.pivot_table(index=["peer", "distribution"], columns="threads",
                            values="speedup").round(2).to_string())
    fig, ax = plt.subplots(figsize=(5, 3.5))
    for (peer, d), g in table.groupby(["peer", "distribution"]):
        ax.plot(g["threads"], g["speedup"], "-o", label=f"{peer} {d}")
    ax.plot(table["threads"], table["threads"], "k:", lw=0.8)
    ax.set_xlabel("threads")
    ax.set_ylabel("speedup over one thread")
    ax.legend(fontsize=6)

# %% [markdown]
# ## Predicate counts per point against N, both pipelines
#
# The divide and conquer (`lfqt-dc` in `fig4`) and the inserter
# (`lfqt-insert-*` in `liu_counts`) report the same counters
# (`lfqt.predicates.counters`).  Flat counts per point are what linear
# scaling needs.

# %%
rows = []
for name in ("fig4", "liu_counts"):
    df = stored(name)
    if df is None:
        continue
    df = df[(df["status"] == "ok") & df["peer"].str.startswith("lfqt")]
    for r in df.drop_duplicates(["peer", "distribution", "n"]).itertuples():
        for key in ("orientation_tests", "incircle_tests", "conflicts"):
            if key in r.counts:
                rows.append((r.peer, r.distribution, r.n, key, r.counts[key] / r.n))
counts = pd.DataFrame(rows, columns=["peer", "distribution", "n", "count", "per point"])
if len(counts):
    print(counts.pivot_table(index=["peer", "distribution", "count"], columns="n",
                             values="per point").round(2).to_string())
