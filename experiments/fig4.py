"""Paper 1, Figure 4: lfqt's single-thread rate (million points per second)
from 1k points upward, per distribution, with this machine's L1/L2/L3 sizes
marked.  The paper's figure gives no numbers; its text says the rate is flat
but for bends where the data leaves L1/L2 and L3."""
import sys

import numpy as np

from . import results
from .experiment import Experiment, figure_paths
from .machine import cache_sizes
from .runner import Cell

DISTS = ["uniform", "grid", "cluster", "circle", "spiral"]
SIZES = {"smoke": [1_000, 10_000, 100_000],
         "default": [1_000, 3_000, 10_000, 30_000, 100_000, 300_000, 1_000_000, 3_000_000],
         "paper": [int(v) for v in np.logspace(3, 8, 16)] + [500_000_000]}
WORKING_SET_BYTES_PER_POINT = 64  # coordinates in Morton order (16) + triangle records (48)


def grid(scale, threads):
    return [Cell("lfqt-dc", d, n, threads=threads) for d in DISTS for n in SIZES[scale]]


def plot(df, out):
    import matplotlib.pyplot as plt
    s = results.summarize(df)
    fig, ax = plt.subplots(figsize=(8, 5))
    print(f"\n{'distribution':12} " + " ".join(f"{n:>10,}" for n in sorted(df['n'].unique()))
          + "   (MP/s, from the minimum of the repeats as the paper did)")
    for d in DISTS:
        ns = sorted(df.loc[df["distribution"] == d, "n"].unique())
        rates = [n / results.cell(s, "lfqt-dc", d, n, False)["min"] / 1e6
                 if results.cell(s, "lfqt-dc", d, n, False).get("min") else np.nan for n in ns]
        ax.plot(ns, rates, marker="o", label=d)
        print(f"{d:12} " + " ".join(f"{r:10.2f}" for r in rates))
    for name, size in cache_sizes().items():
        if name in ("L1d", "L2", "L3"):
            n = size / WORKING_SET_BYTES_PER_POINT
            ax.axvline(n, color="gray", ls="--", lw=0.8)
            ax.text(n, ax.get_ylim()[1] * 0.97, f" {name} {size // 1024} KiB", fontsize=8,
                    va="top", color="gray")
    ax.set_xscale("log")
    ax.set_xlabel("points")
    ax.set_ylabel("rate, million points / s (1 thread)")
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    ax.legend()
    ax.set_title("Paper 1, Fig. 4: rate vs size (published figure has no numbers:\n"
                 "flat with bends at L1/L2 and L3; Grid fastest)", fontsize=10)
    return figure_paths(fig, out, "fig4")


EXPERIMENT = Experiment("fig4", "lfqt's single-thread rate from 1k points up, cache sizes marked",
                        grid, plot, reproduces=(("Paper 1", "Fig. 4"),), repeats=5, main_job=True)
main = EXPERIMENT.main


if __name__ == "__main__":
    sys.exit(main())
