"""Paper 2, Table 1 (cube): run time, order building included, of the
Kd-tree, BRIO and Hilbert orders, through CGAL as the paper measured (Kd and
BRIO inserted one by one with their hints; Hilbert is CGAL's own range
insertion, which spatially sorts) and through lfqt.insert."""
import sys

import numpy as np

from . import results
from .experiment import Experiment, figure_paths
from .runner import Cell

SIZES = {"smoke": [5_000], "default": [100_000, 200_000],
         "paper": [100_000, 200_000, 300_000, 400_000, 500_000, 600_000]}
# (label, ours, CGAL)
ORDERS = [("kdtree", "lfqt-insert-kdtree", "cgal-dt3-kdtree"),
          ("brio", "lfqt-insert-brio", "cgal-dt3-brio"),
          ("hilbert", "lfqt-insert-hilbert", "cgal-dt3")]
MODEL = "cube"
TABLE = "Table 1"


def grid(scale, threads):
    return [Cell(peer, MODEL, n, threads=threads) for n in SIZES[scale] for _, ours, cgal in ORDERS
            for peer in (ours, cgal)]


def published_times(table=TABLE):
    out = {}
    for r in results.published("liu2013").to_dict("records"):
        if r["table"] == table and r["metric"] == "cpu_time" and r["value"]:
            out[(r["order"], int(r["n"]))] = float(r["value"])
    return out


def plot(df, out):
    import matplotlib.pyplot as plt
    s = results.summarize(df)
    pub = published_times()
    fig, ax = plt.subplots(figsize=(8, 5))
    colors = {"kdtree": "#1b6ca8", "brio": "#d1495b", "hilbert": "#66a182"}
    ns = sorted(df["n"].unique())
    print(f"\n{'n':>9} {'order':8} {'lfqt s':>9} {'CGAL s':>9} {'paper s':>8}   ratios to Kd: lfqt / CGAL / paper")
    kd = {}
    for label, ours, cgal in ORDERS:
        ys_ours = [results.cell(s, ours, MODEL, n, False).get("median") for n in ns]
        ys_cgal = [results.cell(s, cgal, MODEL, n, False).get("median") for n in ns]
        ax.plot(ns, [y or np.nan for y in ys_ours], "-o", color=colors[label], label=f"{label}: lfqt")
        ax.plot(ns, [y or np.nan for y in ys_cgal], "--s", color=colors[label], label=f"{label}: CGAL")
        pn = sorted(n for (o, n) in pub if o == label)
        ax.plot(pn, [pub[(label, n)] for n in pn], ":^", color=colors[label], alpha=0.6,
                label=f"{label}: paper (2012 PC)")
        for n, yo, yc in zip(ns, ys_ours, ys_cgal):
            kd.setdefault(n, (yo, yc, pub.get(("kdtree", n))))
            k = kd[n]
            print(f"{n:>9,} {label:8} {yo or float('nan'):9.3f} {yc or float('nan'):9.3f} "
                  f"{pub.get((label, n), float('nan')):8.0f}   "
                  f"{results.fmt_ratio(results.ratio(yo, k[0]))} / {results.fmt_ratio(results.ratio(yc, k[1]))} / "
                  f"{results.fmt_ratio(results.ratio(pub.get((label, n)), k[2]))}")
    ax.set_xlabel("points")
    ax.set_ylabel("seconds (median; paper: CPU seconds)")
    ax.set_yscale("log")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, ncol=3)
    ax.set_title(f"Paper 2, {TABLE} ({MODEL}): time per insertion order")
    return figure_paths(fig, out, "liu_table1")


EXPERIMENT = Experiment("liu_table1", "cube: time of the Kd-tree, BRIO and Hilbert orders, in CGAL "
                        "and in lfqt", grid, plot, reproduces=(("Paper 2", "Table 1"),),
                        main_job=True)
main = EXPERIMENT.main


if __name__ == "__main__":
    sys.exit(main())
