"""Paper 2, Table 15: the time to build the insertion sequence alone, for
the Kd-tree and Hilbert orders on the cube and the cylinder, from 500k to
3.5M points (lfqt.orders, the orders both systems insert in)."""
import sys

import numpy as np

from . import liu
from ..core import results
from ..core.experiment import Experiment, figure_paths
from ..core.runner import Cell

MODELS = ["cube", "cylinder"]
ORDERS = ["kdtree", "hilbert"]
SIZES = {"smoke": [liu.SMOKE_N], "default": [500_000, 1_500_000], "paper": liu.table_sizes(15)}


def grid(scale, threads):
    return [Cell(f"lfqt-order-{o}", m, n) for m in MODELS for n in SIZES[scale] for o in ORDERS]


def plot(df, out):
    import matplotlib.pyplot as plt
    s = results.summarize(df)
    pub = liu.values(15, "order_build_time")
    fig, axes = plt.subplots(1, len(MODELS), figsize=(11, 4), sharey=True)
    print(f"\n{'model':9} {'n':>10} {'order':8} {'ours s':>8} {'paper s':>8}   Kd/Hilbert: ours, "
          "paper")
    for ax, model in zip(axes, MODELS):
        ns = sorted(df.loc[df["distribution"] == model, "n"].unique())
        for order in ORDERS:
            t = [results.median(s, f"lfqt-order-{order}", model, n, False) for n in ns]
            ax.plot(ns, [v or np.nan for v in t], "-o", color=liu.COLORS[order],
                    label=f"{order}: lfqt (this machine)")
            pn = sorted(n for (m, o, n) in pub if (m, o) == (model, order))
            ax.plot(pn, [pub[(model, order, n)][0] for n in pn], ":^", color=liu.COLORS[order],
                    alpha=0.6, label=f"{order}: paper (whole seconds, 2012 PC)")
        for n in ns:
            kd, hb = (results.median(s, f"lfqt-order-{o}", model, n, False) for o in ORDERS)
            pk, ph = (pub.get((model, o, n), (None,))[0] for o in ORDERS)
            for order, v in zip(ORDERS, (kd, hb)):
                print(f"{model:9} {n:>10,} {order:8} {v or np.nan:8.3f} "
                      f"{pub.get((model, order, n), (np.nan,))[0] or np.nan:8.0f}   "
                      f"{results.fmt_ratio(results.ratio(kd, hb))}, "
                      f"{results.fmt_ratio(results.ratio(pk, ph))}")
        ax.set_title(f"{model} (Table 15)", fontsize=9)
        ax.set_xlabel("points")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("sequence building time, s (median)")
    axes[0].legend(fontsize=8)
    fig.suptitle("Paper 2, Table 15: time to build the insertion order alone", fontsize=10)
    fig.tight_layout()
    return figure_paths(fig, out, "liu_order_time")


EXPERIMENT = Experiment("liu_order_time", "time to build the Kd-tree and Hilbert orders alone, "
                        "cube and cylinder", grid, plot, reproduces=(("Paper 2", "Table 15"),),
                        main_job=True)
main = EXPERIMENT.main

if __name__ == "__main__":
    sys.exit(main())
