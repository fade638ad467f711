"""Paper 1, Figure 4: lfqt's single-thread rate (million points per second)
from 1k points upward, per distribution, with this machine's L1/L2/L3 sizes
marked.  The paper's figure gives no numbers; its text says the rate is flat
but for bends where the data leaves L1/L2 and L3."""
import sys

import numpy as np

from ..core.experiment import Experiment, figure_paths
from ..core.machine import cache_sizes
from ..core.runner import Cell

DISTS = ["uniform", "grid", "cluster", "circle", "spiral"]
SIZES = {"smoke": [1_000, 10_000, 100_000],
         "default": [1_000, 3_000, 10_000, 30_000, 100_000, 300_000, 1_000_000, 3_000_000],
         "paper": [int(v) for v in np.logspace(3, 8, 16)] + [500_000_000]}
WORKING_SET_BYTES_PER_POINT = 64  # coordinates in Morton order (16) + triangle records (48)


def grid(scale, threads):
    return [Cell("lfqt-dc", d, n, threads=threads) for d in DISTS for n in SIZES[scale]]


def _rates(df, d, column):
    """(sizes, MP/s from the minimum of ``column`` over the repeats) of lfqt on d."""
    ok = df[(df["peer"] == "lfqt-dc") & (df["distribution"] == d) & (df["status"] == "ok")]
    best = ok.groupby("n")[column].min().dropna()
    return best.index.to_numpy(), (best.index / best / 1e6).to_numpy()


def plot(df, out):
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(13, 5), sharey=True)
    panels = (("seconds", "wall clock"), ("seconds_at_3ghz", "TSC cycles at 3 GHz, as the paper"))
    print(f"\n{'distribution':12} " + " ".join(f"{n:>10,}" for n in sorted(df['n'].unique()))
          + "   (MP/s, from the minimum of the repeats as the paper did; wall / cycles at 3 GHz)")
    highest = 0.0
    for ax, (column, label) in zip(axes, panels):
        for d in DISTS:
            ns, rates = _rates(df, d, column)
            ax.plot(ns, rates, marker="o", label=d)
            highest = max([highest, *rates])
            if column == "seconds":
                print(f"{d:12} " + " ".join(f"{r:10.2f}" for r in rates))
        ax.set_xscale("log")
        ax.set_xlabel("points")
        ax.grid(alpha=0.3)
        ax.set_title(f"rate from {label}", fontsize=10)
    top = 1.3 * highest if highest else 1.0  # a margin above the curves for the cache labels
    for ax in axes:
        ax.set_ylim(0, top)
        for name, size in cache_sizes().items():
            if name in ("L1d", "L2", "L3"):
                n = size / WORKING_SET_BYTES_PER_POINT
                ax.axvline(n, color="gray", ls="--", lw=0.8)
                # the label sits in a white box under the top edge: no curve strikes it
                ax.text(n, top * 0.99, f"{name} {size // 1024} KiB", fontsize=8, va="top",
                        ha="center", color="gray", rotation=90,
                        bbox=dict(facecolor="white", edgecolor="none", pad=1.0))
    for d in DISTS:
        ns, rates = _rates(df, d, "seconds_at_3ghz")
        if len(rates):
            print(f"{d:12} " + " ".join(f"{r:10.2f}" for r in rates) + "   (cycles at 3 GHz)")
    axes[0].set_ylabel("rate, million points / s (1 thread)")
    axes[1].legend()
    fig.suptitle("Paper 1, Fig. 4: rate vs size (the published figure has no numbers: flat with "
                 "bends at L1/L2 and L3; Grid fastest)", fontsize=10)
    fig.tight_layout()
    return figure_paths(fig, out, "fig4")


EXPERIMENT = Experiment("fig4", "lfqt's single-thread rate from 1k points up, cache sizes marked",
                        grid, plot, reproduces=(("Paper 1", "Fig. 4"),), repeats=5, main_job=True)
main = EXPERIMENT.main


if __name__ == "__main__":
    sys.exit(main())
